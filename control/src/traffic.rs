//! Sharing the floor with other robots that avoid too (`[control.avoidance.traffic]`): the
//! velocity-aware controller's rule for obstacles that may move.
//!
//! A robot seen on the camera is not a wall: it may come nearer while this robot brakes. Two
//! such robots, each braking short of the other's present place, can still meet in the middle.
//! The rule adapts the *buffered Voronoi cells* of Zhou, Wang, Bandyopadhyay and Schwager
//! ("Fast, on-line collision avoidance for dynamic vehicles using buffered Voronoi cells",
//! IEEE Robotics and Automation Letters 2(2), 2017, eqs. (3)-(5)) to what a camera gives: the
//! other robot's centre is unknown, only points on the floor where its body begins (the
//! boundary of the surely free space toward it). For such a point `o` (robot frame, the robot
//! at the origin), the robot keeps its whole predicted path (holding the command for one
//! period, then braking at its limit) in the half-plane
//!
//! ```text
//!     p . o / |o|  <=  max(0, (|o| - r - g) / 2)
//! ```
//!
//! (`r` the robot's radius, `g` the gap kept between two robots, [`TrafficConfig::gap_mm`]): it
//! advances toward the point by at most half of what is left of the gap beyond `g`. When both
//! robots do so, each stays on its side of the line halfway between them, and their edges stay
//! `g` apart; a robot already nearer only keeps from coming nearer. It needs no velocity of the
//! other: motion is taken care of by each taking half. What Zhou et al. take as the
//! neighbours' positions, shared by radio, is here the nearest place each may stand, seen.
//!
//! The horizon of the free space (where the unknown begins) is such a point too: another robot
//! may come out of the unknown toward this one, and two robots that first see each other at the
//! edge of their templates must both stop in half the distance. This caps the speed at
//! `sqrt(alpha (range - r - g))`, the price of not knowing what lies beyond.
//!
//! Buffered cells deadlock where robots meet symmetrically (six robots crossing at the centre
//! stop at the corners of a hexagon). Zhou et al. break it with a right-hand rule; ours acts
//! before the deadlock, as the rule of the road at sea does for vessels meeting head-on
//! (COLREGs Rule 14: each alters course to starboard): the heading the controller scores
//! against turns to the right of the goal direction by up to
//! [`TrafficConfig::keep_right_deg`], the more the nearer a moving obstacle stands ahead
//! (within 60 degrees of the goal direction and [`TrafficConfig::look_ahead_mm`]). Robots
//! meeting head-on pass left side to left side; six crossing at the centre turn it into a
//! roundabout.
//!
//! A robot that has arrived holds its target, and buffered cells never make it give way: robots
//! that arrived first wall in those still on their way (three standing across the Small-Size
//! field leave gaps narrower than two robots need to pass, and the one that must pass circles
//! in front of them). With [`TrafficConfig::yield_mm`], a robot within that distance of its
//! target makes way for moving obstacles that come nearer than that to its edge
//! ([`TrafficConfig::make_way`]), the share of the room reciprocal avoidance gives every
//! party (van den Berg, Guy, Lin and Manocha, "Reciprocal n-body collision avoidance", ISRR
//! 2009, Sect. 5), and comes back once they have passed.
//!
//! Which obstacles may move is the robot software's call (its map explains walls, goals and
//! pillars; everything else may be a robot; with [`TrafficConfig::moved_s`], only what was
//! seen to move); the rule itself needs only the points.

use crate::Vec2;
use crate::angle::angle_diff;
use serde::{Deserialize, Serialize};

/// Whether the controller shares the floor with robots that avoid too.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TrafficRule {
    /// Every obstacle is kept at the clearance, as if it stood still (the papers' set-up).
    #[default]
    Static,
    /// Obstacles that may move, and the horizon, get the reciprocal half-gap (see the module).
    Reciprocal,
}

/// Settings of the rule for other robots (`[control.avoidance.traffic]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrafficConfig {
    /// `static` (default) or `reciprocal`.
    pub rule: TrafficRule,
    /// Gap kept between the edges of two robots, mm (the half-planes' buffer).
    pub gap_mm: f64,
    /// Largest turn of the scored heading to the right of the goal direction, degrees, when a
    /// moving obstacle stands ahead (0: no rule of the road).
    pub keep_right_deg: f64,
    /// A moving obstacle ahead turns the heading from this gap on, mm, fully at `gap_mm`.
    pub look_ahead_mm: f64,
    /// An obstacle the map does not explain counts as moving only when it stands where the
    /// robot saw the floor surely free within this time, s; one standing where the floor was
    /// not seen free lately (a robot that arrived, or waits) is kept at the normal clearance,
    /// as a wall is. 0: every obstacle the map does not explain may move.
    pub moved_s: f64,
    /// A robot within this distance of its target makes way for moving obstacles whose gap
    /// to its edge is under this, mm, by as much as they come nearer, staying within this of
    /// its target (see [`TrafficConfig::make_way`]); 0: it holds its target. Without
    /// `moved_s`, everything the map does not explain counts as moving, robots standing on
    /// their own targets included: two whose targets leave less than this between their
    /// edges push each other off them for good, so keep it under the least such gap (or set
    /// `moved_s`).
    pub yield_mm: f64,
}

impl Default for TrafficConfig {
    fn default() -> Self {
        Self {
            rule: TrafficRule::Static,
            gap_mm: 150.0,
            keep_right_deg: 50.0,
            look_ahead_mm: 900.0,
            moved_s: 0.0,
            yield_mm: 0.0,
        }
    }
}

/// Half the cone ahead of the goal direction in which a moving obstacle makes the robot keep
/// right.
const AHEAD_RAD: f64 = std::f64::consts::FRAC_PI_3;

/// A half-plane `p . n <= b` the predicted path must keep to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfPlane {
    /// Unit normal, toward the obstacle.
    pub n: Vec2,
    /// Offset, mm.
    pub b: f64,
}

impl HalfPlane {
    /// Whether `p` lies in it (within a micrometre).
    pub fn holds(&self, p: Vec2) -> bool {
        p.dot(&self.n) <= self.b + 1e-3
    }
}

impl TrafficConfig {
    /// Whether the rule is on.
    pub fn reciprocal(&self) -> bool {
        self.rule == TrafficRule::Reciprocal
    }

    /// Where a robot at its target (`target`, robot frame, within `yield_mm`) heads to make
    /// way for the moving obstacles `moving` (robot frame) that come nearer than `yield_mm`
    /// to its edge (`radius_mm` from its centre): away from them (the sum of their
    /// directions, each weighted by how far it comes inside that reach) by as far as the
    /// deepest comes inside, but no farther than `yield_mm` from the target; the target
    /// itself when none comes that near, or farther from it. Buffered Voronoi cells (Zhou et
    /// al. 2017) and reciprocal avoidance in general (van den Berg et al., "Reciprocal
    /// n-body collision avoidance", ISRR 2009, Sect. 5: each agent takes half the
    /// responsibility) let a robot that has arrived stand where it is: it never comes nearer,
    /// but never makes room either, and robots that arrived first wall in those still on
    /// their way (three robots standing across a field leave gaps narrower than two robots
    /// passing need). Making way for what moves, and coming back once it has passed, lends
    /// the others the room.
    pub fn make_way(&self, target: Vec2, moving: &[Vec2], radius_mm: f64) -> Vec2 {
        if !self.reciprocal() || self.yield_mm <= 0.0 || target.norm() > self.yield_mm {
            return target;
        }
        let reach = radius_mm + self.yield_mm;
        let (mut sum, mut deepest) = (Vec2::zeros(), 0.0_f64);
        for o in moving {
            let d = o.norm();
            if d < 1e-9 || d >= reach {
                continue;
            }
            sum += o / d * (reach - d);
            deepest = deepest.max(reach - d);
        }
        if deepest <= 0.0 || sum.norm() < 1e-9 {
            return target;
        }
        let to = -sum.normalize() * deepest;
        let off = to - target;
        if off.norm() <= self.yield_mm {
            to
        } else {
            target + off.normalize() * self.yield_mm
        }
    }

    /// The half-plane of each point (robot frame) that may be another robot or hide one, for
    /// a robot of `radius_mm`: the reciprocal half-gap of the module's documentation. Points
    /// farther than `reach_mm` cannot constrain a path that short and are left out.
    pub fn half_planes(&self, points: &[Vec2], radius_mm: f64, reach_mm: f64) -> Vec<HalfPlane> {
        points
            .iter()
            .filter_map(|o| {
                let d = o.norm();
                let b = (0.5 * (d - radius_mm - self.gap_mm)).max(0.0);
                (d > 1e-9 && b <= reach_mm).then(|| HalfPlane { n: o / d, b })
            })
            .collect()
    }

    /// The direction the controller scores headings against: the goal direction `goal_rad`,
    /// turned right by up to `keep_right_deg` as the nearest moving obstacle within 60 degrees
    /// of it (and nearer than the goal, `goal_mm` away) comes from `look_ahead_mm` to
    /// `gap_mm` (the gap from the robot's edge, `radius_mm`).
    pub fn heading_rad(&self, goal_rad: f64, goal_mm: f64, moving: &[Vec2], radius_mm: f64) -> f64 {
        if !self.reciprocal() || self.keep_right_deg <= 0.0 {
            return goal_rad;
        }
        let nearest = moving
            .iter()
            .filter(|o| {
                let d = o.norm();
                d < goal_mm && angle_diff(o.y.atan2(o.x), goal_rad) <= AHEAD_RAD
            })
            .map(|o| o.norm() - radius_mm)
            .fold(f64::INFINITY, f64::min);
        let span = (self.look_ahead_mm - self.gap_mm).max(1.0);
        let k = ((self.look_ahead_mm - nearest) / span).clamp(0.0, 1.0);
        goal_rad - k * self.keep_right_deg.to_radians()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn on() -> TrafficConfig {
        TrafficConfig {
            rule: TrafficRule::Reciprocal,
            ..TrafficConfig::default()
        }
    }

    #[test]
    fn a_robot_may_advance_half_the_gap_left_beyond_the_buffer() {
        let t = on();
        // Another robot's edge 690 mm ahead of the centre: 690 - 90 - 150 = 450 left, half 225.
        let planes = t.half_planes(&[Vec2::new(690.0, 0.0)], 90.0, 1e9);
        assert_eq!(planes.len(), 1);
        assert!((planes[0].b - 225.0).abs() < 1e-9);
        assert!(planes[0].holds(Vec2::new(225.0, 500.0)));
        assert!(!planes[0].holds(Vec2::new(226.0, 0.0)));
        // Nearer than the buffer: no nearer at all, but sideways and away are free.
        let planes = t.half_planes(&[Vec2::new(0.0, 200.0)], 90.0, 1e9);
        assert_eq!(planes[0].b, 0.0);
        assert!(planes[0].holds(Vec2::new(300.0, 0.0)));
        assert!(!planes[0].holds(Vec2::new(0.0, 1.0)));
    }

    #[test]
    fn two_robots_keeping_their_half_planes_keep_the_gap() {
        // Robots at -D/2 and +D/2 on x, each seeing the other's edge: the farthest each may go
        // leaves their edges gap_mm apart.
        let t = on();
        let (r, d) = (90.0, 1000.0);
        let seen = Vec2::new(d - r, 0.0);
        let b = t.half_planes(&[seen], r, 1e9)[0].b;
        let gap = (d - 2.0 * b) - 2.0 * r;
        assert!((gap - t.gap_mm).abs() < 1e-9, "{gap}");
    }

    #[test]
    fn a_robot_ahead_turns_the_heading_right_the_more_the_nearer() {
        let t = on();
        let far = t.heading_rad(0.0, 3000.0, &[Vec2::new(2000.0, 0.0)], 90.0);
        let mid = t.heading_rad(0.0, 3000.0, &[Vec2::new(615.0, 0.0)], 90.0);
        let near = t.heading_rad(0.0, 3000.0, &[Vec2::new(200.0, 0.0)], 90.0);
        assert_eq!(far, 0.0);
        assert!(mid < 0.0 && mid > near, "{mid} {near}");
        assert!((near + t.keep_right_deg.to_radians()).abs() < 1e-12);
        // Behind the robot or beyond the goal, nothing turns it.
        assert_eq!(
            t.heading_rad(0.0, 3000.0, &[Vec2::new(-300.0, 0.0)], 90.0),
            0.0
        );
        assert_eq!(
            t.heading_rad(0.0, 250.0, &[Vec2::new(300.0, 0.0)], 90.0),
            0.0
        );
        // Off: the goal direction.
        let off = TrafficConfig::default();
        assert_eq!(
            off.heading_rad(0.0, 3000.0, &[Vec2::new(200.0, 0.0)], 90.0),
            0.0
        );
    }

    #[test]
    fn moved_s_and_yield_mm_must_be_finite_and_not_negative() {
        let checked = |t: TrafficConfig| {
            crate::avoidance::check_config(&crate::AvoidanceConfig {
                traffic: t,
                ..crate::AvoidanceConfig::default()
            })
        };
        assert!(checked(on()).is_ok());
        assert!(
            checked(TrafficConfig {
                moved_s: 1.0,
                ..on()
            })
            .is_ok()
        );
        for bad in [-1.0, f64::NAN, f64::INFINITY] {
            assert!(
                checked(TrafficConfig {
                    moved_s: bad,
                    ..on()
                })
                .is_err(),
                "{bad}"
            );
            assert!(
                checked(TrafficConfig {
                    yield_mm: bad,
                    ..on()
                })
                .is_err(),
                "{bad}"
            );
        }
    }

    #[test]
    fn a_robot_at_its_target_makes_way_for_one_coming_near_and_no_farther_than_yield_mm() {
        let t = TrafficConfig {
            yield_mm: 250.0,
            ..on()
        };
        // At its target; another robot's edge 200 mm ahead (110 mm from this one's edge, 140
        // inside the reach of 340 mm): it heads 140 mm back.
        let to = t.make_way(Vec2::zeros(), &[Vec2::new(200.0, 0.0)], 90.0);
        assert!((to - Vec2::new(-140.0, 0.0)).norm() < 1e-9, "{to:?}");
        // Nothing near: the target.
        let target = Vec2::new(30.0, 40.0);
        assert_eq!(t.make_way(target, &[Vec2::new(600.0, 0.0)], 90.0), target);
        // Pressed hard while already off its target: no farther than yield_mm from it.
        let target = Vec2::new(200.0, 0.0);
        // Something at its edge on the target's side pushes it 339 mm back, held to 250 mm
        // from the target.
        let to = t.make_way(target, &[Vec2::new(1.0, 0.0)], 90.0);
        assert!((to - Vec2::new(-50.0, 0.0)).norm() < 1e-9, "{to:?}");
        // Far from its target, or with the rule off: the target.
        let far = Vec2::new(1000.0, 0.0);
        assert_eq!(t.make_way(far, &[Vec2::new(200.0, 0.0)], 90.0), far);
        let off = TrafficConfig {
            yield_mm: 0.0,
            ..on()
        };
        assert_eq!(
            off.make_way(Vec2::zeros(), &[Vec2::new(200.0, 0.0)], 90.0),
            Vec2::zeros()
        );
    }
}
