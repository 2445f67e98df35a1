//! `omniloop replay robustness`: every estimator of the papers' methods (free space, floor
//! localization, luminance heading, omnistereo ranges and trilateration, resection, forward
//! odometry) against each way the world departs from the ideal (sensor noise, defocus,
//! exposure while moving, the mirror's tilt and offset, frame latency and loss) at four or five
//! levels, run as one sweep: `robustness.md`, `robustness.csv` and `robustness.png`.
//!
//! The estimators ([`estimators::ESTIMATORS`]) and knobs ([`knobs::KNOBS`]) are registries: a
//! new one is an entry there.

pub mod estimators;
pub mod grid;
pub mod knobs;
pub mod report;

pub use estimators::{ESTIMATORS, Estimator, Score, estimator};
pub use grid::{Cell, Grid, GridError, GridOptions, Outcome, Selection, run_grid};
pub use knobs::{KNOBS, Knob, knob};

use crate::experiments::{Replay, ReplayContext};
use anyhow::Context;
use std::fmt::Write as _;

/// `omniloop replay robustness`.
pub const REPLAY: Replay = Replay {
    name: "robustness",
    title: "every estimator against noise, defocus, exposure, mirror tilt and offset, latency \
            and frame loss",
    run: replay,
};

/// Runs the whole grid and writes its table, CSV and figure into the context's folder.
fn replay(ctx: &mut ReplayContext<'_>) -> anyhow::Result<String> {
    let options = GridOptions {
        renderer: ctx.options.renderer,
        seed: ctx.seed,
        workers: 0,
    };
    let progress = &mut *ctx.progress;
    let started = std::time::Instant::now();
    let grid = run_grid(&Selection::default(), &options, |k, n| {
        progress("robustness", k as u64, n as u64);
    })?;
    write_outputs(ctx.out, &grid, started.elapsed().as_secs_f64())
}

/// Writes `robustness.md`, `robustness.csv` and `robustness.png` into `dir`; returns the table.
pub fn write_outputs(dir: &std::path::Path, grid: &Grid, wall_s: f64) -> anyhow::Result<String> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut header = String::new();
    let seeds: Vec<String> = grid.seeds.iter().map(u64::to_string).collect();
    let _ = writeln!(
        header,
        "{} runs in {:.0} s; seeds by estimator: {}.",
        grid.runs,
        wall_s,
        seeds.join(", ")
    );
    let md = report::markdown(grid, &header);
    let files = [
        ("robustness.md", md.clone().into_bytes()),
        ("robustness.csv", report::csv(grid).into_bytes()),
        ("robustness.png", report::figure(grid)?),
    ];
    for (name, bytes) in files {
        let file = dir.join(name);
        std::fs::write(&file, bytes).with_context(|| format!("writing {}", file.display()))?;
    }
    Ok(md)
}
