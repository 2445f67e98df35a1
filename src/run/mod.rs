//! The run layer: the closed loop on the simulator's side ([`simulation`]), the sensors and
//! actuators it simulates ([`cameras`], [`odometry`], [`column_calibration`]), its pilot for
//! the other robots ([`pilot`]), the truth-side scores ([`score`]) and the records of a run
//! ([`record`]). It never calls up into an experiment: an experiment drives it.

pub mod cameras;
pub mod column_calibration;
pub mod error;
pub mod observer;
pub mod odometry;
pub mod pilot;
pub mod record;
pub mod score;
pub mod simulation;

pub use error::RunError;
pub use record::{Summary, TrajectoryRow};
pub use simulation::{
    OutputFile, RunOptions, RunOutput, Simulation, Truth, builtin_software, render_snapshot,
};
