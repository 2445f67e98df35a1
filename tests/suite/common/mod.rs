//! Helpers shared by the end-to-end tests.
#![allow(dead_code)]
// Helpers of tests: a broken fixture stops the test where it breaks.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use omniloop::run::RunOptions;
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

/// The GPU renderer, or `None` (the comparison skipped, and said so) where no adapter opens;
/// with `OMNILOOP_REQUIRE_GPU` set, no adapter fails the test instead.
pub fn gpu_or_skip() -> Option<omniloop_sim::Renderer> {
    match omniloop_sim::Renderer::new(RendererChoice::Gpu, |_| {}) {
        Ok(r) => Some(r),
        Err(e) => {
            if std::env::var_os("OMNILOOP_REQUIRE_GPU").is_some() {
                panic!("OMNILOOP_REQUIRE_GPU is set but no adapter opened: {e}");
            }
            eprintln!("skipping the GPU comparison: {e}");
            None
        }
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
        "{}: {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// `omniloop check` on scenario file `scenario` (of `scenarios/`) with the first `from`
/// replaced by `to`, written under a folder named `name`: its exit status and standard error.
pub fn check_variant(scenario: &str, name: &str, from: &str, to: &str) -> (Option<i32>, String) {
    let text = std::fs::read_to_string(scenario_path(scenario)).unwrap();
    assert!(text.contains(from), "{scenario}: {from}");
    let dir = tmp(name);
    let file = dir.join("broken.toml");
    std::fs::write(&file, text.replacen(from, to, 1)).unwrap();
    let out = bin().arg("check").arg(&file).output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The share of the pixels whose every colour channel is within `levels` of the other
/// image's.
pub fn share_within(a: &image::RgbaImage, b: &image::RgbaImage, levels: i32) -> f64 {
    let close = a
        .pixels()
        .zip(b.pixels())
        .filter(|(p, q)| (0..3).all(|c| (p.0[c] as i32 - q.0[c] as i32).abs() <= levels))
        .count();
    close as f64 / (a.width() * a.height()) as f64
}

/// Requires at least 99.9% of the pixels within `levels` of the other image's (each channel),
/// and prints the share found under `what`.
pub fn assert_alike(a: &image::RgbaImage, b: &image::RgbaImage, levels: i32, what: &str) {
    let frac = share_within(a, b, levels);
    eprintln!(
        "{what}: {:.4}% of pixels within {levels} levels",
        100.0 * frac
    );
    assert!(frac >= 0.999, "{what}: only {:.4}%", 100.0 * frac);
}

/// The corner paper's f(R): the floor distance (mm) of image radius R (px).
pub fn paper_f(r_px: f64) -> f64 {
    r_px / (10.12 - 2.054e-2 * (2.298e5 + r_px * r_px).sqrt())
}

/// The image radius (px) of floor distance `r_mm` by the paper's f(R), by bisection.
pub fn paper_f_inverse(r_mm: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 113.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if paper_f(mid) < r_mm {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}
