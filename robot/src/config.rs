//! The robot's software configuration: the `[vision]`, `[control]` and `[goal]` tables of a
//! scenario, plus what the robot knows of its own body, cameras and start.

use nalgebra::{Isometry2, Point2};
use omniloop_control::AvoidanceConfig;
use omniloop_vision::forward::{FlowConfig, ForwardCamera, GroundConfig, OdometryConfig};
use omniloop_vision::luminance_heading::LuminanceConfig;
use omniloop_vision::omnistereo::OmnistereoConfig;
use omniloop_vision::resection::{ColumnCalibration, ResectionConfig, StripePattern};
use omniloop_vision::{FreeSpaceConfig, LocalizationConfig, RadialCalibration};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Which controller chooses the robot's command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ControllerKind {
    /// Stand still (the default: nothing drives unless the scenario says so).
    #[default]
    Idle,
    /// Not the robot's software: the simulator drives the robot straight to its targets on the
    /// true pose (a reference that needs no vision). The robot's own controller stays idle; its
    /// perception and estimator still run and are recorded.
    GoToGoalTruth,
    /// Free direction closest to the goal direction, from the image (ref. [4] of the corner
    /// paper).
    GoalDirection,
    /// Velocity-aware avoidance of Sect. 3.2 of the corner paper, from the image.
    VelocityAware,
    /// Random wandering on the map (E4, Spacek and Burbridge, Sect. 2.1): forward until the
    /// map says a pillar or a wall is near, then a random turn left or right.
    Wander,
    /// Stand still while the cameras search, and drive to the observation points perception
    /// asks for (E5's "change the observation point by making a move", Fig. 4).
    Observe,
    /// A forward camera's ground segmentation (Ahmed et al., Sect. 2.1.1): straight while the
    /// ground ahead reaches far enough, else turn on the spot to the clearer side.
    Segmentation,
    /// A forward camera's Horn-Schunck flow balance (Ahmed et al., Sect. 2.1.2): straight
    /// until the flow is strong, then turn away from the side with more.
    OpticalFlow,
    /// Drive a list of moves (straight runs and turns on the spot) on dead reckoning
    /// (`[control.script]`).
    Script,
}

impl ControllerKind {
    /// Whether the controller needs the free-space detection.
    pub fn uses_freespace(self) -> bool {
        matches!(self, Self::GoalDirection | Self::VelocityAware)
    }

    /// The name as written in scenario files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Idle => "idle",
            Self::GoToGoalTruth => "go_to_goal_truth",
            Self::GoalDirection => "goal_direction",
            Self::VelocityAware => "velocity_aware",
            Self::Wander => "wander",
            Self::Observe => "observe",
            Self::Segmentation => "segmentation",
            Self::OpticalFlow => "optical_flow",
            Self::Script => "script",
        }
    }
}

/// Where the robot's pose estimate comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum PoseSource {
    /// Dead reckoning from wheel odometry alone, from the start pose the robot is given.
    #[default]
    Odometry,
    /// Odometry corrected by floor-region self-localization (Sect. 4 of the corner paper) in
    /// every cycle that gives a fix.
    Localization,
    /// Odometry whose heading is corrected at the goal's checkpoints from the luminance circle
    /// (Kim, Kim and Kwon).
    Checkpoints,
    /// Odometry corrected by trilateration from the conical omnistereo ranges to the map's
    /// landmarks (Spacek and Burbridge), every cycle that gives a fix.
    Omnistereo,
    /// Resection from three striped marks (Ishikawa, Kikuchi and Kato): a panning search for
    /// the marks while the pose is unknown, one fix when all three are found.
    Resection,
}

/// How the robot chooses its velocity (`[control]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControlSpec {
    /// The controller.
    pub kind: ControllerKind,
    /// Settings of the avoidance controllers.
    pub avoidance: AvoidanceConfig,
    /// Where the pose estimate comes from.
    pub pose_source: PoseSource,
    /// With `pose_source = "localization"` or `"omnistereo"`: how far each fix pulls the
    /// dead-reckoned pose toward itself (0: odometry only, 1: jump to the measurement).
    pub localization_gain: f64,
    /// Settings of the wandering controller (`kind = "wander"`).
    pub wander: WanderConfig,
    /// The search for the marks (`pose_source = "resection"`).
    pub resection: SearchConfig,
    /// Speeds of the forward camera's avoidance (`kind = "segmentation"`, `"optical_flow"`).
    pub forward: ForwardDriveConfig,
    /// The moves of `kind = "script"`.
    pub script: ScriptConfig,
}

/// How the forward camera's avoidance drives (`[control.forward]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ForwardDriveConfig {
    /// Speed straight ahead, mm/s.
    pub speed_mm_s: f64,
    /// Rate of the turns on the spot, deg/s.
    pub turn_rate_deg_s: f64,
    /// Segmentation: once turning, go on until this many ground pixels more than needed lie
    /// ahead (so the robot does not stop turning at the first clear column).
    pub hysteresis_px: u32,
    /// Optical flow: how long one turn away from the stronger flow lasts, s.
    pub flow_turn_s: f64,
    /// Optical flow: frames after a turn whose flow is not read (it is the turn's own).
    pub flow_settle_frames: u32,
}

impl Default for ForwardDriveConfig {
    fn default() -> Self {
        Self {
            speed_mm_s: 150.0,
            turn_rate_deg_s: 60.0,
            hysteresis_px: 6,
            flow_turn_s: 0.75,
            flow_settle_frames: 2,
        }
    }
}

/// One move of a script.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Move {
    /// Straight ahead by this much (negative: back), mm: `{ forward_mm = 914.4 }`.
    ForwardMm(f64),
    /// Turn on the spot by this much (counter-clockwise positive), degrees:
    /// `{ turn_deg = -90.0 }`.
    TurnDeg(f64),
}

/// A scripted drive (`[control.script]`), judged on dead reckoning.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ScriptConfig {
    /// The moves, in order.
    pub moves: Vec<Move>,
    /// Speed of the straight runs, mm/s.
    pub speed_mm_s: f64,
    /// Rate of the turns, deg/s.
    pub turn_rate_deg_s: f64,
    /// Standstill after each move, s.
    pub pause_s: f64,
}

impl Default for ScriptConfig {
    fn default() -> Self {
        Self {
            moves: Vec::new(),
            speed_mm_s: 150.0,
            turn_rate_deg_s: 45.0,
            pause_s: 0.5,
        }
    }
}

/// How the robot searches for the three marks (`[control.resection]`, Fig. 4 of the resection
/// paper).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SearchConfig {
    /// Rate of the pan from right to left, deg/s (the pan unit clips it to its limit).
    pub pan_rate_deg_s: f64,
    /// Sightings count toward a mark's bearing when its centre is within this fraction of the
    /// half-width of the image from the optical axis (ours: the calibration is best there).
    pub central_fraction: f64,
    /// Length of the move to another observation point when a mark was not found, mm.
    pub move_mm: f64,
    /// Moves before the robot gives up.
    pub max_moves: u32,
}

impl Default for SearchConfig {
    fn default() -> Self {
        Self {
            pan_rate_deg_s: 60.0,
            central_fraction: 0.5,
            move_mm: 300.0,
            max_moves: 3,
        }
    }
}

/// How the wandering controller drives (`[control.wander]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WanderConfig {
    /// Gap the robot keeps between its body and the map's obstacles, mm (room for the error
    /// of its estimate).
    pub clearance_mm: f64,
    /// Rate of the turns, deg/s.
    pub turn_rate_deg_s: f64,
    /// Once the way ahead is clear the robot turns on by a random angle up to this, degrees
    /// (ours: without it a robot that stops turning at the first clear heading skims along
    /// walls).
    pub max_extra_turn_deg: f64,
}

impl Default for WanderConfig {
    fn default() -> Self {
        Self {
            clearance_mm: 200.0,
            turn_rate_deg_s: 90.0,
            max_extra_turn_deg: 60.0,
        }
    }
}

impl Default for ControlSpec {
    fn default() -> Self {
        Self {
            kind: ControllerKind::default(),
            avoidance: AvoidanceConfig::default(),
            pose_source: PoseSource::Odometry,
            localization_gain: 0.3,
            wander: WanderConfig::default(),
            resection: SearchConfig::default(),
            forward: ForwardDriveConfig::default(),
            script: ScriptConfig::default(),
        }
    }
}

/// Image processing settings (`[vision]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct VisionSpec {
    /// The camera whose images vision uses (default: the robot's first).
    pub sensor: Option<String>,
    /// A calibration table written by `omniloop calibrate` (relative to the scenario file);
    /// default: traced from the sensor's optics at start.
    pub calibration_file: Option<PathBuf>,
    /// Free-space detection (Sect. 3.1 of the corner paper).
    pub freespace: FreeSpaceConfig,
    /// Self-localization from the floor region (Sect. 4 of the corner paper).
    pub localization: LocalizationConfig,
    /// Heading from a luminance circle (Kim, Kim and Kwon, Sect. 3).
    pub luminance_heading: LuminanceConfig,
    /// Conical omnistereo: range, trilateration, visual compass and interframe motion
    /// (Spacek and Burbridge).
    pub omnistereo: OmnistereoConfig,
    /// Striped-mark recognition for resection (Ishikawa, Kikuchi and Kato).
    pub resection: ResectionConfig,
    /// A forward camera's avoidance and visual odometry (Ahmed, Saatchi and Caparrelli).
    pub forward: ForwardVisionConfig,
}

/// A forward camera's image processing (`[vision.forward]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct ForwardVisionConfig {
    /// Run the visual odometry (scan-line rotation, LK and NCC translation) every frame.
    pub visual_odometry: bool,
    /// Ground segmentation.
    pub ground: GroundConfig,
    /// Horn-Schunck flow.
    pub flow: FlowConfig,
    /// Visual odometry.
    pub odometry: OdometryConfig,
}

/// The goal point, reached through optional waypoints (`[goal]`), in the world (field) frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GoalSpec {
    /// Points to pass (within the tolerance) in order before the goal point.
    #[serde(default)]
    pub waypoints_mm: Vec<[f64; 2]>,
    /// x of the goal point.
    pub x_mm: f64,
    /// y of the goal point.
    pub y_mm: f64,
    /// A target is reached when the robot centre is this close (judged on the truth when a
    /// run is scored).
    #[serde(default = "default_goal_tolerance")]
    pub tolerance_mm: f64,
    /// The robot moves on from a waypoint when its own estimate is within `tolerance_mm -
    /// estimate_margin_mm` of it: room for the error of that estimate, so that the robot truly
    /// passes within the tolerance.
    #[serde(default)]
    pub estimate_margin_mm: f64,
    /// Checkpoints (field frame): the robot stores the luminance circle at each the first time
    /// its estimate is within `checkpoint_store_mm` of it, and reads its heading error against
    /// it whenever its estimate is within `checkpoint_radius_mm` later.
    #[serde(default)]
    pub checkpoints_mm: Vec<[f64; 2]>,
    /// See `checkpoints_mm`.
    #[serde(default = "default_checkpoint_store")]
    pub checkpoint_store_mm: f64,
    /// See `checkpoints_mm`.
    #[serde(default = "default_checkpoint_radius")]
    pub checkpoint_radius_mm: f64,
}

fn default_checkpoint_store() -> f64 {
    30.0
}

fn default_checkpoint_radius() -> f64 {
    250.0
}

fn default_goal_tolerance() -> f64 {
    100.0
}

impl GoalSpec {
    /// A goal at `point_mm` reached within `tolerance_mm`, with no waypoints, margin or
    /// checkpoints.
    pub fn to(point_mm: [f64; 2], tolerance_mm: f64) -> Self {
        Self {
            waypoints_mm: Vec::new(),
            x_mm: point_mm[0],
            y_mm: point_mm[1],
            tolerance_mm,
            estimate_margin_mm: 0.0,
            checkpoints_mm: Vec::new(),
            checkpoint_store_mm: default_checkpoint_store(),
            checkpoint_radius_mm: default_checkpoint_radius(),
        }
    }

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

/// What the robot knows of its own body (design constants, not measurements).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodySpec {
    /// Disc radius, mm.
    pub radius_mm: f64,
    /// Top speed the controllers command, mm/s.
    pub max_speed_mm_s: f64,
    /// Translational acceleration limit alpha of eq. (8), mm/s^2.
    pub accel_limit_mm_s2: f64,
    /// Rotational acceleration limit, rad/s^2.
    pub angular_accel_limit_rad_s2: f64,
}

/// A landmark of the robot's map: an upright cylinder of one colour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapLandmark {
    /// Centre, world frame, mm.
    pub centre_mm: Point2<f64>,
    /// Radius, mm.
    pub radius_mm: f64,
    /// Its colour.
    pub rgb: [u8; 3],
}

/// A straight obstacle of the robot's map (a wall, a board, a side of a box).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapSegment {
    /// One end of its centre line, world frame, mm.
    pub from_mm: Point2<f64>,
    /// The other end.
    pub to_mm: Point2<f64>,
    /// Half its thickness, mm.
    pub half_thickness_mm: f64,
}

/// A striped mark of the robot's map (a named board).
#[derive(Debug, Clone, PartialEq)]
pub struct MapMark {
    /// Where its centre stands, world frame, mm.
    pub centre_mm: Point2<f64>,
    /// Its stripes, named.
    pub pattern: StripePattern,
}

/// What the robot is told of its surroundings (E4's "map of the arena programmed into the
/// robot"): where the landmarks stand and where the obstacles are. Not its own pose.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WorldMap {
    /// Landmarks, with the colours vision names them by.
    pub landmarks: Vec<MapLandmark>,
    /// Straight obstacles.
    pub segments: Vec<MapSegment>,
    /// Striped marks.
    pub marks: Vec<MapMark>,
}

/// The design of a conical omnistereo rig (two coaxial 90-degree cones), as built.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StereoRig {
    /// Mirror radius R, mm.
    pub mirror_radius_mm: f64,
    /// Lens to cone tip d, mm.
    pub tip_distance_mm: f64,
    /// Distance between the mirrors s, mm.
    pub separation_mm: f64,
    /// Where the mirrors' axis stands in the robot frame, mm.
    pub mount_mm: [f64; 2],
}

/// Everything the robot's software is built from.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotConfig {
    /// The pose the robot is told it starts at (world frame): the origin of its dead reckoning.
    pub start: Isometry2<f64>,
    /// Its body.
    pub body: BodySpec,
    /// Period of the control cycle, s.
    pub control_period_s: f64,
    /// Names of its cameras, in order (the first is vision's default).
    pub cameras: Vec<String>,
    /// Image-to-floor calibrations of the mirror cameras vision uses (each names its sensor).
    pub calibrations: Vec<RadialCalibration>,
    /// Column-to-bearing calibrations of the pinhole cameras vision uses.
    pub columns: Vec<ColumnCalibration>,
    /// Vision's camera when it is a forward pinhole (its intrinsics, height and tilt).
    pub forward_camera: Option<ForwardCamera>,
    /// Image processing.
    pub vision: VisionSpec,
    /// Controller and estimator.
    pub control: ControlSpec,
    /// Where to go, if anywhere.
    pub goal: Option<GoalSpec>,
    /// Its map, when it is given one.
    pub map: WorldMap,
    /// Its omnistereo rig's design, when it has one.
    pub stereo: Option<StereoRig>,
    /// Seed of the software's own random choices (the wandering's turns).
    pub seed: u64,
}

impl RobotConfig {
    /// The camera vision uses: `vision.sensor`, or the first camera.
    pub fn vision_camera(&self) -> Option<&str> {
        match &self.vision.sensor {
            Some(name) => self.cameras.iter().find(|c| *c == name).map(String::as_str),
            None => self.cameras.first().map(String::as_str),
        }
    }

    /// The calibration of camera `sensor`.
    pub fn calibration(&self, sensor: &str) -> Option<&RadialCalibration> {
        self.calibrations.iter().find(|c| c.sensor == sensor)
    }

    /// Whether the robot runs the free-space stage.
    pub fn detects_freespace(&self) -> bool {
        self.control.kind.uses_freespace()
    }

    /// Whether the robot runs the omnistereo stage.
    pub fn uses_omnistereo(&self) -> bool {
        self.control.pose_source == PoseSource::Omnistereo
    }

    /// Whether the robot's forward camera runs: its avoidance or its visual odometry.
    pub fn uses_forward_camera(&self) -> bool {
        matches!(
            self.control.kind,
            ControllerKind::Segmentation | ControllerKind::OpticalFlow
        ) || self.vision.forward.visual_odometry
    }

    /// Whether the robot runs the resection stage.
    pub fn resects(&self) -> bool {
        self.control.pose_source == PoseSource::Resection
    }

    /// The column calibration of camera `sensor`.
    pub fn columns(&self, sensor: &str) -> Option<&ColumnCalibration> {
        self.columns.iter().find(|c| c.sensor == sensor)
    }

    /// Whether the robot runs floor-region self-localization.
    pub fn localizes(&self) -> bool {
        self.control.pose_source == PoseSource::Localization
    }

    /// The goal's checkpoints, where the robot reads its heading from the luminance circle.
    pub fn checkpoints(&self) -> &[[f64; 2]] {
        self.goal
            .as_ref()
            .map_or(&[], |g| g.checkpoints_mm.as_slice())
    }
}
