//! Dead reckoning: the robot's pose in its start frame from its measured body velocity.

use crate::Vec2;
use nalgebra::{Isometry2, Rotation2, Vector2};

/// Integrates body-frame velocity measurements into a pose in the start frame.
#[derive(Debug, Clone, PartialEq)]
pub struct DeadReckoning {
    position_mm: Vec2,
    heading_rad: f64,
    last_v_body_mm_s: Vec2,
    last_omega_rad_s: f64,
}

impl Default for DeadReckoning {
    fn default() -> Self {
        Self::new()
    }
}

impl DeadReckoning {
    /// Starts at the origin of the start frame, at rest.
    pub fn new() -> Self {
        Self {
            position_mm: Vec2::zeros(),
            heading_rad: 0.0,
            last_v_body_mm_s: Vec2::zeros(),
            last_omega_rad_s: 0.0,
        }
    }

    /// Takes a measurement `dt` after the previous one: body velocity and rotation rate,
    /// integrated with the trapezoidal rule.
    pub fn update(&mut self, v_body_mm_s: Vec2, omega_rad_s: f64, dt_s: f64) {
        let h0 = self.heading_rad;
        let h1 = h0 + 0.5 * (self.last_omega_rad_s + omega_rad_s) * dt_s;
        let v0 = Rotation2::new(h0) * self.last_v_body_mm_s;
        let v1 = Rotation2::new(h1) * v_body_mm_s;
        self.position_mm += (v0 + v1) * (0.5 * dt_s);
        self.heading_rad = h1;
        self.last_v_body_mm_s = v_body_mm_s;
        self.last_omega_rad_s = omega_rad_s;
    }

    /// The pose in the start frame.
    pub fn pose(&self) -> Isometry2<f64> {
        Isometry2::new(
            Vector2::new(self.position_mm.x, self.position_mm.y),
            self.heading_rad,
        )
    }

    /// The last measured body velocity.
    pub fn velocity_body_mm_s(&self) -> Vec2 {
        self.last_v_body_mm_s
    }

    /// A point of the start frame in the robot's body frame.
    pub fn to_body(&self, p_start: Vec2) -> Vec2 {
        Rotation2::new(-self.heading_rad) * (p_start - self.position_mm)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_a_turning_robot() {
        let mut d = DeadReckoning::new();
        // Constant body velocity 100 mm/s forward while turning at 0.5 rad/s: a circle of
        // radius 200 mm; after 2 pi seconds the robot is at (0, 400) facing backward.
        let n = 10_000;
        let dt = std::f64::consts::TAU / n as f64;
        d.update(Vec2::new(100.0, 0.0), 0.5, 0.0);
        for _ in 0..n {
            d.update(Vec2::new(100.0, 0.0), 0.5, dt);
        }
        let p = d.pose();
        assert!((p.translation.x).abs() < 0.01, "{p:?}");
        assert!((p.translation.y - 400.0).abs() < 0.01, "{p:?}");
        assert!((p.rotation.angle().abs() - std::f64::consts::FRAC_PI_2 * 2.0).abs() < 1e-6);
        let b = d.to_body(Vec2::new(0.0, 300.0));
        // 100 mm toward -y in the world is to the left of a robot facing -x.
        assert!((b - Vec2::new(0.0, 100.0)).norm() < 0.02, "{b:?}");
    }
}
