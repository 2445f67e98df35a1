//! `omniloop ssl`: a scenario served as a Small-Size League simulator (docs/ssl.md): a team's
//! AI drives the robots over the SSL simulation protocol and gets ssl-vision's packets and the
//! referee's, while every robot's own cameras are rendered and recorded as in `omniloop run`.

use super::load;
use anyhow::Context;
use omniloop::report::output::{default_out_dir, write_run};
use omniloop::run::RunOptions;
use omniloop::scenario::ssl::SslSpec;
use omniloop::ssl::{Bound, Pace, Ports, ServeOptions, ServeReport, Server, SslSimulator};
use omniloop::viewing::{FoxgloveLog, LiveOptions, Sinks};
use omniloop_sim::RendererChoice;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// `omniloop ssl`'s arguments.
#[derive(clap::Args)]
pub struct SslArgs {
    /// Scenario file (its `[ssl]` table: teams, ports, vision, referee; defaults without one).
    scenario: PathBuf,
    /// Output folder (default: runs/<scenario name>): the run's files and ssl.log, the
    /// league's log of every vision and referee packet sent.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Lockstep: the simulation advances only on the clients' `SimulationSyncRequest`s.
    #[arg(long)]
    lockstep: bool,
    /// Stop after this much simulated time, s (default: the scenario's run.duration_s).
    #[arg(long, value_name = "S")]
    duration_s: Option<f64>,
    /// Lockstep: stop when no datagram came for this long of wall time, s.
    #[arg(long, value_name = "S")]
    idle_exit_s: Option<f64>,
    /// Seed overriding the scenario's.
    #[arg(long)]
    seed: Option<u64>,
    /// Address the ports listen on (overrides [ssl.network] bind_address).
    #[arg(long, value_name = "IP")]
    bind: Option<String>,
    /// Simulation-control port (0: any free one).
    #[arg(long, value_name = "PORT")]
    control_port: Option<u16>,
    /// Blue team's robot-control port.
    #[arg(long, value_name = "PORT")]
    blue_port: Option<u16>,
    /// Yellow team's robot-control port.
    #[arg(long, value_name = "PORT")]
    yellow_port: Option<u16>,
    /// Where vision goes, ADDRESS:PORT (multicast, unicast or loopback).
    #[arg(long, value_name = "ADDR")]
    vision: Option<String>,
    /// Where the referee's packets go, ADDRESS:PORT.
    #[arg(long, value_name = "ADDR")]
    referee: Option<String>,
    /// No referee packets (an external game controller runs).
    #[arg(long)]
    no_referee: bool,
    /// Vision with ER-Force's "realistic" errors ([ssl.vision.realism] enabled).
    #[arg(long)]
    realism: bool,
    /// Do not render the protocol robots' cameras (faster; they record no frames).
    #[arg(long)]
    no_cameras: bool,
    /// Write the ports' addresses, once bound, to this JSON file.
    #[arg(long, value_name = "FILE")]
    ports_file: Option<PathBuf>,
    /// Renderer for the robots' cameras: auto, gpu or cpu.
    #[arg(long, default_value = "auto")]
    renderer: RendererChoice,
    /// Save every robot's camera images to OUT/frames/ every K cycles.
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u64).range(1..))]
    save_frames: Option<u64>,
    /// Record the game as MCAP for Foxglove (every robot's cameras, poses, the ball): into
    /// FILE, or OUT/run.mcap.
    #[arg(long, value_name = "FILE", num_args = 0..=1)]
    mcap: Option<Option<PathBuf>>,
    /// Serve the game live to the Foxglove app on ADDR (default 127.0.0.1:8765).
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:8765")]
    live: Option<String>,
}

impl SslArgs {
    /// The scenario's `[ssl]` table with the command line's overrides.
    fn spec(&self, mut spec: SslSpec) -> SslSpec {
        let n = &mut spec.network;
        let set = |v: &Option<u16>, into: &mut u16| {
            if let Some(p) = v {
                *into = *p;
            }
        };
        set(&self.control_port, &mut n.control_port);
        set(&self.blue_port, &mut n.blue_port);
        set(&self.yellow_port, &mut n.yellow_port);
        if let Some(b) = &self.bind {
            n.bind_address = b.clone();
        }
        if let Some(v) = &self.vision {
            n.vision_address = v.clone();
        }
        if let Some(r) = &self.referee {
            n.referee_address = r.clone();
        }
        spec.referee.enabled &= !self.no_referee;
        spec.vision.realism.enabled |= self.realism;
        spec.render_cameras &= !self.no_cameras;
        spec
    }
}

/// Serves the scenario until its time is up, Ctrl-C or (lockstep) the clients fall idle; then
/// writes the run's files.
pub fn ssl_cmd(args: SslArgs) -> anyhow::Result<()> {
    let mut s = load(&args.scenario)?;
    if let Some(seed) = args.seed {
        s.seed = seed;
    }
    s.ssl = Some(args.spec(s.ssl.clone().unwrap_or_default()));
    let dir = args.out.clone().unwrap_or_else(|| default_out_dir(&s));
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let sinks = Sinks {
        mcap: (args.mcap.clone()).map(|f| f.unwrap_or_else(|| dir.join("run.mcap"))),
        live: args.live.clone().map(|addr| LiveOptions {
            addr,
            ..LiveOptions::default()
        }),
    };
    let log = super::run::start_log(&s, &sinks)?;
    let options = RunOptions {
        renderer: args.renderer,
        save_frames_every: args.save_frames,
        frames_dir: args.save_frames.map(|_| dir.join("frames")),
        observers: log.iter().map(FoxgloveLog::observer).collect(),
        ..RunOptions::default()
    };
    let sim = SslSimulator::new(&s, &options)
        .with_context(|| format!("serving {}", args.scenario.display()))?;
    let ports = Ports::bind(sim.spec())?;
    let bound = ports.bound()?;
    eprintln!(
        "omniloop ssl: {} ({}): control {}, blue {}, yellow {}; vision to {}, referee to {}",
        s.name,
        if args.lockstep {
            "lockstep"
        } else {
            "real time"
        },
        bound.control,
        bound.blue,
        bound.yellow,
        bound.vision_to,
        bound.referee_to
    );
    if let Some(file) = &args.ports_file {
        write_ports(file, &bound)?;
    }
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed));
    let serve = ServeOptions {
        pace: if args.lockstep {
            Pace::Lockstep
        } else {
            Pace::RealTime
        },
        duration_s: args.duration_s,
        idle_exit_s: args.idle_exit_s,
        log: Some(dir.join("ssl.log")),
    };
    let (sim, report) = Server::new(sim, ports, &serve)?.run(&serve, &stop)?;
    let output = sim.finish(report.wall_s);
    write_run(&dir, &s, &output)?;
    if let Some(log) = log
        && let Some(file) = log.finish(&output.summary)?
    {
        eprintln!("recorded {}", file.display());
    }
    println!(
        "{}; results in {}",
        report_line(&s.name, &report),
        dir.display()
    );
    Ok(())
}

/// What the game came to, in a line.
fn report_line(name: &str, r: &ServeReport) -> String {
    format!(
        "{name}: {} cycles, {:.2} s simulated in {:.2} s ({:.0} cycles/s, {} late); score blue \
         {} yellow {}; {} datagrams malformed, {} errors answered, {} dropped in floods, {} \
         refused",
        r.cycles,
        r.sim_time_s,
        r.wall_s,
        r.cycles as f64 / r.wall_s.max(1e-9),
        r.late_cycles,
        r.score[0],
        r.score[1],
        r.malformed,
        r.errors,
        r.flood_dropped,
        r.refused,
    )
}

/// Writes the bound ports' addresses as JSON into `file`.
fn write_ports(file: &Path, bound: &Bound) -> anyhow::Result<()> {
    let json = serde_json::json!({
        "control": bound.control.to_string(),
        "blue": bound.blue.to_string(),
        "yellow": bound.yellow.to_string(),
        "vision": bound.vision_to.to_string(),
        "referee": bound.referee_to.to_string(),
    });
    // Written beside and renamed: a reader never sees half of it.
    let tmp = file.with_extension("tmp");
    std::fs::write(&tmp, json.to_string()).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, file).with_context(|| format!("writing {}", file.display()))
}
