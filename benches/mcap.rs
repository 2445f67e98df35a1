//! What `omniloop run --mcap` costs: E1's control cycles per second (CPU renderer, all cores)
//! with and without recording it to MCAP, alternating, eleven runs each; the medians and the
//! overhead.
//!
//!     cargo bench --bench mcap
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use omniloop::viewing::{FoxgloveLog, Sinks};
use omniloop::{RunOptions, load_scenario, run_scenario};
use omniloop_sim::RendererChoice;

fn main() {
    let s = load_scenario(&common::scenario_path("corner55_velocity_aware.toml")).unwrap();
    let file = std::env::temp_dir().join("omniloop_bench.mcap");
    let (mut plain, mut recorded) = (Vec::new(), Vec::new());
    for _ in 0..11 {
        let options = RunOptions {
            renderer: RendererChoice::Cpu,
            ..RunOptions::default()
        };
        plain.push(
            run_scenario(&s, &options, |_| {}, |_, _| {})
                .unwrap()
                .summary
                .cycles_per_s,
        );
        let sinks = Sinks {
            mcap: Some(file.clone()),
            live: None,
        };
        let log = FoxgloveLog::create(
            &sinks,
            &[omniloop::viewing::RobotCameras {
                robot: None,
                sensors: vec!["omni".to_string()],
            }],
        )
        .unwrap();
        let options = RunOptions {
            observers: vec![log.observer()],
            ..options
        };
        let out = run_scenario(&s, &options, |_| {}, |_, _| {}).unwrap();
        log.finish(&out.summary).unwrap();
        recorded.push(out.summary.cycles_per_s);
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (p, r) = (median(&mut plain), median(&mut recorded));
    let size = std::fs::metadata(&file).map_or(0, |m| m.len());
    println!("E1 (corner55_velocity_aware), CPU renderer, median of 11 runs each:");
    println!("  without --mcap  {p:>8.0} cycles/s");
    println!(
        "  with --mcap     {r:>8.0} cycles/s   ({:.1} MB file)",
        size as f64 / 1e6
    );
    println!("  overhead        {:>8.1} %", 100.0 * (1.0 - r / p));
}
