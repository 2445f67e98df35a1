//! Obstacle avoidance on detected free space (Sect. 3.2 of the corner paper).
//!
//! Both controllers see only what vision gives them ([`Surroundings`]: per direction the free
//! distance, obstacle points and where the known free space ends, in the robot frame), the
//! robot's current velocity and the goal relative to the robot.
//!
//! - [`GoalDirection`] (the method of the paper's ref. [4], without the velocity term): command
//!   full speed in the free direction closest to the goal direction, a direction being free when
//!   the straight strip the robot would sweep along it (its radius plus the margin to each side)
//!   holds no obstacle point up to the free distance.
//! - [`crate::VelocityAware`] (Sect. 3.2, and its extension to chosen speeds): see its module.

use crate::angle::angle_diff;
use crate::traffic::TrafficConfig;
use crate::{AccelLimitedDrive, ControlError, Vec2, require_positive};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// What vision reports around the robot, in the robot frame.
#[derive(Debug, Clone, Copy)]
pub struct Surroundings<'a> {
    /// Centre angle of each direction (rad, counter-clockwise from the robot's x axis).
    pub direction_rad: &'a [f64],
    /// Free distance of each direction, mm; equal to `range_mm` when free throughout.
    pub free_mm: &'a [f64],
    /// How far the free-space detection looks, mm.
    pub range_mm: f64,
    /// Points on obstacles, mm.
    pub obstacle_points: &'a [Vec2],
    /// Points on the boundary of the surely free space: obstacles placed as near as they may
    /// be, and where the unknown begins beyond the template, mm.
    pub clear_points: &'a [Vec2],
    /// Something stands in these directions inside the blind zone of the robot's body, at a
    /// distance nobody knows (vision sees only that the first ring is blocked, and nothing
    /// remembers it): points at the body's edge, mm. The robot may pass them at a slant but
    /// never head into them (see [`crate::VelocityAware`]).
    pub blind_points: &'a [Vec2],
    /// Points on obstacles that may move (another robot: what the robot's map does not
    /// explain), mm; used by the traffic rule ([`crate::traffic`]).
    pub moving_points: &'a [Vec2],
    /// Where the unknown begins beyond the template in the directions free throughout, mm;
    /// another robot may come from there (the traffic rule's horizon).
    pub horizon_points: &'a [Vec2],
}

/// How the velocity-aware controller sets the speed of its command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum SpeedChoice {
    /// The paper's Sect. 3.2: every candidate direction at the approach speed
    /// `min(v_max, sqrt(2 alpha d))`; space beyond the template counts as free.
    Fixed,
    /// Candidates are direction and speed; paths must stay inside the surely free space (what
    /// lies beyond the template is unknown, and a cell judged free may be partly occupied); the
    /// path that brakes one control period later must be clear too.
    #[default]
    Chosen,
}

/// Settings of the avoidance controllers (`[control.avoidance]` in scenarios).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AvoidanceConfig {
    /// Clearance kept between the robot's edge and obstacle points.
    pub margin_mm: f64,
    /// Goal direction: how far the strip swept along a direction must be free of obstacle
    /// points (or to just beyond the goal when the goal is nearer).
    pub free_distance_mm: f64,
    /// Velocity aware: candidate directions, evenly spaced (the goal direction is added).
    pub candidates: usize,
    /// Velocity aware: time step of the predicted paths.
    pub prediction_step_s: f64,
    /// Velocity aware: time added to each predicted path beyond reaching the commanded velocity
    /// and covering the stopping distance.
    pub extra_horizon_s: f64,
    /// Velocity aware, fixed speed: also require the path that brakes one control period from
    /// now to be clear (guarantees that stopping at the next cycle is safe, at the price of
    /// stop-and-go near walls; with chosen speeds it is always required).
    pub check_period_brake: bool,
    /// Velocity aware: how the speed of the command is set.
    pub speed: SpeedChoice,
    /// Velocity aware, chosen speeds: the speeds tried in each direction, `v k / speeds` for
    /// `k = speeds ... 1` of the approach speed `v`.
    pub speeds: usize,
    /// Velocity aware, chosen speeds: the rule for other robots that avoid too
    /// (`[control.avoidance.traffic]`, [`crate::traffic`]).
    pub traffic: TrafficConfig,
}

impl Default for AvoidanceConfig {
    fn default() -> Self {
        Self {
            margin_mm: 30.0,
            free_distance_mm: 1000.0,
            candidates: 64,
            prediction_step_s: 0.04,
            extra_horizon_s: 0.0,
            check_period_brake: false,
            speed: SpeedChoice::Chosen,
            speeds: 16,
            traffic: TrafficConfig::default(),
        }
    }
}

/// A controller's choice for one cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decision {
    /// Commanded velocity, robot frame, mm/s.
    pub v_mm_s: Vec2,
    /// The direction chosen, or `None` when stopping.
    pub heading_rad: Option<f64>,
}

/// Speed toward a goal `d` mm away: `min(v_max, sqrt(2 alpha d))`, so the robot can stop on it.
pub(crate) fn approach_speed(max_speed: f64, drive: &AccelLimitedDrive, d: f64) -> f64 {
    max_speed.min((2.0 * drive.accel_limit_mm_s2() * d).sqrt())
}

/// Heads at full speed for the free direction closest to the goal direction.
#[derive(Debug, Clone)]
pub struct GoalDirection {
    config: AvoidanceConfig,
    drive: AccelLimitedDrive,
    max_speed_mm_s: f64,
    radius_mm: f64,
}

pub(crate) fn check_config(c: &AvoidanceConfig) -> Result<(), ControlError> {
    if !(c.margin_mm.is_finite() && c.margin_mm >= 0.0) {
        return Err(ControlError::InvalidParameter {
            name: "margin_mm",
            value: c.margin_mm,
            rule: "must be finite and >= 0",
        });
    }
    require_positive("free_distance_mm", c.free_distance_mm)?;
    require_positive("prediction_step_s", c.prediction_step_s)?;
    if c.candidates < 4 {
        return Err(ControlError::InvalidParameter {
            name: "candidates",
            value: c.candidates as f64,
            rule: "must be >= 4",
        });
    }
    if c.speeds < 1 {
        return Err(ControlError::InvalidParameter {
            name: "speeds",
            value: c.speeds as f64,
            rule: "must be >= 1",
        });
    }
    if !(c.extra_horizon_s.is_finite() && c.extra_horizon_s >= 0.0) {
        return Err(ControlError::InvalidParameter {
            name: "extra_horizon_s",
            value: c.extra_horizon_s,
            rule: "must be finite and >= 0",
        });
    }
    let t = &c.traffic;
    for (name, value) in [
        ("traffic.gap_mm", t.gap_mm),
        ("traffic.keep_right_deg", t.keep_right_deg),
        ("traffic.moved_s", t.moved_s),
        ("traffic.yield_mm", t.yield_mm),
    ] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(ControlError::InvalidParameter {
                name,
                value,
                rule: "must be finite and >= 0",
            });
        }
    }
    if t.keep_right_deg > 90.0 {
        return Err(ControlError::InvalidParameter {
            name: "traffic.keep_right_deg",
            value: t.keep_right_deg,
            rule: "must be at most 90",
        });
    }
    if !(t.look_ahead_mm.is_finite() && t.look_ahead_mm > t.gap_mm) {
        return Err(ControlError::InvalidParameter {
            name: "traffic.look_ahead_mm",
            value: t.look_ahead_mm,
            rule: "must be finite and > traffic.gap_mm",
        });
    }
    if t.reciprocal() && c.speed != SpeedChoice::Chosen {
        return Err(ControlError::InvalidParameter {
            name: "traffic.rule",
            value: 1.0,
            rule: "the reciprocal rule needs speed = \"chosen\" (it bounds the chosen speeds)",
        });
    }
    Ok(())
}

impl GoalDirection {
    /// A controller for a robot of `radius_mm` with top speed `max_speed_mm_s`.
    pub fn new(
        config: AvoidanceConfig,
        drive: AccelLimitedDrive,
        max_speed_mm_s: f64,
        radius_mm: f64,
    ) -> Result<Self, ControlError> {
        check_config(&config)?;
        Ok(Self {
            config,
            drive,
            max_speed_mm_s: require_positive("max_speed_mm_s", max_speed_mm_s)?,
            radius_mm: require_positive("radius_mm", radius_mm)?,
        })
    }

    /// The command for a goal at `goal` (robot frame, relative to the robot).
    pub fn decide(&self, s: &Surroundings<'_>, goal: Vec2) -> Decision {
        let d_goal = goal.norm();
        let stop = Decision {
            v_mm_s: Vec2::zeros(),
            heading_rad: None,
        };
        if d_goal < 1e-6 || s.direction_rad.is_empty() {
            return stop;
        }
        let goal_rad = goal.y.atan2(goal.x);
        let n = s.direction_rad.len();
        let need = self
            .config
            .free_distance_mm
            .min(d_goal + self.radius_mm)
            .min(s.range_mm);
        let half_width = self.radius_mm + self.config.margin_mm;
        let free: Vec<bool> = (0..n)
            .map(|j| {
                let u = Vec2::new(s.direction_rad[j].cos(), s.direction_rad[j].sin());
                s.free_mm[j] >= need
                    && s.obstacle_points.iter().all(|o| {
                        let along = o.dot(&u);
                        let across = (o.x * u.y - o.y * u.x).abs();
                        along <= 0.0 || along >= need + self.radius_mm || across >= half_width
                    })
            })
            .collect();
        // The direction cell holding the goal direction, then the nearest free one.
        let best = (0..n).filter(|&j| free[j]).min_by(|&a, &b| {
            angle_diff(s.direction_rad[a], goal_rad)
                .total_cmp(&angle_diff(s.direction_rad[b], goal_rad))
        });
        let Some(j) = best else {
            return stop;
        };
        let step = TAU / n as f64;
        let heading = if angle_diff(s.direction_rad[j], goal_rad) <= 0.5 * step {
            goal_rad
        } else {
            s.direction_rad[j]
        };
        let speed = approach_speed(self.max_speed_mm_s, &self.drive, d_goal);
        Decision {
            v_mm_s: Vec2::new(heading.cos(), heading.sin()) * speed,
            heading_rad: Some(heading),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{drive, rush_at_wall, surroundings, wall_ahead};

    #[test]
    fn without_the_velocity_term_the_robot_runs_into_the_wall() {
        // Sect. 3.2's point: heading for a free direction without predicting the path, the
        // acceleration limit carries the robot into the wall it is rushing at (the path here
        // ignores the wall, so the centre passes the 510 mm where its edge would touch).
        let gd = GoalDirection::new(AvoidanceConfig::default(), drive(), 400.0, 90.0).unwrap();
        let (max_x, _) = rush_at_wall(400.0, |s, goal, _| gd.decide(s, goal).v_mm_s);
        assert!(max_x > 600.0 - 90.0, "max x {max_x}");
    }

    #[test]
    fn goal_direction_goes_straight_when_free_and_around_when_not() {
        let c = GoalDirection::new(AvoidanceConfig::default(), drive(), 400.0, 90.0).unwrap();
        let w = wall_ahead(10_000.0);
        let d = c.decide(&surroundings(&w), Vec2::new(3000.0, 100.0));
        assert!((d.heading_rad.unwrap() - 100f64.atan2(3000.0)).abs() < 1e-12);
        assert!((d.v_mm_s.norm() - 400.0).abs() < 1e-9);
        let w = wall_ahead(500.0);
        let d = c.decide(&surroundings(&w), Vec2::new(3000.0, 100.0));
        let h = d.heading_rad.unwrap();
        // The wall at 500 mm: at 56.25 degrees it is 900 mm away, at 67.5 degrees 1306 mm, and
        // the strip swept along 67.5 degrees keeps 176 mm from the nearest wall point.
        assert!(
            (h.to_degrees().abs() - 67.5).abs() < 1e-9,
            "{}",
            h.to_degrees()
        );
    }

    #[test]
    fn bad_settings_are_refused() {
        let bad = AvoidanceConfig {
            margin_mm: -1.0,
            ..AvoidanceConfig::default()
        };
        assert!(GoalDirection::new(bad, drive(), 400.0, 90.0).is_err());
    }
}
