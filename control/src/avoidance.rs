//! Obstacle avoidance on detected free space (Sect. 3.2 of the corner paper).
//!
//! Both controllers see only what vision gives them ([`Surroundings`]: per direction the free
//! distance, plus obstacle points, in the robot frame), the robot's current velocity and the
//! goal relative to the robot.
//!
//! - [`GoalDirection`] (the method of the paper's ref. [4], without the velocity term): command
//!   full speed in the free direction closest to the goal direction, a direction being free when
//!   the straight strip the robot would sweep along it (its radius plus the margin to each side)
//!   holds no obstacle point up to the free distance.
//! - [`VelocityAware`] (Sect. 3.2): for every candidate direction, predict with eq. (8) the path
//!   from the current velocity toward that direction at the commanded speed until the drive gets
//!   there and then braking to rest (and, since the next decision comes one control period
//!   later, also the path that brakes after that period); reject candidates whose paths come
//!   within the robot radius plus a margin of an obstacle point; head for the
//!   admissible direction closest to the goal direction, or stop at the acceleration limit when
//!   there is none and keep looking.

use crate::angle::angle_diff;
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
    /// Velocity aware: also require the path that brakes one control period from now to be
    /// clear (guarantees that stopping at the next cycle is safe, at the price of stop-and-go
    /// near walls).
    pub check_period_brake: bool,
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
fn approach_speed(max_speed: f64, drive: &AccelLimitedDrive, d: f64) -> f64 {
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

fn check_config(c: &AvoidanceConfig) -> Result<(), ControlError> {
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
    if !(c.extra_horizon_s.is_finite() && c.extra_horizon_s >= 0.0) {
        return Err(ControlError::InvalidParameter {
            name: "extra_horizon_s",
            value: c.extra_horizon_s,
            rule: "must be finite and >= 0",
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

/// Chooses among directions whose eq. (8) paths stay clear of the obstacles.
#[derive(Debug, Clone)]
pub struct VelocityAware {
    config: AvoidanceConfig,
    drive: AccelLimitedDrive,
    max_speed_mm_s: f64,
    radius_mm: f64,
    period_s: f64,
}

impl VelocityAware {
    /// A controller for a robot of `radius_mm` with top speed `max_speed_mm_s`, deciding every
    /// `period_s`.
    pub fn new(
        config: AvoidanceConfig,
        drive: AccelLimitedDrive,
        max_speed_mm_s: f64,
        radius_mm: f64,
        period_s: f64,
    ) -> Result<Self, ControlError> {
        check_config(&config)?;
        Ok(Self {
            config,
            drive,
            max_speed_mm_s: require_positive("max_speed_mm_s", max_speed_mm_s)?,
            radius_mm: require_positive("radius_mm", radius_mm)?,
            period_s: require_positive("period_s", period_s)?,
        })
    }

    /// Whether the paths of a command `v_b` stay clear of `obstacles` (robot frame, robot at
    /// the origin moving at `v_now`). Two paths are predicted with eq. (8): toward `v_b` until
    /// the drive gets there, then braking to rest; and toward `v_b` for one control period
    /// (the time until the next decision), then braking to rest — the path the robot takes if
    /// the next cycle finds nothing admissible and stops. Each is sampled every
    /// `prediction_step_s`, and every obstacle must keep the robot radius plus the margin from
    /// each segment between samples.
    pub fn path_is_clear(&self, v_now: Vec2, v_b: Vec2, obstacles: &[Vec2]) -> bool {
        let t_a = self.drive.settle_time_s(v_now, v_b);
        self.phases_clear(v_now, v_b, t_a, obstacles)
            && (!self.config.check_period_brake
                || self.phases_clear(v_now, v_b, self.period_s, obstacles))
    }

    /// Toward `v_b` for `t1`, then toward rest until stopped (plus `extra_horizon_s`).
    fn phases_clear(&self, v_now: Vec2, v_b: Vec2, t1: f64, obstacles: &[Vec2]) -> bool {
        let alpha = self.drive.accel_limit_mm_s2();
        let p1 = self.drive.displacement(v_now, v_b, t1);
        let v1 = self.drive.velocity_at(v_now, v_b, t1);
        let t2 = v1.norm() / alpha + self.config.extra_horizon_s;
        let horizon = t1 + t2;
        let dt = self.config.prediction_step_s;
        let steps = (horizon / dt).ceil().max(1.0) as usize;
        let clearance = self.radius_mm + self.config.margin_mm;
        let c2 = clearance * clearance;
        let at = |t: f64| {
            if t <= t1 {
                self.drive.displacement(v_now, v_b, t)
            } else {
                p1 + self.drive.displacement(v1, Vec2::zeros(), t - t1)
            }
        };
        let mut a = Vec2::zeros();
        for k in 1..=steps {
            let b = at((k as f64 * dt).min(horizon));
            let ab = b - a;
            let len2 = ab.norm_squared();
            for o in obstacles {
                let u = if len2 > 0.0 {
                    ((o - a).dot(&ab) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                if (o - (a + ab * u)).norm_squared() < c2 {
                    return false;
                }
            }
            a = b;
        }
        true
    }

    /// The command for a robot moving at `v_now` (robot frame) with the goal at `goal`.
    pub fn decide(&self, s: &Surroundings<'_>, goal: Vec2, v_now: Vec2) -> Decision {
        let d_goal = goal.norm();
        if d_goal < 1e-6 {
            return Decision {
                v_mm_s: Vec2::zeros(),
                heading_rad: None,
            };
        }
        let goal_rad = goal.y.atan2(goal.x);
        let speed = approach_speed(self.max_speed_mm_s, &self.drive, d_goal);
        // Only obstacles the robot could reach within the longest horizon matter.
        let alpha = self.drive.accel_limit_mm_s2();
        let top = v_now.norm().max(speed);
        let longest = (v_now.norm() + speed) / alpha
            + self.period_s
            + top / alpha
            + self.config.extra_horizon_s;
        let reach = top * longest + self.radius_mm + self.config.margin_mm;
        let near: Vec<Vec2> = s
            .obstacle_points
            .iter()
            .copied()
            .filter(|o| o.norm() <= reach)
            .collect();
        let k = self.config.candidates;
        let mut headings: Vec<f64> = (0..k).map(|i| i as f64 * TAU / k as f64).collect();
        headings.push(goal_rad);
        headings.sort_by(|a, b| angle_diff(*a, goal_rad).total_cmp(&angle_diff(*b, goal_rad)));
        // Candidates in order of closeness to the goal direction: the first admissible wins.
        let chosen = headings.into_iter().find_map(|h| {
            let v_b = Vec2::new(h.cos(), h.sin()) * speed;
            self.path_is_clear(v_now, v_b, &near).then_some((h, v_b))
        });
        match chosen {
            Some((h, v_b)) => Decision {
                v_mm_s: v_b,
                heading_rad: Some(h),
            },
            None => Decision {
                v_mm_s: Vec2::zeros(),
                heading_rad: None,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drive() -> AccelLimitedDrive {
        AccelLimitedDrive::new(300.0, 10.0).unwrap()
    }

    /// What vision reports with a 1000 mm template.
    fn surroundings<'a>(dirs: &'a [f64], free: &'a [f64], pts: &'a [Vec2]) -> Surroundings<'a> {
        Surroundings {
            direction_rad: dirs,
            free_mm: free,
            range_mm: 1000.0,
            obstacle_points: pts,
        }
    }

    /// A wall across the robot's path at x = `x_mm`, seen in 32 directions up to 1000 mm.
    fn wall_ahead(x_mm: f64) -> (Vec<f64>, Vec<f64>, Vec<Vec2>) {
        let dirs: Vec<f64> = (0..32).map(|j| j as f64 * TAU / 32.0).collect();
        let mut free = Vec::new();
        let mut pts = Vec::new();
        for &a in &dirs {
            let c = a.cos();
            let d = if c > 1e-9 { x_mm / c } else { f64::INFINITY };
            if d < 1000.0 {
                free.push(d);
                pts.push(Vec2::new(d * c, d * a.sin()));
            } else {
                free.push(1000.0);
            }
        }
        (dirs, free, pts)
    }

    #[test]
    fn without_the_velocity_term_the_robot_runs_into_the_wall() {
        // Sect. 3.2's point: heading for a free direction without predicting the path, the
        // acceleration limit carries the robot into the wall it is rushing at (the path here
        // ignores the wall, so the centre passes the 510 mm where its edge would touch).
        let (max_x, _) = rush_at_wall(false, false);
        assert!(max_x > 600.0 - 90.0, "max x {max_x}");
    }

    #[test]
    fn goal_direction_goes_straight_when_free_and_around_when_not() {
        let c = GoalDirection::new(AvoidanceConfig::default(), drive(), 400.0, 90.0).unwrap();
        let (dirs, free, pts) = wall_ahead(10_000.0);
        let s = surroundings(&dirs, &free, &pts);
        let d = c.decide(&s, Vec2::new(3000.0, 100.0));
        assert!((d.heading_rad.unwrap() - 100f64.atan2(3000.0)).abs() < 1e-12);
        assert!((d.v_mm_s.norm() - 400.0).abs() < 1e-9);
        let (dirs, free, pts) = wall_ahead(500.0);
        let s = surroundings(&dirs, &free, &pts);
        let d = c.decide(&s, Vec2::new(3000.0, 100.0));
        let h = d.heading_rad.unwrap();
        // The wall at 500 mm: at 56.25 degrees it is 900 mm away, at 67.5 degrees 1306 mm, and
        // the strip swept along 67.5 degrees keeps 176 mm from the nearest wall point.
        assert!(
            (h.to_degrees().abs() - 67.5).abs() < 1e-9,
            "{}",
            h.to_degrees()
        );
    }

    /// Closed loop against a wall at x = 600: decide every 40 ms on what the wall looks like
    /// from where the robot is, drive with eq. (8) in 1 ms steps.
    fn rush_at_wall(velocity_aware: bool, check_period_brake: bool) -> (f64, Vec2) {
        let cfg = AvoidanceConfig {
            check_period_brake,
            ..AvoidanceConfig::default()
        };
        let va = VelocityAware::new(cfg.clone(), drive(), 400.0, 90.0, 0.04).unwrap();
        let gd = GoalDirection::new(cfg, drive(), 400.0, 90.0).unwrap();
        let mut p = Vec2::zeros();
        let mut v = Vec2::new(400.0, 0.0);
        let mut max_x: f64 = f64::MIN;
        for _ in 0..200 {
            let (dirs, free, pts) = wall_ahead(600.0 - p.x);
            let s = surroundings(&dirs, &free, &pts);
            let goal = Vec2::new(3000.0, 50.0) - p;
            let cmd = if velocity_aware {
                va.decide(&s, goal, v).v_mm_s
            } else {
                gd.decide(&s, goal).v_mm_s
            };
            for _ in 0..40 {
                let v1 = drive().step(v, cmd, 0.001);
                p += (v + v1) * 0.0005;
                v = v1;
                max_x = max_x.max(p.x);
            }
        }
        (max_x, p)
    }

    #[test]
    fn velocity_aware_never_reaches_a_wall_it_rushes_at() {
        // With the braking path one period ahead checked too, it keeps the margin from the
        // obstacle points: the centre stays 90 + 30 mm before the wall, up to what slips between
        // points sampled 11.25 degrees apart (about 1 mm here).
        let (max_x, p) = rush_at_wall(true, true);
        assert!(max_x <= 600.0 - 120.0 + 2.0, "max x {max_x}");
        // The goal lies beyond the wall: it ends at rest in front of it.
        assert!(p.x > 400.0, "{p:?}");
        // Without it, braking can start one period (16 mm at 400 mm/s) late: the margin may
        // shrink by that much, never more, and the robot never touches.
        let (max_x, p) = rush_at_wall(true, false);
        assert!(max_x <= 600.0 - 120.0 + 16.0 + 2.0, "max x {max_x}");
        assert!(max_x < 600.0 - 90.0);
        assert!(p.x > 400.0, "{p:?}");
    }

    #[test]
    fn velocity_aware_stops_when_boxed_in() {
        let c = VelocityAware::new(AvoidanceConfig::default(), drive(), 400.0, 90.0, 0.04).unwrap();
        let dirs: Vec<f64> = (0..32).map(|j| j as f64 * TAU / 32.0).collect();
        let pts: Vec<Vec2> = dirs
            .iter()
            .map(|a| Vec2::new(a.cos(), a.sin()) * 130.0)
            .collect();
        let free = vec![130.0; 32];
        let s = surroundings(&dirs, &free, &pts);
        let d = c.decide(&s, Vec2::new(1000.0, 0.0), Vec2::new(100.0, 0.0));
        assert_eq!(d.v_mm_s, Vec2::zeros());
        assert!(d.heading_rad.is_none());
    }

    #[test]
    fn bad_settings_are_refused() {
        let bad = AvoidanceConfig {
            candidates: 2,
            ..AvoidanceConfig::default()
        };
        assert!(VelocityAware::new(bad, drive(), 400.0, 90.0, 0.04).is_err());
        let bad = AvoidanceConfig {
            margin_mm: -1.0,
            ..AvoidanceConfig::default()
        };
        assert!(GoalDirection::new(bad, drive(), 400.0, 90.0).is_err());
    }
}
