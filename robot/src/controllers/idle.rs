//! Stand still: the default, so that nothing drives unless the scenario says so.

use crate::boundary::BodyCommand;
use crate::controller::{Controller, ControllerEntry, Situation, no_problems};

/// The registry's entry.
pub const ENTRY: ControllerEntry = ControllerEntry {
    name: "idle",
    summary: "stand still (the default)",
    tables: &[],
    needs_goal: false,
    stages: &[],
    check_use: no_problems,
    build: |_| Ok(Box::new(Idle)),
};

/// Stands still.
pub struct Idle;

impl Controller for Idle {
    fn decide(&mut self, _: &Situation<'_>) -> BodyCommand {
        BodyCommand::STOP
    }
}
