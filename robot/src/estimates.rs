//! What the robot believes: the typed record it returns each cycle, written beside the truth.

use crate::percept::{Percept, Percepts};
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_vision::LocalizationQuality;

/// A measurement a perception stage gives the estimator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Measurement {
    /// A full pose in the world frame.
    Pose {
        /// The pose the stage chose.
        pose: Isometry2<f64>,
        /// A second solution the image cannot rule out by geometry alone (the half-turn twin of
        /// floor-region localization), if any.
        alternative: Option<Isometry2<f64>>,
        /// Whether the image itself told the solutions apart (e.g. by the goals' colours).
        unambiguous: bool,
    },
    /// The heading alone, world frame, rad.
    Heading {
        /// Heading, rad.
        heading_rad: f64,
    },
    /// The position alone, world frame.
    Position {
        /// Position, mm.
        position: Point2<f64>,
    },
    /// How the robot moved since the previous cycle, in the body frame of that cycle.
    Motion {
        /// The motion.
        delta: Isometry2<f64>,
    },
}

/// What the estimator did with a fix.
#[derive(Debug, Clone, PartialEq)]
pub enum FixOutcome {
    /// It set the estimate (the first fix after the pose was unknown or given only as a start).
    Anchored,
    /// It pulled the estimate toward itself by the gain.
    Used,
    /// It was not used, and why.
    Rejected(String),
    /// The estimator does not take fixes (`control.pose_source = "odometry"`).
    Ignored,
}

/// A fix of one cycle and what became of it.
#[derive(Debug, Clone, PartialEq)]
pub struct Fix {
    /// The stage that gave it.
    pub source: &'static str,
    /// The measurement.
    pub measurement: Measurement,
    /// What the estimator did with it.
    pub outcome: FixOutcome,
    /// How good the stage judged it (floor-region localization: residual, points per line,
    /// standard deviations, whether the view was cut, global or tracking).
    pub quality: Option<LocalizationQuality>,
}

/// A stage that looked and found nothing, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct NotFound {
    /// The stage.
    pub source: &'static str,
    /// Why (e.g. "floor region too small (812 pixels, need 2000)").
    pub reason: String,
}

/// What the robot believes after one cycle.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Estimates {
    /// Time of the cycle, s.
    pub t_s: f64,
    /// The pose estimate the controller used (world frame), `None` while the pose is unknown.
    pub pose: Option<Isometry2<f64>>,
    /// The measured body velocity, mm/s.
    pub velocity_body_mm_s: Vector2<f64>,
    /// The fixes of this cycle and what the estimator did with each.
    pub fixes: Vec<Fix>,
    /// Stages that gave no fix this cycle, and why ("not localized: ...").
    pub not_found: Vec<NotFound>,
    /// Index of the target (waypoints, then the goal) the robot is heading for, with a goal.
    pub target: Option<usize>,
    /// What the perception stages found this cycle, by type (free space, the landmarks
    /// ranged, a ground reading, ...): [`Estimates::percept`].
    pub percepts: Percepts,
    /// The move a scripted drive is at (the number of moves once done).
    pub step: Option<usize>,
    /// What the planner did, when the controller plans.
    pub navigation: Option<crate::NavigationReport>,
}

impl Estimates {
    /// An empty record of the cycle at `t_s`, for the software to fill in.
    pub fn at(t_s: f64) -> Self {
        Self {
            t_s,
            ..Self::default()
        }
    }

    /// What the stages found of type `T` this cycle (e.g. `FreeSpace`), if any.
    pub fn percept<T: Percept>(&self) -> Option<&T> {
        self.percepts.get::<T>()
    }

    /// The first full-pose fix of the cycle from stage `source`, with what became of it.
    pub fn pose_fix(&self, source: &str) -> Option<&Fix> {
        self.fixes
            .iter()
            .find(|f| f.source == source && matches!(f.measurement, Measurement::Pose { .. }))
    }

    /// Why stage `source` found nothing this cycle, if it did not.
    pub fn not_found(&self, source: &str) -> Option<&str> {
        self.not_found
            .iter()
            .find(|n| n.source == source)
            .map(|n| n.reason.as_str())
    }
}
