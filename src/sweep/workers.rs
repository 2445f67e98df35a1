//! Running a plan's jobs on a pool of workers, one run each at a time. The workers are tasks
//! of one thread pool of a thread a core, which the CPU renderer's parallel loops also use: while
//! every worker is busy each renders on its own thread, and a thread left idle (the last runs of
//! a sweep) helps the others render, so the cores are neither oversubscribed nor left waiting.

use super::plan::{Job, Plan};
use crate::experiments::run_scenario;
use crate::report::output::write_run;
use crate::run::record::Summary;
use crate::run::{RunError, RunOptions};
use crate::scenario::Scenario;
use omniloop_sim::render::{BatchHandle, BatchServer, GpuRenderer};
use omniloop_sim::{RenderError, RendererChoice};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// How a sweep runs.
#[derive(Debug, Clone)]
pub struct SweepOptions {
    /// Runs at a time.
    pub workers: usize,
    /// Threads of the pool the workers and the CPU renderer share (at least `workers`).
    pub threads: usize,
    /// The renderer of every run.
    pub renderer: RendererChoice,
    /// Where each run's own outputs go (`runs/` of the sweep), if kept.
    pub keep_runs: Option<PathBuf>,
    /// The GPU every run's frames go to, traced in batches across runs (see [`shared_gpu`]).
    pub shared_gpu: Option<BatchHandle>,
    /// Trace each frame's truth and score the free space pixel by pixel in every run.
    pub truth: bool,
}

/// A batch server on the GPU for a sweep with `choice`: with `gpu`, the first adapter; with
/// `auto`, a hardware one (a software rasterizer is slower than the CPU renderer: none);
/// with `cpu`, none.
pub fn shared_gpu(choice: RendererChoice) -> Result<Option<BatchServer>, RenderError> {
    let gpu = match choice {
        RendererChoice::Cpu => return Ok(None),
        RendererChoice::Gpu => GpuRenderer::new()?,
        RendererChoice::Auto => match GpuRenderer::hardware()? {
            Some(g) => g,
            None => return Ok(None),
        },
    };
    Ok(Some(BatchServer::start(gpu, BATCH_WAIT)))
}

/// How long a batch waits for the runs that have not sent their frame yet.
const BATCH_WAIT: Duration = Duration::from_millis(10);

impl SweepOptions {
    /// `workers` runs at a time (0: one a core) over `cores` cores.
    pub fn new(workers: usize, cores: usize, renderer: RendererChoice) -> Self {
        let cores = cores.max(1);
        let workers = if workers == 0 { cores } else { workers };
        Self {
            workers,
            threads: cores.max(workers),
            renderer,
            keep_runs: None,
            shared_gpu: None,
            truth: false,
        }
    }
}

/// Why a job of a sweep has no summary.
#[derive(Debug, Clone, thiserror::Error)]
pub enum JobError {
    /// The run failed.
    #[error("{0:#}")]
    Run(Arc<RunError>),
    /// The run's outputs could not be written.
    #[error("{0:#}")]
    Write(Arc<anyhow::Error>),
    /// A failure as recorded in a journal or a run's `error.txt`: its text.
    #[error("{0}")]
    Recorded(String),
    /// A journal's record with neither a summary nor an error.
    #[error("recorded without a summary or an error")]
    Unrecorded,
}

/// What became of one run.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The job's index in the plan.
    pub job: usize,
    /// Its summary, or the error that stopped it.
    pub result: Result<Summary, JobError>,
}

/// Runs the plan's jobs, calling `done` as each ends (in the order they end); stops taking new
/// jobs once `stop` is set. The outcomes come back in the plan's order, `None` for a job that
/// did not run.
pub fn run_jobs(
    plan: &Plan,
    options: &SweepOptions,
    stop: &AtomicBool,
    done: impl Fn(&Outcome) + Sync,
) -> Vec<Option<Outcome>> {
    run_remaining(plan, options, stop, vec![None; plan.jobs.len()], done)
}

/// [`run_jobs`] for the jobs `previous` has no outcome of (a resumed sweep); the others keep
/// theirs.
pub fn run_remaining(
    plan: &Plan,
    options: &SweepOptions,
    stop: &AtomicBool,
    previous: Vec<Option<Outcome>>,
    done: impl Fn(&Outcome) + Sync,
) -> Vec<Option<Outcome>> {
    let todo: Vec<usize> = (0..plan.jobs.len())
        .filter(|&i| previous.get(i).is_none_or(Option::is_none))
        .collect();
    let mut previous = previous;
    previous.resize(plan.jobs.len(), None);
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Outcome>>> = Mutex::new(previous);
    let workers = options.workers.clamp(1, todo.len().max(1));
    let worker = || {
        loop {
            if stop.load(Ordering::SeqCst) {
                break;
            }
            let Some(&i) = todo.get(next.fetch_add(1, Ordering::SeqCst)) else {
                break;
            };
            let job = &plan.jobs[i];
            let outcome = Outcome {
                job: i,
                result: run_one(plan, job, options),
            };
            done(&outcome);
            results.lock().unwrap_or_else(|e| e.into_inner())[i] = Some(outcome);
        }
    };
    match rayon::ThreadPoolBuilder::new()
        .num_threads(options.threads.max(workers))
        .build()
    {
        Ok(pool) => pool.scope(|s| {
            for _ in 0..workers {
                s.spawn(|_| worker());
            }
        }),
        // Without a pool of its own the sweep runs one job at a time on the global pool.
        Err(_) => worker(),
    }
    results.into_inner().unwrap_or_else(|e| e.into_inner())
}

/// One run, its outputs written under `keep_runs` when kept.
fn run_one(plan: &Plan, job: &Job, options: &SweepOptions) -> Result<Summary, JobError> {
    let run_options = RunOptions {
        renderer: options.renderer,
        shared_gpu: options.shared_gpu.clone(),
        truth: options.truth,
        ..RunOptions::default()
    };
    let keep = options
        .keep_runs
        .as_ref()
        .map(|d| d.join(job.dir_name(&plan.sets)));
    run_job(&job.scenario, &run_options, keep.as_deref())
}

/// Runs `scenario` as a sweep's job, its outputs written into `keep` when given: its summary,
/// or why it failed.
pub fn run_job(
    scenario: &Scenario,
    options: &RunOptions,
    keep: Option<&Path>,
) -> Result<Summary, JobError> {
    let out = run_scenario(scenario, options, |_| {}, |_, _| {})
        .map_err(|e| JobError::Run(Arc::new(e)))?;
    if let Some(dir) = keep {
        write_run(dir, scenario, &out).map_err(|e| JobError::Write(Arc::new(e)))?;
    }
    Ok(out.summary)
}
