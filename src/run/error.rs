//! Why a run could not be carried out.

use omniloop_problem::Problem;
use omniloop_robot::RobotError;
use omniloop_sim::{RenderError, SimError};
use omniloop_vision::VisionError;
use std::path::PathBuf;

/// Why a run could not be carried out.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The world could not be built.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The simulator's pilot could not be built.
    #[error(transparent)]
    Control(#[from] omniloop_control::ControlError),
    /// The renderer could not open or render.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// A calibration file could not be used.
    #[error(transparent)]
    Vision(#[from] VisionError),
    /// The robot's software could not be built or failed.
    #[error(transparent)]
    Robot(#[from] RobotError),
    /// The robot commanded an actuator it does not have.
    #[error("actuator: {0}")]
    Actuator(String),
    /// The scenario's experiment section does not parse (a scenario not checked first).
    #[error("scenario: {0}")]
    Scenario(String),
    /// A run that is over was stepped again.
    #[error(
        "the run of {scenario:?} is over after {cycles} cycles (time up or goal reached); reset it to run again"
    )]
    Finished {
        /// The scenario's name.
        scenario: String,
        /// The cycles it ran.
        cycles: u64,
    },
    /// Something failed in one robot of a team.
    #[error("robot {robot:?}: {message}")]
    InRobot {
        /// The robot's name.
        robot: String,
        /// What failed.
        message: String,
    },
    /// A team's robots and the software asked for them do not match (a name that is no
    /// robot's, a robot left without software).
    #[error("{0}")]
    Team(String),
    /// A frame's truth could not be written.
    #[error(transparent)]
    Truth(#[from] super::truth_files::TruthFileError),
    /// A frame could not be written.
    #[error("writing frame {path}: {reason}")]
    Frame {
        /// The file.
        path: PathBuf,
        /// Why (in the message, not a separate cause).
        reason: image::ImageError,
    },
}

impl From<Problem> for RunError {
    /// A settings table that does not parse (a scenario not checked first).
    fn from(p: Problem) -> Self {
        Self::Scenario(p.to_string())
    }
}
