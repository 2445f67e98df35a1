//! Heading at checkpoints from the luminance circle (Kim, Kim and Kwon, Sect. 3): the first time
//! the robot's estimate is at a checkpoint it stores the circle whose rays are horizontal, with
//! the heading it believes then; on later visits it reads its turn since against that circle
//! (the angular shift, eqs. (7)-(10) or (2)-(6)) and gives the estimator a heading-only fix, or
//! "N/A" when the pattern match (eqs. (11)-(12)) says it is not at the checkpoint.
//!
//! The paper's robot stops at the checkpoint; ours may pass through it, and a view some 20 cm
//! off reads a translation as a turn of a few degrees (Sect. 4) while still matching. So within
//! one visit (the estimate within the read radius) only a reading that matches better than
//! every one before it becomes a fix: the readings improve as the robot nears the checkpoint
//! and are passed over as it leaves.

use super::stage::{
    Belief, CameraNeed, Perceived, Sighting, Stage, StageEntry, calibration, image, vision_camera,
    vision_settings,
};
use crate::RobotError;
use crate::boundary::Observation;
use crate::estimates::{Measurement, NotFound};
use nalgebra::Point2;
use omniloop_vision::RadialCalibration;
use omniloop_vision::luminance_heading::{LuminanceCircle, LuminanceConfig};

/// The stage's name, in the estimates record and the registry.
pub const NAME: &str = "luminance_heading";

/// The `control.pose_source` under which its fixes correct the estimate.
pub const POSE_SOURCE: &str = "checkpoints";

/// The registry's entry.
pub const ENTRY: StageEntry = StageEntry {
    name: NAME,
    summary: "heading at the goal's checkpoints from the luminance circle (Kim, Kim and Kwon, \
              Sect. 3)",
    pose_source: Some(POSE_SOURCE),
    table: None,
    vision_table: Some("luminance_heading"),
    check_vision: |v| {
        v.tables
            .check::<LuminanceConfig>("vision", "luminance_heading", |_, _| {})
    },
    asked: |c| !c.checkpoints().is_empty(),
    camera: CameraNeed::Mirror,
    world: &[],
    check: |_| Vec::new(),
    build: |c| {
        let camera = vision_camera(c, "the luminance heading")?;
        let cal = calibration(c, camera)?;
        let (config, goal) = (vision_settings(c, "luminance_heading")?, c.goal.as_ref());
        let (store, read) = goal.map_or((0.0, 0.0), |g| {
            (g.checkpoint_store_mm, g.checkpoint_radius_mm)
        });
        let stage = LuminanceHeadingStage::new(camera, config, cal, c.checkpoints(), store, read)?;
        Ok(Box::new(stage))
    },
};

/// One checkpoint and what the robot stored there.
struct Checkpoint {
    at: Point2<f64>,
    /// The circle and the heading the robot believed when it stored it, rad.
    reference: Option<(LuminanceCircle, f64)>,
    /// The best pattern match of the visit in progress, percent.
    best_match: Option<f64>,
}

/// Reads the heading at checkpoints from one mirror camera.
pub struct LuminanceHeadingStage {
    camera: String,
    config: LuminanceConfig,
    centre_px: [f64; 2],
    radius_px: f64,
    checkpoints: Vec<Checkpoint>,
    store_mm: f64,
    read_mm: f64,
}

impl LuminanceHeadingStage {
    /// A stage for `camera`, calibrated by `cal`, at `checkpoints` (field frame): storing
    /// within `store_mm` of one, reading within `read_mm`.
    pub fn new(
        camera: &str,
        config: LuminanceConfig,
        cal: &RadialCalibration,
        checkpoints: &[[f64; 2]],
        store_mm: f64,
        read_mm: f64,
    ) -> Result<Self, RobotError> {
        config.validate()?;
        let radius_px = config.circle_radius_px(cal)?;
        Ok(Self {
            camera: camera.to_string(),
            config,
            centre_px: cal.principal_point_px,
            radius_px,
            checkpoints: checkpoints
                .iter()
                .map(|c| Checkpoint {
                    at: Point2::new(c[0], c[1]),
                    reference: None,
                    best_match: None,
                })
                .collect(),
            store_mm,
            read_mm,
        })
    }
}

impl Stage for LuminanceHeadingStage {
    fn name(&self) -> &'static str {
        NAME
    }

    fn cameras(&self) -> Vec<&str> {
        vec![&self.camera]
    }

    fn run(
        &mut self,
        obs: &Observation<'_>,
        belief: &Belief,
        out: &mut Perceived,
    ) -> Result<(), RobotError> {
        let Some(pose) = belief.pose else {
            return Ok(());
        };
        let here = Point2::from(pose.translation.vector);
        let Some((k, d)) = self
            .checkpoints
            .iter()
            .enumerate()
            .map(|(k, c)| (k, (c.at - here).norm()))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .filter(|&(_, d)| d <= self.read_mm)
        else {
            // Away from every checkpoint: the next visit starts afresh.
            self.checkpoints
                .iter_mut()
                .for_each(|c| c.best_match = None);
            return Ok(());
        };
        let img = image(obs, &self.camera, self.name())?;
        let circle = LuminanceCircle::capture(img, self.centre_px, self.radius_px, &self.config)?;
        let source = self.name();
        let checkpoint = &mut self.checkpoints[k];
        let Some((reference, heading)) = &checkpoint.reference else {
            if d <= self.store_mm {
                checkpoint.reference = Some((circle, pose.rotation.angle()));
            }
            return Ok(());
        };
        let shift = circle.shift_from(reference, self.config.method, &self.config)?;
        let better = checkpoint
            .best_match
            .is_none_or(|b| shift.matched.percent > b);
        match shift.accepted_deg() {
            Some(_) if !better => {}
            Some(deg) => {
                out.fixes.push(Sighting {
                    source,
                    measurement: Measurement::Heading {
                        heading_rad: heading + deg.to_radians(),
                    },
                    quality: None,
                    expected_error_mm: None,
                });
                // Ours: a match this good puts the robot at the checkpoint itself.
                if shift.matched.percent >= self.config.at_checkpoint_match_percent {
                    out.fixes.push(Sighting {
                        source,
                        measurement: Measurement::Position {
                            position: checkpoint.at,
                        },
                        quality: None,
                        expected_error_mm: None,
                    });
                }
            }
            None => out.not_found.push(NotFound {
                source,
                reason: format!(
                    "N/A at checkpoint {k} ({d:.0} mm away by the estimate): pattern match \
                     {:.1}% below the {:.1}% required at a {:.0} deg shift",
                    shift.matched.percent, shift.matched.required, shift.shift_deg
                ),
            }),
        }
        // An N/A ends the visit as far as the image can tell.
        checkpoint.best_match = match shift.accepted_deg() {
            None => None,
            Some(_) if better => Some(shift.matched.percent),
            Some(_) => checkpoint.best_match,
        };
        Ok(())
    }
}
