//! Controllers: from what the robot perceives and believes to a body-frame velocity command.

use crate::RobotError;
use crate::boundary::BodyCommand;
use crate::config::{ControllerKind, RobotConfig};
use crate::estimates::GroundReading;
use crate::forward_drive;
use crate::near_field::{NearField, NearSpace};
use crate::wander::Wander;
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_control::{
    AccelLimitedDrive, GoalDirection, SpeedChoice, Surroundings, VelocityAware,
};
use omniloop_vision::FreeSpace;
use omniloop_vision::forward::FlowBalance;

/// What a controller decides on.
#[derive(Debug, Clone, Copy)]
pub struct Situation<'a> {
    /// Free space around the robot, when perceived this cycle.
    pub freespace: Option<&'a FreeSpace>,
    /// The target relative to the robot (body frame, by the estimate), with a mission.
    pub target_body_mm: Option<Vector2<f64>>,
    /// The measured body velocity.
    pub velocity_body_mm_s: Vector2<f64>,
    /// The pose estimate (world frame), when the robot has one.
    pub pose: Option<Isometry2<f64>>,
    /// The dead-reckoned pose in the odometry frame.
    pub odometry_pose: Isometry2<f64>,
    /// A point perception asks the robot to drive to (odometry frame).
    pub observation_point: Option<Point2<f64>>,
    /// A forward camera's ground segmentation, when perceived this cycle.
    pub ground: Option<&'a GroundReading>,
    /// A forward camera's flow balance, when perceived this cycle.
    pub flow: Option<FlowBalance>,
    /// Time of the cycle, s.
    pub t_s: f64,
}

/// Chooses the command each cycle.
pub trait Controller: Send {
    /// The command for this cycle.
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand;
    /// The move a scripted controller is at (after the cycle's decision), if it follows one.
    fn step(&self) -> Option<usize> {
        None
    }
}

/// The controller a configuration names.
pub fn build(config: &RobotConfig) -> Result<Box<dyn Controller>, RobotError> {
    let b = &config.body;
    let drive = AccelLimitedDrive::new(b.accel_limit_mm_s2, b.angular_accel_limit_rad_s2)?;
    let avoid = config.control.avoidance.clone();
    Ok(match config.control.kind {
        // The truth pilot is the simulator's; the robot's own controller stays idle.
        ControllerKind::Idle | ControllerKind::GoToGoalTruth => Box::new(Idle),
        ControllerKind::GoalDirection => Box::new(GoalDirection::new(
            avoid,
            drive,
            b.max_speed_mm_s,
            b.radius_mm,
        )?),
        ControllerKind::VelocityAware => Box::new(VelocityAwareStack {
            near: (avoid.speed == SpeedChoice::Chosen).then(|| NearField::new(b.radius_mm)),
            controller: VelocityAware::new(
                avoid,
                drive,
                b.max_speed_mm_s,
                b.radius_mm,
                config.control_period_s,
            )?,
        }),
        ControllerKind::Wander => Box::new(Wander::new(config)?),
        ControllerKind::Segmentation => Box::new(forward_drive::Segmentation::new(config)),
        ControllerKind::OpticalFlow => Box::new(forward_drive::FlowAvoidance::new(config)),
        ControllerKind::Script => Box::new(forward_drive::Script::new(config)),
        ControllerKind::Observe => Box::new(Observe {
            max_speed_mm_s: b.max_speed_mm_s,
            accel_limit_mm_s2: b.accel_limit_mm_s2,
            period_s: config.control_period_s,
        }),
    })
}

/// Stands still, or drives straight to the observation point perception asks for, arriving at
/// rest: the speed is the one from which the acceleration limit stops the robot over the
/// distance left (less one period's travel), capped at the top speed.
struct Observe {
    max_speed_mm_s: f64,
    accel_limit_mm_s2: f64,
    period_s: f64,
}

impl Controller for Observe {
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand {
        let Some(target) = s.observation_point else {
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

/// Stands still.
struct Idle;

impl Controller for Idle {
    fn decide(&mut self, _: &Situation<'_>) -> BodyCommand {
        BodyCommand::STOP
    }
}

/// Runs `f` on the surroundings vision reported (with `near` as the surely free boundary, when
/// given) and the target, or stops without either.
fn with_surroundings(
    s: &Situation<'_>,
    near: Option<NearSpace>,
    f: impl FnOnce(&Surroundings<'_>, Vector2<f64>) -> Vector2<f64>,
) -> BodyCommand {
    let (Some(fs), Some(target)) = (s.freespace, s.target_body_mm) else {
        return BodyCommand::STOP;
    };
    let coords = |pts: &[nalgebra::Point2<f64>]| -> Vec<Vector2<f64>> {
        pts.iter().map(|p| p.coords).collect()
    };
    let obstacles = coords(&fs.obstacle_points);
    let near = near.unwrap_or_else(|| NearSpace {
        clear: coords(&fs.clear_points),
        blind: Vec::new(),
    });
    let surroundings = Surroundings {
        direction_rad: &fs.direction_rad,
        free_mm: &fs.free_mm,
        range_mm: fs.range_mm,
        obstacle_points: &obstacles,
        clear_points: &near.clear,
        blind_points: &near.blind,
    };
    BodyCommand::translate(f(&surroundings, target))
}

impl Controller for GoalDirection {
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand {
        with_surroundings(s, None, |sur, target| {
            GoalDirection::decide(self, sur, target).v_mm_s
        })
    }
}

/// The velocity-aware controller; with chosen speeds, its near-field memory supplies where
/// obstacles are inside the camera's blind zone.
struct VelocityAwareStack {
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
