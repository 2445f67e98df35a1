//! Free space in the floor region (Sect. 3.1 of the corner paper): the polar template on the
//! floor-colour mask, eqs. (5)-(7).

use super::{Belief, Percepts, Stage, image};
use crate::RobotError;
use crate::boundary::Observation;
use omniloop_vision::{FreeSpaceConfig, FreeSpaceDetector, RadialCalibration};

/// Detects free space in every frame of one mirror camera.
pub struct FreeSpaceStage {
    camera: String,
    detector: FreeSpaceDetector,
}

impl FreeSpaceStage {
    /// A stage for `camera`, calibrated by `cal`.
    pub fn new(
        camera: &str,
        config: FreeSpaceConfig,
        cal: &RadialCalibration,
    ) -> Result<Self, RobotError> {
        Ok(Self {
            camera: camera.to_string(),
            detector: FreeSpaceDetector::new(config, cal)?,
        })
    }
}

impl Stage for FreeSpaceStage {
    fn name(&self) -> &'static str {
        "freespace"
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
        let img = image(obs, &self.camera, self.name())?;
        out.freespace = Some(self.detector.detect(img)?);
        Ok(())
    }
}
