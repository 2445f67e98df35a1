//! Heading from a luminance circle (E3): median time per frame of sampling the circle (360
//! samples, bilinear, eq. (1)) and both shift searches (eqs. (2)-(6) and (7)-(10)) with the
//! pattern match, at 256x256 through the hemispherical mirror.
//!
//!     cargo bench --bench heading
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use nalgebra::{Isometry2, Vector2};
use omniloop::load_scenario;
use omniloop::scenario::calibrate::calibrate_sensor;
use omniloop_sim::{Renderer, Scene, SensorNoise, World};
use omniloop_vision::luminance_heading::{LuminanceCircle, LuminanceConfig, ShiftMethod};
use std::time::Instant;

fn main() {
    let s = load_scenario(&common::scenario_path("render_spherical.toml")).expect("scenario");
    let spec = &s.robot.sensors[0];
    let sensor = spec.build();
    let cal = calibrate_sensor(spec).expect("calibration");
    let config = LuminanceConfig::default();
    let radius = config.circle_radius_px(&cal).expect("horizontal circle");
    let centre = cal.principal_point_px;
    let mut renderer = Renderer::cpu();
    let mut noise = SensorNoise::new(1);
    let frames: Vec<_> = [0.0, -24.0, 60.0, 120.0, 180.0]
        .iter()
        .map(|deg: &f64| {
            let pose = Isometry2::new(Vector2::zeros(), deg.to_radians());
            let mut bodies = s.robot_bodies();
            bodies[0].start = pose;
            let world = World::new(&s.world, &bodies, 0.0025).expect("world");
            renderer
                .render(&Scene::of_world(&world), &sensor, &pose, Some(&mut noise))
                .expect("render")
        })
        .collect();
    let reference = LuminanceCircle::capture(&frames[0], centre, radius, &config).expect("ref");
    let mut t = Vec::new();
    for _ in 0..200 {
        for img in &frames {
            let t0 = Instant::now();
            let c = LuminanceCircle::capture(img, centre, radius, &config).expect("circle");
            for method in [ShiftMethod::Signs, ShiftMethod::Differences] {
                std::hint::black_box(c.shift_from(&reference, method, &config).expect("shift"));
            }
            t.push(t0.elapsed().as_secs_f64() * 1e3);
        }
    }
    t.sort_by(f64::total_cmp);
    let title = format!("luminance heading (256x256, R = {radius:.1} px)");
    println!("{title:<52} {:>10} {:>10}", "median ms", "p90 ms");
    println!(
        "{:<52} {:>10.4} {:>10.4}",
        "sampling + signs + differences + pattern match",
        t[t.len() / 2],
        t[t.len() * 9 / 10]
    );
}
