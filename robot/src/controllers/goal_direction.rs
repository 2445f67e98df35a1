//! The free direction closest to the goal's, from the image (ref. [4] of the corner paper),
//! with the settings it shares with the velocity-aware controller (`[control.avoidance]`).

use crate::boundary::BodyCommand;
use crate::config::ControlSpec;
use crate::controller::{
    ControlTable, Controller, ControllerEntry, Situation, check_table, no_problems, settings,
    with_surroundings,
};
use omniloop_control::{AccelLimitedDrive, AvoidanceConfig, GoalDirection, SpeedChoice};
use omniloop_problem::{Problem, Problems};

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
    stages: &[crate::perception::freespace::NAME],
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
pub fn check_avoidance(spec: &ControlSpec) -> Vec<Problem> {
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
            let t = &a.traffic;
            p.non_negative("traffic.gap_mm", t.gap_mm);
            p.non_negative("traffic.moved_s", t.moved_s);
            p.non_negative("traffic.yield_mm", t.yield_mm);
            if !(t.keep_right_deg.is_finite() && (0.0..=90.0).contains(&t.keep_right_deg)) {
                p.fail(
                    "traffic.keep_right_deg",
                    format!("must lie in [0, 90] (got {})", t.keep_right_deg),
                );
            }
            if !(t.look_ahead_mm.is_finite() && t.look_ahead_mm > t.gap_mm) {
                p.fail(
                    "traffic.look_ahead_mm",
                    format!(
                        "must be finite and > traffic.gap_mm = {} (got {})",
                        t.gap_mm, t.look_ahead_mm
                    ),
                );
            }
            if t.reciprocal() && a.speed != SpeedChoice::Chosen {
                p.fail(
                    "traffic.rule",
                    "\"reciprocal\" bounds the chosen speeds: it needs speed = \"chosen\"",
                );
            }
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
