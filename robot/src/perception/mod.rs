//! Perception stages: each reads the frames of its cameras and gives free space, fixes for the
//! estimator, or the reason it found nothing.

mod floor_localization;
mod forward;
mod freespace;
mod luminance_heading;
mod omnistereo;
pub mod resection;

pub use floor_localization::FloorLocalizationStage;
pub use forward::{FlowStage, GroundStage, VisualOdometryStage};
pub use freespace::FreeSpaceStage;
pub use luminance_heading::LuminanceHeadingStage;
pub use omnistereo::OmnistereoStage;
pub use resection::ResectionStage;

use crate::RobotError;
use crate::boundary::{ActuatorCommand, Observation};
use crate::config::RobotConfig;
use crate::estimates::{GroundReading, LandmarkSighting, Measurement, MotionReading, NotFound};
use image::RgbaImage;
use nalgebra::{Isometry2, Point2};
use omniloop_vision::forward::{FlowBalance, OdometryStep};
use omniloop_vision::{FreeSpace, LocalizationQuality, RadialCalibration};

/// What the stages of one cycle found.
#[derive(Debug, Clone, Default)]
pub struct Percepts {
    /// Free space around the robot.
    pub freespace: Option<FreeSpace>,
    /// Measurements for the estimator.
    pub fixes: Vec<Sighting>,
    /// Stages that found nothing, and why.
    pub not_found: Vec<NotFound>,
    /// Landmarks of the map identified and ranged.
    pub landmarks: Vec<LandmarkSighting>,
    /// The motion since the previous frame, as vision read it.
    pub motion: Option<MotionReading>,
    /// Commands to the actuators (a stage steering its camera).
    pub actuators: Vec<ActuatorCommand>,
    /// A point to drive to (odometry frame), when a stage needs another view.
    pub observation_point: Option<Point2<f64>>,
    /// A forward camera's ground segmentation.
    pub ground: Option<GroundReading>,
    /// A forward camera's flow balance.
    pub flow: Option<FlowBalance>,
    /// A forward camera's visual odometry.
    pub visual_odometry: Option<OdometryStep>,
}

/// A measurement, the stage that made it and how good that stage judged it.
#[derive(Debug, Clone)]
pub struct Sighting {
    /// The stage.
    pub source: &'static str,
    /// The measurement.
    pub measurement: Measurement,
    /// Its quality record, when the stage keeps one.
    pub quality: Option<LocalizationQuality>,
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
    /// Processes the cycle's frames, knowing what the estimator predicts.
    fn run(
        &mut self,
        obs: &Observation<'_>,
        belief: &Belief,
        out: &mut Percepts,
    ) -> Result<(), RobotError>;
}

/// The stages a configuration asks for, in the order they run.
pub fn build(config: &RobotConfig) -> Result<Vec<Box<dyn Stage>>, RobotError> {
    let mut stages: Vec<Box<dyn Stage>> = Vec::new();
    if config.uses_omnistereo() {
        let rig = config.stereo.ok_or_else(|| {
            RobotError::Config("pose_source \"omnistereo\" needs the robot's two cones".into())
        })?;
        stages.push(Box::new(OmnistereoStage::new(
            config.vision.omnistereo.clone(),
            rig,
            &config.map.landmarks,
        )?));
    }
    if config.resects() {
        stages.push(Box::new(resection_stage(config)?));
    }
    if config.uses_forward_camera() {
        forward::build(config, &mut stages)?;
    }
    if !(config.detects_freespace() || config.localizes() || !config.checkpoints().is_empty()) {
        return Ok(stages);
    }
    let camera = config.vision_camera().ok_or_else(|| {
        RobotError::Config(match &config.vision.sensor {
            Some(n) => format!("vision.sensor names a camera the robot does not have: {n:?}"),
            None => "vision needs a camera and the robot has none".into(),
        })
    })?;
    let cal = calibration(config, camera)?;
    if config.detects_freespace() {
        stages.push(Box::new(FreeSpaceStage::new(
            camera,
            config.vision.freespace.clone(),
            cal,
        )?));
    }
    if config.localizes() {
        stages.push(Box::new(FloorLocalizationStage::new(
            camera,
            config.vision.localization.clone(),
            cal,
        )?));
    }
    if let Some(goal) = config
        .goal
        .as_ref()
        .filter(|g| !g.checkpoints_mm.is_empty())
    {
        stages.push(Box::new(LuminanceHeadingStage::new(
            camera,
            config.vision.luminance_heading.clone(),
            cal,
            &goal.checkpoints_mm,
            goal.checkpoint_store_mm,
            goal.checkpoint_radius_mm,
        )?));
    }
    Ok(stages)
}

/// The resection stage on vision's camera: panning with a pinhole's column calibration, or
/// from one image of a mirror camera.
fn resection_stage(config: &RobotConfig) -> Result<ResectionStage, RobotError> {
    let camera = config.vision_camera().ok_or_else(|| {
        RobotError::Config("resection needs a camera and the robot has none".into())
    })?;
    let view = match (config.columns(camera), config.calibration(camera)) {
        (Some(c), _) => resection::View::Pan(c.clone()),
        (None, Some(c)) => resection::View::Ring(c.clone()),
        (None, None) => {
            return Err(RobotError::Config(format!(
                "no column or mirror calibration for camera {camera:?}"
            )));
        }
    };
    ResectionStage::new(
        camera,
        view,
        config.vision.resection.clone(),
        config.control.resection.clone(),
        &config.map.marks,
    )
}

fn calibration<'a>(
    config: &'a RobotConfig,
    camera: &str,
) -> Result<&'a RadialCalibration, RobotError> {
    config.calibration(camera).ok_or_else(|| {
        RobotError::Config(format!(
            "no image-to-floor calibration for camera {camera:?}"
        ))
    })
}

/// The image of camera `sensor` this cycle, or the error naming the stage that needed it.
fn image<'a>(
    obs: &Observation<'a>,
    sensor: &str,
    stage: &'static str,
) -> Result<&'a RgbaImage, RobotError> {
    obs.image(sensor, stage)
}
