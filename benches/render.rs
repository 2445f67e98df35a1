//! Renderer benchmark: median time per frame (and frames per second) of the field scene seen
//! through the corner paper's hyperbolic mirror, at 256x220 and 512x512, on the CPU (one core,
//! then all cores) and, when an adapter exists, the GPU (readback and the sensor noise included,
//! as a run draws them); the extra cost of the truth beside a frame (depth, labels), frames with
//! and without it in turn; then batches of 1, 16, 256 and 1024 noisy frames (the GPU traces a
//! batch in one dispatch).
//!
//!     cargo bench --bench render
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use omniloop::load_scenario;
use omniloop_sim::render::noise::frame_key;
use omniloop_sim::{FrameNoise, FrameRequest, Renderer, RendererChoice, Scene, SensorNoise, World};
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median time of `f` over `reps` calls, ms.
fn median_ms(reps: usize, mut f: impl FnMut()) -> f64 {
    median(
        (0..reps)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect(),
    )
}

fn main() {
    let path = common::scenario_path("render_hyperbolic.toml");
    let s = load_scenario(&path).expect("render_hyperbolic.toml loads");
    let world = World::new(&s.world, &s.robot_bodies(), 0.002).expect("world");
    let scene = Scene::of_world(&world);
    let pose = world.robot_state(0).pose;
    let small = s.robot.sensors[0].build();
    let mut big_spec = s.robot.sensors[0].clone();
    big_spec.width_px = 512;
    big_spec.height_px = 512;
    if let omniloop_sim::optics::Optics::Hyperbolic(m) = &mut big_spec.optics {
        m.focal_px *= 2.0;
    }
    let big = big_spec.build();

    println!(
        "{:<48} {:>10} {:>12} {:>10}",
        "renderer", "image", "median ms", "fps"
    );
    // The CPU renderer on one core (a pool of one thread), then on all cores, then the GPU.
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    one.install(|| {
        let mut cpu = Renderer::cpu();
        frame_times(&mut cpu, &scene, &[&small, &big], &pose);
        clean_frame_time(&mut cpu, &scene, &small, &pose);
        truth_cost(&mut cpu, &scene, &small, &pose);
    });
    let mut renderers = vec![Renderer::cpu()];
    match Renderer::new(RendererChoice::Gpu, |_| {}) {
        Ok(g) => renderers.push(g),
        Err(e) => println!("GPU: not measured ({e})"),
    }
    for r in renderers.iter_mut() {
        frame_times(r, &scene, &[&small, &big], &pose);
    }
    for r in renderers.iter_mut().filter(|r| r.is_gpu()) {
        truth_cost(r, &scene, &small, &pose);
    }
    batches(&mut renderers, &scene, &small, &pose);
}

/// The median time of a noisy frame of each sensor, a line each.
fn frame_times(
    r: &mut Renderer,
    scene: &Scene,
    sensors: &[&omniloop_sim::Sensor],
    pose: &nalgebra::Isometry2<f64>,
) {
    for sensor in sensors {
        // Warm-up (caches, pipeline, buffers).
        let mut noise = SensorNoise::new(1);
        for _ in 0..5 {
            r.render(scene, sensor, pose, Some(&mut noise))
                .expect("render");
        }
        let frames = if sensor.width_px > 256 { 60 } else { 200 };
        let m = median_ms(frames, || {
            r.render(scene, sensor, pose, Some(&mut noise))
                .expect("render");
        });
        println!(
            "{:<48} {:>10} {:>12.3} {:>10.1}",
            r.name(),
            format!("{}x{}", sensor.width_px, sensor.height_px),
            m,
            1e3 / m
        );
    }
}

/// The median time of a frame of `sensor` without noise (as the renderer traced it before the
/// noise was drawn as the frame is read back).
fn clean_frame_time(
    r: &mut Renderer,
    scene: &Scene,
    sensor: &omniloop_sim::Sensor,
    pose: &nalgebra::Isometry2<f64>,
) {
    for _ in 0..5 {
        r.render_packed(scene, sensor, pose).expect("render");
    }
    let m = median_ms(200, || {
        r.render_packed(scene, sensor, pose).expect("render");
    });
    println!(
        "{:<48} {:>10} {:>12.3} {:>10.1}",
        format!("{} without noise", r.name()),
        format!("{}x{}", sensor.width_px, sensor.height_px),
        m,
        1e3 / m
    );
}

/// The median time of a noisy frame with its truth and without, taken in turn, and the truth's
/// extra cost as a share of the frame.
fn truth_cost(
    r: &mut Renderer,
    scene: &Scene,
    sensor: &omniloop_sim::Sensor,
    pose: &nalgebra::Isometry2<f64>,
) {
    let mut noise = SensorNoise::new(1);
    let poses = [*pose];
    let (mut without, mut with) = (Vec::new(), Vec::new());
    for k in 0..405 {
        let t = Instant::now();
        if k % 2 == 0 {
            r.render_exposed(scene, sensor, &poses, Some(&mut noise))
                .expect("render");
        } else {
            r.render_exposed_truth(scene, sensor, &poses, Some(&mut noise))
                .expect("render with truth");
        }
        let ms = t.elapsed().as_secs_f64() * 1e3;
        // The first frames of each warm the caches.
        if k >= 5 {
            if k % 2 == 0 { &mut without } else { &mut with }.push(ms);
        }
    }
    let (a, b) = (median(without), median(with));
    for (what, m) in [("noisy", a), ("noisy, with truth", b)] {
        println!(
            "{:<48} {:>10} {:>12.3} {:>10.1}",
            format!("{} {what}", r.name()),
            format!("{}x{}", sensor.width_px, sensor.height_px),
            m,
            1e3 / m
        );
    }
    println!(
        "{:<48} {:>10} {:>11.0}%",
        format!("{}: the truth's extra cost", r.name()),
        "",
        100.0 * (b - a) / a
    );
}

/// Frames/s of batches of 1, 16, 256 and 1024 noisy frames of the small sensor, each frame at its own pose
/// (a step apart along x): on the GPU one dispatch and one readback a batch, on the CPU the
/// frames one after the other.
fn batches(
    renderers: &mut [Renderer],
    scene: &Scene,
    sensor: &omniloop_sim::Sensor,
    pose: &nalgebra::Isometry2<f64>,
) {
    println!(
        "\n{:<48} {:>10} {:>12} {:>10}",
        "batched (256x220)", "batch", "median ms", "frames/s"
    );
    let poses: Vec<nalgebra::Isometry2<f64>> = (0..1024)
        .map(|k| {
            let mut p = *pose;
            p.translation.x += 2.0 * k as f64;
            p
        })
        .collect();
    for r in renderers.iter_mut() {
        for n in [1usize, 16, 256, 1024] {
            if !r.is_gpu() && n > 16 {
                continue;
            }
            let requests: Vec<FrameRequest> = poses[..n]
                .iter()
                .enumerate()
                .map(|(k, p)| FrameRequest {
                    scene,
                    sensor,
                    pose: p,
                    noise: Some(FrameNoise {
                        key: frame_key(1, k as u64),
                        sigma: sensor.noise_sigma as f32,
                    }),
                })
                .collect();
            r.render_batch_packed(&requests).expect("render");
            let reps = if n >= 256 { 3 } else { 20 };
            let m = median_ms(reps, || {
                r.render_batch_packed(&requests).expect("render");
            });
            println!(
                "{:<48} {:>10} {:>12.3} {:>10.1}",
                r.name(),
                n,
                m,
                n as f64 * 1e3 / m
            );
        }
    }
}
