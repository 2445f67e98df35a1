//! The robot's software configuration: the `[vision]`, `[control]` and `[goal]` tables of a
//! scenario, plus what the robot knows of its own body, cameras and start.

use crate::tables::Tables;
use nalgebra::{Isometry2, Point2};
use omniloop_problem::Problem;
use omniloop_vision::RadialCalibration;
use omniloop_vision::forward::ForwardCamera;
use omniloop_vision::resection::{ColumnCalibration, StripePattern};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// How the robot chooses its velocity and where its pose estimate comes from (`[control]`).
///
/// `kind` names a registered controller ([`crate::controllers::CONTROLLERS`]); `pose_source`
/// is `"odometry"` or names a perception stage that gives the estimator fixes
/// ([`crate::perception::STAGES`]). The other tables of the section (`[control.avoidance]`,
/// `[control.wander]`, ...) belong to the registered controllers and stages, which parse and
/// check them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ControlSpec {
    /// The controller, by its registered name.
    pub kind: String,
    /// Where the pose estimate comes from: `"odometry"` (dead reckoning alone), or the pose
    /// source of a registered stage (`"localization"`, `"checkpoints"`, `"omnistereo"`,
    /// `"resection"`).
    pub pose_source: String,
    /// With a pose source other than odometry: how far each fix pulls the dead-reckoned pose
    /// toward itself (0: odometry only, 1: jump to the measurement).
    pub localization_gain: f64,
    /// The registered parts' own tables.
    #[serde(flatten)]
    pub tables: Tables,
}

/// The pose source of dead reckoning alone.
pub const ODOMETRY: &str = "odometry";

impl Default for ControlSpec {
    fn default() -> Self {
        Self {
            kind: "idle".to_string(),
            pose_source: ODOMETRY.to_string(),
            localization_gain: 0.3,
            tables: Tables::default(),
        }
    }
}

impl ControlSpec {
    /// Table `name` of `[control]` as its owner's settings.
    pub fn table<T: DeserializeOwned + Default>(&self, name: &str) -> Result<T, Problem> {
        self.tables.parse("control", name)
    }
}

/// Image processing settings (`[vision]`).
///
/// `sensor` and `calibration_file` are vision's camera; the other tables (`[vision.freespace]`,
/// `[vision.localization]`, ...) belong to the registered perception stages
/// ([`crate::perception::STAGES`]), which parse and check them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default)]
pub struct VisionSpec {
    /// The camera whose images vision uses (default: the robot's first).
    pub sensor: Option<String>,
    /// A calibration table written by `omniloop calibrate` (relative to the scenario file);
    /// default: traced from the sensor's optics at start.
    pub calibration_file: Option<PathBuf>,
    /// The registered stages' own tables.
    #[serde(flatten)]
    pub tables: Tables,
}

impl VisionSpec {
    /// Table `name` of `[vision]` as its owner's settings (their defaults when not written).
    pub fn table<T: DeserializeOwned + Default>(&self, name: &str) -> Result<T, Problem> {
        self.tables.parse("vision", name)
    }
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
    /// Its kicker and dribbler, when it has them.
    pub kicker: Option<KickerBody>,
}

/// What the robot knows of its kicker and dribbler.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KickerBody {
    /// Distance of the flat front (where the dribbler holds the ball) from the centre, mm.
    pub front_mm: f64,
    /// The fastest kick, mm/s.
    pub max_kick_mm_s: f64,
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
    /// Straight obstacles that stay put: walls and boards standing in the world.
    pub segments: Vec<MapSegment>,
    /// The sides of the boxes (cubes) where the map says they stand: things that may be moved,
    /// so a planner does not trust them.
    pub boxes: Vec<MapSegment>,
    /// The walls that bound the floor: the field's walls and goals, corridor walls.
    pub bounds: Vec<MapSegment>,
    /// Striped marks.
    pub marks: Vec<MapMark>,
    /// The Small-Size field's figures, when the floor is one.
    pub field: Option<FieldMap>,
}

/// The figures of a Small-Size field the robot is told (the league publishes them): centred on
/// the world origin, its long axis the world x axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldMap {
    /// Half the length of the playing area, to the goal lines, mm.
    pub half_length_mm: f64,
    /// Half its width, mm.
    pub half_width_mm: f64,
    /// Width of each goal's mouth, mm.
    pub goal_width_mm: f64,
    /// Depth of each defense area from its goal line, mm (0: none).
    pub defense_depth_mm: f64,
    /// Width of each defense area, mm.
    pub defense_width_mm: f64,
    /// Floor beyond the outer lines to the field walls, mm (0: the walls stand on the lines).
    pub run_off_mm: f64,
}

impl FieldMap {
    /// The centre of the goal at `+x` (`side` 1) or `-x` (`side` -1).
    pub fn goal_centre(&self, side: f64) -> Point2<f64> {
        Point2::new(side.signum() * self.half_length_mm, 0.0)
    }

    /// Whether `p` lies in either defense area (between its front line and the goal line)
    /// grown by `margin_mm`.
    pub fn in_defense_area(&self, p: Point2<f64>, margin_mm: f64) -> bool {
        self.defense_depth_mm > 0.0
            && p.x.abs() >= self.half_length_mm - self.defense_depth_mm - margin_mm
            && p.x.abs() <= self.half_length_mm + margin_mm
            && p.y.abs() <= 0.5 * self.defense_width_mm + margin_mm
    }
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
    /// Its name (`robot` for the one robot of a scenario; a team's robots each their own).
    pub name: String,
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
    /// A robot of the tests: at the origin, a 90 mm body at 400 mm/s and 300 mm/s^2, a 40 ms
    /// cycle, no camera, goal or map, seed 1 (each test changes what it needs).
    #[cfg(test)]
    pub(crate) fn for_tests() -> Self {
        Self {
            name: "robot".to_string(),
            start: Isometry2::identity(),
            body: BodySpec {
                radius_mm: 90.0,
                max_speed_mm_s: 400.0,
                accel_limit_mm_s2: 300.0,
                angular_accel_limit_rad_s2: 10.0,
                kicker: None,
            },
            control_period_s: 0.04,
            cameras: Vec::new(),
            calibrations: Vec::new(),
            columns: Vec::new(),
            forward_camera: None,
            vision: VisionSpec::default(),
            control: ControlSpec::default(),
            goal: None,
            map: WorldMap::default(),
            stereo: None,
            seed: 1,
        }
    }

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

    /// The column calibration of camera `sensor`.
    pub fn columns(&self, sensor: &str) -> Option<&ColumnCalibration> {
        self.columns.iter().find(|c| c.sensor == sensor)
    }

    /// The goal's checkpoints, where the robot reads its heading from the luminance circle.
    pub fn checkpoints(&self) -> &[[f64; 2]] {
        self.goal
            .as_ref()
            .map_or(&[], |g| g.checkpoints_mm.as_slice())
    }
}
