//! Sweep benchmark: the 55-degree corner (velocity-aware, CPU renderer) over 16 seeds with one
//! worker and with one worker a core; runs per second and the speed-up (target >= 0.9 x cores).
//!
//!     cargo bench --bench sweep

mod common;

use omniloop::sweep::{Seeds, SweepOptions, plan, run_jobs};
use omniloop_sim::RendererChoice;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

fn main() {
    let file = common::scenario_path("corner55_velocity_aware.toml");
    let plan = plan(&file, &[], &Seeds::Count(16)).expect("the corner scenario plans");
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let stop = AtomicBool::new(false);
    let mut rates = Vec::new();
    // One worker on one core, one worker with the renderer on every core (`--jobs 1`), and
    // one worker a core (the default).
    for (workers, threads) in [(1, 1), (1, cores), (cores, 1)] {
        let mut options = SweepOptions::new(workers, cores, RendererChoice::Cpu);
        options.render_threads = threads;
        let t = Instant::now();
        let out = run_jobs(&plan, &options, &stop, |_| {});
        let s = t.elapsed().as_secs_f64();
        let ok = out.iter().flatten().filter(|o| o.result.is_ok()).count();
        let cycles: u64 = out
            .iter()
            .flatten()
            .filter_map(|o| o.result.as_ref().ok())
            .map(|s| s.cycles)
            .sum();
        let rate = plan.jobs.len() as f64 / s;
        rates.push(rate);
        println!(
            "{workers} worker(s) x {} renderer thread(s): {} runs ({ok} finished) in {s:.1} s, \
             {rate:.2} runs/s, {:.0} closed-loop cycles/s",
            options.render_threads,
            plan.jobs.len(),
            cycles as f64 / s
        );
    }
    for (k, over) in [
        (0, "one worker on one core"),
        (1, "one worker, renderer on every core"),
    ] {
        let speedup = rates[2] / rates[k];
        println!(
            "speed-up of {cores} workers over {over}: {speedup:.2} x ({:.2} x cores; target >= 0.9)",
            speedup / cores as f64
        );
    }
}
