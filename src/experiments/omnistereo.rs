//! E4, conical omnistereo (Spacek and Burbridge, Sect. 2 and 2.1): a robot with two coaxial
//! 90-degree cones wanders the 6 m x 4 m arena of six coloured pillars for 450 frames, on its
//! own estimate (trilateration fused with odometry). Every frame is scored against the truth:
//! the range of eq. (1) to each pillar it ranged, the trilaterated position, the visual
//! compass's rotation and the interframe translation since the previous frame. Its replay,
//! `omnistereo`, runs `scenarios/omnistereo_arena.toml`.

use super::experiment::{Experiment, ExperimentEntry, ExperimentSetup, Metrics, setup};
use super::replay::{Replay, ReplayContext, write_text};
use crate::report::charts::{Chart, Series, Style, charts_png};
use crate::run::record::Summary;
use crate::run::score::quantile;
use crate::run::{OutputFile, RunError, RunOutput};
use crate::scenario::Checker;
use crate::scenario::Scenario;
use nalgebra::{Isometry2, Point2, Rotation2, Vector2};
use omniloop_control::wrap_pi;
use omniloop_robot::Measurement;
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
    fn validate(&self, s: &Scenario, c: &mut Checker) {
        let [a, b] = self.range_band_mm;
        if !(a >= 0.0 && b > a) {
            c.fail(
                "experiment.omnistereo.range_band_mm",
                format!("must be [near, far] with 0 <= near < far (got [{a}, {b}])"),
            );
        }
        if s.control.pose_source != "omnistereo" {
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
    fn check(&self, s: &Scenario, c: &mut Checker) {
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
            for l in &e.landmarks {
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
                e.pose_fix("omnistereo").map(|f| &f.measurement)
            {
                let r = &out.trajectory[k];
                let err = (pose.translation.vector - Vector2::new(r.x_mm, r.y_mm)).norm();
                s.trilateration_mm.push((k, err));
            }
            if let (Some(m), true) = (&e.motion, k > 0) {
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

/// Median and 95th percentile of `v`, with their count, as JSON.
fn stats(v: &[f64]) -> serde_json::Value {
    serde_json::json!({
        "median": quantile(v, 0.5),
        "p95": quantile(v, 0.95),
        "n": v.len(),
    })
}

impl Experiment for Omnistereo {
    fn metrics(&self, out: &RunOutput) -> Metrics {
        let s = self.scores(out);
        let band: Vec<&RangeScore> = self.in_band(&s).collect();
        let pct: Vec<f64> = band.iter().map(|r| r.error_pct().abs()).collect();
        let second = |v: &[(usize, f64)]| v.iter().map(|x| x.1).collect::<Vec<f64>>();
        let mut m = Metrics::new();
        let mut range = stats(&pct);
        range["band_mm"] = serde_json::json!(self.band);
        range["nearest_ranged_mm"] = serde_json::json!(
            s.ranges
                .iter()
                .map(|r| r.true_mm)
                .fold(None::<f64>, |a, x| Some(a.map_or(x, |a| a.min(x))))
        );
        m.insert("range_error_pct".into(), range);
        m.insert(
            "trilateration_error_mm".into(),
            stats(&second(&s.trilateration_mm)),
        );
        m.insert("compass_error_deg".into(), stats(&second(&s.compass_deg)));
        m.insert(
            "interframe_translation_error_mm".into(),
            stats(&second(&s.interframe_mm)),
        );
        m.insert("frames".into(), serde_json::json!(s.frames));
        m
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
    let get = |key: &str, q: &str| {
        m.experiment
            .get(key)
            .and_then(|v| v.get(q))
            .and_then(serde_json::Value::as_f64)
    };
    let n = |key: &str| get(key, "n").unwrap_or(0.0) as u64;
    let _ = writeln!(
        s,
        "Renderer: {}. Seed {}. {} frames, {} wall contacts, path {:.1} m.\n",
        m.renderer.clone().unwrap_or_else(|| "-".into()),
        m.seed,
        m.experiment
            .get("frames")
            .and_then(serde_json::Value::as_u64)
            .unwrap_or(0),
        m.wall_contacts,
        m.path_length_mm / 1000.0
    );
    let _ = writeln!(s, "| quantity | n | median | p95 | target |");
    let _ = writeln!(s, "|---|---|---|---|---|");
    let f = |v: Option<f64>, unit: &str, digits: usize| {
        v.map_or("-".into(), |x| format!("{x:.digits$} {unit}"))
    };
    let band = m
        .experiment
        .get("range_error_pct")
        .and_then(|v| v.get("band_mm"))
        .and_then(|b| serde_json::from_value::<[f64; 2]>(b.clone()).ok())
        .unwrap_or(default_band());
    for (label, key, unit, digits, target) in omnistereo_rows(band) {
        let _ = writeln!(
            s,
            "| {label} | {} | {} | {} | {target} |",
            n(key),
            f(get(key, "median"), unit, digits),
            f(get(key, "p95"), unit, digits)
        );
    }
    if let Some(near) = get("range_error_pct", "nearest_ranged_mm") {
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

/// The table's rows: label, the key of its statistics in the summary, unit, decimals and the
/// target; the range error's over the pillars of `band` (mm).
fn omnistereo_rows(
    band: [f64; 2],
) -> [(String, &'static str, &'static str, usize, &'static str); 4] {
    [
        (
            format!(
                "range error, pillars {:.1}-{:.1} m",
                band[0] / 1000.0,
                band[1] / 1000.0
            ),
            "range_error_pct",
            "%",
            2,
            "median <= 1%, p95 <= 3%",
        ),
        (
            "trilateration position error".into(),
            "trilateration_error_mm",
            "mm",
            1,
            "median <= 40 mm, p95 <= 100 mm",
        ),
        (
            "visual compass error per frame pair".into(),
            "compass_error_deg",
            "deg",
            3,
            "median <= 0.3 deg",
        ),
        (
            "interframe translation error".into(),
            "interframe_translation_error_mm",
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
