//! Free space on rendered frames: the detected free distance of every direction against the
//! distance ray-cast in the world, and the labelling and counting variants of eq. (5).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::scenario;
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop::run::cameras::sensor_noise_seed;
use omniloop::scenario::calibrate::calibrate_sensor;
use omniloop_sim::{Renderer, Scene, SensorNoise, World};
use omniloop_vision::{FreeSpaceDetector, FreeSpaceMethod};

/// Poses along and around the E1 corridor.
const POSES: [(f64, f64, f64); 8] = [
    (-2500.0, 0.0, 0.0),
    (-1800.0, 200.0, 0.0),
    (-1200.0, -250.0, 30.0),
    (-900.0, 250.0, 0.0),
    (-600.0, 200.0, -45.0),
    (-200.0, 0.0, 90.0),
    (-500.0, 700.0, 125.0),
    (-800.0, 1100.0, 0.0),
];

#[test]
fn detected_free_distances_match_the_ray_cast_world_within_a_ring() {
    let s = scenario("corner55_velocity_aware.toml");
    let spec = &s.robot.sensors[0];
    let sensor = spec.build();
    let cal = calibrate_sensor(spec).unwrap();
    let mut renderer = Renderer::cpu();
    let mut noise = SensorNoise::new(sensor_noise_seed(s.seed, 0));
    let config: omniloop_vision::FreeSpaceConfig = s.vision.table("freespace").unwrap();
    let mut count = FreeSpaceDetector::new(config.clone(), &cal).unwrap();
    let mut labeling = FreeSpaceDetector::new(
        omniloop_vision::FreeSpaceConfig {
            method: FreeSpaceMethod::Labeling,
            ..config
        },
        &cal,
    )
    .unwrap();
    let edges = count.template().edges_mm().to_vec();
    let range = *edges.last().unwrap();
    let mut errors: Vec<f64> = Vec::new();
    let mut within = 0;
    let mut total = 0;
    let mut differ = 0;
    for (x, y, deg) in POSES {
        let mut bodies = s.robot_bodies();
        bodies[0].start = Isometry2::new(Vector2::new(x, y), deg.to_radians());
        let world = World::new(&s.world, &bodies, 0.002).unwrap();
        let pose = world.robot_state(0).pose;
        let scene = Scene::of_world(&world);
        let img = renderer
            .render(&scene, &sensor, &pose, Some(&mut noise))
            .unwrap();
        let fs = count.detect(&img).unwrap();
        let fl = labeling.detect(&img).unwrap();
        differ += fs.a.iter().zip(&fl.a).filter(|(a, b)| a != b).count();
        for (a, free) in fs.direction_rad.iter().zip(&fs.free_mm) {
            let theta = pose.rotation.angle() + a;
            let truth = world
                .ray_cast_mm(
                    Point2::from(pose.translation.vector),
                    Vector2::new(theta.cos(), theta.sin()),
                    range,
                    Some(0),
                )
                .unwrap_or(range);
            errors.push((free - truth).abs());
            total += 1;
            // Eq. (6) judges a cell by the share of floor in it, so the detected distance is
            // one of the two edges of the ring that holds the true distance: the inner one when
            // the obstacle fills at least half of the cell, the outer one otherwise.
            let ring = edges.windows(2).find(|w| truth >= w[0] && truth < w[1]);
            let ok = match ring {
                Some(w) => *free >= w[0] - 1.0 && *free <= w[1] + 1.0,
                None => (*free - truth).abs() < 1e-6 || truth < edges[0],
            };
            within += ok as usize;
            if !ok {
                eprintln!(
                    "pose ({x}, {y}, {deg}) direction {:.1} deg: free {free:.1}, truth {truth:.1}",
                    a.to_degrees()
                );
            }
        }
    }
    errors.sort_by(f64::total_cmp);
    let median = errors[errors.len() / 2];
    eprintln!(
        "free space vs ray-cast truth over {total} directions: median error {median:.1} mm, \
         {within} within a ring, labelling and counting differ in {differ}"
    );
    assert!(median < 40.0, "median {median}");
    assert!(within as f64 >= 0.98 * total as f64, "{within} of {total}");
    // The template's one-pixel lines keep every labelled area inside its cell, so the two
    // variants of eq. (5) agree.
    assert_eq!(differ, 0);
}
