//! E2, self-localization at places (Sekimori et al., Sect. 5.2, Fig. 8): the robot is carried
//! to each place, told nothing of where it is, and localizes itself from `frames_per_place`
//! frames with fresh sensor noise; each place is scored by its RMS errors. Its replay,
//! `selfloc`, runs the six places on the Small-Size field.

use super::experiment::{Experiment, ExperimentEntry, ExperimentSetup, MetricKeys, Metrics, setup};
use super::localization_map::map_table;
use super::replay::{Replay, ReplayContext, write_text};
use crate::report::output::write_run;
use crate::report::topview::{Marker, Panel, PathLayer, draw_panels};
use crate::run::record::Summary;
use crate::run::{RunError, RunOutput, Simulation};
use crate::scenario::{PoseChecks, Problems};
use crate::scenario::{PoseSpec, Scenario};
use anyhow::Context;
use nalgebra::{Isometry2, Point2};
use omniloop_control::wrap_pi;
use omniloop_robot::Measurement;
use omniloop_robot::perception::floor_localization;
use omniloop_vision::{LocalizationConfig, LocalizationMethod};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;

/// The stage whose fixes E2 scores.
const STAGE: &str = floor_localization::NAME;

/// The places (`[experiment.places]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlacesSpec {
    /// The places (field frame).
    pub places: Vec<PoseSpec>,
    /// Frames (pose estimates) at each place.
    #[serde(default = "default_frames_per_place")]
    pub frames_per_place: u32,
}

fn default_frames_per_place() -> u32 {
    10
}

impl PlacesSpec {
    fn validate(&self, s: &Scenario, c: &mut Problems) {
        if self.places.is_empty() {
            c.fail("experiment.places.places", "needs at least one place");
        }
        if self.frames_per_place == 0 {
            c.fail("experiment.places.frames_per_place", "must be >= 1");
        }
        for (i, p) in self.places.iter().enumerate() {
            c.pose_in_world(
                &format!("experiment.places.places[{i}]"),
                p,
                s.robot.radius_mm,
                &s.world,
            );
        }
        if s.control.pose_source != floor_localization::POSE_SOURCE {
            c.fail(
                "experiment.places",
                "the robot localizes itself at each place: set control.pose_source = \
                 \"localization\"",
            );
        }
    }
}

/// The registry's entry: `[experiment.places]`.
pub const ENTRY: ExperimentEntry = ExperimentEntry {
    name: "places",
    summary: "E2 of the corner paper (Sect. 5.2): self-localization at places on the field",
    setup: |t| setup::<PlacesSpec>(t, "places"),
};

impl ExperimentSetup for PlacesSpec {
    fn check(&self, s: &Scenario, c: &mut Problems) {
        self.validate(s, c);
    }

    fn table(&self, summary: &Summary) -> Option<String> {
        Some(places_table(summary))
    }

    fn procedure(&self, s: &Scenario) -> Result<Box<dyn Experiment>, RunError> {
        let config: LocalizationConfig = s.vision.table("localization")?;
        Ok(Box::new(Places::new(self, config.method)))
    }
}

/// Self-localization at one place.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlaceResult {
    /// The true pose: x_mm, y_mm, theta_deg.
    pub true_pose: [f64; 3],
    /// RMS distance of the localized estimates from the true position.
    pub rms_position_mm: f64,
    /// RMS heading error of the localized estimates.
    pub rms_heading_deg: f64,
    /// Estimates that took the wrong one of the two half-turn solutions.
    pub ambiguity_errors: usize,
    /// Frames taken here.
    pub frames: usize,
    /// Frames that gave no estimate.
    pub not_localized: usize,
}

/// Sums of one place's scores.
#[derive(Debug, Default)]
struct Tally {
    sq_position: f64,
    sq_heading: f64,
    localized: usize,
    ambiguous: usize,
    missing: usize,
}

impl Tally {
    /// Scores the fix of one frame against the true pose.
    fn add(&mut self, fix: Option<&Measurement>, truth: &Isometry2<f64>) {
        let Some(Measurement::Pose {
            pose, alternative, ..
        }) = fix
        else {
            self.missing += 1;
            return;
        };
        let err = |q: &Isometry2<f64>| (q.translation.vector - truth.translation.vector).norm();
        if alternative.is_some_and(|a| err(&a) < err(pose)) {
            self.ambiguous += 1;
        }
        let dh = wrap_pi(pose.rotation.angle() - truth.rotation.angle());
        self.sq_position += err(pose).powi(2);
        self.sq_heading += dh.powi(2);
        self.localized += 1;
    }

    fn result(&self, place: &PoseSpec, frames: usize) -> PlaceResult {
        let rms = |sq: f64| {
            if self.localized > 0 {
                (sq / self.localized as f64).sqrt()
            } else {
                f64::NAN
            }
        };
        PlaceResult {
            true_pose: [place.x_mm, place.y_mm, place.heading_deg],
            rms_position_mm: rms(self.sq_position),
            rms_heading_deg: rms(self.sq_heading).to_degrees(),
            ambiguity_errors: self.ambiguous,
            frames,
            not_localized: self.missing,
        }
    }
}

/// The procedure and metrics of E2.
pub struct Places {
    spec: PlacesSpec,
    method: LocalizationMethod,
    results: Vec<PlaceResult>,
}

impl Places {
    /// E2 at the places of `spec`, localizing with `method`.
    pub fn new(spec: &PlacesSpec, method: LocalizationMethod) -> Self {
        Self {
            spec: spec.clone(),
            method,
            results: Vec::new(),
        }
    }
}

/// How E2 localized (`summary.json`: `localization`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlacesMethod {
    /// The method of `[vision.localization]`.
    pub method: LocalizationMethod,
    /// The mode: every frame from no prior.
    pub mode: String,
}

impl Experiment for Places {
    fn drives(&self) -> bool {
        false
    }

    /// Carries the robot to each place and has it localize itself there `frames_per_place`
    /// times, each time from nothing: it is told it was moved and nothing else (no prior).
    /// Only frames taken at the place count (`frames` of the place's result says how many).
    fn run(
        &mut self,
        sim: &mut Simulation,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<(), RunError> {
        let frames = self.spec.frames_per_place as usize;
        let total = (self.spec.places.len() * frames) as u64;
        for place in &self.spec.places {
            let truth = place.isometry();
            sim.place_robot(truth);
            let set_down_s = sim.world().time_s();
            let mut tally = Tally::default();
            let (mut taken, mut cycles) = (0, 0);
            // A cycle whose frame was lost, or taken before the robot was set down (a late
            // frame), is no frame taken at the place: the robot takes another, up to ten
            // cycles a frame.
            while taken < frames && cycles < 10 * frames {
                cycles += 1;
                sim.robot_mut().forget_pose();
                sim.sense()?;
                let fresh = sim.frames().iter().any(|f| f.t_s >= set_down_s);
                sim.act()?;
                if !fresh {
                    continue;
                }
                taken += 1;
                let fix = sim
                    .last_estimates()
                    .and_then(|e| e.pose_fix(STAGE))
                    .map(|f| &f.measurement);
                tally.add(fix, &truth);
                progress(sim.cycle(), total);
            }
            self.results.push(tally.result(place, taken));
        }
        Ok(())
    }

    fn metrics(&self, _out: &RunOutput) -> MetricKeys {
        PlacesMetrics {
            places: self.results.clone(),
            localization: PlacesMethod {
                method: self.method,
                mode: "global".into(),
            },
        }
        .keys()
    }
}

/// E2's metrics (`summary.json`: `places`, `localization`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlacesMetrics {
    /// Per place, in the order of `[experiment.places]`.
    pub places: Vec<PlaceResult>,
    /// How it localized.
    pub localization: PlacesMethod,
}

impl Metrics for PlacesMetrics {}

/// The per-place results of a summary (`places`), empty without them.
pub fn place_results(m: &Summary) -> Vec<PlaceResult> {
    PlacesMetrics::of(m).map(|p| p.places).unwrap_or_default()
}

/// `omniloop replay selfloc`.
pub const REPLAY: Replay = Replay {
    name: "selfloc",
    title: "E2: floor-region self-localization at six places on the field (Fig. 8), and its \
            error map over the whole field",
    run: replay,
};

/// The E2 scenario file, built into the binary.
pub const SCENARIO: (&str, &str) = (
    "scenarios/selfloc_field.toml",
    include_str!("../../scenarios/selfloc_field.toml"),
);

/// The error map's scenario file, built into the binary.
pub const MAP_SCENARIO: (&str, &str) = (
    "scenarios/selfloc_map.toml",
    include_str!("../../scenarios/selfloc_map.toml"),
);

/// Runs E2, writes the run into `out/`, the places with their errors (like Fig. 8) into
/// `places.png` and the table into `places.md`; then the error map over the whole field,
/// its run into `out/map/`, its figure and rows into `selfloc_map.png` and `selfloc_map.csv`
/// and its table into `selfloc_map.md`.
fn replay(ctx: &mut ReplayContext<'_>) -> anyhow::Result<String> {
    let out = ctx.out.to_path_buf();
    let run = ctx.run("selfloc_field", SCENARIO.0, SCENARIO.1, &out)?;
    draw_places(&out.join("places.png"), &run.scenario, &run.output)?;
    let md = places_table(&run.output.summary);
    write_text(&out.join("places.md"), &md)?;

    let mut map = ctx.simulate("selfloc_map", MAP_SCENARIO.0, MAP_SCENARIO.1)?;
    // The map's own files go to the top, where a user looks first; the rest of its run below.
    let files = std::mem::take(&mut map.output.files);
    write_run(&out.join("map"), &map.scenario, &map.output)?;
    for f in files {
        let path = out.join(&f.name);
        std::fs::write(&path, &f.bytes).with_context(|| format!("writing {}", path.display()))?;
    }
    let map_md = map_table(&map.output.summary);
    write_text(&out.join("selfloc_map.md"), &map_md)?;
    Ok(format!("{md}\n{map_md}"))
}

/// Fig. 8: the field with its cubes, each place with the robot's outline, its estimates, and
/// its RMS errors written beside it.
fn draw_places(file: &Path, scenario: &Scenario, out: &RunOutput) -> anyhow::Result<()> {
    let estimates: Vec<Point2<f64>> = out
        .trajectory
        .iter()
        .filter_map(|r| Some(Point2::new(r.est_x_mm?, r.est_y_mm?)))
        .collect();
    let markers = place_results(&out.summary)
        .iter()
        .enumerate()
        .map(|(k, p)| Marker {
            at: Point2::new(p.true_pose[0], p.true_pose[1]),
            radius_mm: scenario.robot.radius_mm,
            rgb: [20, 20, 20],
            label: format!(
                "{}: {:.1} mm, {:.2} deg",
                k + 1,
                p.rms_position_mm,
                p.rms_heading_deg
            ),
        })
        .collect();
    let panel = Panel {
        title: format!("{}: RMS error at each place", scenario.name),
        layout: &scenario.world,
        paths: vec![PathLayer {
            label: "estimates".into(),
            rgb: [30, 80, 230],
            points: &estimates,
            dots: true,
            discs: None,
        }],
        markers,
        spots: Vec::new(),
        grid: None,
    };
    draw_panels(file, &[panel], 1100)?;
    Ok(())
}

/// E2 per place as a Markdown table.
pub fn places_table(m: &Summary) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# E2: self-localization on the field\n");
    let method = PlacesMetrics::of(m).map_or("-", |p| match p.localization.method {
        LocalizationMethod::Paper => "the paper's (Sect. 4, steps 1-7, as published)",
        LocalizationMethod::Robust => "robust (boundary points, decision rule)",
    });
    let _ = writeln!(
        s,
        "Renderer: {}. Seed {}. Method: {method}. Global mode: every frame from no prior. \
         Paper: errors of \"dozens of mm\" at each place.\n",
        m.renderer.clone().unwrap_or_else(|| "-".into()),
        m.seed
    );
    let _ = writeln!(
        s,
        "| place | x_mm | y_mm | theta_deg | frames | not localized | RMS position (mm) | RMS heading (deg) | ambiguity errors |"
    );
    let _ = writeln!(s, "|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (k, p) in place_results(m).iter().enumerate() {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {:.1} | {:.2} | {} |",
            k + 1,
            p.true_pose[0],
            p.true_pose[1],
            p.true_pose[2],
            p.frames,
            p.not_localized,
            p.rms_position_mm,
            p.rms_heading_deg,
            p.ambiguity_errors
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::experiment::tests::round_trip;
    use nalgebra::Vector2;

    /// A place's result from its tally: two fixes 3 mm and 4 mm off, one frame lost.
    fn place_result() -> PlaceResult {
        let place = PoseSpec {
            x_mm: 500.0,
            y_mm: -250.0,
            heading_deg: 90.0,
        };
        let truth = place.isometry();
        let mut tally = Tally::default();
        for dx in [3.0, 4.0] {
            let pose = Isometry2::new(truth.translation.vector + Vector2::new(dx, 0.0), 1.6);
            let fix = Measurement::Pose {
                pose,
                alternative: None,
                unambiguous: true,
            };
            tally.add(Some(&fix), &truth);
        }
        tally.add(None, &truth);
        tally.result(&place, 3)
    }

    #[test]
    fn the_metrics_read_back_from_the_summary_for_the_table_and_the_places() {
        let m = PlacesMetrics {
            places: vec![place_result()],
            localization: PlacesMethod {
                method: LocalizationMethod::Robust,
                mode: "global".into(),
            },
        };
        let summary = round_trip(&m);
        let keys: Vec<&String> = summary.experiment.keys().collect();
        assert_eq!(keys, ["places", "localization"]);
        let places = place_results(&summary);
        assert_eq!(places, m.places);
        assert_eq!((places[0].frames, places[0].not_localized), (3, 1));
        assert!((places[0].rms_position_mm - 12.5f64.sqrt()).abs() < 1e-9);
        assert!(places_table(&summary).contains("Method: robust"));
    }
}
