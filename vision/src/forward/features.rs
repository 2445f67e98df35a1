//! The translation half of the forward camera's visual odometry (Sects. 2.2.2-2.2.3): Harris
//! corners of a key frame's lower window, followed into each later frame by Lucas-Kanade
//! (eq. (6)) and by normalised cross-correlation (eq. (7)), and put on the floor.
//!
//! A feature at floor point `P` in the key frame and `Q` now, after the robot turned by `R` and
//! moved by `t` since the key, gives `P = R Q + t`, so `t = P - R Q` (ours: the paper turns the
//! mean vertical shift into distance by a scale factor; the floor homography is exact for any
//! row and any turn). The paper compares consecutive frames; following each feature from a key
//! frame over several frames (`key_frames`) makes one tracking error count once per key instead
//! of once per frame (ours: at 6 mm a frame and about 0.3 px of error per match, consecutive
//! frames read a 240 mm leg to about 2%; 1 restores the paper's way).

use super::camera::ForwardCamera;
use super::grey::Grey;
use super::harris::{HarrisConfig, harris_corners};
use super::lk::{LkConfig, track_lk};
use super::ncc::{NccConfig, match_ncc};
use nalgebra::{Isometry2, Point2, Rotation2, Vector2};
use serde::{Deserialize, Serialize};

/// Settings of the feature tracks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FeatureConfig {
    /// Frames a key frame's features are followed before the frame they reach becomes the
    /// key (1: consecutive frames, the paper's way).
    pub key_frames: u32,
    /// Top of the window the corners are taken in (Fig. 3's bottom window), as a fraction of
    /// the height.
    pub window_top: f64,
    /// Corners are taken this far from the image's sides and bottom, px.
    pub border_px: u32,
    /// Corner detection.
    pub harris: HarrisConfig,
    /// Lucas-Kanade tracking.
    pub lk: LkConfig,
    /// Cross-correlation matching.
    pub ncc: NccConfig,
    /// Features within this of the median translation are averaged, mm.
    pub inlier_mm: f64,
    /// Fewest inliers for a translation.
    pub min_features: usize,
}

impl Default for FeatureConfig {
    fn default() -> Self {
        Self {
            key_frames: 5,
            window_top: 0.25,
            border_px: 7,
            harris: HarrisConfig::default(),
            lk: LkConfig::default(),
            ncc: NccConfig::default(),
            inlier_mm: 3.0,
            min_features: 1,
        }
    }
}

/// A translation read from features.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeatureMotion {
    /// The translation in the earlier frame's robot axes, mm.
    pub translation_mm: Vector2<f64>,
    /// Features followed into the later frame.
    pub features: usize,
    /// Of which within `inlier_mm` of the median.
    pub inliers: usize,
}

/// One tracker's features since the key frame: where each is now (`None`: lost) and the pose
/// of the last frame in the key frame's axes.
#[derive(Debug, Clone)]
struct Track {
    ends: Vec<Option<(f64, f64)>>,
    pose: Isometry2<f64>,
}

/// A key frame: its image (full resolution first, then the pyramid), its corners and their
/// floor points, the scan line's rotation since it, its age.
#[derive(Debug, Clone)]
struct Key {
    pyramid: Vec<Grey>,
    corners: Vec<(f64, f64)>,
    floor: Vec<Point2<f64>>,
    rotation_rad: f64,
    frames: u32,
    lk: Track,
    ncc: Track,
}

/// Why a tracker gives no translation between two frames.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrackingError {
    /// The key frame has no corner on the floor in the lower window.
    #[error("no corner in the lower window")]
    NoCorner,
    /// Every feature was lost.
    #[error("no feature followed")]
    NoneFollowed,
    /// Too few features agree on the translation.
    #[error("{inliers} of {features} features agree (need {needed})")]
    TooFewAgree {
        /// Features near the median translation.
        inliers: usize,
        /// Features followed.
        features: usize,
        /// Features that must agree.
        needed: usize,
    },
}

/// Both trackers' translations between two frames, or why there is none.
pub type Translations = (
    Result<FeatureMotion, TrackingError>,
    Result<FeatureMotion, TrackingError>,
);

/// Feature tracks of one camera from key frame to key frame.
#[derive(Debug, Clone)]
pub struct FeatureTracks {
    camera: ForwardCamera,
    config: FeatureConfig,
    key: Option<Key>,
}

impl FeatureTracks {
    /// Tracks of `camera`'s features.
    pub fn new(camera: ForwardCamera, config: FeatureConfig) -> Self {
        Self {
            camera,
            config,
            key: None,
        }
    }

    /// Forgets the key frame.
    pub fn reset(&mut self) {
        self.key = None;
    }

    /// The translations between the previous frame `prev` and `now` (pyramids), the robot
    /// having turned by `rotation_rad` between them.
    pub fn step(&mut self, prev: &[Grey], now: &[Grey], rotation_rad: f64) -> Translations {
        if self.key.is_none() {
            self.key = self.key_of(prev);
        }
        let Some(key) = self.key.as_mut() else {
            return (Err(TrackingError::NoCorner), Err(TrackingError::NoCorner));
        };
        key.rotation_rad += rotation_rad;
        key.frames += 1;
        let r_now = Rotation2::new(key.rotation_rad);
        let r_step = Rotation2::new(rotation_rad);
        let (camera, c) = (&self.camera, &self.config);
        let guesses = |t: &Track| -> Vec<(f64, f64)> {
            t.ends
                .iter()
                .zip(&key.corners)
                .map(|(e, k)| predict(camera, e.unwrap_or(*k), &r_step).unwrap_or(*k))
                .collect()
        };
        let (lk_guess, ncc_guess) = (guesses(&key.lk), guesses(&key.ncc));
        let lk_ends = track_lk(&key.pyramid, now, &key.corners, &lk_guess, &c.lk);
        let ncc_ends = ncc_ends(&key.pyramid[0], &now[0], &key.corners, &ncc_guess, &c.ncc);
        let lk = advance(camera, c, &key.floor, &mut key.lk, lk_ends, &r_now);
        let ncc = advance(camera, c, &key.floor, &mut key.ncc, ncc_ends, &r_now);
        let live = |t: &Track| t.ends.iter().flatten().count();
        if key.frames >= c.key_frames
            || lk.is_err()
            || ncc.is_err()
            || live(&key.lk).min(live(&key.ncc)) < c.min_features.max(2)
        {
            self.key = self.key_of(now);
        }
        (lk, ncc)
    }

    /// `image` (a pyramid) as a key frame: its corners on the floor; `None` without any.
    fn key_of(&self, image: &[Grey]) -> Option<Key> {
        let c = &self.config;
        let h = self.camera.height_px;
        let top = (c.window_top * h as f64).round() as u32;
        let bottom = h.saturating_sub(c.border_px);
        let mut corners = Vec::new();
        let mut floor = Vec::new();
        for k in harris_corners(&image[0], &c.harris, top..bottom, c.border_px) {
            let p = (k.x as f64, k.y as f64);
            if let Some(fp) = self.camera.floor_point(p.0, p.1) {
                corners.push(p);
                floor.push(fp);
            }
        }
        if corners.is_empty() {
            return None;
        }
        let track = Track {
            ends: corners.iter().map(|&p| Some(p)).collect(),
            pose: Isometry2::identity(),
        };
        Some(Key {
            pyramid: image.to_vec(),
            corners,
            floor,
            rotation_rad: 0.0,
            frames: 0,
            lk: track.clone(),
            ncc: track,
        })
    }
}

/// Where the feature seen at pixel `at` in the previous frame is now if the robot only turned
/// by `r` (floor points: `Q = R^-1 P`).
fn predict(camera: &ForwardCamera, at: (f64, f64), r: &Rotation2<f64>) -> Option<(f64, f64)> {
    let p = camera.floor_point(at.0, at.1)?;
    camera.project_floor(&Point2::from(r.inverse() * p.coords))
}

/// The key frame's corners matched in `now` by cross-correlation around `guesses`.
fn ncc_ends(
    key: &Grey,
    now: &Grey,
    corners: &[(f64, f64)],
    guesses: &[(f64, f64)],
    config: &NccConfig,
) -> Vec<Option<(f64, f64)>> {
    corners
        .iter()
        .zip(guesses)
        .map(|(&p, &g)| {
            match_ncc(key, now, (p.0 as u32, p.1 as u32), g, config).map(|m| (m.x, m.y))
        })
        .collect()
}

/// Moves `track` on to `ends` (a lost feature stays lost) and returns the motion from its last
/// frame: the key-to-now pose `(R, t)` from `t = P - R Q`, then `pose_prev^-1 pose_now`.
fn advance(
    camera: &ForwardCamera,
    config: &FeatureConfig,
    floor: &[Point2<f64>],
    track: &mut Track,
    ends: Vec<Option<(f64, f64)>>,
    r_now: &Rotation2<f64>,
) -> Result<FeatureMotion, TrackingError> {
    for (old, new) in track.ends.iter_mut().zip(ends) {
        *old = old.and(new);
    }
    let t: Vec<Vector2<f64>> = floor
        .iter()
        .zip(&track.ends)
        .filter_map(|(p, e)| {
            let (x, y) = (*e)?;
            let q = camera.floor_point(x, y)?;
            Some(p.coords - r_now * q.coords)
        })
        .collect();
    let motion = robust_mean(&t, config)?;
    let pose = Isometry2::new(motion.translation_mm, r_now.angle());
    let step = track.pose.inverse() * pose;
    track.pose = pose;
    Ok(FeatureMotion {
        translation_mm: step.translation.vector,
        ..motion
    })
}

/// The mean of the translations within `inlier_mm` of their componentwise median.
fn robust_mean(t: &[Vector2<f64>], config: &FeatureConfig) -> Result<FeatureMotion, TrackingError> {
    if t.is_empty() {
        return Err(TrackingError::NoneFollowed);
    }
    let m = Vector2::new(median(t.iter().map(|v| v.x)), median(t.iter().map(|v| v.y)));
    let inliers: Vec<&Vector2<f64>> = t
        .iter()
        .filter(|v| (*v - m).norm() <= config.inlier_mm)
        .collect();
    if inliers.is_empty() || inliers.len() < config.min_features {
        return Err(TrackingError::TooFewAgree {
            inliers: inliers.len(),
            features: t.len(),
            needed: config.min_features.max(1),
        });
    }
    let sum: Vector2<f64> = inliers.iter().copied().sum();
    Ok(FeatureMotion {
        translation_mm: sum / inliers.len() as f64,
        features: t.len(),
        inliers: inliers.len(),
    })
}

/// The median (the mean of the middle two of an even count); `values` is not empty.
fn median(values: impl Iterator<Item = f64>) -> f64 {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::super::lk::pyramid;
    use super::super::testing::{camera, floor_view};
    use super::*;

    #[test]
    fn median_of_an_even_count_is_the_mean_of_the_middle_two() {
        assert_eq!(median([4.0, 1.0, 3.0].into_iter()), 3.0);
        assert_eq!(median([4.0, 1.0, 3.0, 2.0].into_iter()), 2.5);
    }

    #[test]
    fn robust_mean_drops_a_feature_far_from_the_median() {
        let t = [
            Vector2::new(6.0, 0.1),
            Vector2::new(6.2, -0.1),
            Vector2::new(5.9, 0.0),
            Vector2::new(14.0, 3.0),
        ];
        let m = robust_mean(&t, &FeatureConfig::default()).unwrap();
        assert_eq!((m.features, m.inliers), (4, 3));
        assert!((m.translation_mm.x - 6.0333).abs() < 1e-3, "{m:?}");
        assert_eq!(
            robust_mean(&[], &FeatureConfig::default()).unwrap_err(),
            TrackingError::NoneFollowed
        );
    }

    /// Driving 6 mm a frame straight ahead over dark squares, each tracker reads each frame's
    /// motion, by consecutive frames and by key frames, and adds up to the distance.
    #[test]
    fn straight_run_adds_up_to_the_distance_by_both_trackers() {
        let cam = camera();
        for key_frames in [1, 5] {
            let config = FeatureConfig {
                key_frames,
                ..FeatureConfig::default()
            };
            let mut tracks = FeatureTracks::new(cam.clone(), config.clone());
            let frame = |x_mm: f64| pyramid(&floor_view(&cam, x_mm, 0.0, 0.0), 3, 1.0);
            let (mut lk, mut ncc) = (Vector2::zeros(), Vector2::zeros());
            let mut prev = frame(0.0);
            for k in 1..=20 {
                let now = frame(6.0 * k as f64);
                let (a, b) = tracks.step(&prev, &now, 0.0);
                let (a, b) = (a.expect("lk"), b.expect("ncc"));
                assert!(
                    (a.translation_mm.x - 6.0).abs() < 1.0,
                    "{key_frames}: {a:?}"
                );
                lk += a.translation_mm;
                ncc += b.translation_mm;
                prev = now;
            }
            for (name, t) in [("lk", lk), ("ncc", ncc)] {
                eprintln!("key_frames {key_frames}, {name}: {t:?}");
                assert!((t.x - 120.0).abs() < 1.5, "{key_frames} {name}: {t}");
                assert!(t.y.abs() < 1.5, "{key_frames} {name}: {t}");
            }
        }
    }

    /// Turning on the spot by 1.5 degrees a frame, with the rotation given, the trackers read
    /// no translation.
    #[test]
    fn turn_on_the_spot_reads_no_translation() {
        let cam = camera();
        let mut tracks = FeatureTracks::new(cam.clone(), FeatureConfig::default());
        let step = 1.5f64.to_radians();
        let frame = |k: i32| pyramid(&floor_view(&cam, 0.0, 0.0, step * k as f64), 3, 1.0);
        let mut prev = frame(0);
        let mut sum = Vector2::zeros();
        for k in 1..=10 {
            let now = frame(k);
            let (a, _) = tracks.step(&prev, &now, step);
            sum += a.expect("lk").translation_mm;
            prev = now;
        }
        assert!(sum.norm() < 1.5, "{sum}");
    }
}
