//! Teams on one floor end to end: a team of one runs as the one-robot form, bit for bit; a
//! team's run is the same whatever the number of threads; six robots swap through the centre
//! on their own cameras without touching, recorded per robot (files, MCAP channels, top view);
//! a user's software on one robot by name; bad team input located by file, line, column and
//! field.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{bin, cpu, omniloop, scenario, scenario_path, tmp};
use omniloop::robot::{BodyCommand, Estimates, Observation, OdometryReading, Outputs};
use omniloop::robot::{RobotError, RobotSoftware};
use omniloop::run::record::write_team_trajectory_csv;
use omniloop::run::{RunOutput, TrajectoryRow};
use omniloop::{Runner, parse_scenario};
use std::path::Path;

/// `file` of `scenarios/` with `from` replaced by `to` (each must be there), parsed.
fn variant(file: &str, edits: &[(&str, &str)]) -> omniloop::Scenario {
    let mut text = std::fs::read_to_string(scenario_path(file)).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "{file}: {from}");
        text = text.replacen(from, to, 1);
    }
    parse_scenario(&text, &scenario_path(file), "variant").unwrap_or_else(|e| panic!("{e}"))
}

/// A team's trajectories as `trajectory.csv` writes them.
fn team_csv(out: &RunOutput) -> Vec<u8> {
    let rows: Vec<(&str, &[TrajectoryRow])> = out
        .robots
        .iter()
        .map(|r| (r.name.as_str(), r.trajectory.as_slice()))
        .collect();
    let mut csv = Vec::new();
    write_team_trajectory_csv(&rows, &mut csv).unwrap();
    csv
}

#[test]
fn a_team_of_one_is_the_one_robot_run_bit_for_bit() {
    // The field route with localization in the loop, shortened; as a team, the same robot
    // named in a [[robots]] entry that writes nothing over the shared tables.
    let short = ("duration_s = 40.0", "duration_s = 3.0");
    let one = variant("field_waypoints.toml", &[short]);
    let team = variant(
        "field_waypoints.toml",
        &[
            short,
            ("[robot]\n", "[[robots]]\nname = \"solo\"\n\n[robot]\n"),
        ],
    );
    assert!(team.is_team() && !one.is_team());
    let a = Runner::new(&one).options(cpu()).run().unwrap();
    let b = Runner::new(&team).options(cpu()).run().unwrap();
    assert_eq!(b.robots.len(), 1);
    assert!(!a.trajectory.is_empty());
    assert_eq!(a.trajectory, b.robots[0].trajectory);
    assert_eq!(a.summary.wall_contacts, b.summary.wall_contacts);
}

#[test]
fn a_team_runs_the_same_whatever_the_number_of_threads() {
    let s = variant(
        "swarm_swap.toml",
        &[("duration_s = 40.0", "duration_s = 2.0")],
    );
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| Runner::new(&s).options(cpu()).run().unwrap())
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one.robots.len(), 6);
    assert_eq!(one.summary.cycles, 50);
    assert_eq!(team_csv(&one), team_csv(&two));
    assert_eq!(one.summary.team, two.summary.team);
}

#[test]
fn six_robots_swap_through_the_centre_on_their_own_cameras_without_touching() {
    let dir = tmp("team_swarm_swap");
    let out = dir.display().to_string();
    let file = scenario_path("swarm_swap.toml").display().to_string();
    let line = omniloop([
        "run",
        &file,
        "--renderer",
        "cpu",
        "--out",
        &out,
        "-q",
        "--mcap",
    ]);
    assert!(line.contains("6 of 6 arrived"), "{line}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let team = &summary["team"];
    eprintln!("{team}");
    assert_eq!(team["arrived"], 6);
    assert_eq!(summary["wall_contacts"], 0);
    assert_eq!(team["robot_contacts"], 0);
    assert!(team["min_robot_clearance_mm"].as_f64().unwrap() > 0.0);
    let rows = summary["robots"].as_array().unwrap();
    assert_eq!(rows.len(), 6);
    assert!(
        rows.iter()
            .all(|r| r["reached_goal"] == true && r["contacts"] == 0)
    );
    // Each robot's records, and all of them in one CSV with the robot's name first.
    for k in 1..=6 {
        let own = dir.join("robots").join(format!("r{k}"));
        assert!(own.join("estimates.jsonl").is_file());
        let csv = std::fs::read_to_string(own.join("trajectory.csv")).unwrap();
        assert!(csv.starts_with("t_s,x_mm,"));
    }
    let all = std::fs::read_to_string(dir.join("trajectory.csv")).unwrap();
    assert!(all.starts_with("robot,t_s,x_mm,"));
    assert_eq!(
        all.lines().filter(|l| l.starts_with("r4,")).count(),
        std::fs::read_to_string(dir.join("robots/r4/trajectory.csv"))
            .unwrap()
            .lines()
            .count()
            - 1
    );
    assert!(dir.join("topview.png").is_file());
    // A camera channel and a frame tree per robot.
    let bytes = std::fs::read(dir.join("run.mcap")).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let topics: Vec<String> = summary.channels.values().map(|c| c.topic.clone()).collect();
    for k in 1..=6 {
        for t in ["camera/omni", "truth/pose", "truth/tf", "estimate/pose"] {
            let topic = format!("/r{k}/{t}");
            assert!(topics.contains(&topic), "{topic} in {topics:?}");
        }
    }
}

/// Runs a shipped team scenario on the CPU with its seed: the summary.
fn team_run(file: &str) -> omniloop::run::Summary {
    let out = Runner::new(&scenario(file)).options(cpu()).run().unwrap();
    eprintln!("{file}: {:?}", out.summary.team);
    out.summary
}

#[test]
fn two_robots_meeting_head_on_in_a_700_mm_corridor_pass_without_touching() {
    let m = team_run("corridor_passing.toml");
    let team = m.team.unwrap();
    assert_eq!((team.arrived, team.with_goal), (2, 2));
    assert_eq!(m.wall_contacts, 0);
    assert!(team.min_robot_clearance_mm > 0.0);
}

#[test]
fn two_teams_of_six_swap_halves_of_the_field_localizing_on_their_own_cameras() {
    let m = team_run("ssl_teams.toml");
    let team = m.team.unwrap();
    assert_eq!((team.arrived, team.with_goal), (12, 12));
    assert_eq!(m.wall_contacts, 0);
    assert!(team.min_robot_clearance_mm > 0.0);
    // Localization in the loop: every robot used fixes, and its estimate stayed near the truth.
    for r in m.robots.unwrap() {
        assert!(r.localization_fixes.unwrap_or(0) > 0, "{}", r.name);
        assert!(
            r.pose_error_mm.unwrap() < 30.0,
            "{}: {:?}",
            r.name,
            r.pose_error_mm
        );
    }
}

/// Drives straight ahead at 300 mm/s and reads no camera.
struct Straight;

impl RobotSoftware for Straight {
    fn name(&self) -> String {
        "straight".into()
    }
    fn cameras(&self) -> Vec<String> {
        Vec::new()
    }
    fn cycle(&mut self, obs: &Observation<'_>) -> Result<Outputs, RobotError> {
        Ok(Outputs::drive(
            BodyCommand::forward(300.0),
            Estimates {
                t_s: obs.t_s,
                ..Estimates::default()
            },
        ))
    }
    fn odometry(&mut self, _reading: &OdometryReading) {}
}

#[test]
fn a_users_software_runs_on_the_robot_it_names_and_the_others_keep_theirs() {
    let s = variant(
        "swarm_swap.toml",
        &[("duration_s = 40.0", "duration_s = 1.0")],
    );
    let out = Runner::new(&s)
        .options(cpu())
        .software_for("r4", |_config| Ok(Straight))
        .run()
        .unwrap();
    let controllers: Vec<&str> = out
        .summary
        .robots
        .as_ref()
        .unwrap()
        .iter()
        .map(|r| r.controller.as_str())
        .collect();
    assert_eq!(controllers[3], "straight");
    assert!(
        controllers
            .iter()
            .enumerate()
            .all(|(k, c)| k == 3 || *c == "velocity_aware")
    );
    // r4 starts at (-1200, 0) facing +x: straight ahead along y = 0.
    let end = out.robots[3].trajectory.last().unwrap();
    assert!(
        end.x_mm > -1200.0 + 150.0 && end.y_mm.abs() < 1e-6,
        "{end:?}"
    );
    let err = Runner::new(&s)
        .options(cpu())
        .software_for("r9", |_config| Ok(Straight))
        .run()
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("no robot of that name") && err.contains("r1, r2"),
        "{err}"
    );
}

/// `omniloop check` on `text` written as `name.toml`: exit code and standard error.
fn check(name: &str, text: &str) -> (i32, String) {
    let dir = tmp(&format!("team_check_{name}"));
    let f = dir.join(format!("{name}.toml"));
    std::fs::write(&f, text).unwrap();
    let out = bin().arg("check").arg(&f).output().unwrap();
    (
        out.status.code().unwrap(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

const TEAM: &str = "[world.field]\n\n\
[[robots]]\nname = \"a\"\nstart = { x_mm = -600.0, y_mm = 0.0 }\ngoal = { x_mm = 600.0, y_mm = 0.0 }\n\n\
[[robots]]\nname = \"b\"\nstart = { x_mm = 600.0, y_mm = 0.0 }\ngoal = { x_mm = -600.0, y_mm = 0.0 }\n";

#[test]
fn bad_team_input_exits_2_with_file_line_column_and_field() {
    let (code, err) = check("good", TEAM);
    assert_eq!(code, 0, "{err}");
    let cases = [
        (
            "one_name_twice",
            TEAM.replace("name = \"b\"", "name = \"a\""),
            ":9:1: field `robots[1].name`: robot name \"a\" is used twice",
        ),
        (
            "overlapping",
            TEAM.replace("x_mm = 600.0, y_mm = 0.0 }\ngoal = { x_mm = -600.0", "x_mm = -500.0, y_mm = 50.0 }\ngoal = { x_mm = -600.0"),
            ":10:1: field `robots[1].start`: robot \"b\" starts overlapping a",
        ),
        (
            "in_a_wall",
            TEAM.replace("x_mm = 600.0, y_mm = 0.0 }\ngoal = { x_mm = -600.0", "x_mm = 600.0, y_mm = 720.0 }\ngoal = { x_mm = -600.0"),
            "field `robots[1].start",
        ),
        (
            "bad_controller",
            TEAM.replace(
                "goal = { x_mm = -600.0, y_mm = 0.0 }\n",
                "goal = { x_mm = -600.0, y_mm = 0.0 }\n[robots.control]\nkind = \"velocity_awre\"\n",
            ),
            ":13:1: field `robots[1].control.kind`: no controller \"velocity_awre\"",
        ),
        (
            "shared_controller",
            TEAM.replacen("\n\n[[robots]]", "\n\n[control]\nkind = \"velocity_awre\"\n\n[[robots]]", 1),
            ":4:1: field `control.kind`: no controller \"velocity_awre\"",
        ),
        (
            "unknown_key",
            TEAM.replace("name = \"b\"\n", "name = \"b\"\nspeed_mm_s = 3.0\n"),
            "field `robots[1].speed_mm_s`: unknown field `speed_mm_s`",
        ),
        (
            "wrong_type",
            TEAM.replace("name = \"b\"\n", "name = \"b\"\nmax_speed_mm_s = \"fast\"\n"),
            "field `robots[1].max_speed_mm_s`: invalid type",
        ),
        (
            "no_name",
            TEAM.replace("name = \"b\"\n", ""),
            "field `robots[1].name`: missing",
        ),
        (
            "no_start",
            TEAM.replace("start = { x_mm = 600.0, y_mm = 0.0 }\n", ""),
            "field `robots[1].start`: missing",
        ),
        (
            "experiment",
            format!("{TEAM}\n[experiment.places]\nplaces = []\n"),
            "field `experiment`: a team ([[robots]]) runs no experiment",
        ),
    ];
    for (name, text, want) in cases {
        let (code, err) = check(name, &text);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(err.contains(&format!("{name}.toml")), "{name}: {err}");
        assert!(err.contains(want), "{name}: expected {want:?} in\n{err}");
    }
}

#[test]
fn the_shipped_team_scenarios_check() {
    for file in [
        "swarm_swap.toml",
        "corridor_passing.toml",
        "ssl_teams.toml",
        "forward_swarm.toml",
    ] {
        let s = scenario(file);
        assert!(s.is_team(), "{file}");
        let path = scenario_path(file);
        assert!(Path::new(&path).is_file());
    }
}

#[test]
fn a_teams_frames_traced_in_one_gpu_batch_match_the_cpus() {
    let Some(_gpu) = common::gpu_or_skip() else {
        return;
    };
    let s = variant(
        "swarm_swap.toml",
        &[("duration_s = 40.0", "duration_s = 1.0")],
    );
    let frames = |renderer| {
        let options = omniloop::run::RunOptions {
            renderer,
            ..omniloop::run::RunOptions::default()
        };
        let mut sim = omniloop::Simulation::new(&s, &options, |_| {}).unwrap();
        sim.sense().unwrap();
        let names: Vec<String> = sim
            .robots()
            .iter()
            .map(|a| a.renderer_name().unwrap_or_default().to_string())
            .collect();
        let images: Vec<image::RgbaImage> = sim
            .robots()
            .iter()
            .map(|a| a.frames()[0].image.clone())
            .collect();
        (names, images)
    };
    let (gpu_names, gpu) = frames(omniloop_sim::RendererChoice::Gpu);
    let (_, cpu) = frames(omniloop_sim::RendererChoice::Cpu);
    assert!(
        gpu_names.iter().all(|n| n.contains("batched")),
        "{gpu_names:?}"
    );
    for (k, (g, c)) in gpu.iter().zip(&cpu).enumerate() {
        common::assert_alike(g, c, 2, &format!("robot r{} GPU against CPU", k + 1));
    }
}

#[test]
fn a_sweep_of_a_team_reports_the_teams_figures_as_columns() {
    let dir = tmp("team_sweep");
    let file = dir.join("short.toml");
    let text = std::fs::read_to_string(scenario_path("swarm_swap.toml")).unwrap();
    std::fs::write(&file, text.replace("duration_s = 40.0", "duration_s = 1.0")).unwrap();
    let out = dir.join("sweep");
    omniloop([
        "sweep",
        file.to_str().unwrap(),
        "--set",
        "robot.max_speed_mm_s=400,600",
        "--renderer",
        "cpu",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let head: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    for column in [
        "team.arrived",
        "team.robot_contacts",
        "team.min_robot_clearance_mm",
    ] {
        assert!(head.contains(&column), "{column} in {head:?}");
    }
    // One second is too short to arrive: no run is a success, each has its six robots.
    let arrived = head.iter().position(|c| *c == "team.arrived").unwrap();
    let success = head.iter().position(|c| *c == "success").unwrap();
    for line in csv.lines().skip(1) {
        let cells = csv_fields(line);
        assert_eq!(cells[arrived], "0", "{line}");
        assert_eq!(cells[success], "false", "{line}");
    }
}

/// The fields of a CSV line whose quoted fields may hold commas.
fn csv_fields(line: &str) -> Vec<String> {
    let (mut out, mut cur, mut quoted) = (Vec::new(), String::new(), false);
    for c in line.chars() {
        match (c, quoted) {
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}
