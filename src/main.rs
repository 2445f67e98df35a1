//! The `omniloop` command line.

use anyhow::Context;
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use omniloop::output::{default_out_dir, write_run};
use omniloop::{DEFAULT_SCENARIO, LoadError, load_scenario, run_scenario};
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
        #[arg(required_unless_present = "print_default")]
        scenario: Option<PathBuf>,
        /// Output folder (default: runs/<scenario name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Seed overriding the scenario's.
        #[arg(long)]
        seed: Option<u64>,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
        /// Print a complete, commented example scenario and exit.
        #[arg(long)]
        print_default: bool,
    },
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

fn load(path: &Path) -> anyhow::Result<omniloop::Scenario> {
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
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
    }
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{prefix} [{bar:40}] {pos}/{len} cycles {per_sec} eta {eta}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Check { files } => {
            let mut bad = false;
            for f in &files {
                match load_scenario(f) {
                    Ok(s) => println!("{}: ok ({})", f.display(), s.name),
                    Err(e @ LoadError::Invalid { .. }) => {
                        eprintln!("{e}");
                        bad = true;
                    }
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
            out,
            seed,
            quiet,
            print_default,
        } => {
            if print_default {
                print!("{DEFAULT_SCENARIO}");
                return Ok(());
            }
            let path = scenario.expect("clap requires a scenario");
            let mut s = load(&path)?;
            if let Some(seed) = seed {
                s.seed = seed;
            }
            let dir = out.unwrap_or_else(|| default_out_dir(&s));
            let bar = progress_bar(s.max_cycles(), quiet);
            bar.set_prefix(s.name.clone());
            let output = run_scenario(&s, |k, _| bar.set_position(k))
                .with_context(|| format!("running {}", path.display()))?;
            bar.finish_and_clear();
            write_run(&dir, &s, &output)?;
            let m = &output.summary;
            println!(
                "{}: {} cycles, {:.2} s simulated in {:.2} s ({:.0} cycles/s); goal {}; contacts {}; \
                 min clearance {:.1} mm; results in {}",
                m.scenario,
                m.cycles,
                m.sim_time_s,
                m.wall_time_s,
                m.cycles_per_s,
                match m.time_to_goal_s {
                    Some(t) => format!("reached at {t:.2} s"),
                    None => "not reached".into(),
                },
                m.wall_contacts,
                m.min_clearance_mm,
                dir.display()
            );
            Ok(())
        }
    }
}

fn main() -> ExitCode {
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
