//! The estimators the robustness replay scores: each one's scenario (an experiment's own, as
//! its replay runs it), its error and its own target.
//! A new estimator is one more entry in [`ESTIMATORS`].

use crate::experiments::heading::RotationResult;
use crate::experiments::{corner, forward, heading, omnistereo, places, resection};
use crate::run::Summary;
use serde::de::DeserializeOwned;

/// An estimator's error in one run, and how it missed its target there, if it did.
#[derive(Debug, Clone, PartialEq)]
pub struct Score {
    /// The error, in the estimator's unit ([`Estimator::error_label`]).
    pub error: f64,
    /// How the run missed the estimator's target (`None`: it met it).
    pub missed: Option<String>,
}

impl Score {
    /// A score with the target's parts that failed (`(failed, what)`), joined by `; `.
    fn new(error: f64, parts: &[(bool, String)]) -> Self {
        let failed: Vec<&str> = parts
            .iter()
            .filter(|(f, _)| *f)
            .map(|(_, w)| w.as_str())
            .collect();
        Self {
            error,
            missed: (!failed.is_empty()).then(|| failed.join("; ")),
        }
    }

    /// Whether the run met the target.
    pub fn meets(&self) -> bool {
        self.missed.is_none()
    }
}

/// One estimator of the papers' methods.
pub struct Estimator {
    /// Short name (`ranges`), the column of `robustness.csv`.
    pub name: &'static str,
    /// Its title in the table and the figure.
    pub title: &'static str,
    /// The built-in scenario it runs in (file, text).
    pub scenario: (&'static str, &'static str),
    /// What the error is, with its unit.
    pub error_label: &'static str,
    /// The target, as the table states it.
    pub target: &'static str,
    /// The target's bound on the error, drawn in the figure (`None`: the target is not a bound).
    pub bound: Option<f64>,
    /// The error and the target's verdict from a run's summary (`None`: the run gave none).
    pub score: fn(&Summary) -> Option<Score>,
}

/// Every estimator, in the order of the tables and the figure's panels.
pub const ESTIMATORS: &[Estimator] = &[
    Estimator {
        name: "free_space",
        title: "Free space (E1)",
        scenario: (corner::SCENARIOS[1].1, corner::SCENARIOS[1].2),
        error_label: "median free-distance error, mm",
        target: "the goal reached without contact (E1)",
        bound: None,
        score: |s| {
            let contacts = s.wall_contacts;
            Some(Score::new(
                s.freespace_error_mm?,
                &[
                    (!s.reached_goal, "goal not reached".into()),
                    (contacts > 0, format!("{contacts} contacts")),
                ],
            ))
        },
    },
    Estimator {
        name: "floor_region",
        title: "Floor region, pixel by pixel (E1)",
        scenario: (corner::SCENARIOS[1].1, corner::SCENARIOS[1].2),
        error_label: "1 - median floor-region IoU, %",
        target: "the floor region's median IoU with the truth at least 0.9 (spec)",
        bound: Some(10.0),
        score: |s| {
            let loss = 100.0 * (1.0 - s.floor_region_iou?);
            Some(Score::new(
                loss,
                &[(loss > 10.0, format!("median IoU {:.3}", 1.0 - loss / 100.0))],
            ))
        },
    },
    Estimator {
        name: "floor_localization",
        title: "Floor localization (E2)",
        scenario: places::SCENARIO,
        error_label: "worst place's RMS position error, mm",
        target: "every frame localized, no ambiguity error, RMS <= 30 mm (\"dozens of mm\")",
        bound: Some(30.0),
        score: |s| {
            let results = places::place_results(s);
            let worst = results.iter().map(|p| p.rms_position_mm).reduce(f64::max)?;
            let lost: usize = results.iter().map(|p| p.not_localized).sum();
            let frames: usize = results.iter().map(|p| p.frames).sum();
            let wrong: usize = results.iter().map(|p| p.ambiguity_errors).sum();
            Some(Score::new(
                worst,
                &[
                    (worst > 30.0, "RMS over 30 mm".into()),
                    (lost > 0, format!("{lost} of {frames} frames not localized")),
                    (wrong > 0, format!("{wrong} ambiguity errors")),
                ],
            ))
        },
    },
    Estimator {
        name: "heading",
        title: "Luminance heading (E3)",
        scenario: heading::SCENARIO,
        error_label: "worst turn error, degrees",
        target: "every turn read, within 1 degree (E3)",
        bound: Some(1.0),
        score: |s| {
            let turns: Vec<RotationResult> = field(s, "rotations")?;
            let sweep: Option<f64> = field(s, "sweep_max_abs_error_deg");
            let sweep_na: usize = field(s, "sweep_na")?;
            let worst = turns
                .iter()
                .filter_map(|r| r.max_abs_error_deg)
                .chain(sweep)
                .reduce(f64::max)?;
            let na: usize = turns.iter().map(|r| r.na_frames).sum::<usize>() + sweep_na;
            Some(Score::new(
                worst,
                &[
                    (worst > 1.0, "over 1 degree".into()),
                    (na > 0, format!("{na} readings N/A")),
                ],
            ))
        },
    },
    Estimator {
        name: "ranges",
        title: "Omnistereo ranges (E4)",
        scenario: omnistereo::SCENARIO,
        error_label: "median range error, %",
        target: "median <= 1%, p95 <= 3% (E4)",
        bound: Some(1.0),
        score: |s| {
            let median = nested(s, "range_error_pct", "median")?;
            let p95 = nested(s, "range_error_pct", "p95")?;
            Some(Score::new(
                median,
                &[
                    (median > 1.0, "median over 1%".into()),
                    (p95 > 3.0, format!("p95 {p95:.2}% over 3%")),
                ],
            ))
        },
    },
    Estimator {
        name: "trilateration",
        title: "Trilateration (E4)",
        scenario: omnistereo::SCENARIO,
        error_label: "median position error, mm",
        target: "median <= 40 mm, p95 <= 100 mm (E4)",
        bound: Some(40.0),
        score: |s| {
            let median = nested(s, "trilateration_error_mm", "median")?;
            let p95 = nested(s, "trilateration_error_mm", "p95")?;
            Some(Score::new(
                median,
                &[
                    (median > 40.0, "median over 40 mm".into()),
                    (p95 > 100.0, format!("p95 {p95:.0} mm over 100 mm")),
                ],
            ))
        },
    },
    Estimator {
        name: "resection",
        title: "Three-mark resection (E5)",
        scenario: resection::SCENARIO,
        error_label: "largest position error, cm",
        target: "every place located, within 2 cm (E5)",
        bound: Some(2.0),
        score: |s| {
            let worst = s.metric("max_error_cm")?;
            let located: usize = field(s, "located")?;
            let places: Vec<serde_json::Value> = field(s, "places")?;
            let n = places.len();
            Some(Score::new(
                worst,
                &[
                    (worst > 2.0, "over 2 cm".into()),
                    (located < n, format!("{located} of {n} places located")),
                ],
            ))
        },
    },
    Estimator {
        name: "odometry_turn",
        title: "Forward odometry: turn (E6)",
        scenario: forward::ODOMETRY,
        error_label: "scan line's turn error, degrees",
        target: "within 2 degrees (the paper's square: 88-92 for 90)",
        bound: Some(2.0),
        score: |s| {
            let worst = forward::moves_of(s)
                .iter()
                .filter_map(|m| Some((m.scanline_deg? - m.truth).abs()))
                .reduce(f64::max)?;
            Some(Score::new(worst, &[(worst > 2.0, "over 2 degrees".into())]))
        },
    },
    Estimator {
        name: "odometry_legs",
        title: "Forward odometry: legs (E6)",
        scenario: forward::ODOMETRY,
        error_label: "worst Lucas-Kanade leg error, %",
        target: "within 7.2% (the paper's LK: 38.6 in for 36)",
        bound: Some(7.2),
        score: |s| {
            let worst = forward::moves_of(s)
                .iter()
                .filter(|m| m.truth.abs() > 0.0)
                .filter_map(|m| Some(100.0 * ((m.lk_mm? - m.truth) / m.truth).abs()))
                .reduce(f64::max)?;
            Some(Score::new(worst, &[(worst > 7.2, "over 7.2%".into())]))
        },
    },
];

/// The estimator called `name`.
pub fn estimator(name: &str) -> Option<&'static Estimator> {
    ESTIMATORS.iter().find(|e| e.name == name)
}

/// The experiment's summary key `key`, read as `T`.
fn field<T: DeserializeOwned>(s: &Summary, key: &str) -> Option<T> {
    serde_json::from_value(s.experiment.get(key)?.clone()).ok()
}

/// The number `inner` of the experiment's summary object `key`.
fn nested(s: &Summary, key: &str, inner: &str) -> Option<f64> {
    s.experiment.get(key)?.get(inner)?.as_f64()
}
