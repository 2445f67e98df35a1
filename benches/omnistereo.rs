//! Conical omnistereo (E4): median time of the whole per-frame estimate from both images at the
//! arena's 512x512 (the robot's omnistereo stage: the marks in both images, the ranges of
//! eq. (1), trilateration, the visual compass against the previous frame and the interframe
//! clustering), with the parts it is made of.
//!
//!     cargo bench --bench omnistereo
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use nalgebra::{Isometry2, Vector2};
use omniloop::load_scenario;
use omniloop_robot::perception::{Belief, OmnistereoStage, Perceived, Stage};
use omniloop_robot::{Frame, Observation};
use omniloop_sim::{Renderer, Scene, SensorNoise, World};
use omniloop_vision::omnistereo::{AngularProfile, MirrorRim, OmnistereoConfig, detect_marks};
use std::time::Instant;

/// Median and 90th percentile of `t`, ms.
fn summary(mut t: Vec<f64>) -> (f64, f64) {
    t.sort_by(f64::total_cmp);
    (t[t.len() / 2], t[t.len() * 9 / 10])
}

fn main() {
    let s = load_scenario(&common::scenario_path("omnistereo_arena.toml")).expect("scenario");
    let config = s.robot_config(Vec::new(), Vec::new());
    let rig = config.stereo.expect("the arena's robot has two cones");
    let sensors: Vec<_> = s.robot.sensors.iter().map(|x| x.build()).collect();
    let mut renderer = Renderer::cpu();
    let mut noise: Vec<SensorNoise> = (0..2).map(|i| SensorNoise::new(i + 1)).collect();
    // Twenty frames along a straight leg, 15 mm and a quarter degree apart.
    let frames: Vec<Vec<image::RgbaImage>> = (0..20)
        .map(|k| {
            let pose = Isometry2::new(
                Vector2::new(-600.0 + 15.0 * k as f64, 100.0),
                (10.0 + 0.25 * k as f64).to_radians(),
            );
            let mut bodies = s.robot_bodies();
            bodies[0].start = pose;
            let world = World::new(&s.world, &bodies, 0.002).expect("world");
            let scene = Scene::of_world(&world);
            sensors
                .iter()
                .zip(&mut noise)
                .map(|(sensor, n)| {
                    renderer
                        .render(&scene, sensor, &pose, Some(n))
                        .expect("render")
                })
                .collect()
        })
        .collect();
    let settings = config.vision.table("omnistereo").expect("settings");
    let mut stage = OmnistereoStage::new(settings, rig, &config.map.landmarks).expect("stage");
    let belief = Belief {
        pose: None,
        fixed: false,
        odometry_pose: Isometry2::identity(),
    };
    let mut run = |imgs: &[image::RgbaImage]| {
        let f = [
            Frame {
                sensor: "lower",
                t_s: 0.0,
                image: &imgs[0],
            },
            Frame {
                sensor: "upper",
                t_s: 0.0,
                image: &imgs[1],
            },
        ];
        let obs = Observation {
            t_s: 0.0,
            frames: &f,
            actuators: &[],
        };
        let mut out = Perceived::default();
        stage.run(&obs, &belief, &mut out).expect("stage");
        out
    };
    // The first frame calibrates (the rims, eq. (2)); it is not a per-frame cost.
    let first = Instant::now();
    run(&frames[0]);
    let calibration_ms = first.elapsed().as_secs_f64() * 1e3;
    let mut whole = Vec::new();
    for _ in 0..20 {
        for imgs in &frames {
            let t0 = Instant::now();
            std::hint::black_box(run(imgs));
            whole.push(t0.elapsed().as_secs_f64() * 1e3);
        }
    }
    let rims: Vec<MirrorRim> = frames[0]
        .iter()
        .map(|i| MirrorRim::measure(i).expect("rim"))
        .collect();
    let palette: Vec<[u8; 3]> = config.map.landmarks.iter().map(|l| l.rgb).collect();
    let vision: &OmnistereoConfig = &config.vision.table("omnistereo").expect("settings");
    let (mut marks, mut compass) = (Vec::new(), Vec::new());
    for _ in 0..20 {
        for imgs in &frames {
            let t0 = Instant::now();
            for (img, rim) in imgs.iter().zip(&rims) {
                std::hint::black_box(detect_marks(img, rim, &palette, &vision.marks));
            }
            marks.push(t0.elapsed().as_secs_f64() * 1e3);
            let t0 = Instant::now();
            let pairs: Vec<_> = imgs.iter().zip(&rims).collect();
            std::hint::black_box(AngularProfile::capture(&pairs, &vision.compass));
            compass.push(t0.elapsed().as_secs_f64() * 1e3);
        }
    }
    println!(
        "{:<60} {:>10} {:>10}",
        "omnistereo per frame (2 x 512x512)", "median ms", "p90 ms"
    );
    for (name, t) in [
        (
            "whole estimate (marks, ranges, trilateration, compass, motion)",
            whole,
        ),
        ("  marks in both images", marks),
        ("  compass profiles of both images", compass),
    ] {
        let (m, p) = summary(t);
        println!("{name:<60} {m:>10.4} {p:>10.4}");
    }
    println!(
        "{:<60} {calibration_ms:>10.4}",
        "first frame, with the rim calibration"
    );
}
