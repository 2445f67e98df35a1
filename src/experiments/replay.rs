//! Replays of the papers' experiments (`omniloop replay NAME`): where a replay writes, how it
//! loads, runs and reports its built-in scenarios.

use crate::report::write_run;
use crate::run::{RunError, RunOptions, RunOutput};
use crate::scenario::{LoadError, Scenario};
use anyhow::Context;
use std::path::Path;

/// A replay of a paper's experiment: `omniloop replay NAME`.
pub struct Replay {
    /// The name on the command line.
    pub name: &'static str,
    /// One line saying what it replays.
    pub title: &'static str,
    /// Runs it, writes its outputs under the context's folder, returns its table (Markdown).
    pub run: fn(&mut ReplayContext<'_>) -> anyhow::Result<String>,
}

/// Parses and validates built-in scenario text (`text`, `file`, default name).
pub type LoadFn = fn(&str, &Path, &str) -> Result<Scenario, LoadError>;

/// Runs a scenario by its experiment's procedure, with notices and progress (cycle, total).
pub type RunFn = fn(
    &Scenario,
    &RunOptions,
    &mut dyn FnMut(&str),
    &mut dyn FnMut(u64, u64),
) -> Result<RunOutput, RunError>;

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
    /// The loader, with every experiment's checks ([`crate::experiments::parse_scenario`]).
    pub load: LoadFn,
    /// The runner, by every experiment's procedure ([`crate::experiments::run_dyn`]).
    pub run: RunFn,
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
        let mut scenario = (self.load)(text, path, &stem)?;
        edit(&mut scenario)?;
        if let Some(v) = crate::scenario::validate(&scenario).first() {
            anyhow::bail!("{file} ({name}): field `{}`: {}", v.field, v.message);
        }
        if let Some(seed) = self.seed {
            scenario.seed = seed;
        }
        let progress = &mut *self.progress;
        let mut cycles = |k, n| progress(name, k, n);
        let output = (self.run)(&scenario, self.options, &mut *self.notice, &mut cycles)
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
