//! A mirror off its place (`[robot.sensors.mounting]`), end to end: a tilted hyperbolic mirror
//! moves the floor horizon where the closed form puts it, the culled CPU tracer still equals
//! tracing every primitive, and the GPU and the CPU agree.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{assert_alike, gpu_or_skip, scenario};
use nalgebra::{Isometry2, Vector2, Vector3};
use omniloop::run::render_snapshot;
use omniloop_sim::optics::{HyperbolicMirror, MirrorMounting};
use omniloop_sim::render::SensorRays;
use omniloop_sim::{Renderer, Scene, SensorSpec, World};

#[test]
fn a_tilted_hyperbolic_mirror_moves_the_floor_horizon_where_the_closed_form_says() {
    // Tilted by 2 degrees toward azimuth 30 degrees about the camera's pinhole C (the vertex
    // pivot with the offset -(I - R)(P - C)), the mirror and camera are the nominal pair with
    // the camera turned by R^T, all turned by R. A world direction u is the nominal system's
    // R^T u, at elevation e' and azimuth psi', which the single-viewpoint mirror images at
    // radius R(e') = f a^2 cos e' / (2 b c - (b^2 + c^2) sin e') (HyperOmni's projection at
    // unit distance) and angle psi'; the tilted camera's pixel is the projection of R times
    // that pixel's direction.
    let m = HyperbolicMirror::corner_paper();
    let mut spec = SensorSpec::corner_paper("omni");
    let frame = spec.optics.mirror_frame().unwrap();
    let mut mounting = MirrorMounting {
        mirror_tilt_deg: 2.0,
        tilt_azimuth_deg: 30.0,
        ..MirrorMounting::default()
    };
    let r = mounting.rotation();
    let p_minus_c = Vector3::new(0.0, 0.0, frame.pivot_mm - frame.pinhole_mm);
    let offset = -(p_minus_c - r * p_minus_c);
    mounting.mirror_offset_mm = [offset.x, offset.y, offset.z];
    spec.mounting = mounting;
    let sensor = spec.build();
    let (a, b, c, f) = (m.a_mm, m.b_mm, m.focal_half_distance_mm(), m.focal_px);
    let radius_of = |e: f64| f * a * a * e.cos() / (2.0 * b * c - (b * b + c * c) * e.sin());
    let nominal = radius_of(0.0);
    let mut largest_shift: f64 = 0.0;
    for psi_deg in [0.0f64, 60.0, 120.0, 180.0, 240.0, 300.0] {
        let psi = psi_deg.to_radians();
        let w = r.inverse() * Vector3::new(psi.cos(), psi.sin(), 0.0);
        let (e, az) = (w.z.asin(), w.y.atan2(w.x));
        let rn = radius_of(e);
        let d = r * Vector3::new(rn * az.cos(), rn * az.sin(), f);
        let (x, y) = (f * d.x / d.z, f * d.y / d.z);
        let (predicted, angle) = (x.hypot(y), y.atan2(x));
        // The tracer: where along that image direction its rays stop going down.
        let down = |rho: f64| {
            sensor
                .scene_ray(rho * angle.cos(), rho * angle.sin())
                .is_some_and(|ray| ray.dir.z < 0.0)
        };
        let (mut lo, mut hi) = (predicted - 3.0, predicted + 3.0);
        assert!(
            down(lo) && !down(hi),
            "psi {psi_deg}: no horizon near {predicted:.2} px"
        );
        for _ in 0..50 {
            let mid = 0.5 * (lo + hi);
            if down(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let traced = 0.5 * (lo + hi);
        assert!(
            (traced - predicted).abs() < 1e-3,
            "psi {psi_deg}: traced {traced:.5} px, closed form {predicted:.5} px"
        );
        largest_shift = largest_shift.max((predicted - nominal).abs());
    }
    // Two degrees move the horizon by pixels, not by rounding.
    assert!(largest_shift > 2.0, "{largest_shift}");
}

fn tilted_corner() -> omniloop::Scenario {
    let mut s = scenario("corner55_velocity_aware.toml");
    s.robot.sensors[0].mounting = MirrorMounting {
        mirror_tilt_deg: 1.5,
        tilt_azimuth_deg: -40.0,
        mirror_offset_mm: [0.8, -0.5, 1.0],
        ..MirrorMounting::default()
    };
    s
}

#[test]
fn the_culled_tracer_equals_tracing_every_primitive_with_a_mirror_off_its_place() {
    let s = tilted_corner();
    let mut bodies = s.robot_bodies();
    bodies[0].start = Isometry2::new(Vector2::new(-650.0, 150.0), 40f64.to_radians());
    let world = World::new(&s.world, &bodies, 0.002).unwrap();
    let scene = Scene::of_world(&world);
    let pose = world.robot_state(0).pose;
    let sensor = s.robot.sensors[0].build();
    let culled = Renderer::cpu()
        .render_packed(&scene, &sensor, &pose)
        .unwrap()
        .to_vec();
    let reference =
        omniloop_sim::render::cpu::render_reference(&scene, &SensorRays::new(&sensor), &pose);
    assert_eq!(culled, reference);
    // And the mounting changed the frame.
    let nominal = scenario("corner55_velocity_aware.toml").robot.sensors[0].build();
    let plain = Renderer::cpu()
        .render_packed(&scene, &nominal, &pose)
        .unwrap()
        .to_vec();
    let differ = plain.iter().zip(&culled).filter(|(a, b)| a != b).count();
    assert!(differ > 1000, "{differ}");
}

#[test]
fn gpu_and_cpu_agree_with_a_mirror_off_its_place() {
    let Some(mut gpu) = gpu_or_skip() else {
        return;
    };
    let s = tilted_corner();
    let mut cpu = Renderer::cpu();
    let pose = Some(Isometry2::new(
        Vector2::new(-650.0, 150.0),
        40f64.to_radians(),
    ));
    for pose in [None, pose] {
        let a = render_snapshot(&s, &mut cpu, None, pose, true).unwrap();
        let b = render_snapshot(&s, &mut gpu, None, pose, true).unwrap();
        assert_alike(&a, &b, 2, gpu.name());
    }
}

/// E1 with its mirror shifted 1 mm forward: the free-space stage finds the robot's own dark
/// image off the calibration's centre in the first frame and lays its template about it, so the robot still turns the corner without contact (before, the dark image filled
/// the first ring ahead and the robot never started). Off by default, it stays where it was.
#[test]
fn e1_turns_the_corner_with_its_mirror_shifted_1_mm() {
    let run = |recentre_px: f64| {
        let mut s = scenario("corner55_velocity_aware.toml");
        s.robot.sensors[0].mounting.mirror_offset_mm = [1.0, 0.0, 0.0];
        let mut fs: omniloop_vision::FreeSpaceConfig = s.vision.table("freespace").unwrap();
        fs.recentre_px = recentre_px;
        s.vision.tables.set("freespace", &fs).unwrap();
        omniloop::run_scenario(&s, &common::cpu(), |_| {}, |_, _| {})
            .unwrap()
            .summary
    };
    let m = run(1.0);
    eprintln!(
        "recentred: goal {}, {} contacts, min clearance {:.1} mm, free-space error {:.1} mm",
        m.reached_goal,
        m.wall_contacts,
        m.min_clearance_mm,
        m.freespace_error_mm.unwrap_or(f64::NAN)
    );
    assert!(m.reached_goal && m.wall_contacts == 0);
    assert!(m.freespace_error_mm.unwrap() < 30.0);
    let stuck = run(0.0);
    assert!(
        !stuck.reached_goal && stuck.path_length_mm < 100.0,
        "{stuck:?}"
    );
}
