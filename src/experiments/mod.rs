//! Experiments, one module each: its scenario section (`[experiment.NAME]`), its procedure,
//! its metrics (computed from the truth and the robot's estimates) and its replay of a
//! paper's experiment (scenario files, figure, table).
//!
//! A new experiment is a module here with a spec type (a variant of [`ExperimentSpec`]), an
//! [`Experiment`] (procedure and metrics) and, when it replays a paper, a [`Replay`] in
//! [`REPLAYS`]; plus its scenario files, its end-to-end test and its section of
//! `docs/experiments.md`.

pub mod corner;
pub mod forward;
pub mod heading;
pub mod localization_map;
pub mod omnistereo;
pub mod places;
pub mod resection;

use crate::load::parse_scenario;
use crate::output::write_run;
use crate::record::Summary;
use crate::scenario::Scenario;
use crate::simulation::{OutputFile, RunError, RunOptions, RunOutput, Simulation, run_scenario};
use crate::validate::Checker;
use anyhow::Context;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The metrics an experiment adds to `summary.json`, by key.
pub type Metrics = serde_json::Map<String, serde_json::Value>;

/// What an experiment does with the simulation, and what it measures.
pub trait Experiment {
    /// Carries out the procedure, calling `progress(cycle, total)` as it goes. The default
    /// drives: control cycles until the goal is reached or the time is up.
    fn run(
        &mut self,
        sim: &mut Simulation,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<(), RunError> {
        drive(sim, progress)
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
struct Drive;

impl Experiment for Drive {}

/// The experiment a scenario belongs to (`[experiment.corner]`, `[experiment.places]`,
/// `[experiment.localization_map]`, `[experiment.heading]`, `[experiment.omnistereo]`,
/// `[experiment.resection]`, `[experiment.forward]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ExperimentSpec {
    /// E1: a corridor corner, its turn metrics.
    Corner(corner::CornerSpec),
    /// E2: localize at places on the field.
    Places(places::PlacesSpec),
    /// The self-localization error map: a grid over the whole floor region, both modes.
    LocalizationMap(localization_map::MapSpec),
    /// E3: heading error from a luminance circle at a checkpoint.
    Heading(heading::HeadingSpec),
    /// E4: conical omnistereo range, trilateration, compass and interframe motion.
    Omnistereo(omnistereo::OmnistereoSpec),
    /// E5: three-mark resection at places.
    Resection(resection::ResectionSpec),
    /// E6: a forward camera's avoidance or visual odometry.
    Forward(forward::ForwardSpec),
}

impl ExperimentSpec {
    /// Checks the section against the rest of the scenario.
    pub(crate) fn validate(&self, s: &Scenario, c: &mut Checker) {
        match self {
            Self::Corner(spec) => spec.validate(c),
            Self::Places(spec) => spec.validate(s, c),
            Self::LocalizationMap(spec) => spec.validate(s, c),
            Self::Heading(spec) => spec.validate(s, c),
            Self::Omnistereo(spec) => spec.validate(s, c),
            Self::Resection(spec) => spec.validate(s, c),
            Self::Forward(spec) => spec.validate(s, c),
        }
    }

    /// Builds what the experiment owns into the scenario, before it is validated.
    pub(crate) fn prepare(&self, s: &mut Scenario) {
        match self {
            Self::Corner(spec) => spec.prepare(s),
            Self::Places(_)
            | Self::LocalizationMap(_)
            | Self::Heading(_)
            | Self::Omnistereo(_)
            | Self::Resection(_)
            | Self::Forward(_) => {}
        }
    }

    /// Whether the experiment takes frames of the robot's camera itself (so the camera is
    /// rendered and calibrated whatever the robot's software uses).
    pub fn takes_frames(&self) -> bool {
        matches!(self, Self::Heading(_))
    }

    /// The table `omniloop run` prints for a run of this experiment, if it has one.
    pub fn table(&self, summary: &Summary) -> Option<String> {
        match self {
            Self::Corner(_) => None,
            Self::Places(_) => Some(places::places_table(summary)),
            Self::LocalizationMap(_) => Some(localization_map::map_table(summary)),
            Self::Heading(_) => Some(heading::heading_table(summary)),
            Self::Omnistereo(_) => Some(omnistereo::omnistereo_table(summary)),
            Self::Resection(_) => Some(resection::resection_table(&[summary])),
            Self::Forward(_) => None,
        }
    }
}

/// The procedure and metrics of a scenario's experiment.
pub fn procedure(s: &Scenario) -> Box<dyn Experiment> {
    match &s.experiment {
        None => Box::new(Drive),
        Some(ExperimentSpec::Corner(_)) => Box::new(corner::Corner),
        Some(ExperimentSpec::Places(spec)) => {
            Box::new(places::Places::new(spec, s.vision.localization.method))
        }
        Some(ExperimentSpec::LocalizationMap(spec)) => Box::new(
            localization_map::LocalizationMap::new(spec, s.vision.localization.method),
        ),
        Some(ExperimentSpec::Heading(spec)) => {
            Box::new(heading::Heading::new(spec, &s.vision.luminance_heading))
        }
        Some(ExperimentSpec::Omnistereo(spec)) => Box::new(omnistereo::Omnistereo::new(spec, s)),
        Some(ExperimentSpec::Resection(spec)) => Box::new(resection::Resection::new(spec, s)),
        Some(ExperimentSpec::Forward(_)) => Box::new(forward::Forward::new(s)),
    }
}

/// A replay of a paper's experiment: `omniloop replay NAME`.
pub struct Replay {
    /// The name on the command line.
    pub name: &'static str,
    /// One line saying what it replays.
    pub title: &'static str,
    /// Runs it, writes its outputs under the context's folder, returns its table (Markdown).
    pub run: fn(&mut ReplayContext<'_>) -> anyhow::Result<String>,
}

/// Every replay, in the order `omniloop replay --list` shows them.
pub const REPLAYS: &[Replay] = &[
    corner::REPLAY,
    places::REPLAY,
    heading::REPLAY,
    omnistereo::REPLAY,
    resection::REPLAY,
    forward::REPLAY,
];

/// The replay called `name`.
pub fn replay(name: &str) -> Option<&'static Replay> {
    REPLAYS.iter().find(|r| r.name == name)
}

/// Where a replay writes, how it renders, and how it reports.
pub struct ReplayContext<'a> {
    /// Output folder.
    pub out: &'a Path,
    /// Renderer and frame options.
    pub options: &'a RunOptions,
    /// Seed overriding the scenarios'.
    pub seed: Option<u64>,
    /// Progress: run name, cycle, total.
    pub progress: &'a mut dyn FnMut(&str, u64, u64),
    /// One-line notices for the user.
    pub notice: &'a mut dyn FnMut(&str),
}

/// One run of a replay.
pub struct ReplayRun {
    /// Short name (`goal_direction`).
    pub name: String,
    /// The scenario.
    pub scenario: Scenario,
    /// What it produced.
    pub output: RunOutput,
}

impl ReplayContext<'_> {
    /// Runs the built-in scenario `text` (from `file`, named in messages) with the replay's
    /// seed, and writes its outputs into `dir`.
    pub fn run(
        &mut self,
        name: &str,
        file: &str,
        text: &str,
        dir: &Path,
    ) -> anyhow::Result<ReplayRun> {
        let run = self.simulate(name, file, text)?;
        write_run(dir, &run.scenario, &run.output)?;
        Ok(run)
    }

    /// Runs the built-in scenario `text` (from `file`) with the replay's seed, writing nothing.
    pub fn simulate(&mut self, name: &str, file: &str, text: &str) -> anyhow::Result<ReplayRun> {
        self.simulate_edited(name, file, text, |_| Ok(()))
    }

    /// Runs the built-in scenario `text` (from `file`) as changed by `edit` (a variant of it:
    /// another camera), with the replay's seed, writing nothing. The variant is validated again.
    pub fn simulate_edited(
        &mut self,
        name: &str,
        file: &str,
        text: &str,
        edit: impl FnOnce(&mut Scenario) -> anyhow::Result<()>,
    ) -> anyhow::Result<ReplayRun> {
        let path = Path::new(file);
        let stem = path
            .file_stem()
            .map_or(String::new(), |s| s.to_string_lossy().into_owned());
        let mut scenario = parse_scenario(text, path, &stem)?;
        edit(&mut scenario)?;
        if let Some(v) = crate::validate::validate(&scenario).first() {
            anyhow::bail!("{file} ({name}): field `{}`: {}", v.path, v.message);
        }
        if let Some(seed) = self.seed {
            scenario.seed = seed;
        }
        let progress = &mut *self.progress;
        let output = run_scenario(&scenario, self.options, &mut *self.notice, |k, n| {
            progress(name, k, n)
        })
        .with_context(|| format!("running {file}"))?;
        Ok(ReplayRun {
            name: name.to_string(),
            scenario,
            output,
        })
    }
}

/// Writes `text` to `file`, naming the file in the error.
pub(crate) fn write_text(file: &Path, text: &str) -> anyhow::Result<()> {
    std::fs::write(file, text).with_context(|| format!("writing {}", file.display()))
}
