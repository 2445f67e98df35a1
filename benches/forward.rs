//! The forward camera (E6): median time per 160 x 120 frame of each method — ground
//! segmentation, Horn-Schunck flow (with its balance), the scan-line profile and shift, Harris
//! corners, and one visual odometry step (scan line, corners, Lucas-Kanade and
//! cross-correlation) — on frames rendered along a straight run over the marked floor.
//!
//!     cargo bench --bench forward
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use nalgebra::{Isometry2, Vector2};
use omniloop::load_scenario;
use omniloop_sim::{Renderer, Scene, SensorNoise};
use omniloop_vision::forward::{
    FlowBalance, FlowConfig, ForwardOdometry, GroundConfig, GroundSegmenter, HarrisConfig,
    OdometryConfig, ScanLine, ScanLineConfig, grey, harris_corners, horn_schunck, reduce,
};
use std::hint::black_box;
use std::time::Instant;

/// Median time of `f` over `reps` runs, ms.
fn time(reps: usize, mut f: impl FnMut(usize)) -> f64 {
    let mut t: Vec<f64> = (0..reps)
        .map(|k| {
            let t0 = Instant::now();
            f(k);
            t0.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

fn main() {
    let s = load_scenario(&common::scenario_path("forward_odometry.toml")).expect("scenario");
    let camera = s.forward_camera().expect("a forward camera");
    let sensor = s.robot.sensors[0].build();
    let scene = Scene::new(&s.world, &[]);
    let mut renderer = Renderer::cpu();
    let mut noise = SensorNoise::new(1);
    // Twenty frames 6 mm apart (150 mm/s at 25 frames a second).
    let frames: Vec<_> = (0..20)
        .map(|k| {
            let pose = Isometry2::new(
                Vector2::new(-700.0, -600.0 + 6.0 * k as f64),
                std::f64::consts::FRAC_PI_2,
            );
            let img = renderer
                .render(&scene, &sensor, &pose, Some(&mut noise))
                .expect("render");
            grey(&img)
        })
        .collect();
    let n = frames.len();
    let mut ground = GroundSegmenter::new(&camera, 120.0, GroundConfig::default());
    let seg = time(200, |k| {
        black_box(ground.update(&frames[k % n]));
    });
    let fc = FlowConfig::default();
    let small: Vec<_> = frames.iter().map(|f| reduce(f, fc.downsample)).collect();
    let flow = time(30, |k| {
        let f = horn_schunck(&small[k % n], &small[(k + 1) % n], fc.alpha, fc.iterations);
        black_box(FlowBalance::of(&f, fc.skip_top, fc.downsample));
    });
    let scan = ScanLine::new(&camera, &ScanLineConfig::default()).expect("scan line");
    let profiles: Vec<_> = frames.iter().map(|f| scan.profile(f)).collect();
    let scanline = time(200, |k| {
        let p = scan.profile(&frames[k % n]);
        black_box(scan.rotation_rad(&profiles[(k + 1) % n], &p));
    });
    let h = camera.height_px;
    let harris = time(200, |k| {
        black_box(harris_corners(
            &frames[k % n],
            &HarrisConfig::default(),
            h / 4..h - 7,
            7,
        ));
    });
    let mut vo = ForwardOdometry::new(camera.clone(), OdometryConfig::default()).expect("vo");
    let mut tracked = 0usize;
    let step = time(100, |k| {
        if let Some(s) = vo.step(&frames[k % n]) {
            tracked += s.lk.as_ref().map_or(0, |m| m.inliers);
        }
    });
    println!(
        "forward camera, {}x{} frames (median per frame):",
        camera.width_px, h
    );
    println!("  ground segmentation            {seg:8.3} ms");
    println!(
        "  Horn-Schunck flow ({} iterations at 1/{}) {flow:8.3} ms",
        fc.iterations, fc.downsample
    );
    println!("  scan-line profile and shift    {scanline:8.3} ms");
    println!("  Harris corners                 {harris:8.3} ms");
    println!("  odometry step (scan line, Harris, LK, NCC) {step:8.3} ms  ({tracked} LK inliers)");
}
