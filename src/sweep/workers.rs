//! Running a plan's jobs on a pool of workers, one run each at a time, the CPU renderer's own
//! threads shared out so that the cores are not oversubscribed.

use super::{Job, Plan};
use crate::output::write_run;
use crate::record::Summary;
use crate::simulation::{RunOptions, run_scenario};
use omniloop_sim::RendererChoice;
use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// How a sweep runs.
#[derive(Debug, Clone)]
pub struct SweepOptions {
    /// Runs at a time.
    pub workers: usize,
    /// Threads of the CPU renderer within each run.
    pub render_threads: usize,
    /// The renderer of every run.
    pub renderer: RendererChoice,
    /// Where each run's own outputs go (`runs/` of the sweep), if kept.
    pub keep_runs: Option<PathBuf>,
}

impl SweepOptions {
    /// `workers` runs at a time (0: one a core) over `cores` cores.
    pub fn new(workers: usize, cores: usize, renderer: RendererChoice) -> Self {
        let cores = cores.max(1);
        let workers = if workers == 0 { cores } else { workers };
        Self {
            workers,
            render_threads: (cores / workers).max(1),
            renderer,
            keep_runs: None,
        }
    }
}

/// What became of one run.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The job's index in the plan.
    pub job: usize,
    /// Its summary, or the error that stopped it.
    pub result: Result<Summary, String>,
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
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Outcome>>> = Mutex::new(vec![None; plan.jobs.len()]);
    let workers = options.workers.clamp(1, plan.jobs.len().max(1));
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(options.render_threads)
                    .build();
                loop {
                    if stop.load(Ordering::SeqCst) {
                        break;
                    }
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(job) = plan.jobs.get(i) else { break };
                    let result = match &pool {
                        Ok(pool) => pool.install(|| run_one(plan, job, options)),
                        Err(e) => Err(format!("cannot start the renderer's threads: {e}")),
                    };
                    let outcome = Outcome { job: i, result };
                    done(&outcome);
                    results.lock().unwrap_or_else(|e| e.into_inner())[i] = Some(outcome);
                }
            });
        }
    });
    results.into_inner().unwrap_or_else(|e| e.into_inner())
}

/// One run, its outputs written under `keep_runs` when kept.
fn run_one(plan: &Plan, job: &Job, options: &SweepOptions) -> Result<Summary, String> {
    let run_options = RunOptions {
        renderer: options.renderer,
        ..RunOptions::default()
    };
    let out = run_scenario(&job.scenario, &run_options, |_| {}, |_, _| {})
        .map_err(|e| format!("{e:#}"))?;
    if let Some(dir) = &options.keep_runs {
        let dir = dir.join(job.dir_name(&plan.sets));
        write_run(&dir, &job.scenario, &out).map_err(|e| format!("{e:#}"))?;
    }
    Ok(out.summary)
}
