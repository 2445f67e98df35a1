//! Scenario files: the schema of the TOML a user writes, with its defaults.
//!
//! Every table rejects unknown keys, but for the tables that registered parts own and check
//! themselves (`[control.*]` of controllers and stages, `[experiment.NAME]`).

use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_control::DifferentialDrive;
use omniloop_problem::Problem;
use omniloop_robot::perception::CameraNeed;
use omniloop_robot::{
    BodySpec, ControlSpec, GoalSpec, KickerBody, MapLandmark, MapMark, MapSegment, RobotConfig,
    StageEntry, StereoRig, Tables, VisionSpec, WorldMap, stages_of,
};
use omniloop_sim::{Layout, MapFeature, Rgb, SensorSpec};
use omniloop_vision::RadialCalibration;
use omniloop_vision::forward::ForwardCamera;
use omniloop_vision::omnistereo::OmnistereoConfig;
use omniloop_vision::resection::{ColumnCalibration, StripePattern};
use serde::{Deserialize, Serialize};

/// Why a scenario's robot has no sensor of a name ([`Scenario::sensor_index`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SensorLookupError {
    /// No sensor has the name.
    #[error("the robot has no sensor {name:?} (it has{})", it_has(.sensors))]
    NoSuchSensor {
        /// The name asked for.
        name: String,
        /// The robot's sensors' names.
        sensors: Vec<String>,
    },
    /// The robot has no sensor at all.
    #[error("the robot has no sensor (add a [[robot.sensors]] table)")]
    NoSensor,
}

/// ` none` or `: NAME, NAME`: the sensors a robot has.
fn it_has(sensors: &[String]) -> String {
    if sensors.is_empty() {
        " none".to_string()
    } else {
        format!(": {}", sensors.join(", "))
    }
}

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
    /// The robot under test; with `[[robots]]`, the settings every robot of the team shares
    /// (each robot's own keys are written over them).
    #[serde(default)]
    pub robot: RobotSpec,
    /// A team (`[[robots]]`): each robot named and written as the keys of `[robot]` (start,
    /// body, sensors, timing, marking) and of its own `goal`, `vision`, `control` and
    /// `odometry` tables, over the shared `[robot]`, `[goal]`, `[vision]`, `[control]` and
    /// `[odometry]` (see [`super::team`]). Empty: the one robot of `[robot]`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub robots: Vec<toml::Table>,
    /// The team as resolved when the scenario was loaded: every robot complete.
    #[serde(skip)]
    pub team: Vec<TeamMember>,
    /// Further robots, moving obstacles driven between waypoints.
    #[serde(default)]
    pub other_robots: Vec<OtherRobotSpec>,
    /// Where the robot should go, if anywhere.
    #[serde(default)]
    pub goal: Option<GoalSpec>,
    /// Image processing.
    #[serde(default)]
    pub vision: VisionSpec,
    /// How the robot chooses its velocity and where its pose estimate comes from.
    #[serde(default)]
    pub control: ControlSpec,
    /// The errors of the robot's wheel odometry.
    #[serde(default)]
    pub odometry: OdometrySpec,
    /// The experiment this scenario belongs to (`[experiment.NAME]`, a registered experiment
    /// that parses its own table): its procedure and metrics. Without one, the robot drives
    /// until the goal or the time is up.
    #[serde(default, skip_serializing_if = "Tables::is_empty")]
    pub experiment: Tables,
    /// The scenario as a Small-Size League simulator (`omniloop ssl`): teams, ports, overhead
    /// vision, referee. Other commands ignore it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ssl: Option<super::ssl::SslSpec>,
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
    /// Who drives the robot: its software (`"robot"`), or the simulator's pilot on the true
    /// pose (`"truth"`, a reference that needs no vision: the software still runs and is
    /// recorded, but its commands are not applied).
    pub pilot: PilotChoice,
}

/// Who drives the robot under test (`run.pilot`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PilotChoice {
    /// Its software.
    #[default]
    Robot,
    /// The simulator, straight to the goal's targets on the true pose.
    Truth,
}

impl Default for RunSpec {
    fn default() -> Self {
        Self {
            duration_s: 30.0,
            control_period_s: 0.04,
            physics_step_s: 0.002,
            stop_at_goal: true,
            pilot: PilotChoice::Robot,
        }
    }
}

/// A planar pose as written in scenario files.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
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

/// The robot under test (or a robot of a team).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// Its name (a team's robots each need one: letters, digits, `_` and `-`); the one
    /// robot of `[robot]` is `robot` unless named.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Where it starts, at rest (required, unless the experiment places the robot).
    #[serde(default)]
    pub start: Option<PoseSpec>,
    /// Disc radius.
    #[serde(default = "default_radius")]
    pub radius_mm: f64,
    /// Body height.
    #[serde(default = "default_height")]
    pub height_mm: f64,
    /// Top speed: the controllers command at most this, and the world scales a faster command
    /// down to it by its norm (from Rust, Python, Gymnasium, PettingZoo and ROS 2 alike).
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
    /// Colour of the top of its body, which the other robots' cameras see (a team's
    /// marking); default: the body colour.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub marking_rgb: Option<Rgb>,
    /// Cameras on the robot (`[[robot.sensors]]`).
    #[serde(default)]
    pub sensors: Vec<SensorSpec>,
    /// A differential drive (`[robot.differential]`): the robot moves along its heading and
    /// turns on the spot; without it the robot is omnidirectional.
    #[serde(default)]
    pub differential: Option<DifferentialSpec>,
    /// When frames and commands arrive (`[robot.timing]`; default: at once, none lost).
    #[serde(default, skip_serializing_if = "TimingSpec::is_ideal")]
    pub timing: TimingSpec,
    /// A kicker and a dribbler on a flat front (`[robot.kicker]`), to play the ball.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kicker: Option<omniloop_sim::KickerSpec>,
}

/// Latency and loss between the robot's software and its cameras and drive
/// (`[robot.timing]`), drawn from the run's seed.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TimingSpec {
    /// A frame reaches the robot's software this long after it was captured (its `t_s` is the
    /// capture time).
    pub frame_latency_s: f64,
    /// Probability that a frame is lost (the software gets no frame of that camera that
    /// cycle).
    pub frame_drop_rate: f64,
    /// A command reaches the drive this long after the software gave it.
    pub command_latency_s: f64,
}

impl TimingSpec {
    /// Whether frames and commands arrive at once and none is lost.
    pub fn is_ideal(&self) -> bool {
        *self == Self::default()
    }
}

/// A two-wheeled differential drive (`[robot.differential]`). Its top wheel speed is
/// `robot.max_speed_mm_s`; its accelerations are `robot.accel_limit_mm_s2` and
/// `robot.angular_accel_limit_rad_s2`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DifferentialSpec {
    /// Distance between the wheels.
    pub track_mm: f64,
    /// Fastest turn.
    pub max_turn_rate_deg_s: f64,
}

impl Default for DifferentialSpec {
    fn default() -> Self {
        Self {
            track_mm: 100.0,
            max_turn_rate_deg_s: 90.0,
        }
    }
}

impl Default for RobotSpec {
    fn default() -> Self {
        Self {
            name: None,
            start: None,
            radius_mm: default_radius(),
            height_mm: default_height(),
            max_speed_mm_s: default_max_speed(),
            accel_limit_mm_s2: default_accel(),
            angular_accel_limit_rad_s2: default_angular_accel(),
            rgb: default_robot_rgb(),
            marking_rgb: None,
            sensors: Vec::new(),
            differential: None,
            timing: TimingSpec::default(),
            kicker: None,
        }
    }
}

/// A robot of a team, complete: its entry of `[[robots]]` written over the shared tables.
#[derive(Debug, Clone, PartialEq)]
pub struct TeamMember {
    /// Its name.
    pub name: String,
    /// Its start, body, sensors, timing and marking.
    pub robot: RobotSpec,
    /// Where it goes, if anywhere.
    pub goal: Option<GoalSpec>,
    /// Its image processing.
    pub vision: VisionSpec,
    /// Its controller and pose source.
    pub control: ControlSpec,
    /// The errors of its wheel odometry.
    pub odometry: OdometrySpec,
}

/// The seed of robot `k` of a team: the scenario's for the first (a team of one runs as the
/// one-robot form does, bit for bit), a SplitMix64 draw from it for the others.
pub fn member_seed(seed: u64, k: usize) -> u64 {
    if k == 0 {
        return seed;
    }
    let mut z = seed.wrapping_add((k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The name of the one robot of `[robot]` when it names none.
pub const DEFAULT_ROBOT_NAME: &str = "robot";

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

/// The errors of the robot's wheel odometry (`[odometry]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OdometrySpec {
    /// Standard deviation of the relative error of each velocity component.
    pub speed_noise_frac: f64,
    /// Standard deviation of the rotation-rate error, rad/s.
    pub omega_noise_rad_s: f64,
    /// Systematic scale error of the measured speed (e.g. a wheel radius off by this fraction).
    pub scale_bias_frac: f64,
    /// Systematic rotation-rate error (gyro bias, wheel slip), rad/s.
    pub omega_bias_rad_s: f64,
    /// Wheel slip that grows with acceleration, s: the wheels read the body's velocity plus
    /// `slip_s` times its acceleration (body frame) over the last period.
    #[serde(skip_serializing_if = "is_zero")]
    pub slip_s: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl Default for OdometrySpec {
    fn default() -> Self {
        Self {
            speed_noise_frac: 0.01,
            omega_noise_rad_s: 0.0,
            scale_bias_frac: 0.0,
            omega_bias_rad_s: 0.0,
            slip_s: 0.0,
        }
    }
}

impl Scenario {
    /// Parses a scenario from TOML text (no validation; see [`crate::load_scenario`]).
    pub fn from_toml(text: &str) -> Result<Self, toml::de::Error> {
        toml::from_str(text)
    }

    /// The robot bodies of the world: the robots with software first (the one robot, or
    /// the team in its order), then the other robots.
    pub fn robot_bodies(&self) -> Vec<omniloop_sim::RobotBodySpec> {
        let mut out: Vec<omniloop_sim::RobotBodySpec> =
            self.members().iter().map(Self::own_body).collect();
        for o in &self.other_robots {
            out.push(omniloop_sim::RobotBodySpec {
                start: o.start.isometry(),
                radius_mm: o.radius_mm,
                height_mm: o.height_mm,
                accel_limit_mm_s2: o.accel_limit_mm_s2,
                angular_accel_limit_rad_s2: default_angular_accel(),
                max_speed_mm_s: o.max_speed_mm_s,
                rgb: o.rgb,
                marking_rgb: None,
                differential: None,
                kicker: None,
            });
        }
        out
    }

    /// The body of the one robot of a one-robot scenario (a member's view).
    fn own_body(&self) -> omniloop_sim::RobotBodySpec {
        omniloop_sim::RobotBodySpec {
            start: self.start().isometry(),
            radius_mm: self.robot.radius_mm,
            height_mm: self.robot.height_mm,
            accel_limit_mm_s2: self.robot.accel_limit_mm_s2,
            angular_accel_limit_rad_s2: self.robot.angular_accel_limit_rad_s2,
            max_speed_mm_s: self.robot.max_speed_mm_s,
            rgb: self.robot.rgb,
            marking_rgb: self.robot.marking_rgb,
            differential: self.differential_drive(),
            kicker: self.robot.kicker,
        }
    }

    /// Whether the scenario has a team (`[[robots]]`).
    pub fn is_team(&self) -> bool {
        !self.team.is_empty()
    }

    /// The robots that run software, each as a one-robot scenario of its own: its robot,
    /// goal, vision, control and odometry, its seed (the scenario's for the first robot, one
    /// drawn from it for the others); the rest is the scenario's. One robot: the scenario.
    pub fn members(&self) -> Vec<Scenario> {
        if self.team.is_empty() {
            return vec![self.clone()];
        }
        (0..self.team.len()).map(|k| self.member(k)).collect()
    }

    /// Robot `k` of the team as a one-robot scenario (see [`Scenario::members`]).
    pub fn member(&self, k: usize) -> Scenario {
        let Some(m) = self.team.get(k) else {
            return self.clone();
        };
        Scenario {
            seed: member_seed(self.seed, k),
            robot: m.robot.clone(),
            robots: Vec::new(),
            team: Vec::new(),
            goal: m.goal.clone(),
            vision: m.vision.clone(),
            control: m.control.clone(),
            odometry: m.odometry.clone(),
            ..self.clone()
        }
    }

    /// The names of the robots that run software, in order.
    pub fn robot_names(&self) -> Vec<String> {
        if self.team.is_empty() {
            return vec![self.robot_name().to_string()];
        }
        self.team.iter().map(|m| m.name.clone()).collect()
    }

    /// Whether a robot has a goal (the one robot's `[goal]`, or any of a team's).
    pub fn has_goal(&self) -> bool {
        match self.team.is_empty() {
            true => self.goal.is_some(),
            false => self.team.iter().any(|m| m.goal.is_some()),
        }
    }

    /// The name of the one robot (`robot.name`, default `robot`).
    pub fn robot_name(&self) -> &str {
        self.robot.name.as_deref().unwrap_or(DEFAULT_ROBOT_NAME)
    }

    /// The drive of a differential robot (validation makes sure its numbers are good).
    pub fn differential_drive(&self) -> Option<DifferentialDrive> {
        let r = &self.robot;
        let d = r.differential.as_ref()?;
        DifferentialDrive::new(
            d.track_mm,
            r.max_speed_mm_s,
            d.max_turn_rate_deg_s.to_radians(),
            r.accel_limit_mm_s2,
            r.angular_accel_limit_rad_s2,
        )
        .ok()
    }

    /// The index of the robot's sensor called `name`, or of its first sensor when `name` is
    /// `None`; the error says which sensors there are.
    pub fn sensor_index(&self, name: Option<&str>) -> Result<usize, SensorLookupError> {
        let sensors = &self.robot.sensors;
        match name {
            Some(n) => sensors.iter().position(|s| s.name == n).ok_or_else(|| {
                SensorLookupError::NoSuchSensor {
                    name: n.to_string(),
                    sensors: sensors.iter().map(|s| s.name.clone()).collect(),
                }
            }),
            None if sensors.is_empty() => Err(SensorLookupError::NoSensor),
            None => Ok(0),
        }
    }

    /// The sensor called `name`, or the first one when `name` is `None`.
    pub fn sensor(&self, name: Option<&str>) -> Result<&SensorSpec, SensorLookupError> {
        self.sensor_index(name).map(|i| &self.robot.sensors[i])
    }

    /// The index of the sensor vision uses (`vision.sensor`, else the first).
    pub fn vision_sensor_index(&self) -> Result<usize, SensorLookupError> {
        self.sensor_index(self.vision.sensor.as_deref())
    }

    /// The configuration of the robot's software: what it is told of its start, its body and
    /// cameras, with the image-to-floor calibrations of the cameras vision uses.
    pub fn robot_config(
        &self,
        calibrations: Vec<RadialCalibration>,
        columns: Vec<ColumnCalibration>,
    ) -> RobotConfig {
        let r = &self.robot;
        RobotConfig {
            name: self.robot_name().to_string(),
            start: self.start().isometry(),
            body: BodySpec {
                radius_mm: r.radius_mm,
                max_speed_mm_s: r.max_speed_mm_s,
                accel_limit_mm_s2: r.accel_limit_mm_s2,
                angular_accel_limit_rad_s2: r.angular_accel_limit_rad_s2,
                kicker: r.kicker.as_ref().map(|k| KickerBody {
                    front_mm: k.front_mm,
                    max_kick_mm_s: k.max_kick_mm_s,
                }),
            },
            control_period_s: self.run.control_period_s,
            cameras: r.sensors.iter().map(|s| s.name.clone()).collect(),
            calibrations,
            columns,
            forward_camera: self.forward_camera(),
            vision: self.vision.clone(),
            control: self.control.clone(),
            goal: self.goal.clone(),
            map: self.robot_map(),
            stereo: self.stereo_rig().ok(),
            seed: self.seed,
        }
    }

    /// Vision's camera as the robot knows it when it is a pinhole: size, principal point,
    /// focal length, height, tilt and mount (design constants of a forward camera).
    pub fn forward_camera(&self) -> Option<ForwardCamera> {
        let s = self.sensor(self.vision.sensor.as_deref()).ok()?;
        let p = s.optics.pinhole()?;
        let built = s.build();
        Some(ForwardCamera {
            sensor: s.name.clone(),
            width_px: s.width_px,
            height_px: s.height_px,
            cx_px: built.cx_px,
            cy_px: built.cy_px,
            focal_px: p.focal_px,
            height_mm: p.height_mm,
            tilt_rad: p.tilt_deg.to_radians(),
            mount_mm: s.mount_mm,
        })
    }

    /// The map the robot is given: what each kind of thing on the floor puts in it (the
    /// pillars as landmarks by colour, walls and boards as straight obstacles, the cubes as
    /// boxes which may be moved, the field's walls and the corridors' faces as the floor's
    /// bounds, the named boards as marks, the field's figures with its defense areas).
    pub fn robot_map(&self) -> WorldMap {
        let mut map = WorldMap {
            landmarks: Vec::new(),
            segments: Vec::new(),
            boxes: Vec::new(),
            bounds: Vec::new(),
            marks: Vec::new(),
            field: self.world.field.as_ref().map(|f| omniloop_robot::FieldMap {
                half_length_mm: f.half_length_mm,
                half_width_mm: f.half_width_mm,
                goal_width_mm: f.goal_width_mm,
                defense_depth_mm: 0.0,
                defense_width_mm: 0.0,
                run_off_mm: f.boundary_width_mm,
            }),
        };
        for feature in self.world.map_features() {
            match feature {
                MapFeature::Landmark {
                    centre_mm,
                    radius_mm,
                    rgb,
                } => map.landmarks.push(MapLandmark {
                    centre_mm,
                    radius_mm,
                    rgb: rgb.0,
                }),
                MapFeature::Segment {
                    from_mm,
                    to_mm,
                    half_thickness_mm,
                } => map.segments.push(MapSegment {
                    from_mm,
                    to_mm,
                    half_thickness_mm,
                }),
                MapFeature::Bound {
                    from_mm,
                    to_mm,
                    half_thickness_mm,
                } => map.bounds.push(MapSegment {
                    from_mm,
                    to_mm,
                    half_thickness_mm,
                }),
                MapFeature::BoxEdge { from_mm, to_mm } => map.boxes.push(MapSegment {
                    from_mm,
                    to_mm,
                    half_thickness_mm: 0.0,
                }),
                MapFeature::Mark {
                    name,
                    centre_mm,
                    stripes,
                } => map.marks.push(MapMark {
                    centre_mm,
                    pattern: StripePattern::new(&name, &stripes),
                }),
                // The robot's field map holds the defense areas of the painted lines (it has no
                // place yet for the centre circle and the halfway line).
                MapFeature::Lines(lines) => {
                    if let Some(f) = map.field.as_mut() {
                        f.defense_depth_mm = lines.defense_area_depth_mm;
                        f.defense_width_mm = lines.defense_area_width_mm;
                    }
                }
            }
        }
        map
    }

    /// The omnistereo rig of `vision.omnistereo`'s two sensors, or the field at fault and why.
    pub fn stereo_rig(&self) -> Result<StereoRig, Problem> {
        let o: OmnistereoConfig = self.vision.table("omnistereo")?;
        let cone = |key: &str, name: &str| {
            let field = format!("vision.omnistereo.{key}");
            let s = self
                .robot
                .sensors
                .iter()
                .find(|s| s.name == name)
                .ok_or_else(|| {
                    Problem::new(field.as_str(), format!("the robot has no sensor {name:?}"))
                })?;
            let m = s.optics.conical().ok_or_else(|| {
                Problem::new(
                    field.as_str(),
                    format!("sensor {name:?} is not a conical mirror"),
                )
            })?;
            if (m.apex_angle_deg - 90.0).abs() > 1e-9 {
                return Err(Problem::new(
                    field,
                    format!(
                        "eqs. (1)-(2) hold for 90-degree cones; {name:?} has {} degrees",
                        m.apex_angle_deg
                    ),
                ));
            }
            Ok((s, m))
        };
        let (ls, lower) = cone("lower_sensor", &o.lower_sensor)?;
        let (us, upper) = cone("upper_sensor", &o.upper_sensor)?;
        let field = || "vision.omnistereo.upper_sensor";
        if ls.mount_mm != us.mount_mm {
            return Err(Problem::new(
                field(),
                "the two cones must be coaxial (the same mount_mm)",
            ));
        }
        if lower.radius_mm != upper.radius_mm || lower.tip_distance_mm != upper.tip_distance_mm {
            return Err(Problem::new(
                field(),
                "the two cones must be alike (radius_mm, tip_distance_mm)",
            ));
        }
        let s = upper.lens_height_mm - lower.lens_height_mm;
        if s <= 0.0 {
            return Err(Problem::new(
                field(),
                format!(
                    "must stand above the lower sensor (lens_height_mm {} <= {})",
                    upper.lens_height_mm, lower.lens_height_mm
                ),
            ));
        }
        Ok(StereoRig {
            mirror_radius_mm: lower.radius_mm,
            tip_distance_mm: lower.tip_distance_mm,
            separation_mm: s,
            mount_mm: ls.mount_mm,
        })
    }

    /// The perception stages the built-in software runs for this scenario (none when its
    /// controller is unknown: validation says so).
    pub fn stages(&self) -> Vec<&'static StageEntry> {
        stages_of(&self.robot_config(Vec::new(), Vec::new())).unwrap_or_default()
    }

    /// Whether vision's camera is a pinhole.
    fn vision_is_pinhole(&self) -> bool {
        self.sensor(self.vision.sensor.as_deref())
            .is_ok_and(|s| s.optics.pinhole().is_some())
    }

    /// Whether the robot's software reads bearings from a pinhole camera's columns (which it
    /// calibrates first).
    pub fn needs_columns(&self) -> bool {
        let pinhole_ok = |s: &&StageEntry| s.camera == CameraNeed::MirrorOrPinhole;
        self.stages().iter().any(pinhole_ok) && self.vision_is_pinhole()
    }

    /// Whether the robot's software uses a mirror camera's image-to-floor map.
    pub fn needs_calibration(&self) -> bool {
        let pinhole = self.vision_is_pinhole();
        let mirror = |s: &&StageEntry| match s.camera {
            CameraNeed::Mirror | CameraNeed::MirrorFloor => true,
            CameraNeed::MirrorOrPinhole | CameraNeed::MirrorOrForward => !pinhole,
            CameraNeed::None | CameraNeed::Forward => false,
        };
        self.stages().iter().any(mirror)
    }

    /// The name of the experiment the scenario belongs to, if any.
    pub fn experiment_name(&self) -> Option<&str> {
        self.experiment.names().next()
    }

    /// Where the robot under test starts (validation makes sure it is given).
    pub fn start(&self) -> PoseSpec {
        self.robot.start.unwrap_or_default()
    }

    /// Number of control cycles the run lasts at most.
    pub fn max_cycles(&self) -> u64 {
        (self.run.duration_s / self.run.control_period_s).round() as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_sensor_names_the_ones_there_are() {
        let missing = |sensors: &[&str]| SensorLookupError::NoSuchSensor {
            name: "front".into(),
            sensors: sensors.iter().map(|s| s.to_string()).collect(),
        };
        assert_eq!(
            missing(&["omni", "down"]).to_string(),
            "the robot has no sensor \"front\" (it has: omni, down)"
        );
        assert_eq!(
            missing(&[]).to_string(),
            "the robot has no sensor \"front\" (it has none)"
        );
    }
}
