//! The acceleration-limited velocity response of the omnidirectional drive.
//!
//! Eq. (8), Sect. 3.2 of Sekimori et al., "High-speed obstacle avoidance and self-localization
//! for mobile robots based on omni-directional imaging of floor region": when the command
//! `v_b` arrives while the robot moves at `v_a`, the velocity moves along the straight line from
//! `v_a` to `v_b` at the constant rate `alpha`:
//!
//! ```text
//! v_r(t) = v_a + (dv / |dv|) * alpha * t    (t <= t_a)
//! v_r(t) = v_b                              (t >  t_a),   t_a = |dv| / alpha,  dv = v_b - v_a
//! ```
//!
//! The simulator applies the command through [`AccelLimitedDrive::step`]; controllers predict
//! trajectories with [`AccelLimitedDrive::velocity_at`] and [`AccelLimitedDrive::displacement`],
//! the very same model.

use crate::{ControlError, Vec2, require_positive};
use serde::{Deserialize, Serialize};

/// A velocity command for an omnidirectional robot, in the world (or odometry) frame.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct VelocityCommand {
    /// Translational velocity, mm/s.
    pub v_mm_s: Vec2,
    /// Rotation rate, rad/s (counter-clockwise positive).
    pub omega_rad_s: f64,
}

impl VelocityCommand {
    /// Stand still.
    pub const STOP: Self = Self {
        v_mm_s: Vec2::new(0.0, 0.0),
        omega_rad_s: 0.0,
    };

    /// A pure translation.
    pub fn translate(v_mm_s: Vec2) -> Self {
        Self {
            v_mm_s,
            omega_rad_s: 0.0,
        }
    }
}

/// The drive model of eq. (8): translational acceleration limited to `alpha` along the straight
/// line from the current to the commanded velocity, rotation rate limited the same way.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AccelLimitedDrive {
    accel_limit_mm_s2: f64,
    angular_accel_limit_rad_s2: f64,
}

impl AccelLimitedDrive {
    /// A drive with translational limit `alpha` (mm/s^2) and rotational limit (rad/s^2).
    pub fn new(
        accel_limit_mm_s2: f64,
        angular_accel_limit_rad_s2: f64,
    ) -> Result<Self, ControlError> {
        Ok(Self {
            accel_limit_mm_s2: require_positive("accel_limit_mm_s2", accel_limit_mm_s2)?,
            angular_accel_limit_rad_s2: require_positive(
                "angular_accel_limit_rad_s2",
                angular_accel_limit_rad_s2,
            )?,
        })
    }

    /// alpha, mm/s^2.
    pub fn accel_limit_mm_s2(&self) -> f64 {
        self.accel_limit_mm_s2
    }

    /// Angular acceleration limit, rad/s^2.
    pub fn angular_accel_limit_rad_s2(&self) -> f64 {
        self.angular_accel_limit_rad_s2
    }

    /// t_a = |v_b - v_a| / alpha: how long the velocity takes to reach the command (Eq. (8)).
    pub fn settle_time_s(&self, v_a: Vec2, v_b: Vec2) -> f64 {
        (v_b - v_a).norm() / self.accel_limit_mm_s2
    }

    /// v_r(t) of Eq. (8): the velocity `t` seconds after the command `v_b` was received at
    /// velocity `v_a`.
    pub fn velocity_at(&self, v_a: Vec2, v_b: Vec2, t_s: f64) -> Vec2 {
        let dv = v_b - v_a;
        let n = dv.norm();
        let t_a = n / self.accel_limit_mm_s2;
        if t_s >= t_a || n == 0.0 {
            v_b
        } else {
            v_a + dv * (self.accel_limit_mm_s2 * t_s / n)
        }
    }

    /// The displacement (mm) after `t` seconds: the integral of Eq. (8) in closed form,
    /// `v_a t + (dv/|dv|) alpha t^2 / 2` while accelerating, then straight at `v_b`.
    pub fn displacement(&self, v_a: Vec2, v_b: Vec2, t_s: f64) -> Vec2 {
        let dv = v_b - v_a;
        let n = dv.norm();
        if n == 0.0 {
            return v_a * t_s;
        }
        let t_a = n / self.accel_limit_mm_s2;
        let dir = dv / n;
        if t_s <= t_a {
            v_a * t_s + dir * (0.5 * self.accel_limit_mm_s2 * t_s * t_s)
        } else {
            v_a * t_a + dir * (0.5 * self.accel_limit_mm_s2 * t_a * t_a) + v_b * (t_s - t_a)
        }
    }

    /// One step of length `dt` from velocity `v` toward the command `v_b`: the velocity changes
    /// by at most `alpha * dt`, along `v_b - v` (the discrete form of Eq. (8)).
    pub fn step(&self, v: Vec2, v_b: Vec2, dt_s: f64) -> Vec2 {
        self.velocity_at(v, v_b, dt_s)
    }

    /// One step of the rotation rate toward `omega_b`, changing it by at most the angular limit
    /// times `dt`.
    pub fn step_angular(&self, omega: f64, omega_b: f64, dt_s: f64) -> f64 {
        let max = self.angular_accel_limit_rad_s2 * dt_s;
        omega + (omega_b - omega).clamp(-max, max)
    }

    /// The distance (mm) needed to stop from `speed` at the acceleration limit, `v^2 / (2 alpha)`.
    pub fn stopping_distance_mm(&self, speed_mm_s: f64) -> f64 {
        speed_mm_s * speed_mm_s / (2.0 * self.accel_limit_mm_s2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drive() -> AccelLimitedDrive {
        AccelLimitedDrive::new(300.0, 10.0).unwrap()
    }

    #[test]
    fn rejects_non_positive_limits() {
        assert!(AccelLimitedDrive::new(0.0, 1.0).is_err());
        assert!(AccelLimitedDrive::new(300.0, -1.0).is_err());
        assert!(AccelLimitedDrive::new(f64::NAN, 1.0).is_err());
    }

    #[test]
    fn velocity_follows_straight_line_at_alpha() {
        let d = drive();
        let v_a = Vec2::new(400.0, 0.0);
        let v_b = Vec2::new(-229.4, 327.7); // 400 mm/s at 125 degrees
        let t_a = d.settle_time_s(v_a, v_b);
        // Closed form: t_a = |dv| / alpha.
        assert!((t_a - (v_b - v_a).norm() / 300.0).abs() < 1e-12);
        for k in 0..=50 {
            let t = t_a * k as f64 / 40.0;
            let v = d.velocity_at(v_a, v_b, t);
            if t <= t_a {
                // On the segment from v_a to v_b, at distance alpha t from v_a.
                assert!(((v - v_a).norm() - 300.0 * t).abs() < 1e-9);
                let cross = (v - v_a).perp(&(v_b - v_a));
                assert!(cross.abs() < 1e-6);
            } else {
                assert_eq!(v, v_b);
            }
        }
    }

    #[test]
    fn stepping_matches_closed_form_profile_and_displacement() {
        let d = drive();
        let v_a = Vec2::new(350.0, -100.0);
        let v_b = Vec2::new(-200.0, 300.0);
        let dt = 0.001;
        let mut v = v_a;
        let mut p = Vec2::zeros();
        let mut t = 0.0;
        let mut max_accel: f64 = 0.0;
        for _ in 0..4000 {
            let v_next = d.step(v, v_b, dt);
            max_accel = max_accel.max((v_next - v).norm() / dt);
            // Trapezoidal integration is exact for a piecewise-linear velocity whose kink falls
            // inside one step up to O(dt^2).
            p += (v + v_next) * (0.5 * dt);
            v = v_next;
            t += dt;
            let v_closed = d.velocity_at(v_a, v_b, t);
            assert!(
                (v - v_closed).norm() < 1e-6,
                "t = {t}: {v:?} vs {v_closed:?}"
            );
        }
        let p_closed = d.displacement(v_a, v_b, t);
        assert!((p - p_closed).norm() < 1e-3, "{p:?} vs {p_closed:?}");
        assert!(max_accel <= 300.0 * (1.0 + 1e-9));
    }

    #[test]
    fn displacement_is_continuous_at_settle_time() {
        let d = drive();
        let v_a = Vec2::new(0.0, 0.0);
        let v_b = Vec2::new(400.0, 0.0);
        let t_a = d.settle_time_s(v_a, v_b);
        let before = d.displacement(v_a, v_b, t_a - 1e-9);
        let after = d.displacement(v_a, v_b, t_a + 1e-9);
        assert!((before - after).norm() < 1e-5);
        // From rest: x = alpha t_a^2 / 2 = v^2 / (2 alpha).
        assert!((d.displacement(v_a, v_b, t_a).x - 400.0 * 400.0 / 600.0).abs() < 1e-9);
        assert!((d.stopping_distance_mm(400.0) - 266.666_666_666_666_7).abs() < 1e-9);
    }

    #[test]
    fn angular_rate_is_limited() {
        let d = drive();
        assert_eq!(d.step_angular(0.0, 5.0, 0.01), 0.1);
        assert_eq!(d.step_angular(1.0, 1.05, 0.01), 1.05);
        assert_eq!(d.step_angular(0.0, -5.0, 0.01), -0.1);
    }
}
