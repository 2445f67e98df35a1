//! E3 end to end: heading error from a luminance circle through the hemispherical mirror, at
//! the checkpoint of the room and off it.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{cpu, scenario};
use nalgebra::{Isometry2, Vector2};
use omniloop::experiments::Metrics;
use omniloop::experiments::heading::HeadingMetrics;
use omniloop::run_scenario;
use omniloop::scenario::calibrate::calibrate_sensor;
use omniloop_sim::{Renderer, Scene, SensorNoise, World};
use omniloop_vision::luminance_heading::{LuminanceConfig, near_ring};

#[test]
fn e3_turns_are_read_within_a_degree_and_translations_turn_na() {
    let s = scenario("heading_room.toml");
    let out = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap();
    let h = HeadingMetrics::of(&out.summary).unwrap();
    eprintln!("{h:#?}");
    // The paper's turns, 20 noisy frames each: every frame within +-1 degree, none N/A.
    assert_eq!(h.rotations.len(), 3);
    for r in &h.rotations {
        assert_eq!((r.frames, r.na_frames), (20, 0), "{r:?}");
        assert!(r.max_abs_error_deg.unwrap() <= 1.0, "{r:?}");
    }
    // The whole turn in 5-degree steps.
    assert_eq!(h.sweep_na, 0);
    assert!(h.sweep_max_abs_error_deg.unwrap() <= 1.0, "{h:?}");
    // Off the checkpoint: at 20 cm still read, within a few degrees; by 50 cm N/A everywhere.
    for (dir, readings) in &h.translation_shift_deg {
        let readings = readings.as_array().unwrap();
        let at = |cm: usize| readings[cm / 5].as_f64();
        let at20 = at(20).unwrap_or_else(|| panic!("{dir}: N/A at 20 cm"));
        assert!(at20.abs() <= 3.0, "{dir}: {at20} deg at 20 cm");
        for cm in [50, 55, 60] {
            assert!(at(cm).is_none(), "{dir}: read at {cm} cm: {readings:?}");
        }
    }
}

#[test]
fn on_patrol_the_checkpoint_keeps_the_heading_and_without_it_the_error_grows() {
    // Ten laps through the checkpoint on odometry with a rotation-rate bias.
    let mut s = scenario("heading_patrol.toml");
    assert!(s.odometry.omega_bias_rad_s > 0.0);
    let with = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap().summary;
    let visits = with.checkpoint_heading_error_deg.clone().unwrap();
    eprintln!("with correction: {visits:.2?}; {with:?}");
    assert!(with.reached_goal, "{with:?}");
    assert_eq!(with.wall_contacts, 0);
    // The start, nine passes and the arrival at the goal.
    assert!(visits.len() >= 11, "{visits:?}");
    assert!(visits.iter().all(|&e| e <= 1.5), "{visits:?}");
    // The same patrol reading but not correcting: the error grows by the bias, lap by lap.
    s.control.pose_source = omniloop_robot::ODOMETRY.into();
    let without = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap().summary;
    let drift = without.checkpoint_heading_error_deg.clone().unwrap();
    eprintln!("without: {drift:.2?}");
    assert!(drift.len() >= 11, "{drift:?}");
    assert!(drift[1..].windows(2).all(|w| w[1] > w[0]), "{drift:?}");
    assert!(*drift.last().unwrap() > 30.0, "{drift:?}");
}

#[test]
fn the_inner_circle_tells_which_way_something_stands_near() {
    // Sect. 4: a second circle looking down at the floor close by. The grey box at (1200,
    // -2300), 700 mm wide, has its face 250 mm from a robot at (1200, -1700): seen toward -y.
    let s = scenario("heading_room.toml");
    let spec = &s.robot.sensors[0];
    let sensor = spec.build();
    let cal = calibrate_sensor(spec).unwrap();
    let config = LuminanceConfig::default();
    let mut renderer = Renderer::cpu();
    let mut noise = SensorNoise::new(2);
    let mut near_at = |x: f64, y: f64| {
        let pose = Isometry2::new(Vector2::new(x, y), 0.0);
        let mut bodies = s.robot_bodies();
        bodies[0].start = pose;
        let world = World::new(&s.world, &bodies, 0.0025).unwrap();
        let img = renderer
            .render(&Scene::of_world(&world), &sensor, &pose, Some(&mut noise))
            .unwrap();
        near_ring(&img, &cal, &config).unwrap()
    };
    // At the room's centre nothing is near.
    assert!(near_at(0.0, 0.0).iter().all(|&n| !n));
    let near = near_at(1200.0, -1700.0);
    let toward = |deg: i32| near[deg.rem_euclid(360) as usize];
    // Toward the box (-90 degrees) it is near; away from it nothing is.
    assert!((-110..=-70).all(toward), "{near:?}");
    assert!((30..=150).all(|d| !toward(d)), "{near:?}");
}
