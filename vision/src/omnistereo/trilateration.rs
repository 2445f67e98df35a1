//! Self-localization by trilateration (Sect. 1): the robot's position from its ranges to the
//! three nearest landmarks at known places, its heading from their bearings.
//!
//! The paper names the method and not its solution. Ours: the circles `|p - c_i| = r_i`
//! subtracted pairwise give a linear system in `p` (exact for exact ranges), solved by least
//! squares; a few Gauss-Newton steps on the range residuals, weighted by each range's expected
//! error, then make it the least-squares position for noisy ranges. The heading is the circular
//! mean of `atan2(c_i - p) - bearing_i`.

use crate::VisionError;
use nalgebra::{Isometry2, Matrix2, Point2, Vector2};
use serde::{Deserialize, Serialize};

/// Which ranges trilateration uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum TrilaterationMode {
    /// The paper's: the three nearest landmarks.
    #[default]
    Nearest3,
    /// Every ranged landmark, by weighted least squares.
    AllLeastSquares,
}

/// A landmark of the map and what the robot measured of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LandmarkRange {
    /// The landmark's centre in the world frame, mm.
    pub centre_mm: Point2<f64>,
    /// Measured range from the robot to the centre, mm.
    pub range_mm: f64,
    /// Measured bearing of the centre (robot frame), rad.
    pub bearing_rad: f64,
    /// Expected error of the range, mm (weights the least squares).
    pub sigma_mm: f64,
}

/// Gauss-Newton steps after the linear solution (the residuals converge in two or three).
const STEPS: usize = 4;

/// The robot's pose from its ranges and bearings to mapped landmarks.
pub fn trilaterate(
    seen: &[LandmarkRange],
    mode: TrilaterationMode,
) -> Result<Isometry2<f64>, VisionError> {
    trilaterate_with_error(seen, mode).map(|t| t.pose)
}

/// A trilaterated pose and the expected error of its position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trilateration {
    /// The pose (world frame).
    pub pose: Isometry2<f64>,
    /// Expected position error, mm: `sqrt(trace(C) / 2)` with `C = (J^T W J)^-1` the
    /// covariance of the weighted least squares at the solution, the ranges' expected errors
    /// as their sigmas (our choice; the paper gives none).
    pub sigma_mm: f64,
}

/// [`trilaterate`] with the expected error of the position.
pub fn trilaterate_with_error(
    seen: &[LandmarkRange],
    mode: TrilaterationMode,
) -> Result<Trilateration, VisionError> {
    let mut used: Vec<LandmarkRange> = seen.to_vec();
    used.sort_by(|a, b| a.range_mm.total_cmp(&b.range_mm));
    if mode == TrilaterationMode::Nearest3 {
        used.truncate(3);
    }
    if used.len() < 3 {
        return Err(VisionError::NotFound(format!(
            "{} landmark(s) ranged: trilateration needs three",
            used.len()
        )));
    }
    let mut p = linear_solution(&used)?;
    for _ in 0..STEPS {
        p = gauss_newton_step(&used, p)?;
    }
    let (mut s, mut c) = (0.0, 0.0);
    for l in &used {
        let d = l.centre_mm - p;
        let h = d.y.atan2(d.x) - l.bearing_rad;
        s += h.sin();
        c += h.cos();
    }
    let (information, _) = normal_equations(&used, p);
    let covariance = information
        .try_inverse()
        .ok_or_else(|| VisionError::NotFound("singular trilateration".into()))?;
    Ok(Trilateration {
        pose: Isometry2::new(p.coords, s.atan2(c)),
        sigma_mm: (0.5 * covariance.trace()).max(0.0).sqrt(),
    })
}

/// Solves `2 (c_i - c_0) . p = r_0^2 - r_i^2 + |c_i|^2 - |c_0|^2` by least squares.
fn linear_solution(used: &[LandmarkRange]) -> Result<Point2<f64>, VisionError> {
    let c0 = used[0].centre_mm.coords;
    let r0 = used[0].range_mm;
    let mut ata = Matrix2::zeros();
    let mut atb = Vector2::zeros();
    for l in &used[1..] {
        let c = l.centre_mm.coords;
        let row = 2.0 * (c - c0);
        let b = r0 * r0 - l.range_mm * l.range_mm + c.norm_squared() - c0.norm_squared();
        ata += row * row.transpose();
        atb += row * b;
    }
    solve(ata, atb).map(Point2::from)
}

/// `J^T W J` and `J^T W r` of the range residuals `r_i = |p - c_i| - r_i` at `p` (the weights
/// are the ranges' inverse variances).
fn normal_equations(used: &[LandmarkRange], p: Point2<f64>) -> (Matrix2<f64>, Vector2<f64>) {
    let mut jtj = Matrix2::zeros();
    let mut jtr = Vector2::zeros();
    for l in used {
        let d = p - l.centre_mm;
        let n = d.norm().max(1e-9);
        let j = d / n;
        let w = 1.0 / (l.sigma_mm * l.sigma_mm).max(1e-6);
        jtj += w * j * j.transpose();
        jtr += w * j * (n - l.range_mm);
    }
    (jtj, jtr)
}

/// One weighted Gauss-Newton step on `|p - c_i| - r_i`.
fn gauss_newton_step(used: &[LandmarkRange], p: Point2<f64>) -> Result<Point2<f64>, VisionError> {
    let (jtj, jtr) = normal_equations(used, p);
    Ok(p - solve(jtj, jtr)?)
}

fn solve(a: Matrix2<f64>, b: Vector2<f64>) -> Result<Vector2<f64>, VisionError> {
    // Conditioning: the landmarks seen must not lie on one line through the robot.
    let (tr, det) = (a.trace(), a.determinant());
    if det.is_nan() || det <= 1e-9 * tr * tr {
        return Err(VisionError::NotFound(
            "the ranged landmarks are (nearly) on one line: the position is not determined".into(),
        ));
    }
    a.lu()
        .solve(&b)
        .ok_or_else(|| VisionError::NotFound("singular trilateration".into()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};

    fn pillars() -> Vec<Point2<f64>> {
        [
            (-2000.0, 1200.0),
            (0.0, 1500.0),
            (2100.0, 1100.0),
            (2200.0, -1300.0),
            (200.0, -1500.0),
            (-1900.0, -1200.0),
        ]
        .iter()
        .map(|&(x, y)| Point2::new(x, y))
        .collect()
    }

    fn seen(pose: Isometry2<f64>, noise_mm: f64, rng: &mut StdRng) -> Vec<LandmarkRange> {
        pillars()
            .iter()
            .map(|c| {
                let local = pose.inverse_transform_point(c);
                LandmarkRange {
                    centre_mm: *c,
                    range_mm: local.coords.norm() + noise_mm * (2.0 * rng.random::<f64>() - 1.0),
                    bearing_rad: local.y.atan2(local.x),
                    sigma_mm: 10.0,
                }
            })
            .collect()
    }

    #[test]
    fn exact_ranges_give_the_pose_back() {
        let mut rng = StdRng::seed_from_u64(1);
        for (x, y, h) in [
            (0.0, 0.0, 0.3),
            (-1200.0, 700.0, -2.5),
            (1500.0, -900.0, 3.0),
        ] {
            let pose = Isometry2::new(Vector2::new(x, y), h);
            for mode in [
                TrilaterationMode::Nearest3,
                TrilaterationMode::AllLeastSquares,
            ] {
                let est = trilaterate(&seen(pose, 0.0, &mut rng), mode).unwrap();
                assert!((est.translation.vector - pose.translation.vector).norm() < 1e-6);
                let dh = (est.rotation.angle() - h + 3.0 * std::f64::consts::PI)
                    .rem_euclid(2.0 * std::f64::consts::PI)
                    - std::f64::consts::PI;
                assert!(dh.abs() < 1e-9, "{mode:?}: heading off by {dh}");
            }
        }
    }

    #[test]
    fn the_expected_error_is_the_spread_of_the_position() {
        // Ranges off by uniform noise of half-width a (sigma a / sqrt 3), told as such.
        let mut rng = StdRng::seed_from_u64(3);
        let pose = Isometry2::new(Vector2::new(600.0, -400.0), 0.2);
        let a = 30.0;
        let (mut sum2, mut predicted) = (0.0, 0.0);
        let trials = 2000;
        for _ in 0..trials {
            let mut s = seen(pose, a, &mut rng);
            s.iter_mut().for_each(|l| l.sigma_mm = a / 3f64.sqrt());
            let t = trilaterate_with_error(&s, TrilaterationMode::Nearest3).unwrap();
            sum2 += (t.pose.translation.vector - pose.translation.vector).norm_squared() / 2.0;
            predicted += t.sigma_mm / trials as f64;
        }
        let actual = (sum2 / trials as f64).sqrt();
        assert!(
            (predicted / actual - 1.0).abs() < 0.15,
            "predicted {predicted:.2} mm, actual {actual:.2} mm"
        );
    }

    #[test]
    fn noise_degrades_the_position_gracefully() {
        let mut rng = StdRng::seed_from_u64(2);
        let pose = Isometry2::new(Vector2::new(-300.0, 200.0), 0.7);
        let mut last = 0.0;
        for noise in [5.0, 20.0, 80.0] {
            let mut sum = 0.0;
            for _ in 0..200 {
                let est =
                    trilaterate(&seen(pose, noise, &mut rng), TrilaterationMode::Nearest3).unwrap();
                sum += (est.translation.vector - pose.translation.vector).norm();
            }
            let mean = sum / 200.0;
            // Of the order of the range error, and growing with it, never a jump.
            assert!(
                mean < 2.5 * noise && mean > last,
                "noise {noise}: mean error {mean}"
            );
            last = mean;
        }
    }

    #[test]
    fn too_few_or_collinear_landmarks_are_not_found() {
        let mut rng = StdRng::seed_from_u64(3);
        let pose = Isometry2::new(Vector2::new(0.0, 0.0), 0.0);
        let two = &seen(pose, 0.0, &mut rng)[..2];
        assert!(trilaterate(two, TrilaterationMode::Nearest3).is_err());
        let line: Vec<LandmarkRange> = [-2000.0, 0.0, 2000.0]
            .iter()
            .map(|&x: &f64| LandmarkRange {
                centre_mm: Point2::new(x, 0.0),
                range_mm: f64::abs(x).max(1.0),
                bearing_rad: 0.0,
                sigma_mm: 10.0,
            })
            .collect();
        let e = trilaterate(&line, TrilaterationMode::Nearest3).unwrap_err();
        assert!(e.to_string().contains("one line"), "{e}");
    }
}
