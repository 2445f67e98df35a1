//! The drive of a small differential-drive robot: two wheels on one axle, so it moves along its
//! heading and turns on the spot, never sideways.
//!
//! A body command `(v, omega)` asks the left and right wheels for `v -/+ omega b / 2` (`b` the
//! track). A command beyond the wheels' top speed or the turn-rate limit is scaled down as a
//! whole, keeping the curvature `omega / v` the controller chose; the forward speed and the turn
//! rate then follow it at their acceleration limits, like the omnidirectional drive of eq. (8).

use crate::{ControlError, require_positive};

/// Limits of a differential drive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DifferentialDrive {
    track_mm: f64,
    max_wheel_speed_mm_s: f64,
    max_turn_rate_rad_s: f64,
    accel_limit_mm_s2: f64,
    angular_accel_limit_rad_s2: f64,
}

impl DifferentialDrive {
    /// A drive with wheel track `b`, top wheel speed, top turn rate and acceleration limits.
    pub fn new(
        track_mm: f64,
        max_wheel_speed_mm_s: f64,
        max_turn_rate_rad_s: f64,
        accel_limit_mm_s2: f64,
        angular_accel_limit_rad_s2: f64,
    ) -> Result<Self, ControlError> {
        Ok(Self {
            track_mm: require_positive("track_mm", track_mm)?,
            max_wheel_speed_mm_s: require_positive("max_wheel_speed_mm_s", max_wheel_speed_mm_s)?,
            max_turn_rate_rad_s: require_positive("max_turn_rate_rad_s", max_turn_rate_rad_s)?,
            accel_limit_mm_s2: require_positive("accel_limit_mm_s2", accel_limit_mm_s2)?,
            angular_accel_limit_rad_s2: require_positive(
                "angular_accel_limit_rad_s2",
                angular_accel_limit_rad_s2,
            )?,
        })
    }

    /// Top turn rate, rad/s.
    pub fn max_turn_rate_rad_s(&self) -> f64 {
        self.max_turn_rate_rad_s
    }

    /// Top forward speed, mm/s.
    pub fn max_speed_mm_s(&self) -> f64 {
        self.max_wheel_speed_mm_s
    }

    /// Left and right wheel speeds of a body command, mm/s.
    pub fn wheel_speeds(&self, v_mm_s: f64, omega_rad_s: f64) -> (f64, f64) {
        let half = 0.5 * omega_rad_s * self.track_mm;
        (v_mm_s - half, v_mm_s + half)
    }

    /// The command the wheels can follow: `(v, omega)` scaled down as a whole until neither
    /// wheel exceeds its top speed and the turn rate its limit.
    pub fn limit(&self, v_mm_s: f64, omega_rad_s: f64) -> (f64, f64) {
        let (l, r) = self.wheel_speeds(v_mm_s, omega_rad_s);
        let wheel = l.abs().max(r.abs()) / self.max_wheel_speed_mm_s;
        let turn = omega_rad_s.abs() / self.max_turn_rate_rad_s;
        let k = wheel.max(turn).max(1.0);
        (v_mm_s / k, omega_rad_s / k)
    }

    /// One step of length `dt` from `(v, omega)` toward the (limited) command: each changes by
    /// at most its acceleration limit times `dt`.
    pub fn step(
        &self,
        v_mm_s: f64,
        omega_rad_s: f64,
        command: (f64, f64),
        dt_s: f64,
    ) -> (f64, f64) {
        let (v_b, w_b) = self.limit(command.0, command.1);
        let dv = self.accel_limit_mm_s2 * dt_s;
        let dw = self.angular_accel_limit_rad_s2 * dt_s;
        (
            v_mm_s + (v_b - v_mm_s).clamp(-dv, dv),
            omega_rad_s + (w_b - omega_rad_s).clamp(-dw, dw),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drive() -> DifferentialDrive {
        DifferentialDrive::new(100.0, 200.0, 90f64.to_radians(), 1000.0, 20.0).unwrap()
    }

    #[test]
    fn rejects_non_positive_limits() {
        assert!(DifferentialDrive::new(0.0, 200.0, 1.0, 1.0, 1.0).is_err());
        assert!(DifferentialDrive::new(100.0, 200.0, f64::NAN, 1.0, 1.0).is_err());
    }

    #[test]
    fn a_command_beyond_the_wheels_keeps_its_curvature() {
        let d = drive();
        // 300 mm/s with 1 rad/s: wheels at 250 and 350 mm/s; the faster one is cut to 200.
        let (v, w) = d.limit(300.0, 1.0);
        assert!((w / v - 1.0 / 300.0).abs() < 1e-12);
        let (l, r) = d.wheel_speeds(v, w);
        assert!((l.abs().max(r.abs()) - 200.0).abs() < 1e-9);
        // On the spot, the turn-rate limit binds: 3 rad/s -> 90 deg/s.
        let (v, w) = d.limit(0.0, 3.0);
        assert_eq!(v, 0.0);
        assert!((w - 90f64.to_radians()).abs() < 1e-12);
        // A command within the limits is kept.
        assert_eq!(d.limit(100.0, 0.5), (100.0, 0.5));
    }

    #[test]
    fn speed_and_turn_rate_follow_at_their_limits() {
        let d = drive();
        let (mut v, mut w) = (0.0, 0.0);
        for _ in 0..50 {
            (v, w) = d.step(v, w, (150.0, 0.0), 0.002);
        }
        // 1000 mm/s^2 for 0.1 s.
        assert!((v - 100.0).abs() < 1e-9);
        for _ in 0..100 {
            (v, w) = d.step(v, w, (0.0, 1.0), 0.002);
        }
        assert_eq!(v, 0.0);
        assert!((w - 1.0).abs() < 1e-9);
    }
}
