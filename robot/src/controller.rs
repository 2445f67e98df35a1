//! What a controller is: from what the robot perceives and believes to a body-frame velocity
//! command. The controllers themselves, one file each, are registered in
//! [`crate::controllers`].

use crate::RobotError;
use crate::boundary::{ActuatorCommand, ActuatorState, BodyCommand};
use crate::config::{ControlSpec, RobotConfig};
use crate::navigation::{MapSnapshot, NavigationReport};
use crate::near_field::NearSpace;
use crate::percept::{Percept, Percepts};
use crate::traffic::TrafficPoints;
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_control::Surroundings;
use omniloop_problem::{Problem, Problems};
use omniloop_vision::FreeSpace;

/// What a controller decides on.
#[derive(Debug, Clone, Copy)]
pub struct Situation<'a> {
    /// What the perception stages found this cycle, by type: [`Situation::percept`].
    pub percepts: &'a Percepts,
    /// The target relative to the robot (body frame, by the estimate), with a mission.
    pub target_body_mm: Option<Vector2<f64>>,
    /// The target itself (world frame), with a mission and a pose estimate.
    pub target_mm: Option<Point2<f64>>,
    /// The measured body velocity.
    pub velocity_body_mm_s: Vector2<f64>,
    /// The pose estimate (world frame), when the robot has one.
    pub pose: Option<Isometry2<f64>>,
    /// The dead-reckoned pose in the odometry frame.
    pub odometry_pose: Isometry2<f64>,
    /// Time of the cycle, s.
    pub t_s: f64,
    /// The state of the robot's actuators (pan units, the kicker's light barrier).
    pub actuators: &'a [ActuatorState],
}

impl Situation<'_> {
    /// What the stages found of type `T` this cycle (free space, a ground reading, ...), if a
    /// stage the controller reads gave it.
    pub fn percept<T: Percept>(&self) -> Option<&T> {
        self.percepts.get::<T>()
    }
}

/// Chooses the command each cycle.
pub trait Controller: Send {
    /// The command for this cycle.
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand;
    /// Commands to the actuators (kicker, dribbler) after the cycle's decision; default none.
    fn actuators(&mut self) -> Vec<ActuatorCommand> {
        Vec::new()
    }
    /// The move a scripted controller is at (after the cycle's decision), if it follows one.
    fn step(&self) -> Option<usize> {
        None
    }
    /// What its planner did this cycle, if it plans.
    fn navigation(&self) -> Option<&NavigationReport> {
        None
    }
    /// The map its planner built, if it plans.
    fn map(&self) -> Option<MapSnapshot> {
        None
    }
}

/// A settings table of a controller (`[control.NAME]`) and its check, which parses it and
/// names each field at fault.
#[derive(Clone, Copy)]
pub struct ControlTable {
    /// Its name under `[control]`.
    pub name: &'static str,
    /// Parses and checks it.
    pub check: fn(&ControlSpec) -> Vec<Problem>,
}

/// A controller as the registry lists it: a new controller is its own file with one of these
/// and one line in [`crate::controllers::CONTROLLERS`].
pub struct ControllerEntry {
    /// Its name in scenario files (`control.kind`) and in `summary.json`.
    pub name: &'static str,
    /// What it does, in one line, with the paper and section it follows.
    pub summary: &'static str,
    /// Its own tables under `[control]`, if it has settings (controllers alike may share one).
    pub tables: &'static [ControlTable],
    /// Whether it drives to the scenario's `[goal]`, which must then be given.
    pub needs_goal: bool,
    /// The perception stages it reads, by name ([`crate::perception::STAGES`]).
    pub stages: &'static [&'static str],
    /// Checks what it needs of the robot (a camera, a map) when it is the robot's controller.
    pub check_use: fn(&RobotConfig) -> Vec<Problem>,
    /// Builds it for a robot.
    pub build: fn(&RobotConfig) -> Result<Box<dyn Controller>, RobotError>,
}

/// A check that finds nothing (for a controller without a table, or without needs).
pub fn no_problems<T: ?Sized>(_: &T) -> Vec<Problem> {
    Vec::new()
}

/// Parses table `name` of `[control]` and runs `check` on it; either's problems.
pub fn check_table<T: serde::de::DeserializeOwned + Default>(
    spec: &ControlSpec,
    name: &str,
    check: impl FnOnce(&T, &mut Problems),
) -> Vec<Problem> {
    spec.tables.check("control", name, check)
}

/// Parses table `name` of `[control]` as `T`: its problem, if it does not parse.
pub fn parses<T: serde::de::DeserializeOwned + Default>(
    spec: &ControlSpec,
    name: &str,
) -> Vec<Problem> {
    spec.table::<T>(name).err().into_iter().collect()
}

/// The settings table `name` of a robot's `[control]`, as a build error when it does not parse.
pub fn settings<T: serde::de::DeserializeOwned + Default>(
    config: &RobotConfig,
    name: &str,
) -> Result<T, RobotError> {
    Ok(config.control.table(name)?)
}

/// Runs `f` on the surroundings vision reported (with `near` as the surely free boundary, when
/// given, else the free space's own; with `traffic`'s moving obstacles and horizon for the
/// traffic rule) and the target, or stops without either.
pub fn with_surroundings(
    s: &Situation<'_>,
    near: Option<NearSpace>,
    traffic: Option<&TrafficPoints>,
    f: impl FnOnce(&Surroundings<'_>, Vector2<f64>) -> Vector2<f64>,
) -> BodyCommand {
    let (Some(fs), Some(target)) = (s.percept::<FreeSpace>(), s.target_body_mm) else {
        return BodyCommand::STOP;
    };
    let coords =
        |pts: &[Point2<f64>]| -> Vec<Vector2<f64>> { pts.iter().map(|p| p.coords).collect() };
    let obstacles = coords(&fs.obstacle_points);
    let near = near.unwrap_or_else(|| NearSpace {
        clear: coords(&fs.clear_points),
        blind: Vec::new(),
    });
    let none = TrafficPoints::default();
    let traffic = traffic.unwrap_or(&none);
    let surroundings = Surroundings {
        direction_rad: &fs.direction_rad,
        free_mm: &fs.free_mm,
        range_mm: fs.range_mm,
        obstacle_points: &obstacles,
        clear_points: &near.clear,
        blind_points: &near.blind,
        moving_points: &traffic.moving,
        horizon_points: &traffic.horizon,
    };
    BodyCommand::translate(f(&surroundings, target))
}
