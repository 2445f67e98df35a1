//! How runs with a goal end, end to end: the simulator's pilot drives straight for the goal on
//! the truth, so that the outcome and the route's reachability in `summary.json` are known in
//! advance (reached; stuck against a wall when the goal is closed off; time up while still
//! driving), for one robot and for a team's rows.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use omniloop::run::{GoalOutcome, Summary};
use omniloop::{parse_scenario, run_scenario};
use std::path::Path;

/// Walls closing the square of 400 mm around (900, 0) (their inner faces 200 mm from it).
const BOX: &str = "[[world.walls]]\nfrom_mm = [650.0, -250.0]\nto_mm = [650.0, 250.0]\n\
[[world.walls]]\nfrom_mm = [1150.0, -250.0]\nto_mm = [1150.0, 250.0]\n\
[[world.walls]]\nfrom_mm = [650.0, -250.0]\nto_mm = [1150.0, -250.0]\n\
[[world.walls]]\nfrom_mm = [650.0, 250.0]\nto_mm = [1150.0, 250.0]\n";

/// The run of the truth pilot for `duration_s` from the origin to `goal` in `world`.
fn pilot_run(world: &str, goal: [f64; 2], duration_s: f64, speed_mm_s: f64) -> Summary {
    let text = format!(
        "[run]\nduration_s = {duration_s}\npilot = \"truth\"\n\n[world]\n{world}\n\
         [robot]\nstart = {{ x_mm = 0.0, y_mm = 0.0 }}\nmax_speed_mm_s = {speed_mm_s}\n\n\
         [goal]\nx_mm = {}\ny_mm = {}\n",
        goal[0], goal[1]
    );
    let s = parse_scenario(&text, Path::new("pilot.toml"), "pilot").unwrap();
    run_scenario(&s, &Default::default(), |_| {}, |_, _| {})
        .unwrap()
        .summary
}

#[test]
fn an_open_goal_is_reached_and_reachable() {
    let m = pilot_run("", [900.0, 0.0], 10.0, 1000.0);
    let g = m.goal_figures.expect("a goal has its figures");
    assert!(m.reached_goal);
    assert_eq!(g.outcome, GoalOutcome::Reached);
    assert!(
        g.goal_reachable && g.reachable_margin_mm.is_some_and(|m| m > 1000.0),
        "{g:?}"
    );
    assert_eq!(g.unreachable_reason, None);
}

#[test]
fn a_goal_closed_off_leaves_the_pilot_stuck_against_the_wall() {
    let m = pilot_run(BOX, [900.0, 0.0], 20.0, 1000.0);
    let g = m.goal_figures.expect("a goal has its figures");
    assert!(!m.reached_goal);
    assert_eq!(m.wall_contacts, 1);
    assert_eq!((g.goal_reachable, g.reachable_margin_mm), (false, None));
    assert_eq!(g.outcome, GoalOutcome::Stuck, "{g:?}");
    let json = serde_json::to_value(&g).unwrap();
    assert_eq!(json["outcome"], "stuck");
    assert_eq!(json["reachable_margin_mm"], serde_json::Value::Null);
}

#[test]
fn time_running_out_while_driving_is_time_up() {
    // 2 s at 300 mm/s towards a goal 3 m away: short of it, moving all along.
    let m = pilot_run("", [3000.0, 0.0], 2.0, 300.0);
    let g = m.goal_figures.expect("a goal has its figures");
    assert_eq!(g.outcome, GoalOutcome::TimeUp, "{g:?}");
    // No goal: no figures, and none of their keys.
    let text = "[run]\nduration_s = 0.5\n\n[robot]\nstart = { x_mm = 0.0, y_mm = 0.0 }\n";
    let s = parse_scenario(text, Path::new("idle.toml"), "idle").unwrap();
    let out = run_scenario(&s, &Default::default(), |_| {}, |_, _| {}).unwrap();
    assert!(out.summary.goal_figures.is_none());
    let json = serde_json::to_value(&out.summary).unwrap();
    for key in ["outcome", "goal_reachable", "reachable_margin_mm"] {
        assert!(json.get(key).is_none(), "{key}");
    }
}

#[test]
fn a_team_has_its_figures_per_robot_and_its_worst_outcome() {
    let text = format!(
        "[run]\nduration_s = 20.0\npilot = \"truth\"\n\n[world]\n{BOX}\n\
         [robot]\nmax_speed_mm_s = 1000.0\n\n\
         [[robots]]\nname = \"open\"\nstart = {{ x_mm = 0.0, y_mm = 600.0 }}\n\
         goal = {{ x_mm = 900.0, y_mm = 600.0 }}\n\n\
         [[robots]]\nname = \"boxed\"\nstart = {{ x_mm = 0.0, y_mm = 0.0 }}\n\
         goal = {{ x_mm = 900.0, y_mm = 0.0 }}\n"
    );
    let s = parse_scenario(&text, Path::new("team.toml"), "team").unwrap();
    let m = run_scenario(&s, &Default::default(), |_| {}, |_, _| {})
        .unwrap()
        .summary;
    let rows = m.robots.expect("a team's rows");
    let figures: Vec<_> = rows
        .iter()
        .map(|r| r.goal_figures.clone().unwrap())
        .collect();
    assert_eq!(figures[0].outcome, GoalOutcome::Reached);
    assert!(figures[0].goal_reachable);
    assert_eq!(figures[1].outcome, GoalOutcome::Stuck);
    assert!(!figures[1].goal_reachable);
    let team = m.goal_figures.expect("the team's figures");
    assert_eq!(team.outcome, GoalOutcome::Stuck);
    assert_eq!(
        (team.goal_reachable, team.reachable_margin_mm),
        (false, None)
    );
}
