//! The direction of an image column (Sect. 3.2): where the optical axis meets the image and how
//! many pixels make a degree, measured from images of a set of equally spaced vertical lines.
//!
//! The paper compares the image with a zoomed image of the same lines: the line that does not
//! move between them is on the optical axis (column 148 on its camera); the spacing gives about
//! 9 pixels a degree. A zoom magnifies the image about the axis; so does stepping toward a flat
//! target square to the camera (a point at lateral offset `x` and depth `D` images at
//! `cx + f (x - x0) / D`), which is what our calibration does: two images of the lines from
//! `far` and `near` depths. Each gives a straight line `column = b + s x` through its edges; the
//! fixed point of the two (the paper's line that does not move) is the axis column
//! `cx = b1 + s1 (b2 - b1) / (s1 - s2)`, and `f = s D` (the two depths' mean). The edges are
//! identified by a reference stripe three times as wide as the others at the target's middle.
//!
//! We keep the pinhole model `column = cx + f tan(theta)` rather than the paper's linear 9 px a
//! degree: over a 28-degree field they differ by 0.3 degrees at the edges.

use super::stripes::{band_profile, luminance};
use crate::VisionError;
use image::RgbaImage;
use serde::{Deserialize, Serialize};

/// Image column to bearing for a pinhole camera that turns about the vertical.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ColumnCalibration {
    /// The camera.
    pub sensor: String,
    /// Image width.
    pub width_px: u32,
    /// Image height.
    pub height_px: u32,
    /// The column where the optical axis meets the image (in the units of a band profile:
    /// column `i` is sample `i`).
    pub axis_column_px: f64,
    /// Focal length, px (pixels a radian near the axis).
    pub focal_px: f64,
    /// Where the pan axis stands in the robot frame, mm (x forward, y left).
    #[serde(default)]
    pub mount_mm: [f64; 2],
}

impl ColumnCalibration {
    /// The bearing of column `column_px` from the optical axis, rad (counter-clockwise
    /// positive: columns right of the axis are negative).
    pub fn bearing_rad(&self, column_px: f64) -> f64 {
        -((column_px - self.axis_column_px) / self.focal_px).atan()
    }

    /// Pixels per degree at the axis (the paper's "1 degree is about 9 pixels").
    pub fn px_per_deg(&self) -> f64 {
        self.focal_px * 1f64.to_radians()
    }

    /// Measures the calibration of camera `sensor` from `far` and `near`, images of the
    /// [`LineTarget`] square to the camera at depths `target.far_mm` and `target.near_mm`.
    pub fn measure(
        sensor: &str,
        far: &RgbaImage,
        near: &RgbaImage,
        target: &LineTarget,
    ) -> Result<Self, VisionError> {
        let (w, h) = far.dimensions();
        if near.dimensions() != (w, h) {
            return Err(VisionError::Calibration(
                "the two images of the calibration target differ in size".into(),
            ));
        }
        let rows = [h * 7 / 16, h * 9 / 16];
        let (s1, b1) = line_fit(&band_profile(far, rows), target, "far")?;
        let (s2, b2) = line_fit(&band_profile(near, rows), target, "near")?;
        if (s1 - s2).abs() < 1e-9 * s1.abs() {
            return Err(VisionError::Calibration(
                "the near and far images have the same scale".into(),
            ));
        }
        let x0 = (b2 - b1) / (s1 - s2);
        Ok(Self {
            sensor: sensor.to_string(),
            width_px: w,
            height_px: h,
            axis_column_px: b1 + s1 * x0,
            focal_px: 0.5 * (s1 * target.far_mm + s2 * target.near_mm),
            mount_mm: [0.0, 0.0],
        })
    }
}

/// The calibration target: black and white vertical stripes `stripe_mm` wide, with a black
/// reference stripe `3 stripe_mm` wide in the middle, filling the camera's view.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LineTarget {
    /// Width of each stripe but the reference, mm.
    pub stripe_mm: f64,
    /// Depth of the far view, mm (pinhole to target).
    pub far_mm: f64,
    /// Depth of the near view, mm.
    pub near_mm: f64,
}

impl Default for LineTarget {
    fn default() -> Self {
        Self {
            stripe_mm: 40.0,
            far_mm: 2000.0,
            near_mm: 1000.0,
        }
    }
}

impl LineTarget {
    /// The target's stripes from its left end, relative widths (black first and last):
    /// `side` stripes, the reference, `side` stripes (`side` even, so the reference is black).
    pub fn stripes(side: usize) -> Vec<f64> {
        let side = side + side % 2;
        let mut s = vec![1.0; 2 * side + 1];
        s[side] = 3.0;
        s
    }
}

/// Slope and intercept of `column = b + s x` through the target's edges in one image, `x` the
/// edge's lateral position on the target (mm from its middle, positive to the camera's right).
fn line_fit(profile: &[f32], target: &LineTarget, which: &str) -> Result<(f64, f64), VisionError> {
    let (lo, hi) = profile
        .iter()
        .fold((f32::MAX, f32::MIN), |(l, h), &v| (l.min(v), h.max(v)));
    let t = 0.5 * (lo + hi);
    let mut edges: Vec<f64> = Vec::new();
    let mut dark_after: Vec<bool> = Vec::new();
    for (i, p) in profile.windows(2).enumerate() {
        if (p[0] >= t) != (p[1] >= t) {
            edges.push(i as f64 + ((t - p[0]) / (p[1] - p[0])) as f64);
            dark_after.push(p[0] >= t);
        }
    }
    // The reference: the widest dark run between two crossings.
    let reference = (0..edges.len().saturating_sub(1))
        .filter(|&k| dark_after[k])
        .max_by(|&a, &b| (edges[a + 1] - edges[a]).total_cmp(&(edges[b + 1] - edges[b])))
        .ok_or_else(|| {
            VisionError::Calibration(format!("no stripes in the {which} calibration image"))
        })?;
    let typical = {
        let mut widths: Vec<f64> = edges.windows(2).map(|w| w[1] - w[0]).collect();
        widths.sort_by(f64::total_cmp);
        widths[widths.len() / 2]
    };
    if edges[reference + 1] - edges[reference] < 2.0 * typical {
        return Err(VisionError::Calibration(format!(
            "the reference stripe is not in view in the {which} calibration image"
        )));
    }
    let s = target.stripe_mm;
    let xs: Vec<(f64, f64)> = edges
        .iter()
        .enumerate()
        .map(|(k, &col)| {
            let x = if k <= reference {
                -(1.5 + (reference - k) as f64) * s
            } else {
                (1.5 + (k - reference - 1) as f64) * s
            };
            (x, col)
        })
        .collect();
    let n = xs.len() as f64;
    let (mx, my) = xs
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxx: f64 = xs.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    let sxy: f64 = xs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    if xs.len() < 6 || sxx <= 0.0 {
        return Err(VisionError::Calibration(format!(
            "too few edges in the {which} calibration image ({})",
            xs.len()
        )));
    }
    let slope = sxy / sxx;
    Ok((slope, my - slope * mx))
}

/// The mean luminance of the pixel at `(u, v)` by bilinear interpolation (pixel centres at
/// integer coordinates), or `None` outside the image.
pub fn bilinear(image: &RgbaImage, u: f64, v: f64) -> Option<f32> {
    let (w, h) = image.dimensions();
    if !(u >= 0.0 && v >= 0.0 && u <= (w - 1) as f64 && v <= (h - 1) as f64) {
        return None;
    }
    let (u0, v0) = (u.floor() as u32, v.floor() as u32);
    let (u1, v1) = ((u0 + 1).min(w - 1), (v0 + 1).min(h - 1));
    let (fu, fv) = ((u - u0 as f64) as f32, (v - v0 as f64) as f32);
    let l = |x, y| luminance(&image.get_pixel(x, y).0);
    let top = l(u0, v0) * (1.0 - fu) + l(u1, v0) * fu;
    let bottom = l(u0, v1) * (1.0 - fu) + l(u1, v1) * fu;
    Some(top * (1.0 - fv) + bottom * fv)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An image of the target at depth `depth_mm` seen by a pinhole of focal `f` whose axis
    /// meets the image at column `cx` and the target `x0` mm right of its middle (each pixel the
    /// mean of 8 sub-columns).
    fn view(f: f64, cx: f64, x0: f64, depth_mm: f64, t: &LineTarget) -> RgbaImage {
        let stripes = LineTarget::stripes(40);
        let total: f64 = stripes.iter().sum();
        let half = 0.5 * total * t.stripe_mm;
        let dark = |x: f64| {
            let mut acc = -half;
            for (k, w) in stripes.iter().enumerate() {
                acc += w * t.stripe_mm;
                if x < acc {
                    return k % 2 == 0;
                }
            }
            false
        };
        RgbaImage::from_fn(256, 64, |u, _| {
            let v: f64 = (0..8)
                .map(|s| {
                    let col = u as f64 - 0.5 + (s as f64 + 0.5) / 8.0;
                    let x = x0 + (col - cx) * depth_mm / f;
                    if dark(x) { 20.0 } else { 230.0 }
                })
                .sum::<f64>()
                / 8.0;
            let g = v.round() as u8;
            image::Rgba([g, g, g, 255])
        })
    }

    #[test]
    fn the_axis_column_and_focal_length_are_recovered() {
        let t = LineTarget::default();
        let (f, cx) = (516.0, 148.0);
        let far = view(f, cx, 37.0, t.far_mm, &t);
        let near = view(f, cx, 37.0, t.near_mm, &t);
        let c = ColumnCalibration::measure("cam", &far, &near, &t).unwrap();
        assert!(
            (c.axis_column_px - cx).abs() < 0.1,
            "axis {}",
            c.axis_column_px
        );
        assert!((c.focal_px - f).abs() < 0.5, "focal {}", c.focal_px);
        assert!((c.px_per_deg() - 9.0).abs() < 0.1);
        assert!((c.bearing_rad(cx - f) - std::f64::consts::FRAC_PI_4).abs() < 1e-3);
    }
}
