//! The grid of the robustness replay: every estimator's scenario at every level of every knob,
//! built and validated as a sweep's combinations are ([`with_values`]), identical scenarios run
//! once (every knob's gentlest level is the same run), all of them run as one sweep
//! ([`run_jobs`]) and scored.

use super::estimators::{ESTIMATORS, Estimator, Score};
use super::knobs::{KNOBS, Knob};
use crate::sweep::{Job, Plan, SweepOptions, run_jobs, with_values};
use omniloop_sim::RendererChoice;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Duration;
use toml::Value;

/// Which estimators and knobs the replay covers (all by default).
#[derive(Clone)]
pub struct Selection {
    /// The estimators, in the tables' order.
    pub estimators: Vec<&'static Estimator>,
    /// The knobs, in the tables' order.
    pub knobs: Vec<&'static Knob>,
    /// At most this many levels of each knob, the gentlest first (`None`: all).
    pub max_levels: Option<usize>,
}

impl Default for Selection {
    fn default() -> Self {
        Self {
            estimators: ESTIMATORS.iter().collect(),
            knobs: KNOBS.iter().collect(),
            max_levels: None,
        }
    }
}

/// How the grid runs.
#[derive(Debug, Clone)]
pub struct GridOptions {
    /// The renderer of every run.
    pub renderer: RendererChoice,
    /// The seed of every run (`None`: each scenario's own).
    pub seed: Option<u64>,
    /// Runs at a time (0: one a core).
    pub workers: usize,
}

/// What came of one estimator at one level of one knob.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// The knob cannot reach the estimator, and why.
    NotApplicable(String),
    /// The run's error and the target's verdict.
    Scored(Score),
    /// The run failed, or gave no figure for the estimator, and why.
    Failed(String),
}

/// One cell of the tables.
#[derive(Clone)]
pub struct Cell {
    /// The estimator.
    pub estimator: &'static Estimator,
    /// The knob.
    pub knob: &'static Knob,
    /// The knob's level, in its label's unit.
    pub level: f64,
    /// The run behind it (its index among the runs), if one ran.
    pub run: Option<usize>,
    /// What came of it.
    pub outcome: Outcome,
}

/// The grid's cells and how many runs they took.
pub struct Grid {
    /// Every cell: estimators in order, knobs within, levels within.
    pub cells: Vec<Cell>,
    /// The distinct runs.
    pub runs: usize,
    /// The seeds the runs used, by estimator (in the selection's order).
    pub seeds: Vec<u64>,
}

/// Why the grid cannot run.
#[derive(Debug, thiserror::Error)]
pub enum GridError {
    /// An estimator's own scenario does not load.
    #[error("the {estimator} scenario {file}: {}", problems.join("; "))]
    Scenario {
        /// The estimator.
        estimator: String,
        /// Its scenario file.
        file: String,
        /// What is wrong with it.
        problems: Vec<String>,
    },
}

/// A cell before it ran: the scenario to run, or why there is none.
enum Planned {
    Run(usize),
    NotApplicable(String),
}

/// Builds every cell's scenario, runs the distinct ones, scores the cells; `progress` gets
/// (runs finished, runs) now and then while they run.
pub fn run_grid(
    selection: &Selection,
    options: &GridOptions,
    mut progress: impl FnMut(usize, usize),
) -> Result<Grid, GridError> {
    let mut jobs: Vec<Job> = Vec::new();
    let mut planned: Vec<(&'static Estimator, &'static Knob, f64, Planned)> = Vec::new();
    let mut seeds = Vec::new();
    for &e in &selection.estimators {
        let (file, text) = e.scenario;
        let base = with_values(Path::new(file), text, &[])
            .map_err(|problems| GridError::Scenario {
                estimator: e.title.to_string(),
                file: file.to_string(),
                problems,
            })?
            .0;
        seeds.push(options.seed.unwrap_or(base.seed));
        for &k in &selection.knobs {
            let levels = &k.levels[..selection
                .max_levels
                .unwrap_or(usize::MAX)
                .min(k.levels.len())];
            let why = (k.not_applicable)(&base)
                .map(str::to_string)
                .or_else(|| refused(e, k, &base));
            for &level in levels {
                let cell = match &why {
                    Some(why) => Planned::NotApplicable(why.clone()),
                    None => plan_cell(e, k, level, &base, options.seed, &mut jobs),
                };
                planned.push((e, k, level, cell));
            }
        }
    }
    let runs = jobs.len();
    let plan = Plan {
        file: PathBuf::from("robustness"),
        name: "robustness".into(),
        sets: Vec::new(),
        jobs,
    };
    let outcomes = run_all(&plan, options, &mut progress);
    let cells = planned
        .into_iter()
        .map(|(estimator, knob, level, p)| {
            let (run, outcome) = match p {
                Planned::NotApplicable(why) => (None, Outcome::NotApplicable(why)),
                Planned::Run(i) => (Some(i), score(estimator, outcomes.get(i))),
            };
            Cell {
                estimator,
                knob,
                level,
                run,
                outcome,
            }
        })
        .collect();
    Ok(Grid { cells, runs, seeds })
}

/// What the rules say against the knob's strongest level in the estimator's scenario (a
/// mirror's mounting on a pinhole camera), if anything: then no level of it applies.
fn refused(e: &Estimator, k: &Knob, base: &crate::scenario::Scenario) -> Option<String> {
    let strongest = k.levels.iter().copied().fold(f64::MIN, f64::max);
    let values = (k.values)(base, strongest);
    with_values(Path::new(e.scenario.0), e.scenario.1, &values)
        .err()
        .map(|problems| problems.join("; "))
}

/// The cell's scenario (the estimator's with the knob at `level`) as a job, shared with an
/// identical one already planned; a level the rules refuse is not applicable, with their words.
fn plan_cell(
    e: &Estimator,
    k: &Knob,
    level: f64,
    base: &crate::scenario::Scenario,
    seed: Option<u64>,
    jobs: &mut Vec<Job>,
) -> Planned {
    let (file, text) = e.scenario;
    let values = (k.values)(base, level);
    let (mut scenario, toml) = match with_values(Path::new(file), text, &values) {
        Ok(st) => st,
        Err(problems) => return Planned::NotApplicable(problems.join("; ")),
    };
    if let Some(seed) = seed {
        scenario.seed = seed;
    }
    if let Some(i) = jobs.iter().position(|j| j.scenario == scenario) {
        return Planned::Run(i);
    }
    let values: Vec<Value> = values.into_iter().map(|(_, v)| v).collect();
    jobs.push(Job {
        index: jobs.len(),
        combination: jobs.len(),
        values,
        seed: scenario.seed,
        scenario,
        toml: toml.into(),
    });
    Planned::Run(jobs.len() - 1)
}

/// Runs the plan as a sweep on every core, reporting progress from this thread.
fn run_all(
    plan: &Plan,
    options: &GridOptions,
    progress: &mut impl FnMut(usize, usize),
) -> Vec<Option<crate::sweep::Outcome>> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    // The truth beside every frame: the floor region's estimator scores pixels.
    let sweep = SweepOptions {
        truth: true,
        ..SweepOptions::new(options.workers, cores, options.renderer)
    };
    let stop = AtomicBool::new(false);
    let finished = AtomicUsize::new(0);
    let total = plan.jobs.len();
    std::thread::scope(|s| {
        let worker = s.spawn(|| {
            run_jobs(plan, &sweep, &stop, |_| {
                finished.fetch_add(1, Ordering::SeqCst);
            })
        });
        while !worker.is_finished() {
            progress(finished.load(Ordering::SeqCst), total);
            std::thread::sleep(Duration::from_millis(200));
        }
        progress(total, total);
        worker.join().unwrap_or_else(|_| vec![None; total])
    })
}

/// The estimator's score from its run's outcome.
fn score(e: &Estimator, outcome: Option<&Option<crate::sweep::Outcome>>) -> Outcome {
    match outcome.and_then(Option::as_ref).map(|o| &o.result) {
        Some(Ok(summary)) => match (e.score)(summary) {
            Some(s) => Outcome::Scored(s),
            None => Outcome::Failed(format!("the run gave no {}", e.error_label)),
        },
        Some(Err(why)) => Outcome::Failed(why.to_string()),
        None => Outcome::Failed("the run did not finish".into()),
    }
}
