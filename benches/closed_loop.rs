//! Closed-loop benchmark: control cycles per second of the E1 corner runs (render, free space,
//! controller, physics, recording) with the CPU renderer on one core and on all cores and, when
//! an adapter exists, the GPU; the goal-direction run also with a ball on the floor far from
//! the robot's path (behind its start), which every frame renders and every physics step
//! moves.
//!
//!     cargo bench --bench closed_loop
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use omniloop::load_scenario;
use omniloop::{RunOptions, run_scenario};
use omniloop_sim::RendererChoice;

fn main() {
    println!(
        "{:<28} {:<44} {:>8} {:>10}",
        "scenario", "renderer", "cycles", "cycles/s"
    );
    // The CPU renderer on one core (a pool of one thread: what a run gets per core in a
    // sweep), then on all of them, then the GPU.
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    one.install(|| measure(RendererChoice::Cpu));
    measure(RendererChoice::Cpu);
    measure(RendererChoice::Gpu);
}

/// The E1 scenarios, and the first with a ball behind the robot's start (at rest in the
/// corridor's end, 350 mm behind the start and 350 mm aside).
fn scenarios() -> Vec<(String, omniloop::Scenario)> {
    let mut out = Vec::new();
    for name in ["corner55_goal_direction", "corner55_velocity_aware"] {
        let path = common::scenario_path(&format!("{name}.toml"));
        out.push((
            name.to_string(),
            load_scenario(&path).expect("scenario loads"),
        ));
    }
    let mut with_ball = out[0].1.clone();
    with_ball.world.ball = Some(omniloop_sim::BallSpec {
        center_mm: [-2850.0, 350.0],
        ..omniloop_sim::BallSpec::default()
    });
    out.push(("corner55_goal_direction+ball".to_string(), with_ball));
    out
}

/// Best of three runs of each E1 scenario with `choice`, a line each.
fn measure(choice: RendererChoice) {
    for (name, s) in scenarios() {
        let options = RunOptions {
            renderer: choice,
            ..RunOptions::default()
        };
        // Best of three runs (the machine may be shared).
        let mut best: Option<omniloop::Summary> = None;
        for _ in 0..3 {
            match run_scenario(&s, &options, |_| {}, |_, _| {}) {
                Ok(out) => {
                    if best
                        .as_ref()
                        .is_none_or(|b| out.summary.cycles_per_s > b.cycles_per_s)
                    {
                        best = Some(out.summary);
                    }
                }
                Err(e) => {
                    println!("{name:<28} {choice:?}: not measured ({e})");
                    break;
                }
            }
        }
        if let Some(m) = best {
            println!(
                "{:<28} {:<44} {:>8} {:>10.0}",
                name,
                m.renderer.unwrap_or_default(),
                m.cycles,
                m.cycles_per_s
            );
        }
    }
}
