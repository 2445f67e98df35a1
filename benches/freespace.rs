//! Free-space stage benchmark: median time of steps 1-4 of Sect. 3.1 (binarize, clean, polar
//! template, eq. (5)-(7)) on a 256x220 frame of the E1 corridor, both variants of eq. (5).
//!
//!     cargo bench --bench freespace
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use nalgebra::{Isometry2, Vector2};
use omniloop::load_scenario;
use omniloop::scenario::calibrate::calibrate_sensor;
use omniloop_sim::{Renderer, Scene, SensorNoise, World};
use omniloop_vision::{FreeSpaceConfig, FreeSpaceDetector, FreeSpaceMethod};
use std::time::Instant;

fn main() {
    let path = common::scenario_path("corner55_velocity_aware.toml");
    let s = load_scenario(&path).expect("corner scenario loads");
    let spec = &s.robot.sensors[0];
    let sensor = spec.build();
    let cal = calibrate_sensor(spec).expect("calibration");
    let mut bodies = s.robot_bodies();
    bodies[0].start = Isometry2::new(Vector2::new(-900.0, 250.0), 0.0);
    let world = World::new(&s.world, &bodies, 0.002).expect("world");
    let scene = Scene::of_world(&world);
    let mut noise = SensorNoise::new(1);
    let img = Renderer::cpu()
        .render(
            &scene,
            &sensor,
            &world.robot_state(0).pose,
            Some(&mut noise),
        )
        .expect("render");
    println!(
        "{:<36} {:>12} {:>12}",
        "free-space stage (256x220)", "median ms", "per second"
    );
    for method in [FreeSpaceMethod::Count, FreeSpaceMethod::Labeling] {
        let config = FreeSpaceConfig {
            method,
            ..s.vision.table("freespace").expect("settings")
        };
        let mut d = FreeSpaceDetector::new(config, &cal).expect("detector");
        for _ in 0..20 {
            d.detect(&img).expect("detect");
        }
        let mut t: Vec<f64> = (0..500)
            .map(|_| {
                let t0 = Instant::now();
                std::hint::black_box(d.detect(&img).expect("detect"));
                t0.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        t.sort_by(f64::total_cmp);
        let m = t[t.len() / 2];
        println!(
            "{:<36} {:>12.4} {:>12.0}",
            format!("{method:?}"),
            m,
            1e3 / m
        );
    }
}
