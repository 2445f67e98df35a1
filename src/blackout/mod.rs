//! `omniloop replay blackout`: the league's vision-blackout technical challenge replayed and
//! scored. A striker on E1's robot plays every stage from its own camera alone; the simulator
//! places robot and ball by the seed, watches each trial and scores it by the rules' points
//! ([`score`]), on the challenge's 4 m x 3 m field and on Division B's, and writes the score
//! sheet (`blackout.md`), the paths (`blackout.png`) and `summary.json`.

pub mod report;
pub mod score;
pub mod trials;

use crate::experiments::{Replay, ReplayContext};
use crate::run::{RunOptions, Simulation};
use anyhow::Context;
use score::{TrialScore, Watch};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use trials::{DIVISION_B, Field, HARDWARE_CHALLENGE, Stage, place, scenario_text};

/// The replay's entry.
pub const REPLAY: Replay = Replay {
    name: "blackout",
    title: "the vision-blackout challenge (2021 stages 1-3, the 2019 moving ball) played on the \
            robot's own camera and scored by the rules",
    run: replay,
};

/// One block of trials: a stage on a field, clean or with E1's latency and blur.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Block {
    /// The stage.
    pub stage: Stage,
    /// The field.
    pub field: Field,
    /// With E1's frame latency (80 ms), exposure (10 ms) and defocus (1 px).
    pub realism: bool,
}

/// The trials of one block, scored.
#[derive(Debug, Clone)]
pub struct BlockResult {
    /// The block.
    pub block: Block,
    /// Its trials, in seed order.
    pub trials: Vec<TrialScore>,
}

/// The blocks of the full replay: every stage on both fields, and stages 1 and 2 with E1's
/// latency and blur on the challenge's field.
pub fn all_blocks() -> Vec<Block> {
    let mut out = Vec::new();
    for field in [HARDWARE_CHALLENGE, DIVISION_B] {
        for stage in Stage::ALL {
            out.push(Block {
                stage,
                field,
                realism: false,
            });
        }
    }
    for stage in [Stage::Grab, Stage::EmptyGoal] {
        out.push(Block {
            stage,
            field: HARDWARE_CHALLENGE,
            realism: true,
        });
    }
    out
}

/// Trials per block in the replay.
pub const TRIALS: u64 = 20;

/// Runs and scores one trial.
pub fn run_trial(block: &Block, seed: u64, options: &RunOptions) -> anyhow::Result<TrialScore> {
    let p = place(block.stage, &block.field, seed);
    let text = scenario_text(block.stage, &block.field, &p, seed, block.realism);
    let file = format!(
        "blackout-{}-{}-{seed}.toml",
        block.field.preset,
        block.stage.key()
    );
    let scenario = crate::experiments::parse_scenario(&text, Path::new(&file), "blackout")
        .with_context(|| format!("the trial scenario {file}"))?;
    if let Some(v) = crate::scenario::validate(&scenario).first() {
        anyhow::bail!("{file}: field `{}`: {}", v.field, v.message);
    }
    let mut sim = Simulation::new(&scenario, options, |_| {})?;
    let mut watch = Watch::new(block.stage, block.field, seed);
    while !sim.finished() {
        sim.step().with_context(|| format!("running {file}"))?;
        if watch.observe(&sim) {
            break;
        }
    }
    Ok(watch.finish())
}

/// Runs `trials` seeds (from `first_seed`) of every block over the cores, in a deterministic
/// order whatever the threads do; `progress` hears (trials done, total).
pub fn run_blocks(
    blocks: &[Block],
    first_seed: u64,
    trials: u64,
    options: &RunOptions,
    mut progress: impl FnMut(usize, usize),
) -> anyhow::Result<Vec<BlockResult>> {
    let jobs: Vec<(usize, u64)> = (0..blocks.len())
        .flat_map(|b| (0..trials).map(move |k| (b, first_seed + k)))
        .collect();
    let next = AtomicUsize::new(0);
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(jobs.len().max(1));
    let (tx, rx) = mpsc::channel();
    let mut results: Vec<Option<TrialScore>> = vec![None; jobs.len()];
    std::thread::scope(|s| -> anyhow::Result<()> {
        for _ in 0..workers {
            let (tx, next, jobs) = (tx.clone(), &next, &jobs);
            s.spawn(move || {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&(b, seed)) = jobs.get(i) else { break };
                    if tx.send((i, run_trial(&blocks[b], seed, options))).is_err() {
                        break;
                    }
                }
            });
        }
        drop(tx);
        for (done, (i, r)) in rx.iter().enumerate() {
            results[i] = Some(r?);
            progress(done + 1, jobs.len());
        }
        Ok(())
    })?;
    let mut scores = results.into_iter().flatten();
    Ok(blocks
        .iter()
        .map(|&block| BlockResult {
            block,
            trials: scores.by_ref().take(trials as usize).collect(),
        })
        .collect())
}

/// The replay: every block, its score sheet, figure and summary.
fn replay(ctx: &mut ReplayContext<'_>) -> anyhow::Result<String> {
    let started = std::time::Instant::now();
    let blocks = all_blocks();
    let progress = &mut *ctx.progress;
    let results = run_blocks(
        &blocks,
        ctx.seed.unwrap_or(1),
        TRIALS,
        ctx.options,
        |k, n| progress("blackout", k as u64, n as u64),
    )?;
    report::write(ctx.out, &results, started.elapsed().as_secs_f64())
}
