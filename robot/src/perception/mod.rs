//! Perception stages, one file each, and their registry: each reads the frames of its
//! cameras and gives free space, fixes for the estimator, or the reason it found nothing.
//!
//! A new stage is a file here with its [`StageEntry`] (`pub const ENTRY`) and one line in
//! [`STAGES`]; a controller reads it by naming it in its entry's `stages`, or a pose source
//! selects it through the entry's `pose_source`.

pub mod ball;
pub mod floor_localization;
pub mod forward;
pub mod freespace;
pub mod goal;
pub mod luminance_heading;
pub mod omnistereo;
pub mod resection;
pub mod stage;

pub use ball::{BallEstimate, BallSource, BallStage};
pub use floor_localization::FloorLocalizationStage;
pub use forward::GroundReading;
pub use forward::{FlowStage, GroundStage, VisualOdometryStage};
pub use freespace::FreeSpaceStage;
pub use goal::{GoalStage, GoalsSeen};
pub use luminance_heading::LuminanceHeadingStage;
pub use omnistereo::OmnistereoStage;
pub use omnistereo::{LandmarkSighting, Landmarks, MotionReading};
pub use resection::ResectionStage;
pub use stage::{
    Belief, CameraNeed, ObservationPoint, Perceived, Sighting, Stage, StageEntry, WorldNeed,
};

use crate::RobotError;
use crate::config::{ODOMETRY, RobotConfig};

/// Every perception stage, in the order they run in a cycle.
pub const STAGES: &[StageEntry] = &[
    omnistereo::ENTRY,
    resection::ENTRY,
    forward::GROUND,
    forward::FLOW,
    forward::VISUAL_ODOMETRY,
    freespace::ENTRY,
    floor_localization::ENTRY,
    luminance_heading::ENTRY,
    ball::ENTRY,
    goal::ENTRY,
];

/// The stages a robot runs, in order: those its controller reads (`read`, by name) and those
/// its configuration asks for.
pub fn wanted(config: &RobotConfig, read: &[&str]) -> Vec<&'static StageEntry> {
    STAGES
        .iter()
        .filter(|s| read.contains(&s.name) || (s.asked)(config))
        .collect()
}

/// Whether `name` is a pose source: `"odometry"`, or a stage's.
pub fn is_pose_source(name: &str) -> bool {
    name == ODOMETRY || STAGES.iter().any(|s| s.pose_source == Some(name))
}

/// Every pose source, for messages.
pub fn pose_sources() -> String {
    let stages = STAGES.iter().filter_map(|s| s.pose_source);
    let names: Vec<&str> = std::iter::once(ODOMETRY).chain(stages).collect();
    names.join(", ")
}

/// Builds the stages of `wanted`, in order.
pub fn build(
    config: &RobotConfig,
    wanted: &[&'static StageEntry],
) -> Result<Vec<Box<dyn Stage>>, RobotError> {
    wanted.iter().map(|s| (s.build)(config)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::VisionSpec;

    #[test]
    fn every_vision_table_takes_its_defaults_and_names_a_stray_key() {
        for entry in STAGES {
            let Some(table) = entry.vision_table else {
                continue;
            };
            let mut spec = VisionSpec::default();
            assert_eq!((entry.check_vision)(&spec), Vec::new(), "{}", entry.name);
            let stray: toml::Value = toml::from_str("no_such_key = 1").unwrap();
            spec.tables.0.insert(table.to_string(), stray);
            let problems = (entry.check_vision)(&spec);
            assert_eq!(problems.len(), 1, "{}: {problems:?}", entry.name);
            assert_eq!(
                problems[0].field.to_string(),
                format!("vision.{table}.no_such_key")
            );
        }
    }
}
