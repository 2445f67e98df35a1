//! Sweep benchmark: the 55-degree corner (velocity-aware, CPU renderer) over 16 seeds with one
//! worker and with one worker a core; runs per second and the speed-up (target >= 0.9 x cores).
//!
//!     cargo bench --bench sweep
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use omniloop::sweep::{Seeds, SweepOptions, plan, run_jobs, shared_gpu};
use omniloop_sim::RendererChoice;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

fn main() {
    let file = common::scenario_path("corner55_velocity_aware.toml");
    let plan = plan(&file, &[], &Seeds::Count(16)).expect("the corner scenario plans");
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let stop = AtomicBool::new(false);
    // Warm-up: the first run traces the mirror's calibration, which later runs of the
    // process reuse.
    let one = omniloop::sweep::Plan {
        jobs: plan.jobs[..1].to_vec(),
        ..plan.clone()
    };
    run_jobs(
        &one,
        &SweepOptions::new(1, cores, RendererChoice::Cpu),
        &stop,
        |_| {},
    );
    // Three rounds over the configurations in turn; each figure is the round's median.
    let configs = [(1, 1), (1, cores), (cores, cores)];
    let mut times: Vec<Vec<(f64, u64, usize)>> = vec![Vec::new(); configs.len()];
    for _round in 0..3 {
        for (k, &(workers, threads)) in configs.iter().enumerate() {
            let mut options = SweepOptions::new(workers, cores, RendererChoice::Cpu);
            options.threads = threads;
            let t = Instant::now();
            let out = run_jobs(&plan, &options, &stop, |_| {});
            let s = t.elapsed().as_secs_f64();
            let done: Vec<_> = out
                .iter()
                .flatten()
                .filter_map(|o| o.result.as_ref().ok())
                .collect();
            let cycles: u64 = done.iter().map(|s| s.cycles).sum();
            times[k].push((s, cycles, done.len()));
        }
    }
    let mut rates = Vec::new();
    for (k, &(workers, threads)) in configs.iter().enumerate() {
        let mut t = times[k].clone();
        t.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (s, cycles, ok) = t[t.len() / 2];
        let rate = plan.jobs.len() as f64 / s;
        rates.push(rate);
        println!(
            "{workers} worker(s) on {threads} thread(s): {} runs ({ok} finished) in {s:.1} s \
             (median of 3), {rate:.2} runs/s, {:.0} closed-loop cycles/s",
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
    gpu_batched(&plan, cores, &stop);
}

/// The same sweep with every run's frames traced in shared GPU batches, 16 runs at a time
/// (one batch of up to 16 frames a cycle), when an adapter opens.
fn gpu_batched(plan: &omniloop::sweep::Plan, cores: usize, stop: &AtomicBool) {
    let server = match shared_gpu(RendererChoice::Gpu) {
        Ok(Some(s)) => s,
        Ok(None) => return,
        Err(e) => {
            println!("GPU batches: not measured ({e})");
            return;
        }
    };
    let handle = server.handle();
    let mut options = SweepOptions::new(16, cores, RendererChoice::Gpu);
    options.shared_gpu = Some(handle.clone());
    let t = Instant::now();
    let out = run_jobs(plan, &options, stop, |_| {});
    let s = t.elapsed().as_secs_f64();
    let cycles: u64 = out
        .iter()
        .flatten()
        .filter_map(|o| o.result.as_ref().ok())
        .map(|s| s.cycles)
        .sum();
    println!(
        "16 workers, GPU batches on {}: {} runs in {s:.1} s, {:.2} runs/s, {:.0} closed-loop \
         cycles/s",
        handle.name(),
        plan.jobs.len(),
        plan.jobs.len() as f64 / s,
        cycles as f64 / s
    );
}
