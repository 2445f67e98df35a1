//! `omniloop dataset`: frames of a camera with their truth (depth, labels, poses) and the
//! camera model.

use super::{load, styled_bar};
use anyhow::Context;
use omniloop::dataset::{DatasetOptions, PoseMode, write_dataset};
use omniloop::report::output::default_out_dir;
use omniloop_sim::RendererChoice;
use std::path::{Path, PathBuf};

/// `omniloop dataset`'s arguments.
#[derive(clap::Args)]
pub struct DatasetArgs {
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

/// `omniloop dataset`: frames of a camera with their truth.
pub fn dataset_cmd(args: DatasetArgs) -> anyhow::Result<()> {
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
