//! omniloop-robot: the robot's software, behind the boundary a real robot has.
//!
//! The robot's software is anything that implements [`RobotSoftware`]; [`Robot`], the
//! built-in stack, is one. Each control cycle it receives what its own sensors give and nothing else
//! ([`Observation`]: camera frames by sensor name with their time, the state of its actuators;
//! [`OdometryReading`]: what the wheel encoders measured over the last period), and returns a
//! body-frame velocity command, actuator commands and what it believes ([`Outputs`],
//! [`Estimates`]). It never sees the world it drives in: the same stack runs on a simulated
//! robot and on recorded or live images of a real one.
//!
//! Inside, the stack is built from a [`RobotConfig`]:
//! - perception stages ([`perception`], registered by name) turn frames into free space and fixes (a full pose,
//!   a heading, a position or a relative motion);
//! - the [`PoseEstimator`] dead-reckons the wheel odometry and fuses the fixes;
//! - the [`Mission`] holds the targets (waypoints, then the goal) and moves on when the robot's
//!   *own estimate* says a target is reached;
//! - the controller ([`controllers`], registered by name) chooses the command.

pub mod ball_tracker;
pub mod boundary;
pub mod config;
pub mod controller;
pub mod controllers;
pub mod estimates;
pub mod estimator;
pub mod mission;
pub mod navigation;
pub mod near_field;
pub mod percept;
pub mod perception;
pub mod remote;
pub mod robot;
pub mod tables;
pub mod traffic;

pub use boundary::{
    ActuatorCommand, ActuatorState, BodyCommand, Frame, Observation, OdometryReading, Outputs,
    RobotSoftware,
};
pub use config::{
    BodySpec, ControlSpec, FieldMap, GoalSpec, KickerBody, MapLandmark, MapMark, MapSegment,
    ODOMETRY, RobotConfig, StereoRig, VisionSpec, WorldMap,
};
pub use controller::{Controller, ControllerEntry};
pub use controllers::CONTROLLERS;
pub use estimates::{Estimates, Fix, FixOutcome, Measurement, NotFound};
pub use estimator::PoseEstimator;
pub use mission::Mission;
pub use navigation::{
    CellState, GridGeometry, MapSnapshot, NavigationReport, PlannerConfig, Unreachable,
};
pub use percept::{Percept, Percepts};
pub use perception::forward::ForwardVisionConfig;
pub use perception::{
    GroundReading, LandmarkSighting, Landmarks, MotionReading, ObservationPoint, STAGES, StageEntry,
};
pub use remote::{Mailbox, Remote, RemoteHandle};
pub use robot::{Robot, stages_of};
pub use tables::Tables;

/// Why the robot's software could not be built or run a cycle.
///
/// Each variant either says all there is to say or is its cause itself (`transparent`), so that
/// a chain of errors printed cause by cause names each cause once.
#[derive(Debug, thiserror::Error)]
pub enum RobotError {
    /// A vision stage could not be set up or failed on a frame.
    #[error(transparent)]
    Vision(#[from] omniloop_vision::VisionError),
    /// A controller could not be built.
    #[error(transparent)]
    Control(#[from] omniloop_control::ControlError),
    /// A settings field breaks a rule (a table that does not parse, a value out of range),
    /// naming the field.
    #[error(transparent)]
    Field(#[from] omniloop_problem::Problem),
    /// The robot lacks what its configuration asks for (a calibration, marks on its map, a
    /// pan unit); a field that breaks a rule is a [`RobotError::Field`].
    #[error("{0}")]
    Missing(String),
    /// A user's robot software failed, and why.
    #[error("{0}")]
    Software(Box<dyn std::error::Error + Send + Sync>),
    /// A stage needs a camera frame that the cycle did not bring.
    #[error("no frame from sensor {sensor:?} this cycle (stage {stage})")]
    MissingFrame {
        /// The sensor.
        sensor: String,
        /// The stage that needed it.
        stage: &'static str,
    },
}
