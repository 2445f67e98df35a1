//! The robot's wheel odometry as a sensor: the true body velocity and rotation rate with the
//! encoders' systematic errors and seeded Gaussian noise, drawn on the simulator's side.

use crate::scenario::OdometrySpec;
use nalgebra::{Rotation2, Vector2};
use omniloop_robot::OdometryReading;
use omniloop_sim::RobotState;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;

/// Makes the readings of one robot's wheel encoders.
#[derive(Debug)]
pub struct WheelOdometry {
    spec: OdometrySpec,
    rng: StdRng,
    /// The true body-frame velocity of the last reading (for the slip).
    last_v_body: Option<Vector2<f64>>,
}

impl WheelOdometry {
    /// Encoders with the errors of `spec`, their noise drawn from the run's `seed`.
    pub fn new(spec: &OdometrySpec, seed: u64) -> Self {
        Self {
            spec: spec.clone(),
            rng: StdRng::seed_from_u64(seed ^ 0x0D0_3E7E_u64),
            last_v_body: None,
        }
    }

    /// The reading after `dt_s` that ended in `state` (true velocity in the world frame):
    /// measured in the body frame, scaled by `1 + scale_bias_frac`, each component with
    /// relative noise `speed_noise_frac`, the rotation rate with bias and noise; with slip,
    /// the wheels read `slip_s` times the body's acceleration over the period more.
    pub fn read(&mut self, state: &RobotState, dt_s: f64) -> OdometryReading {
        let s = &self.spec;
        let heading = state.pose.rotation.angle();
        let true_body = Rotation2::new(-heading) * state.velocity_mm_s;
        let accel = match self.last_v_body.replace(true_body) {
            Some(before) if dt_s > 0.0 => (true_body - before) / dt_s,
            _ => Vector2::zeros(),
        };
        let v_body = (true_body + accel * s.slip_s) * (1.0 + s.scale_bias_frac);
        let mut n = || self.rng.sample::<f64, _>(StandardNormal);
        let noisy = Vector2::new(
            v_body.x * (1.0 + s.speed_noise_frac * n()),
            v_body.y * (1.0 + s.speed_noise_frac * n()),
        );
        let omega = state.omega_rad_s + s.omega_bias_rad_s + s.omega_noise_rad_s * n();
        OdometryReading {
            v_body_mm_s: noisy,
            omega_rad_s: omega,
            dt_s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Isometry2;

    #[test]
    fn readings_carry_the_bias_in_the_body_frame_and_repeat_with_the_seed() {
        let spec = OdometrySpec {
            speed_noise_frac: 0.0,
            omega_noise_rad_s: 0.0,
            scale_bias_frac: 0.1,
            omega_bias_rad_s: 0.02,
            slip_s: 0.0,
        };
        let state = RobotState {
            pose: Isometry2::new(Vector2::zeros(), std::f64::consts::FRAC_PI_2),
            velocity_mm_s: Vector2::new(0.0, 200.0),
            omega_rad_s: 0.0,
        };
        let r = WheelOdometry::new(&spec, 3).read(&state, 0.04);
        // Moving along world +y while facing +y is moving forward, 10% over-read.
        assert!(
            (r.v_body_mm_s - Vector2::new(220.0, 0.0)).norm() < 1e-9,
            "{r:?}"
        );
        assert!((r.omega_rad_s - 0.02).abs() < 1e-12);
        let noisy = OdometrySpec::default();
        let a = WheelOdometry::new(&noisy, 5).read(&state, 0.04);
        let b = WheelOdometry::new(&noisy, 5).read(&state, 0.04);
        let c = WheelOdometry::new(&noisy, 6).read(&state, 0.04);
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn slip_reads_more_while_the_robot_accelerates() {
        let spec = OdometrySpec {
            speed_noise_frac: 0.0,
            slip_s: 0.1,
            ..OdometrySpec::default()
        };
        let mut wheels = WheelOdometry::new(&spec, 1);
        let at = |v: f64| RobotState {
            pose: Isometry2::new(Vector2::zeros(), 0.0),
            velocity_mm_s: Vector2::new(v, 0.0),
            omega_rad_s: 0.0,
        };
        assert_eq!(wheels.read(&at(0.0), 0.04).v_body_mm_s.x, 0.0);
        // 300 mm/s^2 over the period: 30 mm/s more than the body's 12 mm/s.
        let r = wheels.read(&at(12.0), 0.04);
        assert!((r.v_body_mm_s.x - 42.0).abs() < 1e-9, "{r:?}");
        // At constant speed, none.
        assert!((wheels.read(&at(12.0), 0.04).v_body_mm_s.x - 12.0).abs() < 1e-9);
    }
}
