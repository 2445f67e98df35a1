//! E4, conical omnistereo (Spacek and Burbridge, Sect. 2 and 2.1): a robot with two coaxial
//! 90-degree cones wanders the 6 m x 4 m arena of six coloured pillars for 450 frames, on its
//! own estimate (trilateration fused with odometry). Every frame is scored against the truth:
//! the range of eq. (1) to each pillar it ranged, the trilaterated position, the visual
//! compass's rotation and the interframe translation since the previous frame. Its replay,
//! `omnistereo`, runs `scenarios/omnistereo_arena.toml`.

use super::experiment::{Experiment, ExperimentEntry, ExperimentSetup, MetricKeys, Metrics, setup};
use super::replay::{Replay, ReplayContext, write_text};
use crate::report::charts::{Chart, Series, Style, charts_png};
use crate::run::record::Summary;
use crate::run::score::quantile;
use crate::run::{OutputFile, RunError, RunOutput};
use crate::scenario::Problems;
use crate::scenario::Scenario;
use nalgebra::{Isometry2, Point2, Rotation2, Vector2};
use omniloop_control::wrap_pi;
use omniloop_robot::perception::omnistereo;
use omniloop_robot::{Landmarks, Measurement, MotionReading};
use omniloop_sim::SimError;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// What E4 scores (`[experiment.omnistereo]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OmnistereoSpec {
    /// Range errors are summarised over pillars this far from the axis, mm (the issue's
    /// 0.5-4 m).
    #[serde(default = "default_band")]
    pub range_band_mm: [f64; 2],
}

fn default_band() -> [f64; 2] {
    [500.0, 4000.0]
}

impl OmnistereoSpec {
    fn validate(&self, s: &Scenario, c: &mut Problems) {
        let [a, b] = self.range_band_mm;
        if !(a >= 0.0 && b > a) {
            c.fail(
                "experiment.omnistereo.range_band_mm",
                format!("must be [near, far] with 0 <= near < far (got [{a}, {b}])"),
            );
        }
        if s.control.pose_source != omnistereo::POSE_SOURCE {
            c.fail(
                "control.pose_source",
                "experiment.omnistereo scores the omnistereo stage: set pose_source = \
                 \"omnistereo\"",
            );
        }
    }
}

/// The registry's entry: `[experiment.omnistereo]`.
pub const ENTRY: ExperimentEntry = ExperimentEntry {
    name: "omnistereo",
    summary: "E4 of Spacek and Burbridge (Sect. 2): conical omnistereo range, trilateration, compass, interframe motion",
    setup: |t| setup::<OmnistereoSpec>(t, "omnistereo"),
};

impl ExperimentSetup for OmnistereoSpec {
    fn check(&self, s: &Scenario, c: &mut Problems) {
        self.validate(s, c);
    }

    fn table(&self, summary: &Summary) -> Option<String> {
        Some(omnistereo_table(summary))
    }

    fn procedure(&self, s: &Scenario) -> Result<Box<dyn Experiment>, RunError> {
        Ok(Box::new(Omnistereo::new(self, s)))
    }
}

/// E4's procedure (the default drive) and its scoring.
pub struct Omnistereo {
    band: [f64; 2],
    pillars: Vec<(Point2<f64>, f64)>,
    mount: Vector2<f64>,
}

impl Omnistereo {
    /// The experiment of scenario `s`.
    pub fn new(spec: &OmnistereoSpec, s: &Scenario) -> Self {
        Self {
            band: spec.range_band_mm,
            pillars: s
                .world
                .pillars
                .iter()
                .map(|p| (Point2::from(p.center_mm), p.radius_mm))
                .collect(),
            mount: s
                .stereo_rig()
                .map_or(Vector2::zeros(), |r| r.mount_mm.into()),
        }
    }
}

/// One pillar ranged in one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
struct RangeScore {
    frame: usize,
    landmark: usize,
    true_mm: f64,
    est_mm: f64,
    bearing_error_deg: f64,
}

impl RangeScore {
    fn error_pct(&self) -> f64 {
        100.0 * (self.est_mm - self.true_mm) / self.true_mm
    }
}

/// Every frame's errors against the truth.
#[derive(Debug, Clone, Default)]
struct Scores {
    ranges: Vec<RangeScore>,
    trilateration_mm: Vec<(usize, f64)>,
    compass_deg: Vec<(usize, f64)>,
    interframe_mm: Vec<(usize, f64)>,
    frames: usize,
}

impl Omnistereo {
    /// The true pose of the mirrors' axis in frame `k`.
    fn axis(&self, out: &RunOutput, k: usize) -> Isometry2<f64> {
        let r = &out.trajectory[k];
        let pose = Isometry2::new(Vector2::new(r.x_mm, r.y_mm), r.theta_rad);
        Isometry2::new(
            pose.translation.vector + pose.rotation * self.mount,
            r.theta_rad,
        )
    }

    fn scores(&self, out: &RunOutput) -> Scores {
        let mut s = Scores {
            frames: out.estimates.len().min(out.trajectory.len()),
            ..Scores::default()
        };
        for k in 0..s.frames {
            let e = &out.estimates[k];
            let axis = self.axis(out, k);
            for l in e.percept::<Landmarks>().map_or(&[][..], |l| &l.0) {
                let Some(&(c, radius)) = self.pillars.get(l.landmark) else {
                    continue;
                };
                let local = axis.inverse_transform_point(&c);
                s.ranges.push(RangeScore {
                    frame: k,
                    landmark: l.landmark,
                    true_mm: local.coords.norm() - radius,
                    est_mm: l.range_mm,
                    bearing_error_deg: wrap_pi(l.bearing_rad - local.y.atan2(local.x)).to_degrees(),
                });
            }
            if let Some(Measurement::Pose { pose, .. }) =
                e.pose_fix(omnistereo::NAME).map(|f| &f.measurement)
            {
                let r = &out.trajectory[k];
                let err = (pose.translation.vector - Vector2::new(r.x_mm, r.y_mm)).norm();
                s.trilateration_mm.push((k, err));
            }
            if let (Some(m), true) = (e.percept::<MotionReading>(), k > 0) {
                let before = self.axis(out, k - 1);
                let turn = wrap_pi(axis.rotation.angle() - before.rotation.angle());
                s.compass_deg
                    .push((k, wrap_pi(m.rotation_rad - turn).to_degrees().abs()));
                if let Some(t) = m.translation_mm {
                    let truth = Rotation2::new(-before.rotation.angle())
                        * (axis.translation.vector - before.translation.vector);
                    s.interframe_mm.push((k, (t - truth).norm()));
                }
            }
        }
        s
    }

    /// Range observations within the band.
    fn in_band<'a>(&self, s: &'a Scores) -> impl Iterator<Item = &'a RangeScore> {
        let [a, b] = self.band;
        s.ranges
            .iter()
            .filter(move |r| r.true_mm >= a && r.true_mm <= b)
    }
}

/// Median and 95th percentile of a quantity, with their count (`summary.json`: `median`,
/// `p95`, `n`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Stats {
    /// Median (`None`: no value).
    pub median: Option<f64>,
    /// 95th percentile.
    pub p95: Option<f64>,
    /// How many values.
    pub n: usize,
}

impl Stats {
    /// The statistics of `v`.
    fn of(v: &[f64]) -> Self {
        Self {
            median: quantile(v, 0.5),
            p95: quantile(v, 0.95),
            n: v.len(),
        }
    }
}

/// The range errors' statistics (percent of the true range), with the band of true ranges
/// they cover and the nearest true range of any observation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RangeStats {
    /// The errors' statistics, within the band.
    #[serde(flatten)]
    pub stats: Stats,
    /// The band of true ranges scored, mm.
    pub band_mm: [f64; 2],
    /// The nearest true range of an observation, mm (`None`: nothing ranged).
    pub nearest_ranged_mm: Option<f64>,
}

/// E4's metrics (`summary.json`: a key per field).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OmnistereoMetrics {
    /// |range error| of the pillars ranged within the band, percent.
    pub range_error_pct: RangeStats,
    /// Trilateration's position error per frame, mm.
    pub trilateration_error_mm: Stats,
    /// The visual compass's turn error per frame pair, degrees.
    pub compass_error_deg: Stats,
    /// The interframe translation's error per frame pair, mm.
    pub interframe_translation_error_mm: Stats,
    /// Frames scored.
    pub frames: usize,
}

impl Metrics for OmnistereoMetrics {}

impl Omnistereo {
    /// E4's metrics of its scores.
    fn measure(&self, s: &Scores) -> OmnistereoMetrics {
        let pct: Vec<f64> = self.in_band(s).map(|r| r.error_pct().abs()).collect();
        let second = |v: &[(usize, f64)]| Stats::of(&v.iter().map(|x| x.1).collect::<Vec<f64>>());
        OmnistereoMetrics {
            range_error_pct: RangeStats {
                stats: Stats::of(&pct),
                band_mm: self.band,
                nearest_ranged_mm: s
                    .ranges
                    .iter()
                    .map(|r| r.true_mm)
                    .fold(None::<f64>, |a, x| Some(a.map_or(x, |a| a.min(x)))),
            },
            trilateration_error_mm: second(&s.trilateration_mm),
            compass_error_deg: second(&s.compass_deg),
            interframe_translation_error_mm: second(&s.interframe_mm),
            frames: s.frames,
        }
    }
}

impl Experiment for Omnistereo {
    fn metrics(&self, out: &RunOutput) -> MetricKeys {
        self.measure(&self.scores(out)).keys()
    }

    fn files(&self, _scenario: &Scenario, out: &RunOutput) -> Result<Vec<OutputFile>, RunError> {
        let s = self.scores(out);
        let png = figure(self, &s).map_err(|e| SimError::Invalid(e.to_string()))?;
        Ok(vec![
            OutputFile {
                name: "omnistereo.png".into(),
                bytes: png,
            },
            OutputFile {
                name: "omnistereo_ranges.csv".into(),
                bytes: ranges_csv(&s).into_bytes(),
            },
            OutputFile {
                name: "omnistereo_frames.csv".into(),
                bytes: frames_csv(&s).into_bytes(),
            },
        ])
    }
}

fn ranges_csv(s: &Scores) -> String {
    let mut out = String::from("frame,pillar,true_range_mm,range_mm,error_pct,bearing_error_deg\n");
    for r in &s.ranges {
        let _ = writeln!(
            out,
            "{},{},{:.1},{:.1},{:.3},{:.3}",
            r.frame,
            r.landmark,
            r.true_mm,
            r.est_mm,
            r.error_pct(),
            r.bearing_error_deg
        );
    }
    out
}

fn frames_csv(s: &Scores) -> String {
    let mut out = String::from(
        "frame,trilateration_error_mm,compass_error_deg,interframe_translation_error_mm\n",
    );
    let find = |v: &[(usize, f64)], k: usize| {
        v.iter()
            .find(|x| x.0 == k)
            .map_or(String::new(), |x| format!("{:.3}", x.1))
    };
    for k in 0..s.frames {
        let _ = writeln!(
            out,
            "{k},{},{},{}",
            find(&s.trilateration_mm, k),
            find(&s.compass_deg, k),
            find(&s.interframe_mm, k)
        );
    }
    out
}

/// Range error against distance; trilateration, compass and interframe errors per frame.
fn figure(e: &Omnistereo, s: &Scores) -> Result<Vec<u8>, crate::report::topview::FigureError> {
    let frames = s.frames.max(1) as f64;
    let per_frame = |v: &[(usize, f64)]| v.iter().map(|&(k, x)| (k as f64, x)).collect();
    let top = |v: &[(usize, f64)], floor: f64| 1.1 * v.iter().map(|x| x.1).fold(floor, f64::max);
    let band: Vec<(f64, f64)> = e
        .in_band(s)
        .map(|r| (r.true_mm / 1000.0, r.error_pct()))
        .collect();
    let outside: Vec<(f64, f64)> = s
        .ranges
        .iter()
        .filter(|r| r.true_mm < e.band[0] || r.true_mm > e.band[1])
        .map(|r| (r.true_mm / 1000.0, r.error_pct()))
        .collect();
    let dots = |label: &str, rgb: [u8; 3], points: Vec<(f64, f64)>, style: Style| Series {
        label: label.into(),
        rgb,
        points,
        style,
    };
    let far = s.ranges.iter().map(|r| r.true_mm).fold(4000.0, f64::max) / 1000.0;
    let range_chart = Chart {
        title: "range of eq. (1): error against distance".into(),
        x_label: "true range to the pillar's face (m)".into(),
        y_label: "error (%)".into(),
        x_range: (0.0, far + 0.2),
        y_range: (-6.0, 6.0),
        series: vec![
            dots("within the band", [30, 90, 200], band, Style::Dots),
            dots("outside it", [160, 160, 160], outside, Style::Crosses),
        ],
    };
    let chart = |title: &str, y: &str, v: &[(usize, f64)], floor: f64, rgb: [u8; 3]| Chart {
        title: title.into(),
        x_label: "frame".into(),
        y_label: y.into(),
        x_range: (0.0, frames),
        y_range: (0.0, top(v, floor)),
        series: vec![dots("", rgb, per_frame(v), Style::Dots)],
    };
    charts_png(
        "omnistereo.png",
        &[
            range_chart,
            chart(
                "trilateration: position error",
                "error (mm)",
                &s.trilateration_mm,
                50.0,
                [200, 60, 30],
            ),
            chart(
                "visual compass: rotation error per frame pair",
                "|error| (deg)",
                &s.compass_deg,
                0.5,
                [40, 140, 60],
            ),
            chart(
                "interframe translation error per frame pair",
                "error (mm)",
                &s.interframe_mm,
                10.0,
                [120, 60, 170],
            ),
        ],
        2,
        (640, 440),
    )
}

/// E4 as a Markdown table with the targets.
pub fn omnistereo_table(m: &Summary) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# E4: conical omnistereo, trilateration and interframe motion\n"
    );
    let e = OmnistereoMetrics::of(m);
    let _ = writeln!(
        s,
        "Renderer: {}. Seed {}. {} frames, {} wall contacts, path {:.1} m.\n",
        m.renderer.clone().unwrap_or_else(|| "-".into()),
        m.seed,
        e.map_or(0, |e| e.frames),
        m.wall_contacts,
        m.path_length_mm / 1000.0
    );
    let _ = writeln!(s, "| quantity | n | median | p95 | target |");
    let _ = writeln!(s, "|---|---|---|---|---|");
    let f = |v: Option<f64>, unit: &str, digits: usize| {
        v.map_or("-".into(), |x| format!("{x:.digits$} {unit}"))
    };
    let rows = omnistereo_rows(e);
    for (label, stats, unit, digits, target) in rows {
        let _ = writeln!(
            s,
            "| {label} | {} | {} | {} | {target} |",
            stats.map_or(0, |x| x.n),
            f(stats.and_then(|x| x.median), unit, digits),
            f(stats.and_then(|x| x.p95), unit, digits)
        );
    }
    if let Some(near) = e.and_then(|e| e.range_error_pct.nearest_ranged_mm) {
        let _ = writeln!(
            s,
            "\nNearest pillar ranged: {:.2} m. Nearer, a pillar's top is above the lower \
             mirror's view: the common region of two cones (R = 30, d = 100, s = 150 mm) \
             starts at s (d + R) / R - d = 550 mm for any feature, and later for the top of a \
             600 mm pillar.",
            near / 1000.0
        );
    }
    s
}

/// The table's rows: label, the statistics, unit, decimals and the target; the range error's
/// over the pillars of the metrics' band.
fn omnistereo_rows(
    e: Option<OmnistereoMetrics>,
) -> [(String, Option<Stats>, &'static str, usize, &'static str); 4] {
    let band = e.map_or(default_band(), |e| e.range_error_pct.band_mm);
    [
        (
            format!(
                "range error, pillars {:.1}-{:.1} m",
                band[0] / 1000.0,
                band[1] / 1000.0
            ),
            e.map(|e| e.range_error_pct.stats),
            "%",
            2,
            "median <= 1%, p95 <= 3%",
        ),
        (
            "trilateration position error".into(),
            e.map(|e| e.trilateration_error_mm),
            "mm",
            1,
            "median <= 40 mm, p95 <= 100 mm",
        ),
        (
            "visual compass error per frame pair".into(),
            e.map(|e| e.compass_error_deg),
            "deg",
            3,
            "median <= 0.3 deg",
        ),
        (
            "interframe translation error".into(),
            e.map(|e| e.interframe_translation_error_mm),
            "mm",
            1,
            "median <= 10 mm",
        ),
    ]
}

/// `omniloop replay omnistereo`.
pub const REPLAY: Replay = Replay {
    name: "omnistereo",
    title: "E4: conical omnistereo range, trilateration, compass and interframe motion (Sect. 2)",
    run: replay,
};

/// The E4 scenario file, built into the binary.
pub const SCENARIO: (&str, &str) = (
    "scenarios/omnistereo_arena.toml",
    include_str!("../../scenarios/omnistereo_arena.toml"),
);

/// Runs E4, writes the run (with `omnistereo.png` and the CSVs) into `out/` and the table into
/// `omnistereo.md`.
fn replay(ctx: &mut ReplayContext<'_>) -> anyhow::Result<String> {
    let out = ctx.out.to_path_buf();
    let run = ctx.run("omnistereo_arena", SCENARIO.0, SCENARIO.1, &out)?;
    let md = omnistereo_table(&run.output.summary);
    write_text(&out.join("omnistereo.md"), &md)?;
    Ok(md)
}
