//! The ball map as an experiment (`[experiment.ball_map]`): any scenario with a mirror camera
//! runs it with `omniloop run`, and the robustness replay scores it at every level of its knobs.

use super::measure::{self, Measured};
use super::report;
use super::spec::BallMapSpec;
use super::stats::{BallMapFigures, BallMapMetrics, CameraMap, FalseBalls};
use crate::experiments::{Experiment, ExperimentEntry, ExperimentSetup, MetricKeys, Metrics};
use crate::run::{OutputFile, RunError, RunOutput, Simulation, Summary};
use crate::scenario::{Problems, Scenario};

/// The registry's entry: `[experiment.ball_map]`.
pub const ENTRY: ExperimentEntry = ExperimentEntry {
    name: "ball_map",
    summary: "the ball detector's error map: the ball at rings of distances all round the \
              robot, and false balls in ball-free frames",
    setup: |t| crate::experiments::experiment::setup::<BallMapSpec>(t, "ball_map"),
};

impl ExperimentSetup for BallMapSpec {
    fn check(&self, s: &Scenario, c: &mut Problems) {
        self.validate(s, c);
    }

    fn takes_frames(&self) -> bool {
        true
    }

    fn table(&self, summary: &Summary) -> Option<String> {
        let f = BallMapMetrics::of(summary)?.ball_map;
        let mut out = String::new();
        if let Some(m) = &f.map {
            out += &report::summary_table(std::slice::from_ref(m));
            out += "\n";
            out += &report::camera_table(m);
        }
        if let Some(b) = &f.false_balls {
            out += &report::false_ball_line(&summary.scenario, b);
            out += "\n";
        }
        Some(out)
    }

    fn procedure(&self, _s: &Scenario) -> Result<Box<dyn Experiment>, RunError> {
        Ok(Box::new(BallMap {
            spec: self.clone(),
            measured: None,
        }))
    }
}

/// The procedure and its frames.
pub struct BallMap {
    spec: BallMapSpec,
    measured: Option<Measured>,
}

impl BallMap {
    /// The figures of the frames taken.
    fn figures(&self) -> Option<BallMapFigures> {
        let m = self.measured.as_ref()?;
        Some(BallMapFigures {
            map: CameraMap::of(m, self.spec.target_range_mm),
            false_balls: FalseBalls::of(m),
        })
    }
}

impl Experiment for BallMap {
    fn drives(&self) -> bool {
        false
    }

    /// Every frame of the map, at placed poses.
    fn run(
        &mut self,
        sim: &mut Simulation,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<(), RunError> {
        self.measured = Some(measure::run(sim, &self.spec, progress)?);
        Ok(())
    }

    fn metrics(&self, _out: &RunOutput) -> MetricKeys {
        self.figures()
            .map(|ball_map| BallMapMetrics { ball_map }.keys())
            .unwrap_or_default()
    }

    fn files(&self, _scenario: &Scenario, _out: &RunOutput) -> Result<Vec<OutputFile>, RunError> {
        let Some(m) = &self.measured else {
            return Ok(Vec::new());
        };
        Ok(vec![OutputFile {
            name: "ball_map.csv".into(),
            bytes: report::csv(&m.camera, &m.rows).into_bytes(),
        }])
    }
}
