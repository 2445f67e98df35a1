//! Self-localization benchmark: median time of one localization at 256x220, on frames of the
//! E2 field from the six E2 places and from four places near its walls and corners: the
//! paper's method, and ours in global and tracking mode (prior 100 mm and 5 degrees off).
//!
//!     cargo bench --bench localization
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use nalgebra::{Isometry2, Vector2};
use omniloop::experiments::places::PlacesSpec;
use omniloop::load_scenario;
use omniloop::scenario::calibrate::calibrate_sensor;
use omniloop_sim::{Renderer, Scene, SensorNoise, World};
use omniloop_vision::{FloorLocalizer, LocalizationConfig, LocalizationMethod};
use std::time::Instant;

fn main() {
    let path = common::scenario_path("selfloc_field.toml");
    let s = load_scenario(&path).expect("E2 scenario loads");
    let spec = &s.robot.sensors[0];
    let sensor = spec.build();
    let cal = calibrate_sensor(spec).expect("calibration");
    let mut renderer = Renderer::cpu();
    let mut noise = SensorNoise::new(1);
    let places: PlacesSpec = s
        .experiment
        .parse_present("experiment", "places")
        .expect("selfloc_field.toml has [experiment.places]");
    let mut poses: Vec<Isometry2<f64>> = places.places.iter().map(|p| p.isometry()).collect();
    for (x, y, deg) in [
        (-1250.0, -650.0, 0.0),
        (1200.0, -600.0, -45.0),
        (-700.0, -600.0, 135.0),
        (1410.0, 150.0, 90.0),
    ] {
        poses.push(Isometry2::new(Vector2::new(x, y), f64::to_radians(deg)));
    }
    let mut frames = Vec::new();
    for pose in &poses {
        let mut bodies = s.robot_bodies();
        bodies[0].start = *pose;
        let world = World::new(&s.world, &bodies, 0.0025).expect("world");
        let scene = Scene::of_world(&world);
        let img = renderer
            .render(&scene, &sensor, pose, Some(&mut noise))
            .expect("render");
        let prior = Isometry2::new(
            pose.translation.vector + Vector2::new(70.7, 70.7),
            pose.rotation.angle() + 5f64.to_radians(),
        );
        frames.push((img, prior));
    }
    println!(
        "{:<44} {:>10} {:>10}",
        "self-localization (256x220, 10 places)", "median ms", "p90 ms"
    );
    let configs = [
        ("paper's method (global)", LocalizationMethod::Paper, false),
        ("robust, global", LocalizationMethod::Robust, false),
        ("robust, tracking", LocalizationMethod::Robust, true),
    ];
    let mut localizers: Vec<FloorLocalizer> = configs
        .iter()
        .map(|&(_, method, _)| {
            let config = LocalizationConfig {
                method,
                ..s.vision.table("localization").expect("settings")
            };
            FloorLocalizer::new(config, &cal).expect("localizer")
        })
        .collect();
    // The configurations take turns frame by frame, so that a shared machine's changing load
    // falls on all of them alike.
    let rounds = 600;
    let mut times = vec![Vec::with_capacity(rounds); configs.len()];
    for k in 0..rounds {
        let (img, prior) = &frames[k % frames.len()];
        for ((loc, &(_, _, tracking)), t) in localizers.iter_mut().zip(&configs).zip(&mut times) {
            let t0 = Instant::now();
            let r = if tracking {
                loc.track(img, prior)
            } else {
                loc.locate(img, None)
            };
            std::hint::black_box(r.expect("locate"));
            t.push(t0.elapsed().as_secs_f64() * 1e3);
        }
    }
    for ((name, _, _), t) in configs.iter().zip(&mut times) {
        t.sort_by(f64::total_cmp);
        println!(
            "{:<44} {:>10.4} {:>10.4}",
            name,
            t[t.len() / 2],
            t[t.len() * 9 / 10]
        );
    }
}
