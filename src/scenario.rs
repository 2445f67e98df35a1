//! Scenario files: the schema of the TOML a user writes, with defaults, and its validation.
//!
//! Every table rejects unknown keys. Parsing and validation errors name the file, the line
//! and column, and the dotted path of the field ([`crate::scenario_error`]).

use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_control::AvoidanceConfig;
use omniloop_sim::{Layout, Rgb, SensorSpec};
use omniloop_vision::{FreeSpaceConfig, LocalizationConfig};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// A complete scenario: the world, the robot, what it should do and for how long.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Name of the scenario (default: the file name without extension).
    #[serde(default)]
    pub name: String,
    /// One line saying what the scenario shows.
    #[serde(default)]
    pub description: String,
    /// Seed of every random draw in the run (sensor noise, odometry noise).
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Timing of the run.
    #[serde(default)]
    pub run: RunSpec,
    /// Floor, field, walls, cubes and pillars.
    #[serde(default)]
    pub world: Layout,
    /// The robot under test.
    pub robot: RobotSpec,
    /// Further robots, moving obstacles driven between waypoints.
    #[serde(default)]
    pub other_robots: Vec<OtherRobotSpec>,
    /// Where the robot should go, if anywhere.
    #[serde(default)]
    pub goal: Option<GoalSpec>,
    /// Image processing.
    #[serde(default)]
    pub vision: VisionSpec,
    /// How the robot chooses its velocity.
    #[serde(default)]
    pub control: ControlSpec,
    /// The robot's wheel odometry.
    #[serde(default)]
    pub odometry: OdometrySpec,
    /// Experiment metrics to compute.
    #[serde(default)]
    pub metrics: MetricsSpec,
    /// Experiment mode: carry the robot to places and estimate its pose there, instead of
    /// driving.
    #[serde(default)]
    pub experiment: Option<ExperimentSpec>,
}

/// Experiment mode (E2): the robot is put at each place in turn and estimates its pose
/// `frames_per_place` times there, with fresh sensor noise in every frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExperimentSpec {
    /// The places (field frame).
    pub places: Vec<PoseSpec>,
    /// Estimates at each place.
    #[serde(default = "default_frames_per_place")]
    pub frames_per_place: u32,
}

fn default_frames_per_place() -> u32 {
    10
}

fn default_seed() -> u64 {
    1
}

/// Timing of the run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RunSpec {
    /// Longest simulated time; the run ends earlier when the goal is reached.
    pub duration_s: f64,
    /// Period of the control cycle (render, vision, control).
    pub control_period_s: f64,
    /// Physics step; a whole number of them makes one control period.
    pub physics_step_s: f64,
    /// End the run as soon as the goal is reached.
    pub stop_at_goal: bool,
}

impl Default for RunSpec {
    fn default() -> Self {
        Self {
            duration_s: 30.0,
            control_period_s: 0.04,
            physics_step_s: 0.002,
            stop_at_goal: true,
        }
    }
}

/// A planar pose as written in scenario files.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseSpec {
    /// x position.
    pub x_mm: f64,
    /// y position.
    pub y_mm: f64,
    /// Heading, counter-clockwise from the world x axis.
    #[serde(default)]
    pub heading_deg: f64,
}

impl PoseSpec {
    /// As an isometry (mm, rad).
    pub fn isometry(&self) -> Isometry2<f64> {
        Isometry2::new(
            Vector2::new(self.x_mm, self.y_mm),
            self.heading_deg.to_radians(),
        )
    }

    /// The position.
    pub fn point(&self) -> Point2<f64> {
        Point2::new(self.x_mm, self.y_mm)
    }
}

/// The robot under test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// Where it starts, at rest.
    pub start: PoseSpec,
    /// Disc radius.
    #[serde(default = "default_radius")]
    pub radius_mm: f64,
    /// Body height.
    #[serde(default = "default_height")]
    pub height_mm: f64,
    /// Top speed the controllers command.
    #[serde(default = "default_max_speed")]
    pub max_speed_mm_s: f64,
    /// Translational acceleration limit alpha of eq. (8).
    #[serde(default = "default_accel")]
    pub accel_limit_mm_s2: f64,
    /// Rotational acceleration limit.
    #[serde(default = "default_angular_accel")]
    pub angular_accel_limit_rad_s2: f64,
    /// Body colour.
    #[serde(default = "default_robot_rgb")]
    pub rgb: Rgb,
    /// Cameras on the robot (`[[robot.sensors]]`).
    #[serde(default)]
    pub sensors: Vec<SensorSpec>,
}

fn default_radius() -> f64 {
    90.0
}
fn default_height() -> f64 {
    110.0
}
fn default_max_speed() -> f64 {
    400.0
}
fn default_accel() -> f64 {
    300.0
}
fn default_angular_accel() -> f64 {
    10.0
}
fn default_robot_rgb() -> Rgb {
    Rgb([25, 25, 30])
}

/// Another robot: a moving obstacle that drives through its waypoints (on ground truth).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OtherRobotSpec {
    /// Where it starts, at rest.
    pub start: PoseSpec,
    /// Points it drives to in turn; empty to stand still.
    #[serde(default)]
    pub waypoints_mm: Vec<[f64; 2]>,
    /// Start again at the first waypoint after the last.
    #[serde(default)]
    pub cycle: bool,
    /// Its top speed.
    #[serde(default = "default_other_speed")]
    pub max_speed_mm_s: f64,
    /// Its acceleration limit.
    #[serde(default = "default_accel")]
    pub accel_limit_mm_s2: f64,
    /// Disc radius.
    #[serde(default = "default_radius")]
    pub radius_mm: f64,
    /// Body height.
    #[serde(default = "default_height")]
    pub height_mm: f64,
    /// Body colour.
    #[serde(default = "default_other_rgb")]
    pub rgb: Rgb,
}

fn default_other_speed() -> f64 {
    300.0
}
fn default_other_rgb() -> Rgb {
    Rgb([200, 40, 160])
}

/// The goal point, reached through optional waypoints.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GoalSpec {
    /// Points to pass (within the tolerance) in order before the goal point.
    #[serde(default)]
    pub waypoints_mm: Vec<[f64; 2]>,
    /// x of the goal point (world frame).
    pub x_mm: f64,
    /// y of the goal point (world frame).
    pub y_mm: f64,
    /// The goal is reached when the robot centre is this close.
    #[serde(default = "default_goal_tolerance")]
    pub tolerance_mm: f64,
}

fn default_goal_tolerance() -> f64 {
    100.0
}

impl GoalSpec {
    /// The goal point.
    pub fn point(&self) -> Point2<f64> {
        Point2::new(self.x_mm, self.y_mm)
    }

    /// The waypoints and then the goal point.
    pub fn targets(&self) -> Vec<Point2<f64>> {
        self.waypoints_mm
            .iter()
            .map(|w| Point2::new(w[0], w[1]))
            .chain(std::iter::once(self.point()))
            .collect()
    }
}

/// Which controller drives the robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ControllerKind {
    /// Stand still.
    Idle,
    /// Straight to the goal on the true pose (a reference that needs no vision).
    #[default]
    GoToGoalTruth,
    /// Free direction closest to the goal direction, from the image (ref. [4] of the corner
    /// paper); goal dead-reckoned from odometry.
    GoalDirection,
    /// Velocity-aware avoidance of Sect. 3.2, from the image; goal dead-reckoned.
    VelocityAware,
}

impl ControllerKind {
    /// Whether the controller needs the free-space detection.
    pub fn uses_vision(self) -> bool {
        matches!(self, Self::GoalDirection | Self::VelocityAware)
    }
}

/// How the robot chooses its velocity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControlSpec {
    /// The controller.
    pub kind: ControllerKind,
    /// Settings of the avoidance controllers.
    pub avoidance: AvoidanceConfig,
    /// Where the vision controllers' pose comes from.
    pub pose_source: PoseSource,
    /// With `pose_source = "localization"`: how far each localization pulls the dead-reckoned
    /// pose toward itself (0: odometry only, 1: jump to the measurement).
    pub localization_gain: f64,
}

/// Where the vision controllers' pose estimate comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum PoseSource {
    /// Dead reckoning from wheel odometry alone (the goal is given in the start frame).
    #[default]
    Odometry,
    /// Odometry corrected by floor-region self-localization every cycle (the goal and the
    /// start are in the field frame).
    Localization,
}

impl Default for ControlSpec {
    fn default() -> Self {
        Self {
            kind: ControllerKind::default(),
            avoidance: AvoidanceConfig::default(),
            pose_source: PoseSource::Odometry,
            localization_gain: 0.3,
        }
    }
}

/// Image processing settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct VisionSpec {
    /// The sensor whose images vision uses (default: the robot's first).
    pub sensor: Option<String>,
    /// A calibration table written by `omniloop calibrate` (relative to the scenario file);
    /// default: traced from the sensor's optics at start.
    pub calibration_file: Option<PathBuf>,
    /// Free-space detection (Sect. 3.1 of the corner paper).
    pub freespace: FreeSpaceConfig,
    /// Self-localization from the floor region (Sect. 4 of the corner paper).
    pub localization: LocalizationConfig,
}

/// The robot's wheel odometry: the true body velocity with systematic and seeded Gaussian
/// errors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OdometrySpec {
    /// Standard deviation of the relative error of each velocity component.
    pub speed_noise_frac: f64,
    /// Standard deviation of the rotation-rate error.
    pub omega_noise_rad_s: f64,
    /// Systematic scale error of the measured speed (e.g. a wheel radius off by this fraction).
    pub scale_bias_frac: f64,
    /// Systematic rotation-rate error (gyro bias, wheel slip).
    pub omega_bias_rad_s: f64,
}

impl Default for OdometrySpec {
    fn default() -> Self {
        Self {
            speed_noise_frac: 0.01,
            omega_noise_rad_s: 0.0,
            scale_bias_frac: 0.0,
            omega_bias_rad_s: 0.0,
        }
    }
}

/// Experiment metrics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct MetricsSpec {
    /// The corner metrics of E1 (`turn_onset_mm`, `overshoot_mm`).
    pub corner: Option<CornerSpec>,
}

/// The corner of E1: the corner point K and the direction of the first leg.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CornerSpec {
    /// K, where the legs' centre lines meet.
    pub k_mm: [f64; 2],
    /// Direction u1 of the first leg.
    pub leg1_heading_deg: f64,
}

impl Scenario {
    /// Parses a scenario from TOML text (no validation; see [`crate::load_scenario`]).
    pub fn from_toml(text: &str) -> Result<Self, toml::de::Error> {
        toml::from_str(text)
    }

    /// The robot bodies of the world: the robot under test first, then the others.
    pub fn robot_bodies(&self) -> Vec<omniloop_sim::RobotBodySpec> {
        let mut out = vec![omniloop_sim::RobotBodySpec {
            start: self.robot.start.isometry(),
            radius_mm: self.robot.radius_mm,
            height_mm: self.robot.height_mm,
            accel_limit_mm_s2: self.robot.accel_limit_mm_s2,
            angular_accel_limit_rad_s2: self.robot.angular_accel_limit_rad_s2,
            rgb: self.robot.rgb,
        }];
        for o in &self.other_robots {
            out.push(omniloop_sim::RobotBodySpec {
                start: o.start.isometry(),
                radius_mm: o.radius_mm,
                height_mm: o.height_mm,
                accel_limit_mm_s2: o.accel_limit_mm_s2,
                angular_accel_limit_rad_s2: default_angular_accel(),
                rgb: o.rgb,
            });
        }
        out
    }

    /// The sensor called `name`, or the first one when `name` is `None`.
    pub fn sensor(&self, name: Option<&str>) -> Option<&SensorSpec> {
        match name {
            Some(n) => self.robot.sensors.iter().find(|s| s.name == n),
            None => self.robot.sensors.first(),
        }
    }

    /// Number of control cycles the run lasts at most.
    pub fn max_cycles(&self) -> u64 {
        (self.run.duration_s / self.run.control_period_s).round() as u64
    }
}

/// The name of a controller as written in scenario files.
pub fn controller_name(kind: ControllerKind) -> String {
    match toml::Value::try_from(kind) {
        Ok(toml::Value::String(s)) => s,
        _ => format!("{kind:?}"),
    }
}
