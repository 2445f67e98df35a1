//! The estimators the robustness replay scores: each one's scenario (an experiment's own, as
//! its replay runs it), its error and its own target.
//! A new estimator is one more entry in [`ESTIMATORS`]. Each reads its experiment's typed metrics ([`crate::experiments::Metrics`]) from the run's
//! summary, so that a metric renamed there fails to compile here.

use crate::ball_map::BallMapMetrics;
use crate::experiments::heading::HeadingMetrics;
use crate::experiments::omnistereo::OmnistereoMetrics;
use crate::experiments::resection::ResectionMetrics;
use crate::experiments::{Metrics, corner, forward, heading, omnistereo, places, resection};
use crate::run::Summary;

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
            let h = HeadingMetrics::of(s)?;
            let worst = h
                .rotations
                .iter()
                .filter_map(|r| r.max_abs_error_deg)
                .chain(h.sweep_max_abs_error_deg)
                .reduce(f64::max)?;
            let na: usize = h.rotations.iter().map(|r| r.na_frames).sum::<usize>() + h.sweep_na;
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
            let range = OmnistereoMetrics::of(s)?.range_error_pct.stats;
            let (median, p95) = (range.median?, range.p95?);
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
            let position = OmnistereoMetrics::of(s)?.trilateration_error_mm;
            let (median, p95) = (position.median?, position.p95?);
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
            let r = ResectionMetrics::of(s)?;
            let (worst, located, n) = (r.max_error_cm?, r.located, r.places.len());
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
    Estimator {
        name: "ball",
        title: "Ball detection (E1)",
        scenario: crate::ball_map::ROBUSTNESS,
        error_label: "median range error within 1 m, %",
        target: "the ball detected in >= 95% of frames within 1 m, median range error <= 3%, \
                 median bearing error <= 1 degree (ball map)",
        bound: Some(3.0),
        score: |s| {
            let w = BallMapMetrics::of(s)?.ball_map.map?.within_target;
            let (median, rate) = (w.median_range_error_pct?, w.detection_rate?);
            let bearing = w.median_bearing_error_deg?;
            Some(Score::new(
                median,
                &[
                    (median > 3.0, "median over 3%".into()),
                    (
                        rate < 0.95,
                        format!("detected in {:.0}% of frames", 100.0 * rate),
                    ),
                    (
                        bearing > 1.0,
                        format!("median bearing error {bearing:.2} deg"),
                    ),
                ],
            ))
        },
    },
];

/// The estimator called `name`.
pub fn estimator(name: &str) -> Option<&'static Estimator> {
    ESTIMATORS.iter().find(|e| e.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ball_map::stats::{BallMapFigures, CameraMap, Rates};
    use crate::experiments::MetricKeys;
    use crate::experiments::experiment::tests::summary_with;
    use crate::experiments::forward::{ForwardMetrics, MoveResult};
    use crate::experiments::heading::RotationResult;
    use crate::experiments::omnistereo::{RangeStats, Stats};
    use crate::experiments::places::{PlaceResult, PlacesMethod, PlacesMetrics};
    use omniloop_vision::LocalizationMethod;

    /// Estimator `name`'s score of a run whose experiment wrote `m`.
    fn score(name: &str, m: &impl Metrics) -> Option<Score> {
        (estimator(name).unwrap().score)(&summary_with(m.keys()))
    }

    fn stats(median: f64, p95: f64) -> Stats {
        Stats {
            median: Some(median),
            p95: Some(p95),
            n: 10,
        }
    }

    #[test]
    fn the_heading_estimator_reads_the_rotations() {
        let turn = |max: f64, na_frames| RotationResult {
            true_deg: 60.0,
            median_deg: Some(60.0),
            max_abs_error_deg: Some(max),
            na_frames,
            frames: 20,
        };
        let heading = HeadingMetrics {
            circle_radius_px: 40.0,
            rotations: vec![turn(0.5, 0), turn(1.5, 2)],
            sweep_max_abs_error_deg: Some(0.7),
            sweep_na: 1,
            methods_disagree: 0,
            translation_na_cm: serde_json::Map::new(),
            translation_shift_deg: serde_json::Map::new(),
        };
        let s = score("heading", &heading).unwrap();
        assert_eq!(s.error, 1.5);
        assert_eq!(s.missed.as_deref(), Some("over 1 degree; 3 readings N/A"));
    }

    #[test]
    fn the_omnistereo_estimators_read_ranges_and_trilateration() {
        let omnistereo = OmnistereoMetrics {
            range_error_pct: RangeStats {
                stats: stats(0.8, 3.5),
                band_mm: [500.0, 3000.0],
                nearest_ranged_mm: Some(600.0),
            },
            trilateration_error_mm: stats(50.0, 90.0),
            compass_error_deg: stats(0.1, 0.2),
            interframe_translation_error_mm: stats(5.0, 9.0),
            frames: 10,
        };
        let s = score("ranges", &omnistereo).unwrap();
        assert_eq!(s.error, 0.8);
        assert_eq!(s.missed.as_deref(), Some("p95 3.50% over 3%"));
        let s = score("trilateration", &omnistereo).unwrap();
        assert_eq!(s.error, 50.0);
        assert_eq!(s.missed.as_deref(), Some("median over 40 mm"));
    }

    #[test]
    fn the_resection_estimator_reads_its_places() {
        let place = |place_cm: [f64; 2], error_cm: Option<f64>| resection::PlaceResult {
            place_cm,
            true_cm: place_cm,
            estimate_cm: error_cm.map(|_| place_cm),
            error_cm,
            heading_error_deg: None,
            pan_search_s: 10.0,
            moved: false,
            failure: None,
        };
        let located = [place([0.0, 0.0], Some(1.5)), place([50.0, 0.0], None)];
        let s = score("resection", &ResectionMetrics::new("pan", &located)).unwrap();
        assert_eq!(s.error, 1.5);
        assert_eq!(s.missed.as_deref(), Some("1 of 2 places located"));
    }

    #[test]
    fn the_floor_localization_estimator_reads_its_places() {
        let at = |rms_position_mm| PlaceResult {
            true_pose: [0.0, 0.0, 0.0],
            rms_position_mm,
            rms_heading_deg: 0.2,
            ambiguity_errors: 0,
            frames: 5,
            not_localized: 0,
        };
        let places = PlacesMetrics {
            places: vec![at(12.0), at(21.0)],
            localization: PlacesMethod {
                method: LocalizationMethod::Paper,
                mode: "global".into(),
            },
        };
        let s = score("floor_localization", &places).unwrap();
        assert!(s.meets());
        assert_eq!(s.error, 21.0);
    }

    #[test]
    fn the_odometry_estimators_read_the_forward_moves() {
        let step = |kind: &str, commanded, truth, scanline_deg, lk_mm| MoveResult {
            kind: kind.into(),
            commanded,
            truth,
            scanline_deg,
            lk_mm,
            ncc_mm: lk_mm,
            lk_gaps: 0,
            ncc_gaps: 0,
        };
        let forward = ForwardMetrics {
            moves: Some(vec![
                step("forward", 600.0, 500.0, None, Some(550.0)),
                step("turn", 90.0, 89.0, Some(92.0), None),
            ]),
            avoidance: None,
        };
        let s = score("odometry_turn", &forward).unwrap();
        assert_eq!(s.error, 3.0);
        assert_eq!(s.missed.as_deref(), Some("over 2 degrees"));
        let s = score("odometry_legs", &forward).unwrap();
        assert_eq!(s.error, 10.0);
        assert_eq!(s.missed.as_deref(), Some("over 7.2%"));
    }

    #[test]
    fn the_ball_estimator_reads_the_ball_map() {
        let within = Rates {
            frames: 20,
            detected: 18,
            detection_rate: Some(0.9),
            median_range_error_pct: Some(1.5),
            p90_range_error_pct: Some(2.5),
            median_range_bias_mm: Some(2.0),
            median_bearing_error_deg: Some(0.2),
            misses: vec![("too small".into(), 2)],
        };
        let map = CameraMap {
            camera: "omni".into(),
            image_px: [256, 220],
            shadow: None,
            rings: Vec::new(),
            all: within.clone(),
            unoccluded: within.clone(),
            target_range_mm: 1000.0,
            within_target: within,
            lost_from_mm: None,
            reaches_90: true,
        };
        let ball = BallMapMetrics {
            ball_map: BallMapFigures {
                map: Some(map),
                false_balls: None,
            },
        };
        let s = score("ball", &ball).unwrap();
        assert_eq!(s.error, 1.5);
        assert_eq!(s.missed.as_deref(), Some("detected in 90% of frames"));
    }

    #[test]
    fn a_run_without_its_experiments_metrics_gives_no_score() {
        let none = summary_with(MetricKeys::new());
        for name in [
            "floor_localization",
            "heading",
            "ranges",
            "trilateration",
            "resection",
            "odometry_turn",
            "odometry_legs",
            "ball",
        ] {
            assert_eq!((estimator(name).unwrap().score)(&none), None, "{name}");
        }
    }
}
