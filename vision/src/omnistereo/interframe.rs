//! Interframe motion (Sect. 1): the robot's translation between two frames from features seen
//! in both, each with its omnistereo range and bearing, given the rotation the visual compass
//! read.
//!
//! A fixed point seen at `(r1, theta1)` in the earlier frame and `(r2, theta2)` in the later
//! one, the robot having turned by `omega`, satisfies `r1 u(theta1) = t + r2 u(theta2 + omega)`
//! (`u(a) = (cos a, sin a)`, everything in the earlier frame's robot axes), so one feature gives
//! the translation `t = r1 u(theta1) - r2 u(theta2 + omega)`. Many features give many
//! solutions, some wrong (features on moving objects, mismatches); the paper combines them with
//! its robust clustering `Clumat`, which it does not publish.
//!
//! Ours, [`densest_cluster`]: each solution `t_i` comes with its expected error `sigma_i` (from
//! its ranges). Two solutions agree when `|t_i - t_j| <= k sqrt(sigma_i^2 + sigma_j^2)`. The
//! seed is the solution with the largest agreeing weight (`sum 1 / sigma_j^2` over those that
//! agree with it); the estimate is the weighted mean of the solutions that agree with the seed,
//! and once more of those within `k sigma_j` of that mean. Two fixed passes, no iteration to
//! convergence: a minority of outliers, however far, never moves the estimate, and a cluster of
//! outliers wins only by outweighing the true one.

use super::numbers::wrap;
use crate::VisionError;
use nalgebra::Vector2;

/// One feature seen in two frames.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeaturePair {
    /// Range in the earlier frame, mm.
    pub range_before_mm: f64,
    /// Bearing in the earlier frame (robot frame), rad.
    pub bearing_before_rad: f64,
    /// Range in the later frame, mm.
    pub range_after_mm: f64,
    /// Bearing in the later frame, rad.
    pub bearing_after_rad: f64,
    /// Expected error of one range, mm.
    pub sigma_mm: f64,
}

/// A translation solution and its expected error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// The translation, mm (earlier frame's axes).
    pub t_mm: Vector2<f64>,
    /// Its expected error, mm.
    pub sigma_mm: f64,
}

/// The combined translation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Translation {
    /// The robot's translation between the frames, in the earlier frame's axes, mm.
    pub translation_mm: Vector2<f64>,
    /// Solutions in the cluster.
    pub inliers: usize,
    /// Solutions rejected.
    pub outliers: usize,
}

fn unit(a: f64) -> Vector2<f64> {
    Vector2::new(a.cos(), a.sin())
}

/// One translation per feature: `t = r1 u(theta1) - r2 u(theta2 + omega)`.
pub fn translation_candidates(pairs: &[FeaturePair], rotation_rad: f64) -> Vec<Candidate> {
    pairs
        .iter()
        .map(|p| Candidate {
            t_mm: p.range_before_mm * unit(p.bearing_before_rad)
                - p.range_after_mm * unit(wrap(p.bearing_after_rad + rotation_rad)),
            // Two independent ranges, each along its own bearing.
            sigma_mm: p.sigma_mm * std::f64::consts::SQRT_2,
        })
        .collect()
}

/// Combines the solutions robustly (see the module's description); `k` is the agreement
/// radius in units of the expected error.
pub fn densest_cluster(candidates: &[Candidate], k: f64) -> Result<Translation, VisionError> {
    let w = |c: &Candidate| 1.0 / (c.sigma_mm * c.sigma_mm).max(1e-9);
    let agree = |a: &Candidate, b: &Candidate| {
        (a.t_mm - b.t_mm).norm() <= k * (a.sigma_mm.powi(2) + b.sigma_mm.powi(2)).sqrt()
    };
    let support = |a: &Candidate| -> f64 {
        candidates
            .iter()
            .filter(|b| agree(a, b))
            .map(w)
            .sum::<f64>()
    };
    let best = candidates.iter().map(|c| (c, support(c))).fold(
        None::<(&Candidate, f64)>,
        |best, (c, s)| match best {
            Some((_, b)) if b >= s => best,
            _ => Some((c, s)),
        },
    );
    let Some((&seed, _)) = best else {
        return Err(VisionError::NotFound(
            "no feature seen in both frames: no translation".into(),
        ));
    };
    let first: Vec<&Candidate> = candidates.iter().filter(|c| agree(&seed, c)).collect();
    let mean = weighted_mean(&first, w);
    let second: Vec<&Candidate> = candidates
        .iter()
        .filter(|c| (c.t_mm - mean).norm() <= k * c.sigma_mm)
        .collect();
    let (chosen, t) = if second.is_empty() {
        (first.len(), mean)
    } else {
        (second.len(), weighted_mean(&second, w))
    };
    Ok(Translation {
        translation_mm: t,
        inliers: chosen,
        outliers: candidates.len() - chosen,
    })
}

fn weighted_mean(cs: &[&Candidate], w: impl Fn(&Candidate) -> f64) -> Vector2<f64> {
    let total: f64 = cs.iter().map(|c| w(c)).sum();
    cs.iter()
        .map(|c| c.t_mm * w(c))
        .fold(Vector2::zeros(), |a, b| a + b)
        / total
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Isometry2, Point2};
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};

    #[test]
    fn one_fixed_point_gives_the_translation() {
        // The robot moves from pose a to pose b; every fixed point yields t = a^-1 b's
        // translation, in a's axes.
        let a = Isometry2::new(Vector2::new(100.0, -50.0), 0.4);
        let b = Isometry2::new(Vector2::new(112.0, -41.0), 0.43);
        let truth = (a.inverse() * b).translation.vector;
        let omega = b.rotation.angle() - a.rotation.angle();
        for p in [Point2::new(1500.0_f64, 300.0), Point2::new(-800.0, 2500.0)] {
            let (la, lb) = (a.inverse_transform_point(&p), b.inverse_transform_point(&p));
            let pair = FeaturePair {
                range_before_mm: la.coords.norm(),
                bearing_before_rad: la.y.atan2(la.x),
                range_after_mm: lb.coords.norm(),
                bearing_after_rad: lb.y.atan2(lb.x),
                sigma_mm: 5.0,
            };
            let c = translation_candidates(&[pair], omega)[0];
            assert!((c.t_mm - truth).norm() < 1e-9, "{} vs {truth}", c.t_mm);
        }
    }

    #[test]
    fn the_clustering_ignores_thirty_percent_outliers() {
        let mut rng = StdRng::seed_from_u64(7);
        let truth = Vector2::new(14.0, -3.0);
        for trial in 0..50 {
            let mut cs = Vec::new();
            for _ in 0..14 {
                let e = Vector2::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5);
                cs.push(Candidate {
                    t_mm: truth + 10.0 * e,
                    sigma_mm: 4.0,
                });
            }
            // Six outliers (30%): far ones and some close to the truth but off.
            for _ in 0..6 {
                let e = Vector2::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5);
                cs.push(Candidate {
                    t_mm: truth + 400.0 * e + Vector2::new(30.0, 0.0),
                    sigma_mm: 4.0,
                });
            }
            let t = densest_cluster(&cs, 3.0).unwrap();
            let mean_of_all = cs.iter().map(|c| c.t_mm).sum::<Vector2<f64>>() / cs.len() as f64;
            assert!(
                (t.translation_mm - truth).norm() < 3.0,
                "trial {trial}: {} vs {truth} (the plain mean: {mean_of_all})",
                t.translation_mm
            );
            assert!(t.outliers >= 5, "trial {trial}: {t:?}");
        }
    }

    #[test]
    fn nothing_to_cluster_is_not_found() {
        assert!(densest_cluster(&[], 3.0).is_err());
    }
}
