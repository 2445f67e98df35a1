//! E5, three-mark resection (Ishikawa, Kikuchi and Kato, Sect. 3-4, Table 1): the robot is
//! carried to each place and told nothing; it pans its camera from right to left until it has
//! found the three striped marks, computes where it is, and moves to look again if a mark is
//! hidden. Each place is scored by the distance of that one fix from the true position at the
//! moment of the fix. Its replay, `resection`, runs the ten places of Table 1 and a place
//! behind a cabinet with the panning camera, then again with an omnidirectional camera.

use super::experiment::{Experiment, ExperimentEntry, ExperimentSetup, MetricKeys, Metrics, setup};
use super::replay::{Replay, ReplayContext, write_text};
use crate::report::output::write_run;
use crate::report::topview::{Mark, Marker, Panel, Spots, panels_png};
use crate::run::record::Summary;
use crate::run::{OutputFile, RunError, RunOutput, Simulation};
use crate::scenario::{PoseChecks, Problems};
use crate::scenario::{PoseSpec, Scenario};
use nalgebra::Point2;
use omniloop_control::wrap_pi;
use omniloop_robot::Measurement;
use omniloop_robot::perception::resection::{GAVE_UP, NAME, POSE_SOURCE};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// The places (`[experiment.resection]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ResectionSpec {
    /// The places the robot is carried to (world frame).
    pub places: Vec<PoseSpec>,
    /// The longest the robot may take at one place, s.
    #[serde(default = "default_timeout")]
    pub timeout_s: f64,
}

fn default_timeout() -> f64 {
    120.0
}

impl ResectionSpec {
    fn validate(&self, s: &Scenario, c: &mut Problems) {
        if self.places.is_empty() {
            c.fail("experiment.resection.places", "needs at least one place");
        }
        c.positive("experiment.resection.timeout_s", self.timeout_s);
        for (i, p) in self.places.iter().enumerate() {
            c.pose_in_world(
                &format!("experiment.resection.places[{i}]"),
                p,
                s.robot.radius_mm,
                &s.world,
            );
        }
        if s.control.pose_source != POSE_SOURCE {
            c.fail(
                "control.pose_source",
                "experiment.resection scores the resection stage: set pose_source = \
                 \"resection\"",
            );
        }
    }
}

/// The registry's entry: `[experiment.resection]`.
pub const ENTRY: ExperimentEntry = ExperimentEntry {
    name: "resection",
    summary: "E5 of Ishikawa, Kikuchi and Kato: three-mark resection at places",
    setup: |t| setup::<ResectionSpec>(t, "resection"),
};

impl ExperimentSetup for ResectionSpec {
    fn check(&self, s: &Scenario, c: &mut Problems) {
        self.validate(s, c);
    }

    fn table(&self, summary: &Summary) -> Option<String> {
        Some(resection_table(&[summary]))
    }

    fn procedure(&self, s: &Scenario) -> Result<Box<dyn Experiment>, RunError> {
        Ok(Box::new(Resection::new(self, s)))
    }
}

/// Self-location at one place (`summary.json`: `places`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlaceResult {
    /// Where the robot was carried to, cm.
    pub place_cm: [f64; 2],
    /// Where it truly was when it located itself (the place, unless it moved), cm.
    pub true_cm: [f64; 2],
    /// Where it computed it was, cm; `None` when it did not locate itself.
    pub estimate_cm: Option<[f64; 2]>,
    /// Distance of the estimate from the truth, cm.
    pub error_cm: Option<f64>,
    /// Heading error, degrees.
    pub heading_error_deg: Option<f64>,
    /// Time from being set down to the fix (turning the camera to its stop, the pans and any
    /// moves), s.
    pub pan_search_s: f64,
    /// Whether it moved to another observation point.
    pub moved: bool,
    /// Why it did not locate itself, if it did not.
    pub failure: Option<String>,
}

/// The procedure and metrics of E5.
pub struct Resection {
    spec: ResectionSpec,
    camera: String,
    results: Vec<PlaceResult>,
}

impl Resection {
    /// E5 at the places of `spec`, seen by vision's camera of `s`.
    pub fn new(spec: &ResectionSpec, s: &Scenario) -> Self {
        Self {
            spec: spec.clone(),
            camera: s
                .sensor(s.vision.sensor.as_deref())
                .map_or_else(|_| "-".into(), |c| c.name.clone()),
            results: Vec::new(),
        }
    }

    /// Carries the robot to `place` and runs cycles until it locates itself, gives up, or the
    /// time is up.
    fn locate(
        sim: &mut Simulation,
        place: &PoseSpec,
        timeout_s: f64,
    ) -> Result<PlaceResult, RunError> {
        let truth = place.isometry();
        sim.place_robot(truth);
        sim.robot_mut().forget_pose();
        let period = sim.scenario().run.control_period_s;
        let max = (timeout_s / period).ceil() as u64;
        let cm = |p: Point2<f64>| [p.x / 10.0, p.y / 10.0];
        let (mut k, mut fix, mut gave_up) = (0, None, None);
        while fix.is_none() && gave_up.is_none() && k < max.max(1) {
            sim.step()?;
            k += 1;
            if let Some(est) = sim.last_estimates() {
                fix = est.pose_fix(NAME).map(|f| f.measurement);
                gave_up = est
                    .not_found(NAME)
                    .filter(|r| r.contains(GAVE_UP))
                    .map(str::to_string);
            }
        }
        // The fix is of the image taken at the start of the cycle, before the world moved.
        let now = sim.last_truth_pose().unwrap_or(truth);
        let mut r = PlaceResult {
            place_cm: cm(truth.translation.vector.into()),
            true_cm: cm(now.translation.vector.into()),
            estimate_cm: None,
            error_cm: None,
            heading_error_deg: None,
            pan_search_s: k as f64 * period,
            moved: (now.translation.vector - truth.translation.vector).norm() > 10.0,
            failure: gave_up,
        };
        if let Some(Measurement::Pose { pose, .. }) = fix {
            let e = pose.translation.vector - now.translation.vector;
            r.estimate_cm = Some(cm(pose.translation.vector.into()));
            r.error_cm = Some(e.norm() / 10.0);
            r.heading_error_deg =
                Some(wrap_pi(pose.rotation.angle() - now.rotation.angle()).to_degrees());
        } else if r.failure.is_none() {
            r.failure = Some(format!("not located within {timeout_s} s"));
        }
        Ok(r)
    }
}

impl Experiment for Resection {
    fn drives(&self) -> bool {
        false
    }

    fn run(
        &mut self,
        sim: &mut Simulation,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<(), RunError> {
        let n = self.spec.places.len() as u64;
        for (k, place) in self.spec.places.iter().enumerate() {
            self.results
                .push(Self::locate(sim, place, self.spec.timeout_s)?);
            progress(k as u64 + 1, n);
        }
        Ok(())
    }

    fn metrics(&self, _out: &RunOutput) -> MetricKeys {
        ResectionMetrics::new(&self.camera, &self.results).keys()
    }

    fn files(&self, scenario: &Scenario, _out: &RunOutput) -> Result<Vec<OutputFile>, RunError> {
        let bytes = figure(scenario, &self.camera, &self.results)
            .map_err(|e| RunError::Sim(omniloop_sim::SimError::Invalid(e.to_string())))?;
        Ok(vec![OutputFile {
            name: "resection.png".into(),
            bytes,
        }])
    }
}

/// E5's metrics (`summary.json`: a key per field).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResectionMetrics {
    /// The camera that located the robot.
    pub camera: String,
    /// Per place, in the order of `[experiment.resection]`.
    pub places: Vec<PlaceResult>,
    /// The largest position error of the places located, cm (`None`: none was).
    pub max_error_cm: Option<f64>,
    /// Places located.
    pub located: usize,
}

impl ResectionMetrics {
    /// The metrics of the places' `results` with `camera`.
    pub fn new(camera: &str, results: &[PlaceResult]) -> Self {
        Self {
            camera: camera.to_string(),
            places: results.to_vec(),
            max_error_cm: results
                .iter()
                .filter_map(|r| r.error_cm)
                .fold(None, |m: Option<f64>, e| Some(m.map_or(e, |m| m.max(e)))),
            located: results.iter().filter(|r| r.error_cm.is_some()).count(),
        }
    }
}

impl Metrics for ResectionMetrics {}

/// The per-place results of a summary (`places`), empty without them.
pub fn place_results(m: &Summary) -> Vec<PlaceResult> {
    ResectionMetrics::of(m)
        .map(|r| r.places)
        .unwrap_or_default()
}

/// The top view of the lab: the marks, each place with the robot's outline and its error, and
/// where the robot computed it was.
fn figure(
    s: &Scenario,
    camera: &str,
    results: &[PlaceResult],
) -> Result<Vec<u8>, crate::report::topview::FigureError> {
    let mm = |c: [f64; 2]| Point2::new(c[0] * 10.0, c[1] * 10.0);
    let markers = results
        .iter()
        .enumerate()
        .map(|(k, r)| Marker {
            at: mm(r.true_cm),
            radius_mm: s.robot.radius_mm,
            rgb: [20, 20, 20],
            label: match r.error_cm {
                Some(e) => format!(
                    "{}: {e:.1} cm{}",
                    k + 1,
                    if r.moved { " (moved)" } else { "" }
                ),
                None => format!("{}: not located", k + 1),
            },
        })
        .collect();
    let map = s.robot_map();
    let marks: Vec<Point2<f64>> = map.marks.iter().map(|m| m.centre_mm).collect();
    let estimates: Vec<Point2<f64>> = results
        .iter()
        .filter_map(|r| r.estimate_cm.map(mm))
        .collect();
    let moves: Vec<Point2<f64>> = results
        .iter()
        .filter(|r| r.moved)
        .map(|r| mm(r.place_cm))
        .collect();
    let panel = Panel {
        title: format!("{}: three-mark resection with camera {camera:?}", s.name),
        layout: &s.world,
        paths: Vec::new(),
        markers,
        spots: vec![
            Spots {
                label: "marks O, P, Q".into(),
                rgb: [200, 30, 30],
                points: marks,
                mark: Mark::Disc,
                size_px: 7,
            },
            Spots {
                label: "set down here, moved".into(),
                rgb: [240, 150, 0],
                points: moves,
                mark: Mark::Cross,
                size_px: 6,
            },
            Spots {
                label: "estimates".into(),
                rgb: [30, 80, 230],
                points: estimates,
                mark: Mark::Cross,
                size_px: 5,
            },
        ],
        grid: None,
    };
    panels_png("resection.png", &[panel], 1000)
}

/// Table 1 of the paper: the true places and the positions the real robot computed, cm.
pub const TABLE_1: [([f64; 2], [f64; 2]); 10] = [
    ([91.0, 61.0], [93.0, 60.0]),
    ([164.0, 245.0], [168.0, 238.0]),
    ([164.0, 138.0], [166.0, 135.0]),
    ([164.0, 61.0], [165.0, 56.0]),
    ([256.0, 245.0], [260.0, 243.0]),
    ([256.0, 138.0], [252.0, 129.0]),
    ([256.0, 61.0], [257.0, 61.0]),
    ([340.0, 245.0], [342.0, 244.0]),
    ([340.0, 138.0], [347.0, 140.0]),
    ([340.0, 61.0], [344.0, 72.0]),
];

/// The paper's observed position at place `p` (cm), when `p` is one of Table 1's.
fn paper_observed(p: [f64; 2]) -> Option<[f64; 2]> {
    TABLE_1
        .iter()
        .find(|(t, _)| (t[0] - p[0]).abs() < 0.5 && (t[1] - p[1]).abs() < 0.5)
        .map(|(_, o)| *o)
}

/// E5 as a Markdown table: Table 1 side by side with each run in `runs` (the panning camera,
/// then the omnidirectional one), places beyond Table 1 after it.
pub fn resection_table(runs: &[&Summary]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# E5: three-mark resection (Table 1)\n");
    let Some(first) = runs.first() else {
        return s;
    };
    let camera = |m: &Summary| ResectionMetrics::of(m).map_or("-".into(), |r| r.camera);
    let _ = writeln!(
        s,
        "Renderer: {}. Seed {}. Cameras: {}. Positions in cm; error = distance from the true \
         position at the moment of the fix. Paper: the real robot, errors up to 11 cm.\n",
        first.renderer.clone().unwrap_or_else(|| "-".into()),
        first.seed,
        runs.iter()
            .map(|m| camera(m))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let mut head = "| place | true | paper observed | paper error |".to_string();
    let mut rule = "|---:|---|---|---:|".to_string();
    for m in runs {
        let c = camera(m);
        let _ = write!(head, " {c}: ours | {c}: error | {c}: search (s) |");
        rule.push_str("---|---:|---:|");
    }
    let _ = writeln!(s, "{head}\n{rule}");
    let results: Vec<Vec<PlaceResult>> = runs.iter().map(|m| place_results(m)).collect();
    write_place_rows(&mut s, &results);
    s.push('\n');
    for m in runs {
        let r = ResectionMetrics::of(m);
        let max = r
            .as_ref()
            .and_then(|r| r.max_error_cm)
            .map_or("-".into(), |e| format!("{e:.2} cm"));
        let located = r.as_ref().map_or(0, |r| r.located);
        let _ = writeln!(
            s,
            "- {}: located at {located} of {} places, largest error {max}.",
            camera(m),
            place_results(m).len()
        );
    }
    s
}

/// The table's rows into `s`, a place a row: Table 1's true and observed position and error,
/// then each run's estimate, error and search time (`results`: each run's places).
fn write_place_rows(s: &mut String, results: &[Vec<PlaceResult>]) {
    let n = results.iter().map(Vec::len).max().unwrap_or(0);
    let pt = |p: [f64; 2]| format!("({:.0}, {:.0})", p[0], p[1]);
    for k in 0..n {
        let Some(place) = results.iter().find_map(|r| r.get(k)).map(|r| r.place_cm) else {
            continue;
        };
        let (obs, err) = match paper_observed(place) {
            Some(o) => (
                pt(o),
                format!("{:.1}", (o[0] - place[0]).hypot(o[1] - place[1])),
            ),
            None => ("-".into(), "-".into()),
        };
        let _ = write!(s, "| {} | {} | {obs} | {err} |", k + 1, pt(place));
        for r in results {
            match r.get(k) {
                Some(r) => {
                    let ours = r.estimate_cm.map_or("not located".into(), |e| {
                        format!(
                            "({:.1}, {:.1}){}",
                            e[0],
                            e[1],
                            if r.moved { " moved" } else { "" }
                        )
                    });
                    let err = r.error_cm.map_or("-".into(), |e| format!("{e:.2}"));
                    let _ = write!(s, " {ours} | {err} | {:.1} |", r.pan_search_s);
                }
                None => s.push_str(" - | - | - |"),
            }
        }
        s.push('\n');
    }
}

/// `omniloop replay resection`.
pub const REPLAY: Replay = Replay {
    name: "resection",
    title: "E5: three-mark resection with a panning camera at the places of Table 1, and with \
            an omnidirectional camera",
    run: replay,
};

/// The E5 scenario file, built into the binary.
pub const SCENARIO: (&str, &str) = (
    "scenarios/resection_lab.toml",
    include_str!("../../scenarios/resection_lab.toml"),
);

/// The omnidirectional camera of the E5 scenario.
pub const OMNI_CAMERA: &str = "omni";

/// Runs E5 with the panning camera into `out/` (with `resection.png`), again with the
/// omnidirectional camera into `out/omni/`, and writes both beside Table 1 into
/// `resection.md`.
fn replay(ctx: &mut ReplayContext<'_>) -> anyhow::Result<String> {
    let out = ctx.out.to_path_buf();
    let pan = ctx.run("resection_lab", SCENARIO.0, SCENARIO.1, &out)?;
    let omni = ctx.simulate_edited("resection_omni", SCENARIO.0, SCENARIO.1, |s| {
        s.vision.sensor = Some(OMNI_CAMERA.into());
        s.name = "resection_omni".into();
        Ok(())
    })?;
    write_run(&out.join("omni"), &omni.scenario, &omni.output)?;
    let md = resection_table(&[&pan.output.summary, &omni.output.summary]);
    write_text(&out.join("resection.md"), &md)?;
    Ok(md)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::experiment::tests::round_trip;

    /// A place's result: located `error_cm` off, or not located.
    fn result(place_cm: [f64; 2], error_cm: Option<f64>) -> PlaceResult {
        PlaceResult {
            place_cm,
            true_cm: place_cm,
            estimate_cm: error_cm.map(|e| [place_cm[0] + e, place_cm[1]]),
            error_cm,
            heading_error_deg: error_cm.map(|_| 0.5),
            pan_search_s: 12.0,
            moved: false,
            failure: error_cm.is_none().then(|| GAVE_UP.to_string()),
        }
    }

    #[test]
    fn the_metrics_read_back_from_the_summary_for_the_table() {
        let results = [
            result([100.0, 200.0], Some(1.25)),
            result([300.0, 50.0], None),
            result([150.0, 120.0], Some(0.5)),
        ];
        let m = ResectionMetrics::new("pan", &results);
        assert_eq!((m.max_error_cm, m.located), (Some(1.25), 2));
        let summary = round_trip(&m);
        let keys: Vec<&String> = summary.experiment.keys().collect();
        assert_eq!(keys, ["camera", "places", "max_error_cm", "located"]);
        assert_eq!(place_results(&summary), results);
        let table = resection_table(&[&summary]);
        assert!(
            table.contains("- pan: located at 2 of 3 places, largest error 1.25 cm."),
            "{table}"
        );
        let none = ResectionMetrics::new("omni", &[]);
        assert_eq!((none.max_error_cm, none.located), (None, 0));
        round_trip(&none);
    }
}
