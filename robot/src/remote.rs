//! Robot software driven from outside the loop: a Python agent, a learning library or a tool
//! that steps the simulation itself. [`Remote`] is one more implementation of
//! [`RobotSoftware`]: it hands each cycle the command its [`RemoteHandle`] was last given (the
//! outside reads the frames and odometry from the loop itself). Like any robot software it
//! never sees the world.

use crate::boundary::{ActuatorCommand, BodyCommand, Observation, OdometryReading, Outputs};
use crate::{Estimates, RobotConfig, RobotError, RobotSoftware};
use nalgebra::Isometry2;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

/// What the outside hands the next cycle.
#[derive(Debug, Clone, Default)]
pub struct Mailbox {
    /// The body-frame command the next cycle applies.
    pub command: BodyCommand,
    /// Actuator commands the next cycle applies (taken by it).
    pub actuators: Vec<ActuatorCommand>,
    /// The pose estimate the outside reports for the next cycle (recorded in
    /// `trajectory.csv`'s estimate columns), if any.
    pub estimate: Option<Isometry2<f64>>,
}

/// The outside's end of a [`Remote`]: sets what the next cycle applies.
#[derive(Debug, Clone)]
pub struct RemoteHandle(Arc<Mutex<Mailbox>>);

impl RemoteHandle {
    /// The mailbox, locked (a panic elsewhere while it was held leaves its data usable).
    pub fn lock(&self) -> MutexGuard<'_, Mailbox> {
        self.0.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// Robot software whose commands come from outside (see the module's documentation).
pub struct Remote {
    name: String,
    cameras: Vec<String>,
    mailbox: Arc<Mutex<Mailbox>>,
}

impl Remote {
    /// Software reading every camera of `config`, reported as `name` in `summary.json`, and
    /// the handle that drives it.
    pub fn new(config: &RobotConfig, name: &str) -> (Self, RemoteHandle) {
        let mailbox = Arc::new(Mutex::new(Mailbox::default()));
        let remote = Self {
            name: name.to_string(),
            cameras: config.cameras.clone(),
            mailbox: Arc::clone(&mailbox),
        };
        (remote, RemoteHandle(mailbox))
    }

    fn lock(&self) -> MutexGuard<'_, Mailbox> {
        self.mailbox.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

impl RobotSoftware for Remote {
    fn name(&self) -> String {
        self.name.clone()
    }

    fn cameras(&self) -> Vec<String> {
        self.cameras.clone()
    }

    fn cycle(&mut self, obs: &Observation<'_>) -> Result<Outputs, RobotError> {
        let mut m = self.lock();
        let mut estimates = Estimates::at(obs.t_s);
        estimates.pose = m.estimate;
        Ok(Outputs {
            command: m.command,
            actuators: std::mem::take(&mut m.actuators),
            estimates,
        })
    }

    fn odometry(&mut self, _reading: &OdometryReading) {}

    fn estimate(&self) -> Option<Isometry2<f64>> {
        self.lock().estimate
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    fn config() -> RobotConfig {
        RobotConfig {
            name: "robot".to_string(),
            start: Isometry2::new(Vector2::new(100.0, -50.0), 0.0),
            cameras: vec!["cam".into()],
            ..RobotConfig::for_tests()
        }
    }

    #[test]
    fn the_cycle_applies_the_handles_command_and_takes_its_actuator_commands() {
        let (mut remote, handle) = Remote::new(&config(), "python");
        {
            let mut m = handle.lock();
            m.command = BodyCommand::forward(250.0);
            m.actuators.push(ActuatorCommand::PanTo {
                sensor: "cam".into(),
                pan_rad: 0.5,
            });
        }
        let obs = Observation {
            t_s: 0.4,
            frames: &[],
            actuators: &[],
        };
        let out = remote.cycle(&obs).unwrap();
        assert_eq!(out.command, BodyCommand::forward(250.0));
        assert_eq!(out.actuators.len(), 1);
        assert_eq!(out.estimates.t_s, 0.4);
        // Actuator commands are sent once; the drive command holds until changed.
        let again = remote.cycle(&obs).unwrap();
        assert!(again.actuators.is_empty());
        assert_eq!(again.command, BodyCommand::forward(250.0));
    }
}
