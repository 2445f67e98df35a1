//! `omniloop sweep`: parse the `--set`s, check every combination, run them on all cores with a
//! progress bar, write the table and the picture; Ctrl-C stops taking new runs and keeps what
//! finished (a second Ctrl-C quits at once).

use super::Exit;
use anyhow::Context;
use omniloop::sweep::{
    PlanError, Seeds, Set, SweepOptions, known_metric, plan, rows, run_jobs, shared_gpu,
    write_outputs,
};
use omniloop::{LoadError, report::default_out_dir};
use omniloop_sim::RendererChoice;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

/// The command's arguments.
pub struct Args {
    pub scenario: PathBuf,
    pub sets: Vec<String>,
    pub seeds: Seeds,
    pub jobs: usize,
    pub out: Option<PathBuf>,
    pub renderer: RendererChoice,
    pub plot: String,
    pub keep_runs: bool,
    pub quiet: bool,
}

/// Set by Ctrl-C: no new runs start.
static STOP: AtomicBool = AtomicBool::new(false);

fn parse_sets(args: &[String]) -> anyhow::Result<Vec<Set>> {
    let (sets, errors): (Vec<_>, Vec<_>) =
        args.iter().map(|a| Set::parse(a)).partition(Result::is_ok);
    if !errors.is_empty() {
        for e in errors.into_iter().filter_map(Result::err) {
            eprintln!("{e}");
        }
        return Err(Exit(2).into());
    }
    Ok(sets.into_iter().filter_map(Result::ok).collect())
}

/// Runs the sweep.
pub fn command(a: Args) -> anyhow::Result<()> {
    let sets = parse_sets(&a.sets)?;
    let plan = match plan(&a.scenario, &sets, &a.seeds) {
        Ok(p) => p,
        Err(PlanError::Scenario(e @ LoadError::Invalid { .. })) => {
            eprintln!("{e}");
            return Err(Exit(2).into());
        }
        Err(PlanError::Invalid(messages)) => {
            for m in messages.iter().take(12) {
                eprintln!("{m}");
            }
            if messages.len() > 12 {
                eprintln!("... and {} more", messages.len() - 12);
            }
            eprintln!("nothing was run");
            return Err(Exit(2).into());
        }
        Err(e) => return Err(e.into()),
    };
    let base = &plan.jobs[0].scenario;
    let dir = a.out.unwrap_or_else(|| {
        let d = default_out_dir(base);
        d.with_file_name(format!("{}_sweep", plan.name))
    });
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut options = SweepOptions::new(a.jobs, cores, a.renderer);
    options.keep_runs = a.keep_runs.then(|| dir.join("runs"));
    // One GPU for all runs, their frames traced in batches; kept alive for the whole sweep.
    let server = shared_gpu(a.renderer)?;
    options.shared_gpu = server.as_ref().map(|s| s.handle());
    let renderer = match &options.shared_gpu {
        Some(h) => h.name().to_string(),
        None => "cpu".to_string(),
    };
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let _ = ctrlc::set_handler(|| {
        if STOP.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("\nstopping after the runs under way (Ctrl-C again to quit now)");
    });
    let n = plan.jobs.len();
    let combos = plan.jobs.last().map_or(0, |j| j.combination + 1);
    let progress = super::styled_bar(
        n as u64,
        a.quiet,
        "{prefix} [{bar:40}] {pos}/{len} runs {msg} eta {eta}",
    );
    progress.set_prefix(plan.name.clone());
    let failed = AtomicUsize::new(0);
    let start = Instant::now();
    let outcomes = run_jobs(&plan, &options, &STOP, |o| {
        if let Err(e) = &o.result {
            let f = failed.fetch_add(1, Ordering::SeqCst) + 1;
            progress.set_message(format!("({f} failed)"));
            progress.println(format!("run {} failed: {e}", o.job));
        }
        progress.inc(1);
    });
    progress.finish_and_clear();
    let wall_s = start.elapsed().as_secs_f64();
    let ran = outcomes.iter().flatten().count();
    let rows = rows(&plan, &outcomes);
    let mut metric = a.plot.clone();
    if !known_metric(&rows, &metric) {
        eprintln!("--plot {metric}: no run has this number; plotting success_rate");
        metric = "success_rate".into();
    }
    let stopped = STOP.load(Ordering::SeqCst);
    let header = format!(
        "{ran} of {n} runs ({combos} combinations x {} seeds){}, {} at a time on {} threads, \
         renderer {renderer}: {wall_s:.1} s, {:.2} runs/s. Figure: sweep.png ({metric}).",
        n / combos.max(1),
        if stopped { ", stopped by Ctrl-C" } else { "" },
        options.workers.min(n),
        options.threads,
        ran as f64 / wall_s.max(1e-9),
    );
    let md = write_outputs(&dir, &plan, &rows, &metric, &header)?;
    print!("{md}");
    println!("\nwritten to {}", dir.display());
    if stopped {
        return Err(Exit(130).into());
    }
    Ok(())
}
