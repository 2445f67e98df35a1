//! The `omniloop` command line: one module a subcommand, each with its clap arguments and the
//! function that carries it out.

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use omniloop::{LoadError, Scenario, load_scenario};
use std::io::IsTerminal;
use std::path::Path;
use std::process::ExitCode;

mod calibrate;
mod check;
mod dataset;
mod render;
mod replay;
mod run;
mod ssl;
mod sweep;

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
    Check(check::CheckArgs),
    /// Run a scenario headless and write summary.json, trajectory.csv and topview.png.
    Run(run::RunArgs),
    /// Render one frame of a sensor to a PNG.
    Render(render::RenderArgs),
    /// Replay an experiment of the papers (`--list` shows them).
    Replay(replay::ReplayArgs),
    /// Run a scenario over a grid of values and seeds in parallel: sweep.csv, sweep.md, sweep.png.
    Sweep(sweep::Args),
    /// Write frames of a camera with their truth (depth, labels, poses) and the camera model,
    /// for training and evaluating perception (docs/truth.md).
    Dataset(dataset::DatasetArgs),
    /// Serve a scenario as a Small-Size League simulator: a team's AI drives the robots over
    /// the SSL simulation protocol and gets ssl-vision's and the referee's packets, while
    /// every robot's cameras are rendered (docs/ssl.md).
    Ssl(ssl::SslArgs),
    /// Trace a mirror sensor's image-to-floor map r = f(R) and write it for the vision crate;
    /// with --format, fit a standard camera model to its rays and write that tool's file.
    Calibrate(calibrate::CalibrateArgs),
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

/// The scenario of `path`; an invalid one is printed with its problems and exits 2.
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

/// A progress bar of `total` cycles.
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

/// Carries out the subcommand.
fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Check(args) => check::check_cmd(args),
        Command::Run(args) => run::run_cmd(args),
        Command::Render(args) => render::render_cmd(args),
        Command::Replay(args) => replay::replay_cmd(args),
        Command::Sweep(args) => sweep::sweep_cmd(args),
        Command::Dataset(args) => dataset::dataset_cmd(args),
        Command::Calibrate(args) => calibrate::calibrate_cmd(args),
        Command::Ssl(args) => ssl::ssl_cmd(args),
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
