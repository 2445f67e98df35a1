//! Avoidance beyond the paper's speed and geometry: the velocity-aware controller with chosen
//! speeds, on vision alone, through a family of corridor corners at speeds from the paper's to
//! a Small-Size robot's, and to waypoints 150 mm from the walls in every corner of the field.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{cpu, scenario, scenario_path};
use omniloop::{Summary, parse_scenario, run_scenario};

/// Corner angles (degrees) and widths (mm) of the family.
const ANGLES: [f64; 5] = [35.0, 55.0, 80.0, 105.0, 135.0];
const WIDTHS: [f64; 3] = [600.0, 800.0, 1000.0];

/// The E1 velocity-aware scenario as a corner of `angle` and `width` for a robot of top speed
/// `v_max` and acceleration limit `alpha`, choosing its speeds (the default).
fn corner(angle: f64, width: f64, v_max: f64, alpha: f64) -> omniloop::Scenario {
    let path = scenario_path("corner55_velocity_aware.toml");
    let mut doc: toml::Table = std::fs::read_to_string(&path).unwrap().parse().unwrap();
    let table = |doc: &mut toml::Table, key: &str| -> toml::Table {
        doc.get(key).and_then(|v| v.as_table()).cloned().unwrap()
    };
    let mut exp = table(&mut doc, "experiment");
    let mut c = exp["corner"].as_table().cloned().unwrap();
    c.insert("angle_deg".into(), angle.into());
    c.insert("width_mm".into(), width.into());
    exp.insert("corner".into(), c.into());
    doc.insert("experiment".into(), exp.into());
    let mut robot = table(&mut doc, "robot");
    robot.insert("max_speed_mm_s".into(), v_max.into());
    robot.insert("accel_limit_mm_s2".into(), alpha.into());
    doc.insert("robot".into(), robot.into());
    let mut run = table(&mut doc, "run");
    run.insert("duration_s".into(), 60.0.into());
    doc.insert("run".into(), run.into());
    let mut control = table(&mut doc, "control");
    control.remove("avoidance");
    doc.insert("control".into(), control.into());
    let name = format!("corner_{angle}_{width}_{v_max}_{alpha}");
    parse_scenario(&doc.to_string(), &path, &name).unwrap()
}

/// Runs the family for one robot; every run reaches its goal with no contact and within 1% of
/// alpha.
fn family(v_max: f64, alpha: f64) {
    let mut failures = Vec::new();
    for angle in ANGLES {
        for width in WIDTHS {
            let s = corner(angle, width, v_max, alpha);
            let avoidance: omniloop_control::AvoidanceConfig =
                s.control.table("avoidance").unwrap();
            assert_eq!(avoidance.speed, omniloop_control::SpeedChoice::Chosen);
            let m: Summary = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap().summary;
            eprintln!(
                "| {angle} | {width} | {v_max} | {alpha} | {} | {} | {} | {:.1} | {:.0} | {:.1} |",
                m.reached_goal,
                m.wall_contacts,
                m.time_to_goal_s.map_or("-".into(), |t| format!("{t:.2}")),
                m.min_clearance_mm,
                m.peak_speed_mm_s,
                m.peak_accel_mm_s2
            );
            if !m.reached_goal || m.wall_contacts > 0 || m.peak_accel_mm_s2 > 1.01 * alpha {
                failures.push(format!("{angle} deg, {width} mm: {m:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn the_papers_robot_turns_every_corner() {
    family(400.0, 300.0);
}

#[test]
fn a_faster_robot_with_the_papers_acceleration_turns_every_corner() {
    family(1000.0, 300.0);
}

#[test]
fn a_robot_twice_as_fast_again_turns_every_corner() {
    family(2000.0, 300.0);
}

#[test]
fn a_small_size_robot_turns_every_corner() {
    family(2000.0, 3000.0);
}

#[test]
fn the_robot_reaches_waypoints_150_mm_from_the_walls_in_every_corner_of_the_field() {
    let s = scenario("field_corners.toml");
    let goal = s.goal.as_ref().unwrap();
    let field = s.world.field.as_ref().unwrap();
    // Every target lies 150 mm from a wall; the four waypoints from two.
    for t in goal.targets() {
        let gap_y = field.half_width_mm - t.y.abs();
        assert!((gap_y - 150.0).abs() < 1e-9, "{t}");
    }
    for w in &goal.waypoints_mm {
        assert!(
            (field.half_length_mm - w[0].abs() - 150.0).abs() < 1e-9,
            "{w:?}"
        );
    }
    let m = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap().summary;
    eprintln!("{m:?}");
    assert!(m.reached_goal, "{m:?}");
    assert_eq!(m.targets_reached, Some(5), "{m:?}");
    assert_eq!(m.wall_contacts, 0, "{m:?}");
    assert!(
        m.peak_accel_mm_s2 <= 1.01 * s.robot.accel_limit_mm_s2,
        "{m:?}"
    );
}

#[test]
fn a_robot_started_in_a_corner_of_the_field_leaves_it() {
    // 150 mm from two walls, with nothing remembered yet: its body hides the walls' feet in more
    // than half of the directions. It must still leave the corner and reach the goal along the
    // touchline.
    let mut s = scenario("field_corners.toml");
    s.robot.start = Some(omniloop::scenario::PoseSpec {
        x_mm: 1220.0,
        y_mm: -612.5,
        heading_deg: 0.0,
    });
    let goal = s.goal.as_mut().unwrap();
    goal.waypoints_mm.clear();
    s.run.duration_s = 15.0;
    let m = run_scenario(&s, &cpu(), |_| {}, |_, _| {}).unwrap().summary;
    eprintln!("{m:?}");
    assert!(m.reached_goal, "{m:?}");
    assert_eq!(m.wall_contacts, 0, "{m:?}");
}
