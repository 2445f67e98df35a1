//! The SSL simulation protocol's messages (github.com/RoboCup-SSL/ssl-simulation-protocol,
//! proto2, no package), written from its documentation with its field numbers. Units are the
//! protocol's: metres, m/s, radians (degrees for the kick angle), rpm. Every field the
//! protocol marks optional is an `Option`: unset means "leave unchanged".

use super::vision::GeometryData;

/// A team's colour (`Team` of the game controller's common types).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, prost::Enumeration)]
#[repr(i32)]
pub enum Team {
    /// Not set.
    Unknown = 0,
    /// Yellow.
    Yellow = 1,
    /// Blue.
    Blue = 2,
}

/// A robot by team and number (`RobotId`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct RobotId {
    /// Its number.
    #[prost(uint32, optional, tag = "1")]
    pub id: Option<u32>,
    /// Its team ([`Team`]).
    #[prost(enumeration = "Team", optional, tag = "2")]
    pub team: Option<i32>,
}

/// One robot's command (`RobotCommand`); the team is the port's.
#[derive(Clone, PartialEq, prost::Message)]
pub struct RobotCommand {
    /// The robot's number.
    #[prost(uint32, required, tag = "1")]
    pub id: u32,
    /// How it is to move.
    #[prost(message, optional, tag = "2")]
    pub move_command: Option<RobotMoveCommand>,
    /// Kick speed, m/s (absolute, 3-D); 0 or unset: no kick.
    #[prost(float, optional, tag = "3")]
    pub kick_speed: Option<f32>,
    /// Kick angle above the floor, degrees (0: a flat kick).
    #[prost(float, optional, tag = "4", default = "0")]
    pub kick_angle: Option<f32>,
    /// Dribbler speed, rpm.
    #[prost(float, optional, tag = "5")]
    pub dribbler_speed: Option<f32>,
}

/// How a robot is to move (`RobotMoveCommand`): one of three.
#[derive(Clone, PartialEq, prost::Message)]
pub struct RobotMoveCommand {
    /// The command.
    #[prost(oneof = "MoveCommand", tags = "1, 2, 3")]
    pub command: Option<MoveCommand>,
}

/// The oneof of [`RobotMoveCommand`].
#[derive(Clone, PartialEq, prost::Oneof)]
pub enum MoveCommand {
    /// Each wheel's speed.
    #[prost(message, tag = "1")]
    WheelVelocity(MoveWheelVelocity),
    /// The robot's velocity in its own frame.
    #[prost(message, tag = "2")]
    LocalVelocity(MoveLocalVelocity),
    /// The robot's velocity in the field frame.
    #[prost(message, tag = "3")]
    GlobalVelocity(MoveGlobalVelocity),
}

/// Wheel speeds at the wheels' rims, m/s (`MoveWheelVelocity`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct MoveWheelVelocity {
    /// Front right.
    #[prost(float, required, tag = "1")]
    pub front_right: f32,
    /// Back right.
    #[prost(float, required, tag = "2")]
    pub back_right: f32,
    /// Back left.
    #[prost(float, required, tag = "3")]
    pub back_left: f32,
    /// Front left.
    #[prost(float, required, tag = "4")]
    pub front_left: f32,
}

/// Velocity in the robot's frame (`MoveLocalVelocity`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct MoveLocalVelocity {
    /// Toward the dribbler, m/s.
    #[prost(float, required, tag = "1")]
    pub forward: f32,
    /// To the robot's left, m/s.
    #[prost(float, required, tag = "2")]
    pub left: f32,
    /// Counter-clockwise, rad/s.
    #[prost(float, required, tag = "3")]
    pub angular: f32,
}

/// Velocity in the field frame (`MoveGlobalVelocity`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct MoveGlobalVelocity {
    /// Along the field's x, m/s.
    #[prost(float, required, tag = "1")]
    pub x: f32,
    /// Along the field's y, m/s.
    #[prost(float, required, tag = "2")]
    pub y: f32,
    /// Counter-clockwise, rad/s.
    #[prost(float, required, tag = "3")]
    pub angular: f32,
}

/// A team's commands, to its robot-control port (`RobotControl`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct RobotControl {
    /// One for each robot commanded.
    #[prost(message, repeated, tag = "1")]
    pub robot_commands: Vec<RobotCommand>,
}

/// A robot's feedback (`RobotFeedback`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct RobotFeedback {
    /// The robot's number.
    #[prost(uint32, required, tag = "1")]
    pub id: u32,
    /// Whether its dribbler touches the ball now (the light barrier).
    #[prost(bool, optional, tag = "2")]
    pub dribbler_ball_contact: Option<bool>,
    /// Simulator-specific.
    #[prost(message, optional, tag = "3")]
    pub custom: Option<prost_types::Any>,
}

/// The answer on a robot-control port (`RobotControlResponse`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct RobotControlResponse {
    /// What went wrong.
    #[prost(message, repeated, tag = "1")]
    pub errors: Vec<SimulatorError>,
    /// The team's robots' feedback.
    #[prost(message, repeated, tag = "2")]
    pub feedback: Vec<RobotFeedback>,
}

/// An error for the client (`SimulatorError`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct SimulatorError {
    /// Unique in this simulator, for software to act on.
    #[prost(string, optional, tag = "1")]
    pub code: Option<String>,
    /// For people.
    #[prost(string, optional, tag = "2")]
    pub message: Option<String>,
}

/// Moves the ball (`TeleportBall`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct TeleportBall {
    /// m.
    #[prost(float, optional, tag = "1")]
    pub x: Option<f32>,
    /// m.
    #[prost(float, optional, tag = "2")]
    pub y: Option<f32>,
    /// Height, m.
    #[prost(float, optional, tag = "3")]
    pub z: Option<f32>,
    /// m/s.
    #[prost(float, optional, tag = "4")]
    pub vx: Option<f32>,
    /// m/s.
    #[prost(float, optional, tag = "5")]
    pub vy: Option<f32>,
    /// m/s.
    #[prost(float, optional, tag = "6")]
    pub vz: Option<f32>,
    /// Move robots out of the ball's way.
    #[prost(bool, optional, tag = "7", default = "false")]
    pub teleport_safely: Option<bool>,
    /// Give the ball the spin of rolling.
    #[prost(bool, optional, tag = "8", default = "false")]
    pub roll: Option<bool>,
    /// Push it there instead of teleporting it.
    #[prost(bool, optional, tag = "9", default = "false")]
    pub by_force: Option<bool>,
}

/// Moves, adds or removes a robot (`TeleportRobot`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct TeleportRobot {
    /// Which.
    #[prost(message, required, tag = "1")]
    pub id: RobotId,
    /// m.
    #[prost(float, optional, tag = "2")]
    pub x: Option<f32>,
    /// m.
    #[prost(float, optional, tag = "3")]
    pub y: Option<f32>,
    /// rad, counter-clockwise from the field's x.
    #[prost(float, optional, tag = "4")]
    pub orientation: Option<f32>,
    /// m/s, field frame.
    #[prost(float, optional, tag = "5", default = "0")]
    pub v_x: Option<f32>,
    /// m/s, field frame.
    #[prost(float, optional, tag = "6", default = "0")]
    pub v_y: Option<f32>,
    /// rad/s.
    #[prost(float, optional, tag = "7", default = "0")]
    pub v_angular: Option<f32>,
    /// On the field (added if absent) or not (removed).
    #[prost(bool, optional, tag = "8")]
    pub present: Option<bool>,
    /// Push it there instead of teleporting it.
    #[prost(bool, optional, tag = "9", default = "false")]
    pub by_force: Option<bool>,
}

/// Controls the simulation (`SimulatorControl`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct SimulatorControl {
    /// The ball.
    #[prost(message, optional, tag = "1")]
    pub teleport_ball: Option<TeleportBall>,
    /// Robots.
    #[prost(message, repeated, tag = "2")]
    pub teleport_robot: Vec<TeleportRobot>,
    /// Simulated time over wall time.
    #[prost(float, optional, tag = "3")]
    pub simulation_speed: Option<f32>,
}

/// A robot's acceleration and speed limits (`RobotLimits`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct RobotLimits {
    /// m/s².
    #[prost(float, optional, tag = "1")]
    pub acc_speedup_absolute_max: Option<f32>,
    /// rad/s².
    #[prost(float, optional, tag = "2")]
    pub acc_speedup_angular_max: Option<f32>,
    /// m/s².
    #[prost(float, optional, tag = "3")]
    pub acc_brake_absolute_max: Option<f32>,
    /// rad/s².
    #[prost(float, optional, tag = "4")]
    pub acc_brake_angular_max: Option<f32>,
    /// m/s.
    #[prost(float, optional, tag = "5")]
    pub vel_absolute_max: Option<f32>,
    /// rad/s.
    #[prost(float, optional, tag = "6")]
    pub vel_angular_max: Option<f32>,
}

/// The wheels' directions, rad from forward, clockwise (`RobotWheelAngles`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct RobotWheelAngles {
    /// Front right.
    #[prost(float, required, tag = "1")]
    pub front_right: f32,
    /// Back right.
    #[prost(float, required, tag = "2")]
    pub back_right: f32,
    /// Back left.
    #[prost(float, required, tag = "3")]
    pub back_left: f32,
    /// Front left.
    #[prost(float, required, tag = "4")]
    pub front_left: f32,
}

/// A robot's specification (`RobotSpecs`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct RobotSpecs {
    /// Which robot.
    #[prost(message, required, tag = "1")]
    pub id: RobotId,
    /// m.
    #[prost(float, optional, tag = "2", default = "0.09")]
    pub radius: Option<f32>,
    /// m.
    #[prost(float, optional, tag = "3", default = "0.15")]
    pub height: Option<f32>,
    /// kg.
    #[prost(float, optional, tag = "4")]
    pub mass: Option<f32>,
    /// m/s (unset: no limit).
    #[prost(float, optional, tag = "7")]
    pub max_linear_kick_speed: Option<f32>,
    /// m/s (unset: no limit).
    #[prost(float, optional, tag = "8")]
    pub max_chip_kick_speed: Option<f32>,
    /// Centre to the dribbler, m.
    #[prost(float, optional, tag = "9")]
    pub center_to_dribbler: Option<f32>,
    /// Limits.
    #[prost(message, optional, tag = "10")]
    pub limits: Option<RobotLimits>,
    /// The wheels.
    #[prost(message, optional, tag = "13")]
    pub wheel_angles: Option<RobotWheelAngles>,
    /// Simulator-specific.
    #[prost(message, repeated, tag = "14")]
    pub custom: Vec<prost_types::Any>,
}

/// Realism, simulator-specific (`RealismConfig`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct RealismConfig {
    /// Simulator-specific messages.
    #[prost(message, repeated, tag = "1")]
    pub custom: Vec<prost_types::Any>,
}

/// Changes the simulation's setup (`SimulatorConfig`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct SimulatorConfig {
    /// The field.
    #[prost(message, optional, tag = "1")]
    pub geometry: Option<GeometryData>,
    /// Robots' specifications.
    #[prost(message, repeated, tag = "2")]
    pub robot_specs: Vec<RobotSpecs>,
    /// Realism.
    #[prost(message, optional, tag = "3")]
    pub realism_config: Option<RealismConfig>,
    /// Where vision goes, port.
    #[prost(uint32, optional, tag = "4")]
    pub vision_port: Option<u32>,
}

/// To the simulation-control port (`SimulatorCommand`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct SimulatorCommand {
    /// Control.
    #[prost(message, optional, tag = "1")]
    pub control: Option<SimulatorControl>,
    /// Configuration.
    #[prost(message, optional, tag = "2")]
    pub config: Option<SimulatorConfig>,
}

/// From the simulation-control port (`SimulatorResponse`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct SimulatorResponse {
    /// What went wrong.
    #[prost(message, repeated, tag = "1")]
    pub errors: Vec<SimulatorError>,
}

/// One lockstep exchange (`SimulationSyncRequest`, the protocol's draft synchronous message):
/// apply the commands, then advance the simulation by `sim_step`.
#[derive(Clone, PartialEq, prost::Message)]
pub struct SimulationSyncRequest {
    /// How far to advance, s (0 or unset: not at all).
    #[prost(float, optional, tag = "1")]
    pub sim_step: Option<f32>,
    /// Control and configuration, applied first.
    #[prost(message, optional, tag = "2")]
    pub simulator_command: Option<SimulatorCommand>,
    /// A team's robot commands.
    #[prost(message, optional, tag = "3")]
    pub robot_control: Option<RobotControl>,
}

/// The answer to a [`SimulationSyncRequest`] (`SimulationSyncResponse`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct SimulationSyncResponse {
    /// The detection frames of the step.
    #[prost(message, repeated, tag = "1")]
    pub detection: Vec<super::vision::DetectionFrame>,
    /// Feedback and errors.
    #[prost(message, optional, tag = "2")]
    pub robot_control_response: Option<RobotControlResponse>,
}
