//! Sweeps from Python (`omniloop.sweep`): the plan written and checked once by the same code
//! as `omniloop sweep` ([`SweepPlan`]), the jobs run on the Rust pool (`executor="local"`) or
//! one by one wherever a Ray task calls [`run_planned_job`], each finished job a line of the
//! sweep's `rows.jsonl`, the report written by the same code as the command's.

use crate::convert::toml_value;
use crate::errors::ScenarioError;
use crate::simulation::renderer_choice;
use omniloop::RunOptions;
use omniloop::sweep::plan_file::scenario_of_lines;
use omniloop::sweep::{
    Journal, Outcome, Plan, PlanError, Record, Seeds, Set, SweepOptions, read_journal, row_json,
    run_job, run_remaining, write_plan, write_report,
};
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

/// An error of the plan's files as an `OSError`.
fn os_error(e: impl std::fmt::Display) -> PyErr {
    PyOSError::new_err(e.to_string())
}

/// `sets` as `--set` arguments: a value list (each a TOML value) or a string as the command
/// line takes it (`"40..130:15"`, `"300,400"`).
fn set_args(sets: &Bound<'_, PyDict>) -> PyResult<Vec<String>> {
    let mut out = Vec::with_capacity(sets.len());
    for (k, v) in sets.iter() {
        let key: String = k
            .extract()
            .map_err(|_| PyValueError::new_err("sets: every key must be a str"))?;
        let values = if let Ok(text) = v.cast::<PyString>() {
            text.to_string()
        } else if let Ok(list) = v.cast::<PyList>() {
            let mut lits = Vec::with_capacity(list.len());
            for item in list.iter() {
                lits.push(toml_value(&key, &item)?.to_string());
            }
            lits.join(",")
        } else {
            toml_value(&key, &v)?.to_string()
        };
        out.push(format!("{key}={values}"));
    }
    Ok(out)
}

/// Plans the sweep of `scenario` over `sets` x `seeds` into `out` (default
/// `runs/<name>_sweep`), checking every job first and writing `plan.jsonl`. Raises
/// `ScenarioError` with every problem.
#[pyfunction]
#[pyo3(signature = (scenario, sets, seeds = "1", out = None))]
pub fn sweep_plan(
    scenario: PathBuf,
    sets: &Bound<'_, PyDict>,
    seeds: &str,
    out: Option<PathBuf>,
) -> PyResult<SweepPlan> {
    let args = set_args(sets)?;
    let parsed = args
        .iter()
        .map(|a| Set::parse(a).map_err(|e| ScenarioError::new_err(e.to_string())))
        .collect::<PyResult<Vec<_>>>()?;
    let seeds: Seeds = seeds
        .parse::<Seeds>()
        .map_err(|e| PyValueError::new_err(format!("seeds={seeds:?}: {e}")))?;
    let plan = omniloop::sweep::plan(&scenario, &parsed, &seeds).map_err(|e| match e {
        PlanError::Invalid(m) => ScenarioError::new_err(m.join("\n")),
        PlanError::Scenario(e) => ScenarioError::new_err(e.to_string()),
    })?;
    let dir = out.unwrap_or_else(|| Path::new("runs").join(format!("{}_sweep", plan.name)));
    let file = dir.join("plan.jsonl");
    write_plan(&plan, &seeds, &file).map_err(os_error)?;
    let text = std::fs::read_to_string(&file).map_err(os_error)?;
    Ok(SweepPlan {
        plan,
        out: dir,
        lines: text.lines().map(String::from).collect(),
    })
}

/// A checked sweep and its folder: what `sweep_plan` gives and the sweep's steps take.
#[pyclass(module = "omniloop", name = "SweepPlan", frozen)]
pub struct SweepPlan {
    plan: Plan,
    /// The sweep's folder.
    #[pyo3(get)]
    out: PathBuf,
    /// The lines of `plan.jsonl`, the header first.
    #[pyo3(get)]
    lines: Vec<String>,
}

#[pymethods]
impl SweepPlan {
    /// Opens the sweep's journal (emptied unless `resume`): the indices of the jobs still to
    /// run.
    fn open(&self, resume: bool) -> PyResult<Vec<usize>> {
        let (_, previous) = Journal::open(&self.out, &self.plan, resume).map_err(os_error)?;
        Ok((0..self.plan.jobs.len())
            .filter(|&i| previous[i].is_none())
            .collect())
    }

    /// Runs the jobs the journal lacks on the Rust pool (`jobs` at a time, 0: one a core), as
    /// `omniloop sweep` does, each one's record appended to the journal and handed to
    /// `done(record_json)` as it ends. Ctrl-C stops taking jobs (the finished are kept).
    #[pyo3(signature = (jobs = 0, renderer = "cpu", keep_runs = false, done = None))]
    fn run_local(
        &self,
        py: Python<'_>,
        jobs: usize,
        renderer: &str,
        keep_runs: bool,
        done: Option<Py<PyAny>>,
    ) -> PyResult<()> {
        let choice = renderer_choice(renderer)?;
        let plan = &self.plan;
        let (journal, previous) = Journal::open(&self.out, plan, true).map_err(os_error)?;
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let mut options = SweepOptions::new(jobs, cores, choice);
        options.keep_runs = keep_runs.then(|| self.out.join("runs"));
        let stop = AtomicBool::new(false);
        let problem: Mutex<Option<PyErr>> = Mutex::new(None);
        py.detach(|| {
            run_remaining(plan, &options, &stop, previous, |o: &Outcome| {
                let job = &plan.jobs[o.job];
                let record = Record::new(o, &job.dir_name(&plan.sets), job.seed);
                let written = journal.record(&record).map_err(os_error);
                let called = Python::attach(|py| {
                    py.check_signals()?;
                    if let Some(f) = &done {
                        f.call1(py, (record.line().trim_end(),))?;
                    }
                    Ok::<(), PyErr>(())
                });
                if let Err(e) = written.and(called) {
                    stop.store(true, Ordering::SeqCst);
                    problem
                        .lock()
                        .unwrap_or_else(|p| p.into_inner())
                        .get_or_insert(e);
                }
            })
        });
        match problem.into_inner().unwrap_or_else(|p| p.into_inner()) {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Writes `sweep.csv`, `sweep.md` (after `header`) and `sweep.png` (`plot`'s metric) from
    /// the journal; the rows as JSON (the columns of `sweep.csv`).
    #[pyo3(signature = (plot = "success_rate", header = ""))]
    fn report(&self, plot: &str, header: &str) -> PyResult<String> {
        let plan = &self.plan;
        let journal = self.out.join(omniloop::sweep::journal::JOURNAL);
        let outcomes = if journal.exists() {
            read_journal(&journal, plan).map_err(os_error)?
        } else {
            vec![None; plan.jobs.len()]
        };
        let (_, rows) = write_report(&self.out, plan, &outcomes, plot, header)
            .map_err(|e| os_error(format!("{e:#}")))?;
        let json: Vec<serde_json::Value> = rows.iter().map(|r| row_json(plan, r)).collect();
        serde_json::to_string(&json).map_err(|e| PyRuntimeError::new_err(e.to_string()))
    }
}

/// Runs one planned job, given the plan's header line and the job's line (as a Ray task gets
/// them), on `threads` threads; its outputs into `keep` when given. Its record, one JSON line
/// for the sweep's journal: a run that fails is recorded with its error, not raised.
#[pyfunction]
#[pyo3(signature = (header, job, keep = None, renderer = "cpu", threads = 1))]
pub fn run_planned_job(
    py: Python<'_>,
    header: &str,
    job: &str,
    keep: Option<PathBuf>,
    renderer: &str,
    threads: usize,
) -> PyResult<String> {
    let choice = renderer_choice(renderer)?;
    let (planned, scenario) =
        scenario_of_lines(header, job).map_err(|e| ScenarioError::new_err(e.to_string()))?;
    let options = RunOptions {
        renderer: choice,
        ..RunOptions::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    let keep = keep.map(|d| d.join(&planned.name));
    let result = py.detach(|| pool.install(|| run_job(&scenario, &options, keep.as_deref())));
    let outcome = Outcome {
        job: planned.index,
        result,
    };
    Ok(Record::new(&outcome, &planned.name, planned.seed)
        .line()
        .trim_end()
        .to_string())
}
