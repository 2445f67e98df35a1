//! A forward camera's stages (Ahmed, Saatchi and Caparrelli): ground segmentation and
//! Horn-Schunck flow for avoidance, scan-line and feature visual odometry.

use super::stage::{Belief, CameraNeed, Perceived, Stage, StageEntry, image, vision_settings};
use crate::RobotError;
use crate::boundary::Observation;
use crate::config::{RobotConfig, VisionSpec};
use crate::percept::Percept;
use omniloop_problem::Problem;
use omniloop_vision::forward::{
    FlowBalance, FlowConfig, ForwardCamera, ForwardOdometry, Grey, GroundConfig, GroundSegmenter,
    OdometryConfig, OdometryStep, grey, horn_schunck, reduce,
};
use serde::{Deserialize, Serialize};

/// What the ground segmentation of a forward camera showed this cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundReading {
    /// The fewest ground pixels from the bottom over the columns of the robot's path.
    pub ahead_px: u32,
    /// Ground pixels needed ahead to go straight.
    pub needed_px: u32,
    /// Mean run of ground over the left half, px.
    pub left_px: f64,
    /// Mean run of ground over the right half, px.
    pub right_px: f64,
    /// Whether the level at the bottom centre jumped (an obstacle right in front).
    pub jumped: bool,
}

impl GroundReading {
    /// Whether more ground pixels than needed lie ahead.
    pub fn clear_ahead(&self) -> bool {
        self.ahead_px > self.needed_px
    }
}

impl Percept for GroundReading {}

/// A forward camera's flow balance (Sect. 2.1.2), as the optical-flow controller reads it.
impl Percept for FlowBalance {}

/// A forward camera's visual odometry since the previous frame (Sect. 2.2).
impl Percept for OdometryStep {}

/// The forward camera the stages read, or the error saying vision's camera is not one.
fn camera(c: &RobotConfig) -> Result<ForwardCamera, RobotError> {
    c.forward_camera.clone().ok_or_else(|| {
        RobotError::Field(Problem::new(
            "control.kind",
            format!(
                "controller {:?} and the visual odometry need a forward pinhole camera",
                c.control.kind
            ),
        ))
    })
}

/// A forward camera's image processing (`[vision.forward]`), shared by its three stages.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct ForwardVisionConfig {
    /// Run the visual odometry (scan-line rotation, LK and NCC translation) every frame.
    pub visual_odometry: bool,
    /// Ground segmentation.
    pub ground: GroundConfig,
    /// Horn-Schunck flow.
    pub flow: FlowConfig,
    /// Visual odometry.
    pub odometry: OdometryConfig,
}

/// The table the three stages share.
const TABLE: &str = "forward";

/// The forward camera's stages, and the controllers that read them, need vision's camera to be
/// a forward pinhole.
pub fn needs_forward_camera(c: &RobotConfig) -> Vec<Problem> {
    if c.forward_camera.is_some() {
        return Vec::new();
    }
    vec![Problem::new(
        "vision.sensor",
        "the forward camera's avoidance and visual odometry need vision's camera to be a \
         pinhole ([robot.sensors.pinhole])",
    )]
}

/// `[vision.forward]`'s settings.
fn settings(c: &RobotConfig) -> Result<ForwardVisionConfig, RobotError> {
    vision_settings(c, TABLE)
}

/// `[vision.forward]` parses.
fn check_vision(v: &VisionSpec) -> Vec<Problem> {
    v.tables
        .check::<ForwardVisionConfig>("vision", TABLE, |_, _| {})
}

/// The ground segmentation's name in the registry.
pub const GROUND_NAME: &str = "ground";

/// The flow balance's name in the registry.
pub const FLOW_NAME: &str = "flow";

/// The visual odometry's name in the registry and the estimates record.
pub const VISUAL_ODOMETRY_NAME: &str = "visual_odometry";

/// The registry's entry of the ground segmentation.
pub const GROUND: StageEntry = StageEntry {
    name: GROUND_NAME,
    summary: "a forward camera's ground segmentation (Ahmed et al., Sect. 2.1.1)",
    pose_source: None,
    table: None,
    vision_table: Some(TABLE),
    check_vision,
    asked: |_| false,
    camera: CameraNeed::Forward,
    world: &[],
    check: |_| Vec::new(),
    build: |c| {
        let camera = camera(c)?;
        let config = settings(c)?.ground;
        Ok(Box::new(GroundStage {
            segmenter: GroundSegmenter::new(&camera, 2.0 * c.body.radius_mm, config),
            camera: camera.sensor.clone(),
        }))
    },
};

/// The registry's entry of the Horn-Schunck flow.
pub const FLOW: StageEntry = StageEntry {
    name: FLOW_NAME,
    summary: "a forward camera's Horn-Schunck flow balance (Ahmed et al., Sect. 2.1.2)",
    pose_source: None,
    table: None,
    vision_table: Some(TABLE),
    check_vision,
    asked: |_| false,
    camera: CameraNeed::Forward,
    world: &[],
    check: |_| Vec::new(),
    build: |c| {
        Ok(Box::new(FlowStage {
            camera: camera(c)?.sensor.clone(),
            config: settings(c)?.flow,
            previous: None,
        }))
    },
};

/// The registry's entry of the visual odometry (`vision.forward.visual_odometry = true`).
pub const VISUAL_ODOMETRY: StageEntry = StageEntry {
    name: VISUAL_ODOMETRY_NAME,
    summary: "a forward camera's visual odometry: scan-line rotation, LK and NCC translation \
              (Ahmed et al., Sect. 2.2)",
    pose_source: None,
    table: None,
    vision_table: Some(TABLE),
    check_vision,
    asked: |c| settings(c).is_ok_and(|f| f.visual_odometry),
    camera: CameraNeed::Forward,
    world: &[],
    check: needs_forward_camera,
    build: |c| {
        Ok(Box::new(VisualOdometryStage::new(
            camera(c)?,
            settings(c)?.odometry,
        )?))
    },
};

/// Ground segmentation of every frame (Sect. 2.1.1).
pub struct GroundStage {
    camera: String,
    segmenter: GroundSegmenter,
}

impl Stage for GroundStage {
    fn name(&self) -> &'static str {
        GROUND_NAME
    }

    fn cameras(&self) -> Vec<&str> {
        vec![&self.camera]
    }

    fn run(
        &mut self,
        obs: &Observation<'_>,
        _belief: &Belief,
        out: &mut Perceived,
    ) -> Result<(), RobotError> {
        let img = grey(image(obs, &self.camera, self.name())?);
        let v = self.segmenter.update(&img);
        out.percepts.put(GroundReading {
            ahead_px: v.ahead_px,
            needed_px: v.needed_px,
            left_px: v.left_px,
            right_px: v.right_px,
            jumped: v.jumped,
        });
        Ok(())
    }
}

/// Horn-Schunck flow between successive frames and its left/right balance (Sect. 2.1.2).
pub struct FlowStage {
    camera: String,
    config: FlowConfig,
    previous: Option<Grey>,
}

impl Stage for FlowStage {
    fn name(&self) -> &'static str {
        "optical_flow"
    }

    fn cameras(&self) -> Vec<&str> {
        vec![&self.camera]
    }

    fn carried(&mut self) {
        self.previous = None;
    }

    fn run(
        &mut self,
        obs: &Observation<'_>,
        _belief: &Belief,
        out: &mut Perceived,
    ) -> Result<(), RobotError> {
        let c = &self.config;
        let img = reduce(&grey(image(obs, &self.camera, self.name())?), c.downsample);
        if let Some(prev) = &self.previous {
            let field = horn_schunck(prev, &img, c.alpha, c.iterations);
            out.percepts
                .put(FlowBalance::of(&field, c.skip_top, c.downsample.max(1)));
        }
        self.previous = Some(img);
        Ok(())
    }
}

/// Scan-line rotation and feature translation between successive frames (Sect. 2.2).
pub struct VisualOdometryStage {
    camera: String,
    odometry: ForwardOdometry,
}

impl VisualOdometryStage {
    fn new(camera: ForwardCamera, config: OdometryConfig) -> Result<Self, RobotError> {
        Ok(Self {
            camera: camera.sensor.clone(),
            odometry: ForwardOdometry::new(camera, config)?,
        })
    }
}

impl Stage for VisualOdometryStage {
    fn name(&self) -> &'static str {
        VISUAL_ODOMETRY_NAME
    }

    fn cameras(&self) -> Vec<&str> {
        vec![&self.camera]
    }

    fn carried(&mut self) {
        self.odometry.reset();
    }

    fn run(
        &mut self,
        obs: &Observation<'_>,
        _belief: &Belief,
        out: &mut Perceived,
    ) -> Result<(), RobotError> {
        let img = grey(image(obs, &self.camera, self.name())?);
        if let Some(step) = self.odometry.step(&img) {
            out.percepts.put(step);
        }
        Ok(())
    }
}
