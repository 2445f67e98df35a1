//! Three-mark resection (E5): median time of the mark search in one frame of the panning camera
//! (256 x 256, 16 grey levels: bands R1 and R2 averaged, binarized, stripe ratios matched and
//! confirmed), with the resection itself, and the search in one 1024 x 1024 omnidirectional
//! image (both rings) for comparison.
//!
//!     cargo bench --bench resection
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use nalgebra::{Isometry2, Point2, Vector2};
use omniloop::load_scenario;
use omniloop::scenario::calibrate::calibrate_sensor;
use omniloop_sim::optics::Optics;
use omniloop_sim::{Renderer, Scene, SensorNoise};
use omniloop_vision::resection::{
    MarkBearing, ResectionConfig, StripePattern, find_marks, find_marks_ring, resect,
};
use std::hint::black_box;
use std::time::Instant;

/// Median of `t`.
fn median(mut t: Vec<f64>) -> f64 {
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

/// Median time of `f` over `reps` runs, ms.
fn time(reps: usize, mut f: impl FnMut(usize)) -> f64 {
    let t: Vec<f64> = (0..reps)
        .map(|k| {
            let t0 = Instant::now();
            f(k);
            t0.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    median(t)
}

fn main() {
    let s = load_scenario(&common::scenario_path("resection_lab.toml")).expect("scenario");
    let map = s.robot_map();
    let patterns: Vec<StripePattern> = map.marks.iter().map(|m| m.pattern.clone()).collect();
    let config = ResectionConfig::default();
    let scene = Scene::new(&s.world, &[]);
    let mut renderer = Renderer::cpu();
    let mut noise = SensorNoise::new(1);
    let pose = Isometry2::new(Vector2::new(2560.0, 1380.0), 0.0);
    // Twenty frames of a sweep, 18 degrees apart: some show a mark, most do not.
    let mut pan = s.robot.sensors[0].build();
    let frames: Vec<image::RgbaImage> = (0..20)
        .map(|k| {
            if let Optics::Pinhole(c) = &mut pan.optics {
                c.pan_deg = -180.0 + 18.0 * k as f64;
            }
            renderer
                .render(&scene, &pan, &pose, Some(&mut noise))
                .expect("render")
        })
        .collect();
    let seen: usize = frames
        .iter()
        .map(|f| find_marks(f, &patterns, &config).map_or(0, |m| m.len()))
        .sum();
    let search = time(2000, |k| {
        black_box(find_marks(black_box(&frames[k % frames.len()]), &patterns, &config).ok());
    });
    let marks: Vec<MarkBearing> = map
        .marks
        .iter()
        .map(|m| {
            let v = m.centre_mm - Point2::from(pose.translation.vector);
            MarkBearing {
                position: m.centre_mm,
                bearing_rad: v.y.atan2(v.x),
            }
        })
        .collect();
    let solve = time(2000, |_| {
        black_box(resect(&marks[0], &marks[1], &marks[2]).ok());
    });
    let omni_spec = &s.robot.sensors[1];
    let omni = omni_spec.build();
    let cal = calibrate_sensor(omni_spec).expect("omni calibration");
    let image = renderer
        .render(&scene, &omni, &pose, Some(&mut noise))
        .expect("render");
    let ring = time(30, |_| {
        black_box(find_marks_ring(black_box(&image), &cal, &patterns, &config).ok());
    });
    println!("resection (E5), CPU, this machine:");
    println!(
        "  mark search, one 256x256 frame of the pan camera: median {:.4} ms (target <= 0.05 ms; \
         {seen} marks in the 20 frames)",
        search
    );
    println!("  resection from three bearings: median {:.5} ms", solve);
    println!(
        "  mark search, one 1024x1024 omnidirectional image (two rings of {} samples): median \
         {:.2} ms",
        config.ring_samples, ring
    );
}
