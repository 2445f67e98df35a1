//! Self-location from three striped marks (Ishikawa, Kikuchi and Kato, "Visual self-location of
//! a mobile robot"): the marks recognized by their stripes in two bands of a camera image
//! ([`stripes`], Sect. 3.4), their directions from the image column ([`columns`], Sect. 3.2)
//! and the position from the angles between them ([`resect`], Sect. 3.1). [`ring`] reads the
//! same marks from one omnidirectional image.

pub mod columns;
pub mod resect;
pub mod ring;
pub mod stripes;

pub use columns::{ColumnCalibration, LineTarget};
pub use resect::{MarkBearing, Resection, resect};
pub use ring::{ring_bearing_rad, ring_profile};
pub use stripes::{StripeConfig, StripeMatch, StripePattern, band_profile, find_stripes};

use crate::VisionError;
use image::RgbaImage;
use serde::{Deserialize, Serialize};

/// Settings of mark recognition (`[vision.resection]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ResectionConfig {
    /// Rows of band R1 (inclusive) on an image `reference_height_px` high, scaled to the image:
    /// the paper's rows 20-45 of 256.
    pub r1_rows: [u32; 2],
    /// Rows of band R2, which confirms R1 (the paper's 60-85).
    pub r2_rows: [u32; 2],
    /// The image height the rows are given for.
    pub reference_height_px: u32,
    /// R2 confirms a mark of R1 when it finds the same mark this close, as a fraction of the
    /// mark's width (at least one pixel).
    pub confirm_fraction: f64,
    /// Matching the stripes.
    pub stripes: StripeConfig,
    /// With an omnidirectional camera: elevations of ring R1, degrees above the horizontal.
    pub ring_r1_deg: [f64; 2],
    /// Elevations of ring R2.
    pub ring_r2_deg: [f64; 2],
    /// Azimuth samples of a ring's profile.
    pub ring_samples: usize,
    /// Radii averaged at each azimuth.
    pub ring_radii: usize,
}

impl Default for ResectionConfig {
    fn default() -> Self {
        Self {
            r1_rows: [20, 45],
            r2_rows: [60, 85],
            reference_height_px: 256,
            confirm_fraction: 0.1,
            stripes: StripeConfig::default(),
            ring_r1_deg: [11.0, 14.0],
            ring_r2_deg: [6.5, 9.0],
            ring_samples: 4096,
            ring_radii: 12,
        }
    }
}

impl ResectionConfig {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), VisionError> {
        self.stripes.validate()?;
        for (name, r) in [("r1_rows", self.r1_rows), ("r2_rows", self.r2_rows)] {
            if r[0] > r[1] || r[1] >= self.reference_height_px {
                return Err(VisionError::InvalidParameter {
                    name,
                    value: r[1] as f64,
                    rule: "rows must be increasing and inside the reference height",
                });
            }
        }
        for (name, e) in [
            ("ring_r1_deg", self.ring_r1_deg),
            ("ring_r2_deg", self.ring_r2_deg),
        ] {
            if !(e[0] < e[1] && e[0] > -90.0 && e[1] < 90.0) {
                return Err(VisionError::InvalidParameter {
                    name,
                    value: e[1],
                    rule: "elevations must be increasing, within -90..90 degrees",
                });
            }
        }
        if self.ring_samples < 360 || self.ring_radii == 0 {
            return Err(VisionError::InvalidParameter {
                name: "ring_samples",
                value: self.ring_samples as f64,
                rule: "need at least 360 samples and one radius",
            });
        }
        if self.confirm_fraction.is_nan() || self.confirm_fraction <= 0.0 {
            return Err(VisionError::InvalidParameter {
                name: "confirm_fraction",
                value: self.confirm_fraction,
                rule: "must be > 0",
            });
        }
        Ok(())
    }

    /// Band `rows` scaled to an image `height_px` high.
    fn scaled(&self, rows: [u32; 2], height_px: u32) -> [u32; 2] {
        let k = height_px as f64 / self.reference_height_px as f64;
        [
            (rows[0] as f64 * k).round() as u32,
            ((rows[1] as f64 + 1.0) * k).round() as u32 - 1,
        ]
    }
}

/// A mark found in an image: which, where its centre is, and how well it matched.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarkSighting {
    /// Index of the pattern.
    pub mark: usize,
    /// Column (pinhole) or profile sample (ring) of the board's centre: the mean of R1's and
    /// R2's (ours; the paper reads R1 and uses R2 only to confirm).
    pub centre: f64,
    /// Width of the mark in R1, samples.
    pub width: f64,
    /// The lower of R1's and R2's match scores.
    pub score: f64,
}

/// The marks of `patterns` in a pinhole camera's image (Sect. 3.4): found in band R1, kept
/// when R2 finds the same mark at about the same column. Each mark at most once (its best).
pub fn find_marks(
    image: &RgbaImage,
    patterns: &[StripePattern],
    config: &ResectionConfig,
) -> Result<Vec<MarkSighting>, VisionError> {
    let h = image.height();
    let r1 = find_stripes(
        &band_profile(image, config.scaled(config.r1_rows, h)),
        patterns,
        &config.stripes,
    )?;
    let r2 = find_stripes(
        &band_profile(image, config.scaled(config.r2_rows, h)),
        patterns,
        &config.stripes,
    )
    .unwrap_or_default();
    Ok(confirm(&r1, &r2, config, None))
}

/// The marks in an omnidirectional image, from rings R1 and R2 (see [`ring`]); centres are
/// profile samples (bearing by [`ring_bearing_rad`]).
pub fn find_marks_ring(
    image: &RgbaImage,
    calibration: &crate::RadialCalibration,
    patterns: &[StripePattern],
    config: &ResectionConfig,
) -> Result<Vec<MarkSighting>, VisionError> {
    let n = config.ring_samples;
    let profile = |e| ring_profile(image, calibration, e, n, config.ring_radii);
    let read = |e: [f64; 2]| {
        stripes::find_stripes_circular(
            &profile(e)?,
            patterns,
            &ring_stripes(calibration, e, config),
        )
    };
    let r1 = read(config.ring_r1_deg)?;
    let r2 = read(config.ring_r2_deg).unwrap_or_default();
    Ok(confirm(&r1, &r2, config, Some(n as f64)))
}

/// The stripe settings for a ring: their pixel lengths (`tolerance_px`, `min_width_px`) turned
/// into profile samples at the ring's middle radius, where a pixel spans
/// `samples / (2 pi r)` samples.
fn ring_stripes(
    calibration: &crate::RadialCalibration,
    elevation_deg: [f64; 2],
    config: &ResectionConfig,
) -> StripeConfig {
    let middle = (0.5 * (elevation_deg[0] + elevation_deg[1])).to_radians();
    let r = calibration
        .radius_at_elevation_px(middle)
        .unwrap_or(1.0)
        .max(1.0);
    let per_px = config.ring_samples as f64 / (std::f64::consts::TAU * r);
    StripeConfig {
        tolerance_px: config.stripes.tolerance_px * per_px,
        min_width_px: config.stripes.min_width_px * per_px,
        ..config.stripes.clone()
    }
}

/// R1's matches that R2 confirms, the best of each mark. `wrap`: the profile's length when it
/// is circular.
fn confirm(
    r1: &[StripeMatch],
    r2: &[StripeMatch],
    config: &ResectionConfig,
    wrap: Option<f64>,
) -> Vec<MarkSighting> {
    let gap = |a: f64, b: f64| match wrap {
        Some(n) => {
            let d = (a - b).rem_euclid(n);
            d.min(n - d)
        }
        None => (a - b).abs(),
    };
    let mut out: Vec<MarkSighting> = Vec::new();
    for m in r1 {
        let near = (config.confirm_fraction * m.width).max(1.0);
        let Some(c) = r2
            .iter()
            .filter(|c| c.mark == m.mark && gap(c.centre, m.centre) <= near)
            .max_by(|a, b| a.score.total_cmp(&b.score))
        else {
            continue;
        };
        if out.iter().any(|o| o.mark == m.mark) {
            continue;
        }
        let centre = match wrap {
            Some(n) => (m.centre + 0.5 * signed(c.centre - m.centre, n)).rem_euclid(n),
            None => 0.5 * (m.centre + c.centre),
        };
        out.push(MarkSighting {
            mark: m.mark,
            centre,
            width: m.width,
            score: m.score.min(c.score),
        });
    }
    out
}

/// `d` wrapped into `[-n/2, n/2)`.
fn signed(d: f64, n: f64) -> f64 {
    (d + 0.5 * n).rem_euclid(n) - 0.5 * n
}
