//! End-to-end checks of the catadioptric renderer: the hyperbolic mirror's image-to-floor map
//! against the paper's f(R), the calibration fit, conical omnistereo range (eqs. (1)-(2) of
//! Spacek and Burbridge), GPU/CPU agreement and golden images of the render examples.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;
use nalgebra::{Isometry2, Vector2};
use omniloop::load_scenario;
use omniloop::run::render_snapshot;
use omniloop::scenario::calibrate::calibrate_sensor;
use omniloop_sim::labels::{Class, ObjectId};
use omniloop_sim::optics::HyperbolicMirror;
use omniloop_sim::render::{CpuRenderer, SensorRays};
use omniloop_sim::{
    FloorRect, FrameRequest, Layout, Pillar, Renderer, RendererChoice, Rgb, Scene, SensorNoise,
    SensorSpec, Sphere, Wall,
};

use common::{
    gpu_or_skip, omniloop, paper_f, paper_f_inverse, scenario_path as scenario, share_within,
};
use std::path::Path;

#[test]
fn every_pixel_of_the_corner_mirror_sees_the_floor_where_the_papers_f_says() {
    // The renderer's own scene rays, pixel by pixel: the floor point a pixel at image radius R
    // sees must image back, through the paper's f, within 0.5 px of R.
    let sensor = SensorSpec::corner_paper("omni").build();
    let mut worst: f64 = 0.0;
    let mut n = 0;
    for v in 0..sensor.height_px {
        for u in 0..sensor.width_px {
            let (x, y) = sensor.image_coords(u, v);
            let big_r = x.hypot(y);
            if big_r > 105.0 {
                continue;
            }
            let hit = sensor.pixel_ray(u, v).unwrap().floor_hit().unwrap();
            let r = hit.coords.xy().norm();
            worst = worst.max((paper_f_inverse(r) - big_r).abs());
            n += 1;
        }
    }
    assert!(n > 30_000);
    assert!(worst < 0.5, "worst deviation {worst} px");
    // The reconstruction is in fact exact up to the rounding of the paper's constants.
    assert!(worst < 0.05, "worst deviation {worst} px");
}

#[test]
fn rendered_floor_edges_lie_between_the_pixels_the_papers_f_puts_them() {
    // Floor stripes (floor colour on a different colour) with edges at known distances ahead of
    // the robot; along the image row through the principal point, each colour change between
    // two neighbouring pixels must bracket f^-1(distance).
    let edges: Vec<f64> = vec![
        150.0, 230.0, 320.0, 450.0, 600.0, 800.0, 1000.0, 1300.0, 1600.0, 2000.0, 2300.0, 2550.0,
    ];
    let rects: Vec<FloorRect> = edges
        .chunks(2)
        .map(|p| FloorRect {
            center_mm: [(p[0] + p[1]) / 2.0, 0.0],
            size_mm: [p[1] - p[0], 400.0],
            angle_deg: 0.0,
        })
        .collect();
    let layout = Layout {
        floor_rects: rects,
        ..Layout::default()
    };
    let sensor = SensorSpec::corner_paper("omni").build();
    let scene = Scene::new(&layout, &[]);
    let mut r = Renderer::cpu();
    let pose = Isometry2::new(Vector2::zeros(), 0.0);
    let img = r.render(&scene, &sensor, &pose, None).unwrap();
    let row = 109; // pixel centres at Y = +0.5, next to the principal point
    let green = layout.floor_rgb.0;
    let is_floor = |u: u32| img.get_pixel(u, row).0[..3] == green;
    let mut checked = 0;
    for e in &edges {
        let big_r = paper_f_inverse(*e);
        assert!(big_r <= 105.0);
        // Pixel u has its centre at X = u + 0.5 - 128.
        let x = big_r;
        let u0 = (x + 128.0 - 0.5).floor() as u32;
        assert_ne!(
            is_floor(u0),
            is_floor(u0 + 1),
            "edge at {e} mm (R = {big_r:.2} px) not between pixels {u0} and {}",
            u0 + 1
        );
        checked += 1;
    }
    assert_eq!(checked, edges.len());
}

#[test]
fn calibrate_prints_the_papers_constants_within_one_percent() {
    let table = Path::new(env!("CARGO_TARGET_TMPDIR")).join("calibration_omni.json");
    let text = omniloop([
        "calibrate".as_ref(),
        "--out".as_ref(),
        table.as_os_str(),
        scenario("render_hyperbolic.toml").as_os_str(),
    ]);
    let value = |key: &str| -> f64 {
        let line = text
            .lines()
            .find(|l| l.starts_with(key))
            .unwrap_or_else(|| panic!("no {key} in {text}"));
        line[key.len()..].trim().parse().unwrap()
    };
    for (key, paper) in [("A=", 10.12), ("B=", 2.054e-2), ("C=", 2.298e5)] {
        let v = value(key);
        assert!(
            (v / paper - 1.0).abs() < 0.01,
            "{key} {v} vs {paper}\n{text}"
        );
    }
    // The written table is what the vision crate reads.
    let cal = omniloop_vision::RadialCalibration::load(
        &Path::new(env!("CARGO_TARGET_TMPDIR")).join("calibration_omni.json"),
    )
    .unwrap();
    let r = cal.floor_distance_mm(80.0).unwrap();
    assert!((r - paper_f(80.0)).abs() < 0.01 * paper_f(80.0));
}

#[test]
fn the_closed_form_of_the_reconstructed_mirror_is_the_papers() {
    let spec = SensorSpec::corner_paper("omni");
    let cal = calibrate_sensor(&spec).unwrap();
    let fit = cal.fit.unwrap();
    let (a, b, c) = HyperbolicMirror::corner_paper().closed_form_abc();
    assert!((fit.a / a - 1.0).abs() < 1e-4 && (fit.b / b - 1.0).abs() < 1e-4);
    assert!((fit.c / c - 1.0).abs() < 1e-3);
}

/// Two coaxial 90-degree cones of the E4 geometry: R = 30, d = 100, s = 150.
fn cone(name: &str, lens_height_mm: f64) -> SensorSpec {
    let text = format!(
        "name = \"{name}\"\nwidth_px = 256\nheight_px = 256\nnoise_sigma = 0.0\n\
         [conical]\napex_angle_deg = 90.0\nradius_mm = 30.0\ntip_distance_mm = 100.0\n\
         focal_px = 520.0\nlens_height_mm = {lens_height_mm}\n"
    );
    toml::from_str(&text).unwrap()
}

/// Radius of the mirror rim and of the outermost pixel of the red pillar, along +x.
fn measure(img: &image::RgbaImage) -> (f64, f64) {
    let (cx, cy) = (128.0, 128.0);
    let mut rim: f64 = 0.0;
    let mut top: f64 = 0.0;
    for (u, v, p) in img.enumerate_pixels() {
        let x = u as f64 + 0.5 - cx;
        let y = cy - (v as f64 + 0.5);
        let r = x.hypot(y);
        let [red, green, blue, _] = p.0;
        if (red, green, blue) != (0, 0, 0) {
            rim = rim.max(r);
        }
        if red > 100 && green < 40 && blue < 40 && x > 0.0 {
            top = top.max(r);
        }
    }
    (rim, top)
}

#[test]
fn conical_omnistereo_range_follows_eqs_1_and_2() {
    let lower = cone("lower", 100.0).build();
    let upper = cone("upper", 250.0).build();
    let (d, big_r, s) = (100.0, 30.0, 150.0);
    let mut r = Renderer::cpu();
    for range in [1000.0, 1500.0, 2000.0, 3000.0] {
        let radius = 60.0;
        // Tall enough that its top images near h1 = 100 px in the lower mirror, well inside
        // the common region of both mirrors.
        let top = 200.0 + 100.0 * (range + d) / 520.0;
        let layout = Layout {
            walls: vec![Wall {
                from_mm: [6000.0, -6000.0],
                to_mm: [6000.0, 6000.0],
                thickness_mm: 100.0,
                height_mm: 3000.0,
                rgb: Rgb([120, 120, 120]),
            }],
            pillars: vec![Pillar {
                center_mm: [range + radius, 0.0],
                radius_mm: radius,
                height_mm: top,
                rgb: Rgb([230, 10, 10]),
            }],
            ..Layout::default()
        };
        let scene = Scene::new(&layout, &[]);
        let pose = Isometry2::new(Vector2::zeros(), 0.0);
        let (rim1, h1) = measure(&r.render(&scene, &lower, &pose, None).unwrap());
        let (rim2, h2) = measure(&r.render(&scene, &upper, &pose, None).unwrap());
        // Eq. (2): v = (d / R + 1) r_m, from the rim's radius in the image.
        let r_m = 0.5 * (rim1 + rim2);
        let v = (d / big_r + 1.0) * r_m;
        assert!((v - 520.0).abs() < 0.01 * 520.0, "v = {v}");
        // Eq. (1): r = v s / (h1 - h2) - d, the range to the pillar's near face.
        let est = v * s / (h1 - h2) - d;
        // One pixel of disparity error moves r by (r + d)^2 / (v s).
        let one_px = (range + d) * (range + d) / (v * s);
        eprintln!(
            "range {range} mm: v = {v:.1} px, h1 = {h1:.2}, h2 = {h2:.2}, estimate {est:.1} mm \
             (error {:.1}, one pixel of disparity = {one_px:.1} mm)",
            est - range
        );
        assert!(
            (est - range).abs() <= one_px,
            "range {range}: estimated {est:.1} (h1 {h1:.2}, h2 {h2:.2}); one pixel = {one_px:.1} mm"
        );
    }
}

/// The render examples of `scenarios/`, one per kind of optics.
const RENDER_EXAMPLES: [&str; 4] = [
    "render_hyperbolic",
    "render_conical",
    "render_spherical",
    "render_pinhole",
];

/// The E1 corner seen from near its inner tip, where mitred wall pieces (quad prisms) stand.
const CORNER: &str = "corner55_velocity_aware";
const NEAR_THE_TIP: (f64, f64, f64) = (-650.0, 150.0, 40.0);

/// The render examples at their start, and the corner near its tip.
fn compared_scenes() -> Vec<(&'static str, Option<Isometry2<f64>>)> {
    let (x, y, deg) = NEAR_THE_TIP;
    let mut v: Vec<(&str, Option<Isometry2<f64>>)> =
        RENDER_EXAMPLES.iter().map(|n| (*n, None)).collect();
    v.push((
        CORNER,
        Some(Isometry2::new(Vector2::new(x, y), deg.to_radians())),
    ));
    v
}

/// Scenes of every kind of primitive beyond the render examples: striped boards, pillars and
/// other robots (cylinders), a room's walls.
const MORE_CPU_SCENES: [&str; 3] = ["heading_room", "omnistereo_arena", "corridor_passing"];

#[test]
fn the_culled_cpu_renderer_equals_tracing_every_primitive() {
    let more = MORE_CPU_SCENES.iter().map(|n| (*n, None));
    let mut checked = 0;
    for (name, pose) in compared_scenes().into_iter().chain(more) {
        let s = load_scenario(&scenario(&format!("{name}.toml"))).unwrap();
        let mut bodies = s.robot_bodies();
        if let Some(p) = pose {
            bodies[0].start = p;
        }
        assert!(name != CORNER || !Scene::new(&s.world, &[]).quads.is_empty());
        let world = omniloop_sim::World::new(&s.world, &bodies, 0.002).unwrap();
        let scene = Scene::of_world(&world);
        let start = world.robot_state(0).pose;
        // The start, turned (so that the packets fall across other sectors) and moved.
        let poses = [
            start,
            Isometry2::new(start.translation.vector, start.rotation.angle() + 1.234_567),
            Isometry2::new(
                start.translation.vector + Vector2::new(137.0, -61.0),
                start.rotation.angle() - 2.5,
            ),
        ];
        for spec in &s.robot.sensors {
            let sensor = spec.build();
            // Packets ordered by elevation too (a sensor traced once), and by azimuth alone (one
            // traced again each frame), each traced by both kernels.
            let mut orders = [
                ("by elevation", SensorRays::new(&sensor)),
                ("by azimuth", SensorRays::retraced(&sensor)),
            ];
            for (k, pose) in poses.iter().enumerate() {
                // The body must stand where the pose is: move the scene's robot with it.
                let mut scene = scene.clone();
                for c in &mut scene.cylinders {
                    if c.geom[0] == start.translation.x as f32
                        && c.geom[1] == start.translation.y as f32
                    {
                        c.geom[0] = pose.translation.x as f32;
                        c.geom[1] = pose.translation.y as f32;
                    }
                }
                let traced = omniloop_sim::render::cpu::trace_reference(&scene, &orders[0].1, pose);
                let reference: Vec<u32> = traced.iter().map(|r| r.colour).collect();
                for (order, rays) in &mut orders {
                    for (kind, mut r) in [
                        ("vector", CpuRenderer::new()),
                        ("portable", CpuRenderer::portable()),
                    ] {
                        let mut pixels = vec![0; reference.len()];
                        r.render(&scene, rays, pose, &mut pixels);
                        let diff = pixels
                            .iter()
                            .zip(&reference)
                            .filter(|(a, b)| a != b)
                            .count();
                        assert_eq!(
                            diff, 0,
                            "{name}/{} pose {k}, {kind} kernel, packets {order}",
                            spec.name
                        );
                        let differ = truth_differs(&mut r, &scene, rays, pose, &traced);
                        assert_eq!(
                            differ, 0,
                            "{name}/{} pose {k}, {kind} kernel with truth, packets {order}",
                            spec.name
                        );
                    }
                }
                checked += 1;
            }
        }
    }
    assert!(checked >= 3 * 7, "only {checked} frames checked");
}

/// The pixels whose colour, distance (to the bit) or what they meet, traced with the truth,
/// differ from tracing every primitive.
fn truth_differs(
    r: &mut CpuRenderer,
    scene: &Scene,
    rays: &mut SensorRays,
    pose: &Isometry2<f64>,
    traced: &[omniloop_sim::render::trace::Traced],
) -> usize {
    let n = traced.len();
    let (mut pixels, mut t, mut codes) = (vec![0; n], vec![0.0; n], vec![0; n]);
    r.render_truth(scene, rays, pose, &mut pixels, (&mut t, &mut codes));
    (0..n)
        .filter(|&i| {
            let want = &traced[i];
            pixels[i] != want.colour || t[i].to_bits() != want.t.to_bits() || codes[i] != want.code
        })
        .count()
}

#[test]
fn gpu_and_cpu_renders_agree() {
    let Some(mut gpu) = gpu_or_skip() else {
        return;
    };
    let mut cpu = Renderer::cpu();
    for (name, pose) in compared_scenes() {
        let s = load_scenario(&scenario(&format!("{name}.toml"))).unwrap();
        for spec in &s.robot.sensors {
            // Noise on: the GPU draws it in the shader, the CPU after tracing, from the same
            // counter (the frame's key, the pixel, the channel).
            let a = render_snapshot(&s, &mut cpu, Some(&spec.name), pose, true).unwrap();
            let b = render_snapshot(&s, &mut gpu, Some(&spec.name), pose, true).unwrap();
            let frac = share_within(&a, &b, 2);
            eprintln!(
                "{name}/{}: {:.4}% of pixels within 2 levels ({})",
                spec.name,
                100.0 * frac,
                gpu.name()
            );
            assert!(
                frac >= 0.999,
                "{name}/{}: only {:.3}% within 2 levels",
                spec.name,
                100.0 * frac
            );
        }
    }
}

/// Every sensor of every compared scene traced in one GPU batch (different scenes, mirrors,
/// sizes and poses side by side) gives each image exactly as traced alone; the CPU renderer's
/// batch is its frames one by one.
#[test]
fn a_gpu_batch_equals_its_frames_traced_one_by_one() {
    let Some(mut gpu) = gpu_or_skip() else {
        return;
    };
    let mut frames = Vec::new();
    for (name, pose) in compared_scenes() {
        let s = load_scenario(&scenario(&format!("{name}.toml"))).unwrap();
        let mut bodies = s.robot_bodies();
        if let Some(p) = pose {
            bodies[0].start = p;
        }
        let world = omniloop_sim::World::new(&s.world, &bodies, 0.002).unwrap();
        let scene = Scene::of_world(&world);
        let pose = world.robot_state(0).pose;
        for spec in &s.robot.sensors {
            frames.push((scene.clone(), spec.build(), pose));
        }
    }
    assert!(frames.len() >= 6, "{} frames", frames.len());
    let requests: Vec<FrameRequest> = frames
        .iter()
        .map(|(scene, sensor, pose)| FrameRequest {
            scene,
            sensor,
            pose,
            noise: None,
        })
        .collect();
    let batch = gpu.render_batch_packed(&requests).unwrap();
    assert_eq!(batch.len(), frames.len());
    for (k, (scene, sensor, pose)) in frames.iter().enumerate() {
        let alone = gpu.render_packed(scene, sensor, pose).unwrap();
        let diff = batch[k].iter().zip(alone).filter(|(a, b)| a != b).count();
        assert_eq!(diff, 0, "frame {k} ({}): {diff} pixels differ", sensor.name);
    }
    let mut cpu = Renderer::cpu();
    let cpu_batch = cpu.render_batch_packed(&requests[..2]).unwrap();
    let (scene, sensor, pose) = &frames[1];
    assert_eq!(
        cpu_batch[1],
        cpu.render_packed(scene, sensor, pose).unwrap()
    );
}

/// The hyperbolic render example (the field, its cubes, the robot where it starts) with golf
/// balls 43 mm across around the robot (at (-400, 400)): on the floor 400 and 800 mm off, one
/// raised (its centre 300 mm up) 1.5 m off, one in the face of the cube at (-600, 300); and its
/// sensor and pose.
fn field_with_balls() -> (Scene, omniloop_sim::Sensor, Isometry2<f64>) {
    let s = load_scenario(&scenario("render_hyperbolic.toml")).unwrap();
    let world = omniloop_sim::World::new(&s.world, &s.robot_bodies(), 0.002).unwrap();
    let pose = world.robot_state(0).pose;
    let (x, y) = (pose.translation.x, pose.translation.y);
    let ball = |k: u32, [dx, dy, z]: [f64; 3]| Sphere {
        center_mm: [x + dx, y + dy, z],
        radius_mm: 21.5,
        rgb: Rgb([255, 110, 20]),
        object: ObjectId::new(Class::Ball, k),
    };
    let balls = [
        ball(0, [400.0, 0.0, 21.5]),
        ball(1, [565.7, -565.7, 21.5]),
        ball(2, [1477.2, -260.5, 300.0]),
        ball(3, [-145.0, -70.0, 21.5]),
    ];
    let scene = Scene::of_world(&world).with_spheres(&balls);
    (scene, s.robot.sensors[0].build(), pose)
}

/// The CPU and the GPU draw the same balls: the frames agree as those of the render examples
/// do, and each renderer's image differs from the scene's without the balls where they stand.
#[test]
fn gpu_and_cpu_renders_agree_with_spheres_in_the_scene() {
    let Some(mut gpu) = gpu_or_skip() else {
        return;
    };
    let mut cpu = Renderer::cpu();
    let (scene, sensor, pose) = field_with_balls();
    let bare = bare_scene(scene.clone());
    for noise in [None, Some(0x5eed)] {
        let frame = |r: &mut Renderer, scene: &Scene| {
            let mut noise = noise.map(SensorNoise::new);
            r.render(scene, &sensor, &pose, noise.as_mut()).unwrap()
        };
        let (a, b) = (frame(&mut cpu, &scene), frame(&mut gpu, &scene));
        let frac = share_within(&a, &b, 2);
        let drawn = |img: &image::RgbaImage, without: &image::RgbaImage| {
            let close = share_within(img, without, 2);
            ((1.0 - close) * (img.width() * img.height()) as f64).round() as usize
        };
        let balls = [
            drawn(&a, &frame(&mut cpu, &bare)),
            drawn(&b, &frame(&mut gpu, &bare)),
        ];
        eprintln!(
            "field with balls (noise {noise:?}): {:.4}% of pixels within 2 levels, the balls \
             drawn on {balls:?} pixels (cpu, {})",
            100.0 * frac,
            gpu.name()
        );
        assert!(frac >= 0.999, "only {:.3}% within 2 levels", 100.0 * frac);
        assert!(
            balls.iter().all(|&n| n >= 40),
            "balls drawn on {balls:?} pixels"
        );
    }
}

/// A scene without its spheres, as the scene of the same world had been before they existed.
fn bare_scene(mut scene: Scene) -> Scene {
    let n = scene.objects.len() - scene.spheres.len();
    scene.objects.truncate(n);
    scene.spheres.clear();
    scene.globals.counts[3] = 0;
    scene
}

/// One GPU batch of frames with and without spheres (the spheres' table shared, each frame's
/// first sphere in its header) gives each frame the image it gets traced alone.
#[test]
fn a_gpu_batch_of_scenes_with_and_without_spheres_equals_its_frames_alone() {
    let Some(mut gpu) = gpu_or_skip() else {
        return;
    };
    let (scene, sensor, pose) = field_with_balls();
    let mut fewer = scene.clone();
    // The first ball left out: the frames' spheres differ in number and in place.
    fewer.spheres.remove(0);
    fewer.objects.remove(fewer.objects.len() - 4);
    fewer.globals.counts[3] = 3;
    let bare = bare_scene(scene.clone());
    let turned = Isometry2::new(pose.translation.vector, pose.rotation.angle() + 1.0);
    let frames = [
        (&bare, pose),
        (&scene, pose),
        (&bare, turned),
        (&fewer, turned),
        (&scene, turned),
    ];
    let requests: Vec<FrameRequest> = (frames.iter())
        .map(|(scene, pose)| FrameRequest {
            scene,
            sensor: &sensor,
            pose,
            noise: None,
        })
        .collect();
    let batch = gpu.render_batch_packed(&requests).unwrap();
    for (k, (scene, pose)) in frames.iter().enumerate() {
        let alone = gpu.render_packed(scene, &sensor, pose).unwrap();
        let diff = batch[k].iter().zip(alone).filter(|(a, b)| a != b).count();
        assert_eq!(diff, 0, "frame {k}: {diff} pixels differ");
    }
    // The balls are in the frames that have them.
    assert_ne!(batch[0], batch[1]);
    assert_ne!(batch[3], batch[4]);
}

/// Golden images: the CPU render (no noise) of each render example. A render passes when at
/// most 0.5% of its pixels differ from the golden image by more than 2 levels in some channel
/// (room for floating-point differences between machines; a wrong mirror, pose or scene changes
/// far more). `OMNILOOP_BLESS=1 cargo test --test renderer golden` rewrites them.
#[test]
fn golden_images_of_the_render_examples() {
    let mut cpu = Renderer::cpu();
    for name in RENDER_EXAMPLES {
        let s = load_scenario(&scenario(&format!("{name}.toml"))).unwrap();
        let img = render_snapshot(&s, &mut cpu, None, None, false).unwrap();
        against_golden(name, &img);
    }
}

/// Compares `img` with `tests/golden/NAME.png` (at most 0.5% of its pixels more than 2 levels
/// off in some channel), or writes it there with `OMNILOOP_BLESS` set.
fn against_golden(name: &str, img: &image::RgbaImage) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format!("{name}.png"));
    if std::env::var_os("OMNILOOP_BLESS").is_some() {
        img.save(&path).unwrap();
        return;
    }
    let golden = image::open(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (OMNILOOP_BLESS=1 writes it)", path.display()))
        .to_rgba8();
    assert_eq!(golden.dimensions(), img.dimensions(), "{name}");
    let off = img
        .pixels()
        .zip(golden.pixels())
        .filter(|(p, q)| (0..3).any(|c| (p.0[c] as i32 - q.0[c] as i32).abs() > 2))
        .count();
    let total = (img.width() * img.height()) as usize;
    assert!(
        off * 200 <= total,
        "{name}: {off} of {total} pixels differ from the golden image by more than 2 levels"
    );
}

#[test]
fn auto_picks_a_hardware_gpu_and_passes_over_a_software_rasterizer() {
    let adapter = match omniloop_sim::render::GpuRenderer::adapter() {
        Ok(a) => a.get_info(),
        Err(e) => {
            if std::env::var_os("OMNILOOP_REQUIRE_GPU").is_some() {
                panic!("OMNILOOP_REQUIRE_GPU is set but no adapter opened: {e}");
            }
            eprintln!("no adapter: auto falls back to the CPU ({e})");
            let mut said = String::new();
            let r = Renderer::new(RendererChoice::Auto, |m| said = m.to_string()).unwrap();
            assert!(
                !r.is_gpu() && said.contains("using the CPU renderer"),
                "{said}"
            );
            return;
        }
    };
    let mut said = String::new();
    let r = Renderer::new(RendererChoice::Auto, |m| said = m.to_string()).unwrap();
    let software = adapter.device_type == wgpu::DeviceType::Cpu;
    eprintln!(
        "adapter {} ({:?}): auto chose {}",
        adapter.name,
        adapter.device_type,
        r.name()
    );
    assert_eq!(r.is_gpu(), !software, "{}", r.name());
    if software {
        assert!(
            said.contains("software") && said.contains(&adapter.name),
            "{said}"
        );
    } else {
        assert!(said.is_empty(), "{said}");
    }
}

/// Golden images with the ball: each render example's first camera (no noise, CPU) with a ball
/// on the floor 400 mm ahead of the robot and one in the air (a chip, 300 mm up, 500 mm ahead
/// and 300 mm to the right), each visible (the frame differs from the one without them), against
/// `tests/golden/NAME_ball.png` as the examples are against theirs.
#[test]
fn golden_images_of_the_render_examples_with_a_ball() {
    let mut cpu = Renderer::cpu();
    for name in RENDER_EXAMPLES {
        let s = load_scenario(&scenario(&format!("{name}.toml"))).unwrap();
        let world = omniloop_sim::World::new(&s.world, &s.robot_bodies(), 0.002).unwrap();
        let pose = world.robot_state(0).pose;
        let at = |ahead: f64, left: f64| pose * nalgebra::Point2::new(ahead, left);
        let ball = |p: nalgebra::Point2<f64>, z: f64| Sphere {
            center_mm: [p.x, p.y, z],
            radius_mm: 21.5,
            rgb: Rgb([255, 110, 20]),
            object: ObjectId::of(Class::Ball),
        };
        let balls = [ball(at(400.0, 0.0), 21.5), ball(at(500.0, -300.0), 300.0)];
        let sensor = s.robot.sensors[0].build();
        let bare = cpu
            .render(&Scene::of_world(&world), &sensor, &pose, None)
            .unwrap();
        let scene = Scene::of_world(&world).with_spheres(&balls);
        let img = cpu.render(&scene, &sensor, &pose, None).unwrap();
        let changed = img
            .pixels()
            .zip(bare.pixels())
            .filter(|(a, b)| a != b)
            .count();
        assert!(changed >= 4, "{name}: the balls change {changed} pixels");
        against_golden(&format!("{name}_ball"), &img);
    }
}
