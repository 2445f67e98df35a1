//! Visual odometry of the forward camera (Sect. 2.2): the rotation between two frames from the
//! scan line (eqs. (3)-(5)), the translation from Harris corners of the lower window (Fig. 3)
//! tracked by Lucas-Kanade (eq. (6)) or matched by normalised cross-correlation (eq. (7)), put
//! on the floor ([`FeatureTracks`]). The scan line's rotation ("large rotations taken from the
//! scan line") also predicts where each feature went, which starts the tracker and centres the
//! matcher's search.

use super::camera::ForwardCamera;
use super::features::{FeatureConfig, FeatureMotion, FeatureTracks, TrackingError};
use super::grey::Grey;
use super::lk::pyramid;
use super::scanline::{ScanLine, ScanLineConfig};
use crate::VisionError;
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
    /// The translation's feature tracks.
    pub features: FeatureConfig,
}

impl Default for OdometryConfig {
    fn default() -> Self {
        Self {
            scanline: ScanLineConfig::default(),
            keyframe_px: 30.0,
            keyframe_frames: 6,
            keyframe_check_deg: 0.5,
            features: FeatureConfig::default(),
        }
    }
}

/// What one pair of frames gave.
#[derive(Debug, Clone, PartialEq)]
pub struct OdometryStep {
    /// The scan line's rotation, rad (counter-clockwise positive).
    pub rotation_rad: f64,
    /// The translation by Lucas-Kanade, or why there is none.
    pub lk: Result<FeatureMotion, TrackingError>,
    /// The translation by cross-correlation, or why there is none.
    pub ncc: Result<FeatureMotion, TrackingError>,
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
    features: FeatureTracks,
    config: OdometryConfig,
    previous: Option<Previous>,
    key: Option<Key>,
}

impl ForwardOdometry {
    /// The odometry of `camera`.
    pub fn new(camera: ForwardCamera, config: OdometryConfig) -> Result<Self, VisionError> {
        Ok(Self {
            scanline: ScanLine::new(&camera, &config.scanline)?,
            features: FeatureTracks::new(camera.clone(), config.features.clone()),
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
        self.features.reset();
    }

    /// The rotation since the previous frame through the key frame, unless it disagrees with
    /// the consecutive frames' by more than `keyframe_check_deg` (a key frame whose profile
    /// has changed too much gives a wrong minimum): then the consecutive reading, and a new key.
    fn rotation(&mut self, profile: &[f32], previous: Option<&[f32]>) -> Option<f64> {
        let direct = self.scanline.rotation_near(previous?, profile, 0.0);
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
        let from_key = self
            .scanline
            .rotation_near(&key.profile, profile, key.rotation_rad);
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
        let lk = &self.config.features.lk;
        let now = Previous {
            pyramid: pyramid(img, lk.levels, lk.smooth_sigma_px),
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
            let (lk, ncc) = self
                .features
                .step(&prev.pyramid, &now.pyramid, rotation_rad);
            OdometryStep {
                rotation_rad,
                lk,
                ncc,
            }
        });
        self.previous = Some(now);
        out
    }
}
