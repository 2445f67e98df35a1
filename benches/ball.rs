//! Ball perception benchmark: median time a frame of the ball detector and of the goal runs on
//! E1's 256 x 220 mirror image of the vision-blackout field (the ball 0.6 m ahead), beside the
//! free-space stage on the same frame (the stage every E1 robot already runs), and one
//! stage-1 trial of the blackout replay end to end.
//!
//!     cargo bench --bench ball
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use nalgebra::{Isometry2, Point2, Vector2};
use omniloop::blackout::trials::{HARDWARE_CHALLENGE, Stage};
use omniloop::blackout::{Block, run_trial};
use omniloop::load_scenario;
use omniloop::run::RunOptions;
use omniloop::scenario::calibrate::calibrate_sensor;
use omniloop_sim::{Renderer, Scene, SensorNoise, World};
use omniloop_vision::ball::{BallConfig, detect_mirror};
use omniloop_vision::goal::{Chroma, goal_runs_mirror};
use omniloop_vision::{FreeSpaceConfig, FreeSpaceDetector};
use std::time::Instant;

/// A row of the table: its name and the work it times.
type Row<'a> = (&'static str, Box<dyn FnMut() + 'a>);

/// Median milliseconds of `f` over `n` runs, after 20 to warm up.
fn median_ms(n: usize, mut f: impl FnMut()) -> f64 {
    (0..20).for_each(|_| f());
    let mut t: Vec<f64> = (0..n)
        .map(|_| {
            let t0 = Instant::now();
            f();
            t0.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

fn main() {
    let s = load_scenario(&common::scenario_path("blackout_stage1.toml")).expect("scenario loads");
    let spec = &s.robot.sensors[0];
    let cal = calibrate_sensor(spec).expect("calibration");
    let mut bodies = s.robot_bodies();
    bodies[0].start = Isometry2::new(Vector2::new(300.0, 600.0), 0.0);
    let mut world = World::new(&s.world, &bodies, 0.002).expect("world");
    world.place_ball(Point2::new(900.0, 600.0), Vector2::zeros());
    let scene = Scene::of_world(&world);
    let mut noise = SensorNoise::new(1);
    let pose = world.robot_state(0).pose;
    let img = Renderer::cpu()
        .render(&scene, &spec.build(), &pose, Some(&mut noise))
        .expect("render");
    let seen = detect_mirror(&img, &cal, &BallConfig::default()).expect("the ball is in view");
    println!("ball seen at {:.0} mm (truth 600 mm)", seen.range_mm);
    println!(
        "{:<40} {:>12} {:>12}",
        "256x220 frame", "median ms", "per second"
    );
    let mut fs = FreeSpaceDetector::new(FreeSpaceConfig::default(), &cal).expect("detector");
    let rows: [Row<'_>; 3] = [
        (
            "free-space stage (baseline)",
            Box::new(|| {
                std::hint::black_box(fs.detect(&img).expect("detect"));
            }),
        ),
        (
            "ball detector",
            Box::new(|| {
                std::hint::black_box(detect_mirror(&img, &cal, &BallConfig::default()).ok());
            }),
        ),
        (
            "goal runs (one colour)",
            Box::new(|| {
                std::hint::black_box(goal_runs_mirror(&img, &cal, &Chroma::YELLOW, 0.0));
            }),
        ),
    ];
    for (name, mut f) in rows {
        let m = median_ms(300, &mut f);
        println!("{name:<40} {m:>12.4} {:>12.0}", 1e3 / m);
    }
    let block = Block {
        stage: Stage::Grab,
        field: HARDWARE_CHALLENGE,
        realism: false,
    };
    let t0 = Instant::now();
    let score = run_trial(&block, 1, &RunOptions::default()).expect("trial");
    println!(
        "blackout stage-1 trial, seed 1: {:.2} s wall for {:.1} s simulated ({} points)",
        t0.elapsed().as_secs_f64(),
        score.duration_s,
        score.points
    );
}
