//! The vision-blackout replay: its trials are played by the striker on the robot's own camera
//! and scored by the rules' points, the same on every run.

use crate::common;
use omniloop::blackout::trials::{HARDWARE_CHALLENGE, Stage, place};
use omniloop::blackout::{Block, report, run_blocks, run_trial};

#[test]
fn the_striker_grabs_the_ball_and_scores_on_the_challenge_field() {
    let grab = Block {
        stage: Stage::Grab,
        field: HARDWARE_CHALLENGE,
        realism: false,
    };
    let mut calls = 0;
    let results = run_blocks(&[grab], 1, 2, &common::cpu(), |_, n| {
        calls += 1;
        assert_eq!(n, 2);
    })
    .unwrap();
    assert_eq!(calls, 2, "progress heard every trial");
    for t in &results[0].trials {
        assert_eq!(t.points, 3, "stage 1 full points: {t:?}");
        assert!(t.held_at_end && t.time_s.is_some_and(|s| s < 60.0));
    }
    // The score sheet, the paths and the summary.
    let out = common::tmp("blackout_report");
    let table = report::write(&out, &results, 1.0).unwrap();
    assert!(
        table.contains("| stage 1: grab, hardware_challenge | 2 | 100% |"),
        "{table}"
    );
    let png = image::open(out.join("blackout.png")).unwrap();
    assert!(
        png.width() >= 400 && png.height() >= 300,
        "{:?}",
        (png.width(), png.height())
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["blocks"][0]["success_rate"], 1.0);
    // Stage 2 scores in every one of the replay's 20 placements, none entering a defense area
    // (docs/blackout.md); seed 1's ball lies by the far defense area's corner.
    let empty_goal = Block {
        stage: Stage::EmptyGoal,
        ..grab
    };
    let t = run_trial(&empty_goal, 1, &common::cpu()).unwrap();
    assert!(
        t.goal && t.dribbler,
        "stage 2 scored from the dribbler: {t:?}"
    );
    assert!(!t.robot_in_defense_area, "{t:?}");
    assert_eq!(t.points, 4, "{t:?}");
}

/// Stage 3, seed 8: the defender stands near the middle of the goal, and a shot at the goal's
/// centre hits it. The camera sees the goal's back wall over the defender's top from afar; the
/// goal's runs leave out what the defender hides, so the striker shoots past it.
#[test]
fn the_striker_shoots_past_the_defender() {
    let defended = Block {
        stage: Stage::Defended,
        field: HARDWARE_CHALLENGE,
        realism: false,
    };
    let p = place(Stage::Defended, &HARDWARE_CHALLENGE, 8);
    let defender = p.defender.unwrap();
    assert!(
        defender.y.abs() < 90.0,
        "a defender in the shot's way: {p:?}"
    );
    let t = run_trial(&defended, 8, &common::cpu()).unwrap();
    assert!(t.goal && !t.robot_in_defense_area, "{t:?}");
    assert_eq!(t.points, 4, "{t:?}");
}

#[test]
fn a_trial_is_the_same_every_time() {
    let block = Block {
        stage: Stage::MovingBall,
        field: HARDWARE_CHALLENGE,
        realism: false,
    };
    let a = run_trial(&block, 3, &common::cpu()).unwrap();
    let b = run_trial(&block, 3, &common::cpu()).unwrap();
    assert_eq!(a, b);
    assert!(!a.ball_path.is_empty() && a.ball_path.len() == a.robot_path.len());
}
