//! Errors printed once: an error met deep in the robot's software while a scenario runs reaches
//! the command line with each of its causes named once, not once per layer it passed through.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

/// A scenario the check accepts whose robot's software cannot be built: its planner's grid of
/// 5 mm cells over a 12 x 8 m field has more cells than the planner allows (found when the
/// controller is built, at the start of the run).
const TOO_FINE_A_GRID: &str = r#"
[run]
duration_s = 1.0

[world.field]
half_length_mm = 6000.0
half_width_mm = 4000.0

[robot]
start = { x_mm = 0.0, y_mm = 0.0 }

[[robot.sensors]]
name = "omni"
width_px = 256
height_px = 220
[robot.sensors.hyperbolic]
a_mm = 12.129
b_mm = 15.650
c_mm = 19.8
focal_px = 479.37
focus_height_mm = 205.08
rim_radius_mm = 30.0

[goal]
x_mm = 500.0
y_mm = 0.0

[control]
kind = "velocity_aware"

[control.planner]
kind = "grid"
cell_mm = 5.0
"#;

#[test]
fn an_error_of_the_robots_software_is_printed_with_each_cause_once() {
    let dir = common::tmp("errors_printed_once");
    let file = dir.join("too_fine.toml");
    std::fs::write(&file, TOO_FINE_A_GRID).unwrap();
    common::omniloop(["check".as_ref(), file.as_os_str()]);

    let out = common::bin()
        .args(["run", "--quiet", "--renderer", "cpu", "--out"])
        .arg(dir.join("out"))
        .arg(&file)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "the run should fail: {stderr}");
    let error: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(error.len(), 1, "one error line: {stderr}");
    let error = error[0];
    // The command's context, then the robot's own words: each once.
    for cause in [
        format!("running {}", file.display()),
        "control.planner.cell_mm".to_string(),
        "cells, more than".to_string(),
    ] {
        assert_eq!(error.matches(&cause).count(), 1, "{cause:?} in {error}");
    }
    // And no part of the chain repeats the one before it.
    let parts: Vec<&str> = error.trim_start_matches("error: ").split(": ").collect();
    for w in parts.windows(2) {
        assert_ne!(w[0], w[1], "{error}");
    }
}
