//! `omniloop sweep` interrupted: alone in its binary, so that its signal meets no other test's
//! processes.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

#[path = "suite/common/mod.rs"]
mod common;

use common::{bin, scenario_path, tmp};

/// Ctrl-C (SIGINT) stops starting runs, writes what finished and exits 130.
#[cfg(unix)]
#[test]
fn an_interrupted_sweep_keeps_what_finished() {
    let dir = tmp("sweep_interrupted");
    let mut child = bin()
        .args([
            "sweep",
            scenario_path("corner55_velocity_aware.toml")
                .to_str()
                .unwrap(),
            "--seeds",
            "200",
            "--jobs",
            "1",
            "--renderer",
            "cpu",
            "--out",
        ])
        .arg(&dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_secs(3));
    let killed = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 201, "{csv}");
    let not_run = csv
        .lines()
        .filter(|l| l.contains("not run (the sweep was stopped)"))
        .count();
    // A run of the corner takes a few tenths of a second on one worker: after 3 s, most of
    // the 200 have not started.
    assert!(
        not_run >= 150,
        "200 runs of a few tenths of a second each: {not_run} not run after 3 s"
    );
    assert!(dir.join("sweep.md").is_file() && dir.join("sweep.png").is_file());
}
