//! The sensor boundary: what the robot's software receives each cycle and what it returns.

use crate::estimates::Estimates;
use image::RgbaImage;
use nalgebra::Vector2;

/// One camera image as the robot's camera delivers it.
#[derive(Debug, Clone, Copy)]
pub struct Frame<'a> {
    /// The camera's name (`[[robot.sensors]] name`).
    pub sensor: &'a str,
    /// When the image was taken, s.
    pub t_s: f64,
    /// The image.
    pub image: &'a RgbaImage,
}

/// What the wheel encoders measured over the last period: the body-frame velocity and the
/// rotation rate at its end, with the encoders' own errors in them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdometryReading {
    /// Body-frame velocity (x forward, y left), mm/s.
    pub v_body_mm_s: Vector2<f64>,
    /// Rotation rate, rad/s (counter-clockwise positive).
    pub omega_rad_s: f64,
    /// Time since the previous reading, s.
    pub dt_s: f64,
}

/// The state of an actuator the robot commands.
#[derive(Debug, Clone, PartialEq)]
pub enum ActuatorState {
    /// A camera on a pan unit: its pan angle (counter-clockwise from the robot's forward axis).
    Pan {
        /// The camera.
        sensor: String,
        /// Current pan angle, rad.
        pan_rad: f64,
    },
}

/// A command to an actuator.
#[derive(Debug, Clone, PartialEq)]
pub enum ActuatorCommand {
    /// Pan the camera toward this angle (at most at the pan unit's rate limit).
    PanTo {
        /// The camera.
        sensor: String,
        /// Target pan angle, rad.
        pan_rad: f64,
    },
    /// Pan the camera at this rate (clipped to the pan unit's limit) until told otherwise.
    PanAt {
        /// The camera.
        sensor: String,
        /// Pan rate, rad/s (counter-clockwise positive).
        rate_rad_s: f64,
    },
}

/// Everything the robot's sensors give it at the start of a control cycle (besides the wheel
/// odometry, which arrives as [`OdometryReading`]s).
#[derive(Debug, Clone, Copy)]
pub struct Observation<'a> {
    /// Time of the cycle, s.
    pub t_s: f64,
    /// The frames of the cameras the robot asked for ([`crate::Robot::cameras`]).
    pub frames: &'a [Frame<'a>],
    /// The state of the robot's actuators.
    pub actuators: &'a [ActuatorState],
}

impl<'a> Observation<'a> {
    /// The frame of the camera called `sensor`, if this cycle brought one.
    pub fn frame(&self, sensor: &str) -> Option<&Frame<'a>> {
        self.frames.iter().find(|f| f.sensor == sensor)
    }
}

/// A velocity command in the robot's body frame (x forward, y left).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BodyCommand {
    /// Translational velocity, mm/s.
    pub v_mm_s: Vector2<f64>,
    /// Rotation rate, rad/s (counter-clockwise positive).
    pub omega_rad_s: f64,
}

impl BodyCommand {
    /// Stand still.
    pub const STOP: Self = Self {
        v_mm_s: Vector2::new(0.0, 0.0),
        omega_rad_s: 0.0,
    };

    /// A pure translation.
    pub fn translate(v_mm_s: Vector2<f64>) -> Self {
        Self {
            v_mm_s,
            omega_rad_s: 0.0,
        }
    }
}

/// What the robot's software returns from a control cycle.
#[derive(Debug, Clone)]
pub struct Outputs {
    /// The velocity command for the drive.
    pub command: BodyCommand,
    /// Commands to the actuators.
    pub actuators: Vec<ActuatorCommand>,
    /// What the robot believes after this cycle.
    pub estimates: Estimates,
}
