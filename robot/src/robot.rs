//! The robot's software: perception stages, estimator, mission and controller in one cycle.

use crate::RobotError;
use crate::boundary::{Observation, OdometryReading, Outputs, RobotSoftware};
use crate::config::{ODOMETRY, RobotConfig};
use crate::controller::{Controller, Situation};
use crate::controllers;
use crate::estimates::{Estimates, Fix, NotFound};
use crate::estimator::PoseEstimator;
use crate::mission::Mission;
use crate::navigation::Unreachable;
use crate::perception::{self, Belief, Perceived, Stage, StageEntry};
use nalgebra::Isometry2;
use omniloop_problem::Problem;

/// The perception stages a configuration runs, in order: those its controller reads and those
/// it asks for (its pose source, a goal's checkpoints, the visual odometry).
pub fn stages_of(config: &RobotConfig) -> Result<Vec<&'static StageEntry>, RobotError> {
    let kind = &config.control.kind;
    let controller = controllers::find(kind).ok_or_else(|| {
        RobotError::Field(Problem::new(
            "control.kind",
            format!(
                "no controller {kind:?} (there are: {})",
                controllers::names()
            ),
        ))
    })?;
    Ok(perception::wanted(config, controller.stages))
}

/// The robot's software stack, built once from a [`RobotConfig`].
pub struct Robot {
    stages: Vec<Box<dyn Stage>>,
    estimator: PoseEstimator,
    controller: Box<dyn Controller>,
    mission: Option<Mission>,
    cameras: Vec<String>,
    controller_name: String,
}

impl Robot {
    /// Builds the stack: the perception stages the configuration asks for, the estimator from
    /// the start pose, the mission and the controller.
    pub fn new(config: &RobotConfig) -> Result<Self, RobotError> {
        let stages = perception::build(config, &stages_of(config)?)?;
        let mut cameras: Vec<String> = Vec::new();
        for c in stages.iter().flat_map(|s| s.cameras()) {
            if !cameras.iter().any(|k| k == c) {
                cameras.push(c.to_string());
            }
        }
        Ok(Self {
            estimator: PoseEstimator::new(
                config.start,
                config.control.pose_source != ODOMETRY,
                config.control.localization_gain,
            ),
            controller: controllers::build(config)?,
            mission: config.goal.as_ref().map(Mission::new),
            stages,
            cameras,
            controller_name: config.control.kind.clone(),
        })
    }

    /// The names of the perception stages, in the order they run.
    pub fn stages(&self) -> Vec<&'static str> {
        self.stages.iter().map(|s| s.name()).collect()
    }

    /// Fixes used and rejected so far.
    pub fn fixes(&self) -> (usize, usize) {
        self.estimator.fixes()
    }

    /// Runs every perception stage on this cycle's observation; a stage whose camera's frame
    /// was lost finds nothing (a `not_found` entry), unless it carries on without frames.
    fn perceive(
        &mut self,
        obs: &Observation<'_>,
        belief: &Belief,
    ) -> Result<Perceived, RobotError> {
        let mut percepts = Perceived::default();
        for stage in &mut self.stages {
            // A frame lost on its way: the stage finds nothing this cycle, unless it carries
            // on without one.
            let lost = (stage.wants_frames() && !stage.runs_without_frames())
                .then(|| {
                    stage
                        .cameras()
                        .iter()
                        .find(|c| !obs.frames.iter().any(|f| f.sensor == **c))
                        .map(|c| c.to_string())
                })
                .flatten();
            if let Some(camera) = lost {
                percepts.not_found.push(NotFound {
                    source: stage.name(),
                    reason: format!("no frame of camera {camera:?} this cycle"),
                });
                continue;
            }
            stage.run(obs, belief, &mut percepts)?;
        }
        Ok(percepts)
    }
}

impl RobotSoftware for Robot {
    /// The controller's name.
    fn name(&self) -> String {
        self.controller_name.clone()
    }

    /// The cameras whose frames the stack reads each cycle.
    fn cameras(&self) -> Vec<String> {
        self.cameras.clone()
    }

    /// The cameras whose frames the stack reads this cycle (a stage that is not looking, e.g.
    /// while the robot drives to another observation point, needs none).
    fn cameras_now(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for c in self
            .stages
            .iter()
            .filter(|s| s.wants_frames())
            .flat_map(|s| s.cameras())
        {
            if !out.iter().any(|k| k == c) {
                out.push(c.to_string());
            }
        }
        out
    }

    /// Takes a wheel odometry reading.
    fn odometry(&mut self, reading: &OdometryReading) {
        self.estimator.odometry(reading);
    }

    /// The robot was carried to a place it is not told: its pose is unknown until a fix.
    fn forget_pose(&mut self) {
        self.estimator.forget();
        for stage in &mut self.stages {
            stage.carried();
        }
    }

    /// The current pose estimate (world frame).
    fn estimate(&self) -> Option<Isometry2<f64>> {
        self.estimator.estimate()
    }

    /// The map its planner built, if its controller plans.
    fn map(&self) -> Option<crate::MapSnapshot> {
        self.controller.map()
    }

    /// One control cycle: perceive, fuse, judge the mission on the estimate, decide.
    fn cycle(&mut self, obs: &Observation<'_>) -> Result<Outputs, RobotError> {
        let belief = Belief {
            pose: self.estimator.estimate(),
            fixed: self.estimator.has_fix(),
            odometry_pose: self.estimator.odometry_pose(),
        };
        let percepts = self.perceive(obs, &belief)?;
        let fixes: Vec<Fix> = percepts
            .fixes
            .into_iter()
            .map(|s| Fix {
                source: s.source,
                outcome: self
                    .estimator
                    .fuse_with_error(&s.measurement, s.expected_error_mm),
                measurement: s.measurement,
                quality: s.quality,
            })
            .collect();
        let pose = self.estimator.estimate();
        if let Some(m) = &mut self.mission {
            m.update(pose.as_ref());
        }
        let target_mm = match (&self.mission, &pose) {
            (Some(m), Some(_)) => Some(m.target()),
            _ => None,
        };
        let target_body_mm = match (target_mm, &pose) {
            (Some(t), Some(p)) => Some(p.inverse_transform_point(&t).coords),
            _ => None,
        };
        let velocity_body_mm_s = self.estimator.velocity_body_mm_s();
        let command = self.controller.decide(&Situation {
            percepts: &percepts.percepts,
            target_body_mm,
            target_mm,
            velocity_body_mm_s,
            pose,
            odometry_pose: self.estimator.odometry_pose(),
            t_s: obs.t_s,
            actuators: obs.actuators,
        });
        let mut actuators = percepts.actuators;
        actuators.extend(self.controller.actuators());
        self.estimator.end_cycle();
        let navigation = self.controller.navigation().cloned();
        let mut not_found = percepts.not_found;
        if let (Some(n), Some(t)) = (&navigation, target_mm)
            && let Some(why) = n.unreachable
        {
            not_found.push(unreachable_entry(why, t));
        }
        Ok(Outputs {
            command,
            actuators,
            estimates: Estimates {
                t_s: obs.t_s,
                pose,
                velocity_body_mm_s,
                fixes,
                not_found,
                target: self.mission.as_ref().map(Mission::index),
                percepts: percepts.percepts,
                step: self.controller.step(),
                navigation,
            },
        })
    }
}

/// The estimates record's entry for a goal the planner found unreachable at `target` (world mm).
fn unreachable_entry(why: Unreachable, target: nalgebra::Point2<f64>) -> NotFound {
    NotFound {
        source: "planner",
        reason: format!(
            "unreachable: {} ({:.0}, {:.0}); the robot stopped ({})",
            why.explain(),
            target.x,
            target.y,
            why.as_str()
        ),
    }
}
