//! Controller benchmark: median decision time of the velocity-aware controller per control
//! cycle (64 candidate directions, the default), on the free space of rendered 256x220 frames
//! along the E1 corridor and round its corner, at several velocities; chosen speeds (the
//! default, for the corner paper's robot and a Small-Size one) and the paper's fixed speed.
//!
//!     cargo bench --bench avoidance
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use nalgebra::{Isometry2, Point2, Vector2};
use omniloop::load_scenario;
use omniloop::scenario::calibrate::calibrate_sensor;
use omniloop_control::{
    AccelLimitedDrive, AvoidanceConfig, SpeedChoice, Surroundings, VelocityAware,
};
use omniloop_sim::{Renderer, Scene, SensorNoise, World};
use omniloop_vision::{FreeSpace, FreeSpaceDetector};
use std::time::Instant;

/// Poses along the corridor and round the corner (x, y, heading in degrees).
const POSES: [(f64, f64, f64); 8] = [
    (-2500.0, 0.0, 0.0),
    (-1800.0, 150.0, 0.0),
    (-1200.0, -200.0, 0.0),
    (-800.0, 250.0, 0.0),
    (-400.0, 100.0, 0.0),
    (-150.0, 250.0, 0.0),
    (-450.0, 650.0, 0.0),
    (-750.0, 1100.0, 0.0),
];

fn frames() -> Vec<(FreeSpace, Vector2<f64>)> {
    let s = load_scenario(&common::scenario_path("corner55_velocity_aware.toml"))
        .expect("corner scenario loads");
    let spec = &s.robot.sensors[0];
    let sensor = spec.build();
    let cal = calibrate_sensor(spec).expect("calibration");
    let mut detector = FreeSpaceDetector::new(s.vision.table("freespace").expect("settings"), &cal)
        .expect("detector");
    let goal = s.goal.as_ref().expect("goal").point();
    let mut renderer = Renderer::cpu();
    let mut noise = SensorNoise::new(1);
    POSES
        .iter()
        .map(|&(x, y, deg)| {
            let mut bodies = s.robot_bodies();
            bodies[0].start = Isometry2::new(Vector2::new(x, y), deg.to_radians());
            let world = World::new(&s.world, &bodies, 0.002).expect("world");
            let pose = world.robot_state(0).pose;
            let img = renderer
                .render(&Scene::of_world(&world), &sensor, &pose, Some(&mut noise))
                .expect("render");
            let fs = detector.detect(&img).expect("detect");
            (fs, pose.inverse_transform_point(&goal).coords)
        })
        .collect()
}

fn points(p: &[Point2<f64>]) -> Vec<Vector2<f64>> {
    p.iter().map(|q| q.coords).collect()
}

fn main() {
    let frames = frames();
    println!(
        "{:<44} {:>10} {:>10} {:>10}",
        "velocity-aware decision (64 directions)", "median ms", "p90 ms", "decisions"
    );
    let cases = [
        (
            "chosen speeds, 400 mm/s, alpha 300",
            SpeedChoice::Chosen,
            400.0,
            300.0,
        ),
        (
            "chosen speeds, 2000 mm/s, alpha 3000",
            SpeedChoice::Chosen,
            2000.0,
            3000.0,
        ),
        (
            "fixed speed (the paper's), 400 mm/s",
            SpeedChoice::Fixed,
            400.0,
            300.0,
        ),
    ];
    for (name, speed, v_max, alpha) in cases {
        let config = AvoidanceConfig {
            speed,
            ..AvoidanceConfig::default()
        };
        let drive = AccelLimitedDrive::new(alpha, 10.0).expect("drive");
        let c = VelocityAware::new(config, drive, v_max, 90.0, 0.04).expect("controller");
        let velocities = [0.0, 0.3, 0.7, 1.0].map(|f| Vector2::new(f * v_max, 0.1 * f * v_max));
        let mut t = Vec::new();
        for _ in 0..20 {
            for (fs, goal) in &frames {
                let (obstacles, clear) = (points(&fs.obstacle_points), points(&fs.clear_points));
                let s = Surroundings {
                    direction_rad: &fs.direction_rad,
                    free_mm: &fs.free_mm,
                    range_mm: fs.range_mm,
                    obstacle_points: &obstacles,
                    clear_points: &clear,
                    blind_points: &[],
                    moving_points: &[],
                    horizon_points: &[],
                };
                for v in velocities {
                    let t0 = Instant::now();
                    std::hint::black_box(c.decide(&s, *goal, v));
                    t.push(t0.elapsed().as_secs_f64() * 1e3);
                }
            }
        }
        t.sort_by(f64::total_cmp);
        println!(
            "{:<44} {:>10.4} {:>10.4} {:>10}",
            name,
            t[t.len() / 2],
            t[t.len() * 9 / 10],
            t.len()
        );
    }
}
