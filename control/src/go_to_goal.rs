//! A plain go-to-point controller: head straight for the goal and brake so as to stop on it.
//!
//! It is the reference controller that closes the loop before any estimator exists: given a
//! pose (the truth in simulation, an estimate otherwise) it commands the velocity toward the
//! goal, capped by the speed from which the drive can still stop in the remaining distance,
//! `v = min(v_max, sqrt(2 alpha d))`.

use crate::{AccelLimitedDrive, ControlError, Vec2, VelocityCommand, require_positive};

/// Drives straight to a goal point.
#[derive(Debug, Clone, Copy)]
pub struct GoToGoal {
    max_speed_mm_s: f64,
    drive: AccelLimitedDrive,
}

impl GoToGoal {
    /// A controller with the robot's top speed and drive model.
    pub fn new(max_speed_mm_s: f64, drive: AccelLimitedDrive) -> Result<Self, ControlError> {
        Ok(Self {
            max_speed_mm_s: require_positive("max_speed_mm_s", max_speed_mm_s)?,
            drive,
        })
    }

    /// The command (world frame) for a robot at `position` heading for `goal`.
    pub fn command(&self, position: Vec2, goal: Vec2) -> VelocityCommand {
        let to_goal = goal - position;
        let d = to_goal.norm();
        if d < 1e-6 {
            return VelocityCommand::STOP;
        }
        let braking = (2.0 * self.drive.accel_limit_mm_s2() * d).sqrt();
        let speed = self.max_speed_mm_s.min(braking);
        VelocityCommand::translate(to_goal * (speed / d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brakes_near_the_goal() {
        let drive = AccelLimitedDrive::new(300.0, 10.0).unwrap();
        let c = GoToGoal::new(400.0, drive).unwrap();
        let far = c.command(Vec2::zeros(), Vec2::new(2000.0, 0.0));
        assert!((far.v_mm_s - Vec2::new(400.0, 0.0)).norm() < 1e-9);
        let near = c.command(Vec2::zeros(), Vec2::new(0.0, 60.0));
        assert!((near.v_mm_s.norm() - (2.0f64 * 300.0 * 60.0).sqrt()).abs() < 1e-9);
        assert_eq!(
            c.command(Vec2::new(5.0, 5.0), Vec2::new(5.0, 5.0)),
            VelocityCommand::STOP
        );
    }
}
