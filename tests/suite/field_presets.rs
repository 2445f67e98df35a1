//! The fields of today's Small-Size rules (`[world.field] preset`): each preset's floor region,
//! walls, goals and painted lines, the robot's map of it, its errors and round trip, the
//! defense areas' lines alike in every renderer kernel, and floor-region self-localization on
//! each.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{bin, cpu, gpu_or_skip, scenario, tmp};
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop::scenario::calibrate::calibrate_sensor;
use omniloop::{Scenario, parse_scenario, run_scenario};
use omniloop_sim::render::cpu as kernels;
use omniloop_sim::render::trace::{CODE_FLOOR, FloorPaint, paint_index};
use omniloop_sim::render::{CpuRenderer, SensorRays};
use omniloop_sim::{
    FieldPreset, FieldSpec, MapFeature, Renderer, Scene, SensorNoise, Target, World, reachability,
};
use omniloop_vision::{FloorLocalizer, Localization, LocalizationConfig};
use std::path::Path;

/// E1's hyperbolic camera, as in `ball_kick.toml`.
const CAMERA: &str = r#"
[[robot.sensors]]
name = "omni"
width_px = 256
height_px = 220
noise_sigma = 4.0
[robot.sensors.hyperbolic]
a_mm = 12.129
b_mm = 15.650
c_mm = 19.8
focal_px = 479.37
focus_height_mm = 205.08
rim_radius_mm = 30.0
"#;

/// A scenario on `preset`'s field (with `field_keys` in its table) of a robot standing at
/// `start` and localizing itself for `duration_s`, told the floor's outline.
fn field_scenario(
    preset: FieldPreset,
    field_keys: &str,
    start: [f64; 3],
    duration_s: f64,
) -> String {
    let outline = FieldSpec::from(preset).floor_outline();
    let [x, y, deg] = start;
    format!(
        "description = \"A robot on the {preset} field.\"\nseed = 3\n\n\
         [run]\nduration_s = {duration_s:?}\ncontrol_period_s = 0.045\nphysics_step_s = 0.0025\n\n\
         [world.field]\npreset = \"{preset}\"\n{field_keys}\n\n\
         [robot]\nstart = {{ x_mm = {x:?}, y_mm = {y:?}, heading_deg = {deg:?} }}\n{CAMERA}\n\
         [vision.localization.field]\na1_mm = {:?}\na2_mm = {:?}\nb_mm = {:?}\n\
         goal_half_width_mm = {:?}\nboundary_line_mm = {:?}\n\n\
         [control]\nkind = \"idle\"\npose_source = \"localization\"\n",
        outline.a1_mm,
        outline.a2_mm,
        outline.b_mm,
        outline.goal_half_width_mm,
        outline.boundary_line_mm,
    )
}

/// The scenario of `text`, which must be valid.
fn parse(text: &str) -> Scenario {
    parse_scenario(text, Path::new("field.toml"), "field").unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// Where each preset's robot stands in these tests: in the playing area, the walls it
/// localizes from within its camera's reach (E2's first place on the corner paper's field, near
/// a corner of the others).
fn place(preset: FieldPreset) -> [f64; 3] {
    match preset {
        FieldPreset::CornerPaper => [-900.0, 0.0, 0.0],
        FieldPreset::HardwareChallenge => [-1500.0, -1000.0, 120.0],
        FieldPreset::DivisionB => [-3900.0, -2600.0, 20.0],
        FieldPreset::DivisionA => [-5400.0, -3900.0, 20.0],
    }
}

/// Whether some solid of `s` covers `p`.
fn solid_at(s: &Scenario, p: [f64; 2]) -> bool {
    let p = Point2::from(p);
    s.world
        .solids()
        .iter()
        .any(|solid| solid.shape.distance_mm(p) <= 0.0)
}

/// The floor region, walls and goals of `s`, on `preset`'s field: where the floor ends, where
/// the walls and goals stand, that the run-off is open floor the robot reaches.
fn check_floor_walls_and_goals(s: &Scenario, preset: FieldPreset) {
    let f = s.world.field.clone().unwrap();
    let (a1, b, bw) = (f.half_length_mm, f.half_width_mm, f.boundary_width_mm);
    let (g, t, a2) = (0.5 * f.goal_width_mm, f.wall_thickness_mm, f.goal_back_mm());
    // The floor: the run-off's corner is floor, just beyond the walls' faces is not.
    let floor = |p: [f64; 2]| s.world.is_floor(Point2::from(p));
    assert!(floor([a1 + bw - 1.0, b + bw - 1.0]), "{preset}");
    assert!(!floor([a1 + bw + 1.0, g + 1.0]), "{preset}");
    assert!(!floor([0.0, -b - bw - 1.0]), "{preset}");
    // The walls stand at the floor's edge; the goal's back and sides where its figures say.
    for p in [
        [a1 + bw + 1.0, g + 10.0],
        [0.0, b + bw + 1.0],
        [a2 + 1.0, 0.0],
    ] {
        assert!(solid_at(s, p), "{preset}: {p:?} not in a wall");
    }
    for p in [
        [-a2 - 1.0, 0.0],
        [a1 + 10.0, g + 0.5 * t],
        [-a1 - 10.0, -g - 0.5 * t],
    ] {
        assert!(solid_at(s, p), "{preset}: {p:?} not in a goal");
    }
    for p in [
        [a2 - 1.0, 0.0],
        [a1 + bw - 1.0, b + bw - 1.0],
        [0.0, b - 1.0],
    ] {
        assert!(!solid_at(s, p), "{preset}: {p:?} in a wall");
    }
    if bw > 0.0 {
        // A free-standing goal: the run-off beside it and behind it is open floor.
        for p in [[a1 + 10.0, g + t + 10.0], [a2 + t + 10.0, 0.0]] {
            assert!(!solid_at(s, p) && floor(p), "{preset}: {p:?}");
        }
        // The robot reaches the run-off's corner.
        let [x, y, _] = place(preset);
        let corner = Target {
            point_mm: Point2::new(a1 + bw - 150.0, -b - bw + 150.0),
            tolerance_mm: 20.0,
        };
        let r = reachability(&s.world, 90.0, Point2::new(x, y), &[corner]).unwrap();
        assert!(r.reachable, "{preset}: {r:?}");
    }
}

#[test]
fn every_preset_gives_its_floor_walls_goals_lines_and_map() {
    for preset in FieldPreset::ALL {
        let s = parse(&field_scenario(preset, "", place(preset), 1.0));
        let f = s.world.field.clone().unwrap();
        assert_eq!(f, FieldSpec::from(preset), "{preset}");
        check_floor_walls_and_goals(&s, preset);
        // The lines: halfway line, centre circle, and each defense area's front and side.
        let (a1, b) = (f.half_length_mm, f.half_width_mm);
        let on = |p: [f64; 2]| f.on_line(Point2::from(p));
        assert!(on([0.0, 0.5 * b]), "{preset}");
        assert!(on([0.0, -f.centre_circle_radius_mm]), "{preset}");
        let (d, w) = (f.defense_area_depth_mm, 0.5 * f.defense_area_width_mm);
        if d > 0.0 {
            for p in [
                [a1 - d + 5.0, 0.0],
                [-a1 + d - 5.0, 0.5 * w],
                [a1 - 0.5 * d, w - 5.0],
            ] {
                assert!(on(p), "{preset}: {p:?}");
            }
            assert!(!on([a1 - 0.5 * d, 0.0]), "{preset}");
        }
        // The robot's map: the field's figures with its defense areas, and the painted lines.
        let map = s.robot_map().field.unwrap();
        assert_eq!((map.half_length_mm, map.half_width_mm), (a1, b), "{preset}");
        let defense = (map.defense_depth_mm, map.defense_width_mm);
        assert_eq!(defense, (d, 2.0 * w), "{preset}");
        let lines = s.world.map_features().into_iter().find_map(|m| match m {
            MapFeature::Lines(l) => Some(l),
            _ => None,
        });
        assert_eq!(lines, Some(f.lines()), "{preset}");
    }
}

#[test]
fn a_key_given_beside_the_preset_overrides_its_value() {
    let text = field_scenario(
        FieldPreset::DivisionB,
        "wall_height_mm = 200.0",
        place(FieldPreset::DivisionB),
        1.0,
    );
    let f = parse(&text).world.field.unwrap();
    assert_eq!(
        f,
        FieldSpec {
            wall_height_mm: 200.0,
            ..FieldSpec::from(FieldPreset::DivisionB)
        }
    );
    let walls = f.walls();
    assert!(walls.iter().any(|w| w.height_mm == 200.0));
}

#[test]
fn the_field_is_written_back_as_figures_that_read_back_the_same() {
    for preset in FieldPreset::ALL {
        let s = parse(&field_scenario(
            preset,
            "goal_width_mm = 800.0",
            place(preset),
            1.0,
        ));
        let text = toml::to_string(&s).unwrap();
        let table: toml::Table = toml::from_str(&text).unwrap();
        let field = table["world"]["field"].as_table().unwrap();
        assert!(!field.contains_key("preset"), "{preset}: {field:?}");
        assert_eq!(field["goal_width_mm"].as_float(), Some(800.0), "{preset}");
        let again = parse_scenario(&text, Path::new("again.toml"), "field").unwrap();
        assert_eq!(again.world.field, s.world.field, "{preset}");
    }
}

/// `omniloop check` on a scenario with `[world.field]` replaced: its exit code and stderr.
fn check_field(name: &str, field_table: &str) -> (i32, String) {
    let text = field_scenario(
        FieldPreset::DivisionB,
        "",
        place(FieldPreset::DivisionB),
        1.0,
    )
    .replace("preset = \"division_b\"\n", field_table);
    let dir = tmp(&format!("field_presets_{name}"));
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, text).unwrap();
    let out = bin().arg("check").arg(&file).output().unwrap();
    (
        out.status.code().unwrap(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn an_unknown_preset_or_a_bad_figure_exits_2_naming_the_field() {
    let (code, err) = check_field("unknown_preset", "preset = \"division_c\"\n");
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(":10:10: field `world.field.preset`: unknown variant"),
        "{err}"
    );
    for p in FieldPreset::ALL {
        assert!(err.contains(p.name()), "{err} lacks {p}");
    }
    assert!(!err.contains("panicked"), "{err}");
    let cases = [
        (
            "boundary_width_mm = 100.0",
            "world.field.boundary_width_mm`: must be 0",
        ),
        (
            "defense_area_width_mm = 7000.0",
            "world.field.defense_area_width_mm`: must be narrower",
        ),
        (
            "defense_area_depth_mm = -1.0",
            "world.field.defense_area_depth_mm`: must be >= 0",
        ),
    ];
    for (key, message) in cases {
        let (code, err) = check_field(key, &format!("preset = \"division_b\"\n{key}\n"));
        assert_eq!(code, 2, "{key}: {err}");
        assert!(err.contains(message), "{key}: {err}");
    }
}

/// A defense area's corner seen from near it on the division B field: the pixels it paints are
/// line-coloured and alike in every kernel.
#[test]
fn a_defense_area_line_renders_alike_in_every_kernel() {
    let s = parse(&field_scenario(
        FieldPreset::DivisionB,
        "",
        [3300.0, 800.0, 30.0],
        1.0,
    ));
    let plain = FieldSpec {
        defense_area_depth_mm: 0.0,
        defense_area_width_mm: 0.0,
        ..s.world.field.clone().unwrap()
    };
    let mut without = s.world.clone();
    without.field = Some(plain);
    let sensor = s.robot.sensors[0].build();
    let pose = Isometry2::new(Vector2::new(3300.0, 800.0), 30f64.to_radians());
    let (scene, bare) = (Scene::new(&s.world, &[]), Scene::new(&without, &[]));
    let mut rays = SensorRays::new(&sensor);
    let traced = kernels::trace_reference(&scene, &rays, &pose);
    let reference: Vec<u32> = traced.iter().map(|r| r.colour).collect();
    let bare_reference = kernels::render_reference(&bare, &rays, &pose);
    // The defense lines' pixels: what the bare field shows otherwise.
    let line: Vec<usize> = (0..reference.len())
        .filter(|&i| reference[i] != bare_reference[i])
        .collect();
    eprintln!("defense-line pixels: {}", line.len());
    assert!(line.len() >= 100, "only {} defense-line pixels", line.len());
    let line_code = CODE_FLOOR | paint_index(&scene, FloorPaint::Line);
    assert!(line.iter().all(|&i| traced[i].code == line_code));
    for (kind, mut r) in [
        ("vector", CpuRenderer::new()),
        ("portable", CpuRenderer::portable()),
    ] {
        let mut pixels = vec![0; reference.len()];
        r.render(&scene, &mut rays, &pose, &mut pixels);
        let differ = pixels
            .iter()
            .zip(&reference)
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(differ, 0, "{kind} kernel");
    }
    gpu_paints_the_same_defense_lines(&scene, &bare, &sensor, &pose, &line);
}

/// The GPU's defense-line pixels (where the field with its defense areas differs from the bare
/// one) against the CPU's `line`; skipped, and said so, with no adapter.
fn gpu_paints_the_same_defense_lines(
    scene: &Scene,
    bare: &Scene,
    sensor: &omniloop_sim::Sensor,
    pose: &Isometry2<f64>,
    line: &[usize],
) {
    let Some(mut gpu) = gpu_or_skip() else {
        return;
    };
    let a = Renderer::cpu().render(scene, sensor, pose, None).unwrap();
    let b = gpu.render(scene, sensor, pose, None).unwrap();
    let bare_gpu = gpu.render(bare, sensor, pose, None).unwrap();
    let (w, n) = (a.width() as usize, (a.width() * a.height()) as usize);
    let at = |img: &image::RgbaImage, i: usize| img.get_pixel((i % w) as u32, (i / w) as u32).0;
    let mut on_cpu = vec![false; n];
    line.iter().for_each(|&i| on_cpu[i] = true);
    // Pixels one renderer paints with a defense line and the other not, or in another colour.
    let relabelled = (0..n)
        .filter(|&i| {
            let on_gpu = at(&b, i) != at(&bare_gpu, i);
            on_cpu[i] != on_gpu || (on_gpu && at(&a, i) != at(&b, i))
        })
        .count();
    eprintln!(
        "GPU ({}): {relabelled} of the {} defense-line pixels differ from the CPU's",
        gpu.name(),
        line.len()
    );
    // As in truth.rs: the GPU traces the mirror in f32, the CPU in f64, so a pixel may differ
    // only where its ray grazes an edge (none on llvmpipe), at most 0.05% of the frame.
    assert!(relabelled * 2000 <= n, "{relabelled} of {n} pixels");
}

/// What self-localization makes of one place: the errors (mm, degrees) of its fixes.
#[derive(Debug, Default)]
struct Errors {
    mm: Vec<f64>,
    deg: Vec<f64>,
    missed: usize,
}

impl Errors {
    fn add(&mut self, result: Localization, truth: &Isometry2<f64>) {
        match result {
            Localization::Localized(e) => {
                self.mm
                    .push((e.pose.translation.vector - truth.translation.vector).norm());
                let turn = e.pose.rotation.angle() - truth.rotation.angle();
                self.deg
                    .push(turn.sin().atan2(turn.cos()).abs().to_degrees());
            }
            Localization::NotLocalized(_) => self.missed += 1,
        }
    }

    fn worst(&self) -> (f64, f64) {
        let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
        (max(&self.mm), max(&self.deg))
    }
}

/// Tracking from a prior 150 mm and 10 degrees off the truth, over `frames` noisy frames at
/// the preset's place: each frame's fix.
fn track_from_an_offset_prior(preset: FieldPreset, frames: u64) -> Errors {
    let s = parse(&field_scenario(preset, "", place(preset), 1.0));
    let spec = &s.robot.sensors[0];
    let sensor = spec.build();
    let cal = calibrate_sensor(spec).unwrap();
    let config: LocalizationConfig = s.vision.table("localization").unwrap();
    assert_eq!(
        config.field,
        s.world.field.as_ref().unwrap().floor_outline()
    );
    let mut localizer = FloorLocalizer::new(config, &cal).unwrap();
    let world = World::new(&s.world, &s.robot_bodies(), 0.002).unwrap();
    let truth = world.robot_state(0).pose;
    let scene = Scene::of_world(&world);
    let mut renderer = Renderer::cpu();
    let mut noise = SensorNoise::new(17);
    let mut errors = Errors::default();
    for k in 0..frames {
        let img = renderer
            .render(&scene, &sensor, &truth, Some(&mut noise))
            .unwrap();
        let a = k as f64 * 2.4;
        let prior = Isometry2::new(
            truth.translation.vector + 150.0 * Vector2::new(a.cos(), a.sin()),
            truth.rotation.angle() + if k % 2 == 0 { 0.1745 } else { -0.1745 },
        );
        errors.add(localizer.track(&img, &prior).unwrap(), &truth);
    }
    errors
}

/// Tolerance of the fixes near a corner of every preset: E2's 30 mm, and 1.5 degrees over the
/// 1.15 degrees measured on the hardware challenge's field (worst frames measured, tracking:
/// corner paper 0.3 mm 0.00 deg, division B 0.6 mm 0.19 deg, division A 0.2 mm 0.06 deg,
/// hardware challenge 5.5 mm 1.15 deg).
const TOLERANCE: (f64, f64) = (30.0, 1.5);

#[test]
fn self_localization_tracks_from_an_offset_prior_on_every_preset() {
    // Global mode localizes nowhere near a corner of division A or B (a corner of so large a
    // rectangle looks like any other; docs/field.md), so every preset is tracked from a prior.
    for preset in FieldPreset::ALL {
        let e = track_from_an_offset_prior(preset, 6);
        let (mm, deg) = e.worst();
        eprintln!(
            "{preset} at {:?}: tracking {} of 6 fixed, worst {mm:.1} mm, {deg:.2} deg",
            place(preset),
            e.mm.len()
        );
        assert_eq!(e.missed, 0, "{preset}: {e:?}");
        assert!(mm <= TOLERANCE.0 && deg <= TOLERANCE.1, "{preset}: {e:?}");
    }
}

/// Two seconds of a robot standing near a corner of the fields where global mode finds it: its
/// first fix from the image alone, then every cycle's (measured: corner paper 0.3 mm, 0.00 deg;
/// hardware challenge 5.5 mm, 1.15 deg).
#[test]
fn a_robot_standing_on_the_field_localizes_itself_in_a_short_run() {
    for preset in [FieldPreset::CornerPaper, FieldPreset::HardwareChallenge] {
        let s = parse(&field_scenario(preset, "", place(preset), 2.0));
        let out = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap();
        let m = &out.summary;
        let [x, y, deg] = place(preset);
        let last = out.trajectory.last().unwrap();
        let err = (last.est_x_mm.unwrap() - x).hypot(last.est_y_mm.unwrap() - y);
        let turn = last.est_theta_rad.unwrap() - deg.to_radians();
        let err_deg = turn.sin().atan2(turn.cos()).abs().to_degrees();
        eprintln!(
            "{preset}: {} fixes in {} cycles, median pose error {:.1} mm, last {err:.1} mm, \
             {err_deg:.2} deg",
            m.localization_fixes.unwrap_or(0),
            m.cycles,
            m.pose_error_mm.unwrap_or(f64::NAN)
        );
        assert!(
            m.localization_fixes.unwrap() as u64 >= m.cycles * 9 / 10,
            "{preset}: {m:?}"
        );
        assert!(m.pose_error_mm.unwrap() <= TOLERANCE.0, "{preset}: {m:?}");
        assert!(
            err <= TOLERANCE.0 && err_deg <= TOLERANCE.1,
            "{preset}: {err} mm, {err_deg} deg"
        );
    }
}

#[test]
fn the_example_scenarios_run_on_their_presets() {
    for (name, preset) in [
        ("field_division_b.toml", FieldPreset::DivisionB),
        (
            "field_hardware_challenge.toml",
            FieldPreset::HardwareChallenge,
        ),
    ] {
        let s = scenario(name);
        let f = s.world.field.clone().unwrap();
        assert_eq!(f, FieldSpec::from(preset), "{name}");
        let config: LocalizationConfig = s.vision.table("localization").unwrap();
        assert_eq!(config.field, f.floor_outline(), "{name}");
        let out = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap();
        let m = &out.summary;
        assert_eq!(m.wall_contacts, 0, "{name}");
        if preset == FieldPreset::DivisionB {
            // Kicked across the defense area into the free-standing goal.
            let ball = m.ball.as_ref().expect("a ball table");
            assert_eq!(ball.goals.len(), 1, "{name}: {ball:?}");
            assert_eq!(ball.goals[0].goal, "+x");
        } else {
            assert_eq!(
                m.localization_fixes,
                Some(m.cycles as usize),
                "{name}: {m:?}"
            );
            assert!(m.pose_error_mm.unwrap() <= TOLERANCE.0, "{name}: {m:?}");
        }
    }
}
