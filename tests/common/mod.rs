//! Helpers shared by the end-to-end tests.
#![allow(dead_code)]

use omniloop::simulation::RunOptions;
use omniloop::{Scenario, load_scenario};
use omniloop_sim::RendererChoice;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A file of `scenarios/`.
pub fn scenario_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios")
        .join(name)
}

/// Loads a file of `scenarios/`.
pub fn scenario(name: &str) -> Scenario {
    load_scenario(&scenario_path(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Run options with the CPU renderer (bit-for-bit reproducible).
pub fn cpu() -> RunOptions {
    RunOptions {
        renderer: RendererChoice::Cpu,
        ..RunOptions::default()
    }
}

/// A fresh, empty folder for one test.
pub fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The `omniloop` binary.
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_omniloop"))
}

/// Runs `omniloop` with `args`, requires success and returns its standard output.
pub fn omniloop<I, S>(args: I) -> String
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    let out = bin().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}
