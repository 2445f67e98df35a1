//! The free direction closest to the goal's, from the image (ref. [4] of the corner paper),
//! with the settings it shares with the velocity-aware controller (`[control.avoidance]`).

use crate::boundary::BodyCommand;
use crate::config::ControlSpec;
use crate::controller::{
    ControlTable, Controller, ControllerEntry, Situation, check_table, no_problems, settings,
    with_surroundings,
};
use crate::tables::{ConfigProblem, Problems};
use omniloop_control::{AccelLimitedDrive, AvoidanceConfig, GoalDirection};

/// The registry's entry.
pub const ENTRY: ControllerEntry = ControllerEntry {
    name: "goal_direction",
    summary: "the free direction closest to the goal's, from the image (ref. [4] of the corner \
              paper)",
    tables: &[ControlTable {
        name: "avoidance",
        check: check_avoidance,
    }],
    needs_goal: true,
    stages: &["freespace"],
    check_use: no_problems,
    build: |c| {
        let b = &c.body;
        let drive = AccelLimitedDrive::new(b.accel_limit_mm_s2, b.angular_accel_limit_rad_s2)?;
        let avoid: AvoidanceConfig = settings(c, "avoidance")?;
        Ok(Box::new(GoalDirectionController(GoalDirection::new(
            avoid,
            drive,
            b.max_speed_mm_s,
            b.radius_mm,
        )?)))
    },
};

/// Parses and checks `[control.avoidance]`.
pub fn check_avoidance(spec: &ControlSpec) -> Vec<ConfigProblem> {
    check_table(
        spec,
        "avoidance",
        |a: &AvoidanceConfig, p: &mut Problems| {
            p.non_negative("margin_mm", a.margin_mm);
            p.positive("free_distance_mm", a.free_distance_mm);
            p.positive("prediction_step_s", a.prediction_step_s);
            if a.candidates < 4 {
                p.fail("candidates", format!("must be >= 4 (got {})", a.candidates));
            }
            p.non_negative("extra_horizon_s", a.extra_horizon_s);
        },
    )
}

/// The goal-direction controller on the cycle's free space.
pub struct GoalDirectionController(GoalDirection);

impl Controller for GoalDirectionController {
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand {
        with_surroundings(s, None, None, |sur, target| {
            self.0.decide(sur, target).v_mm_s
        })
    }
}
