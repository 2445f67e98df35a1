//! Velocity-aware avoidance (Sect. 3.2 of the corner paper), from the image; with chosen
//! speeds, a near-field memory supplies where obstacles are inside the camera's blind zone.

use super::goal_direction::check_avoidance;
use crate::boundary::BodyCommand;
use crate::controller::{
    Controller, ControllerEntry, Situation, no_problems, settings, with_surroundings,
};
use crate::near_field::NearField;
use omniloop_control::{AccelLimitedDrive, AvoidanceConfig, SpeedChoice, VelocityAware};

/// The registry's entry.
pub const ENTRY: ControllerEntry = ControllerEntry {
    name: "velocity_aware",
    summary: "velocity-aware avoidance, eq. (8) predicted paths (Sect. 3.2 of the corner paper)",
    table: Some("avoidance"),
    needs_goal: true,
    stages: &["freespace"],
    check_table: check_avoidance,
    check_use: no_problems,
    build: |c| {
        let b = &c.body;
        let drive = AccelLimitedDrive::new(b.accel_limit_mm_s2, b.angular_accel_limit_rad_s2)?;
        let avoid: AvoidanceConfig = settings(c, "avoidance")?;
        Ok(Box::new(VelocityAwareStack {
            near: (avoid.speed == SpeedChoice::Chosen).then(|| NearField::new(b.radius_mm)),
            controller: VelocityAware::new(
                avoid,
                drive,
                b.max_speed_mm_s,
                b.radius_mm,
                c.control_period_s,
            )?,
        }))
    },
};

/// The velocity-aware controller with its near-field memory (chosen speeds only).
pub struct VelocityAwareStack {
    controller: VelocityAware,
    near: Option<NearField>,
}

impl Controller for VelocityAwareStack {
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand {
        let clear = match (&mut self.near, s.freespace) {
            (Some(near), Some(fs)) => Some(near.update(fs, &s.odometry_pose, s.t_s)),
            _ => None,
        };
        let v = s.velocity_body_mm_s;
        let c = &self.controller;
        with_surroundings(s, clear, |sur, target| c.decide(sur, target, v).v_mm_s)
    }
}
