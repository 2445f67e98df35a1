//! Visual odometry of the forward camera (Sect. 2.2): the rotation between two frames from the
//! scan line (eqs. (3)-(5)), the translation from Harris corners of the lower window (Fig. 3)
//! tracked by Lucas-Kanade (eq. (6)) or matched by normalised cross-correlation (eq. (7)).
//!
//! The paper turns the features' mean vertical shift into distance by a scale factor; we put
//! every feature on the floor through the camera's height and tilt (the floor homography,
//! [`ForwardCamera::floor_point`]), so that a feature at `P` before and `Q` after a move by
//! rotation `R` and translation `t` gives `t = P - R Q` (ours: exact for any row). `R` is the
//! scan line's ("large rotations taken from the scan line"); it also predicts where each feature
//! went, which starts the tracker and centres the matcher's search. The translation is the
//! mean of the features within `inlier_mm` of their median (a feature on something that is not
//! floor, or a wrong match, falls out).

use super::harris::{HarrisConfig, harris_corners};
use super::lk::{LkConfig, pyramid, track_lk};
use super::ncc::{NccConfig, match_ncc};
use super::scanline::{ScanLine, ScanLineConfig};
use super::{ForwardCamera, Grey};
use crate::VisionError;
use nalgebra::{Point2, Rotation2, Vector2};
use serde::{Deserialize, Serialize};

/// Which tracker gave a translation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FeatureMethod {
    /// Lucas-Kanade tracking (Sect. 2.2.2).
    Lk,
    /// Normalised cross-correlation matching (Sect. 2.2.3).
    Ncc,
}

impl FeatureMethod {
    /// The name in records.
    pub fn name(self) -> &'static str {
        match self {
            Self::Lk => "lk",
            Self::Ncc => "ncc",
        }
    }
}

/// Settings of the visual odometry (`[vision.forward.odometry]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OdometryConfig {
    /// The rotation's window.
    pub scanline: ScanLineConfig,
    /// The scan line compares each frame with a key frame until the shift passes this many
    /// pixels (at the reference width), then the frame becomes the key (ours: 0 compares
    /// consecutive frames, the paper's way; a key frame adds up the profile's errors once per
    /// key instead of once per frame).
    pub keyframe_px: f64,
    /// Most frames a key frame is kept (forward motion slowly changes the profile).
    pub keyframe_frames: u32,
    /// A key frame's reading further than this from the consecutive frames' is dropped, deg.
    pub keyframe_check_deg: f64,
    /// Top of the translation window (Fig. 3's bottom window), as a fraction of the height.
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

impl Default for OdometryConfig {
    fn default() -> Self {
        Self {
            scanline: ScanLineConfig::default(),
            keyframe_px: 30.0,
            keyframe_frames: 6,
            keyframe_check_deg: 0.5,
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

/// What one pair of frames gave.
#[derive(Debug, Clone, PartialEq)]
pub struct OdometryStep {
    /// The scan line's rotation, rad (counter-clockwise positive).
    pub rotation_rad: f64,
    /// The translation by Lucas-Kanade, or why there is none.
    pub lk: Result<FeatureMotion, String>,
    /// The translation by cross-correlation, or why there is none.
    pub ncc: Result<FeatureMotion, String>,
}

/// The previous frame, as the odometry keeps it.
#[derive(Debug, Clone)]
struct Previous {
    pyramid: Vec<Grey>,
    profile: Vec<f32>,
}

/// The scan line's key frame: its profile, the rotation of the last frame from it, its age.
#[derive(Debug, Clone)]
struct Key {
    profile: Vec<f32>,
    rotation_rad: f64,
    frames: u32,
}

/// Visual odometry over successive frames of one camera.
#[derive(Debug, Clone)]
pub struct ForwardOdometry {
    camera: ForwardCamera,
    scanline: ScanLine,
    config: OdometryConfig,
    previous: Option<Previous>,
    key: Option<Key>,
}

impl ForwardOdometry {
    /// The odometry of `camera`.
    pub fn new(camera: ForwardCamera, config: OdometryConfig) -> Result<Self, VisionError> {
        Ok(Self {
            scanline: ScanLine::new(&camera, &config.scanline)?,
            camera,
            config,
            previous: None,
            key: None,
        })
    }

    /// The scan line's sampling.
    pub fn scanline(&self) -> &ScanLine {
        &self.scanline
    }

    /// Forgets the previous frame (the robot was carried).
    pub fn reset(&mut self) {
        self.previous = None;
        self.key = None;
    }

    /// The rotation since the previous frame through the key frame, unless it disagrees with
    /// the consecutive frames' by more than `keyframe_check_deg` (a key frame whose profile
    /// has changed too much gives a wrong minimum): then the consecutive reading, and a new key.
    fn rotation(&mut self, profile: &[f32], previous: Option<&[f32]>) -> Option<f64> {
        let direct = self.scanline.rotation_rad(previous?, profile);
        let since = self.rotation_from_key(profile)?;
        if (since - direct).abs() > self.config.keyframe_check_deg.to_radians() {
            self.key = None;
            return Some(direct);
        }
        Some(since)
    }

    fn rotation_from_key(&mut self, profile: &[f32]) -> Option<f64> {
        let c = &self.config;
        let scale = self.camera.width_px as f64 / c.scanline.reference_width_px;
        let limit =
            c.keyframe_px * scale * self.scanline.alpha_rad() * c.scanline.oversample.max(1) as f64;
        let key = self.key.as_mut()?;
        let from_key = self.scanline.rotation_rad(&key.profile, profile);
        let since = from_key - key.rotation_rad;
        key.rotation_rad = from_key;
        key.frames += 1;
        if from_key.abs() >= limit || key.frames >= c.keyframe_frames {
            self.key = None;
        }
        Some(since)
    }

    /// Takes the next frame: the motion since the previous one (`None` for the first).
    pub fn step(&mut self, img: &Grey) -> Option<OdometryStep> {
        let now = Previous {
            pyramid: pyramid(img, self.config.lk.levels, self.config.lk.smooth_sigma_px),
            profile: self.scanline.profile(img),
        };
        let previous = self.previous.take();
        let rotation = self.rotation(
            &now.profile,
            previous.as_ref().map(|p| p.profile.as_slice()),
        );
        if self.key.is_none() {
            self.key = Some(Key {
                profile: now.profile.clone(),
                rotation_rad: 0.0,
                frames: 0,
            });
        }
        let out = previous.as_ref().zip(rotation).map(|(prev, rotation_rad)| {
            let (lk, ncc) = self.translations(prev, &now, rotation_rad);
            OdometryStep {
                rotation_rad,
                lk,
                ncc,
            }
        });
        self.previous = Some(now);
        out
    }

    /// The translations by both trackers between `prev` and `now`, given the rotation.
    #[allow(clippy::type_complexity)]
    fn translations(
        &self,
        prev: &Previous,
        now: &Previous,
        rotation_rad: f64,
    ) -> (Result<FeatureMotion, String>, Result<FeatureMotion, String>) {
        let c = &self.config;
        let h = self.camera.height_px;
        let top = (c.window_top * h as f64).round() as u32;
        let corners = harris_corners(
            &prev.pyramid[0],
            &c.harris,
            top..h - c.border_px,
            c.border_px,
        );
        if corners.is_empty() {
            let why = "no corner in the lower window".to_string();
            return (Err(why.clone()), Err(why));
        }
        let r = Rotation2::new(rotation_rad);
        let mut points = Vec::new();
        let mut guesses = Vec::new();
        let mut floor = Vec::new();
        for k in &corners {
            let p = (k.x as f64, k.y as f64);
            let Some(fp) = self.camera.floor_point(p.0, p.1) else {
                continue;
            };
            // Where the point is in the later frame if the robot only turned.
            let q = Point2::from(r.inverse() * fp.coords);
            let Some(g) = self.camera.project_floor(&q) else {
                continue;
            };
            points.push(p);
            guesses.push(g);
            floor.push(fp);
        }
        let lk_ends = track_lk(&prev.pyramid, &now.pyramid, &points, &guesses, &c.lk);
        let ncc_ends: Vec<Option<(f64, f64)>> = points
            .iter()
            .zip(&guesses)
            .map(|(&p, &g)| {
                match_ncc(
                    &prev.pyramid[0],
                    &now.pyramid[0],
                    (p.0 as u32, p.1 as u32),
                    g,
                    &c.ncc,
                )
                .map(|m| (m.x, m.y))
            })
            .collect();
        (
            self.motion(&floor, &lk_ends, &r),
            self.motion(&floor, &ncc_ends, &r),
        )
    }

    /// `t = P - R Q` over the features followed, averaged over the inliers.
    fn motion(
        &self,
        floor: &[Point2<f64>],
        ends: &[Option<(f64, f64)>],
        r: &Rotation2<f64>,
    ) -> Result<FeatureMotion, String> {
        let t: Vec<Vector2<f64>> = floor
            .iter()
            .zip(ends)
            .filter_map(|(p, e)| {
                let (x, y) = (*e)?;
                let q = self.camera.floor_point(x, y)?;
                Some(p.coords - r * q.coords)
            })
            .collect();
        if t.is_empty() {
            return Err(format!("none of {} corners followed", floor.len()));
        }
        let median = |f: &dyn Fn(&Vector2<f64>) -> f64| {
            let mut v: Vec<f64> = t.iter().map(f).collect();
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let m = Vector2::new(median(&|v| v.x), median(&|v| v.y));
        let inliers: Vec<&Vector2<f64>> = t
            .iter()
            .filter(|v| (*v - m).norm() <= self.config.inlier_mm)
            .collect();
        if inliers.len() < self.config.min_features {
            return Err(format!(
                "{} of {} features agree (need {})",
                inliers.len(),
                t.len(),
                self.config.min_features
            ));
        }
        let sum: Vector2<f64> = inliers.iter().copied().sum();
        Ok(FeatureMotion {
            translation_mm: sum / inliers.len() as f64,
            features: t.len(),
            inliers: inliers.len(),
        })
    }
}
