//! Renderer benchmark: median time per frame (and frames per second) of the field scene seen
//! through the corner paper's hyperbolic mirror, at 256x220 and 512x512, on the CPU and, when an
//! adapter exists, the GPU (readback included, noise excluded).
//!
//!     cargo bench --bench render

mod common;

use omniloop::load_scenario;
use omniloop_sim::{Renderer, RendererChoice, Scene, World};
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let path = common::scenario_path("render_hyperbolic.toml");
    let s = load_scenario(&path).expect("render_hyperbolic.toml loads");
    let world = World::new(&s.world, &s.robot_bodies(), 0.002).expect("world");
    let scene = Scene::of_world(&world);
    let pose = world.robot_state(0).pose;
    let small = s.robot.sensors[0].build().expect("sensor");
    let mut big_spec = s.robot.sensors[0].clone();
    big_spec.width_px = 512;
    big_spec.height_px = 512;
    if let Some(m) = big_spec.hyperbolic.as_mut() {
        m.focal_px *= 2.0;
    }
    let big = big_spec.build().expect("sensor");

    let mut renderers = vec![Renderer::cpu()];
    match Renderer::new(RendererChoice::Gpu, |_| {}) {
        Ok(g) => renderers.push(g),
        Err(e) => println!("GPU: not measured ({e})"),
    }
    println!(
        "{:<48} {:>10} {:>12} {:>10}",
        "renderer", "image", "median ms", "fps"
    );
    for r in renderers.iter_mut() {
        for sensor in [&small, &big] {
            // Warm-up (caches, pipeline, buffers).
            for _ in 0..5 {
                r.render_packed(&scene, sensor, &pose).expect("render");
            }
            let frames = if sensor.width_px > 256 { 60 } else { 200 };
            let times: Vec<f64> = (0..frames)
                .map(|_| {
                    let t = Instant::now();
                    r.render_packed(&scene, sensor, &pose).expect("render");
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect();
            let m = median(times);
            println!(
                "{:<48} {:>10} {:>12.3} {:>10.1}",
                r.name(),
                format!("{}x{}", sensor.width_px, sensor.height_px),
                m,
                1e3 / m
            );
        }
    }
}
