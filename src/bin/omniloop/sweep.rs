//! `omniloop sweep`: parse the `--set`s, check every combination, run them on all cores with a
//! progress bar, write the table and the picture; Ctrl-C stops taking new runs and keeps what
//! finished (a second Ctrl-C quits at once), `--resume` goes on from what finished. `--plan`
//! writes the jobs for another engine instead, `--collect` reports on their runs.

use super::Exit;
use anyhow::Context;
use omniloop::RunOptions;
use omniloop::sweep::journal::ERROR_FILE;
use omniloop::sweep::{
    Journal, Outcome, Plan, PlanError, PlanFileError, Record, ReportSettings, Seeds, Set,
    SweepOptions, collect_runs, plan, planned_job, read_plan, run_job, run_remaining, shared_gpu,
    write_plan,
};
use omniloop::{LoadError, report::default_out_dir};
use omniloop_sim::RendererChoice;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

/// `omniloop sweep`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// Scenario file.
    #[arg(required_unless_present = "collect")]
    scenario: Option<PathBuf>,
    /// A dotted key of the scenario and its values: TOML literals, bare words for strings,
    /// ranges A..B:STEP (ends included); array items as `name[2].key`. Repeat for a grid.
    #[arg(long = "set", value_name = "KEY=V1,V2,...")]
    sets: Vec<String>,
    /// Seeds of each combination: N (the scenario's seed and the N - 1 after it) or A..B.
    #[arg(long, default_value = "1")]
    seeds: Seeds,
    /// Runs at a time (default: one a core); the CPU renderer shares the cores among them.
    #[arg(long, default_value_t = 0)]
    jobs: usize,
    /// Output folder (default: runs/<scenario name>_sweep).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Renderer for the sensors' images: auto, gpu or cpu.
    #[arg(long, default_value = "auto")]
    renderer: RendererChoice,
    /// The metric of sweep.png: success_rate or a column of sweep.csv.
    #[arg(long, default_value = "success_rate")]
    plot: String,
    /// Keep each run's own outputs in OUT/runs/.
    #[arg(long)]
    keep_runs: bool,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
    /// Write every job (its values, seed, output name, scenario) as JSON lines into FILE
    /// (default OUT/plan.jsonl) and run nothing: run job N with `omniloop run --plan FILE
    /// --job N`, then report with --collect.
    #[arg(long, value_name = "FILE", num_args = 0..=1, conflicts_with = "resume")]
    plan: Option<Option<PathBuf>>,
    /// Build sweep.csv, sweep.md and sweep.png of DIR/plan.jsonl (or of the plan file DIR,
    /// beside it) from its runs' folders in DIR/runs/ (as `omniloop run --plan` leaves them).
    #[arg(long, value_name = "DIR", conflicts_with_all = ["plan", "resume"])]
    collect: Option<PathBuf>,
    /// Go on with the sweep in OUT: the jobs OUT/rows.jsonl has are not run again.
    #[arg(long)]
    resume: bool,
    /// sweep.md's outcomes: goals reachable on the true world with at least this margin
    /// (mm) count for success, the others for honesty (reached or reported unreachable).
    #[arg(long, value_name = "MM", default_value_t = omniloop::sweep::DEFAULT_REACHABLE_MARGIN_MM, value_parser = margin_mm)]
    reachable_margin_mm: f64,
}

impl Args {
    /// What sweep.md is asked for (the margin of goals counted for success).
    fn report(&self) -> ReportSettings {
        ReportSettings {
            reachable_margin_mm: self.reachable_margin_mm,
        }
    }
}

/// A margin in mm: a finite number >= 0.
fn margin_mm(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("`{text}` is not a margin (a number of mm >= 0)")),
    }
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

/// The sweep's plan, or exit 2 with every problem.
fn checked_plan(scenario: &std::path::Path, sets: &[Set], seeds: &Seeds) -> anyhow::Result<Plan> {
    match plan(scenario, sets, seeds) {
        Ok(p) => Ok(p),
        Err(PlanError::Scenario(e @ LoadError::Invalid { .. })) => {
            eprintln!("{e}");
            Err(Exit(2).into())
        }
        Err(PlanError::Invalid(messages)) => {
            for m in messages.iter().take(12) {
                eprintln!("{m}");
            }
            if messages.len() > 12 {
                eprintln!("... and {} more", messages.len() - 12);
            }
            eprintln!("nothing was run");
            Err(Exit(2).into())
        }
        Err(e) => Err(e.into()),
    }
}

/// Runs the sweep, writes its plan, or collects its runs.
pub fn sweep_cmd(a: Args) -> anyhow::Result<()> {
    if let Some(dir) = &a.collect {
        return collect(dir, &a.plot, &a.report());
    }
    let Some(scenario) = &a.scenario else {
        anyhow::bail!("omniloop sweep needs a scenario file (or --collect DIR)");
    };
    let sets = parse_sets(&a.sets)?;
    let plan = checked_plan(scenario, &sets, &a.seeds)?;
    let base = &plan.jobs[0].scenario;
    let dir = a.out.clone().unwrap_or_else(|| {
        let d = default_out_dir(base);
        d.with_file_name(format!("{}_sweep", plan.name))
    });
    if let Some(file) = &a.plan {
        let file = file.clone().unwrap_or_else(|| dir.join("plan.jsonl"));
        write_plan(&plan, &a.seeds, &file)?;
        let runs = file
            .parent()
            .unwrap_or(std::path::Path::new("."))
            .join("runs");
        println!(
            "{} jobs planned in {}: run job N with `omniloop run --plan {} --job N` (into {}), \
             then `omniloop sweep --collect {}`",
            plan.jobs.len(),
            file.display(),
            file.display(),
            runs.join("NAME").display(),
            file.parent().unwrap_or(std::path::Path::new(".")).display()
        );
        return Ok(());
    }
    run_sweep(&a, &plan, &dir)
}

/// Runs `plan` into `dir`: its plan and journal first, every run on the pool, the report.
fn run_sweep(a: &Args, plan: &Plan, dir: &std::path::Path) -> anyhow::Result<()> {
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
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    write_plan(plan, &a.seeds, &dir.join("plan.jsonl"))?;
    let (journal, previous) = Journal::open(dir, plan, a.resume)?;
    let skipped = previous.iter().flatten().count();
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
    progress.set_position(skipped as u64);
    let failed = AtomicUsize::new(0);
    let start = Instant::now();
    let outcomes = run_remaining(plan, &options, &STOP, previous, |o: &Outcome| {
        let job = &plan.jobs[o.job];
        if let Err(e) = journal.record(&Record::new(o, &job.dir_name(&plan.sets), job.seed)) {
            progress.println(format!("{e}"));
        }
        if let Err(e) = &o.result {
            let f = failed.fetch_add(1, Ordering::SeqCst) + 1;
            progress.set_message(format!("({f} failed)"));
            progress.println(format!("run {} failed: {e}", o.job));
        }
        progress.inc(1);
    });
    progress.finish_and_clear();
    let wall_s = start.elapsed().as_secs_f64();
    let ran = outcomes.iter().flatten().count() - skipped;
    let stopped = STOP.load(Ordering::SeqCst);
    let header = format!(
        "{ran} of {n} runs ({combos} combinations x {} seeds){}{}, {} at a time on {} threads, \
         renderer {renderer}: {wall_s:.1} s, {:.2} runs/s.",
        n / combos.max(1),
        if skipped > 0 {
            format!(", {skipped} more from the sweep resumed")
        } else {
            String::new()
        },
        if stopped { ", stopped by Ctrl-C" } else { "" },
        options.workers.min(n),
        options.threads,
        ran as f64 / wall_s.max(1e-9),
    );
    report(dir, plan, &outcomes, &a.plot, &header, &a.report())?;
    if stopped {
        return Err(Exit(130).into());
    }
    Ok(())
}

/// `sweep.csv`, `sweep.md` (as `settings` ask) and `sweep.png` of `outcomes` into `dir`; the
/// table printed.
fn report(
    dir: &std::path::Path,
    plan: &Plan,
    outcomes: &[Option<Outcome>],
    plot: &str,
    header: &str,
    settings: &ReportSettings,
) -> anyhow::Result<()> {
    let (md, _) = omniloop::sweep::write_report_with(dir, plan, outcomes, plot, header, settings)?;
    print!("{md}");
    println!("\nwritten to {}", dir.display());
    Ok(())
}

/// `--collect DIR`: the report of `DIR/plan.jsonl`'s jobs from their folders in `DIR/runs/`,
/// into DIR (DIR may be the plan file itself, its folder then), as `settings` ask.
fn collect(path: &std::path::Path, plot: &str, settings: &ReportSettings) -> anyhow::Result<()> {
    let (file, dir) = if path.is_file() {
        let dir = path.parent().unwrap_or(std::path::Path::new("."));
        (path.to_path_buf(), dir.to_path_buf())
    } else {
        (path.join("plan.jsonl"), path.to_path_buf())
    };
    let dir = dir.as_path();
    let (plan, _) = read_plan(&file)?;
    let outcomes = collect_runs(&dir.join("runs"), &plan)?;
    let found = outcomes.iter().flatten().count();
    let failed = outcomes
        .iter()
        .flatten()
        .filter(|o| o.result.is_err())
        .count();
    let header = format!(
        "{found} of {} runs collected from {} ({failed} failed).",
        plan.jobs.len(),
        dir.join("runs").display()
    );
    report(dir, &plan, &outcomes, plot, &header, settings)
}

/// `omniloop run --plan FILE --job N`: the job's run, its outputs into `out` (default
/// `runs/NAME` beside the plan); a failed run leaves `error.txt` there instead of a summary.
pub fn run_planned(
    file: &std::path::Path,
    index: usize,
    out: Option<PathBuf>,
    renderer: RendererChoice,
) -> anyhow::Result<()> {
    let (job, scenario) = match planned_job(file, index) {
        Ok(j) => j,
        Err(e @ PlanFileError::Line { .. }) => {
            eprintln!("{e}");
            return Err(Exit(2).into());
        }
        Err(e) => return Err(e.into()),
    };
    let dir = out.unwrap_or_else(|| {
        let base = file.parent().unwrap_or(std::path::Path::new("."));
        base.join("runs").join(&job.name)
    });
    let (summary, error) = (dir.join("summary.json"), dir.join(ERROR_FILE));
    let _ = std::fs::remove_file(&error);
    let options = RunOptions {
        renderer,
        ..RunOptions::default()
    };
    match run_job(&scenario, &options, Some(&dir)) {
        Ok(m) => {
            println!(
                "job {index} ({}): {} cycles; goal {}; contacts {}; results in {}",
                job.name,
                m.cycles,
                if m.reached_goal {
                    "reached"
                } else {
                    "not reached"
                },
                m.wall_contacts,
                dir.display()
            );
            Ok(())
        }
        Err(e) => {
            let _ = std::fs::remove_file(&summary);
            std::fs::create_dir_all(&dir)
                .and_then(|()| std::fs::write(&error, format!("{e}\n")))
                .with_context(|| format!("writing {}", error.display()))?;
            anyhow::bail!("job {index} ({}) failed: {e}", job.name)
        }
    }
}
