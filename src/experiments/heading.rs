//! E3, heading error from a luminance circle (Kim, Kim and Kwon, Sect. 3 and 4, Figs. 6-12):
//! the robot stores the luminance of the image circle whose rays are horizontal at a
//! checkpoint; it is then turned at the checkpoint (the paper's -24, +60 and +120 degrees, 20
//! frames each, and a sweep over the whole turn) and carried off it (0 to 60 cm in four
//! directions), and reads its heading error from each frame, or N/A. Its replay, `heading`,
//! runs it in the 8 m x 6 m room.

use super::experiment::{Experiment, ExperimentEntry, ExperimentSetup, MetricKeys, Metrics, setup};
use super::replay::{Replay, ReplayContext, write_text};
use crate::report::charts::{Chart, Series, Style, charts_png};
use crate::run::record::Summary;
use crate::run::{OutputFile, RunError, RunOutput, Simulation};
use crate::scenario::{PoseChecks, Problems};
use crate::scenario::{PoseSpec, Scenario};
use nalgebra::{Isometry2, Vector2};
use omniloop_sim::SimError;
use omniloop_vision::luminance_heading::{LuminanceCircle, LuminanceConfig, ShiftMethod};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// The checkpoint and the trials (`[experiment.heading]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeadingSpec {
    /// Where the reference is stored (field frame).
    pub checkpoint: PoseSpec,
    /// Turns at the checkpoint, degrees counter-clockwise.
    #[serde(default = "default_rotations")]
    pub rotations_deg: Vec<f64>,
    /// Frames (fresh sensor noise each) at each turn.
    #[serde(default = "default_frames")]
    pub frames_per_rotation: u32,
    /// The sweep over -180..180 degrees, in steps of this.
    #[serde(default = "default_sweep_step")]
    pub sweep_step_deg: f64,
    /// Translations off the checkpoint along +x, -x, +y and -y, in steps of this ...
    #[serde(default = "default_translation_step")]
    pub translation_step_mm: f64,
    /// ... up to this.
    #[serde(default = "default_translation_max")]
    pub translation_max_mm: f64,
}

fn default_rotations() -> Vec<f64> {
    vec![-24.0, 60.0, 120.0]
}
fn default_frames() -> u32 {
    20
}
fn default_sweep_step() -> f64 {
    5.0
}
fn default_translation_step() -> f64 {
    50.0
}
fn default_translation_max() -> f64 {
    600.0
}

/// The four directions of the translation sweep: name and unit vector (field frame).
pub const DIRECTIONS: [(&str, [f64; 2]); 4] = [
    ("+x", [1.0, 0.0]),
    ("-x", [-1.0, 0.0]),
    ("+y", [0.0, 1.0]),
    ("-y", [0.0, -1.0]),
];

impl HeadingSpec {
    fn validate(&self, s: &Scenario, c: &mut Problems) {
        let at = "experiment.heading";
        c.pose_in_world(
            &format!("{at}.checkpoint"),
            &self.checkpoint,
            s.robot.radius_mm,
            &s.world,
        );
        for (i, r) in self.rotations_deg.iter().enumerate() {
            c.finite(format!("{at}.rotations_deg[{i}]"), *r);
        }
        if self.frames_per_rotation == 0 {
            c.fail(format!("{at}.frames_per_rotation"), "must be >= 1");
        }
        c.positive(format!("{at}.sweep_step_deg"), self.sweep_step_deg);
        c.positive(
            format!("{at}.translation_step_mm"),
            self.translation_step_mm,
        );
        c.finite(format!("{at}.translation_max_mm"), self.translation_max_mm);
        if s.robot.sensors.is_empty() {
            c.fail(
                at,
                "the robot needs a mirror camera (add a [[robot.sensors]] table)",
            );
        }
    }
}

/// The registry's entry: `[experiment.heading]`.
pub const ENTRY: ExperimentEntry = ExperimentEntry {
    name: "heading",
    summary: "E3 of Kim, Kim and Kwon (Sect. 4): heading error from a luminance circle at a checkpoint",
    setup: |t| setup::<HeadingSpec>(t, "heading"),
};

impl ExperimentSetup for HeadingSpec {
    fn check(&self, s: &Scenario, c: &mut Problems) {
        self.validate(s, c);
    }

    fn takes_frames(&self) -> bool {
        true
    }

    fn table(&self, summary: &Summary) -> Option<String> {
        Some(heading_table(summary))
    }

    fn procedure(&self, s: &Scenario) -> Result<Box<dyn Experiment>, RunError> {
        let config = s.vision.table("luminance_heading")?;
        Ok(Box::new(Heading::new(self, &config)))
    }
}

/// One frame's reading.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Reading {
    /// The robot's true turn from the checkpoint's heading, degrees.
    pub true_deg: f64,
    /// Its true offset from the checkpoint, mm (field frame).
    pub offset_mm: [f64; 2],
    /// The shift by the sign arrays (eqs. (7)-(10)), degrees.
    pub signs_deg: f64,
    /// The shift by the differences (eqs. (2)-(6)), degrees.
    pub differences_deg: f64,
    /// The pattern match at the configured method's shift (eq. (11)), percent.
    pub match_percent: f64,
    /// Its minimum requirement (eq. (12)), percent.
    pub required_percent: f64,
}

impl Reading {
    /// The configured method's shift, `None` when N/A.
    fn accepted(&self, method: ShiftMethod) -> Option<f64> {
        (self.match_percent >= self.required_percent).then_some(match method {
            ShiftMethod::Signs => self.signs_deg,
            ShiftMethod::Differences => self.differences_deg,
        })
    }
}

/// The procedure and metrics of E3.
pub struct Heading {
    spec: HeadingSpec,
    config: LuminanceConfig,
    radius_px: f64,
    reference: Vec<f64>,
    rotations: Vec<Reading>,
    sweep: Vec<Reading>,
    translations: Vec<(usize, Reading)>,
}

impl Heading {
    /// E3 as `spec` describes it, with the method's settings `config`.
    pub fn new(spec: &HeadingSpec, config: &LuminanceConfig) -> Self {
        Self {
            spec: spec.clone(),
            config: config.clone(),
            radius_px: f64::NAN,
            reference: Vec::new(),
            rotations: Vec::new(),
            sweep: Vec::new(),
            translations: Vec::new(),
        }
    }
}

/// Wraps degrees into (-180, 180].
fn wrap_deg(d: f64) -> f64 {
    let w = d.rem_euclid(360.0);
    if w > 180.0 { w - 360.0 } else { w }
}

/// Takes frames at poses near the checkpoint and reads them against the reference.
struct Probe<'a> {
    sim: &'a mut Simulation,
    checkpoint: Isometry2<f64>,
    centre: [f64; 2],
    radius: f64,
    config: &'a LuminanceConfig,
}

impl Probe<'_> {
    /// The smoothed circle of one frame with the robot turned `turn_deg` from the checkpoint's
    /// heading and `offset` mm off it.
    fn circle(&mut self, turn_deg: f64, offset: [f64; 2]) -> Result<LuminanceCircle, RunError> {
        let pose = Isometry2::new(
            self.checkpoint.translation.vector + Vector2::new(offset[0], offset[1]),
            self.checkpoint.rotation.angle() + turn_deg.to_radians(),
        );
        self.sim.place_robot(pose);
        let img = self
            .sim
            .vision_frame()?
            .ok_or_else(|| SimError::Invalid("the robot's camera is not rendered".into()))?;
        Ok(LuminanceCircle::capture(
            img,
            self.centre,
            self.radius,
            self.config,
        )?)
    }

    fn read(
        &mut self,
        reference: &LuminanceCircle,
        turn_deg: f64,
        offset: [f64; 2],
    ) -> Result<Reading, RunError> {
        let c = self.circle(turn_deg, offset)?;
        let signs = c.shift_from(reference, ShiftMethod::Signs, self.config)?;
        let diffs = c.shift_from(reference, ShiftMethod::Differences, self.config)?;
        let m = match self.config.method {
            ShiftMethod::Signs => signs.matched,
            ShiftMethod::Differences => diffs.matched,
        };
        Ok(Reading {
            true_deg: turn_deg,
            offset_mm: offset,
            signs_deg: signs.shift_deg,
            differences_deg: diffs.shift_deg,
            match_percent: m.percent,
            required_percent: m.required,
        })
    }
}

impl Experiment for Heading {
    fn drives(&self) -> bool {
        false
    }

    /// Stores the reference at the checkpoint, then reads the turns, the sweep and the
    /// translations, each frame with fresh sensor noise.
    fn run(
        &mut self,
        sim: &mut Simulation,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<(), RunError> {
        let cal = sim.vision_calibration().cloned().ok_or_else(|| {
            SimError::Invalid("E3 needs the calibration of the robot's mirror camera".into())
        })?;
        self.radius_px = self.config.circle_radius_px(&cal)?;
        let spec = self.spec.clone();
        let sweep: Vec<f64> = sweep_angles(spec.sweep_step_deg);
        let steps = (spec.translation_max_mm / spec.translation_step_mm).floor() as usize;
        let total = (spec.rotations_deg.len() * spec.frames_per_rotation as usize
            + sweep.len()
            + 4 * (steps + 1)) as u64;
        let mut probe = Probe {
            sim,
            checkpoint: spec.checkpoint.isometry(),
            centre: cal.principal_point_px,
            radius: self.radius_px,
            config: &self.config,
        };
        let reference = probe.circle(0.0, [0.0, 0.0])?;
        let mut done = 0;
        let mut tick = || {
            done += 1;
            progress(done, total);
        };
        for &r in &spec.rotations_deg {
            for _ in 0..spec.frames_per_rotation {
                self.rotations.push(probe.read(&reference, r, [0.0, 0.0])?);
                tick();
            }
        }
        for &r in &sweep {
            self.sweep.push(probe.read(&reference, r, [0.0, 0.0])?);
            tick();
        }
        for (k, (_, u)) in DIRECTIONS.iter().enumerate() {
            for j in 0..=steps {
                let d = j as f64 * spec.translation_step_mm;
                let reading = probe.read(&reference, 0.0, [u[0] * d, u[1] * d])?;
                self.translations.push((k, reading));
                tick();
            }
        }
        self.reference = reference.values;
        Ok(())
    }

    fn metrics(&self, _out: &RunOutput) -> MetricKeys {
        heading_metrics(self).keys()
    }

    fn files(&self, _scenario: &Scenario, out: &RunOutput) -> Result<Vec<OutputFile>, RunError> {
        let png =
            heading_figure(self, &out.summary).map_err(|e| SimError::Invalid(e.to_string()))?;
        Ok(vec![
            OutputFile {
                name: "heading.png".into(),
                bytes: png,
            },
            OutputFile {
                name: "heading.csv".into(),
                bytes: heading_csv(self).into_bytes(),
            },
        ])
    }
}

/// -180, -180 + step, ..., up to 180.
fn sweep_angles(step: f64) -> Vec<f64> {
    let n = (360.0 / step).floor() as usize;
    (0..=n).map(|k| -180.0 + k as f64 * step).collect()
}

/// The readings at one turn (`summary.json`: `rotations`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RotationResult {
    /// The true turn, degrees.
    pub true_deg: f64,
    /// Median of the accepted readings, degrees.
    pub median_deg: Option<f64>,
    /// Largest |reading - truth| of the accepted readings, degrees.
    pub max_abs_error_deg: Option<f64>,
    /// Frames read N/A.
    pub na_frames: usize,
    /// Frames.
    pub frames: usize,
}

/// E3's metrics (`summary.json`: a key per field).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HeadingMetrics {
    /// The circle's image radius, px.
    pub circle_radius_px: f64,
    /// Per turn.
    pub rotations: Vec<RotationResult>,
    /// The sweep: largest |reading - truth| of the accepted readings, degrees.
    pub sweep_max_abs_error_deg: Option<f64>,
    /// The sweep: turns read N/A.
    pub sweep_na: usize,
    /// Frames (turns and sweep) where the two shift searches disagree by more than a degree.
    pub methods_disagree: usize,
    /// Per direction (`+x`, `-x`, `+y`, `-y`): the first distance read N/A, cm (null: none).
    pub translation_na_cm: serde_json::Map<String, serde_json::Value>,
    /// Per direction: the reading at each distance (0, step, ...), degrees (null: N/A).
    pub translation_shift_deg: serde_json::Map<String, serde_json::Value>,
}

fn heading_metrics(h: &Heading) -> HeadingMetrics {
    let method = h.config.method;
    let err = |r: &Reading| r.accepted(method).map(|v| wrap_deg(v - r.true_deg).abs());
    let rotations = h
        .spec
        .rotations_deg
        .iter()
        .map(|&t| {
            let rs: Vec<&Reading> = h.rotations.iter().filter(|r| r.true_deg == t).collect();
            let mut ok: Vec<f64> = rs.iter().filter_map(|r| r.accepted(method)).collect();
            ok.sort_by(f64::total_cmp);
            RotationResult {
                true_deg: t,
                median_deg: ok.get(ok.len() / 2).copied(),
                max_abs_error_deg: rs.iter().filter_map(|r| err(r)).reduce(f64::max),
                na_frames: rs.len() - ok.len(),
                frames: rs.len(),
            }
        })
        .collect();
    let mut na_cm = serde_json::Map::new();
    let mut shifts = serde_json::Map::new();
    for (k, (name, _)) in DIRECTIONS.iter().enumerate() {
        let rs: Vec<&Reading> = h
            .translations
            .iter()
            .filter(|t| t.0 == k)
            .map(|t| &t.1)
            .collect();
        let first_na = rs
            .iter()
            .find(|r| r.accepted(method).is_none())
            .map(|r| r.offset_mm[0].hypot(r.offset_mm[1]) / 10.0);
        na_cm.insert((*name).into(), first_na.into());
        let list: Vec<Option<f64>> = rs.iter().map(|r| r.accepted(method)).collect();
        shifts.insert(
            (*name).into(),
            serde_json::to_value(list).unwrap_or_default(),
        );
    }
    let all = h.rotations.iter().chain(&h.sweep);
    HeadingMetrics {
        circle_radius_px: h.radius_px,
        rotations,
        sweep_max_abs_error_deg: h.sweep.iter().filter_map(err).reduce(f64::max),
        sweep_na: h
            .sweep
            .iter()
            .filter(|r| r.accepted(method).is_none())
            .count(),
        methods_disagree: all
            .filter(|r| wrap_deg(r.signs_deg - r.differences_deg).abs() > 1.0)
            .count(),
        translation_na_cm: na_cm,
        translation_shift_deg: shifts,
    }
}

impl Metrics for HeadingMetrics {}

/// Every reading, one row each.
fn heading_csv(h: &Heading) -> String {
    let mut s = String::from(
        "trial,direction,true_deg,offset_x_mm,offset_y_mm,signs_deg,differences_deg,\
         match_percent,required_percent,accepted\n",
    );
    let rows = h
        .rotations
        .iter()
        .map(|r| ("rotation", "", r))
        .chain(h.sweep.iter().map(|r| ("sweep", "", r)))
        .chain(
            h.translations
                .iter()
                .map(|(k, r)| ("translation", DIRECTIONS[*k].0, r)),
        );
    for (trial, dir, r) in rows {
        let _ = writeln!(
            s,
            "{trial},{dir},{},{},{},{},{},{:.2},{:.2},{}",
            r.true_deg,
            r.offset_mm[0],
            r.offset_mm[1],
            r.signs_deg,
            r.differences_deg,
            r.match_percent,
            r.required_percent,
            u8::from(r.match_percent >= r.required_percent)
        );
    }
    s
}

/// Figs. 6-12 in four panels: the reference circle as a polar plot; the readings of each
/// turn frame by frame; the sweep's error; the translations' readings, N/A marked.
fn heading_figure(
    h: &Heading,
    summary: &Summary,
) -> Result<Vec<u8>, crate::report::topview::FigureError> {
    charts_png(
        "heading.png",
        &[
            polar_chart(h),
            rotation_chart(h),
            sweep_chart(h, summary),
            translation_chart(h),
        ],
        2,
        (640, 480),
    )
}

/// The colours of the turns' and the translations' series, in order.
const HEADING_COLOURS: [[u8; 3]; 4] = [[30, 80, 220], [220, 60, 30], [20, 150, 60], [150, 60, 180]];

/// The reference circle as a polar plot: its grey level by direction, closed.
fn polar_chart(h: &Heading) -> Chart {
    let n = h.reference.len().max(1);
    let polar: Vec<(f64, f64)> = h
        .reference
        .iter()
        .chain(h.reference.first())
        .enumerate()
        .map(|(k, l)| {
            let a = (k as f64 * 360.0 / n as f64).to_radians();
            (l * a.cos(), l * a.sin())
        })
        .collect();
    Chart {
        title: format!(
            "reference circle (R = {:.1} px): grey level by direction",
            h.radius_px
        ),
        x_label: "grey level along the robot's x".into(),
        y_label: "along y".into(),
        x_range: (-260.0, 260.0),
        y_range: (-260.0, 260.0),
        series: vec![Series {
            label: String::new(),
            rgb: [30, 30, 30],
            points: polar,
            style: Style::Line,
        }],
    }
}

/// Each turn at the checkpoint: the accepted reading's error frame by frame.
fn rotation_chart(h: &Heading) -> Chart {
    let method = h.config.method;
    let frames = h.spec.frames_per_rotation as usize;
    let series = h
        .spec
        .rotations_deg
        .iter()
        .enumerate()
        .map(|(k, &t)| Series {
            label: format!("turn {t:+.0} deg"),
            rgb: HEADING_COLOURS[k % 4],
            points: h
                .rotations
                .iter()
                .filter(|r| r.true_deg == t)
                .enumerate()
                .map(|(i, r)| (i as f64, r.accepted(method).unwrap_or(f64::NAN) - t))
                .filter(|p| p.1.is_finite())
                .collect(),
            style: Style::Dots,
        })
        .collect();
    Chart {
        title: "turns at the checkpoint: reading - truth, frame by frame".into(),
        x_label: "frame".into(),
        y_label: "error (deg)".into(),
        x_range: (-0.5, frames as f64 - 0.5),
        y_range: (-3.0, 3.0),
        series,
    }
}

/// The sweep of turns: the accepted reading's error against the true turn, with the largest
/// error and the N/A count in the title.
fn sweep_chart(h: &Heading, summary: &Summary) -> Chart {
    let method = h.config.method;
    Chart {
        title: format!(
            "sweep: reading - truth (max {:.1} deg, {} N/A)",
            HeadingMetrics::of(summary)
                .and_then(|m| m.sweep_max_abs_error_deg)
                .unwrap_or(f64::NAN),
            h.sweep
                .iter()
                .filter(|r| r.accepted(method).is_none())
                .count()
        ),
        x_label: "true turn (deg)".into(),
        y_label: "error (deg)".into(),
        x_range: (-185.0, 185.0),
        y_range: (-3.0, 3.0),
        series: vec![Series {
            label: String::new(),
            rgb: [30, 80, 220],
            points: h
                .sweep
                .iter()
                .filter_map(|r| Some((r.true_deg, wrap_deg(r.accepted(method)? - r.true_deg))))
                .collect(),
            style: Style::Dots,
        }],
    }
}

/// The translations: each direction's accepted readings against the distance, its N/A
/// readings as crosses at the bottom.
fn translation_chart(h: &Heading) -> Chart {
    let method = h.config.method;
    let mut series = Vec::new();
    for (k, (name, _)) in DIRECTIONS.iter().enumerate() {
        let rs: Vec<&Reading> = h
            .translations
            .iter()
            .filter(|t| t.0 == k)
            .map(|t| &t.1)
            .collect();
        let cm = |r: &Reading| r.offset_mm[0].hypot(r.offset_mm[1]) / 10.0;
        series.push(Series {
            label: name.to_string(),
            rgb: HEADING_COLOURS[k],
            points: rs
                .iter()
                .filter_map(|r| Some((cm(r), r.accepted(method)?)))
                .collect(),
            style: Style::Line,
        });
        series.push(Series {
            label: String::new(),
            rgb: HEADING_COLOURS[k],
            points: rs
                .iter()
                .filter(|r| r.accepted(method).is_none())
                .map(|r| (cm(r), -9.0 + k as f64 * 0.6))
                .collect(),
            style: Style::Crosses,
        });
    }
    let max_cm = h.spec.translation_max_mm / 10.0;
    Chart {
        title: "translations: reading (crosses at the bottom: N/A)".into(),
        x_label: "distance from the checkpoint (cm)".into(),
        y_label: "reading (deg)".into(),
        x_range: (-1.0, max_cm + 1.0),
        y_range: (-10.0, 10.0),
        series,
    }
}

/// E3 as a Markdown table beside the paper's figures.
pub fn heading_table(m: &Summary) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# E3: heading error from a luminance circle\n");
    let Some(h) = HeadingMetrics::of(m) else {
        let _ = writeln!(s, "(no E3 results in this summary)");
        return s;
    };
    let _ = writeln!(
        s,
        "Renderer: {}. Seed {}. Circle at R = {:.1} px (horizontal rays).\n",
        m.renderer.clone().unwrap_or_else(|| "-".into()),
        m.seed,
        h.circle_radius_px
    );
    let _ = writeln!(s, "| trial | paper | ours |");
    let _ = writeln!(s, "|---|---|---|");
    let deg = |v: Option<f64>| v.map_or("-".into(), |x| format!("{x:.1} deg"));
    for r in &h.rotations {
        let _ = writeln!(
            s,
            "| turn {:+.0} deg, {} frames | within +-1 deg | median {}, max error {}, {} N/A |",
            r.true_deg,
            r.frames,
            deg(r.median_deg),
            deg(r.max_abs_error_deg),
            r.na_frames
        );
    }
    let _ = writeln!(
        s,
        "| sweep -180..180 deg | (not given) | max error {}, {} N/A |",
        deg(h.sweep_max_abs_error_deg),
        h.sweep_na
    );
    for (name, _) in DIRECTIONS {
        let at20 = h
            .translation_shift_deg
            .get(name)
            .and_then(|v| v.as_array())
            .and_then(|a| a.get(4))
            .map_or("-".to_string(), |v| {
                v.as_f64().map_or("N/A".into(), |x| format!("{x:.0} deg"))
            });
        let na = h
            .translation_na_cm
            .get(name)
            .and_then(|v| v.as_f64())
            .map_or("none up to the end".into(), |cm| format!("{cm:.0} cm"));
        let _ = writeln!(
            s,
            "| translation {name} | 2 deg at 20 cm; N/A from 40 cm | {at20} at 20 cm; N/A from {na} |"
        );
    }
    let _ = writeln!(
        s,
        "\nFrames where the two shift searches (signs, differences) disagree by more than a \
         degree: {}.",
        h.methods_disagree
    );
    s
}

/// `omniloop replay heading`.
pub const REPLAY: Replay = Replay {
    name: "heading",
    title: "E3: heading error from a luminance circle with a hemispherical mirror (Figs. 6-12)",
    run: replay,
};

/// The E3 scenario file, built into the binary.
pub const SCENARIO: (&str, &str) = (
    "scenarios/heading_room.toml",
    include_str!("../../scenarios/heading_room.toml"),
);

/// Runs E3, writes the run (with `heading.png` and `heading.csv`) into `out/` and the table
/// into `heading.md`.
fn replay(ctx: &mut ReplayContext<'_>) -> anyhow::Result<String> {
    let out = ctx.out.to_path_buf();
    let run = ctx.run("heading_room", SCENARIO.0, SCENARIO.1, &out)?;
    let md = heading_table(&run.output.summary);
    write_text(&out.join("heading.md"), &md)?;
    Ok(md)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::experiment::tests::round_trip;

    #[test]
    fn the_sweep_covers_the_whole_turn_and_angles_wrap() {
        let a = sweep_angles(5.0);
        assert_eq!(a.len(), 73);
        assert_eq!((a[0], a[72]), (-180.0, 180.0));
        assert_eq!(wrap_deg(190.0), -170.0);
        assert_eq!(wrap_deg(-180.0), 180.0);
        assert_eq!(wrap_deg(-179.0), -179.0);
    }

    /// A reading at turn `true_deg`, `off` mm along the first direction, read `error` degrees
    /// off (N/A when `error` is `None`).
    fn reading(true_deg: f64, off: f64, error: Option<f64>) -> Reading {
        let shift = true_deg + error.unwrap_or(0.0);
        Reading {
            true_deg,
            offset_mm: [off, 0.0],
            signs_deg: shift,
            differences_deg: shift,
            match_percent: if error.is_some() { 90.0 } else { 10.0 },
            required_percent: 50.0,
        }
    }

    #[test]
    fn the_metrics_read_back_from_the_summary_for_the_table() {
        let spec: HeadingSpec = toml::from_str(
            "checkpoint = { x_mm = 0.0, y_mm = 0.0 }\nrotations_deg = [60.0]\n\
             translation_step_mm = 100.0\ntranslation_max_mm = 100.0",
        )
        .unwrap();
        let mut h = Heading::new(&spec, &LuminanceConfig::default());
        h.radius_px = 42.5;
        h.rotations = vec![reading(60.0, 0.0, Some(0.5)), reading(60.0, 0.0, None)];
        h.sweep = vec![reading(-180.0, 0.0, Some(-0.3))];
        for k in 0..DIRECTIONS.len() {
            h.translations.push((k, reading(0.0, 0.0, Some(0.0))));
            h.translations.push((k, reading(0.0, 100.0, None)));
        }
        let m = heading_metrics(&h);
        assert_eq!(m.rotations[0].max_abs_error_deg, Some(0.5));
        assert_eq!((m.rotations[0].na_frames, m.sweep_na), (1, 0));
        assert_eq!(m.translation_na_cm["-y"], serde_json::json!(10.0));
        let summary = round_trip(&m);
        let keys: Vec<&String> = summary.experiment.keys().collect();
        assert_eq!(
            keys,
            [
                "circle_radius_px",
                "rotations",
                "sweep_max_abs_error_deg",
                "sweep_na",
                "methods_disagree",
                "translation_na_cm",
                "translation_shift_deg"
            ]
        );
        let table = heading_table(&summary);
        assert!(table.contains("R = 42.5 px"), "{table}");
        assert!(table.contains("max error 0.3 deg, 0 N/A"), "{table}");
    }
}
