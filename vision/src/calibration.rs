//! The image-to-floor map of a vertical-axis omnidirectional sensor, eqs. (1)-(4) of the corner
//! paper: a pixel at image radius `R` and angle `Phi` from the principal point sees the floor at
//! distance `r = f(R)` and azimuth `phi = Phi` from the sensor axis.
//!
//! `f` is a table of `(R, r)` samples (from ray tracing or a real calibration) with linear
//! interpolation, valid up to the floor horizon. [`fit_hyperbolic_form`] fits the paper's
//! closed form `f(R) = R / (A - B sqrt(C + R^2))` (Sect. 5) to such a table.

use crate::VisionError;
use nalgebra::{Point2, Vector2};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Constants of `f(R) = R / (A - B sqrt(C + R^2))`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HyperbolicFit {
    /// A.
    pub a: f64,
    /// B.
    pub b: f64,
    /// C (px^2).
    pub c: f64,
    /// RMS of `f(R) - r` over the samples fitted, mm.
    pub rms_mm: f64,
}

impl HyperbolicFit {
    /// `f(R)`, or `None` at and beyond the horizon.
    pub fn floor_distance_mm(&self, r_px: f64) -> Option<f64> {
        let den = self.a - self.b * (self.c + r_px * r_px).sqrt();
        (den > 0.0).then(|| r_px / den)
    }
}

/// The image-to-floor map of one sensor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RadialCalibration {
    /// Sensor name.
    pub sensor: String,
    /// Image width.
    pub width_px: u32,
    /// Image height.
    pub height_px: u32,
    /// Principal point (pixels from the top-left corner).
    pub principal_point_px: [f64; 2],
    /// Position of the sensor axis in the robot frame.
    pub mount_mm: [f64; 2],
    /// `(R, r)` pairs, R strictly increasing from 0, r increasing.
    pub samples: Vec<[f64; 2]>,
    /// Image radius of the floor horizon (rays beyond it do not reach the floor).
    pub horizon_px: f64,
    /// `(R, elevation)` pairs, R strictly increasing from 0: the angle of the scene ray of
    /// image radius R above the horizontal, radians (negative: toward the floor). Empty in
    /// tables written before it was traced.
    #[serde(default)]
    pub elevation: Vec<[f64; 2]>,
    /// The paper's closed form fitted to the samples, where it applies.
    #[serde(default)]
    pub fit: Option<HyperbolicFit>,
}

impl RadialCalibration {
    /// Checks the table: at least two samples, both columns increasing.
    pub fn validate(&self) -> Result<(), VisionError> {
        if self.samples.len() < 2 {
            return Err(VisionError::Calibration("fewer than two samples".into()));
        }
        for w in self.samples.windows(2) {
            if w[1][0] <= w[0][0] || w[1][1] < w[0][1] {
                return Err(VisionError::Calibration(format!(
                    "samples must increase: ({}, {}) then ({}, {})",
                    w[0][0], w[0][1], w[1][0], w[1][1]
                )));
            }
        }
        Ok(())
    }

    /// Reads a calibration written by `omniloop calibrate`.
    pub fn load(path: &Path) -> Result<Self, VisionError> {
        let err = |m: String| VisionError::CalibrationFile {
            path: path.display().to_string(),
            message: m,
        };
        let text = std::fs::read_to_string(path).map_err(|e| err(e.to_string()))?;
        let c: Self = serde_json::from_str(&text).map_err(|e| err(e.to_string()))?;
        c.validate().map_err(|e| err(e.to_string()))?;
        Ok(c)
    }

    /// Writes the calibration as JSON.
    pub fn save(&self, path: &Path) -> Result<(), VisionError> {
        let text =
            serde_json::to_string_pretty(self).map_err(|e| VisionError::CalibrationFile {
                path: path.display().to_string(),
                message: e.to_string(),
            })?;
        std::fs::write(path, text + "\n").map_err(|e| VisionError::CalibrationFile {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    }

    /// Largest image radius the table covers.
    pub fn max_radius_px(&self) -> f64 {
        self.samples.last().map_or(0.0, |s| s[0])
    }

    /// The table segment `(R, r)` to `(R, r)` holding image radius `R`; `None` beyond it.
    fn segment(&self, r_px: f64) -> Option<([f64; 2], [f64; 2])> {
        let s = &self.samples;
        if r_px.is_nan() || r_px < s.first()?[0] || r_px > self.max_radius_px() {
            return None;
        }
        let k = s.partition_point(|p| p[0] <= r_px).clamp(1, s.len() - 1);
        Some((s[k - 1], s[k]))
    }

    /// `r = f(R)` by linear interpolation; `None` beyond the table.
    pub fn floor_distance_mm(&self, r_px: f64) -> Option<f64> {
        let (a, b) = self.segment(r_px)?;
        let u = (r_px - a[0]) / (b[0] - a[0]);
        Some(a[1] + u * (b[1] - a[1]))
    }

    /// `df/dR` (mm per pixel) of the table segment holding `R`.
    pub fn slope_mm_per_px(&self, r_px: f64) -> Option<f64> {
        let (a, b) = self.segment(r_px)?;
        Some((b[1] - a[1]) / (b[0] - a[0]))
    }

    /// `f(R)` and `df/dR` at once (one table lookup).
    pub fn floor_distance_and_slope(&self, r_px: f64) -> Option<(f64, f64)> {
        let (a, b) = self.segment(r_px)?;
        let slope = (b[1] - a[1]) / (b[0] - a[0]);
        Some((a[1] + (r_px - a[0]) * slope, slope))
    }

    /// `R = f^-1(r)`; `None` beyond the table.
    pub fn image_radius_px(&self, r_mm: f64) -> Option<f64> {
        let s = &self.samples;
        if r_mm.is_nan() || r_mm < s.first()?[1] || r_mm > s.last()?[1] {
            return None;
        }
        let k = s.partition_point(|p| p[1] <= r_mm).clamp(1, s.len() - 1);
        let (a, b) = (s[k - 1], s[k]);
        if b[1] == a[1] {
            return Some(a[0]);
        }
        let u = (r_mm - a[1]) / (b[1] - a[1]);
        Some(a[0] + u * (b[0] - a[0]))
    }

    /// The elevation (rad above the horizontal) of the scene ray at image radius `R`, linear
    /// in the elevation column; `None` without one or beyond it.
    pub fn elevation_rad(&self, r_px: f64) -> Option<f64> {
        let e = &self.elevation;
        if e.len() < 2 || r_px.is_nan() || r_px < e[0][0] || r_px > e[e.len() - 1][0] {
            return None;
        }
        let k = e.partition_point(|p| p[0] <= r_px).clamp(1, e.len() - 1);
        let (a, b) = (e[k - 1], e[k]);
        Some(a[1] + (r_px - a[0]) / (b[0] - a[0]) * (b[1] - a[1]))
    }

    /// The image radius whose scene rays are at `elevation_rad` above the horizontal (the
    /// first crossing outward, interpolated in the elevation column); `None` when the table
    /// has no elevation column or never reaches it.
    pub fn radius_at_elevation_px(&self, elevation_rad: f64) -> Option<f64> {
        self.elevation.windows(2).find_map(|w| {
            let (a, b) = (w[0], w[1]);
            let crosses = (a[1] - elevation_rad) * (b[1] - elevation_rad) <= 0.0 && a[1] != b[1];
            crosses.then(|| a[0] + (elevation_rad - a[1]) / (b[1] - a[1]) * (b[0] - a[0]))
        })
    }

    /// Image coordinates `(X, Y)` (from the principal point, Y up) of pixel `(u, v)`'s centre.
    pub fn image_coords(&self, u: f64, v: f64) -> (f64, f64) {
        (
            u + 0.5 - self.principal_point_px[0],
            self.principal_point_px[1] - (v + 0.5),
        )
    }

    /// Floor point in the robot frame seen at image coordinates `(X, Y)`, eqs. (1)-(4).
    pub fn image_to_floor(&self, x_px: f64, y_px: f64) -> Option<Point2<f64>> {
        let big_r = x_px.hypot(y_px);
        let r = self.floor_distance_mm(big_r)?;
        let phi = y_px.atan2(x_px);
        Some(Point2::new(
            self.mount_mm[0] + r * phi.cos(),
            self.mount_mm[1] + r * phi.sin(),
        ))
    }

    /// Image coordinates `(X, Y)` of a floor point given in the robot frame.
    pub fn floor_to_image(&self, p: Point2<f64>) -> Option<(f64, f64)> {
        let d: Vector2<f64> = p - Point2::from(self.mount_mm);
        let big_r = self.image_radius_px(d.norm())?;
        let phi = d.y.atan2(d.x);
        Some((big_r * phi.cos(), big_r * phi.sin()))
    }
}

/// Fits `f(R) = R / (A - B sqrt(C + R^2))` to `(R, r)` samples (R > 0) by least squares on r.
///
/// For a fixed C the model is linear in A and B through `R / r = A - B sqrt(C + R^2)`; each row
/// is weighted by `r^2 / R` so that its residual approximates the error in r. C is found by a
/// golden-section search on log C minimising the r residuals.
pub fn fit_hyperbolic_form(samples: &[[f64; 2]]) -> Option<HyperbolicFit> {
    let pts: Vec<[f64; 2]> = samples
        .iter()
        .copied()
        .filter(|s| s[0] > 0.0 && s[1] > 0.0)
        .collect();
    if pts.len() < 3 {
        return None;
    }
    let solve_ab = |c: f64| -> Option<(f64, f64, f64)> {
        // Weighted normal equations for y = A - B s, s = sqrt(C + R^2), y = R / r.
        let (mut s11, mut s12, mut s22, mut t1, mut t2) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for p in &pts {
            let (big_r, r) = (p[0], p[1]);
            let w = (r * r / big_r).powi(2);
            let s = (c + big_r * big_r).sqrt();
            let y = big_r / r;
            s11 += w;
            s12 += w * s;
            s22 += w * s * s;
            t1 += w * y;
            t2 += w * y * s;
        }
        let det = s11 * s22 - s12 * s12;
        if det.abs() < 1e-300 {
            return None;
        }
        // Minimise sum w (A - B s - y)^2: [s11, -s12; -s12, s22] [A; B] = [t1; -t2].
        let a = (t1 * s22 - t2 * s12) / det;
        let b = (t1 * s12 - t2 * s11) / det;
        let mut sse = 0.0;
        for p in &pts {
            let den = a - b * (c + p[0] * p[0]).sqrt();
            let e = if den > 0.0 { p[0] / den - p[1] } else { 1e9 };
            sse += e * e;
        }
        Some((a, b, sse))
    };
    let cost = |lc: f64| solve_ab(lc.exp()).map_or(f64::INFINITY, |(_, _, e)| e);
    // Bracket on log C from (0.1 px)^2 to (1e5 px)^2, coarse scan then golden section.
    let (lo, hi) = ((0.01f64).ln(), (1e10f64).ln());
    let n = 200;
    let mut best = (lo, f64::INFINITY);
    for k in 0..=n {
        let lc = lo + (hi - lo) * k as f64 / n as f64;
        let e = cost(lc);
        if e < best.1 {
            best = (lc, e);
        }
    }
    let step = (hi - lo) / n as f64;
    let (mut a, mut b) = (best.0 - step, best.0 + step);
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let mut x1 = b - g * (b - a);
    let mut x2 = a + g * (b - a);
    let (mut f1, mut f2) = (cost(x1), cost(x2));
    for _ in 0..200 {
        if f1 < f2 {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - g * (b - a);
            f1 = cost(x1);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + g * (b - a);
            f2 = cost(x2);
        }
    }
    let c = ((a + b) / 2.0).exp();
    let (ca, cb, sse) = solve_ab(c)?;
    Some(HyperbolicFit {
        a: ca,
        b: cb,
        c,
        rms_mm: (sse / pts.len() as f64).sqrt(),
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    fn paper() -> HyperbolicFit {
        HyperbolicFit {
            a: 10.12,
            b: 2.054e-2,
            c: 2.298e5,
            rms_mm: 0.0,
        }
    }

    /// The corner paper's f(R) as a table, 256 x 220, principal point at the centre.
    pub(crate) fn table() -> RadialCalibration {
        let f = paper();
        let samples: Vec<[f64; 2]> = (0..=440)
            .map(|k| k as f64 * 0.25)
            .map(|r| [r, f.floor_distance_mm(r).unwrap()])
            .collect();
        RadialCalibration {
            sensor: "omni".into(),
            width_px: 256,
            height_px: 220,
            principal_point_px: [128.0, 110.0],
            mount_mm: [0.0, 0.0],
            samples,
            horizon_px: 113.9,
            // A made-up elevation column, straight from -90 degrees at R = 0 to +10 at 120 px.
            elevation: (0..=480)
                .map(|k| {
                    let r = k as f64 * 0.25;
                    [r, (-90.0 + 100.0 * r / 120.0f64).to_radians()]
                })
                .collect(),
            fit: None,
        }
    }

    #[test]
    fn the_horizontal_circle_is_where_the_elevation_crosses_zero() {
        use std::f64::consts::PI;
        let cal = table();
        // -90 + 100 R / 120 = 0 at R = 108.
        assert!((cal.radius_at_elevation_px(0.0).unwrap() - 108.0).abs() < 1e-9);
        assert!((cal.radius_at_elevation_px(-0.5 * PI).unwrap()).abs() < 1e-9);
        assert!(cal.radius_at_elevation_px(0.5).is_none());
        let old = RadialCalibration {
            elevation: Vec::new(),
            ..cal
        };
        assert!(old.radius_at_elevation_px(0.0).is_none());
    }

    #[test]
    fn the_fit_recovers_the_papers_constants() {
        let t = table();
        let fit = fit_hyperbolic_form(&t.samples).unwrap();
        assert!((fit.a / 10.12 - 1.0).abs() < 1e-4, "{fit:?}");
        assert!((fit.b / 2.054e-2 - 1.0).abs() < 1e-4, "{fit:?}");
        assert!((fit.c / 2.298e5 - 1.0).abs() < 1e-3, "{fit:?}");
        assert!(fit.rms_mm < 0.01);
    }

    #[test]
    fn lookups_interpolate_and_invert() {
        let t = table();
        t.validate().unwrap();
        let f = paper();
        for r_px in [3.3, 40.1, 80.7, 104.9] {
            let r = t.floor_distance_mm(r_px).unwrap();
            let exact = f.floor_distance_mm(r_px).unwrap();
            assert!(
                (r - exact).abs() < 1e-3 * exact.max(10.0),
                "{r_px}: {r} vs {exact}"
            );
            let back = t.image_radius_px(r).unwrap();
            assert!((back - r_px).abs() < 1e-9);
        }
        assert!(t.floor_distance_mm(200.0).is_none());
        let p = t.image_to_floor(30.0, 40.0).unwrap();
        let (x, y) = t.floor_to_image(p).unwrap();
        assert!((x - 30.0).abs() < 1e-9 && (y - 40.0).abs() < 1e-9);
        // Eq. (2): the floor azimuth equals the image angle.
        assert!((p.y.atan2(p.x) - 40f64.atan2(30.0)).abs() < 1e-12);
    }

    #[test]
    fn a_bad_table_is_refused() {
        let mut t = table();
        t.samples.swap(3, 4);
        assert!(t.validate().is_err());
    }
}
