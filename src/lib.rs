//! omniloop: a closed-loop testbed where a simulated omnidirectional robot sees the world
//! through a catadioptric camera and drives itself.
//!
//! This crate is the simulator's side of the loop, in layers that import downward only:
//! - [`scenario`]: the schema of a scenario file, its rules, parsing with located problems;
//! - [`run`]: the loop that renders the robot's cameras, hands its software what its sensors
//!   give and applies its commands ([`Simulation`]), the simulated sensors, the truth-side
//!   scores and the records of a run;
//! - [`report`]: a run's files and figures;
//! - [`experiments`]: the registered experiments, which drive the loop, with their replays;
//!   [`run_scenario`], [`Runner`] and [`load_scenario`];
//! - [`sweep`]: many runs over a grid of values and seeds;
//! - [`robustness`]: every estimator against each knob of realism, as one sweep;
//! - [`camera_export`]: a mirror sensor as a standard camera model fitted to its traced rays
//!   (OpenCV `omnidir`, Kalibr, OCamCalib);
//! - [`dataset`]: frames of a camera with their truth (depth, labels, poses) for training;
//! - [`replays`]: the registry of `omniloop replay`;
//! - [`viewing`]: a run on Foxglove's channels, into an MCAP file.
//!
//! The robot's software is anything that implements [`robot::RobotSoftware`]; the world lives
//! in `omniloop-sim`, image processing in [`vision`], motion and avoidance in [`control`].

pub mod ball_map;
pub mod blackout;
pub mod camera_export;
pub mod dataset;
pub mod experiments;
pub mod replays;
pub mod report;
pub mod robustness;
pub mod run;
pub mod scenario;
pub mod ssl;
pub mod sweep;
pub mod viewing;

pub use experiments::{Runner, Session, load_scenario, parse_scenario, run_scenario};
pub use run::{RunOptions, RunOutput, Simulation, Summary, TrajectoryRow, Truth};
pub use scenario::{LoadError, Problem, Scenario};

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

/// Scenario files built into the library, `(name, text)` with the name the file's stem under
/// `scenarios/`: for programs without the repository beside them (the Python package ships no
/// `scenarios/`; `omniloop.Scenario.bundled(name)`). One line here bundles another.
pub const BUNDLED_SCENARIOS: &[(&str, &str)] = &[(
    "blackout_stage1",
    include_str!("../scenarios/blackout_stage1.toml"),
)];
