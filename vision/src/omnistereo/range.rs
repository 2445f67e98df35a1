//! Omnistereo range, eqs. (1)-(2) of Sect. 2.
//!
//! Eq. (1): `r = v s / (h_i1 - h_i2) - d`, the horizontal range from the mirrors' axis to a
//! point seen at image radius `h_i1` under the lower cone and `h_i2` under the upper one (the
//! same azimuth: the cones are coaxial), where `d` is the distance from the lens to the cone's
//! tip, `s` the distance between the two mirrors and `v` the distance of the image behind the
//! lens. Eq. (2): `v = (d / R + 1) r_m`, with `R` the mirror's radius and `r_m` its radius in the
//! image ([`super::rim::MirrorRim`]): the calibration that converts pixels to millimetres.
//!
//! One pixel of disparity moves the range by `(r + d)^2 / (v s)`: the error grows with the
//! square of the range.

use super::marks::ColourMark;
use super::numbers::{positive, wrap};
use super::rim::MirrorRim;
use crate::VisionError;

/// The two cones and the camera behind them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StereoGeometry {
    /// Mirror radius R, mm.
    pub mirror_radius_mm: f64,
    /// Lens to cone tip d, mm.
    pub tip_distance_mm: f64,
    /// Distance between the mirrors s, mm.
    pub separation_mm: f64,
    /// Distance of the image behind the lens v, px.
    pub v_px: f64,
}

impl StereoGeometry {
    /// The geometry with `v` from the rims' image radius by eq. (2) (the mean of the two
    /// cameras': the same design, the same lens).
    pub fn calibrate(
        mirror_radius_mm: f64,
        tip_distance_mm: f64,
        separation_mm: f64,
        rims: &[MirrorRim],
    ) -> Result<Self, VisionError> {
        for (name, value) in [
            ("mirror_radius_mm", mirror_radius_mm),
            ("tip_distance_mm", tip_distance_mm),
            ("separation_mm", separation_mm),
        ] {
            positive(name, value)?;
        }
        if rims.is_empty() {
            return Err(VisionError::NotFound(
                "no mirror rim measured: eq. (2) needs r_m".into(),
            ));
        }
        let r_m = rims.iter().map(|r| r.radius_px).sum::<f64>() / rims.len() as f64;
        Ok(Self {
            mirror_radius_mm,
            tip_distance_mm,
            separation_mm,
            v_px: v_from_rim(mirror_radius_mm, tip_distance_mm, r_m),
        })
    }

    /// Eq. (1): the range for image radii `h_lower` (h_i1) and `h_upper` (h_i2), mm; `None`
    /// unless the disparity is positive.
    pub fn range_mm(&self, h_lower_px: f64, h_upper_px: f64) -> Option<f64> {
        let disparity = h_lower_px - h_upper_px;
        (disparity > 0.0).then(|| self.v_px * self.separation_mm / disparity - self.tip_distance_mm)
    }

    /// The range error one pixel of disparity makes at range `r_mm`: `(r + d)^2 / (v s)`.
    pub fn mm_per_px(&self, r_mm: f64) -> f64 {
        let rd = r_mm + self.tip_distance_mm;
        rd * rd / (self.v_px * self.separation_mm)
    }

    /// The image radius under a cone whose tip is `height_mm` below a point at range `r_mm`:
    /// `h = v z / (r + d)` (the inverse of eq. (1) for one mirror).
    pub fn image_radius_px(&self, r_mm: f64, height_mm: f64) -> f64 {
        self.v_px * height_mm / (r_mm + self.tip_distance_mm)
    }
}

/// Eq. (2): `v = (d / R + 1) r_m`.
pub fn v_from_rim(mirror_radius_mm: f64, tip_distance_mm: f64, r_m_px: f64) -> f64 {
    (tip_distance_mm / mirror_radius_mm + 1.0) * r_m_px
}

/// A mark seen under both cones, with its range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RangedMark {
    /// Its colour's index in the palette.
    pub label: usize,
    /// Bearing (the mean of the two images'), rad.
    pub bearing_rad: f64,
    /// Range of eq. (1) from the axis to the mark's near face, mm.
    pub range_mm: f64,
    /// Expected error of the range for one `radius_sigma_px` of error in each image radius, mm.
    pub sigma_mm: f64,
}

/// Matches the marks of the two images by colour and ranges those whose top both images see.
/// Returns the ranged marks, and for the others the reason they have no range.
pub fn range_marks(
    geometry: &StereoGeometry,
    lower: &[ColourMark],
    upper: &[ColourMark],
    radius_sigma_px: f64,
) -> (Vec<RangedMark>, Vec<(usize, String)>) {
    let mut ranged = Vec::new();
    let mut unranged = Vec::new();
    for lo in lower {
        let Some(up) = upper.iter().find(|u| u.label == lo.label) else {
            unranged.push((lo.label, "not seen under the upper cone".to_string()));
            continue;
        };
        let (Some(h1), Some(h2)) = (lo.top_px, up.top_px) else {
            unranged.push((
                lo.label,
                "its top is beyond the lower mirror's view (too near for the common region)"
                    .to_string(),
            ));
            continue;
        };
        let Some(r) = geometry.range_mm(h1, h2) else {
            unranged.push((lo.label, format!("no disparity ({h1:.1} - {h2:.1} px)")));
            continue;
        };
        let mean = lo.bearing_rad + 0.5 * wrap(up.bearing_rad - lo.bearing_rad);
        ranged.push(RangedMark {
            label: lo.label,
            bearing_rad: mean,
            range_mm: r,
            sigma_mm: geometry.mm_per_px(r) * radius_sigma_px * std::f64::consts::SQRT_2,
        });
    }
    (ranged, unranged)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geometry() -> StereoGeometry {
        StereoGeometry {
            mirror_radius_mm: 30.0,
            tip_distance_mm: 100.0,
            separation_mm: 150.0,
            v_px: 1040.0,
        }
    }

    #[test]
    fn range_from_synthetic_disparities_follows_eq_1() {
        let g = geometry();
        // A point 280 mm above the lower tip (130 above the upper) at range r images at
        // h = v z / (r + d) under each cone; eq. (1) must give r back.
        for r in [600.0, 1000.0, 2500.0, 4000.0, 6500.0] {
            let h1 = g.image_radius_px(r, 280.0);
            let h2 = g.image_radius_px(r, 130.0);
            let est = g.range_mm(h1, h2).unwrap();
            assert!((est - r).abs() < 1e-9 * r, "{est} vs {r}");
            // And eq. (1) is exactly v s / (h1 - h2) - d.
            assert_eq!(est, 1040.0 * 150.0 / (h1 - h2) - 100.0);
            // One pixel more disparity: the range moves by about (r + d)^2 / (v s).
            let moved = g.range_mm(h1 + 0.01, h2).unwrap();
            let slope = (est - moved) / 0.01;
            assert!((slope / g.mm_per_px(r) - 1.0).abs() < 0.01);
        }
        assert_eq!(g.range_mm(10.0, 10.0), None);
    }

    #[test]
    fn v_follows_eq_2() {
        // R = 30, d = 100: the rim images at r_m = v R / (d + R).
        let rm = 1040.0 * 30.0 / 130.0;
        assert!((v_from_rim(30.0, 100.0, rm) - 1040.0).abs() < 1e-9);
    }
}
