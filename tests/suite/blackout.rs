//! The vision-blackout replay: its trials are played by the striker on the robot's own camera
//! and scored by the rules' points, the same on every run.

use crate::common;
use omniloop::blackout::trials::{HARDWARE_CHALLENGE, Stage};
use omniloop::blackout::{Block, run_blocks, run_trial};

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
    // Stage 2 scores in 18 of the replay's 20 placements (docs/blackout.md); seed 1 is one of
    // the two it misses, seed 2 one it scores cleanly.
    let empty_goal = Block {
        stage: Stage::EmptyGoal,
        ..grab
    };
    let t = run_trial(&empty_goal, 2, &common::cpu()).unwrap();
    assert!(
        t.goal && t.dribbler,
        "stage 2 scored from the dribbler: {t:?}"
    );
    assert!(!t.robot_in_defense_area, "{t:?}");
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
