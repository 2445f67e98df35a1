//! Conical omnistereo (Spacek and Burbridge, "Instantaneous robot self-localization and motion
//! estimation with omnidirectional vision", 2007): two coaxial 90-degree cones, one above the
//! other, see every object above their tips twice; the radial disparity of its two images gives
//! its range (eqs. (1)-(2), Sect. 2). From the ranges:
//! - [`trilateration`]: the position from the three nearest landmarks of a known map, the
//!   heading from their bearings (Sect. 1);
//! - [`compass`]: the rotation between two frames from the angular optic flow, with no
//!   iteration (the paper gives the idea, not the algorithm: ours is per-ring circular
//!   correlation);
//! - [`interframe`]: the translation between two frames, one solution per feature seen in both,
//!   combined by a robust clustering of ours (the paper's `Clumat` is not published).
//!
//! Image conventions (as everywhere in this crate): image coordinates `(X, Y)` from the mirror
//! axis's image, Y up; a scene ray keeps its pixel's azimuth `atan2(Y, X)`, which is the
//! bearing in the robot frame (counter-clockwise from the robot's x axis). A 90-degree cone
//! images a point at horizontal range `r` from the axis and height `z` above its tip at image
//! radius `h = v z / (r + d)`: height goes outward, the horizon is the image centre.

pub mod compass;
pub mod interframe;
pub mod marks;
pub mod range;
pub mod rim;
pub mod trilateration;

pub use compass::{AngularProfile, CompassConfig, Rotation};
pub use interframe::{
    Candidate, FeaturePair, Translation, densest_cluster, translation_candidates,
};
pub use marks::{ColourMark, MarkConfig, detect_marks};
pub use range::{RangedMark, StereoGeometry, range_marks};
pub use rim::MirrorRim;
pub use trilateration::{LandmarkRange, TrilaterationMode, trilaterate};

use crate::VisionError;
use serde::{Deserialize, Serialize};

/// Settings of the omnistereo pipeline (`[vision.omnistereo]` in scenarios).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OmnistereoConfig {
    /// The camera under the lower cone (eq. (1)'s `h_i1`: the larger image radius).
    pub lower_sensor: String,
    /// The camera under the upper cone.
    pub upper_sensor: String,
    /// Finding the coloured marks (the pillars) in each image.
    pub marks: MarkConfig,
    /// Which ranges trilateration uses.
    pub trilateration: TrilaterationMode,
    /// The visual compass.
    pub compass: CompassConfig,
    /// Interframe translation: two feature solutions agree when they are within this many
    /// times their combined expected error (the clustering's radius, see
    /// [`interframe::densest_cluster`]).
    pub cluster_sigmas: f64,
    /// Expected error of one image radius, px (the radial quantisation of a mark's top edge),
    /// from which each feature's expected range error follows.
    pub radius_sigma_px: f64,
}

impl Default for OmnistereoConfig {
    fn default() -> Self {
        Self {
            lower_sensor: "lower".into(),
            upper_sensor: "upper".into(),
            marks: MarkConfig::default(),
            trilateration: TrilaterationMode::Nearest3,
            compass: CompassConfig::default(),
            cluster_sigmas: 3.0,
            radius_sigma_px: 0.4,
        }
    }
}

impl OmnistereoConfig {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), VisionError> {
        self.marks.validate()?;
        self.compass.validate()?;
        positive("cluster_sigmas", self.cluster_sigmas)?;
        positive("radius_sigma_px", self.radius_sigma_px)
    }
}

pub(crate) use crate::positive;

/// `value` must be below `limit` (`rule` says so in words).
pub(crate) fn below(
    name: &'static str,
    value: f64,
    limit: f64,
    rule: &'static str,
) -> Result<(), VisionError> {
    if value < limit {
        Ok(())
    } else {
        Err(VisionError::InvalidParameter { name, value, rule })
    }
}

/// Wraps an angle into (-pi, pi].
pub(crate) fn wrap(a: f64) -> f64 {
    use std::f64::consts::PI;
    let w = (a + PI).rem_euclid(2.0 * PI) - PI;
    if w <= -PI { w + 2.0 * PI } else { w }
}
