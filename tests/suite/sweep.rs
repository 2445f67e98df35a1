//! `omniloop sweep` end to end: a small sweep's rows equal the runs made one by one, bit for bit
//! in their trajectories and whatever `--jobs` is; a bad `--set` stops it before anything runs.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{bin, omniloop, scenario_path, tmp};
use std::collections::BTreeMap;
use std::path::Path;

/// Columns that depend on the machine's load or on the threads, not on the run.
const TIMING: [&str; 3] = ["wall_time_s", "cycles_per_s", "renderer"];

/// The fields of one CSV line (quoted fields may hold commas).
fn fields(line: &str) -> Vec<String> {
    let (mut out, mut cur, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}

/// `sweep.csv` as rows of column -> value, the timing columns left out.
fn table(dir: &Path) -> Vec<BTreeMap<String, String>> {
    let text = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    let mut lines = text.lines();
    let head = fields(lines.next().unwrap());
    lines
        .map(|l| {
            let cells = fields(l);
            assert_eq!(cells.len(), head.len(), "{l}");
            head.iter()
                .zip(cells)
                .filter(|(h, _)| !TIMING.contains(&h.as_str()))
                .map(|(h, c)| (h.clone(), c))
                .collect()
        })
        .collect()
}

/// The small sweep's arguments after `sweep` (the scenario, the set, the seeds).
fn small_sweep_args() -> Vec<String> {
    [
        scenario_path("corner55_velocity_aware.toml")
            .to_str()
            .unwrap(),
        "--set",
        "robot.max_speed_mm_s=300,400",
        "--seeds",
        "2",
    ]
    .map(String::from)
    .to_vec()
}

fn sweep(out: &Path, jobs: &str) {
    let mut args = vec!["sweep".to_string()];
    args.extend(small_sweep_args());
    args.extend(["--jobs", jobs, "--renderer", "cpu", "--keep-runs", "--out"].map(String::from));
    args.push(out.display().to_string());
    omniloop(&args);
}

/// The run folders of a sweep, in run order.
fn run_dirs(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut d: Vec<_> = std::fs::read_dir(dir.join("runs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    d.sort();
    d
}

#[test]
fn a_sweep_equals_its_runs_one_by_one_whatever_the_jobs() {
    let root = tmp("sweep_small");
    let (two, one) = (root.join("jobs2"), root.join("jobs1"));
    sweep(&two, "2");
    sweep(&one, "1");
    for f in ["sweep.csv", "sweep.md", "sweep.png"] {
        assert!(two.join(f).is_file(), "{f}");
    }
    let rows = table(&two);
    assert_eq!(rows.len(), 4);
    assert_eq!(rows, table(&one), "--jobs 2 and --jobs 1 give other rows");
    let (dirs2, dirs1) = (run_dirs(&two), run_dirs(&one));
    assert_eq!(dirs2.len(), 4);
    for (a, b) in dirs2.iter().zip(&dirs1) {
        let ta = std::fs::read(a.join("trajectory.csv")).unwrap();
        assert_eq!(
            ta,
            std::fs::read(b.join("trajectory.csv")).unwrap(),
            "{a:?}"
        );
    }

    // Each row again, as a run of its own.
    let text = std::fs::read_to_string(scenario_path("corner55_velocity_aware.toml")).unwrap();
    for (k, row) in rows.iter().enumerate() {
        let speed = &row["robot.max_speed_mm_s"];
        let seed = &row["seed"];
        assert!(text.contains("max_speed_mm_s = 400.0"));
        let edited = text.replacen(
            "max_speed_mm_s = 400.0",
            &format!("max_speed_mm_s = {speed}"),
            1,
        );
        let dir = root.join(format!("alone{k}"));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("corner55_velocity_aware.toml");
        std::fs::write(&file, edited).unwrap();
        let out = dir.join("out");
        omniloop([
            "run",
            file.to_str().unwrap(),
            "--seed",
            seed,
            "--renderer",
            "cpu",
            "-q",
            "--out",
            out.to_str().unwrap(),
        ]);
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        for key in [
            "cycles",
            "wall_contacts",
            "path_length_mm",
            "min_clearance_mm",
        ] {
            assert_eq!(row[key], summary[key].to_string(), "run {k}: {key}");
        }
        assert_eq!(row["reached_goal"], summary["reached_goal"].to_string());
        assert_eq!(
            std::fs::read(out.join("trajectory.csv")).unwrap(),
            std::fs::read(dirs2[k].join("trajectory.csv")).unwrap(),
            "run {k}: the trajectory alone differs from the sweep's"
        );
    }
}

#[test]
fn a_bad_set_exits_2_before_anything_runs() {
    let dir = tmp("sweep_bad");
    let scenario = scenario_path("corner55_velocity_aware.toml");
    for (set, expect) in [
        (
            "robot.max_speed_mm_s=400,-5",
            "--set robot.max_speed_mm_s=400,-5:1:26:",
        ),
        (
            "robot.max_speed_mm_s=400,fast!",
            "--set robot.max_speed_mm_s=400,fast!:1:26:",
        ),
        ("experiment.corner.angle_dg=40", "unknown field `angle_dg`"),
        ("robot.sensors[7].noise_sigma=1", "item 7 of 1"),
    ] {
        let out = bin()
            .args(["sweep", scenario.to_str().unwrap(), "--set", set, "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{set}: {err}");
        assert!(err.contains(expect), "{set}: {err}");
        assert!(!dir.join("sweep.csv").exists(), "{set}: something ran");
    }
}

/// With `--renderer gpu` the runs' frames are traced in shared batches; each run's trajectory
/// is the one it gets alone on the GPU, and the two seeds' trajectories differ. E1's first
/// 2 s (50 cycles down the first leg, the camera noise seeded per run) show it: on a CPU-only
/// Vulkan (CI's) a whole 30 s run takes about half a minute.
#[test]
fn gpu_batches_across_runs_give_each_run_its_own_trajectory() {
    if let Err(e) = omniloop_sim::Renderer::new(omniloop_sim::RendererChoice::Gpu, |_| {}) {
        assert!(
            std::env::var_os("OMNILOOP_REQUIRE_GPU").is_none(),
            "OMNILOOP_REQUIRE_GPU is set but no adapter opened: {e}"
        );
        eprintln!("skipping the batched GPU sweep: {e}");
        return;
    }
    let root = tmp("sweep_gpu");
    let e1 = std::fs::read_to_string(scenario_path("corner55_velocity_aware.toml")).unwrap();
    let short = e1.replace("duration_s = 30.0", "duration_s = 2.0");
    assert_ne!(short, e1, "E1's duration line moved");
    let scenario = root.join("corner55_velocity_aware.toml");
    std::fs::write(&scenario, short).unwrap();
    let sweep_dir = root.join("sweep");
    let out = omniloop([
        "sweep",
        scenario.to_str().unwrap(),
        "--seeds",
        "2",
        "--jobs",
        "2",
        "--renderer",
        "gpu",
        "--keep-runs",
        "--out",
        sweep_dir.to_str().unwrap(),
    ]);
    assert!(out.contains("(batched)"), "{out}");
    let rows = table(&sweep_dir);
    let runs = run_dirs(&sweep_dir);
    let trajectory = |dir: &Path| std::fs::read(dir.join("trajectory.csv")).unwrap();
    assert_eq!(runs.len(), 2);
    assert_ne!(
        trajectory(&runs[0]),
        trajectory(&runs[1]),
        "the seeds' runs are alike"
    );
    for (k, dir) in runs.iter().enumerate() {
        let alone = root.join(format!("alone{k}"));
        omniloop([
            "run",
            scenario.to_str().unwrap(),
            "--seed",
            rows[k]["seed"].as_str(),
            "--renderer",
            "gpu",
            "-q",
            "--out",
            alone.to_str().unwrap(),
        ]);
        assert_eq!(trajectory(dir), trajectory(&alone), "run {k}");
    }
}

/// The plan of a sweep run job by job with `omniloop run --plan --job`, then `--collect`ed,
/// gives the sweep's own table and each run's trajectory; a sweep resumed after losing rows
/// runs only those again, and its table is the whole sweep's.
#[test]
fn a_planned_sweep_run_job_by_job_and_collected_is_the_sweep() {
    let root = tmp("sweep_planned");
    let (whole, planned) = (root.join("whole"), root.join("planned"));
    sweep(&whole, "2");
    let mut args = vec!["sweep".to_string()];
    args.extend(small_sweep_args());
    args.extend([
        "--plan".into(),
        planned.join("plan.jsonl").display().to_string(),
    ]);
    omniloop(&args);
    let plan = std::fs::read_to_string(planned.join("plan.jsonl")).unwrap();
    assert_eq!(plan.lines().count(), 1 + 4, "{plan}");
    assert!(!planned.join("runs").exists(), "--plan ran something");
    for job in 0..4 {
        let plan_file = planned.join("plan.jsonl").display().to_string();
        let n = job.to_string();
        omniloop([
            "run",
            "--plan",
            plan_file.as_str(),
            "--job",
            n.as_str(),
            "--renderer",
            "cpu",
        ]);
    }
    omniloop(["sweep", "--collect", planned.to_str().unwrap()]);
    assert_eq!(table(&planned), table(&whole), "collected rows differ");
    for (a, b) in run_dirs(&planned).iter().zip(&run_dirs(&whole)) {
        assert_eq!(a.file_name(), b.file_name());
        assert!(
            std::fs::read(a.join("trajectory.csv")).unwrap()
                == std::fs::read(b.join("trajectory.csv")).unwrap(),
            "{a:?}: the planned run's trajectory differs"
        );
    }
    // A job the plan does not have exits 2 naming the plan.
    let out = bin()
        .args([
            "run",
            "--plan",
            planned.join("plan.jsonl").to_str().unwrap(),
            "--job",
            "9",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("plan.jsonl:1: no job 9"));

    // Resumed: two rows lost, two runs again, the same table.
    let journal = whole.join("rows.jsonl");
    let lines: Vec<String> = std::fs::read_to_string(&journal)
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    assert_eq!(lines.len(), 4);
    let before = table(&whole);
    std::fs::write(&journal, format!("{}\n{}\n", lines[0], lines[3])).unwrap();
    let mut args = vec!["sweep".to_string()];
    args.extend(small_sweep_args());
    args.extend(["--renderer", "cpu", "--resume", "--out"].map(String::from));
    args.push(whole.display().to_string());
    let md = omniloop(&args);
    assert!(
        md.contains("2 of 4 runs") && md.contains("2 more from the sweep resumed"),
        "{md}"
    );
    assert_eq!(table(&whole), before, "the resumed sweep's rows differ");
    assert_eq!(
        std::fs::read_to_string(&journal).unwrap().lines().count(),
        4
    );
}
