//! The experiments layer: each experiment in its own file (its section `[experiment.NAME]`,
//! procedure, metrics, figures and, when it replays a paper, its replay), registered in
//! [`registry`]; running a scenario by its experiment's procedure ([`runner`]: `run_scenario`,
//! [`Runner`]) and loading scenario files with every experiment's checks. An experiment drives
//! the loop of [`crate::run`]; the loop never calls up into an experiment.

pub mod clutter;
pub mod corner;
pub mod experiment;
pub mod forward;
pub mod heading;
pub mod localization_map;
pub mod omnistereo;
pub mod places;
pub mod registry;
pub mod replay;
pub mod resection;
pub mod runner;
pub mod session;

pub use experiment::{Experiment, ExperimentEntry, ExperimentSetup, MetricKeys, Metrics, drive};
pub use registry::EXPERIMENTS;
pub use replay::{Replay, ReplayContext, ReplayRun};
pub use runner::{Runner, load_scenario, parse_scenario, run_dyn, run_scenario, run_scenario_with};
pub use session::Session;
