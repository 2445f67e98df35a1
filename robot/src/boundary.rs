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
    /// The kicker and dribbler on the robot's flat front.
    Kicker {
        /// The light barrier across the dribbler: whether it sees the ball.
        ball_in_dribbler: bool,
        /// Whether the kicker is charged.
        ready: bool,
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
    /// Arm the kicker: it fires once, as soon as the ball is at the dribbler and the kicker is
    /// charged; a speed of 0 disarms it. At most the kicker's limit (the rules' 6.5 m/s).
    Kick {
        /// Speed of the ball off the kicker, mm/s.
        speed_mm_s: f64,
        /// Angle above the floor, rad: 0 a flat kick, above 0 a chip.
        angle_rad: f64,
    },
    /// Spin the dribbler at this speed (0: off) until told otherwise.
    Dribble {
        /// Dribbler speed, rpm.
        rpm: f64,
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
    /// Whether the dribbler's light barrier sees the ball (false without a kicker).
    pub fn ball_in_dribbler(&self) -> bool {
        self.actuators.iter().any(|a| {
            matches!(
                a,
                ActuatorState::Kicker {
                    ball_in_dribbler: true,
                    ..
                }
            )
        })
    }

    /// The frame of the camera called `sensor`, if this cycle brought one.
    pub fn frame(&self, sensor: &str) -> Option<&Frame<'a>> {
        self.frames.iter().find(|f| f.sensor == sensor)
    }

    /// The image of the camera called `sensor`, or the error naming who needed it (`reader`).
    pub fn image(
        &self,
        sensor: &str,
        reader: &'static str,
    ) -> Result<&'a RgbaImage, crate::RobotError> {
        self.frames
            .iter()
            .find(|f| f.sensor == sensor)
            .map(|f| f.image)
            .ok_or_else(|| crate::RobotError::MissingFrame {
                sensor: sensor.to_string(),
                stage: reader,
            })
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

    /// Straight ahead (along the body's x axis) at `speed_mm_s`.
    pub fn forward(speed_mm_s: f64) -> Self {
        Self::translate(Vector2::new(speed_mm_s, 0.0))
    }

    /// A turn on the spot at `rate_rad_s` (counter-clockwise positive).
    pub fn turn(rate_rad_s: f64) -> Self {
        Self {
            v_mm_s: Vector2::zeros(),
            omega_rad_s: rate_rad_s,
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

impl Outputs {
    /// A drive command and the beliefs behind it, no actuator commands.
    pub fn drive(command: BodyCommand, estimates: Estimates) -> Self {
        Self {
            command,
            actuators: Vec::new(),
            estimates,
        }
    }
}

/// The robot's software: whatever turns what the robot's sensors give into commands.
///
/// The simulator calls it once a control cycle, in this order: [`cameras_now`] (which frames
/// to render), [`cycle`] with the [`Observation`] of those frames and the actuators' state,
/// then, once the world has moved on one period, [`odometry`] with the wheel encoders'
/// reading. Nothing else reaches it: no world, no true pose. The built-in stack
/// ([`crate::Robot`]) is one implementation; a user's crate, a Python object or a learning
/// agent are others.
///
/// [`cameras_now`]: RobotSoftware::cameras_now
/// [`cycle`]: RobotSoftware::cycle
/// [`odometry`]: RobotSoftware::odometry
pub trait RobotSoftware: Send {
    /// Its name in `summary.json` (`controller`); default: `custom`.
    fn name(&self) -> String {
        "custom".to_string()
    }

    /// Every camera (`[[robot.sensors]] name`) it may read: the simulator renders only these.
    fn cameras(&self) -> Vec<String>;

    /// The cameras whose frames it reads in the coming cycle (default: all of
    /// [`RobotSoftware::cameras`]); a camera left out gives no frame and draws no noise.
    fn cameras_now(&self) -> Vec<String> {
        self.cameras()
    }

    /// One control cycle: from what the sensors give to a body-frame command, actuator
    /// commands and what it believes (recorded beside the truth, never scored by it here).
    fn cycle(&mut self, obs: &Observation<'_>) -> Result<Outputs, crate::RobotError>;

    /// What the wheel encoders measured over the period that just ended.
    fn odometry(&mut self, reading: &OdometryReading);

    /// The robot was carried to a place it is not told (an experimenter moving it): its pose
    /// is unknown until it finds it again. Default: nothing to forget.
    fn forget_pose(&mut self) {}

    /// Its pose estimate now (world frame), recorded in the final row of `trajectory.csv`;
    /// default: none.
    fn estimate(&self) -> Option<nalgebra::Isometry2<f64>> {
        None
    }

    /// The map it built, if it builds one (drawn under the paths in `topview.png`); default:
    /// none.
    fn map(&self) -> Option<crate::MapSnapshot> {
        None
    }
}
