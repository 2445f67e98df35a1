//! Heading error from a luminance circle (Kim, Kim and Kwon, "A Real Time Detection Algorithm
//! for Direction Error in Omnidirectional Image Sensors for Mobile Robots", Sect. 3 and 4).
//!
//! Indoors almost every structure is vertical, so the grey levels seen along one horizontal
//! plane around the robot are a signature of the place. At a checkpoint the robot stores the
//! luminance of the image circle whose rays are horizontal ([`LuminanceCircle`], 360 samples,
//! smoothed by eq. (1)); back at the checkpoint it compares the new circle with the stored one
//! and reads its heading error from the angular shift between them (eqs. (2)-(6), or the fast
//! form with signs, eqs. (7)-(10)); the pattern match of eqs. (11)-(12) says "N/A" when the two
//! circles differ too much for the robot to be at the checkpoint.
//!
//! Angles: sample `k` of a circle looks along the robot-frame azimuth `k * 360 / n` degrees,
//! counter-clockwise from the robot's x axis (image pixel `(cx + R cos a, cy - R sin a)`: for a
//! convex mirror seen from below a scene ray keeps its pixel's azimuth). A shift is the robot's
//! turn since the reference, counter-clockwise positive: a robot turned by `+d` sees every
//! feature `d` further clockwise, `current[k] = reference[k + d]`. (The paper: "the minus sign
//! means the data sampled is rotated counterclockwise from the reference data", the same
//! convention.)

use crate::{RadialCalibration, VisionError};
use image::RgbaImage;
use serde::{Deserialize, Serialize};

/// Settings of the method (`[vision.luminance_heading]` in scenarios).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LuminanceConfig {
    /// The circle: the image radius whose scene rays are at this elevation above the
    /// horizontal, from the calibration's elevation column, degrees (the paper: a horizontal
    /// plane, 0).
    pub elevation_deg: f64,
    /// ... or this image radius, px, when given.
    pub radius_px: Option<f64>,
    /// Samples on the circle (the paper: 360, one a degree).
    pub samples: usize,
    /// The shift search a reading reports (both are computed where an experiment compares
    /// them).
    pub method: ShiftMethod,
    /// Eq. (1): samples averaged before (`N`) ...
    pub average_before: usize,
    /// ... and after (`M`) each one (the paper: M = N = 2, a 5-point moving average).
    pub average_after: usize,
    /// Eq. (11): a sample matches when the aligned reference and current grey levels differ by
    /// less than this (`theta_th`, grey levels of 255; the paper gives no value). Default 20:
    /// some fifteen times the smoothed circle's noise (sensor sigma 4 a channel is about 1.2
    /// grey levels after eq. (1)), so noise alone never breaks a match, and a tenth of a
    /// room's range of grey levels, so that a view from 40-50 cm away no longer matches. In
    /// E3's room, 20 cm off the checkpoint, 12 levels match 70-72% of the samples (the edge of
    /// the requirement), 20 levels 79-83%; with 20, N/A comes by 50 cm in every direction.
    pub match_threshold: f64,
    /// Eq. (10): a difference between neighbouring samples within this many grey levels has
    /// sign 0. Sect. 3.1: "variations within the threshold value are ignored"; without it the
    /// signs of a flat panel are those of the sensor noise, and they blur the true shift by a
    /// degree or two.
    pub sign_dead_band: f64,
    /// Ours: a reading that matches at least this much (percent) places the robot at the
    /// checkpoint itself, close enough for a position fix (in E3's room 5 cm off the
    /// checkpoint matches 89-94%, 10 cm 78-84%); the paper reads the heading only.
    pub at_checkpoint_match_percent: f64,
    /// Sect. 4, the inner circle `r2 < r1`: the image radius whose rays are at this elevation,
    /// degrees (down toward the floor near the robot; -45 from a mirror 300 mm up meets the
    /// floor 300 mm away).
    pub inner_elevation_deg: f64,
    /// ... a direction holds something near when its grey level differs from the floor's (the
    /// median of the inner circle) by more than this, grey levels.
    pub near_threshold: f64,
}

impl Default for LuminanceConfig {
    fn default() -> Self {
        Self {
            elevation_deg: 0.0,
            radius_px: None,
            samples: 360,
            method: ShiftMethod::Signs,
            average_before: 2,
            average_after: 2,
            match_threshold: 20.0,
            sign_dead_band: 1.0,
            at_checkpoint_match_percent: 92.0,
            inner_elevation_deg: -45.0,
            near_threshold: 25.0,
        }
    }
}

impl LuminanceConfig {
    /// The circle's image radius for the sensor `cal` describes: `radius_px`, or where its
    /// scene rays are at `elevation_deg`.
    pub fn circle_radius_px(&self, cal: &RadialCalibration) -> Result<f64, VisionError> {
        if let Some(r) = self.radius_px {
            return Ok(r);
        }
        cal.radius_at_elevation_px(self.elevation_deg.to_radians())
            .ok_or_else(|| {
                VisionError::Calibration(format!(
                    "no image radius of sensor {:?} looks at {} deg elevation (the table's \
                     elevation column is empty or does not reach it: run omniloop calibrate \
                     again, or set radius_px)",
                    cal.sensor, self.elevation_deg
                ))
            })
    }

    /// Checks the settings.
    pub fn validate(&self) -> Result<(), VisionError> {
        if self.samples < 8 {
            return Err(VisionError::InvalidParameter {
                name: "samples",
                value: self.samples as f64,
                rule: "must be at least 8",
            });
        }
        if self.average_before + self.average_after >= self.samples {
            return Err(VisionError::InvalidParameter {
                name: "average_before + average_after",
                value: (self.average_before + self.average_after) as f64,
                rule: "must be less than the samples",
            });
        }
        if !(self.sign_dead_band.is_finite() && self.sign_dead_band >= 0.0) {
            return Err(VisionError::InvalidParameter {
                name: "sign_dead_band",
                value: self.sign_dead_band,
                rule: "must be a finite number >= 0",
            });
        }
        for (name, v) in [
            ("match_threshold", self.match_threshold),
            ("near_threshold", self.near_threshold),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(VisionError::InvalidParameter {
                    name,
                    value: v,
                    rule: "must be a finite number > 0",
                });
            }
        }
        Ok(())
    }
}

/// The grey level (0-255, ITU-R BT.601 luma) of `img` at continuous pixel coordinates `(x, y)`
/// (pixel `(u, v)` spans `[u, u + 1) x [v, v + 1)`, its centre at `u + 0.5`), bilinear;
/// `None` outside the image.
pub fn grey_at(img: &RgbaImage, x: f64, y: f64) -> Option<f64> {
    let (fx, fy) = (x - 0.5, y - 0.5);
    let (w, h) = (img.width() as f64, img.height() as f64);
    if !(fx >= 0.0 && fy >= 0.0 && fx <= w - 1.0 && fy <= h - 1.0) {
        return None;
    }
    let (u0, v0) = (fx.floor(), fy.floor());
    let (a, b) = (fx - u0, fy - v0);
    let (u0, v0) = (u0 as u32, v0 as u32);
    let (u1, v1) = (
        (u0 + 1).min(img.width() - 1),
        (v0 + 1).min(img.height() - 1),
    );
    let luma = |u: u32, v: u32| {
        let p = img.get_pixel(u, v).0;
        0.299 * f64::from(p[0]) + 0.587 * f64::from(p[1]) + 0.114 * f64::from(p[2])
    };
    Some(
        (1.0 - b) * ((1.0 - a) * luma(u0, v0) + a * luma(u1, v0))
            + b * ((1.0 - a) * luma(u0, v1) + a * luma(u1, v1)),
    )
}

/// `n` grey levels on the image circle of radius `radius_px` about the principal point
/// `centre_px` (pixels from the image's top-left corner), sample `k` at robot-frame azimuth
/// `k * 360 / n` degrees; an error when the circle leaves the image.
pub fn sample_circle(
    img: &RgbaImage,
    centre_px: [f64; 2],
    radius_px: f64,
    n: usize,
) -> Result<Vec<f64>, VisionError> {
    if !(radius_px.is_finite() && radius_px > 0.0) {
        return Err(VisionError::InvalidParameter {
            name: "circle radius (px)",
            value: radius_px,
            rule: "must be a finite number > 0",
        });
    }
    // The azimuth turned sample by sample (a rotation each), not recomputed.
    let (ds, dc) = (std::f64::consts::TAU / n as f64).sin_cos();
    let (mut sin, mut cos) = (0.0f64, 1.0f64);
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let v = grey_at(
            img,
            centre_px[0] + radius_px * cos,
            centre_px[1] - radius_px * sin,
        )
        .ok_or(VisionError::InvalidParameter {
            name: "circle radius (px)",
            value: radius_px,
            rule: "the circle must lie inside the image",
        })?;
        out.push(v);
        (cos, sin) = (cos * dc - sin * ds, sin * dc + cos * ds);
    }
    Ok(out)
}

/// Eq. (1), circular: `y[n] = 1 / (N + M + 1) * sum_{k=-N}^{M} x[n - k]`, with `N` =
/// `before` and `M` = `after`. (As the paper writes it, `k = -N` reaches `N` samples ahead of
/// `n` and `k = M` reaches `M` behind; with M = N the two readings agree.)
pub fn moving_average(x: &[f64], before: usize, after: usize) -> Vec<f64> {
    let n = x.len();
    let width = (before + after + 1) as f64;
    (0..n)
        .map(|i| {
            (0..=before + after)
                .map(|j| x[(i + n * (after + 1) + before - j) % n])
                .sum::<f64>()
                / width
        })
        .collect()
}

/// Eqs. (2)-(3): `D = (l0 - l1, l1 - l2, ..., l359 - l0)`.
pub fn differences(l: &[f64]) -> Vec<f64> {
    let n = l.len();
    (0..n).map(|m| l[m] - l[(m + 1) % n]).collect()
}

/// Eq. (10): `S = (sgn(l0 - l1), ..., sgn(l359 - l0))`, a difference within `dead_band` of
/// zero counting as 0 (Sect. 3.1's ignored variations).
pub fn signs(l: &[f64], dead_band: f64) -> Vec<i8> {
    differences(l)
        .into_iter()
        .map(|d| {
            if d > dead_band {
                1
            } else if d < -dead_band {
                -1
            } else {
                0
            }
        })
        .collect()
}

/// Eqs. (4)-(6): the shift `i` (samples, 0..n) minimising
/// `r_i = sum_m |D_stored[m] - D_current,i[m]|`, with `D_current,i[m] = D_current[m - i]`
/// (wrap-around), and `r_i` itself.
pub fn shift_by_differences(d_stored: &[f64], d_current: &[f64]) -> (usize, f64) {
    let n = d_stored.len();
    // D_current twice over: its shift by i is the window starting at n - i, so that each sum
    // is one straight pass; in single precision (grey levels need no more) and eight running
    // sums, which the compiler keeps in vector registers (one running sum would have to add
    // in order).
    let stored: Vec<f32> = d_stored.iter().map(|&v| v as f32).collect();
    let twice: Vec<f32> = d_current
        .iter()
        .chain(d_current)
        .map(|&v| v as f32)
        .collect();
    let mut best = (0, f64::INFINITY);
    for i in 0..n {
        let window = &twice[n - i..2 * n - i];
        let mut lanes = [0f32; 8];
        let (a8, b8) = (stored.chunks_exact(8), window.chunks_exact(8));
        let (ra, rb) = (a8.remainder(), b8.remainder());
        for (a, b) in a8.zip(b8) {
            for k in 0..8 {
                lanes[k] += (a[k] - b[k]).abs();
            }
        }
        let tail: f32 = ra.iter().zip(rb).map(|(a, b)| (a - b).abs()).sum();
        let r = f64::from(lanes.iter().sum::<f32>() + tail);
        if r < best.1 {
            best = (i, r);
        }
    }
    best
}

/// Eqs. (7)-(9): the shift `i` (samples) at which the sign arrays agree best, and that
/// agreement `s_i = S_stored . S_current,i`.
///
/// The paper writes `s'_n = min(s_0, ..., s_359)` (eq. (8)), but `s_i` is a sum of products of
/// signs: +1 where the two circles rise or fall together, -1 where they disagree. It is largest,
/// not smallest, at the right shift (the minimum picks the shift where the circles disagree
/// most). We take the maximum.
pub fn shift_by_signs(s_stored: &[i8], s_current: &[i8]) -> (usize, i32) {
    let n = s_stored.len();
    let twice: Vec<i8> = s_current.iter().chain(s_current).copied().collect();
    let mut best = (0, i32::MIN);
    for i in 0..n {
        let window = &twice[n - i..2 * n - i];
        let s: i32 = s_stored
            .iter()
            .zip(window)
            .map(|(&a, &b)| i32::from(a) * i32::from(b))
            .sum();
        if s > best.1 {
            best = (i, s);
        }
    }
    best
}

/// A shift of `i` samples of `n` as an angle in (-180, 180] degrees.
pub fn shift_deg(i: usize, n: usize) -> f64 {
    let deg = i as f64 * 360.0 / n as f64;
    if deg > 180.0 { deg - 360.0 } else { deg }
}

/// Eqs. (11)-(12): the pattern match `(m / n) * 100`, with `m` the samples whose aligned
/// reference and current grey levels differ by less than `threshold`, and the minimum
/// requirement `-(15 / 180) * |shift_deg| + 70`. (The paper writes the angle shift without the
/// absolute value, but says the requirement "decreases linearly as the absolute value of the
/// angle shift increases", and rotations either way must be accepted alike.)
pub fn pattern_match(reference: &[f64], current: &[f64], shift: usize, threshold: f64) -> Match {
    let n = reference.len();
    let m = (0..n)
        .filter(|&k| (reference[k] - current[(k + n - shift) % n]).abs() < threshold)
        .count();
    Match {
        percent: 100.0 * m as f64 / n as f64,
        required: -(15.0 / 180.0) * shift_deg(shift, n).abs() + 70.0,
    }
}

/// The pattern match of an alignment (eqs. (11)-(12)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Match {
    /// Current value, percent of the samples that match.
    pub percent: f64,
    /// Minimum requirement, percent.
    pub required: f64,
}

impl Match {
    /// Whether the match meets the requirement (else the shift is N/A).
    pub fn accepted(&self) -> bool {
        self.percent >= self.required
    }
}

/// The smoothed luminance of one image circle: a checkpoint's reference, or the current view.
#[derive(Debug, Clone, PartialEq)]
pub struct LuminanceCircle {
    /// Grey levels after eq. (1), sample `k` at azimuth `k * 360 / n` degrees.
    pub values: Vec<f64>,
}

impl LuminanceCircle {
    /// Samples the circle of radius `radius_px` about `centre_px` and smooths it (eq. (1)).
    pub fn capture(
        img: &RgbaImage,
        centre_px: [f64; 2],
        radius_px: f64,
        config: &LuminanceConfig,
    ) -> Result<Self, VisionError> {
        config.validate()?;
        let raw = sample_circle(img, centre_px, radius_px, config.samples)?;
        Ok(Self {
            values: moving_average(&raw, config.average_before, config.average_after),
        })
    }

    /// How far the robot has turned since `reference` was stored, by the sign arrays
    /// (eqs. (7)-(10)) or the differences (eqs. (2)-(6)), with the pattern match at that shift.
    pub fn shift_from(
        &self,
        reference: &LuminanceCircle,
        method: ShiftMethod,
        config: &LuminanceConfig,
    ) -> Result<HeadingShift, VisionError> {
        let n = reference.values.len();
        if self.values.len() != n {
            return Err(VisionError::InvalidParameter {
                name: "samples of the current circle",
                value: self.values.len() as f64,
                rule: "must equal the reference's",
            });
        }
        let i = match method {
            ShiftMethod::Differences => {
                shift_by_differences(&differences(&reference.values), &differences(&self.values)).0
            }
            ShiftMethod::Signs => {
                let b = config.sign_dead_band;
                shift_by_signs(&signs(&reference.values, b), &signs(&self.values, b)).0
            }
        };
        let matched = pattern_match(&reference.values, &self.values, i, config.match_threshold);
        Ok(HeadingShift {
            shift_deg: shift_deg(i, n),
            matched,
        })
    }
}

/// Which shift search runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ShiftMethod {
    /// Eqs. (2)-(6): sums of absolute differences of the difference arrays.
    Differences,
    /// Eqs. (7)-(10): products of signs, the paper's fast form.
    #[default]
    Signs,
}

/// The reading at a checkpoint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadingShift {
    /// The robot's turn since the reference, degrees in (-180, 180], counter-clockwise positive.
    pub shift_deg: f64,
    /// The pattern match at that shift; below its requirement the reading is N/A.
    pub matched: Match,
}

impl HeadingShift {
    /// The shift, or `None` (N/A) when the pattern match is below its requirement.
    pub fn accepted_deg(&self) -> Option<f64> {
        self.matched.accepted().then_some(self.shift_deg)
    }
}

/// Sect. 4, the inner circle of `cal`'s sensor (rays at `inner_elevation_deg`): for each of
/// `samples` directions (sample `k` at `k * 360 / n` degrees), whether something near stands
/// there, by [`near_directions`] on the smoothed circle.
pub fn near_ring(
    img: &RgbaImage,
    cal: &RadialCalibration,
    config: &LuminanceConfig,
) -> Result<Vec<bool>, VisionError> {
    config.validate()?;
    let r2 = cal
        .radius_at_elevation_px(config.inner_elevation_deg.to_radians())
        .ok_or_else(|| {
            VisionError::Calibration(format!(
                "no image radius of sensor {:?} looks at {} deg elevation",
                cal.sensor, config.inner_elevation_deg
            ))
        })?;
    let raw = sample_circle(img, cal.principal_point_px, r2, config.samples)?;
    let smooth = moving_average(&raw, config.average_before, config.average_after);
    Ok(near_directions(&smooth, config.near_threshold))
}

/// Sect. 4, the inner circle (`r2 < r1`, rays toward the floor near the robot): for each
/// sample, whether something near stands there, its grey level differing from the floor's (the
/// median of the circle, most of it floor) by more than `threshold`.
pub fn near_directions(inner: &[f64], threshold: f64) -> Vec<bool> {
    if inner.is_empty() {
        return Vec::new();
    }
    let mut sorted = inner.to_vec();
    sorted.sort_by(f64::total_cmp);
    let floor = sorted[sorted.len() / 2];
    inner
        .iter()
        .map(|v| (v - floor).abs() > threshold)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};

    /// A room's circle: panels of assorted grey levels (walls, doors, boxes, a pillar) with
    /// sharp edges and a little shading, and noise of `noise` grey levels (uniform, either
    /// way). The robot has turned by `turn` samples: `current[k] = reference[k + turn]`.
    fn signal(n: usize, turn: i64, noise: f64, rng: &mut StdRng) -> Vec<f64> {
        // (start of the panel in degrees, grey level)
        const PANELS: [(f64, f64); 12] = [
            (0.0, 200.0),
            (22.0, 60.0),
            (41.0, 190.0),
            (75.0, 110.0),
            (96.0, 205.0),
            (150.0, 30.0),
            (163.0, 200.0),
            (201.0, 140.0),
            (236.0, 210.0),
            (262.0, 90.0),
            (300.0, 195.0),
            (331.0, 160.0),
        ];
        (0..n as i64)
            .map(|k| {
                let deg = (k + turn).rem_euclid(n as i64) as f64 * 360.0 / n as f64;
                let panel = PANELS
                    .iter()
                    .rev()
                    .find(|p| p.0 <= deg)
                    .unwrap_or(&PANELS[0]);
                let shading = 8.0 * (deg.to_radians() * 3.0).sin();
                panel.1 + shading + noise * (rng.random::<f64>() - 0.5) * 2.0
            })
            .collect()
    }

    #[test]
    fn both_shift_searches_find_known_turns_through_noise() {
        let cfg = LuminanceConfig::default();
        for seed in 0..6 {
            let mut rng = StdRng::seed_from_u64(seed);
            let reference = LuminanceCircle {
                values: moving_average(&signal(360, 0, 4.0, &mut rng), 2, 2),
            };
            for turn in [-179, -24, -1, 0, 1, 60, 120, 180] {
                let current = LuminanceCircle {
                    values: moving_average(&signal(360, turn, 4.0, &mut rng), 2, 2),
                };
                for method in [ShiftMethod::Differences, ShiftMethod::Signs] {
                    let h = current.shift_from(&reference, method, &cfg).unwrap();
                    let want = shift_deg(turn.rem_euclid(360) as usize, 360);
                    assert!(
                        (h.shift_deg - want).abs() <= 1.0,
                        "{method:?}: turn {turn} read as {}",
                        h.shift_deg
                    );
                    assert!(h.matched.accepted(), "{method:?} {turn}: {:?}", h.matched);
                }
            }
        }
    }

    #[test]
    fn the_moving_average_is_circular_and_five_points_wide() {
        let x = [10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 5.0];
        let y = moving_average(&x, 2, 2);
        // Sample 0 averages samples 6, 7, 0, 1, 2.
        assert!((y[0] - 3.0).abs() < 1e-12);
        assert!((y[1] - 3.0).abs() < 1e-12);
        assert!((y[2] - 2.0).abs() < 1e-12);
        assert!((y[3] - 0.0).abs() < 1e-12);
        assert!((y[5] - 1.0).abs() < 1e-12);
        assert!((y[6] - 3.0).abs() < 1e-12);
        assert!((y[7] - 3.0).abs() < 1e-12);
        // Asymmetric: N = 0, M = 1 averages sample n and the one before it.
        let z = moving_average(&x, 0, 1);
        assert!((z[0] - 7.5).abs() < 1e-12);
        assert!((z[1] - 5.0).abs() < 1e-12);
    }

    #[test]
    fn the_na_rule_follows_eqs_11_and_12() {
        let reference: Vec<f64> = (0..360).map(|k| k as f64).collect();
        // 300 of 360 samples match at shift 0: 83.3% >= 70.
        let mut current = reference.clone();
        for v in current.iter_mut().take(60) {
            *v += 50.0;
        }
        let m = pattern_match(&reference, &current, 0, 10.0);
        assert!((m.percent - 300.0 / 3.6).abs() < 1e-9 && m.required == 70.0);
        assert!(m.accepted());
        // The requirement falls by 15 points over 180 degrees, either way.
        assert!((pattern_match(&reference, &current, 90, 10.0).required - 62.5).abs() < 1e-12);
        assert!((pattern_match(&reference, &current, 270, 10.0).required - 62.5).abs() < 1e-12);
        // 200 of 360 (55.6%) fails at shift 0 (70) and passes at 180 degrees (55).
        for v in current.iter_mut().take(160) {
            *v += 50.0;
        }
        assert!(!pattern_match(&reference, &current, 0, 10.0).accepted());
        let rotated: Vec<f64> = (0..360).map(|k| current[(k + 180) % 360]).collect();
        let m = pattern_match(&reference, &rotated, 180, 10.0);
        assert!((m.required - 55.0).abs() < 1e-12 && m.accepted(), "{m:?}");
    }

    #[test]
    fn near_directions_stand_out_from_the_floor() {
        let mut inner = vec![140.0; 36];
        inner[5] = 40.0;
        inner[6] = 60.0;
        inner[20] = 150.0;
        let near = near_directions(&inner, 25.0);
        assert_eq!(
            near.iter()
                .enumerate()
                .filter(|(_, b)| **b)
                .map(|(k, _)| k)
                .collect::<Vec<_>>(),
            vec![5, 6]
        );
    }

    #[test]
    fn a_circle_outside_the_image_is_an_error() {
        let img = RgbaImage::new(64, 64);
        assert!(sample_circle(&img, [32.0, 32.0], 20.0, 90).is_ok());
        assert!(sample_circle(&img, [32.0, 32.0], 40.0, 90).is_err());
        assert!(sample_circle(&img, [32.0, 32.0], f64::NAN, 90).is_err());
    }
}
