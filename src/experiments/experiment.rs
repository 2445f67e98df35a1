//! What an experiment is: its section of a scenario parsed ([`ExperimentSetup`]: what it
//! builds into the scenario, its checks, its table), its procedure and metrics
//! ([`Experiment`]), and the entry that registers it ([`ExperimentEntry`]).

use crate::run::{OutputFile, RunError, RunOutput, Simulation, Summary};
use crate::scenario::{Problem, Problems, Scenario};
use omniloop_robot::Tables;
use serde::de::DeserializeOwned;

/// The metrics an experiment adds to `summary.json`, by key.
pub type Metrics = serde_json::Map<String, serde_json::Value>;

/// What an experiment does with the simulation, and what it measures.
pub trait Experiment: Send {
    /// Carries out the procedure, calling `progress(cycle, total)` as it goes. The default
    /// drives: control cycles until the goal is reached or the time is up.
    fn run(
        &mut self,
        sim: &mut Simulation,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<(), RunError> {
        drive(sim, progress)
    }

    /// Whether its procedure is the drive (cycles until the goal or the time is up), so that a
    /// run of it may be stepped from outside ([`crate::experiments::Session`]); an experiment
    /// that moves the robot itself or takes its own frames says no.
    fn drives(&self) -> bool {
        true
    }

    /// The experiment's own metrics of a finished run.
    fn metrics(&self, _out: &RunOutput) -> Metrics {
        Metrics::new()
    }

    /// The experiment's own files (tables, figures) of a finished run, written beside the
    /// run's outputs.
    fn files(&self, _scenario: &Scenario, _out: &RunOutput) -> Result<Vec<OutputFile>, RunError> {
        Ok(Vec::new())
    }
}

/// The driving procedure: control cycles until the run is over, then the final state.
pub fn drive(sim: &mut Simulation, progress: &mut dyn FnMut(u64, u64)) -> Result<(), RunError> {
    let max = sim.scenario().max_cycles();
    while !sim.finished() {
        sim.step()?;
        progress(sim.cycle(), max);
    }
    sim.record_final_state();
    Ok(())
}

/// A scenario with no experiment: it drives, and measures what every run measures.
pub struct Drive;

impl Experiment for Drive {}

/// An experiment's section of a scenario (`[experiment.NAME]`), parsed by its own type.
pub trait ExperimentSetup {
    /// Builds what the experiment owns into the scenario (the corner's corridor, start and
    /// goal), before the scenario is checked.
    fn prepare(&self, _s: &mut Scenario) {}

    /// Checks the section against the rest of the scenario.
    fn check(&self, s: &Scenario, c: &mut Problems);

    /// Whether it takes frames of vision's camera itself (so the camera is rendered and
    /// calibrated whatever the robot's software reads).
    fn takes_frames(&self) -> bool {
        false
    }

    /// The table `omniloop run` prints for a run of it, if it has one.
    fn table(&self, _summary: &Summary) -> Option<String> {
        None
    }

    /// Its procedure and metrics for scenario `s`.
    fn procedure(&self, s: &Scenario) -> Result<Box<dyn Experiment>, RunError>;
}

/// An experiment as the registry lists it: a new experiment is its own file with one of these
/// and one line in [`crate::experiments::registry::EXPERIMENTS`].
pub struct ExperimentEntry {
    /// Its name: the key of its section (`[experiment.NAME]`).
    pub name: &'static str,
    /// What it measures, in one line, with the paper and section it replays.
    pub summary: &'static str,
    /// Parses its section from the scenario's `[experiment]` tables.
    pub setup: fn(&Tables) -> Result<Box<dyn ExperimentSetup>, Problem>,
}

/// Parses section `name` of `[experiment]` as `T` (the `setup` of an entry).
pub fn setup<T: ExperimentSetup + DeserializeOwned + 'static>(
    tables: &Tables,
    name: &str,
) -> Result<Box<dyn ExperimentSetup>, Problem> {
    let spec: T = tables.parse_present("experiment", name)?;
    Ok(Box::new(spec))
}
