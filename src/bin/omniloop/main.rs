//! The `omniloop` command line.

use anyhow::{Context, bail};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use nalgebra::{Isometry2, Vector2};
use omniloop::dataset::{DatasetOptions, PoseMode, write_dataset};
use omniloop::experiments::registry::setup_of;
use omniloop::experiments::{ReplayContext, parse_scenario, run_dyn};
use omniloop::replays::{REPLAYS, replay};
use omniloop::report::output::{default_out_dir, write_run};
use omniloop::run::observer::ObserverHandle;
use omniloop::run::{RunOptions, render_snapshot, render_snapshot_truth, truth_files};
use omniloop::scenario::calibrate::calibrate_sensor;
use omniloop::scenario::camera_export::{CameraFormat, export_camera_model};
use omniloop::sweep::Seeds;
use omniloop::viewing::{FoxgloveLog, GifLog, LiveOptions, RealTime, RobotCameras, Sinks};
use omniloop::{DEFAULT_SCENARIO, LoadError, Scenario, load_scenario, run_scenario};
use omniloop_sim::render::TruthFrame;
use omniloop_sim::{Renderer, RendererChoice, SensorSpec};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "omniloop",
    version,
    about = "Closed-loop testbed for omnidirectional robots with catadioptric vision"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Validate scenario files; exits 2 naming file, line, column and field of each problem.
    Check {
        /// Scenario files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Run a scenario headless and write summary.json, trajectory.csv and topview.png.
    Run {
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
    },
    /// Render one frame of a sensor to a PNG.
    Render(RenderArgs),
    /// Replay an experiment of the papers (`--list` shows them).
    Replay {
        /// The experiment (without one, the list).
        experiment: Option<String>,
        /// List the experiments and exit.
        #[arg(long)]
        list: bool,
        /// Output folder (default: runs/<experiment>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Seed overriding the scenarios'.
        #[arg(long)]
        seed: Option<u64>,
        /// Renderer for the sensors' images: auto, gpu or cpu.
        #[arg(long, default_value = "auto")]
        renderer: RendererChoice,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Run a scenario over a grid of values and seeds in parallel: sweep.csv, sweep.md, sweep.png.
    Sweep {
        /// Scenario file.
        #[arg(required_unless_present = "collect")]
        scenario: Option<PathBuf>,
        /// A dotted key of the scenario and its values: TOML literals, bare words for strings,
        /// ranges A..B:STEP (ends included); array items as `name[2].key`. Repeat for a grid.
        #[arg(long = "set", value_name = "KEY=V1,V2,...")]
        set: Vec<String>,
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
    },
    /// Write frames of a camera with their truth (depth, labels, poses) and the camera model,
    /// for training and evaluating perception (docs/truth.md).
    Dataset(DatasetArgs),
    /// Trace a mirror sensor's image-to-floor map r = f(R) and write it for the vision crate;
    /// with --format, fit a standard camera model to its rays and write that tool's file.
    Calibrate {
        /// Scenario file.
        scenario: PathBuf,
        /// Sensor name (default: the robot's first sensor).
        #[arg(long)]
        sensor: Option<String>,
        /// Camera model file to write instead: opencv-omnidir or kalibr-omni (Mei's unified
        /// model), ocamcalib (Scaramuzza's polynomial) or kalibr-ds (double sphere);
        /// docs/camera-models.md.
        #[arg(long, value_parser = camera_format)]
        format: Option<CameraFormat>,
        /// Output file (default: runs/<scenario name>/calibration_<sensor>.json, or
        /// camera_<sensor>_<format>.yaml (.txt for ocamcalib) with --format; the model's pose
        /// as JSON beside it).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// `omniloop render`'s arguments.
#[derive(clap::Args)]
struct RenderArgs {
    /// Scenario file.
    scenario: PathBuf,
    /// Robot pose `x_mm,y_mm,theta_deg` (default: the scenario's start).
    #[arg(long, allow_hyphen_values = true)]
    pose: Option<String>,
    /// Output PNG.
    #[arg(long)]
    out: PathBuf,
    /// Sensor name (default: the robot's first sensor).
    #[arg(long)]
    sensor: Option<String>,
    /// Renderer: auto, gpu or cpu.
    #[arg(long, default_value = "auto")]
    renderer: RendererChoice,
    /// Leave out the sensor noise.
    #[arg(long)]
    no_noise: bool,
    /// Write the frame's truth beside it: OUT's stem with `_depth.png` (16-bit, mm),
    /// `_labels.png` (indexed) and `_legend.json`.
    #[arg(long)]
    truth: bool,
}

/// `omniloop dataset`'s arguments.
#[derive(clap::Args)]
struct DatasetArgs {
    /// Scenario file.
    scenario: PathBuf,
    /// Frames to write.
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u64).range(1..))]
    samples: u64,
    /// Where the poses come from: random (over the floor, clear of everything) or
    /// along-run (the scenario's own run).
    #[arg(long, default_value = "random")]
    poses: PoseMode,
    /// Camera (default: the one vision uses, else the robot's first).
    #[arg(long)]
    sensor: Option<String>,
    /// Output folder (default: runs/<scenario name>/dataset).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Seed overriding the scenario's.
    #[arg(long)]
    seed: Option<u64>,
    /// Renderer: auto, gpu or cpu.
    #[arg(long, default_value = "cpu")]
    renderer: RendererChoice,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

mod sweep;

/// A camera model format by its command-line name.
/// A `--live` address, `HOST:PORT`, checked before the run.
fn live_addr(addr: &str) -> Result<String, String> {
    let options = LiveOptions {
        addr: addr.to_string(),
        ..LiveOptions::default()
    };
    options
        .host_port()
        .map(|_| options.addr)
        .map_err(|e| e.to_string())
}

/// A margin in mm: a finite number >= 0.
fn margin_mm(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("`{text}` is not a margin (a number of mm >= 0)")),
    }
}

fn camera_format(name: &str) -> Result<CameraFormat, String> {
    CameraFormat::ALL
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, f)| *f)
        .ok_or_else(|| {
            let names: Vec<&str> = CameraFormat::ALL.iter().map(|(n, _)| *n).collect();
            format!(
                "unknown camera model format {name:?} (one of: {})",
                names.join(", ")
            )
        })
}

/// Fits `format`'s model to `spec`'s rays, writes it to `out` and its pose as JSON beside it,
/// and prints the fit's residual.
fn write_camera_model(spec: &SensorSpec, format: CameraFormat, out: &Path) -> anyhow::Result<()> {
    let e = export_camera_model(spec, format)?;
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
    }
    std::fs::write(out, &e.text).with_context(|| format!("writing {}", out.display()))?;
    let json_path = out.with_extension("json");
    let json = serde_json::to_string_pretty(&e.json)?;
    std::fs::write(&json_path, json + "\n")
        .with_context(|| format!("writing {}", json_path.display()))?;
    println!(
        "sensor {} as {} ({}): reprojection RMS {:.4} px, worst {:.4} px over {} rays; rays \
         within {:.3} mm of the viewpoint",
        spec.name,
        format.name(),
        e.model.summary(),
        e.residual.rms_px,
        e.residual.worst_px,
        e.residual.count,
        e.viewpoint_spread_mm
    );
    println!("wrote {} and {}", out.display(), json_path.display());
    let t = e.pose.translation_mm.map(|v| (v * 1e6).round() / 1e6 + 0.0);
    let circle = e
        .image_circle_px
        .map_or(String::new(), |r| format!("\nimage_circle_px = {r:.4}"));
    println!(
        "as a sensor of a scenario (file relative to the scenario):\n\
         [robot.sensors.calibrated]\nfile = {:?}\nformat = \"{}\"\n\
         translation_mm = [{:?}, {:?}, {:?}]{circle}",
        out.display().to_string(),
        format.name(),
        t.x,
        t.y,
        t.z
    );
    Ok(())
}

/// An error that makes the command exit with a given code.
#[derive(Debug)]
struct Exit(u8);

impl std::fmt::Display for Exit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "exit {}", self.0)
    }
}
impl std::error::Error for Exit {}

fn load(path: &Path) -> anyhow::Result<Scenario> {
    match load_scenario(path) {
        Ok(s) => Ok(s),
        Err(e @ LoadError::Invalid { .. }) => {
            eprintln!("{e}");
            Err(Exit(2).into())
        }
        Err(e) => Err(e.into()),
    }
}

fn progress_bar(total: u64, quiet: bool) -> ProgressBar {
    styled_bar(
        total,
        quiet,
        "{prefix} [{bar:40}] {pos}/{len} cycles {per_sec} eta {eta}",
    )
}

/// A progress bar drawn with `template` on a terminal, hidden otherwise or when `quiet`.
fn styled_bar(total: u64, quiet: bool, template: &str) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
    }
    let bar = ProgressBar::new(total);
    // The templates are the program's own; one that does not parse keeps the default style.
    if let Ok(style) = ProgressStyle::with_template(template) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

fn parse_pose(text: &str) -> anyhow::Result<Isometry2<f64>> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let nums: Result<Vec<f64>, _> = parts.iter().map(|p| p.parse::<f64>()).collect();
    match nums {
        Ok(v) if v.len() == 3 && v.iter().all(|x| x.is_finite()) => {
            Ok(Isometry2::new(Vector2::new(v[0], v[1]), v[2].to_radians()))
        }
        _ => bail!("--pose {text:?}: expected x_mm,y_mm,theta_deg, e.g. --pose -900,0,45"),
    }
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
fn start_log(s: &Scenario, sinks: &Sinks) -> anyhow::Result<Option<FoxgloveLog>> {
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

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Check { files } => {
            let mut bad = false;
            for f in &files {
                match load_scenario(f) {
                    Ok(s) => println!("{}: ok ({})", f.display(), s.name),
                    Err(e) => {
                        eprintln!("{e}");
                        bad = true;
                    }
                }
            }
            if bad {
                return Err(Exit(2).into());
            }
            Ok(())
        }
        Command::Run {
            scenario,
            plan,
            job,
            out,
            seed,
            renderer,
            save_frames,
            truth,
            mcap,
            live,
            live_wait,
            live_linger,
            realtime,
            gif,
            gif_every,
            quiet,
            print_default,
        } => {
            if print_default {
                print!("{DEFAULT_SCENARIO}");
                return Ok(());
            }
            if let (Some(plan), Some(job)) = (&plan, job) {
                return sweep::run_planned(plan, job, out, renderer);
            }
            let Some(path) = scenario else {
                bail!("omniloop run needs a scenario file (or --print-default)");
            };
            let mut s = load(&path)?;
            if let Some(seed) = seed {
                s.seed = seed;
            }
            let dir = out.unwrap_or_else(|| default_out_dir(&s));
            let sinks = Sinks {
                mcap: mcap.map(|f| f.unwrap_or_else(|| dir.join("run.mcap"))),
                live: live.map(|addr| LiveOptions {
                    addr,
                    wait_for_viewer: live_wait,
                    linger_s: live_linger,
                }),
            };
            let log = start_log(&s, &sinks)?;
            let gif = gif.map(|f| {
                (
                    f.unwrap_or_else(|| dir.join("run.gif")),
                    GifLog::new(gif_every),
                )
            });
            let observers = log
                .iter()
                .map(FoxgloveLog::observer)
                .chain(gif.iter().map(|(_, g)| g.observer()))
                .chain(realtime.then(|| ObserverHandle::new(RealTime::default())))
                .collect();
            let options = RunOptions {
                renderer,
                save_frames_every: save_frames,
                frames_dir: save_frames.map(|_| dir.join("frames")),
                truth,
                observers,
                ..RunOptions::default()
            };
            let bar = progress_bar(s.max_cycles(), quiet);
            bar.set_prefix(s.name.clone());
            let output = run_scenario(
                &s,
                &options,
                |msg| eprintln!("{msg}"),
                |k, _| bar.set_position(k),
            )
            .with_context(|| format!("running {}", path.display()))?;
            bar.finish_and_clear();
            write_run(&dir, &s, &output)?;
            if let Some(log) = log
                && let Some(file) = log.finish(&output.summary)?
            {
                eprintln!("recorded {}", file.display());
            }
            if let Some((file, g)) = gif {
                let n = g.write(&file, &s, &output)?;
                eprintln!("animated {} ({n} frames)", file.display());
            }
            let m = &output.summary;
            let experiment = setup_of(&s).ok().flatten();
            if let Some(table) = experiment.and_then(|e| e.table(m)) {
                print!("{table}");
                println!("results in {}", dir.display());
                return Ok(());
            }
            println!("{}; results in {}", outcome_line(m), dir.display());
            Ok(())
        }
        Command::Render(args) => render(args),
        Command::Replay {
            experiment,
            list,
            out,
            seed,
            renderer,
            quiet,
        } => {
            let listing = || -> String {
                REPLAYS
                    .iter()
                    .map(|r| format!("  {:<10} {}", r.name, r.title))
                    .collect::<Vec<_>>()
                    .join("\n")
            };
            let name = match experiment {
                Some(name) if !list => name,
                _ => {
                    println!("{}", listing());
                    return Ok(());
                }
            };
            let Some(r) = replay(&name) else {
                bail!("unknown experiment {name:?}; known:\n{}", listing());
            };
            let dir = out.unwrap_or_else(|| PathBuf::from("runs").join(r.name));
            let options = RunOptions {
                renderer,
                ..RunOptions::default()
            };
            let bar = progress_bar(0, quiet);
            let mut progress = |name: &str, k: u64, n: u64| {
                bar.set_length(n);
                bar.set_prefix(name.to_string());
                bar.set_position(k);
            };
            let mut notice = |msg: &str| eprintln!("{msg}");
            let table = (r.run)(&mut ReplayContext {
                out: &dir,
                options: &options,
                seed,
                progress: &mut progress,
                notice: &mut notice,
                load: parse_scenario,
                run: run_dyn,
            })?;
            bar.finish_and_clear();
            print!("{table}");
            println!("\nwritten to {}", dir.display());
            Ok(())
        }
        Command::Sweep {
            scenario,
            set,
            seeds,
            jobs,
            out,
            renderer,
            plot,
            keep_runs,
            quiet,
            plan,
            collect,
            resume,
            reachable_margin_mm,
        } => sweep::command(sweep::Args {
            scenario,
            sets: set,
            seeds,
            jobs,
            out,
            renderer,
            plot,
            keep_runs,
            quiet,
            plan,
            collect,
            resume,
            report: omniloop::sweep::ReportSettings {
                reachable_margin_mm,
            },
        }),
        Command::Dataset(args) => dataset(args),
        Command::Calibrate {
            scenario,
            sensor,
            format,
            out,
        } => {
            let s = load(&scenario)?;
            let spec = match s.sensor(sensor.as_deref()) {
                Ok(spec) => spec,
                Err(e) => bail!("scenario {:?}: {e}", s.name),
            };
            if let Some(format) = format {
                let out = out.unwrap_or_else(|| {
                    let ext = if format == CameraFormat::Ocamcalib {
                        "txt"
                    } else {
                        "yaml"
                    };
                    default_out_dir(&s).join(format!(
                        "camera_{}_{}.{ext}",
                        spec.name,
                        format.name()
                    ))
                });
                return write_camera_model(spec, format, &out);
            }
            let cal = calibrate_sensor(spec)?;
            let out = out.unwrap_or_else(|| {
                default_out_dir(&s).join(format!("calibration_{}.json", spec.name))
            });
            if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
                std::fs::create_dir_all(parent)
                    .with_context(|| format!("creating {}", parent.display()))?;
            }
            cal.save(&out)?;
            if cal.samples.is_empty() {
                println!(
                    "sensor {}: sees no floor along its image x axis (no floor map)",
                    spec.name
                );
            } else {
                println!(
                    "sensor {}: {} samples every 0.25 px, floor horizon at R = {:.2} px",
                    spec.name,
                    cal.samples.len(),
                    cal.horizon_px
                );
            }
            if let (Some(first), Some(last)) = (cal.elevation.first(), cal.elevation.last()) {
                println!(
                    "elevation of the scene rays: {:.1} deg at R = 0 to {:.1} deg at R = {:.1} px",
                    first[1].to_degrees(),
                    last[1].to_degrees(),
                    last[0]
                );
            }
            if let Some(f) = &cal.fit {
                println!(
                    "f(R) = R / (A - B sqrt(C + R^2)), fitted for R <= {:.1} px:",
                    0.95 * cal.horizon_px
                );
                println!("A= {:.4}", f.a);
                println!("B= {:.4e}", f.b);
                println!("C= {:.4e}", f.c);
                println!("rms residual {:.2e} mm", f.rms_mm);
            }
            println!("written to {}", out.display());
            Ok(())
        }
    }
}

/// Mesa's Vulkan driver complains on every start when `XDG_RUNTIME_DIR` is unset (headless
/// machines, CI): give it a private folder so the terminal shows only what matters.
fn quiet_mesa() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_some() {
        return;
    }
    let user = std::env::var("USER").unwrap_or_else(|_| "user".into());
    let dir = std::env::temp_dir().join(format!("omniloop-runtime-{user}"));
    if std::fs::create_dir_all(&dir).is_ok() {
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let _ = std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700));
        }
        // SAFETY: called first thing in main, before any other thread exists.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
    }
}

fn main() -> ExitCode {
    quiet_mesa();
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if let Some(Exit(code)) = e.downcast_ref::<Exit>() {
                return ExitCode::from(*code);
            }
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Writes a snapshot's truth beside its image `out`: `STEM_depth.png`, `STEM_labels.png` and
/// `STEM_legend.json`; returns the files.
fn write_snapshot_truth(out: &Path, truth: &TruthFrame) -> anyhow::Result<Vec<PathBuf>> {
    let dir = out.parent().unwrap_or(Path::new(""));
    let stem = out
        .file_stem()
        .map_or("frame".into(), |s| s.to_string_lossy().into_owned());
    truth_files::write_truth(dir, &stem, truth)?;
    let legend = dir.join(format!("{stem}_legend.json"));
    truth_files::write_legend(&legend, truth)?;
    Ok(["depth.png", "labels.png"]
        .iter()
        .map(|k| dir.join(format!("{stem}_{k}")))
        .chain([legend])
        .collect())
}

/// The bytes of every file under `dir`.
fn folder_bytes(dir: &Path) -> u64 {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .flatten()
        .map(|e| match e.file_type() {
            Ok(t) if t.is_dir() => folder_bytes(&e.path()),
            _ => e.metadata().map_or(0, |m| m.len()),
        })
        .sum()
}

/// `omniloop render`: one frame of a sensor, with its truth when asked.
fn render(args: RenderArgs) -> anyhow::Result<()> {
    let RenderArgs {
        scenario,
        pose,
        out,
        sensor,
        renderer,
        no_noise,
        truth,
    } = args;
    let s = load(&scenario)?;
    let pose = pose.as_deref().map(parse_pose).transpose()?;
    let mut r = Renderer::new(renderer, |msg| eprintln!("{msg}"))?;
    let (img, truth) = if truth {
        let (img, t) = render_snapshot_truth(&s, &mut r, sensor.as_deref(), pose, !no_noise)?;
        (img, Some(t))
    } else {
        (
            render_snapshot(&s, &mut r, sensor.as_deref(), pose, !no_noise)?,
            None,
        )
    };
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
    }
    img.save(&out)
        .with_context(|| format!("writing {}", out.display()))?;
    if let Some(t) = &truth {
        for file in write_snapshot_truth(&out, t)? {
            println!("truth -> {}", file.display());
        }
    }
    println!(
        "{}: {}x{} rendered by {} -> {}",
        s.name,
        img.width(),
        img.height(),
        r.name(),
        out.display()
    );
    Ok(())
}

/// `omniloop dataset`: frames of a camera with their truth.
fn dataset(args: DatasetArgs) -> anyhow::Result<()> {
    let DatasetArgs {
        scenario,
        samples,
        poses,
        sensor,
        out,
        seed,
        renderer,
        quiet,
    } = args;
    let mut s = load(&scenario)?;
    if let Some(seed) = seed {
        s.seed = seed;
    }
    let dir = out.unwrap_or_else(|| default_out_dir(&s).join("dataset"));
    let options = DatasetOptions {
        samples: samples as usize,
        poses,
        sensor,
        renderer,
    };
    let bar = styled_bar(
        samples,
        quiet,
        "{prefix} [{bar:40}] {pos}/{len} samples {per_sec} eta {eta}",
    );
    bar.set_prefix(s.name.clone());
    let started = std::time::Instant::now();
    let info = write_dataset(&s, &options, &dir, |k, _| bar.set_position(k as u64))
        .with_context(|| format!("writing the dataset of {}", scenario.display()))?;
    bar.finish_and_clear();
    println!(
        "{}: {} samples of camera {:?} ({}x{}, poses {}) in {:.1} s, {:.1} MB -> {}",
        info.scenario,
        info.samples,
        info.sensor,
        info.size_px[0],
        info.size_px[1],
        info.poses.name(),
        started.elapsed().as_secs_f64(),
        folder_bytes(&dir) as f64 / 1e6,
        dir.display()
    );
    Ok(())
}
