//! The goals on the robot's own camera: the azimuths each goal's colour covers
//! ([`omniloop_vision::goal`]), turned to the robot's heading now (a late frame's bearings
//! moved by the turn odometry measured since it was taken). The widest run of a goal is the
//! widest open part of its mouth.

use super::stage::{Belief, CameraNeed, FloorOptics, Perceived, PoseHistory, Stage, StageEntry};
use crate::RobotError;
use crate::boundary::Observation;
use crate::config::RobotConfig;
use crate::estimates::NotFound;
use crate::percept::Percept;
use omniloop_problem::Problems;
use omniloop_vision::goal::{Chroma, GoalRun, goal_runs_forward, goal_runs_mirror};
use serde::{Deserialize, Serialize};

/// The stage's name, in the estimates record and the registry.
pub const NAME: &str = "goal";

/// Its settings table, `[vision.goal]`.
const TABLE: &str = "goal";

/// The registry's entry.
pub const ENTRY: StageEntry = StageEntry {
    name: NAME,
    summary: "the goals by their colours: the azimuths each covers, the widest open part first",
    pose_source: None,
    table: None,
    vision_table: Some(TABLE),
    check_vision: |v| v.tables.check("vision", TABLE, check_values),
    asked: |_| false,
    camera: CameraNeed::MirrorOrForward,
    world: &[],
    check: |_| Vec::new(),
    build: |c| Ok(Box::new(GoalStage::new(c)?)),
};

/// `[vision.goal]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GoalSettings {
    /// The colour of the goal at +x (the league's yellow).
    pub pos_x: Chroma,
    /// The colour of the goal at -x (the league's blue).
    pub neg_x: Chroma,
    /// Pixels nearer the principal point than this are the robot itself, px.
    pub inner_px: f64,
}

impl Default for GoalSettings {
    fn default() -> Self {
        Self {
            pos_x: Chroma::YELLOW,
            neg_x: Chroma::BLUE,
            inner_px: 0.0,
        }
    }
}

/// `[vision.goal]`'s values.
fn check_values(s: &GoalSettings, p: &mut Problems) {
    for (name, c) in [("pos_x", &s.pos_x), ("neg_x", &s.neg_x)] {
        if c.lead > 2 {
            p.fail(
                format!("{name}.lead"),
                format!("must be 0, 1 or 2 (got {})", c.lead),
            );
        }
    }
    p.non_negative("inner_px", s.inner_px);
}

/// What the camera showed of the goals this cycle, azimuths in the robot frame now.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GoalsSeen {
    /// The runs of the goal at +x, widest first.
    pub pos_x: Vec<GoalRun>,
    /// The runs of the goal at -x, widest first.
    pub neg_x: Vec<GoalRun>,
}

impl GoalsSeen {
    /// The runs of the goal at +x (`side` 1) or -x (`side` -1).
    pub fn of(&self, side: f64) -> &[GoalRun] {
        if side > 0.0 { &self.pos_x } else { &self.neg_x }
    }
}

impl Percept for GoalsSeen {
    fn record(&self) -> Option<(&'static str, serde_json::Value)> {
        let widest = |runs: &[GoalRun]| runs.first().map(|r| [r.centre_rad, r.width_rad]);
        Some((
            "goals",
            serde_json::json!({ "pos_x": widest(&self.pos_x), "neg_x": widest(&self.neg_x) }),
        ))
    }
}

/// Finds the goals on vision's camera.
pub struct GoalStage {
    camera: String,
    optics: FloorOptics,
    settings: GoalSettings,
    history: PoseHistory,
}

impl GoalStage {
    /// The stage on vision's camera of `config`.
    pub fn new(config: &RobotConfig) -> Result<Self, RobotError> {
        let (camera, optics) = FloorOptics::of(config, "goal perception")?;
        Ok(Self {
            camera,
            optics,
            settings: config.vision.table(TABLE)?,
            history: PoseHistory::default(),
        })
    }

    /// The runs of `color` in `img`.
    fn runs(&self, img: &image::RgbaImage, color: &Chroma) -> Vec<GoalRun> {
        match &self.optics {
            FloorOptics::Mirror(cal) => goal_runs_mirror(img, cal, color, self.settings.inner_px),
            FloorOptics::Forward(cam) => goal_runs_forward(img, cam, color),
        }
    }
}

/// `run` turned by `-turn_rad` (the robot turned by `turn_rad` since).
fn turned(run: GoalRun, turn_rad: f64) -> GoalRun {
    let wrap = |a: f64| {
        (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
    };
    GoalRun {
        from_rad: wrap(run.from_rad - turn_rad),
        to_rad: wrap(run.from_rad - turn_rad) + run.width_rad,
        centre_rad: wrap(run.centre_rad - turn_rad),
        ..run
    }
}

impl Stage for GoalStage {
    fn name(&self) -> &'static str {
        NAME
    }

    fn cameras(&self) -> Vec<&str> {
        vec![self.camera.as_str()]
    }

    fn run(
        &mut self,
        obs: &Observation<'_>,
        belief: &Belief,
        out: &mut Perceived,
    ) -> Result<(), RobotError> {
        let now = belief.odometry_pose;
        self.history.push(obs.t_s, now, 1.0);
        let Some(frame) = obs.frame(&self.camera) else {
            return Ok(());
        };
        let taken = self.history.at(frame.t_s).unwrap_or(now);
        let turn = now.rotation.angle() - taken.rotation.angle();
        let seen = GoalsSeen {
            pos_x: self
                .runs(frame.image, &self.settings.pos_x)
                .into_iter()
                .map(|r| turned(r, turn))
                .collect(),
            neg_x: self
                .runs(frame.image, &self.settings.neg_x)
                .into_iter()
                .map(|r| turned(r, turn))
                .collect(),
        };
        if seen.pos_x.is_empty() && seen.neg_x.is_empty() {
            out.not_found.push(NotFound {
                source: NAME,
                reason: "no goal-coloured pixel in view".to_string(),
            });
        }
        out.percepts.put(seen);
        Ok(())
    }
}
