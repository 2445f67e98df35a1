//! `omniloop run`: a scenario headless (or a job of a sweep's plan), its files written, its
//! outcome printed; optionally recorded, served live, animated or paced to real time.

use super::{load, progress_bar, sweep};
use anyhow::{Context, bail};
use omniloop::experiments::registry::setup_of;
use omniloop::report::output::{default_out_dir, write_run};
use omniloop::run::observer::ObserverHandle;
use omniloop::run::{RunOptions, RunOutput};
use omniloop::viewing::{FoxgloveLog, GifLog, LiveOptions, RealTime, RobotCameras, Sinks};
use omniloop::{DEFAULT_SCENARIO, Scenario, run_scenario};
use omniloop_sim::RendererChoice;
use std::path::{Path, PathBuf};

/// `omniloop run`'s arguments.
#[derive(clap::Args)]
pub struct RunArgs {
    /// Scenario file.
    #[arg(required_unless_present_any = ["print_default", "plan"])]
    scenario: Option<PathBuf>,
    /// Run a job of a sweep's plan (`omniloop sweep --plan`) instead of a scenario file:
    /// its outputs go to `runs/NAME` beside the plan (or --out); a failed run leaves its
    /// error in `error.txt` there.
    #[arg(
        long,
        value_name = "FILE",
        requires = "job",
        conflicts_with = "scenario"
    )]
    plan: Option<PathBuf>,
    /// The plan's job to run (its index, from 0).
    #[arg(long, value_name = "N", requires = "plan")]
    job: Option<usize>,
    /// Output folder (default: runs/<scenario name>).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Seed overriding the scenario's.
    #[arg(long, conflicts_with = "plan")]
    seed: Option<u64>,
    /// Renderer for the sensors' images: auto, gpu or cpu.
    #[arg(long, default_value = "auto")]
    renderer: RendererChoice,
    /// Save every sensor's image to OUT/frames/ as `<sensor>_<cycle>.png`, beside
    /// trajectory.csv (row k is cycle k): every cycle, or every K cycles.
    #[arg(long, value_name = "K", num_args = 0..=1, default_missing_value = "1",
          value_parser = clap::value_parser!(u64).range(1..))]
    save_frames: Option<u64>,
    /// Trace each frame's truth beside it (the simulator's side; the robot never gets it):
    /// score the free space pixel by pixel (`floor_region` in estimates.jsonl,
    /// `floor_region_iou` in summary.json); with --save-frames, `<sensor>_<cycle>_depth.png`
    /// (16-bit, mm) and `_labels.png` (indexed, `legend.json`); with --mcap, the truth's
    /// channels.
    #[arg(long)]
    truth: bool,
    /// Record the run as MCAP (camera frames, true and estimated poses, the world, free
    /// space, commands, estimates) for Foxglove: into FILE, or OUT/run.mcap.
    #[arg(long, value_name = "FILE", num_args = 0..=1)]
    mcap: Option<Option<PathBuf>>,
    /// Serve the run live to the Foxglove app (WebSocket, the same channels as --mcap) on
    /// ADDR.
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:8765",
          value_parser = live_addr)]
    live: Option<String>,
    /// With --live: wait before the first cycle until a viewer subscribes.
    #[arg(long, requires = "live")]
    live_wait: bool,
    /// With --live: after the run, serve the viewers until they disconnect, at most S seconds.
    #[arg(long, value_name = "S", requires = "live", default_value_t = 2.0)]
    live_linger: f64,
    /// Pace the run to real time (each cycle waits for its simulation time on the clock).
    #[arg(long)]
    realtime: bool,
    /// Write an animated GIF of the run (each camera beside the top view with the paths so
    /// far): into FILE, or OUT/run.gif.
    #[arg(long, value_name = "FILE", num_args = 0..=1)]
    gif: Option<Option<PathBuf>>,
    /// The GIF shows every K-th cycle.
    #[arg(long, value_name = "K", default_value_t = 5,
          value_parser = clap::value_parser!(u64).range(1..))]
    gif_every: u64,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
    /// Print a complete, commented example scenario and exit.
    #[arg(long)]
    print_default: bool,
}

/// `omniloop run`: the default scenario printed, a planned job run, or the scenario run and
/// its files written into `--out`.
pub fn run_cmd(args: RunArgs) -> anyhow::Result<()> {
    if args.print_default {
        print!("{DEFAULT_SCENARIO}");
        return Ok(());
    }
    if let (Some(plan), Some(job)) = (&args.plan, args.job) {
        return sweep::run_planned(plan, job, args.out, args.renderer);
    }
    let Some(path) = &args.scenario else {
        bail!("omniloop run needs a scenario file (or --print-default)");
    };
    let mut s = load(path)?;
    if let Some(seed) = args.seed {
        s.seed = seed;
    }
    let dir = args.out.clone().unwrap_or_else(|| default_out_dir(&s));
    let log = start_log(&s, &sinks(&args, &dir))?;
    let gif = args.gif.clone().map(|f| {
        (
            f.unwrap_or_else(|| dir.join("run.gif")),
            GifLog::new(args.gif_every),
        )
    });
    let observers = log
        .iter()
        .map(FoxgloveLog::observer)
        .chain(gif.iter().map(|(_, g)| g.observer()))
        .chain(
            args.realtime
                .then(|| ObserverHandle::new(RealTime::default())),
        )
        .collect();
    let options = RunOptions {
        renderer: args.renderer,
        save_frames_every: args.save_frames,
        frames_dir: args.save_frames.map(|_| dir.join("frames")),
        truth: args.truth,
        observers,
        ..RunOptions::default()
    };
    let bar = progress_bar(s.max_cycles(), args.quiet);
    bar.set_prefix(s.name.clone());
    let output = run_scenario(
        &s,
        &options,
        |msg| eprintln!("{msg}"),
        |k, _| bar.set_position(k),
    )
    .with_context(|| format!("running {}", path.display()))?;
    bar.finish_and_clear();
    write_outputs(&dir, &s, &output, log, gif)?;
    print_outcome(&s, &output.summary, &dir);
    Ok(())
}

/// Where the run is recorded (`--mcap`, default `dir/run.mcap`) and served (`--live`).
fn sinks(args: &RunArgs, dir: &Path) -> Sinks {
    Sinks {
        mcap: args
            .mcap
            .clone()
            .map(|f| f.unwrap_or_else(|| dir.join("run.mcap"))),
        live: args.live.clone().map(|addr| LiveOptions {
            addr,
            wait_for_viewer: args.live_wait,
            linger_s: args.live_linger,
        }),
    }
}

/// The run's files into `dir`, then its Foxglove recording and its GIF when asked.
fn write_outputs(
    dir: &Path,
    s: &Scenario,
    output: &RunOutput,
    log: Option<FoxgloveLog>,
    gif: Option<(PathBuf, GifLog)>,
) -> anyhow::Result<()> {
    write_run(dir, s, output)?;
    if let Some(log) = log
        && let Some(file) = log.finish(&output.summary)?
    {
        eprintln!("recorded {}", file.display());
    }
    if let Some((file, g)) = gif {
        let n = g.write(&file, s, output)?;
        eprintln!("animated {} ({n} frames)", file.display());
    }
    Ok(())
}

/// The experiment's table of the run, or the outcome in a line; and where the files are.
fn print_outcome(s: &Scenario, m: &omniloop::run::Summary, dir: &Path) {
    let experiment = setup_of(s).ok().flatten();
    if let Some(table) = experiment.and_then(|e| e.table(m)) {
        print!("{table}");
        println!("results in {}", dir.display());
        return;
    }
    println!("{}; results in {}", outcome_line(m), dir.display());
}

/// A `--live` address, `HOST:PORT`, checked before the run.
fn live_addr(addr: &str) -> Result<String, omniloop::viewing::AddressError> {
    let options = LiveOptions {
        addr: addr.to_string(),
        ..LiveOptions::default()
    };
    options.host_port().map(|_| options.addr)
}

/// What a run came to, in a line: the one robot's goal, contacts and clearance, or a team's
/// arrivals, contacts by kind and the least clearance between two robots.
fn outcome_line(m: &omniloop::run::Summary) -> String {
    let head = format!(
        "{}: {} cycles, {:.2} s simulated in {:.2} s ({:.0} cycles/s)",
        m.scenario, m.cycles, m.sim_time_s, m.wall_time_s, m.cycles_per_s
    );
    let Some(t) = &m.team else {
        let goal = match m.time_to_goal_s {
            Some(t) => format!("reached at {t:.2} s"),
            None => "not reached".into(),
        };
        return format!(
            "{head}; goal {goal}; contacts {}; min clearance {:.1} mm",
            m.wall_contacts, m.min_clearance_mm
        );
    };
    let last = match (t.last_arrival_s, t.straight_line_time_s) {
        (Some(a), Some(s)) => format!(", the last at {a:.2} s (straight lines: {s:.2} s)"),
        _ => String::new(),
    };
    format!(
        "{head}, {} robots; {} of {} arrived{last}; contacts {} (with robots {}); least \
         clearance between robots {:.1} mm",
        t.robots,
        t.arrived,
        t.with_goal,
        m.wall_contacts,
        t.robot_contacts,
        t.min_robot_clearance_mm
    )
}

/// The run's Foxglove log, when it is recorded or served; a live server says where it is and,
/// when asked, waits for a viewer.
pub(super) fn start_log(s: &Scenario, sinks: &Sinks) -> anyhow::Result<Option<FoxgloveLog>> {
    if sinks.mcap.is_none() && sinks.live.is_none() {
        return Ok(None);
    }
    let team = s.is_team();
    let robots: Vec<RobotCameras> = s
        .members()
        .iter()
        .zip(s.robot_names())
        .map(|(m, name)| RobotCameras {
            robot: team.then_some(name),
            sensors: m.robot.sensors.iter().map(|c| c.name.clone()).collect(),
        })
        .collect();
    let log = FoxgloveLog::create(sinks, &robots)?;
    if let Some(live) = log.live() {
        eprintln!(
            "serving the run live on ws://{}:{} (Foxglove: Open connection)",
            live.host(),
            live.port()
        );
        if live.waits_for_viewer() {
            eprintln!("waiting for a viewer to subscribe...");
            live.wait_for_viewer();
        }
    }
    Ok(Some(log))
}
