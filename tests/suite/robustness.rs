//! The robustness replay's machinery on a part of its grid: E2's floor localization through a
//! defocused lens (run), and knobs the rules or the experiment keep from an estimator (not
//! run).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use omniloop::robustness::{
    GridOptions, Outcome, Selection, estimator, knob, report, run_grid, write_outputs,
};
use omniloop_sim::RendererChoice;

fn cpu(seed: Option<u64>) -> GridOptions {
    GridOptions {
        renderer: RendererChoice::Cpu,
        seed,
        workers: 0,
    }
}

/// E2's floor localization (the paper's method) through a lens defocused 0 to 2 px: five runs,
/// each scored; the error grows with the blur, and from 1 px the worst place is more than
/// 30 mm off; the table, the CSV and the figure are written.
#[test]
fn floor_localization_against_defocus() {
    let selection = Selection {
        estimators: vec![estimator("floor_localization").unwrap()],
        knobs: vec![knob("defocus").unwrap()],
        max_levels: None,
    };
    let mut calls = 0;
    let grid = run_grid(&selection, &cpu(None), |_, _| calls += 1).unwrap();
    assert_eq!(grid.runs, 5);
    assert!(calls >= 1, "progress was never reported");
    let scores: Vec<_> = grid
        .cells
        .iter()
        .map(|c| match &c.outcome {
            Outcome::Scored(s) => s.clone(),
            o => panic!("defocus {}: {o:?}", c.level),
        })
        .collect();
    let errors: Vec<f64> = scores.iter().map(|s| s.error).collect();
    println!("worst RMS at defocus 0, 0.5, 1, 1.5, 2 px: {errors:?} mm");
    assert!(
        errors.windows(2).all(|w| w[1] >= w[0]) && errors[4] > 2.0 * errors[0],
        "the error does not grow with the blur: {errors:?}"
    );
    assert!(scores[0].meets(), "sharp: {:?}", scores[0].missed);
    for s in &scores[2..] {
        let missed = s.missed.as_deref().unwrap_or_default();
        assert!(missed.contains("RMS over 30 mm"), "{missed}");
    }
    let dir = common::tmp("robustness_defocus");
    let md = write_outputs(&dir, &grid, 0.0).unwrap();
    assert!(
        md.contains("| defocus sigma, px | 0, 0.5, 1, 1.5, 2 |"),
        "{md}"
    );
    let csv = std::fs::read_to_string(dir.join("robustness.csv")).unwrap();
    assert_eq!(csv.lines().count(), 6, "{csv}");
    let png = image::open(dir.join("robustness.png")).unwrap();
    assert_eq!((png.width(), png.height()), (430, 320));
}

/// A mirror's tilt cannot reach the pinhole camera of E5 (the rules refuse it), nor latency
/// E3's frames, which the experiment renders itself: whole rows not applicable, with the
/// reason, and nothing run.
#[test]
fn knobs_that_cannot_reach_an_estimator() {
    for (e, k, reason) in [
        ("resection", "tilt", "mounting"),
        ("heading", "latency", "outside"),
    ] {
        let selection = Selection {
            estimators: vec![estimator(e).unwrap()],
            knobs: vec![knob(k).unwrap()],
            max_levels: None,
        };
        let grid = run_grid(&selection, &cpu(Some(3)), |_, _| {}).unwrap();
        assert_eq!(grid.runs, 0, "{e} x {k} ran");
        assert_eq!(grid.cells.len(), 5);
        for c in &grid.cells {
            match &c.outcome {
                Outcome::NotApplicable(why) => assert!(why.contains(reason), "{e} x {k}: {why}"),
                o => panic!("{e} x {k} at {}: {o:?}", c.level),
            }
        }
        let md = report::markdown(&grid, "");
        let row = format!(
            "| {} | {} | n/a [1]",
            knob(k).unwrap().label,
            "0, 30, 60, 90, 120"
        );
        let row = if k == "tilt" {
            "| mirror tilt, degrees | 0, 0.5, 1, 1.5, 2 | n/a [1]".to_string()
        } else {
            row
        };
        assert!(md.contains(&row), "{md}");
        assert!(md.contains("| n/a |"), "{md}");
    }
}

/// The floor region's estimator shares the free-space estimator's runs (E1, with the truth
/// beside every frame): each noise level is one run, both scored; the stage's floor region
/// strays from the truth's as the noise grows, within the target.
#[test]
fn the_floor_region_is_scored_pixel_by_pixel_in_the_free_space_runs() {
    let selection = Selection {
        estimators: vec![
            estimator("free_space").unwrap(),
            estimator("floor_region").unwrap(),
        ],
        knobs: vec![knob("noise").unwrap()],
        max_levels: None,
    };
    let grid = run_grid(&selection, &cpu(None), |_, _| {}).unwrap();
    assert_eq!(grid.runs, 5, "the two estimators share their runs");
    let floor: Vec<_> = (grid.cells.iter())
        .filter(|c| c.estimator.name == "floor_region")
        .map(|c| match &c.outcome {
            Outcome::Scored(s) => s.clone(),
            o => panic!("noise {}: {o:?}", c.level),
        })
        .collect();
    assert_eq!(floor.len(), 5);
    println!(
        "1 - median IoU at noise 2, 4, 8, 12, 16: {:?} %",
        floor.iter().map(|s| s.error).collect::<Vec<_>>()
    );
    let errors: Vec<f64> = floor.iter().map(|s| s.error).collect();
    assert!(
        errors.windows(2).all(|w| w[1] >= w[0]) && errors[4] > errors[0],
        "the floor region does not stray more with more noise: {errors:?}"
    );
    for s in &floor {
        assert!((0.0..10.0).contains(&s.error), "{}", s.error);
        assert!(s.meets(), "{:?}", s.missed);
    }
}
