//! Settings of the omnistereo pipeline.

use super::compass::CompassConfig;
use super::marks::MarkConfig;
use super::numbers::positive;
use super::trilateration::TrilaterationMode;
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
    /// [`super::interframe::densest_cluster`]).
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
