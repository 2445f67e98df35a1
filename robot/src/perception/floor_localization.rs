//! Self-localization from the shape of the floor region (Sect. 4 of the corner paper): a
//! full-pose fix, with its half-turn twin. Once a fix has set the estimate the stage tracks
//! (the prediction is the first guess and settles the twin when no goal is seen) and falls
//! back to the global search when tracking fails; before, it searches globally, the
//! prediction (the start pose moved by odometry) only choosing between the twins.

use super::stage::{
    Belief, CameraNeed, Perceived, Sighting, Stage, StageEntry, WorldNeed, calibration, image,
    vision_camera, vision_settings,
};
use crate::RobotError;
use crate::boundary::Observation;
use crate::estimates::{Measurement, NotFound};
use omniloop_problem::Problems;
use omniloop_vision::{FloorLocalizer, Localization, LocalizationConfig, RadialCalibration};

/// The stage's name, in the estimates record and the registry.
pub const NAME: &str = "floor_localization";

/// The `control.pose_source` under which its fixes correct the estimate.
pub const POSE_SOURCE: &str = "localization";

/// The registry's entry.
pub const ENTRY: StageEntry = StageEntry {
    name: NAME,
    summary: "self-localization from the shape of the floor region (Sect. 4 of the corner paper)",
    pose_source: Some(POSE_SOURCE),
    table: None,
    vision_table: Some(TABLE),
    check_vision: |v| v.tables.check("vision", TABLE, check),
    asked: |c| c.control.pose_source == POSE_SOURCE,
    camera: CameraNeed::MirrorFloor,
    world: &[WorldNeed::Field],
    check: |_| Vec::new(),
    build: |c| {
        let camera = vision_camera(c, "self-localization")?;
        let cal = calibration(c, camera)?;
        let config = vision_settings(c, TABLE)?;
        Ok(Box::new(FloorLocalizationStage::new(camera, config, cal)?))
    },
};

/// The stage's settings table, `[vision.localization]`.
const TABLE: &str = "localization";

/// `[vision.localization]`'s values.
fn check(l: &LocalizationConfig, p: &mut Problems) {
    let f = &l.field;
    p.positive("field.a1_mm", f.a1_mm);
    if f.a2_mm.is_nan() || f.a2_mm <= f.a1_mm {
        p.fail(
            "field.a2_mm",
            format!("must exceed a1_mm = {} (got {})", f.a1_mm, f.a2_mm),
        );
    }
    p.positive("field.goal_half_width_mm", f.goal_half_width_mm);
    if f.b_mm.is_nan() || f.b_mm <= f.goal_half_width_mm {
        let why = format!(
            "must exceed goal_half_width_mm = {} (got {})",
            f.goal_half_width_mm, f.b_mm
        );
        p.fail("field.b_mm", why);
    }
    for (key, class) in [("goal_pos_x", &l.goal_pos_x), ("goal_neg_x", &l.goal_neg_x)] {
        for (sub, r) in [("r", class.r), ("g", class.g)] {
            if !(0.0..=1.0).contains(&r[0]) || !(0.0..=1.0).contains(&r[1]) || r[0] > r[1] {
                let why = format!("must be [min, max] within 0..1 (got [{}, {}])", r[0], r[1]);
                p.fail(format!("{key}.{sub}"), why);
            }
        }
    }
    if l.max_radius_frac.is_nan() || l.max_radius_frac <= 0.0 || l.max_radius_frac > 1.0 {
        p.fail(
            "max_radius_frac",
            format!("must lie in (0, 1] (got {})", l.max_radius_frac),
        );
    }
    p.positive("gate_initial_mm", l.gate_initial_mm);
    p.positive("gate_mm", l.gate_mm);
    p.positive("offset_threshold_mm", l.offset_threshold_mm);
    p.positive("rotation_threshold_rad", l.rotation_threshold_rad);
    if l.max_iterations == 0 {
        p.fail("max_iterations", "must be >= 1");
    }
}

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
                expected_error_mm: None,
            }),
            Localization::NotLocalized(reason) => out.not_found.push(NotFound {
                source: self.name(),
                reason,
            }),
        }
        Ok(())
    }
}
