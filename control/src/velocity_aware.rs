//! Velocity-aware avoidance (Sect. 3.2 of the corner paper) and its extension to chosen speeds.
//!
//! For a candidate command `v_b`, eq. (8) predicts the path from the current velocity: toward
//! `v_b` until the drive gets there, then braking to rest at alpha. A candidate is admissible
//! when that path keeps the robot radius plus a margin from every obstacle point.
//!
//! - [`SpeedChoice::Fixed`], the paper's: every candidate direction (64 evenly spaced, plus the
//!   goal direction) at the approach speed `min(v_max, sqrt(2 alpha d))`; the admissible
//!   direction closest to the goal direction wins; none admissible: brake.
//! - [`SpeedChoice::Chosen`], ours: a candidate is a direction *and* a speed, judged against
//!   the boundary of the *surely* free space rather than the obstacle points: space beyond the
//!   template's outer edge is unknown, not free, and a cell eq. (6) judges free may still be
//!   partly occupied, so the robot never commits to a speed whose stopping distance exceeds what
//!   it has seen to be free; an obstacle already within the clearance need only get no nearer,
//!   and a blind point (something at an unknown distance inside the body's blind zone, placed
//!   at the body's edge) may be passed at a slant of up to 30 degrees, never headed into: the
//!   path keeps `r cos 30°` from it, or, nearer than that already, gets no nearer; one moved
//!   out beyond the edge (where the robot's map says the obstacle begins) is kept `d cos 30°`
//!   from, never less than the body's radius.
//!   And the next decision comes one control period later, so the path that holds `v_b`
//!   for that period and then brakes must be clear too: whatever the next cycle sees, braking
//!   stays safe. In each direction the fastest admissible of `speeds` speeds is found (by
//!   bisection: a path that brakes from a lower speed is shorter); the command maximises
//!   `v ((1 + cos(delta)) / 2 + 0.5 (1 + cos(gamma)) / 2)`, with `delta` the angle to the goal
//!   direction and `gamma` the angle to the present course: the speed made good toward the goal,
//!   so it would rather go round an obstacle briskly than creep at it, and some commitment to
//!   the course, so it follows a wall round to a goal behind it rather than dithering where both
//!   ways along the wall look alike. The approach speed caps every speed, so the robot arrives at
//!   a target at a speed from which it can stop there.

use crate::angle::angle_diff;
use crate::avoidance::{
    AvoidanceConfig, Decision, SpeedChoice, Surroundings, approach_speed, check_config,
};
use crate::traffic::HalfPlane;
use crate::{AccelLimitedDrive, ControlError, Vec2, require_positive};
use std::f64::consts::TAU;

/// How chosen speeds score a heading (`delta` its angle to the goal, `gamma` to the course).
#[derive(Debug, Clone, Copy)]
enum Score {
    /// `v cos(delta)`: the signed speed made good.
    MadeGood,
    /// `v (1 + cos(delta)) / 2`.
    Toward,
    /// `v ((1 + cos(delta)) / 2 + COURSE_WEIGHT (1 + cos(gamma)) / 2)`, the present course.
    Course(f64),
}

/// What the controller knows of the way to the goal handed to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GoalKind {
    /// The target, or a point on the way to it, the way not known to be clear (the papers'
    /// set-up: the goal may lie behind a wall).
    Ahead,
    /// The target itself, in sight over cells the robot's map has free (a planner's last
    /// leg): the robot is to stop on it.
    InSight,
}

/// Chooses among commands whose eq. (8) paths stay clear of the obstacles.
#[derive(Debug, Clone)]
pub struct VelocityAware {
    config: AvoidanceConfig,
    drive: AccelLimitedDrive,
    max_speed_mm_s: f64,
    radius_mm: f64,
    period_s: f64,
}

/// Chosen speeds: the weight of keeping the present course, against 1 for heading straight
/// at the goal.
const COURSE_WEIGHT: f64 = 0.5;
/// Below this speed the robot has no course to keep.
const COURSE_MIN_SPEED_MM_S: f64 = 50.0;
/// Chosen speeds: a path may pass a blind point (something at an unknown distance, placed at
/// the body's edge) at this slant from it, radians: it keeps `cos` of the body's radius from
/// it, and a blind point already nearer than that (one remembered where it was first placed,
/// which the robot came nearer to) need only get no nearer. Held to "no nearer" (a right angle), a robot that starts in a corner, its blind zone
/// holding walls in more than half of the directions, could not move at all; at this slant
/// it leaves along the free arc's middle, and moving toward a wall stays forbidden (the
/// nearer the wall, the wider the blocked arc).
const BLIND_SLANT_RAD: f64 = std::f64::consts::FRAC_PI_6;

/// A blind point nearer than the body's edge by more than this is held at its distance (no
/// slant), mm: the points placed at the edge this cycle lie at the edge to rounding.
const BLIND_EDGE_TOLERANCE_MM: f64 = 0.5;

/// An obstacle point and the squared distance every predicted path must keep from it.
#[derive(Debug, Clone, Copy)]
struct Obstacle {
    p: Vec2,
    c2: f64,
}

/// What every predicted path must keep to: away from the obstacle points, and inside the
/// traffic rule's half-planes.
#[derive(Debug, Clone, Default)]
struct Keep {
    obstacles: Vec<Obstacle>,
    planes: Vec<HalfPlane>,
}

const STOP: Decision = Decision {
    v_mm_s: Vec2::new(0.0, 0.0),
    heading_rad: None,
};

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
    /// the origin moving at `v_now`) by the robot radius plus the margin: toward `v_b` until the
    /// drive gets there, then braking to rest; with `check_period_brake` (always, with chosen
    /// speeds) also toward `v_b` for one control period, then braking to rest — the path the
    /// robot takes if the next cycle finds nothing admissible. Each is sampled every
    /// `prediction_step_s`, and every obstacle must keep the clearance from each segment between
    /// samples.
    fn clear_among(&self, v_now: Vec2, v_b: Vec2, keep: &Keep) -> bool {
        let t_a = self.drive.settle_time_s(v_now, v_b);
        let period_brake =
            self.config.check_period_brake || self.config.speed == SpeedChoice::Chosen;
        self.phases_clear(v_now, v_b, t_a, keep)
            && (!period_brake || self.phases_clear(v_now, v_b, self.period_s, keep))
    }

    /// The path toward `v_b` for `t1`, then toward rest until stopped (plus
    /// `extra_horizon_s`), sampled every `prediction_step_s` (robot frame, from the origin).
    fn phases(&self, v_now: Vec2, v_b: Vec2, t1: f64) -> Vec<Vec2> {
        let alpha = self.drive.accel_limit_mm_s2();
        let p1 = self.drive.displacement(v_now, v_b, t1);
        let v1 = self.drive.velocity_at(v_now, v_b, t1);
        let t2 = v1.norm() / alpha + self.config.extra_horizon_s;
        let horizon = t1 + t2;
        let dt = self.config.prediction_step_s;
        let steps = (horizon / dt).ceil().max(1.0) as usize;
        let at = |t: f64| {
            if t <= t1 {
                self.drive.displacement(v_now, v_b, t)
            } else {
                p1 + self.drive.displacement(v1, Vec2::zeros(), t - t1)
            }
        };
        (0..=steps)
            .map(|k| at((k as f64 * dt).min(horizon)))
            .collect()
    }

    /// Whether the path toward `v_b` for `t1`, then to rest, keeps clear of `keep`.
    fn phases_clear(&self, v_now: Vec2, v_b: Vec2, t1: f64, keep: &Keep) -> bool {
        let path = self.phases(v_now, v_b, t1);
        // A half-plane is convex: the samples in it, the segments between them are too. One
        // whose offset is at least the path's reach from the robot holds every sample
        // (`p . n <= |p|`): only the nearer ones are checked point by point.
        if !keep.planes.is_empty() {
            let reach = path.iter().map(|p| p.norm()).fold(0.0, f64::max);
            let near = keep.planes.iter().filter(|h| h.b < reach);
            if !near.into_iter().all(|h| path.iter().all(|p| h.holds(*p))) {
                return false;
            }
        }
        let obstacles = &keep.obstacles;
        // Only obstacles within reach of the path's bounding box can come too near.
        let (mut lo, mut hi) = (path[0], path[0]);
        for p in &path {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        for o in obstacles {
            let c = o.c2.sqrt();
            if o.p.x < lo.x - c || o.p.x > hi.x + c || o.p.y < lo.y - c || o.p.y > hi.y + c {
                continue;
            }
            for w in path.windows(2) {
                let (a, ab) = (w[0], w[1] - w[0]);
                let len2 = ab.norm_squared();
                let u = if len2 > 0.0 {
                    ((o.p - a).dot(&ab) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                if (o.p - (a + ab * u)).norm_squared() < o.c2 {
                    return false;
                }
            }
        }
        true
    }

    /// The obstacles the robot could reach moving at `v_now` or `speed` (those within the
    /// longest path any candidate can take), each to be kept `clearance` away; with
    /// `hold_nearer`, one already nearer than that need only get no nearer.
    fn reachable(
        &self,
        points: &[&[Vec2]],
        v_now: Vec2,
        speed: f64,
        clearance: f64,
        hold_nearer: bool,
    ) -> Vec<Obstacle> {
        let reach = self.longest_path_mm(v_now, speed) + clearance;
        let c2 = clearance * clearance;
        points
            .iter()
            .flat_map(|p| p.iter())
            .filter(|o| o.norm() <= reach)
            .map(|&p| Obstacle {
                p,
                c2: if hold_nearer {
                    c2.min(p.norm_squared())
                } else {
                    c2
                },
            })
            .collect()
    }

    /// The longest path any candidate of at most `speed` can take from `v_now`, mm (an upper
    /// bound: the top speed over the longest time to settle, hold a period and brake).
    fn longest_path_mm(&self, v_now: Vec2, speed: f64) -> f64 {
        let alpha = self.drive.accel_limit_mm_s2();
        let top = v_now.norm().max(speed);
        let longest = (v_now.norm() + speed) / alpha
            + self.period_s
            + top / alpha
            + self.config.extra_horizon_s;
        top * longest
    }

    /// Candidate directions, the goal direction among them, nearest the goal direction first.
    fn headings(&self, goal_rad: f64) -> Vec<f64> {
        let k = self.config.candidates;
        let mut headings: Vec<f64> = (0..k).map(|i| i as f64 * TAU / k as f64).collect();
        headings.push(goal_rad);
        headings.sort_by(|a, b| angle_diff(*a, goal_rad).total_cmp(&angle_diff(*b, goal_rad)));
        headings
    }

    /// The command for a robot moving at `v_now` (robot frame) with the goal at `goal`.
    pub fn decide(&self, s: &Surroundings<'_>, goal: Vec2, v_now: Vec2) -> Decision {
        self.decide_toward(s, goal, GoalKind::Ahead, v_now)
    }

    /// The command for a robot moving at `v_now` (robot frame) sent toward `goal`, the target
    /// itself or a point on the way to it (a planner's lookahead point, whose distance is the
    /// way left, shortened before bends), knowing `kind` of the way there.
    pub fn decide_toward(
        &self,
        s: &Surroundings<'_>,
        goal: Vec2,
        kind: GoalKind,
        v_now: Vec2,
    ) -> Decision {
        let d_goal = goal.norm();
        if d_goal < 1e-6 {
            return STOP;
        }
        let goal_rad = goal.y.atan2(goal.x);
        let speed = approach_speed(self.max_speed_mm_s, &self.drive, d_goal);
        // With the traffic rule, a target in the free space is in sight: the robot stops on
        // it and holds there while the others pass, instead of circling it.
        let seen = self.config.traffic.reciprocal() && in_free_space(s, goal_rad, d_goal);
        let in_sight = kind == GoalKind::InSight || seen;
        let arriving = in_sight && speed < self.max_speed_mm_s;
        let holding = seen && speed < self.max_speed_mm_s;
        match self.config.speed {
            SpeedChoice::Fixed => self.decide_fixed(s, goal_rad, speed, v_now),
            SpeedChoice::Chosen => self.decide_chosen(s, goal, speed, (arriving, holding), v_now),
        }
    }

    /// The paper's: the admissible direction nearest the goal direction at `speed`.
    fn decide_fixed(
        &self,
        s: &Surroundings<'_>,
        goal_rad: f64,
        speed: f64,
        v_now: Vec2,
    ) -> Decision {
        let clearance = self.radius_mm + self.config.margin_mm;
        let near = Keep {
            obstacles: self.reachable(&[s.obstacle_points], v_now, speed, clearance, false),
            planes: Vec::new(),
        };
        self.headings(goal_rad)
            .into_iter()
            .find_map(|h| {
                let v_b = Vec2::new(h.cos(), h.sin()) * speed;
                self.clear_among(v_now, v_b, &near).then_some(Decision {
                    v_mm_s: v_b,
                    heading_rad: Some(h),
                })
            })
            .unwrap_or(STOP)
    }

    /// Ours: the admissible direction and speed with the most speed made good toward the goal,
    /// the horizon counting as an obstacle.
    fn decide_chosen(
        &self,
        s: &Surroundings<'_>,
        goal: Vec2,
        speed: f64,
        (arriving, holding): (bool, bool),
        v_now: Vec2,
    ) -> Decision {
        let goal_rad = goal.y.atan2(goal.x);
        // An obstacle already nearer than the clearance (the robot was pushed, or vision put it
        // at the robot's edge for want of knowing better) need only get no nearer, so the robot
        // can always move away.
        let clearance = self.radius_mm + self.config.margin_mm;
        let points = [s.clear_points];
        let mut obstacles = self.reachable(&points, v_now, speed, clearance, true);
        // A blind point at the body's edge may be passed at a slant; one nearer than the edge
        // (a remembered one the robot came nearer to) need only get no nearer: the robot has
        // come up to whatever stands there, a cube's face perhaps, and sliding past it at a
        // slant would close on the face; one beyond the edge is never passed nearer than the
        // edge (see `blind_keep_mm`).
        obstacles.extend(s.blind_points.iter().map(|&p| Obstacle {
            p,
            c2: self.blind_keep_mm(p.norm(), clearance).powi(2),
        }));
        let traffic = &self.config.traffic;
        let planes = if traffic.reciprocal() {
            let reach = self.longest_path_mm(v_now, speed);
            let mut planes = traffic.half_planes(s.moving_points, self.radius_mm, reach);
            planes.extend(traffic.half_planes(s.horizon_points, self.radius_mm, reach));
            planes
        } else {
            Vec::new()
        };
        let near = Keep { obstacles, planes };
        // With the traffic rule, headings are scored against the goal direction turned right
        // while another robot stands ahead (the rule of the road).
        let scored_rad =
            traffic.heading_rad(goal_rad, goal.norm(), s.moving_points, self.radius_mm);
        // Arriving (within braking distance of a target in sight, where the approach speed
        // caps the speed) and moving away from it, the score is the signed speed made good,
        // `v cos(delta)`: a robot that overshot the target brakes and comes back rather than
        // keep its course away at speed, round and round it, when turning back at once would
        // swing it too near something. Only at rest may it move away from the target (to go
        // round what stands in its way), scored as below. (Not where the target may lie
        // behind a wall: the way there may lead away from it.)
        let receding = v_now.norm() > COURSE_MIN_SPEED_MM_S
            && v_now.dot(&Vec2::new(goal_rad.cos(), goal_rad.sin())) < 0.0;
        // Holding on a target in sight with the traffic rule, the robot scores so whatever its
        // course: the course bonus would keep it circling the target.
        if arriving && (receding || holding) {
            if let Some(d) = self.best_heading(&near, goal_rad, speed, v_now, Score::MadeGood) {
                return d;
            }
            if v_now.norm() > COURSE_MIN_SPEED_MM_S {
                return STOP;
            }
        }
        // Moving, the robot keeps to its course unless another serves the goal clearly better,
        // so that it follows a wall round to a goal behind it instead of dithering where the
        // goal direction is blocked and both ways along the wall look alike.
        let score = match v_now.norm() > COURSE_MIN_SPEED_MM_S {
            true => Score::Course(v_now.y.atan2(v_now.x)),
            false => Score::Toward,
        };
        self.best_heading(&near, scored_rad, speed, v_now, score)
            .unwrap_or(STOP)
    }

    /// How far every path keeps from a blind point `d_mm` from the robot's centre, mm. At the
    /// body's edge (placed there for want of knowing better: whatever stands there may be
    /// anywhere out to the blind zone's edge), `r cos 30°`: it may be passed at a slant. Nearer
    /// than the edge (a remembered point the robot came nearer to), `d_mm`: no nearer. Beyond
    /// the edge (moved out to where the robot's map says the floor seen free ends, or
    /// remembered where the robot's edge once was: the obstacle begins right behind it), the
    /// slant's `d_mm cos 30°`, but never less than the body's edge: passed at `r cos 30°`,
    /// such a point let the body graze a cube's corner. Never more than `clearance`.
    fn blind_keep_mm(&self, d_mm: f64, clearance: f64) -> f64 {
        let r = self.radius_mm;
        let keep = if d_mm < r - BLIND_EDGE_TOLERANCE_MM {
            d_mm
        } else if d_mm <= r + BLIND_EDGE_TOLERANCE_MM {
            r * BLIND_SLANT_RAD.cos()
        } else {
            (d_mm * BLIND_SLANT_RAD.cos()).max(r + BLIND_EDGE_TOLERANCE_MM)
        };
        keep.min(clearance)
    }

    /// The admissible heading and speed with the best score, headings nearest the goal first.
    fn best_heading(
        &self,
        near: &Keep,
        goal_rad: f64,
        speed: f64,
        v_now: Vec2,
        score: Score,
    ) -> Option<Decision> {
        let mut best: Option<(f64, Decision)> = None;
        for h in self.headings(goal_rad) {
            let cos = angle_diff(h, goal_rad).cos();
            let (toward_goal, bonus) = match score {
                Score::MadeGood => (cos, 0.0),
                Score::Toward => (0.5 * (1.0 + cos), 0.0),
                Score::Course(c) => (
                    0.5 * (1.0 + cos),
                    COURSE_WEIGHT * 0.5 * (1.0 + angle_diff(h, c).cos()),
                ),
            };
            let floor = best.map_or(0.0, |(score, _)| score);
            // Headings come nearest the goal first: none after this can do better.
            let bound = toward_goal
                + if let Score::Course(_) = score {
                    COURSE_WEIGHT
                } else {
                    0.0
                };
            if speed * bound <= floor {
                break;
            }
            let weight = toward_goal + bonus;
            let u = Vec2::new(h.cos(), h.sin());
            if let Some(v) = self.fastest(v_now, u, speed, floor / weight, near) {
                best = Some((
                    v * weight,
                    Decision {
                        v_mm_s: u * v,
                        heading_rad: Some(h),
                    },
                ));
            }
        }
        best.map(|(_, d)| d)
    }

    /// The fastest admissible of the speeds `speed k / n` (k = n ... 1) along `u` that is faster
    /// than `slowest`, by bisection.
    fn fastest(&self, v_now: Vec2, u: Vec2, speed: f64, slowest: f64, near: &Keep) -> Option<f64> {
        let n = self.config.speeds;
        let at = |k: usize| speed * k as f64 / n as f64;
        let ok = |k: usize| self.clear_among(v_now, u * at(k), near);
        if ok(n) {
            return Some(speed);
        }
        // The largest k with ok(k), in (lo, hi): ok(hi) is false, and every k <= lo is too slow.
        let mut lo = (0..n).take_while(|&k| at(k) <= slowest).last().unwrap_or(0);
        let mut hi = n;
        let mut found = None;
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if ok(mid) {
                found = Some(mid);
                lo = mid;
            } else {
                hi = mid;
            }
        }
        found.map(at)
    }
}

/// Whether the point `d_mm` away at `bearing_rad` lies in the free space (nearer than the free
/// distance of the direction whose sector holds it).
fn in_free_space(s: &Surroundings<'_>, bearing_rad: f64, d_mm: f64) -> bool {
    (0..s.direction_rad.len())
        .min_by(|&a, &b| {
            angle_diff(s.direction_rad[a], bearing_rad)
                .total_cmp(&angle_diff(s.direction_rad[b], bearing_rad))
        })
        .is_some_and(|j| d_mm < s.free_mm[j])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{Seen, drive, rush_at_wall, surroundings, wall_ahead};
    use std::f64::consts::FRAC_PI_3;

    fn controller(speed: SpeedChoice, check_period_brake: bool, v_max: f64) -> VelocityAware {
        let cfg = AvoidanceConfig {
            speed,
            check_period_brake,
            ..AvoidanceConfig::default()
        };
        VelocityAware::new(cfg, drive(), v_max, 90.0, 0.04).unwrap()
    }

    #[test]
    fn the_papers_controller_never_reaches_a_wall_it_rushes_at() {
        // With the braking path one period ahead checked too, it keeps the margin from the
        // obstacle points: the centre stays 90 + 30 mm before the wall, up to what slips between
        // points sampled 11.25 degrees apart (about 1 mm here).
        let c = controller(SpeedChoice::Fixed, true, 400.0);
        let (max_x, p) = rush_at_wall(400.0, |s, g, v| c.decide(s, g, v).v_mm_s);
        assert!(max_x <= 600.0 - 120.0 + 2.0, "max x {max_x}");
        // The goal lies beyond the wall: it ends at rest in front of it.
        assert!(p.x > 400.0, "{p:?}");
        // Without it, braking can start one period (16 mm at 400 mm/s) late: the margin may
        // shrink by that much, never more, and the robot never touches.
        let c = controller(SpeedChoice::Fixed, false, 400.0);
        let (max_x, p) = rush_at_wall(400.0, |s, g, v| c.decide(s, g, v).v_mm_s);
        assert!(max_x <= 600.0 - 120.0 + 16.0 + 2.0, "max x {max_x}");
        assert!(max_x < 600.0 - 90.0);
        assert!(p.x > 400.0, "{p:?}");
    }

    #[test]
    fn at_fixed_speed_a_fast_robot_hits_the_wall_and_with_chosen_speeds_it_stops_in_time() {
        // 1200 mm/s at alpha 300: 2400 mm to stop, more than the 1000 mm the template sees.
        let fixed = controller(SpeedChoice::Fixed, false, 1200.0);
        let (max_x, _) = rush_at_wall(1200.0, |s, g, v| fixed.decide(s, g, v).v_mm_s);
        assert!(max_x > 600.0 - 90.0, "max x {max_x}");
        // Chosen speeds, from rest: it never goes faster than it can stop within what it sees,
        // and keeps the margin; the goal lies beyond the wall, so it ends up going along it,
        // looking for a way round.
        let chosen = controller(SpeedChoice::Chosen, false, 1200.0);
        let (max_x, p) = rush_at_wall(0.0, |s, g, v| chosen.decide(s, g, v).v_mm_s);
        assert!(max_x <= 600.0 - 120.0 + 2.0, "max x {max_x}");
        assert!(p.x > 350.0 && p.y.abs() > 100.0, "{p:?}");
    }

    #[test]
    fn chosen_speeds_never_leave_the_known_free_space() {
        // Open floor all round: the fastest admissible command must stop within the template
        // (1000 mm) less the clearance, and the top speed is not admissible.
        let c = controller(SpeedChoice::Chosen, false, 2000.0);
        let open = wall_ahead(1e6);
        let d = c.decide(
            &surroundings(&open),
            Vec2::new(10_000.0, 0.0),
            Vec2::zeros(),
        );
        let v = d.v_mm_s.norm();
        let stop = drive().stopping_distance_mm(v) + v * 0.04;
        assert!(v > 300.0 && v < 2000.0, "{v}");
        assert!(stop <= 1000.0 - 120.0, "{v} mm/s stops in {stop} mm");
        // The paper's controller commands the approach speed regardless.
        let f = controller(SpeedChoice::Fixed, false, 2000.0);
        let d = f.decide(
            &surroundings(&open),
            Vec2::new(10_000.0, 0.0),
            Vec2::zeros(),
        );
        assert!((d.v_mm_s.norm() - 2000.0).abs() < 1e-9);
    }

    /// Distance along the ray from `p` in direction `u` to the first of `walls` (segments).
    fn cast(p: Vec2, u: Vec2, walls: &[(Vec2, Vec2)]) -> f64 {
        walls.iter().fold(f64::INFINITY, |best, &(a, b)| {
            let (e, w) = (b - a, a - p);
            let den = u.x * e.y - u.y * e.x;
            if den.abs() < 1e-12 {
                return best;
            }
            let t = (w.x * e.y - w.y * e.x) / den;
            let s = (w.x * u.y - w.y * u.x) / den;
            if t > 0.0 && (0.0..=1.0).contains(&s) {
                best.min(t)
            } else {
                best
            }
        })
    }

    /// Distance from `p` to the segment `a`-`b`.
    fn to_segment(p: Vec2, (a, b): (Vec2, Vec2)) -> f64 {
        let ab = b - a;
        let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
        (p - (a + ab * t)).norm()
    }

    /// The four sides of a square of half-side `h` round `c`.
    fn square(c: Vec2, h: f64) -> Vec<(Vec2, Vec2)> {
        let k = [(-h, -h), (h, -h), (h, h), (-h, h)];
        (0..4)
            .map(|i| {
                let (a, b) = (k[i], k[(i + 1) % 4]);
                (c + Vec2::new(a.0, a.1), c + Vec2::new(b.0, b.1))
            })
            .collect()
    }

    /// A 3 m x 2 m room with four square pillars 130 mm across.
    fn room_with_pillars() -> Vec<(Vec2, Vec2)> {
        let mut walls: Vec<(Vec2, Vec2)> = square(Vec2::zeros(), 1500.0)
            .into_iter()
            .map(|(a, b)| {
                (
                    Vec2::new(a.x, a.y * 2.0 / 3.0),
                    Vec2::new(b.x, b.y * 2.0 / 3.0),
                )
            })
            .collect();
        for c in [
            (-600.0, 400.0),
            (600.0, -400.0),
            (0.0, 0.0),
            (-700.0, -500.0),
        ] {
            walls.extend(square(Vec2::new(c.0, c.1), 65.0));
        }
        walls
    }

    /// `walls` seen from `p` as vision would report them: 32 directions up to 1000 mm, each
    /// with three rays (centre and sector edges) whose surely free distance is the least of
    /// the three.
    fn seen_from(p: Vec2, walls: &[(Vec2, Vec2)]) -> Seen {
        let half = 0.5 * TAU / 32.0;
        let mut seen = Seen::in_directions(32);
        for a in seen.dirs.clone() {
            let rays = [a - half, a, a + half].map(|r| Vec2::new(r.cos(), r.sin()));
            let d = rays
                .iter()
                .map(|u| cast(p, *u, walls))
                .fold(f64::INFINITY, f64::min);
            seen.free.push(d.min(1000.0));
            if d < 1000.0 {
                seen.obstacles.push(rays[1] * d);
            }
            seen.clear.extend(rays.iter().map(|u| u * d.min(1000.0)));
        }
        seen
    }

    #[test]
    fn at_2000_mm_s_no_command_takes_the_body_where_it_cannot_stop_short_of_what_it_saw() {
        // The robot (top speed 2000 mm/s, alpha 300 mm/s^2: 6.7 m to stop from the top speed,
        // more than the room) is sent round the room's corners; at no cycle may its braking
        // path from the speed it has run past what it saw, and it must never come nearer a
        // wall than the body's radius plus most of the margin.
        let walls = room_with_pillars();
        let c = controller(SpeedChoice::Chosen, false, 2000.0);
        let goals = [
            (1250.0, 750.0),
            (-1250.0, -750.0),
            (1250.0, -750.0),
            (-1250.0, 750.0),
        ];
        let (mut p, mut v) = (Vec2::new(-1250.0, 0.0), Vec2::zeros());
        let (mut nearest, mut fastest, mut reached) = (f64::INFINITY, 0.0_f64, 0);
        for _ in 0..1500 {
            let goal = goals[reached % goals.len()];
            let goal = Vec2::new(goal.0, goal.1);
            if (goal - p).norm() < 100.0 {
                reached += 1;
                continue;
            }
            // Braking from here, along the velocity, stays inside what is seen this cycle.
            let speed = v.norm();
            if speed > 1.0 {
                let along = cast(p, v / speed, &walls).min(1000.0);
                let stop = drive().stopping_distance_mm(speed);
                assert!(
                    stop + 90.0 <= along + 1.0,
                    "{speed} mm/s needs {stop} mm, {along} mm seen"
                );
            }
            let seen = seen_from(p, &walls);
            let cmd = c.decide(&surroundings(&seen), goal - p, v).v_mm_s;
            for _ in 0..40 {
                let v1 = drive().step(v, cmd, 0.001);
                p += (v + v1) * 0.0005;
                v = v1;
                fastest = fastest.max(v.norm());
                let d = walls.iter().map(|w| to_segment(p, *w));
                nearest = d.fold(nearest, f64::min);
            }
        }
        assert!(nearest >= 90.0 + 20.0, "came within {nearest} mm of a wall");
        assert!(
            fastest > 600.0,
            "it used the speed it could stop from: {fastest} mm/s"
        );
        assert!(reached >= 3, "reached {reached} corners");
    }

    #[test]
    fn velocity_aware_stops_when_boxed_in() {
        let dirs: Vec<f64> = (0..32).map(|j| j as f64 * TAU / 32.0).collect();
        let pts: Vec<Vec2> = dirs
            .iter()
            .map(|a| Vec2::new(a.cos(), a.sin()) * 130.0)
            .collect();
        let free = vec![130.0; 32];
        let s = Surroundings {
            direction_rad: &dirs,
            free_mm: &free,
            range_mm: 1000.0,
            obstacle_points: &pts,
            clear_points: &pts,
            blind_points: &[],
            moving_points: &[],
            horizon_points: &[],
        };
        for speed in [SpeedChoice::Fixed, SpeedChoice::Chosen] {
            let d = controller(speed, false, 400.0).decide(
                &s,
                Vec2::new(1000.0, 0.0),
                Vec2::new(100.0, 0.0),
            );
            assert_eq!(d.v_mm_s, Vec2::zeros());
            assert!(d.heading_rad.is_none());
        }
    }

    /// Surroundings seen to 1000 mm with no obstacle point: clear points and blind ones.
    fn unobstructed<'a>(
        dirs: &'a [f64],
        free: &'a [f64],
        clear: &'a [Vec2],
        blind: &'a [Vec2],
    ) -> Surroundings<'a> {
        Surroundings {
            direction_rad: dirs,
            free_mm: free,
            range_mm: 1000.0,
            obstacle_points: &[],
            clear_points: clear,
            blind_points: blind,
            moving_points: &[],
            horizon_points: &[],
        }
    }

    /// 32 directions seen free to 1000 mm: the directions, free distances and clear points.
    fn open_floor() -> (Vec<f64>, Vec<f64>, Vec<Vec2>) {
        let dirs: Vec<f64> = (0..32).map(|j| j as f64 * TAU / 32.0).collect();
        let clear = dirs
            .iter()
            .map(|a| Vec2::new(a.cos(), a.sin()) * 1000.0)
            .collect();
        (dirs, vec![1000.0; 32], clear)
    }

    /// Blind points at the body's edge (90 mm) in the directions `from_deg..=to_deg`, three a
    /// sector of 32 as the near-field memory gives them, and clear space (1000 mm) elsewhere.
    fn blind_arc(from_deg: i32, to_deg: i32) -> (Vec<f64>, Vec<f64>, Vec<Vec2>, Vec<Vec2>) {
        let dirs: Vec<f64> = (0..32).map(|j| j as f64 * TAU / 32.0).collect();
        let half = TAU / 64.0;
        let (mut clear, mut blind) = (Vec::new(), Vec::new());
        for &c in &dirs {
            let deg = (c.to_degrees().round() as i32 - from_deg).rem_euclid(360);
            let is_blind = deg <= (to_deg - from_deg).rem_euclid(360);
            let (out, r) = if is_blind {
                (&mut blind, 90.0)
            } else {
                (&mut clear, 1000.0)
            };
            for phi in [c - half, c, c + half] {
                out.push(Vec2::new(phi.cos(), phi.sin()) * r);
            }
        }
        (dirs, vec![1000.0; 32], clear, blind)
    }

    #[test]
    fn from_a_corner_it_leaves_along_the_free_arc_and_never_heads_into_a_blind_point() {
        let c = controller(SpeedChoice::Chosen, false, 400.0);
        let decide = |from: i32, to: i32, goal: Vec2| {
            let (dirs, free, clear, blind) = blind_arc(from, to);
            let s = unobstructed(&dirs, &free, &clear, &blind);
            (c.decide(&s, goal, Vec2::zeros()).v_mm_s, blind)
        };
        // A corner: walls behind and to the right, blind from 225 through 45 degrees (a half
        // turn and more with the sectors' edges); the goal up and to the left.
        let (v, blind) = decide(225, 45, Vec2::new(-1200.0, 600.0));
        assert!(v.norm() > 1.0, "stood still in the corner");
        for p in &blind {
            let off = (v.dot(p) / (v.norm() * p.norm())).acos();
            assert!(
                off >= FRAC_PI_3 - 1e-9,
                "{:.1} deg off a blind point",
                off.to_degrees()
            );
        }
        // Something blind straight ahead, the goal beyond it: the robot does not head into it.
        let (v, blind) = decide(-45, 45, Vec2::new(1000.0, 0.0));
        for p in &blind {
            let off = (v.dot(p) / (v.norm().max(1e-12) * p.norm())).acos();
            assert!(v.norm() < 1e-9 || off >= FRAC_PI_3 - 1e-9, "{v:?}");
        }
    }

    #[test]
    fn a_blind_point_nearer_than_the_slant_allows_is_never_approached() {
        // A blind point remembered where it was placed, the robot now 15 mm nearer to it than
        // the body's edge (75 mm < 90 cos 30 = 78 mm), everything else clear, the goal beyond
        // it at a slant of 40 degrees: placed afresh at the body's edge it would be passed at
        // that slant, coming nearer every cycle; remembered, it gets no nearer.
        let c = controller(SpeedChoice::Chosen, false, 400.0);
        let (dirs, free, clear) = open_floor();
        let p = Vec2::new(75.0, 0.0);
        let blind = [p];
        let s = unobstructed(&dirs, &free, &clear, &blind);
        let slant = 40f64.to_radians();
        let goal = Vec2::new(slant.cos(), slant.sin()) * 1000.0;
        let v = c.decide(&s, goal, Vec2::zeros()).v_mm_s;
        assert!(v.norm() > 1.0, "stood still");
        assert!(v.dot(&p) <= 1e-9, "{v:?} approaches the blind point");
    }

    #[test]
    fn a_blind_point_beyond_the_body_edge_is_never_passed_nearer_than_the_edge() {
        let c = controller(SpeedChoice::Chosen, false, 400.0);
        let slant = 30f64.to_radians().cos();
        // At the edge: the slant; nearer: no nearer; beyond: the slant, but not inside the edge.
        assert!((c.blind_keep_mm(90.0, 120.0) - 90.0 * slant).abs() < 1e-9);
        assert!((c.blind_keep_mm(80.0, 120.0) - 80.0).abs() < 1e-9);
        assert!((c.blind_keep_mm(95.0, 120.0) - 90.5).abs() < 1e-9);
        assert!((c.blind_keep_mm(130.0, 120.0) - 130.0 * slant).abs() < 1e-9);
        assert!((c.blind_keep_mm(200.0, 120.0) - 120.0).abs() < 1e-9);
        // A point the map moved out to 100 mm, the goal beyond it at a slant of 20 degrees:
        // the command's path (toward it, then braking to rest) keeps the body off the point.
        let (dirs, free, clear) = open_floor();
        let p = Vec2::new(100.0, 0.0);
        let blind = [p];
        let s = unobstructed(&dirs, &free, &clear, &blind);
        let goal = Vec2::new(20f64.to_radians().cos(), 20f64.to_radians().sin()) * 1000.0;
        let v = c.decide(&s, goal, Vec2::zeros()).v_mm_s;
        assert!(v.norm() > 1.0, "stood still");
        let t_a = c.drive.settle_time_s(Vec2::zeros(), v);
        let nearest = c
            .phases(Vec2::zeros(), v, t_a)
            .windows(2)
            .map(|w| to_segment(p, (w[0], w[1])))
            .fold(f64::INFINITY, f64::min);
        assert!(
            nearest >= 90.0,
            "the body came within {nearest:.1} mm of the point"
        );
    }

    #[test]
    fn bad_settings_are_refused() {
        let bad = AvoidanceConfig {
            candidates: 2,
            ..AvoidanceConfig::default()
        };
        assert!(VelocityAware::new(bad, drive(), 400.0, 90.0, 0.04).is_err());
        let bad = AvoidanceConfig {
            speeds: 0,
            ..AvoidanceConfig::default()
        };
        assert!(VelocityAware::new(bad, drive(), 400.0, 90.0, 0.04).is_err());
    }
}
