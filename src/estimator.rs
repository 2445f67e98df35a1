//! The pose the vision controllers act on: dead reckoning from noisy wheel odometry, optionally
//! corrected by floor-region self-localization (a complementary filter).

use crate::scenario::{OdometrySpec, PoseSource};
use nalgebra::{Isometry2, Point2, Rotation2, Vector2};
use omniloop_control::DeadReckoning;
use omniloop_vision::PoseEstimate;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use std::f64::consts::{PI, TAU};

fn wrap_pi(a: f64) -> f64 {
    let w = a.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

/// A measurement farther than this from the prediction is not trusted.
const GATE_MM: f64 = 400.0;
const GATE_RAD: f64 = 0.35;

/// Tracks the robot's pose in the world frame.
pub struct PoseTracker {
    reckoning: DeadReckoning,
    rng: StdRng,
    speed_noise_frac: f64,
    omega_noise_rad_s: f64,
    scale: f64,
    omega_bias_rad_s: f64,
    /// The start pose: the origin of dead reckoning.
    start: Isometry2<f64>,
    source: PoseSource,
    gain: f64,
    /// Localization mode: the current estimate and the odometry pose it was last moved with.
    fused: Isometry2<f64>,
    fused_odo: Isometry2<f64>,
    initialized: bool,
    fixes: usize,
    rejected: usize,
}

impl PoseTracker {
    /// A tracker for a robot starting at `start` (world frame).
    pub fn new(
        start: Isometry2<f64>,
        odometry: &OdometrySpec,
        source: PoseSource,
        gain: f64,
        seed: u64,
    ) -> Self {
        Self {
            reckoning: DeadReckoning::new(),
            rng: StdRng::seed_from_u64(seed ^ 0x0D0_3E7E_u64),
            speed_noise_frac: odometry.speed_noise_frac,
            omega_noise_rad_s: odometry.omega_noise_rad_s,
            scale: 1.0 + odometry.scale_bias_frac,
            omega_bias_rad_s: odometry.omega_bias_rad_s,
            start,
            source,
            gain,
            fused: start,
            fused_odo: Isometry2::identity(),
            initialized: false,
            fixes: 0,
            rejected: 0,
        }
    }

    /// Takes the wheel odometry for the last `dt`: the true velocity (world frame) and rotation
    /// rate, measured in the body frame with the systematic errors and seeded Gaussian noise.
    pub fn measure(&mut self, v_world: Vector2<f64>, heading: f64, omega: f64, dt: f64) {
        let v_body = Rotation2::new(-heading) * v_world * self.scale;
        let mut n = || self.rng.sample::<f64, _>(StandardNormal);
        let noisy = Vector2::new(
            v_body.x * (1.0 + self.speed_noise_frac * n()),
            v_body.y * (1.0 + self.speed_noise_frac * n()),
        );
        let w = omega + self.omega_bias_rad_s + self.omega_noise_rad_s * n();
        self.reckoning.update(noisy, w, dt);
    }

    /// The measured body velocity.
    pub fn velocity_body_mm_s(&self) -> Vector2<f64> {
        self.reckoning.velocity_body_mm_s()
    }

    /// The pose estimate in the world frame.
    pub fn estimate(&self) -> Isometry2<f64> {
        match self.source {
            PoseSource::Odometry => self.start * self.reckoning.pose(),
            PoseSource::Localization => {
                // The fused pose moved on by the odometry since it was last set.
                let delta = self.fused_odo.inverse() * self.reckoning.pose();
                self.fused * delta
            }
        }
    }

    /// A world point in the robot's body frame, by the estimate.
    pub fn to_body(&self, p: Point2<f64>) -> Vector2<f64> {
        self.estimate().inverse_transform_point(&p).coords
    }

    /// Folds in a localization: the solution nearer the prediction is pulled toward by the
    /// gain (the first one resolved by the goals is taken as it is). Returns whether it was
    /// used.
    pub fn correct(&mut self, loc: &PoseEstimate) -> bool {
        if self.source != PoseSource::Localization {
            return false;
        }
        let predicted = self.estimate();
        if !self.initialized {
            if !loc.quality.resolved_by_goals {
                return false;
            }
            self.fused = loc.pose;
            self.fused_odo = self.reckoning.pose();
            self.initialized = true;
            self.fixes += 1;
            return true;
        }
        let d = |q: &Isometry2<f64>| (q.translation.vector - predicted.translation.vector).norm();
        let z = if d(&loc.pose) <= d(&loc.alternative) {
            loc.pose
        } else {
            loc.alternative
        };
        let dh = wrap_pi(z.rotation.angle() - predicted.rotation.angle());
        if d(&z) > GATE_MM || dh.abs() > GATE_RAD {
            self.rejected += 1;
            return false;
        }
        let t = predicted.translation.vector
            + (z.translation.vector - predicted.translation.vector) * self.gain;
        let h = predicted.rotation.angle() + self.gain * dh;
        self.fused = Isometry2::new(t, h);
        self.fused_odo = self.reckoning.pose();
        self.fixes += 1;
        true
    }

    /// Localizations used and rejected so far.
    pub fn fixes(&self) -> (usize, usize) {
        (self.fixes, self.rejected)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use omniloop_vision::floor_localization::LocalizationQuality;

    fn loc(x: f64, y: f64, h: f64, by_goals: bool) -> PoseEstimate {
        let pose = Isometry2::new(Vector2::new(x, y), h);
        PoseEstimate {
            pose,
            alternative: Isometry2::new(Vector2::new(-x, -y), wrap_pi(h + PI)),
            quality: LocalizationQuality {
                rms_residual_mm: 1.0,
                points: 100,
                lines: 4,
                iterations: 3,
                resolved_by_goals: by_goals,
            },
        }
    }

    #[test]
    fn odometry_moves_the_estimate_and_localization_pulls_it_back() {
        let spec = OdometrySpec {
            speed_noise_frac: 0.0,
            omega_noise_rad_s: 0.0,
            scale_bias_frac: 0.0,
            omega_bias_rad_s: 0.0,
        };
        let start = Isometry2::new(Vector2::new(-500.0, 0.0), 0.0);
        let mut t = PoseTracker::new(start, &spec, PoseSource::Localization, 0.5, 1);
        // Not resolved by goals: not used to initialise.
        assert!(!t.correct(&loc(-400.0, 10.0, 0.0, false)));
        assert!(t.correct(&loc(-490.0, 0.0, 0.0, true)));
        assert!((t.estimate().translation.x + 490.0).abs() < 1e-9);
        // Drive 100 mm along +x.
        t.measure(Vector2::new(100.0, 0.0), 0.0, 0.0, 0.0);
        t.measure(Vector2::new(100.0, 0.0), 0.0, 0.0, 1.0);
        assert!((t.estimate().translation.x + 390.0).abs() < 1e-6);
        // A measurement 20 mm ahead: half of it is taken; its half-turn twin is ignored.
        assert!(t.correct(&loc(370.0, 0.0, PI, false)));
        assert!(
            (t.estimate().translation.x + 380.0).abs() < 1e-6,
            "{}",
            t.estimate()
        );
        // Far off: rejected.
        assert!(!t.correct(&loc(900.0, 500.0, 0.0, true)));
        assert_eq!(t.fixes(), (2, 1));
    }
}
