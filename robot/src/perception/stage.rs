//! What a perception stage is: it reads the frames of its cameras and gives free space, fixes
//! for the estimator, or the reason it found nothing. The stages themselves, one file each, are
//! registered in [`crate::perception`].

use crate::RobotError;
use crate::boundary::{ActuatorCommand, Observation};
use crate::config::{RobotConfig, VisionSpec};
use crate::estimates::{Measurement, NotFound};
use crate::percept::{Percept, Percepts};
use image::RgbaImage;
use nalgebra::{Isometry2, Point2};
use omniloop_problem::Problem;
use omniloop_vision::{LocalizationQuality, RadialCalibration};

/// What the stages of one cycle found: their outputs by type, fixes for the estimator, the
/// stages that found nothing and commands to the actuators.
#[derive(Debug, Clone, Default)]
pub struct Perceived {
    /// The stages' outputs, one of each type (free space, a ground reading, ...).
    pub percepts: Percepts,
    /// Measurements for the estimator.
    pub fixes: Vec<Sighting>,
    /// Stages that found nothing, and why.
    pub not_found: Vec<NotFound>,
    /// Commands to the actuators (a stage steering its camera).
    pub actuators: Vec<ActuatorCommand>,
}

/// A point a stage asks the robot to drive to (odometry frame, mm), when it needs another view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObservationPoint(pub Point2<f64>);

impl Percept for ObservationPoint {}

/// A measurement, the stage that made it and how good that stage judged it.
#[derive(Debug, Clone)]
pub struct Sighting {
    /// The stage.
    pub source: &'static str,
    /// The measurement.
    pub measurement: Measurement,
    /// Its quality record, when the stage keeps one.
    pub quality: Option<LocalizationQuality>,
    /// The expected error of the position it gives (one sigma, mm), when the stage knows it:
    /// the estimator then weighs the fix against its own uncertainty.
    pub expected_error_mm: Option<f64>,
}

/// What the estimator believes at the start of a cycle, as the stages may use it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Belief {
    /// The predicted pose (world frame), if the robot has one.
    pub pose: Option<Isometry2<f64>>,
    /// Whether a fix has set it (not only the start pose and odometry).
    pub fixed: bool,
    /// The dead-reckoned pose in the odometry frame.
    pub odometry_pose: Isometry2<f64>,
}

/// One perception stage.
pub trait Stage: Send {
    /// The stage's name in the estimates record.
    fn name(&self) -> &'static str;
    /// The cameras whose frames it reads.
    fn cameras(&self) -> Vec<&str>;
    /// The robot was carried to a place it is not told: a stage that keeps state starts
    /// afresh.
    fn carried(&mut self) {}
    /// Whether it reads its cameras' frames next cycle.
    fn wants_frames(&self) -> bool {
        true
    }
    /// Whether it runs in a cycle that brought no frame of its cameras (a lost one); the
    /// others are skipped that cycle, noted as finding nothing.
    fn runs_without_frames(&self) -> bool {
        false
    }
    /// Processes the cycle's frames, knowing what the estimator predicts.
    fn run(
        &mut self,
        obs: &Observation<'_>,
        belief: &Belief,
        out: &mut Perceived,
    ) -> Result<(), RobotError>;
}

/// What a stage needs of vision's camera (so the simulator calibrates it first).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraNeed {
    /// Nothing of vision's camera (it names its own cameras).
    None,
    /// A mirror camera's image-to-floor calibration, radius to elevation at least.
    Mirror,
    /// A mirror camera whose image shows the floor, with its image-to-floor map.
    MirrorFloor,
    /// A mirror camera's calibration, or a pinhole camera's column calibration.
    MirrorOrPinhole,
    /// A forward pinhole camera (its intrinsics, height and tilt).
    Forward,
    /// A mirror camera's calibration, or a forward pinhole camera's model.
    MirrorOrForward,
}

/// What a stage needs of the world beyond the robot's own map, so that the scenario's check
/// can say which field is missing before the run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WorldNeed {
    /// A field (`[world.field]`): floor-region localization matches the floor to its lines.
    Field,
    /// Two cameras under coaxial cones that make a stereo rig.
    StereoRig,
    /// A pan camera whose column calibration the resection reads.
    ResectionCamera,
}

/// A perception stage as the registry lists it: a new stage is its own file with one of these
/// and one line in [`crate::perception::STAGES`].
pub struct StageEntry {
    /// Its name in the estimates record.
    pub name: &'static str,
    /// What it does, in one line, with the paper and section it follows.
    pub summary: &'static str,
    /// The `control.pose_source` under which its fixes correct the estimate, if it gives any.
    pub pose_source: Option<&'static str>,
    /// Its own table under `[control]`, if it has one (checked by `check`).
    pub table: Option<&'static str>,
    /// Its settings table under `[vision]`, if it has one (stages may share one).
    pub vision_table: Option<&'static str>,
    /// Parses and checks that table's values wherever it is written, naming each field at
    /// fault.
    pub check_vision: fn(&VisionSpec) -> Vec<Problem>,
    /// Whether the robot's configuration asks for it (besides a controller that reads it).
    pub asked: fn(&RobotConfig) -> bool,
    /// What it needs of vision's camera.
    pub camera: CameraNeed,
    /// What it needs of the world that the robot is not told, checked where the scenario is
    /// read.
    pub world: &'static [WorldNeed],
    /// Checks what it needs of the robot (its camera, the map, its settings on that camera),
    /// naming each field at fault; its vision table's own values are `check_vision`'s.
    pub check: fn(&RobotConfig) -> Vec<Problem>,
    /// Builds it for a robot.
    pub build: fn(&RobotConfig) -> Result<Box<dyn Stage>, RobotError>,
}

/// The settings table `name` of a robot's `[vision]`, as a build error when it does not parse.
pub fn vision_settings<T: serde::de::DeserializeOwned + Default>(
    config: &RobotConfig,
    name: &str,
) -> Result<T, RobotError> {
    Ok(config.vision.table(name)?)
}

/// The calibration of camera `sensor`, or the error saying there is none.
pub fn calibration<'a>(
    config: &'a RobotConfig,
    camera: &str,
) -> Result<&'a RadialCalibration, RobotError> {
    config.calibration(camera).ok_or_else(|| {
        RobotError::Missing(format!(
            "no image-to-floor calibration for camera {camera:?}"
        ))
    })
}

/// Vision's camera (`vision.sensor`, else the robot's first), or the error naming `stage`.
pub fn vision_camera<'a>(config: &'a RobotConfig, stage: &str) -> Result<&'a str, RobotError> {
    config.vision_camera().ok_or_else(|| {
        RobotError::Field(match &config.vision.sensor {
            Some(n) => Problem::new(
                "vision.sensor",
                format!("names a camera the robot does not have: {n:?}"),
            ),
            None => Problem::new(
                "robot.sensors",
                format!("{stage} needs a camera and the robot has none"),
            ),
        })
    })
}

/// The image of camera `sensor` this cycle, or the error naming the stage that needed it.
pub fn image<'a>(
    obs: &Observation<'a>,
    sensor: &str,
    stage: &'static str,
) -> Result<&'a RgbaImage, RobotError> {
    obs.image(sensor, stage)
}

/// The odometry poses at the start of recent cycles, to place a late frame's findings where the
/// robot was when it was taken.
#[derive(Debug, Clone, Default)]
pub struct PoseHistory(std::collections::VecDeque<(f64, Isometry2<f64>)>);

impl PoseHistory {
    /// Keeps `pose` at `t_s`, forgetting poses older than `keep_s` before it.
    pub fn push(&mut self, t_s: f64, pose: Isometry2<f64>, keep_s: f64) {
        self.0.push_back((t_s, pose));
        while self.0.front().is_some_and(|(t, _)| *t < t_s - keep_s) {
            self.0.pop_front();
        }
    }

    /// The pose at `t_s` (linear between the cycles around it; the oldest or newest beyond).
    pub fn at(&self, t_s: f64) -> Option<Isometry2<f64>> {
        let h = &self.0;
        let after = h.iter().position(|(t, _)| *t >= t_s - 1e-9)?;
        let (t1, p1) = h[after];
        if after == 0 || (t1 - t_s).abs() < 1e-9 {
            return Some(p1);
        }
        let (t0, p0) = h[after - 1];
        Some(p0.lerp_slerp(&p1, (t_s - t0) / (t1 - t0)))
    }

    /// The pose `n` cycles back (0: the newest).
    pub fn back(&self, n: usize) -> Option<(f64, Isometry2<f64>)> {
        self.0.iter().rev().nth(n).copied()
    }

    /// Forgets every pose.
    pub fn clear(&mut self) {
        self.0.clear();
    }
}

/// How vision's camera maps pixels to the floor: a mirror's image-to-floor calibration, or a
/// forward pinhole's model.
#[derive(Debug, Clone)]
pub enum FloorOptics {
    /// A mirror camera (calibrated ones too).
    Mirror(RadialCalibration),
    /// A forward pinhole camera.
    Forward(omniloop_vision::forward::ForwardCamera),
}

impl FloorOptics {
    /// Vision's camera of `config` and its optics, or the error naming `what` needs them.
    pub fn of(config: &RobotConfig, what: &str) -> Result<(String, Self), RobotError> {
        let camera = vision_camera(config, what)?;
        let optics = match (config.calibration(camera), &config.forward_camera) {
            (Some(cal), _) => Self::Mirror(cal.clone()),
            (None, Some(f)) if f.sensor == camera => Self::Forward(f.clone()),
            _ => {
                return Err(RobotError::Missing(format!(
                    "{what} needs camera {camera:?}'s image-to-floor calibration or its forward \
                     pinhole model"
                )));
            }
        };
        Ok((camera.to_string(), optics))
    }
}
