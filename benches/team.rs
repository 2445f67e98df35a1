//! Team benchmark: robot-cycles per second (control cycles times robots) of a team of 1, 2, 6
//! and 12 robots of E1's camera, side by side in one run: rounds that each run every team size
//! in turn, the median of each. Each robot runs the built-in stack (free space, the
//! velocity-aware controller under the traffic rule), then software that only looks (its
//! camera rendered, no vision: the loop and the renderer alone); with the CPU renderer on every
//! core, then the GPU renderer where an adapter opens.
//!
//!     cargo bench --bench team
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use omniloop::robot::{BodyCommand, Estimates, Observation, OdometryReading, Outputs};
use omniloop::robot::{RobotError, RobotSoftware};
use omniloop::{RunOptions, Runner, parse_scenario};
use omniloop_sim::RendererChoice;

/// Reads its camera every cycle and stands still: the loop and the renderer without vision.
struct Looker;

impl RobotSoftware for Looker {
    fn cameras(&self) -> Vec<String> {
        vec!["omni".to_string()]
    }
    fn cycle(&mut self, obs: &Observation<'_>) -> Result<Outputs, RobotError> {
        std::hint::black_box(obs.frames.len());
        Ok(Outputs::drive(
            BodyCommand::STOP,
            Estimates {
                t_s: obs.t_s,
                ..Estimates::default()
            },
        ))
    }
    fn odometry(&mut self, _reading: &OdometryReading) {}
}

/// Team sizes measured.
const SIZES: [usize; 4] = [1, 2, 6, 12];
/// Rounds of every size; the median is printed.
const ROUNDS: usize = 5;
/// Simulated time of each run, s (100 control cycles).
const DURATION_S: f64 = 4.0;

/// `swarm_swap.toml` with `n` robots on its 1.2 m circle, each bound for its antipode, running
/// `DURATION_S` whatever they reach.
fn team(n: usize) -> omniloop::Scenario {
    let path = common::scenario_path("swarm_swap.toml");
    let text = std::fs::read_to_string(&path).expect("swarm_swap.toml");
    let shared = &text[..text.find("\n[[robots]]\n").expect("robots")];
    let mut out = shared
        .replace("duration_s = 40.0", &format!("duration_s = {DURATION_S}"))
        .replace("[run]\n", "[run]\nstop_at_goal = false\n");
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        let (x, y) = (1200.0 * a.cos(), 1200.0 * a.sin());
        out.push_str(&format!(
            "\n[[robots]]\nname = \"r{k}\"\nstart = {{ x_mm = {x:.3}, y_mm = {y:.3}, \
             heading_deg = {:.3} }}\ngoal = {{ x_mm = {:.3}, y_mm = {:.3} }}\n",
            (a.to_degrees() + 180.0) % 360.0,
            -x,
            -y
        ));
    }
    parse_scenario(&out, &path, &format!("team{n}")).expect("the team scenario parses")
}

/// Median of `v`.
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let teams: Vec<_> = SIZES.iter().map(|&n| (n, team(n))).collect();
    for choice in [RendererChoice::Cpu, RendererChoice::Gpu] {
        for builtin in [true, false] {
            measure(&teams, choice, builtin);
        }
    }
}

/// Every team size's robot-cycles per second with `choice`, `ROUNDS` rounds side by side; the
/// built-in stack on every robot, or software that only looks.
fn measure(teams: &[(usize, omniloop::Scenario)], choice: RendererChoice, builtin: bool) {
    let options = RunOptions {
        renderer: choice,
        ..RunOptions::default()
    };
    let mut rates: Vec<Vec<f64>> = vec![Vec::new(); teams.len()];
    let mut renderer = String::new();
    for _ in 0..ROUNDS {
        for (k, (n, s)) in teams.iter().enumerate() {
            let runner = Runner::new(s).options(options.clone());
            let runner = match builtin {
                true => runner,
                false => runner.software(|_config| Ok(Looker)),
            };
            match runner.run() {
                Ok(out) => {
                    renderer = out.summary.renderer.clone().unwrap_or_default();
                    rates[k].push(out.summary.cycles_per_s * *n as f64);
                }
                Err(e) => {
                    println!("{choice:?}: not measured ({e})");
                    return;
                }
            }
        }
    }
    let software = match builtin {
        true => "the built-in stack",
        false => "software that only looks",
    };
    println!("{software}; renderer: {renderer}; {ROUNDS} rounds, median of each");
    println!(
        "{:>7} {:>14} {:>12} {:>16}",
        "robots", "robot-cycles/s", "cycles/s", "x one robot's"
    );
    let one = median(rates[0].clone());
    for ((n, _), r) in teams.iter().zip(&rates) {
        let m = median(r.clone());
        println!(
            "{:>7} {:>14.0} {:>12.0} {:>16.2}",
            n,
            m,
            m / *n as f64,
            m / one
        );
    }
}
