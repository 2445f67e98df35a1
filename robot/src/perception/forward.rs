//! A forward camera's stages (Ahmed, Saatchi and Caparrelli): ground segmentation and
//! Horn-Schunck flow for avoidance, scan-line and feature visual odometry.

use super::{Belief, Percepts, Stage, image};
use crate::RobotError;
use crate::boundary::Observation;
use crate::config::{ControllerKind, RobotConfig};
use crate::estimates::GroundReading;
use omniloop_vision::forward::{
    FlowBalance, FlowConfig, ForwardCamera, ForwardOdometry, Grey, GroundSegmenter, grey,
    horn_schunck, reduce,
};

/// The forward camera's stages a configuration asks for.
pub(super) fn build(
    config: &RobotConfig,
    stages: &mut Vec<Box<dyn Stage>>,
) -> Result<(), RobotError> {
    let camera = config.forward_camera.clone().ok_or_else(|| {
        RobotError::Config(format!(
            "controller {:?} and the visual odometry need a forward pinhole camera",
            config.control.kind.name()
        ))
    })?;
    let v = &config.vision.forward;
    match config.control.kind {
        ControllerKind::Segmentation => stages.push(Box::new(GroundStage {
            segmenter: GroundSegmenter::new(&camera, 2.0 * config.body.radius_mm, v.ground.clone()),
            camera: camera.sensor.clone(),
        })),
        ControllerKind::OpticalFlow => stages.push(Box::new(FlowStage {
            camera: camera.sensor.clone(),
            config: v.flow.clone(),
            previous: None,
        })),
        _ => {}
    }
    if v.visual_odometry {
        stages.push(Box::new(VisualOdometryStage::new(camera, v)?));
    }
    Ok(())
}

/// Ground segmentation of every frame (Sect. 2.1.1).
pub struct GroundStage {
    camera: String,
    segmenter: GroundSegmenter,
}

impl Stage for GroundStage {
    fn name(&self) -> &'static str {
        "ground"
    }

    fn cameras(&self) -> Vec<&str> {
        vec![&self.camera]
    }

    fn run(
        &mut self,
        obs: &Observation<'_>,
        _belief: &Belief,
        out: &mut Percepts,
    ) -> Result<(), RobotError> {
        let img = grey(image(obs, &self.camera, self.name())?);
        let v = self.segmenter.update(&img);
        out.ground = Some(GroundReading {
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
        out: &mut Percepts,
    ) -> Result<(), RobotError> {
        let c = &self.config;
        let img = reduce(&grey(image(obs, &self.camera, self.name())?), c.downsample);
        if let Some(prev) = &self.previous {
            let field = horn_schunck(prev, &img, c.alpha, c.iterations);
            out.flow = Some(FlowBalance::of(&field, c.skip_top, c.downsample.max(1)));
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
    fn new(
        camera: ForwardCamera,
        config: &crate::config::ForwardVisionConfig,
    ) -> Result<Self, RobotError> {
        Ok(Self {
            camera: camera.sensor.clone(),
            odometry: ForwardOdometry::new(camera, config.odometry.clone())?,
        })
    }
}

impl Stage for VisualOdometryStage {
    fn name(&self) -> &'static str {
        "visual_odometry"
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
        out: &mut Percepts,
    ) -> Result<(), RobotError> {
        let img = grey(image(obs, &self.camera, self.name())?);
        out.visual_odometry = self.odometry.step(&img);
        Ok(())
    }
}
