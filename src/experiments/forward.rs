//! E6, a forward camera on a small robot (Ahmed, Saatchi and Caparrelli, Sects. 2-3): obstacle
//! avoidance by ground segmentation and by optical flow among obstacles on a light floor, and
//! visual odometry over scripted moves on a floor with dark marks (the scan line reads the
//! turns, Lucas-Kanade and cross-correlation the straight runs). Its replay, `forward`, runs
//! both avoidance methods for a minute, the square of Fig. 8 and the two tests of Fig. 10.

use super::experiment::{Experiment, ExperimentEntry, ExperimentSetup, MetricKeys, Metrics, setup};
use super::replay::{Replay, ReplayContext, write_text};
use crate::report::charts::{Chart, Series, Style, charts_png};
use crate::report::output::write_run;
use crate::run::{OutputFile, RunError, RunOutput, Summary};
use crate::scenario::Problems;
use crate::scenario::Scenario;
use nalgebra::{Isometry2, Vector2};
use omniloop_control::wrap_pi;
use omniloop_robot::controllers::script::{Move, ScriptConfig};
use omniloop_robot::{Estimates, ForwardVisionConfig};
use omniloop_vision::forward::OdometryStep;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// The avoidance controllers the experiment measures.
const AVOIDANCE: [&str; 2] = ["segmentation", "optical_flow"];
/// The scripted drive whose visual odometry it scores.
const SCRIPT: &str = "script";

/// `[experiment.forward]`: no settings; what is measured follows from `control.kind`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct ForwardSpec {}

impl ForwardSpec {
    fn validate(&self, s: &Scenario, c: &mut Problems) {
        let kind = s.control.kind.as_str();
        let odometry = s
            .vision
            .table::<ForwardVisionConfig>("forward")
            .is_ok_and(|f| f.visual_odometry);
        if AVOIDANCE.contains(&kind) || (kind == SCRIPT && odometry) {
        } else if kind == SCRIPT {
            c.fail(
                "vision.forward.visual_odometry",
                "experiment.forward scores the visual odometry of a script: set it to true",
            );
        } else {
            c.fail(
                "control.kind",
                format!(
                    "experiment.forward measures \"segmentation\", \"optical_flow\" or \"script\", \
                     not {kind:?}"
                ),
            );
        }
        if s.robot.differential.is_none() {
            c.fail(
                "robot.differential",
                "experiment.forward's robot is a differential-drive robot: add [robot.differential]",
            );
        }
    }
}

/// The registry's entry: `[experiment.forward]`.
pub const ENTRY: ExperimentEntry = ExperimentEntry {
    name: "forward",
    summary: "E6 of Ahmed, Saatchi and Caparrelli: a forward camera's avoidance or visual odometry",
    setup: |t| setup::<ForwardSpec>(t, "forward"),
};

impl ExperimentSetup for ForwardSpec {
    fn check(&self, s: &Scenario, c: &mut Problems) {
        self.validate(s, c);
    }

    fn procedure(&self, s: &Scenario) -> Result<Box<dyn Experiment>, RunError> {
        Ok(Box::new(Forward::new(s)))
    }
}

/// One scripted move as the odometry read it and as it truly was (`summary.json`: `moves`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MoveResult {
    /// `"forward"` or `"turn"`.
    pub kind: String,
    /// What the script asked for (mm, or degrees).
    pub commanded: f64,
    /// The true length (mm) or turn (degrees), from the truth before and after.
    pub truth: f64,
    /// The scan line's turn, degrees (turns).
    pub scanline_deg: Option<f64>,
    /// The straight distance by Lucas-Kanade, mm (straight runs).
    pub lk_mm: Option<f64>,
    /// The straight distance by cross-correlation, mm.
    pub ncc_mm: Option<f64>,
    /// Frames of the move with no Lucas-Kanade translation.
    pub lk_gaps: usize,
    /// Frames of the move with no cross-correlation translation.
    pub ncc_gaps: usize,
}

/// An avoidance run's figures (`summary.json`: `avoidance`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AvoidanceResult {
    /// The avoidance controller (`segmentation`, `optical_flow`).
    pub method: String,
    /// Contacts with the obstacles and walls.
    pub contacts: u32,
    /// Distance driven, mm.
    pub distance_mm: f64,
    /// Closed-loop cycles per wall-clock second.
    pub fps: f64,
}

impl AvoidanceResult {
    /// The figures of a run of controller `method` with summary `s`.
    fn of(method: &str, s: &Summary) -> Self {
        Self {
            method: method.to_string(),
            contacts: s.wall_contacts,
            distance_mm: s.path_length_mm,
            fps: s.cycles_per_s,
        }
    }
}

/// E6's metrics (`summary.json`): a scripted run's moves, or an avoidance run's figures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ForwardMetrics {
    /// The scripted moves, scored (a run of the script).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub moves: Option<Vec<MoveResult>>,
    /// The avoidance run's figures (a run of an avoidance controller).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub avoidance: Option<AvoidanceResult>,
}

impl Metrics for ForwardMetrics {}

/// The procedure is driving; the metrics depend on the controller.
pub struct Forward {
    kind: String,
    moves: Vec<Move>,
    start: Isometry2<f64>,
}

impl Forward {
    /// The experiment of scenario `s`.
    pub fn new(s: &Scenario) -> Self {
        Self {
            kind: s.control.kind.clone(),
            moves: s
                .control
                .table::<ScriptConfig>(SCRIPT)
                .map(|t| t.moves)
                .unwrap_or_default(),
            start: s.start().isometry(),
        }
    }
}

/// The poses the visual odometry integrates from `start`, one per cycle: the scan line's
/// rotation with the translation of `pick` (nothing where there is none).
pub fn odometry_path(
    start: Isometry2<f64>,
    estimates: &[Estimates],
    pick: impl Fn(&OdometryStep) -> Option<Vector2<f64>>,
) -> Vec<Isometry2<f64>> {
    let mut pose = start;
    estimates
        .iter()
        .map(|e| {
            if let Some(step) = e.percept::<OdometryStep>() {
                let t = pick(step).unwrap_or_else(Vector2::zeros);
                pose *= Isometry2::new(t, step.rotation_rad);
            }
            pose
        })
        .collect()
}

fn lk(step: &OdometryStep) -> Option<Vector2<f64>> {
    step.lk.as_ref().ok().map(|m| m.translation_mm)
}

fn ncc(step: &OdometryStep) -> Option<Vector2<f64>> {
    step.ncc.as_ref().ok().map(|m| m.translation_mm)
}

impl Forward {
    /// Each scripted move: the cycles whose readings it covers, scored.
    fn moves(&self, out: &RunOutput) -> Vec<MoveResult> {
        let e = &out.estimates;
        let lk_path = odometry_path(self.start, e, lk);
        let ncc_path = odometry_path(self.start, e, ncc);
        let rows = &out.trajectory;
        let mut results = Vec::new();
        for (k, m) in self.moves.iter().enumerate() {
            let cycles: Vec<usize> = (0..e.len()).filter(|&i| e[i].step == Some(k)).collect();
            let (Some(&first), Some(&last)) = (cycles.first(), cycles.last()) else {
                continue;
            };
            let before = first.saturating_sub(1);
            let (a, b) = (&rows[before], &rows[last]);
            let gaps = |f: &dyn Fn(&OdometryStep) -> bool| {
                cycles
                    .iter()
                    .filter(|&&i| e[i].percept::<OdometryStep>().is_some_and(f))
                    .count()
            };
            let dist = |p: &[Isometry2<f64>]| {
                (p[last].translation.vector - p[before].translation.vector).norm()
            };
            results.push(match *m {
                Move::ForwardMm(d) => MoveResult {
                    kind: "forward".into(),
                    commanded: d,
                    truth: (b.x_mm - a.x_mm).hypot(b.y_mm - a.y_mm),
                    scanline_deg: None,
                    lk_mm: Some(dist(&lk_path)),
                    ncc_mm: Some(dist(&ncc_path)),
                    lk_gaps: gaps(&|s| s.lk.is_err()),
                    ncc_gaps: gaps(&|s| s.ncc.is_err()),
                },
                Move::TurnDeg(deg) => MoveResult {
                    kind: "turn".into(),
                    commanded: deg,
                    truth: wrap_pi(b.theta_rad - a.theta_rad).to_degrees(),
                    scanline_deg: Some(
                        cycles
                            .iter()
                            .filter_map(|&i| e[i].percept::<OdometryStep>())
                            .map(|s| s.rotation_rad)
                            .sum::<f64>()
                            .to_degrees(),
                    ),
                    lk_mm: None,
                    ncc_mm: None,
                    lk_gaps: 0,
                    ncc_gaps: 0,
                },
                // The kicker's and dribbler's moves take no time and move nothing.
                Move::DribbleRpm(_) | Move::Kick(_) => continue,
            });
        }
        results
    }
}

impl Experiment for Forward {
    fn metrics(&self, out: &RunOutput) -> MetricKeys {
        let scripted = self.kind == SCRIPT;
        ForwardMetrics {
            moves: scripted.then(|| self.moves(out)),
            avoidance: (!scripted).then(|| AvoidanceResult::of(&self.kind, &out.summary)),
        }
        .keys()
    }

    fn files(&self, scenario: &Scenario, out: &RunOutput) -> Result<Vec<OutputFile>, RunError> {
        if self.kind != SCRIPT {
            return Ok(Vec::new());
        }
        let chart = path_chart(&scenario.name, self.start, out);
        let bytes = charts_png("forward_paths.png", &[chart], 1, (700, 640))
            .map_err(|e| RunError::Actuator(e.to_string()))?;
        Ok(vec![OutputFile {
            name: "forward_paths.png".into(),
            bytes,
        }])
    }
}

/// The true path beside the two visual odometry paths of a scripted run.
fn path_chart(title: &str, start: Isometry2<f64>, out: &RunOutput) -> Chart {
    let xy = |p: &[Isometry2<f64>]| -> Vec<(f64, f64)> {
        p.iter()
            .map(|q| (q.translation.x, q.translation.y))
            .collect()
    };
    let truth: Vec<(f64, f64)> = out.trajectory.iter().map(|r| (r.x_mm, r.y_mm)).collect();
    let lk_path = xy(&odometry_path(start, &out.estimates, lk));
    let ncc_path = xy(&odometry_path(start, &out.estimates, ncc));
    let all = truth.iter().chain(&lk_path).chain(&ncc_path);
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in all {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    let span = (x1 - x0).max(y1 - y0) * 0.55 + 50.0;
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let series = |label: &str, rgb, points| Series {
        label: label.into(),
        rgb,
        points,
        style: Style::Line,
    };
    Chart {
        title: title.to_string(),
        x_label: "x (mm)".into(),
        y_label: "y (mm)".into(),
        x_range: (cx - span, cx + span),
        y_range: (cy - span, cy + span),
        series: vec![
            series("truth", [20, 20, 20], truth),
            series("Lucas-Kanade", [200, 40, 40], lk_path),
            series("cross-correlation", [40, 90, 200], ncc_path),
        ],
    }
}

/// The E6 scenario files, built into the binary.
pub const OBSTACLES: (&str, &str) = (
    "scenarios/forward_obstacles.toml",
    include_str!("../../scenarios/forward_obstacles.toml"),
);
/// See [`OBSTACLES`].
pub const ODOMETRY: (&str, &str) = (
    "scenarios/forward_odometry.toml",
    include_str!("../../scenarios/forward_odometry.toml"),
);

/// One inch, mm.
const INCH_MM: f64 = 25.4;

/// The square of Fig. 8 (600 mm sides, four left turns) and the two tests of Fig. 10.
pub fn odometry_runs() -> Vec<(&'static str, Vec<Move>)> {
    let side = Move::ForwardMm(600.0);
    let left = Move::TurnDeg(90.0);
    vec![
        (
            "square",
            vec![side, left, side, left, side, left, side, left],
        ),
        (
            "test1",
            vec![
                Move::ForwardMm(36.0 * INCH_MM),
                Move::TurnDeg(-90.0),
                Move::ForwardMm(11.0 * INCH_MM),
            ],
        ),
        (
            "test2",
            vec![
                Move::ForwardMm(36.0 * INCH_MM),
                Move::TurnDeg(90.0),
                Move::ForwardMm(9.5 * INCH_MM),
            ],
        ),
    ]
}

/// The paper's figures: the square's turns (Fig. 8a) and the legs of Fig. 10 (in), true and by
/// LK and NCC.
pub const PAPER_TURNS_DEG: [f64; 4] = [89.5, 92.0, 91.0, 88.0];
/// Fig. 10 (test 1, test 2): (true, LK, NCC) inches of each leg.
pub const PAPER_LEGS_IN: [(f64, f64, f64); 4] = [
    (36.0, 38.6, 38.7),
    (11.0, 10.0, 9.5),
    (36.0, 37.4, 39.4),
    (9.5, 8.3, 8.6),
];

/// The scripted moves of a summary (`moves`), empty without them.
pub fn moves_of(summary: &Summary) -> Vec<MoveResult> {
    ForwardMetrics::of(summary)
        .and_then(|m| m.moves)
        .unwrap_or_default()
}

/// The replay: both avoidance methods, the square and the two tests; `forward.md`,
/// `forward.png` and `summary.json`.
fn replay(ctx: &mut ReplayContext<'_>) -> anyhow::Result<String> {
    let out = ctx.out.to_path_buf();
    let mut avoidance = Vec::new();
    for kind in AVOIDANCE {
        let run = ctx.simulate_edited(kind, OBSTACLES.0, OBSTACLES.1, |s| {
            s.control.kind = kind.to_string();
            s.name = format!("forward_{kind}");
            Ok(())
        })?;
        write_run(&out.join(kind), &run.scenario, &run.output)?;
        avoidance.push(AvoidanceResult::of(kind, &run.output.summary));
    }
    let mut charts = Vec::new();
    let mut runs = Vec::new();
    for (name, moves) in odometry_runs() {
        let run = ctx.simulate_edited(name, ODOMETRY.0, ODOMETRY.1, |s| {
            let mut script: ScriptConfig = s.control.table(SCRIPT)?;
            script.moves = moves.clone();
            s.control.tables.set(SCRIPT, &script)?;
            s.name = format!("forward_{name}");
            if name == "square" {
                s.robot.start = Some(crate::scenario::PoseSpec {
                    x_mm: -300.0,
                    y_mm: -300.0,
                    heading_deg: 0.0,
                });
            }
            s.run.duration_s = 40.0;
            Ok(())
        })?;
        write_run(&out.join(name), &run.scenario, &run.output)?;
        charts.push(path_chart(
            &format!("{name}: true and visual odometry paths"),
            run.scenario.start().isometry(),
            &run.output,
        ));
        runs.push((name, moves_of(&run.output.summary)));
    }
    let png = charts_png("forward.png", &charts, 3, (560, 520))?;
    std::fs::write(out.join("forward.png"), png)?;
    let summary = replay_summary(&runs, &avoidance);
    write_text(
        &out.join("summary.json"),
        &serde_json::to_string_pretty(&summary)?,
    )?;
    let md = forward_table(&summary);
    write_text(&out.join("forward.md"), &md)?;
    Ok(md)
}

/// `summary.json` of the replay.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ForwardSummary {
    /// The square's turns, [read by the scan line, true], degrees.
    pub square_turns_deg: Vec<[f64; 2]>,
    /// The legs by Lucas-Kanade, [read, true], inches, test 1 then test 2.
    pub lk_legs_in: Vec<[f64; 2]>,
    /// The legs by cross-correlation, as `lk_legs_in`.
    pub ncc_legs_in: Vec<[f64; 2]>,
    /// Each avoidance run's figures.
    pub avoidance: Vec<AvoidanceResult>,
}

/// `summary.json` of the replay, from the scripted runs' moves and the avoidance runs.
pub fn replay_summary(
    runs: &[(&str, Vec<MoveResult>)],
    avoidance: &[AvoidanceResult],
) -> ForwardSummary {
    let turns: Vec<[f64; 2]> = runs
        .iter()
        .filter(|(n, _)| *n == "square")
        .flat_map(|(_, m)| m.iter())
        .filter_map(|m| Some([m.scanline_deg?, m.truth]))
        .collect();
    let legs = |pick: fn(&MoveResult) -> Option<f64>| -> Vec<[f64; 2]> {
        runs.iter()
            .filter(|(n, _)| *n != "square")
            .flat_map(|(_, m)| m.iter())
            .filter_map(|m| Some([pick(m)? / INCH_MM, m.truth / INCH_MM]))
            .collect()
    };
    ForwardSummary {
        square_turns_deg: turns,
        lk_legs_in: legs(|m| m.lk_mm),
        ncc_legs_in: legs(|m| m.ncc_mm),
        avoidance: avoidance.to_vec(),
    }
}

/// `forward.md`: the paper's figures beside ours.
pub fn forward_table(summary: &ForwardSummary) -> String {
    let mut md = String::from("# E6: forward camera (Ahmed, Saatchi and Caparrelli)\n\n");
    md.push_str("## Square path (Fig. 8): turns read by the scan line\n\n");
    md.push_str("| turn | paper read (deg) | ours read (deg) | ours true (deg) | error (deg) |\n");
    md.push_str("|---:|---:|---:|---:|---:|\n");
    for (k, t) in summary.square_turns_deg.iter().enumerate() {
        let paper = PAPER_TURNS_DEG.get(k).copied().unwrap_or(f64::NAN);
        let _ = writeln!(
            md,
            "| {} | {paper:.1} | {:.2} | {:.2} | {:+.2} |",
            k + 1,
            t[0],
            t[1],
            t[0] - t[1]
        );
    }
    md.push_str("\n## Fig. 10: straight legs (inches)\n\n");
    md.push_str(
        "| test, leg | paper true | paper LK | paper NCC | ours true | ours LK | ours NCC |\n",
    );
    md.push_str("|---|---:|---:|---:|---:|---:|---:|\n");
    let (lk, ncc) = (&summary.lk_legs_in, &summary.ncc_legs_in);
    for (k, (l, n)) in lk.iter().zip(ncc).enumerate() {
        let (pt, pl, pn) = PAPER_LEGS_IN
            .get(k)
            .copied()
            .unwrap_or((f64::NAN, f64::NAN, f64::NAN));
        let pct = |v: f64| 100.0 * (v - l[1]) / l[1];
        let _ = writeln!(
            md,
            "| {}, {} | {pt} | {pl} | {pn} | {:.2} | {:.2} ({:+.1}%) | {:.2} ({:+.1}%) |",
            k / 2 + 1,
            k % 2 + 1,
            l[1],
            l[0],
            pct(l[0]),
            n[0],
            pct(n[0])
        );
    }
    md.push_str("\n## Avoidance among eight obstacles\n\n");
    md.push_str("| method | contacts | distance (m) | frames/s (closed loop) | paper frames/s |\n");
    md.push_str("|---|---:|---:|---:|---:|\n");
    for a in &summary.avoidance {
        let method = &a.method;
        let paper = if method == "segmentation" { 2.46 } else { 3.5 };
        let _ = writeln!(
            md,
            "| {method} | {} | {:.1} | {:.0} | {paper} |",
            a.contacts,
            a.distance_mm / 1000.0,
            a.fps
        );
    }
    md.push_str(
        "\nOurs: CPU renderer, 160 x 120 camera 100 mm up tilted 25 degrees down; frames/s are \
         whole closed-loop cycles (rendering included) on this machine; the paper's are its \
         Blackfin's. Figure: forward.png (true and visual odometry paths).\n",
    );
    md
}

/// `omniloop replay forward`.
pub const REPLAY: Replay = Replay {
    name: "forward",
    title: "E6: forward camera avoidance (segmentation, flow) and visual odometry (Figs. 8, 10)",
    run: replay,
};
