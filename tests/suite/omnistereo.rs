//! E4 end to end: conical omnistereo in the pillar arena (Spacek and Burbridge): the 450-frame
//! wander on the robot's own estimates, the rim calibration of eq. (2) and the visual compass
//! on rendered frames, and the saved frame set.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{cpu, omniloop, scenario, scenario_path, tmp};
use nalgebra::{Isometry2, Vector2};
use omniloop::experiments::Metrics;
use omniloop::experiments::omnistereo::OmnistereoMetrics;
use omniloop::run_scenario;
use omniloop_sim::optics::Optics;
use omniloop_sim::{Renderer, Scene, SensorNoise, World};
use omniloop_vision::omnistereo::{AngularProfile, CompassConfig, MirrorRim};

/// The experiment's metrics of a run.
fn metrics(m: &omniloop::run::record::Summary) -> OmnistereoMetrics {
    OmnistereoMetrics::of(m).unwrap_or_else(|| panic!("no E4 metrics: {m:?}"))
}

#[test]
fn e4_wander_of_450_frames_meets_the_targets() {
    let s = scenario("omnistereo_arena.toml");
    let out = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap();
    let m = &out.summary;
    eprintln!("{}", omniloop::experiments::omnistereo::omnistereo_table(m));
    let e = metrics(m);
    assert_eq!(e.frames, 450);
    assert_eq!(m.wall_contacts, 0);
    // It wandered (450 frames at 300 mm/s are 6.75 m without turns), and every frame ranged
    // pillars.
    assert!(m.path_length_mm > 3000.0, "{}", m.path_length_mm);
    let range = e.range_error_pct.stats;
    assert!(range.n > 3 * 450, "{range:?}");
    assert!(range.median.unwrap() <= 1.0, "{range:?}");
    assert!(range.p95.unwrap() <= 3.0, "{range:?}");
    let tri = e.trilateration_error_mm;
    assert!(tri.n >= 400, "{tri:?}");
    assert!(tri.median.unwrap() <= 40.0, "{tri:?}");
    assert!(tri.p95.unwrap() <= 100.0, "{tri:?}");
    assert_eq!(e.compass_error_deg.n, 449);
    assert!(e.compass_error_deg.median.unwrap() <= 0.3, "{e:?}");
    let interframe = e.interframe_translation_error_mm;
    assert!(interframe.n >= 400, "{interframe:?}");
    assert!(interframe.median.unwrap() <= 10.0, "{interframe:?}");
    // The robot drove on its estimate: it stayed well inside the 200 mm clearance the wander
    // keeps from the map's obstacles.
    let worst = out
        .trajectory
        .iter()
        .filter_map(|r| Some((r.est_x_mm? - r.x_mm).hypot(r.est_y_mm? - r.y_mm)))
        .fold(0.0, f64::max);
    assert!(worst < 100.0, "estimate {worst:.1} mm off the truth");
}

/// Renders sensor `index` of the arena scenario with the robot at `pose`, with noise.
fn frame(index: usize, pose: Isometry2<f64>, seed: u64) -> image::RgbaImage {
    noisy_frame(index, pose, seed, 4.0)
}

/// The same with noise of `sigma` levels.
fn noisy_frame(index: usize, pose: Isometry2<f64>, seed: u64, sigma: f64) -> image::RgbaImage {
    let s = scenario("omnistereo_arena.toml");
    let mut bodies = s.robot_bodies();
    bodies[0].start = pose;
    let world = World::new(&s.world, &bodies, 0.002).unwrap();
    let mut sensor = s.robot.sensors[index].build();
    sensor.noise_sigma = sigma;
    let mut noise = SensorNoise::new(seed);
    Renderer::cpu()
        .render(&Scene::of_world(&world), &sensor, &pose, Some(&mut noise))
        .unwrap()
}

#[test]
fn the_rim_calibrates_v_by_eq_2() {
    let s = scenario("omnistereo_arena.toml");
    let Optics::Conical(cone) = s.robot.sensors[0].build().optics else {
        panic!("the arena's sensors are cones");
    };
    // Noise up to 12 levels: a few black pixels lifted over the threshold must not move the
    // rim (at sigma 6 they once left no rim at all).
    for (sigma, seed) in [(4.0, 1), (6.0, 2), (8.0, 3), (12.0, 4)] {
        let img = noisy_frame(
            0,
            Isometry2::new(Vector2::new(-600.0, 100.0), 0.3),
            seed,
            sigma,
        );
        let rim = MirrorRim::measure(&img).unwrap();
        // Eq. (2): v = (d / R + 1) r_m; the robot never reads focal_px, the test compares.
        let v = (cone.tip_distance_mm / cone.radius_mm + 1.0) * rim.radius_px;
        assert!(
            (v / cone.focal_px - 1.0).abs() < 1e-3,
            "sigma {sigma}: v = {v:.2} px from r_m = {:.3} px; focal {}",
            rim.radius_px,
            cone.focal_px
        );
    }
}

#[test]
fn e4_holds_its_targets_at_noise_sigma_8() {
    // The first 150 frames of the wander with twice the noise.
    let mut s = scenario("omnistereo_arena.toml");
    for sensor in &mut s.robot.sensors {
        sensor.noise_sigma = 8.0;
    }
    s.run.duration_s = 7.5;
    let m = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap().summary;
    eprintln!(
        "{}",
        omniloop::experiments::omnistereo::omnistereo_table(&m)
    );
    let e = metrics(&m);
    let range = e.range_error_pct.stats;
    assert!(range.n > 3 * 150, "{range:?}");
    assert!(range.median.unwrap() <= 1.0, "{range:?}");
    assert!(range.p95.unwrap() <= 3.0, "{range:?}");
    assert!(e.trilateration_error_mm.median.unwrap() <= 40.0, "{e:?}");
}

#[test]
fn the_compass_recovers_known_rotations_of_rendered_frames() {
    let cfg = CompassConfig::default();
    let at = Vector2::new(700.0, -300.0);
    let profile = |deg: f64, seed: u64| {
        let pose = Isometry2::new(at, (25.0 + deg).to_radians());
        let (lo, up) = (frame(0, pose, seed), frame(1, pose, seed + 1));
        let (rl, ru) = (
            MirrorRim::measure(&lo).unwrap(),
            MirrorRim::measure(&up).unwrap(),
        );
        AngularProfile::capture(&[(&lo, &rl), (&up, &ru)], &cfg)
    };
    let before = profile(0.0, 10);
    for deg in [0.0, 0.4, -1.7, 4.5, -8.0] {
        let r = profile(deg, 20).rotation_from(&before, &cfg).unwrap();
        let got = r.rotation_rad.to_degrees();
        eprintln!(
            "turned {deg:+.2} deg: read {got:+.3} deg (peak {:.3})",
            r.peak
        );
        assert!((got - deg).abs() < 0.1, "turned {deg}: read {got}");
    }
}

#[test]
fn save_frames_keeps_every_frame_of_both_cameras() {
    // The arena scenario cut to ten frames.
    let text = std::fs::read_to_string(scenario_path("omnistereo_arena.toml")).unwrap();
    let text = text.replace("duration_s = 22.5", "duration_s = 0.5");
    let dir = tmp("omnistereo_frames");
    let file = dir.join("arena10.toml");
    std::fs::write(&file, text).unwrap();
    let out = dir.join("run");
    omniloop([
        "run".as_ref(),
        file.as_os_str(),
        "--renderer".as_ref(),
        "cpu".as_ref(),
        "--save-frames".as_ref(),
        "--quiet".as_ref(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    let rows = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    // Ten cycles and the final state.
    assert_eq!(rows.lines().count(), 1 + 11);
    for k in 0..10 {
        for cam in ["lower", "upper"] {
            let f = out.join("frames").join(format!("{cam}_{k:06}.png"));
            assert!(f.exists(), "{} missing", f.display());
        }
    }
    assert!(!out.join("frames").join("lower_000010.png").exists());
}

#[test]
fn a_rig_that_is_not_two_cones_is_a_scenario_error() {
    let text = std::fs::read_to_string(scenario_path("omnistereo_arena.toml")).unwrap();
    let text = text.replace("upper_sensor = \"upper\"", "upper_sensor = \"top\"");
    let dir = tmp("omnistereo_broken");
    let file = dir.join("broken.toml");
    std::fs::write(&file, text).unwrap();
    let out = common::bin().arg("check").arg(&file).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("vision.omnistereo.upper_sensor") && err.contains("no sensor \"top\""),
        "{err}"
    );
}

#[test]
fn e4_ranges_pillars_through_a_defocused_lens() {
    // The first 150 frames with both cameras defocused by 1.5 px: the stripes are washed out
    // near the image centre, where the colours were looked for (no range at all before); now
    // a colour missing there is looked for farther out.
    let mut s = scenario("omnistereo_arena.toml");
    for sensor in &mut s.robot.sensors {
        sensor.effects.defocus_px = 1.5;
    }
    s.run.duration_s = 7.5;
    let m = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap().summary;
    eprintln!(
        "{}",
        omniloop::experiments::omnistereo::omnistereo_table(&m)
    );
    // Fewer pillars are ranged than sharp (347 ranges and 57 fixes in 150 frames, against
    // about 600 and 150), but more than one a frame, within the targets.
    let e = metrics(&m);
    assert!(e.range_error_pct.stats.n >= 150, "{e:?}");
    assert!(e.trilateration_error_mm.n >= 30, "{e:?}");
    assert!(e.range_error_pct.stats.median.unwrap() <= 1.0, "{e:?}");
    assert!(e.trilateration_error_mm.median.unwrap() <= 40.0, "{e:?}");
}
