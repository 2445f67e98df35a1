//! The striker's geometry on the field: where to stand behind the ball, the path around it,
//! the defense areas it keeps out of, the open part of the goal, and where a rolling ball can
//! be met. World frame, millimetres.

use crate::config::FieldMap;
use nalgebra::{Point2, Rotation2, Vector2};

/// The unit vector of `v`, or zero.
pub fn unit(v: Vector2<f64>) -> Vector2<f64> {
    let n = v.norm();
    if n > 1e-9 { v / n } else { Vector2::zeros() }
}

/// Where to go next on the way to stand `standoff_mm` behind the ball at `ball` (opposite
/// `toward`, the direction the ball is to leave in), from `robot`: that point itself, or a
/// point on a circle of `clear_mm` about the ball when going straight would touch it.
pub fn approach_point(
    robot: Point2<f64>,
    ball: Point2<f64>,
    toward: Vector2<f64>,
    standoff_mm: f64,
    clear_mm: f64,
) -> Point2<f64> {
    let behind = ball - toward * standoff_mm;
    let r = robot - ball;
    let from = r.y.atan2(r.x);
    let to = (-toward).y.atan2((-toward).x);
    let turn = wrap(to - from);
    // Behind the ball already (within 30 degrees of the line), or the way there clear of it.
    if turn.abs() < 0.5
        || (r.dot(&-toward) > 0.0 && distance_to_segment(ball, robot, behind) >= clear_mm)
    {
        return behind;
    }
    // Round the ball on the side the robot is on, a step of at most a radian at a time.
    let step = turn.signum() * turn.abs().min(1.0);
    ball + Rotation2::new(step) * unit(r) * clear_mm.max(r.norm().min(clear_mm * 1.5))
}

/// Distance from `p` to the segment `a`-`b`.
pub fn distance_to_segment(p: Point2<f64>, a: Point2<f64>, b: Point2<f64>) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

/// The angle in `(-pi, pi]`.
pub fn wrap(a: f64) -> f64 {
    let mut a = a % std::f64::consts::TAU;
    if a > std::f64::consts::PI {
        a -= std::f64::consts::TAU;
    } else if a <= -std::f64::consts::PI {
        a += std::f64::consts::TAU;
    }
    a
}

/// The defense area at `+x` (`side` 1) or `-x` (`side` -1) as its lower and upper corners,
/// from its front line to the goal line; `None` on a field without defense areas.
fn defense_rect(field: &FieldMap, side: f64) -> Option<(Point2<f64>, Point2<f64>)> {
    if field.defense_depth_mm <= 0.0 {
        return None;
    }
    let (l, d, w) = (
        field.half_length_mm,
        field.defense_depth_mm,
        0.5 * field.defense_width_mm,
    );
    let (x0, x1) = if side > 0.0 { (l - d, l) } else { (-l, -l + d) };
    Some((Point2::new(x0, -w), Point2::new(x1, w)))
}

/// How far `p` is from the nearer defense area, mm (negative inside it, by the distance to its
/// nearest side toward the field), and the way out of it: the unit vector from the area's
/// nearest point to `p` (inside, out through that side). `None` on a field without them.
pub fn defense_clearance(field: &FieldMap, p: Point2<f64>) -> Option<(f64, Vector2<f64>)> {
    [1.0, -1.0]
        .into_iter()
        .filter_map(|side| defense_rect(field, side).map(|r| (side, r)))
        .map(|(side, (lo, hi))| {
            let q = Point2::new(p.x.clamp(lo.x, hi.x), p.y.clamp(lo.y, hi.y));
            let d = p - q;
            if d.norm() > 1e-9 {
                return (d.norm(), d / d.norm());
            }
            // Inside: out through the front line or a side line, whichever is nearer.
            let front = (p.x - if side > 0.0 { lo.x } else { hi.x }).abs();
            let lateral = hi.y - p.y.abs();
            if front <= lateral {
                (-front, Vector2::new(-side, 0.0))
            } else {
                (
                    -lateral,
                    Vector2::new(0.0, if p.y >= 0.0 { 1.0 } else { -1.0 }),
                )
            }
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// `v` (world frame, mm/s) limited so that the body (radius `radius_mm`, centre at `p`,
/// moving at `now`) can always stop `margin_mm` short of a defense area: the speed toward the
/// nearer area is at most `sqrt(2 (a / 2) room)`, where `room` is the distance left to that
/// margin and `a` the body's acceleration limit (half of it, so the body's lag behind its
/// command still stops in time). When the body already comes faster than that, the command
/// keeps its present speed along the area, so that the whole acceleration brakes (the body
/// changes its velocity toward the command along their difference). Within the margin it is
/// pushed out at `3 room` mm/s, and a body already over the area's line leaves it straight
/// out at `v`'s speed (at least 300 mm/s).
pub fn keep_out(
    field: &FieldMap,
    p: Point2<f64>,
    [v, now]: [Vector2<f64>; 2],
    radius_mm: f64,
    margin_mm: f64,
    accel_mm_s2: f64,
) -> Vector2<f64> {
    let Some((distance, out)) = defense_clearance(field, p) else {
        return v;
    };
    if distance < radius_mm {
        return out * v.norm().max(300.0);
    }
    let room = distance - radius_mm - margin_mm;
    let allowed = if room > 0.0 {
        (accel_mm_s2.max(1.0) * room).sqrt()
    } else {
        3.0 * room
    };
    let toward = -v.dot(&out);
    if -now.dot(&out) > allowed {
        // Braking: along the area as it moves now, toward it at no more than allowed.
        let along = now - out * now.dot(&out);
        return along - out * toward.min(allowed);
    }
    if toward > allowed {
        v + out * (toward - allowed)
    } else {
        v
    }
}

/// Whether the body may stand at `p`: clear of the defense areas by `margin_mm` (centre to
/// area) and `wall_mm` in from the field walls, as [`allowed_point`] keeps it.
pub fn may_stand(field: &FieldMap, p: Point2<f64>, margin_mm: f64, wall_mm: f64) -> bool {
    (allowed_point(field, p, margin_mm, wall_mm) - p).norm() < 1.0
}

/// How much nearer a defense area or a wall than a new approach may come the approach under way
/// may, mm.
const HOLD_SLACK_MM: f64 = 40.0;

/// How the robot takes the ball from behind: the direction the ball is to leave in (world
/// frame, unit) and how far from the ball's centre it lines up first, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Approach {
    /// The direction the ball is to leave in.
    pub toward: Vector2<f64>,
    /// Ball centre to the point it lines up at, mm.
    pub standoff_mm: f64,
    /// Room from the body's centre to the defense areas it keeps on the way, mm.
    pub margin_mm: f64,
}

/// The approach closest to `preferred`: `preferred` itself when the robot can stand behind the
/// ball (at `standoff_mm` and at `contact_mm` from its centre, both where [`may_stand`]
/// allows with `margins_mm[0]` from the defense areas), else `preferred` turned by the least
/// multiple of 15 degrees that makes it so (the side whose standing point is nearer `robot`
/// first); where no direction fits (a ball in a corner of the floor and a defense area), the
/// same with the robot lining up nearer the ball, halfway and then 60 mm beyond contact; and
/// where none of those fits either (a ball right by an area's line), the same again keeping
/// only `margins_mm[1]` from the areas; `None` when nothing fits. `previous` is kept while it fits within
/// [`HOLD_SLACK_MM`] and turns at most 20 degrees more than the best. The robot then turns
/// with the ball on its dribbler.
#[allow(clippy::too_many_arguments)]
pub fn approach_direction(
    field: &FieldMap,
    ball: Point2<f64>,
    robot: Point2<f64>,
    preferred: Vector2<f64>,
    previous: Option<Approach>,
    [contact_mm, standoff_mm]: [f64; 2],
    margins_mm: [f64; 2],
    wall_mm: f64,
) -> Option<Approach> {
    let fits_by = |a: &Approach, slack_mm: f64| {
        [contact_mm, a.standoff_mm].iter().all(|&d| {
            may_stand(
                field,
                ball - a.toward * d,
                a.margin_mm - slack_mm,
                wall_mm - slack_mm,
            )
        })
    };
    let fits = |a: &Approach| fits_by(a, 0.0);
    let off = |t: Vector2<f64>| wrap(t.y.atan2(t.x) - preferred.y.atan2(preferred.x)).abs();
    let standoffs = [
        standoff_mm,
        0.5 * (contact_mm + standoff_mm),
        contact_mm + 60.0,
    ];
    let candidates = margins_mm.into_iter().flat_map(|margin_mm| {
        standoffs.into_iter().flat_map(move |standoff_mm| {
            (0..=12).flat_map(move |k| {
                let turn = (k as f64 * 15.0).to_radians();
                let mut pair = [turn, -turn].map(|a| Approach {
                    toward: Rotation2::new(a) * preferred,
                    standoff_mm,
                    margin_mm,
                });
                let nearness = |a: &Approach| (ball - a.toward * a.standoff_mm - robot).norm();
                pair.sort_by(|a, b| nearness(a).total_cmp(&nearness(b)));
                pair
            })
        })
    });
    let best = candidates.into_iter().find(|a| fits(a))?;
    // The ball's estimate moves a little from frame to frame: the approach under way is kept
    // while it fits within HOLD_SLACK_MM, lines up no farther and keeps no more room than the
    // best, and turns little more.
    match previous {
        Some(p)
            if fits_by(&p, HOLD_SLACK_MM)
                && p.standoff_mm <= best.standoff_mm + 1e-9
                && p.margin_mm <= best.margin_mm + 1e-9
                && off(p.toward) <= off(best.toward) + 20f64.to_radians() =>
        {
            Some(p)
        }
        _ => Some(best),
    }
}

/// `p` moved out of the defense areas grown by `margin_mm` and onto the floor `wall_mm` in
/// from the field walls (the run-off is floor).
pub fn allowed_point(
    field: &FieldMap,
    p: Point2<f64>,
    margin_mm: f64,
    wall_mm: f64,
) -> Point2<f64> {
    let [x, y] =
        [field.half_length_mm, field.half_width_mm].map(|h| h + field.run_off_mm - wall_mm);
    let q = Point2::new(p.x.clamp(-x, x), p.y.clamp(-y, y));
    match defense_clearance(field, q) {
        // Out along the way out, to the margin (inside, through the nearest side).
        Some((d, out)) if d < margin_mm => q + out * (margin_mm - d),
        _ => q,
    }
}

/// The point of the goal mouth at `goal` (its centre; mouth along y, `width_mm` wide) to shoot
/// at from `ball`: of candidates across the mouth (two ball radii in from each post), the one
/// whose line from the ball passes farthest from every `obstacles` point more than 300 mm from
/// the ball (nearer ones are the robot's own body and the ball), by 50 mm steps up to 400 mm;
/// of equals, `previous` if it is one, else the one nearest the centre.
pub fn open_aim(
    goal: Point2<f64>,
    width_mm: f64,
    ball: Point2<f64>,
    ball_radius_mm: f64,
    obstacles: &[Point2<f64>],
    previous: Option<Point2<f64>>,
) -> Point2<f64> {
    let half = 0.5 * width_mm - 2.0 * ball_radius_mm;
    let candidates = (0..=8).map(|k| goal + Vector2::new(0.0, -half + half * k as f64 / 4.0));
    let far: Vec<Point2<f64>> = obstacles
        .iter()
        .copied()
        .filter(|o| (*o - ball).norm() > 300.0)
        .collect();
    let clearance = |a: Point2<f64>| {
        let c = far
            .iter()
            .filter(|o| (**o - ball).norm() < (a - ball).norm() + 200.0)
            .map(|o| distance_to_segment(*o, ball, a))
            .fold(f64::INFINITY, f64::min);
        (c.min(400.0) / 50.0).floor()
    };
    let rank = |a: Point2<f64>| {
        let kept = previous.is_some_and(|p| (p - a).norm() < 1.0);
        (clearance(a), kept, -(a - goal).norm())
    };
    candidates
        .map(|a| (a, rank(a)))
        .max_by(|x, y| {
            (x.1.0.total_cmp(&y.1.0))
                .then(x.1.1.cmp(&y.1.1))
                .then(x.1.2.total_cmp(&y.1.2))
        })
        .map_or(goal, |(a, _)| a)
}

/// Where to meet a ball at `ball` rolling at `velocity` (slowing at `decel_mm_s2`), for a robot
/// at `robot` that covers ground at `speed_mm_s` after `react_s`: the first point of the
/// ball's path it reaches before the ball, else where the ball stops.
pub fn intercept_point(
    robot: Point2<f64>,
    ball: Point2<f64>,
    velocity: Vector2<f64>,
    decel_mm_s2: f64,
    speed_mm_s: f64,
    react_s: f64,
) -> Point2<f64> {
    let s = velocity.norm();
    let dir = unit(velocity);
    let stop_s = if decel_mm_s2 > 0.0 {
        s / decel_mm_s2
    } else {
        5.0
    };
    let at = |t: f64| {
        let t = t.min(stop_s);
        ball + dir * (s * t - 0.5 * decel_mm_s2 * t * t)
    };
    (1..=100)
        .map(|k| k as f64 * 0.05)
        .find(|&t| (at(t) - robot).norm() / speed_mm_s + react_s <= t)
        .map_or_else(|| at(stop_s), at)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field() -> FieldMap {
        FieldMap {
            half_length_mm: 2000.0,
            half_width_mm: 1500.0,
            goal_width_mm: 700.0,
            defense_depth_mm: 800.0,
            defense_width_mm: 2000.0,
            run_off_mm: 300.0,
        }
    }

    #[test]
    fn the_path_goes_round_the_ball_when_the_robot_is_in_front_of_it() {
        let ball = Point2::new(0.0, 0.0);
        let toward = Vector2::new(1.0, 0.0);
        // Behind the ball already: straight to the standoff point.
        let p = approach_point(Point2::new(-600.0, 50.0), ball, toward, 250.0, 200.0);
        assert_eq!(p, Point2::new(-250.0, 0.0));
        // In front of it: a point beside the ball, never through it.
        let p = approach_point(Point2::new(600.0, 10.0), ball, toward, 250.0, 200.0);
        assert!((p - ball).norm() >= 199.0, "{p}");
        assert!(p.y > 0.0, "rounds on its own side: {p}");
    }

    #[test]
    fn a_command_into_the_defense_area_slows_to_stop_short_of_it() {
        let f = field();
        let (r, margin, accel) = (90.0, 60.0, 2000.0);
        let still = Vector2::zeros();
        // 200 mm from the front line at x = 1200: 50 mm of room beyond body and margin, so
        // no faster toward it than stops in half that at the body's acceleration.
        let p = Point2::new(1000.0, 0.0);
        let v = keep_out(
            &f,
            p,
            [Vector2::new(1000.0, 300.0), still],
            r,
            margin,
            accel,
        );
        assert!(
            v.x > 0.0 && v.x * v.x / (2.0 * accel) <= 0.5 * 50.0 + 1e-9,
            "{v}"
        );
        assert_eq!(v.y, 300.0, "along the line untouched");
        // Far enough to stop before the line: left alone.
        let far = keep_out(
            &f,
            Point2::origin(),
            [Vector2::new(1000.0, 0.0), still],
            r,
            margin,
            accel,
        );
        assert_eq!(far, Vector2::new(1000.0, 0.0));
        // Already coming too fast: the command keeps the present speed along the line, so the
        // whole acceleration brakes, whatever was asked along it.
        let now = Vector2::new(1000.0, -800.0);
        let b = keep_out(&f, p, [Vector2::new(800.0, 900.0), now], r, margin, accel);
        assert_eq!(b.y, -800.0, "{b}");
        assert!(b.x < 400.0, "{b}");
        // Near a corner the way out is from the corner.
        let c = Point2::new(1100.0, 1120.0);
        let (d, out) = defense_clearance(&f, c).unwrap();
        assert!((d - (100.0f64).hypot(120.0)).abs() < 1e-9 && out.x < 0.0 && out.y > 0.0);
        let over = Point2::new(1150.0, 0.0);
        let inside = keep_out(
            &f,
            over,
            [Vector2::new(500.0, 0.0), still],
            r,
            margin,
            accel,
        );
        assert!(inside.x < 0.0, "the body over the line leaves");
        let q = allowed_point(&f, Point2::new(1900.0, 100.0), 150.0, 100.0);
        assert!(!f.in_defense_area(q, 149.0), "{q}");
    }

    #[test]
    fn a_ball_by_the_defense_area_is_taken_from_the_side_it_can_be_reached_from() {
        let f = field();
        let goal = Vector2::new(1.0, 0.0);
        let robot = Point2::new(0.0, 0.0);
        let dims = [81.5, 356.5];
        // In the open: straight at the goal.
        let open = approach_direction(
            &f,
            Point2::new(0.0, 300.0),
            robot,
            goal,
            None,
            dims,
            [150.0, 105.0],
            90.0,
        )
        .unwrap();
        assert_eq!(open.toward, goal);
        assert_eq!(open.margin_mm, 150.0);
        assert_eq!(open.standoff_mm, dims[1]);
        // 100 mm in front of the -x area: behind it is inside the area, so another side.
        let ball = Point2::new(-1100.0, 300.0);
        let a =
            approach_direction(&f, ball, robot, goal, None, dims, [150.0, 105.0], 90.0).unwrap();
        assert_ne!(a.toward, goal);
        for d in [dims[0], a.standoff_mm] {
            assert!(may_stand(&f, ball - a.toward * d, 150.0, 90.0), "{a:?}");
        }
        assert_eq!(a.margin_mm, 150.0);
        // 60 mm from the line: reached from the field side only, keeping the lesser room.
        let by_line = Point2::new(-1140.0, -513.0);
        let a =
            approach_direction(&f, by_line, robot, goal, None, dims, [150.0, 105.0], 90.0).unwrap();
        assert_eq!(a.margin_mm, 105.0, "{a:?}");
        assert!(a.toward.x < -0.5, "{a:?}");
        for d in [dims[0], a.standoff_mm] {
            assert!(may_stand(&f, by_line - a.toward * d, 105.0, 90.0), "{a:?}");
        }
        // 10 mm from the line: out of reach from outside the area.
        let at_line = Point2::new(-1190.0, 0.0);
        assert!(
            approach_direction(&f, at_line, robot, goal, None, dims, [150.0, 105.0], 90.0)
                .is_none()
        );
        // Behind the goal line by the wall (walls at x = 2300): no room to line up far off.
        let tight = Point2::new(2221.0, 813.0);
        let a =
            approach_direction(&f, tight, robot, goal, None, dims, [150.0, 105.0], 105.0).unwrap();
        assert!(a.standoff_mm < dims[1], "{a:?}");
        for d in [dims[0], a.standoff_mm] {
            assert!(may_stand(&f, tight - a.toward * d, 150.0, 105.0), "{a:?}");
        }
    }

    #[test]
    fn the_aim_avoids_a_defender() {
        let goal = Point2::new(2000.0, 0.0);
        let ball = Point2::new(1000.0, 0.0);
        assert_eq!(open_aim(goal, 700.0, ball, 21.5, &[], None), goal);
        let a = open_aim(goal, 700.0, ball, 21.5, &[Point2::new(1950.0, 80.0)], None);
        assert!(a.y < -150.0, "{a}");
    }

    #[test]
    fn a_rolling_ball_is_met_ahead_of_the_robot() {
        let p = intercept_point(
            Point2::new(0.0, 0.0),
            Point2::new(-3000.0, 300.0),
            Vector2::new(3000.0, 0.0),
            350.0,
            1500.0,
            0.3,
        );
        assert!(
            (p.y - 300.0).abs() < 1e-9 && p.x > -3000.0 && p.x < 500.0,
            "{p}"
        );
    }
}
