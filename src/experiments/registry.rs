//! The registry of experiments: a new experiment is its own file with its [`ExperimentEntry`]
//! and one line in [`EXPERIMENTS`] (its replay goes in `crate::replays`).

use super::experiment::{ExperimentEntry, ExperimentSetup};
use super::{clutter, corner, forward, heading, localization_map, omnistereo, places, resection};
use crate::scenario::{Problem, Problems, Scenario};

/// Every experiment a scenario can belong to (`[experiment.NAME]`).
pub const EXPERIMENTS: &[ExperimentEntry] = &[
    corner::ENTRY,
    places::ENTRY,
    localization_map::ENTRY,
    heading::ENTRY,
    omnistereo::ENTRY,
    resection::ENTRY,
    forward::ENTRY,
    clutter::ENTRY,
    crate::ball_map::ENTRY,
];

/// The experiment called `name`.
pub fn find(name: &str) -> Option<&'static ExperimentEntry> {
    EXPERIMENTS.iter().find(|e| e.name == name)
}

/// The scenario's experiment section, parsed by its own type: `None` without one.
pub fn setup_of(s: &Scenario) -> Result<Option<Box<dyn ExperimentSetup>>, Problem> {
    let Some(name) = s.experiment_name() else {
        return Ok(None);
    };
    let entry = find(name).ok_or_else(|| {
        let names: Vec<&str> = EXPERIMENTS.iter().map(|e| e.name).collect();
        Problem::new(
            format!("experiment.{name}"),
            format!(
                "unknown experiment `{name}`, expected one of {}",
                names.join(", ")
            ),
        )
    })?;
    (entry.setup)(&s.experiment).map(Some)
}

/// Builds what the scenario's experiment owns into it (before it is checked); a section that
/// does not parse is left for [`check`] to report.
pub fn prepare(s: &mut Scenario) {
    if let Ok(Some(setup)) = setup_of(s) {
        setup.prepare(s);
    }
}

/// The scenario's experiment's own checks (its section parsed, then checked against the rest).
pub fn check(s: &Scenario, c: &mut Problems) {
    match setup_of(s) {
        Ok(Some(setup)) => setup.check(s, c),
        Ok(None) => {}
        Err(p) => c.extend([p]),
    }
}

/// Whether the scenario's experiment takes frames of vision's camera itself.
pub fn takes_frames(s: &Scenario) -> bool {
    matches!(setup_of(s), Ok(Some(setup)) if setup.takes_frames())
}
