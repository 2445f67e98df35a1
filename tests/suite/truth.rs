//! The truth beside each frame, pixel by pixel: depth, floor distance and labels.
// Tests: a broken fixture stops the test where it breaks.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::common;

use common::scenario;
use nalgebra::Vector3;
use omniloop::run::truth_files;
use omniloop_sim::labels::{self, Class, ObjectId};
use omniloop_sim::optics::Optics;
use omniloop_sim::render::cpu::trace_reference;
use omniloop_sim::render::trace::CODE_NOTHING;
use omniloop_sim::render::truth::{self, TruthFrame, TruthRays};
use omniloop_sim::render::{BatchServer, CpuRenderer, SensorRays};
use omniloop_sim::{FrameRequest, Renderer, Rgb, Scene, SensorNoise, Sphere, World};
use std::ffi::OsStr;

/// The world of a scenario with its robots where they start, and the first robot's pose.
fn world_of(s: &omniloop::Scenario) -> (World, nalgebra::Isometry2<f64>) {
    let world = World::new(&s.world, &s.robot_bodies(), 0.002).unwrap();
    let pose = world.robot_state(0).pose;
    (world, pose)
}

#[test]
fn depth_and_floor_distance_on_the_hyperbolic_mirrors_floor_follow_the_papers_f() {
    let s = scenario("render_hyperbolic.toml");
    let sensor = s.robot.sensors[0].build();
    let Optics::Hyperbolic(mirror) = &sensor.optics else {
        panic!("the render example's mirror is hyperbolic");
    };
    let (world, pose) = world_of(&s);
    let truth = Renderer::cpu()
        .render_truth(&Scene::of_world(&world), &sensor, &pose)
        .unwrap();
    // Light from a floor point at distance r bound for the mirror's upper focus F (H above the
    // floor) reflects to the camera at the lower focus C; |CP| - |FP| = 2b on the mirror, so
    // the path floor -> mirror -> camera is 2b + |QF| = 2b + sqrt(r^2 + H^2).
    let (two_b, h) = (2.0 * mirror.b_mm, mirror.focus_height_mm);
    let (mut floor_px, mut worst_r, mut worst_depth) = (0, 0.0f64, 0.0f64);
    for v in 0..truth.height {
        for u in 0..truth.width {
            let k = (v * truth.width + u) as usize;
            let class = truth.legend.object(truth.labels[k]).unwrap().class;
            if !class.is_floor() {
                assert!(truth.floor_mm[k].is_nan(), "({u}, {v}) is not floor");
                continue;
            }
            let (x, y) = sensor.image_coords(u, v);
            let r = mirror.floor_distance_mm(x.hypot(y)).unwrap();
            floor_px += 1;
            worst_r = worst_r.max((truth.floor_mm[k] as f64 - r).abs());
            let depth = two_b + r.hypot(h);
            worst_depth = worst_depth.max((truth.depth_mm[k] as f64 - depth).abs());
        }
    }
    assert!(floor_px > 15_000, "only {floor_px} floor pixels");
    assert!(worst_r < 1.0, "floor distance off f(R) by {worst_r} mm");
    assert!(
        worst_depth < 1.0,
        "depth off 2b + sqrt(f(R)^2 + H^2) by {worst_depth} mm"
    );
    eprintln!(
        "{floor_px} floor pixels: f(R) within {worst_r:.2e} mm, depth within {worst_depth:.2e} mm"
    );
}

#[test]
fn each_cubes_label_covers_exactly_the_pixels_where_it_is_drawn() {
    let s = scenario("render_hyperbolic.toml");
    let sensor = s.robot.sensors[0].build();
    let (world, pose) = world_of(&s);
    let mut renderer = Renderer::cpu();
    let scene = Scene::of_world(&world);
    let truth = renderer.render_truth(&scene, &sensor, &pose).unwrap();
    let full = renderer.render(&scene, &sensor, &pose, None).unwrap();
    let mut seen = 0;
    for k in 0..s.world.cubes.len() {
        // Where the image changes when cube k is taken away is where it is drawn (the renderer
        // casts no shadows).
        let mut without = s.world.clone();
        without.cubes.remove(k);
        let w = World::new(&without, &s.robot_bodies(), 0.002).unwrap();
        let img = renderer
            .render(&Scene::of_world(&w), &sensor, &pose, None)
            .unwrap();
        let label = truth.legend.label(ObjectId::new(Class::Cube, k as u32));
        assert!(label > labels::FLOOR_OUTSIDE, "cube {k} has its own label");
        let drawn: Vec<bool> = (full.pixels().zip(img.pixels()))
            .map(|(a, b)| a != b)
            .collect();
        let labelled: Vec<bool> = truth.labels.iter().map(|&l| l == label).collect();
        let wrong = (0..drawn.len())
            .filter(|&i| drawn[i] != labelled[i])
            .count();
        let n = drawn.iter().filter(|&&d| d).count();
        assert_eq!(
            wrong, 0,
            "cube {k}: {wrong} of {n} drawn pixels labelled otherwise"
        );
        seen += usize::from(n > 20);
    }
    assert!(seen >= 4, "only {seen} cubes in view");
}

#[test]
fn the_truth_names_the_field_walls_goals_and_lines_and_the_sky_is_infinitely_far() {
    let s = scenario("render_hyperbolic.toml");
    let sensor = s.robot.sensors[0].build();
    let (world, pose) = world_of(&s);
    let truth = Renderer::cpu()
        .render_truth(&Scene::of_world(&world), &sensor, &pose)
        .unwrap();
    let count = |label: u16| truth.labels.iter().filter(|&&l| l == label).count();
    let goal = |k| truth.legend.label(ObjectId::new(Class::Goal, k));
    let field_wall = truth.legend.label(ObjectId::of(Class::FieldWall));
    for (name, label) in [
        ("floor region", labels::FLOOR_REGION),
        ("lines", labels::FLOOR_LINE),
        ("field walls", field_wall),
        ("goal +x", goal(0)),
        ("goal -x", goal(1)),
    ] {
        assert!(count(label) > 20, "{name}: {} pixels", count(label));
    }
    // The sky's depth is infinite, nothing's unknown, everything else's finite.
    for (k, &l) in truth.labels.iter().enumerate() {
        if l == labels::SKY {
            assert_eq!(truth.depth_mm[k], f32::INFINITY);
        } else if l == labels::NOTHING {
            assert!(truth.depth_mm[k].is_nan());
        } else {
            assert!(truth.depth_mm[k].is_finite() && truth.depth_mm[k] > 0.0);
        }
    }
}

#[test]
fn another_robot_is_robot_k_and_the_observer_its_own_body() {
    let s = scenario("corridor_passing.toml");
    let sensor = s.robot.sensors[0].build();
    let world = World::new(&s.world, &s.robot_bodies(), 0.002).unwrap();
    let scene = Scene::of_world(&world);
    let legend = scene.legend();
    let other = legend.label(ObjectId::new(Class::Robot, 1));
    let own_as_other = legend.label(ObjectId::new(Class::Robot, 0));
    let mut renderer = Renderer::cpu();
    let mut saw_other = false;
    for robot in 0..2 {
        let pose = world.robot_state(robot).pose;
        let truth = renderer.render_truth(&scene, &sensor, &pose).unwrap();
        let own = truth
            .labels
            .iter()
            .filter(|&&l| l == labels::OWN_BODY)
            .count();
        // Robot 0 may see robot 1 and robot 1 robot 0, never itself as another.
        let me = if robot == 0 { own_as_other } else { other };
        assert_eq!(truth.labels.iter().filter(|&&l| l == me).count(), 0);
        if robot == 0 {
            saw_other = truth.labels.contains(&other);
        }
        assert!(own > 100, "robot {robot} sees its body in {own} pixels");
    }
    assert!(saw_other, "robot 0 sees robot 1 down the corridor");
}

#[test]
fn render_truth_writes_a_depth_png_in_mm_a_label_png_and_its_legend() {
    let dir = common::tmp("render_truth");
    let out = dir.join("h.png");
    let scenario_file = common::scenario_path("render_hyperbolic.toml");
    let flags = ["--renderer", "cpu", "--no-noise", "--truth", "--out"].map(OsStr::new);
    let first = [OsStr::new("render"), scenario_file.as_os_str()];
    common::omniloop([&first[..], &flags, &[out.as_os_str()]].concat());
    // The files hold what the renderer gives.
    let s = scenario("render_hyperbolic.toml");
    let sensor = s.robot.sensors[0].build();
    let (world, pose) = world_of(&s);
    let truth = Renderer::cpu()
        .render_truth(&Scene::of_world(&world), &sensor, &pose)
        .unwrap();
    let depth = truth_files::read_levels(&dir.join("h_depth.png")).unwrap();
    let labels = truth_files::read_levels(&dir.join("h_labels.png")).unwrap();
    assert_eq!((depth.width, depth.height), (256, 220));
    for k in 0..truth.labels.len() {
        assert_eq!(labels.values[k], truth.labels[k], "label of pixel {k}");
        assert_eq!(depth.values[k], truth_files::depth_level(truth.depth_mm[k]));
    }
    let legend: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(dir.join("h_legend.json")).unwrap()).unwrap();
    assert_eq!(legend.len(), truth.legend.len());
    assert_eq!(legend[11]["name"], "cube 0");
}

#[test]
fn a_run_with_truth_scores_the_floor_region_every_cycle_and_its_median() {
    let dir = common::tmp("run_truth");
    let scenario_file = common::scenario_path("corner55_velocity_aware.toml");
    let flags = ["--renderer", "cpu", "--truth", "-q", "--out"].map(OsStr::new);
    let first = [OsStr::new("run"), scenario_file.as_os_str()];
    common::omniloop([&first[..], &flags, &[dir.as_os_str()]].concat());
    let text = std::fs::read_to_string(dir.join("estimates.jsonl")).unwrap();
    let mut ious = Vec::new();
    for line in text.lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        let f = &v["floor_region"];
        let iou = f["iou"].as_f64().expect("a floor-region score every cycle");
        let shares = [f["false_free"].as_f64(), f["false_blocked"].as_f64()];
        assert!(
            shares
                .iter()
                .all(|s| s.is_some_and(|s| (0.0..=1.0).contains(&s)))
        );
        assert_eq!(f["free_label_mm"].as_array().unwrap().len(), 32);
        assert_eq!(f["free_true_mm"].as_array().unwrap().len(), 32);
        ious.push(iou);
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let median = summary["floor_region_iou"].as_f64().unwrap();
    ious.sort_by(f64::total_cmp);
    assert!(ious.len() > 100);
    assert!((ious[0]..=1.0).contains(&median));
    // The floor colour is far from the walls' and the outside's: the stage's floor region
    // agrees with the truth's but for a few edge pixels.
    assert!(ious[0] > 0.98, "worst cycle's IoU {}", ious[0]);
}

#[test]
fn a_dataset_holds_frames_depth_labels_poses_and_the_camera_model() {
    let dir = common::tmp("dataset");
    let s = scenario("corner55_velocity_aware.toml");
    let options = omniloop::dataset::DatasetOptions {
        samples: 4,
        ..Default::default()
    };
    let info = omniloop::dataset::write_dataset(&s, &options, &dir, |_, _| {}).unwrap();
    assert_eq!(info.samples, 4);
    for k in 0..4 {
        let name = format!("{k:06}.png");
        let img = image::open(dir.join("images").join(&name)).unwrap();
        assert_eq!((img.width(), img.height()), (256, 220));
        let labels = truth_files::read_levels(&dir.join("labels").join(&name)).unwrap();
        let depth = truth_files::read_levels(&dir.join("depth").join(&name)).unwrap();
        // Every labelled pixel of the floor or a wall has a depth; the sky has none.
        for (l, d) in labels.values.iter().zip(&depth.values) {
            match *l {
                labels::NOTHING | labels::SKY => assert_eq!(*d, 0),
                _ => assert!(*d > 0),
            }
        }
        assert!(labels.values.contains(&labels::FLOOR_REGION));
    }
    let poses = std::fs::read_to_string(dir.join("poses.csv")).unwrap();
    assert_eq!(poses.lines().count(), 5);
    for f in [
        "dataset.json",
        "legend.json",
        "calibration.json",
        "camera.yaml",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
    // The same scenario and seed, the same dataset.
    let again = common::tmp("dataset_again");
    omniloop::dataset::write_dataset(&s, &options, &again, |_, _| {}).unwrap();
    for f in [
        "poses.csv",
        "images/000003.png",
        "labels/000003.png",
        "depth/000003.png",
    ] {
        assert_eq!(
            std::fs::read(dir.join(f)).unwrap(),
            std::fs::read(again.join(f)).unwrap()
        );
    }
}

/// The first frame traced with its truth on fresh rays gives what tracing every primitive gives,
/// the pixels that see no mirror included (known once the rays' packets are made).
#[test]
fn the_first_cpu_frame_with_truth_marks_the_pixels_that_see_no_mirror() {
    let s = scenario("render_spherical.toml");
    let sensor = s.robot.sensors[0].build();
    let (world, pose) = world_of(&s);
    let scene = Scene::of_world(&world);
    let mut rays = SensorRays::new(&sensor);
    let n = (sensor.width_px * sensor.height_px) as usize;
    let (mut pixels, mut t, mut codes) = (vec![0; n], vec![0.0; n], vec![0; n]);
    CpuRenderer::new().render_truth(&scene, &mut rays, &pose, &mut pixels, (&mut t, &mut codes));
    let traced = trace_reference(&scene, &rays, &pose);
    let blind = traced.iter().filter(|r| r.code == CODE_NOTHING).count();
    assert!(blind > 1000, "{blind} pixels see no mirror");
    for (k, r) in traced.iter().enumerate() {
        assert_eq!(
            (codes[k], t[k].to_bits()),
            (r.code, r.t.to_bits()),
            "pixel {k}"
        );
    }
}

/// The render examples at their start, and the corner of `corner55_velocity_aware` near its
/// tip (its quad prisms in view), as `tests/suite/renderer.rs` compares their images.
fn compared_frames() -> Vec<(omniloop::Scenario, Option<nalgebra::Isometry2<f64>>)> {
    let examples = ["hyperbolic", "conical", "spherical", "pinhole"];
    let mut v: Vec<_> = (examples.iter())
        .map(|k| (scenario(&format!("render_{k}.toml")), None))
        .collect();
    let tip = nalgebra::Isometry2::new(nalgebra::Vector2::new(-650.0, 150.0), 40f64.to_radians());
    v.push((scenario("corner55_velocity_aware.toml"), Some(tip)));
    v
}

/// Beyond this depth (mm) a scene shows only floor near the horizon: every object and the floor
/// region of these scenes lie within it.
const NEAR_MM: f32 = 10_000.0;

/// How a GPU truth differs from the CPU's.
#[derive(Debug, Default)]
struct TruthDifference {
    /// The share of pixels labelled otherwise.
    relabelled: f64,
    /// On the pixels labelled alike within [`NEAR_MM`]: the share whose depths differ by more
    /// than 0.5 mm, and the largest difference (mm).
    near_over: f64,
    near_worst: f32,
    /// On those beyond: the largest difference over the depth squared (1/mm).
    far_worst: f64,
}

fn truth_difference(gpu: &TruthFrame, cpu: &TruthFrame) -> TruthDifference {
    let n = cpu.labels.len();
    let mut d = TruthDifference::default();
    let (mut relabelled, mut near, mut over) = (0usize, 0usize, 0usize);
    for k in 0..n {
        if gpu.labels[k] != cpu.labels[k] {
            relabelled += 1;
            continue;
        }
        let (a, b) = (gpu.depth_mm[k], cpu.depth_mm[k]);
        if !b.is_finite() {
            // The sky (infinite) or no mirror (NaN) on both.
            assert!(
                a == b || (a.is_nan() && b.is_nan()),
                "pixel {k}: {a} vs {b}"
            );
            continue;
        }
        let diff = (a - b).abs();
        if b < NEAR_MM {
            near += 1;
            over += usize::from(diff > 0.5);
            d.near_worst = d.near_worst.max(diff);
        } else {
            d.far_worst = d.far_worst.max(diff as f64 / (b as f64).powi(2));
        }
    }
    d.relabelled = relabelled as f64 / n as f64;
    d.near_over = over as f64 / near.max(1) as f64;
    d
}

/// The GPU's truth is the CPU's up to the rounding of the mirror half (f32 in the shader, f64
/// then f32 on the CPU), and asking for it changes no pixel.
#[test]
fn gpu_and_cpu_truth_agree() {
    let Some(mut gpu) = common::gpu_or_skip() else {
        return;
    };
    let mut cpu = Renderer::cpu();
    let mut frames = 0;
    for (s, pose) in compared_frames() {
        let mut bodies = s.robot_bodies();
        if let Some(p) = pose {
            bodies[0].start = p;
        }
        let world = World::new(&s.world, &bodies, 0.002).unwrap();
        let scene = Scene::of_world(&world);
        let pose = world.robot_state(0).pose;
        for spec in &s.robot.sensors {
            let sensor = spec.build();
            let a = gpu.render_truth(&scene, &sensor, &pose).unwrap();
            let b = cpu.render_truth(&scene, &sensor, &pose).unwrap();
            assert_eq!(a.legend, b.legend);
            let d = truth_difference(&a, &b);
            let frame = format!("{}/{}", s.name, spec.name);
            eprintln!(
                "{frame}: {:.4}% of pixels labelled otherwise; of those alike within {} m, \
                 {:.4}% with depths more than 0.5 mm apart, at most {:.3} mm; beyond, at most \
                 {:.2e} depth^2/mm ({})",
                100.0 * d.relabelled,
                NEAR_MM / 1000.0,
                100.0 * d.near_over,
                d.near_worst,
                d.far_worst,
                gpu.name()
            );
            // The GPU traces the mirror half in f32, the CPU in f64: a ray's direction differs
            // by a few f32 roundings, a small fraction of a pixel, so a label can differ only
            // on a ray that grazes an edge (none on lavapipe; a hardware GPU rounds sqrt and
            // division differently).
            assert!(d.relabelled < 0.0005, "{frame}: {d:?}");
            // Depth: within 0.5 mm nearly everywhere near the robot (lavapipe: at least
            // 99.98%, at most 0.57 mm, on the spherical mirror's floor 4.2 m off).
            assert!(d.near_over < 0.001 && d.near_worst < 1.0, "{frame}: {d:?}");
            // The floor near the horizon amplifies the rounding: it is met at t = h / |d_z|,
            // so a change delta in d_z moves it by t^2 delta / h: 5e-9 / mm is delta up to 1e-6
            // (eight f32 roundings of a unit vector's component) from the hyperbolic mirror's
            // 205 mm (lavapipe: 2.2e-9 / mm, 1.2 m apart at 1.28 km).
            assert!(d.far_worst < 5e-9, "{frame}: {d:?}");
            // The truth changes no pixel: the same image, noise drawn in the shader included,
            // and the same truth as the frame traced for its truth alone.
            let poses = [pose];
            let noise = || SensorNoise::new(0x5eed);
            let plain = gpu.render_exposed(&scene, &sensor, &poses, Some(&mut noise()));
            let (img, truth) = gpu
                .render_exposed_truth(&scene, &sensor, &poses, Some(&mut noise()))
                .unwrap();
            assert!(
                img == plain.unwrap(),
                "{frame}: the truth changed the image"
            );
            assert_eq!(truth.labels, a.labels);
            frames += 1;
        }
    }
    assert!(frames >= 6, "{frames} frames");
}

/// Frames traced in one GPU batch, every other one with its truth, get the pixels and truth
/// they get traced alone; a renderer on the shared batch server gets the same truth too.
#[test]
fn a_gpu_batch_carries_the_truth_of_the_frames_that_ask() {
    let Some(gpu) = common::gpu_or_skip() else {
        return;
    };
    let mut gpu = gpu.into_gpu().unwrap();
    let mut frames = Vec::new();
    for (s, pose) in compared_frames() {
        let mut bodies = s.robot_bodies();
        if let Some(p) = pose {
            bodies[0].start = p;
        }
        let world = World::new(&s.world, &bodies, 0.002).unwrap();
        let pose = world.robot_state(0).pose;
        for spec in &s.robot.sensors {
            frames.push((Scene::of_world(&world), spec.build(), pose));
        }
    }
    let requests: Vec<FrameRequest> = (frames.iter())
        .map(|(scene, sensor, pose)| FrameRequest {
            scene,
            sensor,
            pose,
            noise: None,
        })
        .collect();
    let asks: Vec<bool> = (0..requests.len()).map(|i| i % 2 == 0).collect();
    let batch = gpu.render_batch_truth(&requests, &asks).unwrap();
    let mut alone = Vec::new();
    for (r, (pixels, truth)) in requests.iter().zip(&batch) {
        let n = pixels.len();
        let (mut p, mut t, mut codes) = (vec![0; n], vec![0.0; n], vec![0; n]);
        gpu.render_truth(*r, &mut p, &mut t, &mut codes).unwrap();
        assert_eq!(pixels, &p);
        if let Some(truth) = truth {
            assert_eq!(truth.codes, codes);
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&truth.t), bits(&t));
        }
        alone.push((t, codes));
    }
    assert_eq!(
        batch.iter().map(|(_, t)| t.is_some()).collect::<Vec<_>>(),
        asks
    );
    let server = BatchServer::start(gpu, std::time::Duration::from_millis(1));
    let mut shared = Renderer::shared(&server.handle());
    for ((scene, sensor, pose), (t, codes)) in frames.iter().zip(&alone) {
        let a = shared.render_truth(scene, sensor, pose).unwrap();
        let b = truth::truth_frame(scene, sensor, &TruthRays::new(sensor), pose, t, codes);
        assert_eq!(a.labels, b.labels);
        assert!((a.depth_mm.iter().zip(&b.depth_mm)).all(|(x, y)| x.to_bits() == y.to_bits()));
    }
}

/// Golf balls (43 mm across) around the render example's robot (at (-400, 400) on a field of
/// 2.74 m x 1.52 m, the cubes elsewhere): on the floor 400 mm off along +x and 800 mm off along
/// -45 degrees, and one raised, its centre 150 mm up 1200 mm off along +x.
fn golf_balls() -> Vec<Sphere> {
    let ball = |k: u32, [x, y, z]: [f64; 3]| Sphere {
        center_mm: [x, y, z],
        radius_mm: 21.5,
        rgb: Rgb([255, 110, 20]),
        object: ObjectId::new(Class::Ball, k),
    };
    let at = |r: f64, deg: f64, z: f64| {
        let a = deg.to_radians();
        [-400.0 + r * a.cos(), 400.0 + r * a.sin(), z]
    };
    vec![
        ball(0, at(400.0, 0.0, 21.5)),
        ball(1, at(800.0, -45.0, 21.5)),
        ball(2, at(1200.0, 0.0, 150.0)),
    ]
}

/// The distance along the world ray `o + t d` (unit `d`) to its first crossing of `ball`, and
/// the squared distance of the line from the ball's surface inwards (`r^2 - |line - centre|^2`,
/// negative where it passes by), in `f64` from the textbook quadratic.
fn ball_distance(o: Vector3<f64>, d: Vector3<f64>, ball: &Sphere) -> (f64, f64) {
    let c = Vector3::from(ball.center_mm);
    let m = o - c;
    let b = m.dot(&d);
    let disc = b * b - (m.dot(&m) - ball.radius_mm * ball.radius_mm);
    (-b - disc.max(0.0).sqrt(), disc)
}

#[test]
fn a_balls_depth_is_the_closed_form_distance_along_the_mirrors_ray_and_its_label_the_balls() {
    let s = scenario("render_hyperbolic.toml");
    let sensor = s.robot.sensors[0].build();
    let (world, pose) = world_of(&s);
    let balls = golf_balls();
    let scene = Scene::of_world(&world).with_spheres(&balls);
    let truth = Renderer::cpu()
        .render_truth(&scene, &sensor, &pose)
        .unwrap();
    let labels: Vec<u16> = balls.iter().map(|b| truth.legend.label(b.object)).collect();
    assert!(
        labels
            .iter()
            .all(|&l| truth.legend.object(l).unwrap().class == Class::Ball)
    );
    let (rot, shift) = (pose.rotation.angle(), pose.translation.vector);
    let (c, sn) = (rot.cos(), rot.sin());
    let (mut seen, mut worst) = (vec![0; balls.len()], 0.0f64);
    for v in 0..truth.height {
        for u in 0..truth.width {
            let Some(ray) = sensor.pixel_ray(u, v) else {
                continue;
            };
            // The mirror's scene ray in the world.
            let (p, q) = (ray.origin, ray.dir);
            let o = Vector3::new(
                shift.x + c * p.x - sn * p.y,
                shift.y + sn * p.x + c * p.y,
                p.z,
            );
            let d = Vector3::new(c * q.x - sn * q.y, sn * q.x + c * q.y, q.z);
            let k = (v * truth.width + u) as usize;
            for (j, ball) in balls.iter().enumerate() {
                let (t, disc) = ball_distance(o, d, ball);
                if truth.labels[k] == labels[j] {
                    // The f32 tracer's ray may graze the ball where the f64 one just misses it.
                    assert!(
                        disc > -1.0,
                        "({u}, {v}) labelled ball {j}: misses it by {disc}"
                    );
                    let depth = ray.path_mm + t;
                    worst = worst.max((truth.depth_mm[k] as f64 - depth).abs());
                    seen[j] += 1;
                } else {
                    // A ray well inside the ball's outline (nothing stands in front of them).
                    let inside = disc > 0.1 * ball.radius_mm * ball.radius_mm;
                    assert!(
                        !inside || t < 0.0,
                        "({u}, {v}) meets ball {j} at {t} (disc {disc}) but is labelled {:?} at {}",
                        truth.legend.object(truth.labels[k]),
                        truth.depth_mm[k] as f64 - ray.path_mm
                    );
                }
            }
        }
    }
    eprintln!("ball pixels {seen:?}: depth within {worst:.2e} mm of the closed form");
    assert!(seen.iter().all(|&n| n >= 4), "ball pixels {seen:?}");
    assert!(worst < 1.0, "depth off the closed form by {worst} mm");
}

/// On a field with golf balls, the GPU's truth is the CPU's as on the render examples, and the
/// balls' pixels have the same labels on both.
#[test]
fn gpu_and_cpu_truth_agree_on_balls() {
    let Some(mut gpu) = common::gpu_or_skip() else {
        return;
    };
    let s = scenario("render_hyperbolic.toml");
    let sensor = s.robot.sensors[0].build();
    let (world, pose) = world_of(&s);
    let scene = Scene::of_world(&world).with_spheres(&golf_balls());
    let a = gpu.render_truth(&scene, &sensor, &pose).unwrap();
    let b = Renderer::cpu()
        .render_truth(&scene, &sensor, &pose)
        .unwrap();
    assert_eq!(a.legend, b.legend);
    let d = truth_difference(&a, &b);
    let is_ball =
        |t: &TruthFrame, k: usize| t.legend.object(t.labels[k]).unwrap().class == Class::Ball;
    let balls = (0..b.labels.len()).filter(|&k| is_ball(&b, k)).count();
    let alike = (0..b.labels.len())
        .filter(|&k| is_ball(&b, k) && a.labels[k] == b.labels[k])
        .count();
    eprintln!(
        "{alike} of {balls} ball pixels labelled alike; {d:?} ({})",
        gpu.name()
    );
    assert!(
        balls >= 12 && alike + 1 >= balls,
        "{alike} of {balls} ball pixels alike"
    );
    assert!(d.relabelled < 0.0005, "{d:?}");
    assert!(d.near_over < 0.001 && d.near_worst < 1.0, "{d:?}");
}
