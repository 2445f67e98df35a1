//! Self-localization from the shape of the floor region (Sect. 4 of the corner paper,
//! steps 1-7): a full-pose fix, with its half-turn twin when the goals do not tell them apart.

use super::{Percepts, Stage, image};
use crate::RobotError;
use crate::boundary::Observation;
use crate::estimates::{Measurement, NotFound};
use nalgebra::Isometry2;
use omniloop_vision::{FloorLocalizer, Localization, LocalizationConfig, RadialCalibration};

/// Localizes the robot in every frame of one mirror camera.
pub struct FloorLocalizationStage {
    camera: String,
    localizer: FloorLocalizer,
}

impl FloorLocalizationStage {
    /// A stage for `camera`, calibrated by `cal`.
    pub fn new(
        camera: &str,
        config: LocalizationConfig,
        cal: &RadialCalibration,
    ) -> Result<Self, RobotError> {
        Ok(Self {
            camera: camera.to_string(),
            localizer: FloorLocalizer::new(config, cal)?,
        })
    }
}

impl Stage for FloorLocalizationStage {
    fn name(&self) -> &'static str {
        "floor_localization"
    }

    fn cameras(&self) -> Vec<&str> {
        vec![&self.camera]
    }

    fn run(
        &mut self,
        obs: &Observation<'_>,
        prior: Option<&Isometry2<f64>>,
        out: &mut Percepts,
    ) -> Result<(), RobotError> {
        let img = image(obs, &self.camera, self.name())?;
        match self.localizer.locate(img, prior)? {
            Localization::Localized(e) => out.fixes.push((
                self.name(),
                Measurement::Pose {
                    pose: e.pose,
                    alternative: Some(e.alternative),
                    unambiguous: e.quality.resolved_by_goals,
                },
            )),
            Localization::NotLocalized(reason) => out.not_found.push(NotFound {
                source: self.name(),
                reason,
            }),
        }
        Ok(())
    }
}
