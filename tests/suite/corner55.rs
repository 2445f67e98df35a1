//! E1 end to end: the 55-degree corner with both controllers, on vision alone.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{cpu, omniloop, scenario, tmp};
use omniloop::Summary;
use omniloop::experiments::Metrics;
use omniloop::experiments::corner::CornerMetrics;
use omniloop::run_scenario;
use std::path::Path;

fn run(file: &str) -> Summary {
    run_scenario(&scenario(file), &cpu(), |_| {}, |_, _| {})
        .unwrap()
        .summary
}

#[test]
fn both_controllers_turn_the_corner_and_the_velocity_aware_one_turns_earlier_and_tighter() {
    let gd = run("corner55_goal_direction.toml");
    let va = run("corner55_velocity_aware.toml");
    for m in [&gd, &va] {
        assert!(m.reached_goal, "{m:?}");
        assert_eq!(m.wall_contacts, 0, "{m:?}");
        assert!(m.peak_accel_mm_s2 <= 303.0, "{m:?}");
        assert!(m.min_clearance_mm > 0.0, "{m:?}");
        assert_eq!(
            m.renderer.as_deref().map(|r| r.starts_with("cpu")),
            Some(true)
        );
        // Free space on the rendered frames against the ray-cast truth, along the whole run.
        let e = m.freespace_error_mm.unwrap();
        assert!(e < 40.0, "median free-space error {e} mm");
    }
    let onset = |m: &Summary| CornerMetrics::of(m).unwrap().turn_onset_mm.unwrap();
    let (gd_onset, va_onset) = (onset(&gd), onset(&va));
    assert!(va_onset > gd_onset, "turn onset {va_onset} vs {gd_onset}");
    let over = |m: &Summary| CornerMetrics::of(m).unwrap().overshoot_mm.unwrap();
    let (gd_over, va_over) = (over(&gd), over(&va));
    assert!(va_over < gd_over, "overshoot {va_over} vs {gd_over}");
}

fn replay(dir: &Path) {
    let text = omniloop([
        "replay".as_ref(),
        "corner55".as_ref(),
        "--renderer".as_ref(),
        "cpu".as_ref(),
        "--quiet".as_ref(),
        "--out".as_ref(),
        dir.as_os_str(),
    ]);
    assert!(text.contains("velocity-aware turns earlier: yes"), "{text}");
}

/// The summary without the wall-clock fields.
fn deterministic_part(path: &Path) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    let m = v.as_object_mut().unwrap();
    m.remove("wall_time_s");
    m.remove("cycles_per_s");
    v
}

#[test]
fn the_replay_run_twice_on_the_cpu_gives_identical_results() {
    let dirs = [tmp("corner55_a"), tmp("corner55_b")];
    for d in &dirs {
        replay(d);
        for f in ["comparison.png", "comparison.md"] {
            assert!(d.join(f).exists(), "{f}");
        }
    }
    for name in ["goal_direction", "velocity_aware"] {
        let a = deterministic_part(&dirs[0].join(name).join("summary.json"));
        let b = deterministic_part(&dirs[1].join(name).join("summary.json"));
        assert_eq!(a, b, "{name}");
        for key in ["turn_onset_mm", "overshoot_mm", "freespace_error_mm"] {
            assert!(a[key].is_number(), "{name}: {key} missing");
        }
        let ta = std::fs::read(dirs[0].join(name).join("trajectory.csv")).unwrap();
        let tb = std::fs::read(dirs[1].join(name).join("trajectory.csv")).unwrap();
        assert_eq!(ta, tb, "{name}");
    }
}
