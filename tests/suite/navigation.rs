//! Navigation among obstacles: the planner on the map the robot builds, above the
//! velocity-aware controller, on the traps of `scenarios/` and the clutter generator.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{cpu, omniloop, scenario, tmp};
use omniloop::run_scenario;

/// Runs the shipped scenario `file` on the CPU renderer, without progress or frames.
fn run_shipped(file: &str) -> omniloop::RunOutput {
    run_scenario(&scenario(file), &cpu(), |_| {}, |_, _| {}).unwrap()
}

#[test]
fn an_enclosed_goal_is_reported_unreachable_within_ten_seconds_and_the_robot_stands_still() {
    let out = run_shipped("trap_enclosed.toml");
    let s = &out.summary;
    assert_eq!(s.unreachable, Some(true), "{s:?}");
    assert!(!s.reached_goal);
    assert_eq!(s.wall_contacts, 0, "{s:?}");
    let (k, first) = out
        .estimates
        .iter()
        .enumerate()
        .find(|(_, e)| e.not_found.iter().any(|n| n.source == "planner"))
        .expect("a cycle reports the goal unreachable");
    assert!(first.t_s <= 10.0, "reported at {} s", first.t_s);
    let reason = &first
        .not_found
        .iter()
        .find(|n| n.source == "planner")
        .unwrap()
        .reason;
    assert!(reason.starts_with("unreachable:"), "{reason}");
    // Braking from 400 mm/s at 300 mm/s^2 takes 1.33 s; after that it stands still.
    let stopped_from = first.t_s + 1.5;
    for row in out
        .trajectory
        .iter()
        .skip(k)
        .filter(|r| r.t_s >= stopped_from)
    {
        let v = row.vx_mm_s.hypot(row.vy_mm_s);
        assert!(v < 1.0, "moving at {v} mm/s at {} s", row.t_s);
    }
    // Every later cycle says so too.
    assert!(out.estimates[k..].iter().all(|e| {
        e.navigation
            .as_ref()
            .is_some_and(|n| n.unreachable.is_some())
    }));
}

#[test]
fn the_goal_behind_a_cul_de_sac_facing_the_start_is_reached_without_contact() {
    let out = run_shipped("trap_cul_de_sac.toml");
    let s = &out.summary;
    assert!(s.reached_goal, "{s:?}");
    assert_eq!(s.wall_contacts, 0, "{s:?}");
    assert_eq!(s.unreachable, Some(false), "{s:?}");
    // The way is round an arm of the U: the robot passed beyond the arms' outer faces (y = 455
    // and -455 mm), through a gap of about 300 mm between an arm and the field's wall.
    assert!(
        out.trajectory.iter().any(|r| r.y_mm.abs() > 455.0 + 90.0),
        "never went round an arm"
    );
}

#[test]
fn a_goal_in_a_field_corner_behind_a_cube_is_reached_without_contact() {
    let out = run_shipped("trap_corner_goal.toml");
    let s = &out.summary;
    assert!(s.reached_goal, "{s:?}");
    assert_eq!(s.wall_contacts, 0, "{s:?}");
    assert_eq!(s.unreachable, Some(false));
    // The robot built a map: the field's walls from its map and cells it saw free and blocked.
    let map = out.map.as_ref().expect("the planner's map");
    let count = |st| map.cells.iter().filter(|&&c| c == st).count();
    use omniloop_robot::CellState::{Blocked, Free};
    assert!(
        count(Free) > 1000 && count(Blocked) > 500,
        "free {} blocked {}",
        count(Free),
        count(Blocked)
    );
    // Each cycle records the plan: a path ending within the goal's 100 mm tolerance (the goal,
    // 112 mm from the touchline, lies inside the walls' inflated band, so the plan ends on the
    // nearest passable cell that counts as there).
    let plan = out.estimates[10]
        .navigation
        .as_ref()
        .expect("a plan record");
    let end = plan.path_mm.last().unwrap();
    assert!(
        (end - nalgebra::Point2::new(1250.0, 650.0)).norm() <= 100.0,
        "{end:?}"
    );
}

#[test]
fn the_clutter_layout_follows_its_seed_and_the_run_writes_the_plan_and_the_map() {
    let dir = tmp("clutter_run");
    omniloop([
        "run",
        "scenarios/clutter.toml",
        "--renderer",
        "cpu",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["unreachable"], false);
    assert!(
        summary["straight_mm"].as_f64().unwrap() >= 1500.0,
        "{summary}"
    );
    assert!(dir.join("topview.png").is_file());
    let first = std::fs::read_to_string(dir.join("estimates.jsonl")).unwrap();
    let line: serde_json::Value = serde_json::from_str(first.lines().next().unwrap()).unwrap();
    assert!(
        line["plan"]["path_mm"]
            .as_array()
            .is_some_and(|p| p.len() >= 2),
        "{line}"
    );
    // Another layout seed, another layout (the sweep key `experiment.clutter.seed`).
    let a = scenario("clutter.toml");
    let text = std::fs::read_to_string(common::scenario_path("clutter.toml"))
        .unwrap()
        .replace(
            "[experiment.clutter]\nseed = 1",
            "[experiment.clutter]\nseed = 2",
        );
    let b =
        omniloop::experiments::parse_scenario(&text, "clutter.toml".as_ref(), "clutter").unwrap();
    assert_ne!(a.world.cubes, b.world.cubes);
    assert_ne!(a.goal, b.goal);
    assert_eq!(a.world.cubes.len(), 10);
}

#[test]
fn the_corner_route_passes_every_corner_and_leaves_the_pocket_by_the_gap_it_came_in_by() {
    // The waypoint at (1200, 600) lies in the pocket between E2's cube at (1000, 450) and the
    // field's corner; the way on to (1200, -600) is back down the 305 mm gap beside the cube.
    // Standing in the gap's mouth with the floor by its body out of the near-field memory, the
    // robot once stood there for the rest of the run; the map's floor now says how far off the
    // cube and the wall in its blind zone stand.
    let out = run_shipped("field_corner_route.toml");
    let s = &out.summary;
    assert!(s.reached_goal, "{s:?}");
    assert_eq!(s.targets_reached, Some(4), "{s:?}");
    assert_eq!(s.wall_contacts, 0, "{s:?}");
    assert!(s.time_to_goal_s.is_some_and(|t| t < 60.0), "{s:?}");
    // It went through the pocket: within 100 mm of (1200, 600), then below the cube.
    let near = |x: f64, y: f64| {
        out.trajectory
            .iter()
            .position(|r| (r.x_mm - x).hypot(r.y_mm - y) <= 100.0)
    };
    let (pocket, below) = (near(1200.0, 600.0), near(1200.0, -600.0));
    assert!(pocket.is_some() && below > pocket, "{pocket:?} {below:?}");
}
