//! The run layer: the closed loop on the simulator's side ([`simulation`]), the sensors and
//! actuators it simulates ([`cameras`], [`odometry`], [`column_calibration`]), its pilot for
//! the other robots ([`pilot`]), the truth-side scores ([`score`]), how a run with a goal
//! ended ([`outcome`]) and the records of a run ([`record`]). It never calls up into an
//! experiment: an experiment drives it.

pub mod agent;
pub mod ball_record;
pub mod cameras;
pub mod column_calibration;
pub mod error;
pub mod observer;
pub mod odometry;
pub mod outcome;
pub mod pilot;
pub mod record;
pub mod score;
pub mod simulation;
pub mod truth_files;

pub use agent::{Agent, Truth};
pub use ball_record::{BallOutput, BallRow, BallSummary};
pub use error::RunError;
pub use outcome::{GoalFigures, GoalOutcome};
pub use record::{RobotSummary, Summary, TeamFigures, TrajectoryRow};
pub use simulation::{
    OutputFile, RobotOutput, RunOptions, RunOutput, Simulation, builtin_software, render_snapshot,
    render_snapshot_truth, straight_line_time_s,
};
