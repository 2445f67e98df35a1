//! The controllers, one file each, and their registry.
//!
//! A new controller is a file here with its [`ControllerEntry`] (`pub const ENTRY`), its
//! settings type when it has a `[control.NAME]` table, and one line in [`CONTROLLERS`]:
//! scenario files can then name it in `control.kind`, and the scenario checks validate its
//! table by its own `check_table`.

pub mod goal_direction;
pub mod idle;
pub mod observe;
pub mod optical_flow;
pub mod script;
pub mod segmentation;
pub mod striker;
pub mod velocity_aware;
pub mod wall_follow;
pub mod wander;

use crate::RobotError;
use crate::config::RobotConfig;
use crate::controller::{Controller, ControllerEntry};
use omniloop_problem::Problem;

/// Every controller a scenario can name, in the order `omniloop run --print-default` lists
/// them.
pub const CONTROLLERS: &[ControllerEntry] = &[
    idle::ENTRY,
    goal_direction::ENTRY,
    velocity_aware::ENTRY,
    wander::ENTRY,
    observe::ENTRY,
    segmentation::ENTRY,
    optical_flow::ENTRY,
    script::ENTRY,
    wall_follow::ENTRY,
    striker::ENTRY,
];

/// The controller called `name`.
pub fn find(name: &str) -> Option<&'static ControllerEntry> {
    CONTROLLERS.iter().find(|c| c.name == name)
}

/// The names of every controller, for messages.
pub fn names() -> String {
    let names: Vec<&str> = CONTROLLERS.iter().map(|c| c.name).collect();
    names.join(", ")
}

/// The controller `config.control.kind` names, built for the robot.
pub fn build(config: &RobotConfig) -> Result<Box<dyn Controller>, RobotError> {
    let kind = &config.control.kind;
    let entry = find(kind).ok_or_else(|| {
        RobotError::Field(Problem::new(
            "control.kind",
            format!("no controller {kind:?} (there are: {})", names()),
        ))
    })?;
    (entry.build)(config)
}
