//! `omniloop replay`: an experiment of the papers replayed, its table printed.

use super::progress_bar;
use anyhow::bail;
use omniloop::experiments::{ReplayContext, parse_scenario, run_dyn};
use omniloop::replays::{REPLAYS, replay};
use omniloop::run::RunOptions;
use omniloop_sim::RendererChoice;
use std::path::PathBuf;

/// `omniloop replay`'s arguments.
#[derive(clap::Args)]
pub struct ReplayArgs {
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
}

/// `omniloop replay`: the list of experiments, or one replayed into `--out`.
pub fn replay_cmd(args: ReplayArgs) -> anyhow::Result<()> {
    let ReplayArgs {
        experiment,
        list,
        out,
        seed,
        renderer,
        quiet,
    } = args;
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

/// The experiments, a line each: name and title.
fn listing() -> String {
    REPLAYS
        .iter()
        .map(|r| format!("  {:<10} {}", r.name, r.title))
        .collect::<Vec<_>>()
        .join("\n")
}
