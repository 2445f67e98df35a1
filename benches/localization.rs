//! Self-localization stage benchmark: median time of steps 1-7 of Sect. 4 (floor extraction,
//! boundary, hull, moments, least squares, goal colours) on 256x220 frames of the E2 field.
//!
//!     cargo bench --bench localization

mod common;

use omniloop::calibrate::calibrate_sensor;
use omniloop::experiments::ExperimentSpec;
use omniloop::load_scenario;
use omniloop_sim::{Renderer, Scene, SensorNoise, World};
use omniloop_vision::FloorLocalizer;
use std::time::Instant;

fn main() {
    let path = common::scenario_path("selfloc_field.toml");
    let s = load_scenario(&path).expect("E2 scenario loads");
    let spec = &s.robot.sensors[0];
    let sensor = spec.build().expect("sensor");
    let cal = calibrate_sensor(spec).expect("calibration");
    let mut renderer = Renderer::cpu();
    let mut noise = SensorNoise::new(1);
    let Some(ExperimentSpec::Places(spec)) = &s.experiment else {
        panic!("selfloc_field.toml has [experiment.places]");
    };
    let places = &spec.places;
    let mut frames = Vec::new();
    for p in places {
        let mut bodies = s.robot_bodies();
        bodies[0].start = p.isometry();
        let world = World::new(&s.world, &bodies, 0.0025).expect("world");
        let scene = Scene::of_world(&world);
        frames.push(
            renderer
                .render(
                    &scene,
                    &sensor,
                    &world.robot_state(0).pose,
                    Some(&mut noise),
                )
                .expect("render"),
        );
    }
    let mut loc = FloorLocalizer::new(s.vision.localization.clone(), &cal).expect("localizer");
    for f in &frames {
        loc.locate(f, None).expect("locate");
    }
    let mut t: Vec<f64> = (0..600)
        .map(|k| {
            let f = &frames[k % frames.len()];
            let t0 = Instant::now();
            std::hint::black_box(loc.locate(f, None).expect("locate"));
            t0.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    println!(
        "self-localization (256x220, six E2 places): median {:.4} ms, p90 {:.4} ms",
        t[t.len() / 2],
        t[t.len() * 9 / 10]
    );
}
