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

/// The outward normal of the nearest side of the defense area (grown by `margin_mm`) that
/// `p` is inside of or within `margin_mm` of; `None` when clear of both.
pub fn defense_normal(field: &FieldMap, p: Point2<f64>, margin_mm: f64) -> Option<Vector2<f64>> {
    if !field.in_defense_area(p, margin_mm) {
        return None;
    }
    let front = field.half_length_mm - field.defense_depth_mm - margin_mm;
    let side = 0.5 * field.defense_width_mm + margin_mm;
    let to_front = p.x.abs() - front;
    let to_side = side - p.y.abs();
    Some(if to_front < to_side {
        Vector2::new(-p.x.signum(), 0.0)
    } else {
        Vector2::new(0.0, p.y.signum())
    })
}

/// `v` (world frame) with any part that would take the body (radius `radius_mm`, centre at
/// `p`) within `margin_mm` of a defense area removed, looking as far ahead as the robot needs to
/// stop at `accel_mm_s2`; a body already over the area's line leaves it straight out at `v`'s
/// speed.
pub fn keep_out(
    field: &FieldMap,
    p: Point2<f64>,
    v: Vector2<f64>,
    radius_mm: f64,
    margin_mm: f64,
    accel_mm_s2: f64,
) -> Vector2<f64> {
    if let Some(n) =
        defense_normal(field, p, radius_mm).filter(|_| field.in_defense_area(p, radius_mm))
    {
        return n * v.norm().max(300.0);
    }
    let speed = v.norm();
    let ahead = p + v * (speed / (2.0 * accel_mm_s2.max(1.0)) + 0.1);
    let grown = radius_mm + margin_mm;
    let normal = defense_normal(field, p, grown).or_else(|| defense_normal(field, ahead, grown));
    match normal {
        Some(n) if v.dot(&n) < 0.0 => v - n * v.dot(&n),
        _ => v,
    }
}

/// `p` moved out of the defense areas grown by `margin_mm` and into the playing area less
/// `wall_mm`.
pub fn allowed_point(
    field: &FieldMap,
    p: Point2<f64>,
    margin_mm: f64,
    wall_mm: f64,
) -> Point2<f64> {
    let mut q = Point2::new(
        p.x.clamp(
            -field.half_length_mm + wall_mm,
            field.half_length_mm - wall_mm,
        ),
        p.y.clamp(
            -field.half_width_mm + wall_mm,
            field.half_width_mm - wall_mm,
        ),
    );
    if let Some(n) = defense_normal(field, q, margin_mm) {
        let front = field.half_length_mm - field.defense_depth_mm - margin_mm;
        let side = 0.5 * field.defense_width_mm + margin_mm;
        if n.x != 0.0 {
            q.x = q.x.signum() * front;
        } else {
            q.y = q.y.signum() * side;
        }
    }
    q
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
    fn a_command_into_the_defense_area_slides_along_it() {
        let f = field();
        let p = Point2::new(1000.0, 0.0);
        let v = keep_out(&f, p, Vector2::new(1000.0, 0.0), 90.0, 60.0, 2000.0);
        assert!(v.x <= 1e-9, "{v}");
        // Far enough to stop before the line: left alone.
        let far = keep_out(
            &f,
            Point2::origin(),
            Vector2::new(1000.0, 0.0),
            90.0,
            60.0,
            2000.0,
        );
        assert_eq!(far, Vector2::new(1000.0, 0.0));
        let over = Point2::new(1150.0, 0.0);
        let inside = keep_out(&f, over, Vector2::new(500.0, 0.0), 90.0, 60.0, 2000.0);
        assert!(inside.x < 0.0, "the body over the line leaves");
        let q = allowed_point(&f, Point2::new(1900.0, 100.0), 150.0, 100.0);
        assert!(!f.in_defense_area(q, 149.0), "{q}");
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
