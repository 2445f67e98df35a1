//! A robot of one's own in the loop: `examples/custom_robot.rs` (a gap follower written against
//! the `RobotSoftware` trait alone) drives E1's corner through the library's `Runner`.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

#[path = "../../examples/custom_robot.rs"]
#[allow(dead_code)]
mod example;

use common::{scenario_path, tmp};

#[test]
fn the_example_robot_reaches_the_e1_goal_without_contact_and_writes_its_run() {
    let out = tmp("custom_robot");
    let s = example::run(&scenario_path("corner55_velocity_aware.toml"), &out).unwrap();
    assert!(s.reached_goal, "{s:?}");
    assert_eq!(s.wall_contacts, 0, "{s:?}");
    assert!(s.min_clearance_mm > 20.0, "{s:?}");
    assert_eq!(s.controller, "custom");
    // The truth side scored what the robot reported: its free space and its dead reckoning.
    assert!(s.freespace_error_mm.is_some_and(|e| e < 40.0), "{s:?}");
    assert!(s.pose_error_mm.is_some_and(|e| e < 20.0), "{s:?}");
    for file in [
        "summary.json",
        "trajectory.csv",
        "estimates.jsonl",
        "topview.png",
    ] {
        assert!(out.join(file).is_file(), "{file} missing");
    }
}
