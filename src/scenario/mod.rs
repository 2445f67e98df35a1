//! The scenario layer: the schema of a scenario file ([`schema`]), the rules it must satisfy
//! ([`rules`], with the [`check`] types that name a field at fault), parsing with located
//! problems ([`parse`]), the Small-Size simulator's table ([`ssl`]), and the traced
//! calibration of its mirror cameras ([`calibrate`]).
//! It knows nothing of running: everything above imports it.

pub mod calibrate;
pub mod check;
pub mod parse;
pub mod rules;
pub mod schema;
pub mod ssl;
pub mod team;

pub use check::{FieldPath, Location, PathSeg, PoseChecks, Problem, Problems};
pub use parse::{LoadError, load_scenario_with, parse_scenario_with};
pub use rules::validate;
pub use schema::{
    DEFAULT_ROBOT_NAME, DifferentialSpec, OdometrySpec, OtherRobotSpec, PilotChoice, PoseSpec,
    RobotSpec, RunSpec, Scenario, SensorLookupError, TeamMember, TimingSpec, member_seed,
};
