//! omniloop-control: the acceleration-limited motion model of an omnidirectional robot and the
//! controllers that choose its velocity command.
//!
//! Everything here works on plain numbers (millimetres, seconds, radians) and nalgebra vectors,
//! so the same code drives the simulated robot and a real one. Nothing in this crate knows the
//! simulator.

pub mod angle;
pub mod avoidance;
pub mod differential;
pub mod drive;
pub mod go_to_goal;
pub mod odometry;
#[cfg(test)]
mod testing;
pub mod traffic;
pub mod velocity_aware;

pub use angle::{angle_diff, wrap_pi};
pub use avoidance::{AvoidanceConfig, Decision, GoalDirection, SpeedChoice, Surroundings};
pub use differential::DifferentialDrive;
pub use drive::{AccelLimitedDrive, VelocityCommand};
pub use go_to_goal::GoToGoal;
pub use odometry::DeadReckoning;
pub use traffic::{HalfPlane, TrafficConfig, TrafficRule};
pub use velocity_aware::{GoalKind, VelocityAware};

/// A 2-D vector in millimetres (positions) or millimetres per second (velocities).
pub type Vec2 = nalgebra::Vector2<f64>;

/// Errors of controller construction: a parameter outside its meaningful range.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ControlError {
    /// A parameter has a value that makes no sense (named, with the value and the rule).
    #[error("{name} = {value} is invalid: {rule}")]
    InvalidParameter {
        /// Parameter name, with its unit suffix.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What the value must satisfy.
        rule: &'static str,
    },
}

pub(crate) fn require_positive(name: &'static str, value: f64) -> Result<f64, ControlError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ControlError::InvalidParameter {
            name,
            value,
            rule: "must be finite and > 0",
        })
    }
}
