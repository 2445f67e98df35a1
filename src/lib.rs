//! omniloop: a closed-loop testbed where a simulated omnidirectional robot sees the world
//! through a catadioptric camera and drives itself.
//!
//! This crate is the simulator's side of the loop: the scenario schema and its validation
//! ([`scenario`], [`load`]), the loop that renders the robot's cameras, hands its software
//! (`omniloop-robot`) what its sensors give and applies its commands ([`simulation`]), the
//! sensors and actuators it simulates ([`cameras`], [`odometry`]), the truth-side scores
//! ([`score`]), the experiments with their replays ([`experiments`]), what a run writes
//! ([`record`], [`output`]) and the figures ([`topview`], [`charts`]). The world lives in `omniloop-sim`,
//! image processing in `omniloop-vision`, controllers in `omniloop-control`.

pub mod calibrate;
pub mod cameras;
pub mod charts;
pub mod column_calibration;
pub mod experiments;
pub mod load;
pub mod odometry;
pub mod output;
pub mod pilot;
pub mod record;
pub mod runner;
pub mod scenario;
pub mod score;
pub mod simulation;
pub mod sweep;
pub mod topview;
pub mod validate;

pub use load::{LoadError, Problem, load_scenario, parse_scenario};
pub use record::{Summary, TrajectoryRow};
pub use runner::Runner;
pub use scenario::Scenario;
pub use simulation::{RunOptions, RunOutput, Simulation, run_scenario};

/// Motion models and the avoidance controllers.
pub use omniloop_control as control;
/// The robot's side of the boundary: the [`robot::RobotSoftware`] trait, what it receives and
/// returns, and the built-in stack.
pub use omniloop_robot as robot;
/// Image processing: calibration tables, free space, self-localization and the papers' other
/// estimators (it takes images, never a world).
pub use omniloop_vision as vision;

/// A complete, commented scenario showing every key with its default.
pub const DEFAULT_SCENARIO: &str = include_str!("default_scenario.toml");
