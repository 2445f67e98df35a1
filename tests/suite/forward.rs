//! E6 end to end: a small differential-drive robot with a forward camera (Ahmed, Saatchi and
//! Caparrelli): both avoidance methods among eight obstacles for a minute, the scan line's turns
//! on the square of Fig. 8, the legs of Fig. 10 by Lucas-Kanade and by cross-correlation;
//! scenario errors.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{omniloop, tmp};
use serde_json::Value;

fn pairs(m: &Value, key: &str) -> Vec<(f64, f64)> {
    m[key]
        .as_array()
        .unwrap_or_else(|| panic!("{key} in {m}"))
        .iter()
        .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect()
}

#[test]
fn e6_replay_reads_turns_within_a_degree_legs_within_5_percent_and_avoids_by_segmentation() {
    let dir = tmp("e6_replay");
    let out = dir.display().to_string();
    let md = omniloop([
        "replay",
        "forward",
        "--renderer",
        "cpu",
        "--out",
        out.as_str(),
    ]);
    eprintln!("{md}");
    let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    let m: Value = serde_json::from_str(&text).unwrap();

    let turns = pairs(&m, "square_turns_deg");
    assert_eq!(turns.len(), 4, "{m}");
    for (read, truth) in &turns {
        assert!(
            (truth - 90.0).abs() < 3.0,
            "the robot turned {truth} degrees"
        );
        assert!(
            (read - truth).abs() <= 1.0,
            "turn read {read}, true {truth}"
        );
    }
    for (key, bound) in [("lk_legs_in", 0.05), ("ncc_legs_in", 0.05)] {
        let legs = pairs(&m, key);
        assert_eq!(legs.len(), 4, "{key}: {m}");
        for (read, truth) in &legs {
            assert!(*truth > 9.0, "{key}: true leg {truth} in");
            assert!(
                (read - truth).abs() <= bound * truth,
                "{key}: read {read} in, true {truth} in"
            );
        }
    }

    let avoidance = m["avoidance"].as_array().unwrap();
    assert_eq!(avoidance.len(), 2);
    let seg = &avoidance[0];
    assert_eq!(seg["method"], "segmentation");
    assert_eq!(seg["contacts"], 0, "{seg}");
    // It wandered, not stood: at least 3 m in the minute.
    assert!(seg["distance_mm"].as_f64().unwrap() > 3000.0, "{seg}");
    let flow = &avoidance[1];
    assert_eq!(flow["method"], "optical_flow");
    // The paper shows it noisier: its contacts are reported, not bounded; it must not stall.
    assert!(flow["contacts"].as_u64().is_some(), "{flow}");
    assert!(flow["distance_mm"].as_f64().unwrap() > 3000.0, "{flow}");
    for a in avoidance {
        assert!(a["fps"].as_f64().unwrap() > 0.0, "{a}");
    }
    for f in [
        "forward.md",
        "forward.png",
        "square/trajectory.csv",
        "segmentation/summary.json",
    ] {
        assert!(dir.join(f).is_file(), "{f}");
    }
}

/// `omniloop check` on `forward_obstacles.toml` with `from` replaced by `to`: status, stderr.
fn check_variant(name: &str, from: &str, to: &str) -> (Option<i32>, String) {
    common::check_variant("forward_obstacles.toml", name, from, to)
}

#[test]
fn e6_scenario_errors_name_the_field() {
    let (code, err) = check_variant(
        "e6_omni",
        "[robot.differential]",
        "[robot.differential_not]",
    );
    assert_eq!(code, Some(2), "{err}");
    let (code, err) = check_variant(
        "e6_no_diff",
        "[robot.differential]\ntrack_mm = 100.0\nmax_turn_rate_deg_s = 90.0\n",
        "",
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("robot.differential"), "{err}");
    let (code, err) = check_variant("e6_track", "track_mm = 100.0", "track_mm = -1.0");
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("robot.differential.track_mm"), "{err}");
    let (code, err) = check_variant("e6_kind", "kind = \"segmentation\"", "kind = \"idle\"");
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("control.kind"), "{err}");
}
