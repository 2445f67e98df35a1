//! The simulator's own pilot: drives a robot through waypoints on its *true* pose. It moves the
//! other robots (moving obstacles) and, with `run.pilot = "truth"`, the robot under
//! test as a reference that needs no vision. It is not the robot's software and never runs in
//! it.

use nalgebra::Point2;
use omniloop_control::{AccelLimitedDrive, ControlError, GoToGoal, VelocityCommand};

/// Drives through waypoints on the true position.
#[derive(Debug, Clone)]
pub struct Pilot {
    waypoints: Vec<Point2<f64>>,
    next: usize,
    tolerance_mm: f64,
    cycle: bool,
    controller: GoToGoal,
}

impl Pilot {
    /// A pilot passing `waypoints` within `tolerance_mm`, starting again after the last when
    /// `cycle`, with the robot's top speed and drive.
    pub fn new(
        waypoints: Vec<Point2<f64>>,
        tolerance_mm: f64,
        cycle: bool,
        max_speed_mm_s: f64,
        drive: AccelLimitedDrive,
    ) -> Result<Self, ControlError> {
        Ok(Self {
            waypoints,
            next: 0,
            tolerance_mm,
            cycle,
            controller: GoToGoal::new(max_speed_mm_s, drive)?,
        })
    }

    /// The index of the waypoint it heads for (the count of waypoints once all are passed).
    pub fn index(&self) -> usize {
        self.next
    }

    /// Moves on past a waypoint reached, then the command (world frame) for a robot at `p`:
    /// straight for the waypoint, braking to stop on it; stop when none is left.
    pub fn command(&mut self, p: Point2<f64>) -> VelocityCommand {
        if self.next < self.waypoints.len()
            && (self.waypoints[self.next] - p).norm() < self.tolerance_mm
        {
            self.next += 1;
            if self.cycle && self.next == self.waypoints.len() {
                self.next = 0;
            }
        }
        match self.waypoints.get(self.next) {
            Some(w) => self.controller.command(p.coords, w.coords),
            None => VelocityCommand::STOP,
        }
    }
}
