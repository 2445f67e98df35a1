//! Rotation from scan-line intensity profiles (Sect. 2.2.1, eqs. (3)-(5)).
//!
//! The profile is the mean level of each column of a window near the top of the image; the
//! shift `p_s` that best overlays two successive profiles, times the gain `alpha`, is the
//! rotation. For a camera tilted down, pixel columns are not lines of one azimuth and a turn
//! moves the rows of the window by different numbers of pixels (about 20% apart over a
//! 46-degree field at 25 degrees of tilt); we therefore sample the window along lines of
//! constant azimuth, one bin per pixel-width at the window's centre, so that a turn is an exact
//! shift of the profile and `alpha` (eq. (5)) is the bin's angular width, from the camera's
//! intrinsics and tilt. An untilted camera's bins are its columns, as in the paper.

use super::camera::ForwardCamera;
use super::grey::{Grey, bilinear};
use crate::VisionError;
use serde::{Deserialize, Serialize};

/// Settings of the scan-line rotation (`[vision.forward.scanline]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ScanLineConfig {
    /// Top of the window, as a fraction of the image height (Fig. 3's top window).
    pub window_top: f64,
    /// Bottom of the window, as a fraction of the image height.
    pub window_bottom: f64,
    /// Profile length `w` at the reference width (the paper's 88).
    pub w_px: f64,
    /// Offset `rho` of the shifts tried at the reference width (the paper's 40).
    pub rho_px: f64,
    /// The image width the paper's `w` and `rho` are for (its camera's 160 columns); both are
    /// scaled by the image width over this.
    pub reference_width_px: f64,
    /// Profile bins per pixel of width (ours: 1 is the paper's; more read the image between
    /// its pixels, so the shift is found to a fraction of a pixel without interpolating the
    /// profile).
    pub oversample: u32,
    /// The most the robot turns between two frames, deg: the shifts tried are kept within
    /// this of the expected one (ours: the paper tries every shift in `[rho - w, rho]`, up to
    /// 18 degrees; with the far scene changing under forward motion, a short overlap far out
    /// can score lower than the true shift; 6 covers 90 deg/s at 15 frames/s).
    pub max_step_deg: f64,
}

impl Default for ScanLineConfig {
    fn default() -> Self {
        Self {
            window_top: 0.0,
            window_bottom: 0.3,
            w_px: 88.0,
            rho_px: 40.0,
            reference_width_px: 160.0,
            oversample: 4,
            max_step_deg: 6.0,
        }
    }
}

/// The sampling of one camera's scan-line window.
#[derive(Debug, Clone)]
pub struct ScanLine {
    /// For each bin (left to right), the pixel coordinates of its samples (one per row).
    samples: Vec<Vec<(f64, f64)>>,
    /// `alpha` of eq. (5): rad per bin.
    alpha_rad: f64,
    rho: i64,
    max_step_rad: f64,
}

impl ScanLine {
    /// The window of `camera` with `config`'s sizes.
    pub fn new(camera: &ForwardCamera, config: &ScanLineConfig) -> Result<Self, VisionError> {
        crate::positive("scanline.w_px", config.w_px)?;
        crate::positive("scanline.reference_width_px", config.reference_width_px)?;
        crate::positive("scanline.max_step_deg", config.max_step_deg)?;
        let k = config.oversample.max(1) as f64;
        let scale = camera.width_px as f64 / config.reference_width_px;
        let w = (config.w_px * scale * k).round() as usize;
        let rho = (config.rho_px * scale * k).round() as i64;
        let h = camera.height_px as f64;
        let top = (config.window_top * h).floor().max(0.0);
        let bottom = (config.window_bottom * h).ceil().min(h - 1.0);
        if w < 8 || rho <= 0 || rho >= w as i64 || bottom <= top {
            return Err(VisionError::InvalidParameter {
                name: "scanline",
                value: w as f64,
                rule: "needs w >= 8 bins, 0 < rho < w and a window of at least one row",
            });
        }
        let centre_x = camera.cx_px - 0.5;
        let mid_y = 0.5 * (top + bottom);
        let azimuth = |x: f64| {
            let d = camera.direction(x, mid_y);
            d.y.atan2(d.x)
        };
        let alpha_rad = (azimuth(centre_x - 0.5) - azimuth(centre_x + 0.5)) / k;
        let elevations: Vec<f64> = (top as u32..=bottom as u32)
            .map(|y| camera.direction(centre_x, y as f64).z.asin())
            .collect();
        let c = 0.5 * (w as f64 - 1.0);
        let mut samples = Vec::with_capacity(w);
        for k in 0..w {
            let az = (c - k as f64) * alpha_rad;
            let mut column = Vec::with_capacity(elevations.len());
            for &el in &elevations {
                match camera.pixel_at(az, el) {
                    Some((x, y)) if camera.inside(x, y, 0.0) => column.push((x, y)),
                    _ => {
                        return Err(VisionError::InvalidParameter {
                            name: "scanline.w_px",
                            value: config.w_px,
                            rule: "the window's lines of constant azimuth leave the image",
                        });
                    }
                }
            }
            samples.push(column);
        }
        Ok(Self {
            samples,
            alpha_rad,
            rho,
            max_step_rad: config.max_step_deg.to_radians(),
        })
    }

    /// `alpha` of eq. (5), rad per bin.
    pub fn alpha_rad(&self) -> f64 {
        self.alpha_rad
    }

    /// The profile of `img`: the mean level along each bin's line.
    pub fn profile(&self, img: &Grey) -> Vec<f32> {
        let blurred = imageproc::filter::gaussian_blur_f32(img, 1.0);
        let img = &blurred;
        self.samples
            .iter()
            .map(|col| {
                col.iter().map(|&(x, y)| bilinear(img, x, y)).sum::<f32>() / col.len() as f32
            })
            .collect()
    }

    /// Eq. (3): the mean absolute difference of profiles `a` (earlier) and `b` (later) with `a`
    /// shifted by `t` bins against `b`.
    pub fn difference(a: &[f32], b: &[f32], t: i64) -> f64 {
        let w = a.len().min(b.len()) as i64;
        let n = w - t.abs();
        if n <= 0 {
            return f64::INFINITY;
        }
        let (sa, sb) = (t.max(0), (-t).max(0));
        (0..n)
            .map(|i| (a[(i + sa) as usize] - b[(i + sb) as usize]).abs() as f64)
            .sum::<f64>()
            / n as f64
    }

    /// Eq. (3) at a fractional shift `t`: `a` read `t / 2` ahead and `b` `t / 2` behind, both
    /// between their bins by linear interpolation (so that both are smoothed alike and the
    /// minimum is not pulled toward whole bins).
    fn difference_at(a: &[f32], b: &[f32], t: f64) -> f64 {
        let w = a.len().min(b.len());
        let at = |v: &[f32], x: f64| -> Option<f64> {
            if x < 0.0 || x > (w - 1) as f64 {
                return None;
            }
            // `x >= 0` here, so truncating is flooring (without a call to `floor`).
            let k = (x as usize).min(w - 2);
            let f = x - k as f64;
            Some(v[k] as f64 * (1.0 - f) + v[k + 1] as f64 * f)
        };
        let (mut sum, mut n) = (0.0, 0usize);
        let lo = (-t / 2.0).max(t / 2.0).ceil() as i64;
        for i in -lo..w as i64 + lo {
            let x = i as f64;
            if let (Some(av), Some(bv)) = (at(a, x + t / 2.0), at(b, x - t / 2.0)) {
                sum += (av - bv).abs();
                n += 1;
            }
        }
        if n == 0 {
            f64::INFINITY
        } else {
            sum / n as f64
        }
    }

    /// Eq. (4): the shift `p_s` in `[rho - w, rho]` minimising eq. (3), refined to a hundredth
    /// of a bin by the same mean absolute difference between the bins' linear interpolation
    /// (ours: the paper keeps whole pixels, 0.4 degrees each on a 160-pixel camera, and a turn's
    /// frames would add up their rounding).
    pub fn shift(&self, a: &[f32], b: &[f32]) -> f64 {
        self.shift_within(a, b, self.rho - a.len() as i64, self.rho)
    }

    /// Eq. (4) over the whole shifts in `[lo, hi]` (within eq. (4)'s range), refined.
    fn shift_within(&self, a: &[f32], b: &[f32], lo: i64, hi: i64) -> f64 {
        let w = a.len() as i64;
        let (lo, hi) = (lo.max(self.rho - w), hi.min(self.rho));
        // Each shift's difference computed once; the first of equal minima wins.
        let best = (lo..=hi)
            .map(|t| (t, Self::difference(a, b, t)))
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .map_or(0, |(t, _)| t);
        (-100..=100)
            .map(|k| best as f64 + k as f64 / 100.0)
            .filter(|&t| t >= lo as f64 && t <= hi as f64)
            .map(|t| (t, Self::difference_at(a, b, t)))
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .map_or(best as f64, |(t, _)| t)
    }

    /// Eq. (5): the rotation between the frames of profiles `a` and `b`, rad, counter-clockwise
    /// positive (a left turn moves the scene right, to later bins: `p_s < 0`).
    pub fn rotation_rad(&self, a: &[f32], b: &[f32]) -> f64 {
        -self.alpha_rad * self.shift(a, b)
    }

    /// Eq. (5) with the shifts of eq. (4) kept within `max_step_deg` of the rotation
    /// `expected_rad` (the rotation since the earlier frame as last read, or 0).
    pub fn rotation_near(&self, a: &[f32], b: &[f32], expected_rad: f64) -> f64 {
        let centre = -expected_rad / self.alpha_rad;
        let half = self.max_step_rad / self.alpha_rad;
        let (lo, hi) = (
            (centre - half).floor() as i64,
            (centre + half).ceil() as i64,
        );
        -self.alpha_rad * self.shift_within(a, b, lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::camera;
    use super::*;
    use image::Luma;

    /// What the camera sees inside a drum painted by azimuth when the robot faces `heading`.
    fn drum(c: &ForwardCamera, heading: f64) -> Grey {
        Grey::from_fn(c.width_px, c.height_px, |x, y| {
            let mut sum = 0.0;
            for s in 0..4 {
                let d = c.direction(
                    x as f64 + (s % 2) as f64 * 0.5 - 0.25,
                    y as f64 + (s / 2) as f64 * 0.5 - 0.25,
                );
                let a = d.y.atan2(d.x) + heading;
                sum += 128.0 + 60.0 * (7.0 * a).sin() + 30.0 * (17.0 * a + 1.0).sin();
            }
            Luma([sum as f32 / 4.0])
        })
    }

    #[test]
    fn the_paper_sizes_scale_with_the_width_and_alpha_comes_from_the_tilt() {
        let c = camera();
        let s = ScanLine::new(&c, &ScanLineConfig::default()).unwrap();
        assert_eq!(s.samples.len(), 88 * 4);
        assert_eq!(s.rho, 40 * 4);
        // Near the top of a 25-degree tilt a pixel spans less azimuth than 1/f.
        let px = 4.0 * s.alpha_rad();
        assert!(px < 1.0 / c.focal_px && px > 0.85 / c.focal_px);
        let one = ScanLineConfig {
            oversample: 1,
            ..ScanLineConfig::default()
        };
        let s = ScanLine::new(&c, &one).unwrap();
        assert_eq!((s.samples.len(), s.rho), (88, 40));
        let mut wide = c.clone();
        wide.width_px = 320;
        wide.cx_px = 160.0;
        let s = ScanLine::new(&wide, &one).unwrap();
        assert_eq!((s.samples.len(), s.rho), (176, 80));
    }

    #[test]
    fn a_turn_reads_as_its_angle_either_way() {
        let c = camera();
        let s = ScanLine::new(&c, &ScanLineConfig::default()).unwrap();
        let a = s.profile(&drum(&c, 0.0));
        for deg in [3.6f64, -2.0, 0.7, 9.0, 1.5, 2.25] {
            let b = s.profile(&drum(&c, deg.to_radians()));
            let read = s.rotation_rad(&a, &b).to_degrees();
            assert!((read - deg).abs() < 0.01, "{deg}: read {read}");
        }
    }

    /// Near an expected rotation the reading is the same as the paper's full search, and it
    /// stays within `max_step_deg` of the expected one whatever the profiles.
    #[test]
    fn a_search_near_the_expected_turn_reads_it_and_stays_within_the_step() {
        let c = camera();
        let s = ScanLine::new(&c, &ScanLineConfig::default()).unwrap();
        let a = s.profile(&drum(&c, 0.0));
        for (deg, expected) in [(3.6f64, 0.0f64), (-2.0, 0.0), (9.0, 7.0), (-11.5, -9.0)] {
            let b = s.profile(&drum(&c, deg.to_radians()));
            let read = s.rotation_near(&a, &b, expected.to_radians()).to_degrees();
            assert!(
                (read - deg).abs() < 0.01,
                "{deg} near {expected}: read {read}"
            );
        }
        let b = s.profile(&drum(&c, 9f64.to_radians()));
        let read = s.rotation_near(&a, &b, 0.0).to_degrees();
        let bin = s.alpha_rad().to_degrees();
        assert!(
            read.abs() <= 6.0 + bin,
            "9 degrees searched within 6 read {read}"
        );
    }

    #[test]
    fn eq_3_is_zero_for_identical_profiles_at_zero_shift() {
        let a: Vec<f32> = (0..20).map(|i| (i * i % 7) as f32).collect();
        assert_eq!(ScanLine::difference(&a, &a, 0), 0.0);
        let shifted: Vec<f32> = a[2..].iter().copied().chain([0.0, 0.0]).collect();
        assert_eq!(ScanLine::difference(&a, &shifted, 2), 0.0);
    }
}
