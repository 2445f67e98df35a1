//! The truth beside each frame, pixel by pixel: depth, floor distance and labels.

mod common;

use common::scenario;
use omniloop_sim::labels::{self, Class, ObjectId};
use omniloop_sim::optics::Optics;
use omniloop_sim::{Renderer, Scene, World};

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
            saw_other = truth.labels.iter().any(|&l| l == other);
        }
        assert!(own > 100, "robot {robot} sees its body in {own} pixels");
    }
    assert!(saw_other, "robot 0 sees robot 1 down the corridor");
}
