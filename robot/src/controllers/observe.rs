//! Stand still while the cameras search, and drive to the observation points perception asks
//! for (E5's "change the observation point by making a move", Fig. 4 of the resection paper).

use crate::boundary::BodyCommand;
use crate::controller::{Controller, ControllerEntry, Situation, no_problems};
use crate::perception::ObservationPoint;

/// The registry's entry.
pub const ENTRY: ControllerEntry = ControllerEntry {
    name: "observe",
    summary: "stand still while the cameras search; drive to the observation points perception \
              asks for (E5, Fig. 4)",
    tables: &[],
    needs_goal: false,
    stages: &[],
    check_use: no_problems,
    build: |c| {
        Ok(Box::new(Observe {
            max_speed_mm_s: c.body.max_speed_mm_s,
            accel_limit_mm_s2: c.body.accel_limit_mm_s2,
            period_s: c.control_period_s,
        }))
    },
};

/// Stands still, or drives straight to the observation point perception asks for, arriving at
/// rest: the speed is the one from which the acceleration limit stops the robot over the
/// distance left (less one period's travel), capped at the top speed.
pub struct Observe {
    max_speed_mm_s: f64,
    accel_limit_mm_s2: f64,
    period_s: f64,
}

impl Controller for Observe {
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand {
        let Some(&ObservationPoint(target)) = s.percept::<ObservationPoint>() else {
            return BodyCommand::STOP;
        };
        let to = s.odometry_pose.inverse_transform_point(&target).coords;
        let d = to.norm();
        if d < 1.0 {
            return BodyCommand::STOP;
        }
        let a = self.accel_limit_mm_s2;
        let t = self.period_s;
        // v with v t + v^2 / (2 a) = d: the robot can still stop in what is left after a cycle.
        let v = (-a * t + ((a * t).powi(2) + 2.0 * a * d).sqrt()).min(self.max_speed_mm_s);
        BodyCommand::translate(to * (v / d))
    }
}
