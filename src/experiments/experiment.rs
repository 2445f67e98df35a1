//! What an experiment is: its section of a scenario parsed ([`ExperimentSetup`]: what it
//! builds into the scenario, its checks, its table), its procedure and metrics
//! ([`Experiment`]), and the entry that registers it ([`ExperimentEntry`]).

use crate::run::{OutputFile, RunError, RunOutput, Simulation, Summary};
use crate::scenario::{Problem, Problems, Scenario};
use omniloop_robot::Tables;
use serde::Serialize;
use serde::de::DeserializeOwned;

/// An experiment's metrics as `summary.json` holds them: its keys, in order, beside the run's
/// own ([`Summary::experiment`]).
pub type MetricKeys = serde_json::Map<String, serde_json::Value>;

/// An experiment's metrics, typed: a struct whose fields are the keys it adds to
/// `summary.json`, in the order they are declared (`skip_serializing_if` on a key the summary
/// leaves out). The experiment builds it and hands its [`Metrics::keys`] to the summary
/// ([`Experiment::metrics`]); whatever reads the metrics back from a summary (the experiment's
/// table, the robustness replay) reads the struct with [`Metrics::of`], so that a renamed
/// field fails to compile where it is read instead of reading nothing.
pub trait Metrics: Serialize + DeserializeOwned {
    /// The metrics as the summary's keys.
    fn keys(&self) -> MetricKeys {
        match serde_json::to_value(self) {
            Ok(serde_json::Value::Object(keys)) => keys,
            _ => MetricKeys::new(),
        }
    }

    /// The metrics of `summary`, if its experiment wrote these (`None`: another experiment's,
    /// or none; a struct whose every field may be absent reads from any summary, its fields
    /// `None`).
    fn of(summary: &Summary) -> Option<Self> {
        Self::deserialize(&summary.experiment).ok()
    }
}

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

    /// The experiment's own metrics of a finished run, as the summary's keys (its
    /// [`Metrics`] struct's [`Metrics::keys`]).
    fn metrics(&self, _out: &RunOutput) -> MetricKeys {
        MetricKeys::new()
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

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::fmt::Debug;

    /// A run's summary whose experiment wrote `keys`.
    pub(crate) fn summary_with(keys: MetricKeys) -> Summary {
        let text = r#"{"scenario":"s","seed":1,"controller":"c","cycles":1,"sim_time_s":0.1,
            "wall_time_s":0.1,"cycles_per_s":10.0,"wall_contacts":0,"peak_speed_mm_s":0.0,
            "peak_accel_mm_s2":0.0,"reached_goal":false,"time_to_goal_s":null,
            "min_clearance_mm":5.0,"path_length_mm":0.0}"#;
        let mut s: Summary = serde_json::from_str(text).unwrap();
        s.experiment = keys;
        s
    }

    /// Writes `m` into a summary as its experiment would, through `summary.json`'s text, and
    /// checks that it reads back whole; returns the summary read back.
    pub(crate) fn round_trip<T: Metrics + PartialEq + Debug>(m: &T) -> Summary {
        let text = serde_json::to_string_pretty(&summary_with(m.keys())).unwrap();
        let summary: Summary = serde_json::from_str(&text).unwrap();
        assert_eq!(T::of(&summary).as_ref(), Some(m), "{text}");
        summary
    }

    #[derive(Debug, PartialEq, Serialize, serde::Deserialize)]
    struct Two {
        b: f64,
        #[serde(skip_serializing_if = "Option::is_none", default)]
        a: Option<usize>,
    }

    impl Metrics for Two {}

    #[test]
    fn metrics_are_keys_in_declaration_order_and_read_back_only_whole() {
        let m = Two { b: 1.5, a: Some(2) };
        let s = round_trip(&m);
        assert_eq!(
            serde_json::to_string(&s.experiment).unwrap(),
            r#"{"b":1.5,"a":2}"#
        );
        let none = Two { b: 0.0, a: None };
        assert_eq!(
            serde_json::to_string(&round_trip(&none).experiment).unwrap(),
            r#"{"b":0.0}"#
        );
        // Another experiment's keys, or none, are not these metrics.
        assert_eq!(Two::of(&summary_with(MetricKeys::new())), None);
    }
}
