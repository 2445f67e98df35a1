//! Self-localization from the shape of the floor region (Sect. 4 of the corner paper): a
//! full-pose fix, with its half-turn twin. Once a fix has set the estimate the stage tracks
//! (the prediction is the first guess and settles the twin when no goal is seen) and falls
//! back to the global search when tracking fails; before, it searches globally, the
//! prediction (the start pose moved by odometry) only choosing between the twins.

use super::{Belief, Percepts, Sighting, Stage, image};
use crate::RobotError;
use crate::boundary::Observation;
use crate::estimates::{Measurement, NotFound};
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
        belief: &Belief,
        out: &mut Percepts,
    ) -> Result<(), RobotError> {
        let img = image(obs, &self.camera, self.name())?;
        let result = match (belief.fixed, &belief.pose) {
            (true, Some(prior)) => match self.localizer.track(img, prior)? {
                Localization::NotLocalized(tracking) => {
                    match self.localizer.locate(img, Some(prior))? {
                        Localization::NotLocalized(global) => Localization::NotLocalized(format!(
                            "tracking: {tracking}; global: {global}"
                        )),
                        found => found,
                    }
                }
                found => found,
            },
            _ => self.localizer.locate(img, belief.pose.as_ref())?,
        };
        match result {
            Localization::Localized(e) => out.fixes.push(Sighting {
                source: self.name(),
                measurement: Measurement::Pose {
                    pose: e.pose,
                    alternative: Some(e.alternative),
                    unambiguous: e.quality.resolved_by_goals,
                },
                quality: Some(e.quality),
            }),
            Localization::NotLocalized(reason) => out.not_found.push(NotFound {
                source: self.name(),
                reason,
            }),
        }
        Ok(())
    }
}
