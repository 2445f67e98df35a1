//! End-to-end checks of the foundation: scenario files, the loop, determinism, the drive limit
//! and contacts.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{bin, omniloop, scenario, scenario_path, tmp};
use omniloop::run::record::write_trajectory_csv;
use omniloop::{LoadError, load_scenario, parse_scenario, run_scenario};
use std::path::{Path, PathBuf};

fn scenarios_dir() -> PathBuf {
    scenario_path("")
}

#[test]
fn every_scenario_file_passes_check() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(scenarios_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(!files.is_empty());
    for f in &files {
        if let Err(e) = load_scenario(f) {
            panic!("{} does not load:\n{e}", f.display());
        }
    }
    let mut args = vec![std::ffi::OsString::from("check")];
    args.extend(files.iter().map(|f| f.as_os_str().to_owned()));
    omniloop(args);
}

#[test]
fn the_printed_default_scenario_is_valid_and_complete() {
    let text = omniloop(["run", "--print-default"]);
    let s = parse_scenario(&text, Path::new("default.toml"), "default").unwrap();
    // Every key the schema serialises appears in the printed example.
    let full = toml::Value::try_from(&s).unwrap();
    let printed: toml::Value = toml::from_str(&text).unwrap();
    fn check(full: &toml::Value, printed: &toml::Value, path: &str) {
        if let (Some(f), Some(p)) = (full.as_table(), printed.as_table()) {
            for (k, v) in f {
                let here = format!("{path}.{k}");
                let Some(pv) = p.get(k) else {
                    panic!("the printed default lacks `{here}`");
                };
                check(v, pv, &here);
            }
        }
        if let (Some(f), Some(p)) = (full.as_array(), printed.as_array()) {
            for (a, b) in f.iter().zip(p) {
                check(a, b, path);
            }
        }
    }
    check(&full, &printed, "");
}

fn broken(name: &str, text: &str) -> (i32, String) {
    let dir = tmp(&format!("broken_{name}"));
    let f = dir.join(format!("{name}.toml"));
    std::fs::write(&f, text).unwrap();
    let out = bin().arg("check").arg(&f).output().unwrap();
    (
        out.status.code().unwrap(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

const BASE: &str = "[world.field]\n\n[robot]\nstart = { x_mm = 0.0, y_mm = 0.0 }\n\n[goal]\nx_mm = 500.0\ny_mm = 0.0\n";

#[test]
fn broken_scenarios_exit_2_with_file_line_column_and_field() {
    let cases = [
        (
            "unknown_key",
            BASE.replace("[goal]\n", "[goal]\nspeed_mm_s = 3.0\n"),
            ":7:1: field `goal.speed_mm_s`: unknown field",
        ),
        (
            "wrong_type",
            BASE.replace("x_mm = 500.0", "x_mm = \"far\""),
            ":7:8: field `goal.x_mm`: invalid type",
        ),
        (
            "negative_radius",
            BASE.replace("[goal]", "radius_mm = -90.0\n\n[goal]"),
            ":6:1: field `robot.radius_mm`: must be a finite number > 0",
        ),
        (
            "start_outside_floor",
            BASE.replace("x_mm = 0.0, y_mm = 0.0", "x_mm = 0.0, y_mm = 2000.0"),
            ":4:11: field `robot.start.x_mm`: start (0, 2000) mm is outside the floor region",
        ),
        (
            "map_spacing",
            format!(
                "{BASE}\n[control]\npose_source = \"localization\"\n\n\
                 [experiment.localization_map]\nspacing_mm = 5.0\n"
            ),
            ":14:1: field `experiment.localization_map.spacing_mm`: must be a finite number >= 20",
        ),
        // Controllers, pose sources and their tables are registered: names are looked up, and
        // each table is parsed and checked by its owner, naming the field.
        (
            "unknown_controller",
            format!("{BASE}\n[control]\nkind = \"velocity_awre\"\n"),
            ":11:1: field `control.kind`: no controller \"velocity_awre\" (there are: idle, \
             goal_direction, velocity_aware,",
        ),
        (
            "truth_is_a_pilot",
            format!("{BASE}\n[control]\nkind = \"go_to_goal_truth\"\n"),
            ":11:1: field `control.kind`: \"go_to_goal_truth\" is the simulator's pilot",
        ),
        (
            "unknown_pose_source",
            format!("{BASE}\n[control]\npose_source = \"gps\"\n"),
            ":11:1: field `control.pose_source`: no pose source \"gps\" (there are: odometry,",
        ),
        (
            "avoidance_margin",
            format!(
                "{BASE}\n[control]\nkind = \"velocity_aware\"\n[control.avoidance]\nmargin_mm = -5.0\n"
            ),
            ":13:1: field `control.avoidance.margin_mm`: must be >= 0 (got -5)",
        ),
        (
            "wander_type",
            format!("{BASE}\n[control.wander]\nclearance_mm = \"wide\"\n"),
            ":11:1: field `control.wander.clearance_mm`: invalid type: string \"wide\"",
        ),
        (
            "wall_follow_side",
            format!(
                "{BASE}\n[control]\nkind = \"wall_follow\"\n[control.wall_follow]\nside = \"up\"\n"
            ),
            ":13:1: field `control.wall_follow.side`: unknown variant `up`, expected `left` or \
             `right`",
        ),
        (
            "script_unknown_key",
            format!("{BASE}\n[control.script]\nspeed = 3.0\n"),
            ":11:1: field `control.script.speed`: unknown field `speed`",
        ),
        // A sensor's optics are one typed value, checked once where the file is parsed, and each
        // mirror checks its own numbers.
        (
            "two_optics",
            format!(
                "{BASE}\n[[robot.sensors]]\nname = \"omni\"\n[robot.sensors.pinhole]\n\
                 focal_px = 100.0\nheight_mm = 150.0\n[robot.sensors.spherical]\nradius_mm = 30.0\n\
                 camera_distance_mm = 200.0\nfocal_px = 400.0\nlens_height_mm = 300.0\n"
            ),
            ":10:1: field `robot.sensors[0]`: sensor \"omni\": a sensor needs exactly one of the \
             tables hyperbolic, conical, spherical, pinhole, calibrated (found spherical, pinhole)",
        ),
        (
            "no_optics",
            format!("{BASE}\n[[robot.sensors]]\nname = \"omni\"\n"),
            ":10:1: field `robot.sensors[0]`: sensor \"omni\": a sensor needs exactly one of the \
             tables hyperbolic, conical, spherical, pinhole, calibrated (found none)",
        ),
        (
            "hyperbola_c",
            format!(
                "{BASE}\n[[robot.sensors]]\nname = \"omni\"\n[robot.sensors.hyperbolic]\n\
                 a_mm = 12.129\nb_mm = 15.65\nc_mm = 25.0\nfocal_px = 479.37\n\
                 focus_height_mm = 205.08\nrim_radius_mm = 30.0\n"
            ),
            ":15:1: field `robot.sensors[0].hyperbolic.c_mm`: must equal sqrt(a^2 + b^2)",
        ),
        // So are the perception stages' `[vision.*]` tables, written or not for a stage that
        // runs.
        (
            "unknown_vision_table",
            format!("{BASE}\n[vision.freespce]\ndirections = 8\n"),
            ":10:9: field `vision.freespce`: unknown field `freespce`, expected one of sensor, \
             calibration_file, omnistereo, resection, forward, freespace, localization, \
             luminance_heading, ball, goal",
        ),
        (
            "vision_value",
            format!("{BASE}\n[vision.freespace]\ndirections = 2\n"),
            ":11:1: field `vision.freespace.directions`: must be >= 4 (got 2)",
        ),
        (
            "vision_unknown_key",
            format!("{BASE}\n[vision.localization]\nmethd = \"robust\"\n"),
            ":11:1: field `vision.localization.methd`: unknown field `methd`",
        ),
        (
            "unknown_control_table",
            format!("{BASE}\n[control.avodance]\nmargin_mm = 1.0\n"),
            ":10:10: field `control.avodance`: unknown field `avodance`, expected one of kind, \
             pose_source, localization_gain, avoidance, planner, wander, forward, script, wall_follow, striker, \
             resection",
        ),
    ];
    for (name, text, expected) in cases {
        let (code, err) = broken(name, &text);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(
            err.contains(&format!("{name}.toml{expected}")),
            "{name}: {err}"
        );
    }
}

#[test]
fn smoke_reaches_its_goal_without_contact_and_within_the_acceleration_limit() {
    let s = scenario("smoke.toml");
    let out = run_scenario(&s, &Default::default(), |_| {}, |_, _| {}).unwrap();
    let m = &out.summary;
    assert!(m.reached_goal, "{m:?}");
    assert_eq!(m.wall_contacts, 0);
    assert!(
        m.peak_accel_mm_s2 <= s.robot.accel_limit_mm_s2 * 1.01,
        "{m:?}"
    );
    assert!(m.peak_speed_mm_s <= s.robot.max_speed_mm_s * 1.01, "{m:?}");
    assert!(m.min_clearance_mm > 0.0);
    // Accelerations between control cycles, from the recorded velocities, obey the limit too.
    for w in out.trajectory.windows(2) {
        let dt = w[1].t_s - w[0].t_s;
        let a = ((w[1].vx_mm_s - w[0].vx_mm_s).powi(2) + (w[1].vy_mm_s - w[0].vy_mm_s).powi(2))
            .sqrt()
            / dt;
        assert!(
            a <= s.robot.accel_limit_mm_s2 * 1.01,
            "{a} at t = {}",
            w[0].t_s
        );
    }
}

#[test]
fn same_scenario_and_seed_give_byte_identical_trajectories() {
    let f = scenarios_dir().join("smoke.toml");
    let mut files = Vec::new();
    for k in 0..2 {
        let dir = tmp(&format!("determinism_{k}"));
        omniloop([
            "run".as_ref(),
            "--quiet".as_ref(),
            "--seed".as_ref(),
            "11".as_ref(),
            "--out".as_ref(),
            dir.as_os_str(),
            f.as_os_str(),
        ]);
        files.push(std::fs::read(dir.join("trajectory.csv")).unwrap());
        let summary: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap();
        assert_eq!(summary["seed"], 11);
        assert!(dir.join("topview.png").exists());
        // One line of estimates a control cycle, the truth beside what the robot believed.
        let cycles = summary["cycles"].as_u64().unwrap() as usize;
        let text = std::fs::read_to_string(dir.join("estimates.jsonl")).unwrap();
        assert_eq!(text.lines().count(), cycles);
        for line in text.lines() {
            let v: serde_json::Value = serde_json::from_str(line).unwrap();
            assert!(v["truth"]["x_mm"].is_number(), "{line}");
            assert!(v["estimate"]["x_mm"].is_number(), "{line}");
        }
    }
    assert!(files[0].len() > 1000);
    assert_eq!(files[0], files[1]);
}

#[test]
fn a_robot_commanded_into_a_wall_at_2000_mm_s_stays_outside_and_the_contact_is_counted() {
    let text = "[run]\nduration_s = 3.0\npilot = \"truth\"\n\n[world]\n[[world.walls]]\nfrom_mm = [600.0, -500.0]\nto_mm = [600.0, 500.0]\n\n[robot]\nstart = { x_mm = 0.0, y_mm = 0.0 }\nmax_speed_mm_s = 2000.0\naccel_limit_mm_s2 = 20000.0\n\n[goal]\nx_mm = 900.0\ny_mm = 0.0\n";
    let s = match parse_scenario(text, Path::new("wall.toml"), "wall") {
        Ok(s) => s,
        Err(LoadError::Invalid { problems }) => panic!("{problems:?}"),
        Err(e) => panic!("{e}"),
    };
    let out = run_scenario(&s, &Default::default(), |_| {}, |_, _| {}).unwrap();
    let m = &out.summary;
    assert!(!m.reached_goal);
    assert!(m.peak_speed_mm_s >= 1999.0, "{m:?}");
    assert_eq!(m.wall_contacts, 1, "{m:?}");
    let by_class: Vec<(&str, u32)> = m
        .contacts_by_class
        .iter()
        .map(|(k, v)| (k.as_str(), *v))
        .collect();
    assert_eq!(by_class, [("wall", 1)], "{m:?}");
    // Wall face at x = 550: the centre never gets past 550 - 90 = 460 (1 mm tolerance).
    let max_x = out
        .trajectory
        .iter()
        .map(|r| r.x_mm)
        .fold(f64::MIN, f64::max);
    assert!(max_x <= 461.0, "max x {max_x}");
    assert!(m.min_clearance_mm >= -1.0, "{m:?}");
    let mut csv = Vec::new();
    write_trajectory_csv(&out.trajectory, &mut csv).unwrap();
    assert!(
        String::from_utf8(csv)
            .unwrap()
            .starts_with("t_s,x_mm,y_mm,theta_rad")
    );
}

#[test]
fn a_scenario_that_names_no_controller_stands_still() {
    // Ground truth is never the default: without `control.kind` the robot is idle.
    let s = parse_scenario(BASE, Path::new("idle.toml"), "idle").unwrap();
    let out = run_scenario(&s, &Default::default(), |_| {}, |_, _| {}).unwrap();
    let m = &out.summary;
    assert_eq!(m.controller, "idle");
    assert_eq!(m.path_length_mm, 0.0);
    assert!(!m.reached_goal);
    assert_eq!(m.cycles, s.max_cycles());
}

#[test]
fn replay_lists_its_experiments_and_refuses_unknown_ones() {
    let text = omniloop(["replay", "--list"]);
    for name in ["corner55", "selfloc"] {
        assert!(text.contains(name), "{text}");
    }
    let out = bin().args(["replay", "corner56"]).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("unknown experiment \"corner56\"") && err.contains("corner55"),
        "{err}"
    );
}
