//! omniloop: a closed-loop testbed where a simulated omnidirectional robot sees the world
//! through a catadioptric camera and drives itself.
//!
//! This crate holds the scenario schema and its validation ([`scenario`], [`load`]), the
//! closed loop ([`runner`]), what a run writes ([`record`], [`output`]) and the figures
//! ([`topview`]). The world lives in `omniloop-sim`, image processing in `omniloop-vision`,
//! controllers in `omniloop-control`.

pub mod calibrate;
pub mod estimator;
pub mod load;
pub mod metrics;
pub mod output;
pub mod record;
pub mod replay;
pub mod runner;
pub mod scenario;
pub mod topview;
pub mod validate;

pub use load::{LoadError, Problem, load_scenario, parse_scenario};
pub use record::{Summary, TrajectoryRow};
pub use runner::{RunOutput, Simulation, run_scenario};
pub use scenario::Scenario;

/// A complete, commented scenario showing every key with its default.
pub const DEFAULT_SCENARIO: &str = include_str!("default_scenario.toml");
