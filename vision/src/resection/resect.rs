//! Resection from three marks (Sect. 3.1): the angles `alpha = PXQ` and `beta = QXO` under
//! which the robot at X sees the marks fix two circles, through P, Q, X and through O, Q, X;
//! X is where they cross besides Q.
//!
//! Eqs. (1)-(3) give each circle's radius `r = PQ / (2 sin alpha)` (sine theorem) and put its
//! centre on the chord's perpendicular bisector at that distance from Q, which leaves two
//! centres, one each side of the chord: the paper's angles are unsigned, `0 <= alpha < pi`.
//! We measure them signed (counter-clockwise, from the bearings) and then the inscribed-angle
//! theorem names the centre directly: the chord subtends `2 alpha` at it, so
//! `Q - C = R(2 alpha) (P - C)`, i.e. `C = (I - R(2 alpha))^-1 (Q - R(2 alpha) P)`, which is
//! eqs. (1)-(2) with the root chosen. The second crossing of two circles through Q is the
//! mirror image of Q in the line of their centres. The paper puts O at the origin and Q on the
//! y axis; nothing here needs it.
//!
//! Beyond the paper: the heading, from the bearings once the position is known (the circular
//! mean over the marks of the world direction to each less its bearing in the robot frame).

use crate::VisionError;
use nalgebra::{Matrix2, Point2, Rotation2, Vector2};

/// A mark of known position and the bearing under which the robot sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarkBearing {
    /// Where the mark stands, world frame, mm.
    pub position: Point2<f64>,
    /// Its bearing in the robot frame, rad (counter-clockwise from the robot's x axis).
    pub bearing_rad: f64,
}

/// Where the robot is and which way it faces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resection {
    /// Position, world frame, mm.
    pub position: Point2<f64>,
    /// Heading, world frame, rad.
    pub heading_rad: f64,
}

/// The centres of the two circles nearer than this fraction of their radii: the robot stands
/// (nearly) on the circle through the three marks, where the angles do not fix it.
const DEGENERATE: f64 = 1e-3;

/// The centre of the circle through `a`, `b` and every point seeing the chord from `a` to `b`
/// under the signed angle `angle_rad` (Eqs. (1)-(2), the root chosen by the sign).
pub fn circle_centre(
    a: Point2<f64>,
    b: Point2<f64>,
    angle_rad: f64,
) -> Result<Point2<f64>, VisionError> {
    if angle_rad.sin().abs() < 1e-9 {
        return Err(VisionError::NotFound(format!(
            "the robot is in line with two marks (angle {:.4} deg): no circle",
            angle_rad.to_degrees()
        )));
    }
    let r = Rotation2::new(2.0 * angle_rad).into_inner();
    let m = Matrix2::identity() - r;
    let c = m
        .try_inverse()
        .map(|inv| inv * (b.coords - r * a.coords))
        .ok_or_else(|| VisionError::NotFound("singular circle".into()))?;
    Ok(Point2::from(c))
}

/// The robot's position and heading from three marks seen under the given bearings: circles
/// through `first`, `shared` and through `shared`, `last` (the paper's P, Q, O).
pub fn resect(
    first: &MarkBearing,
    shared: &MarkBearing,
    last: &MarkBearing,
) -> Result<Resection, VisionError> {
    let alpha = shared.bearing_rad - first.bearing_rad;
    let beta = last.bearing_rad - shared.bearing_rad;
    let c1 = circle_centre(first.position, shared.position, alpha)?;
    let c2 = circle_centre(shared.position, last.position, beta)?;
    let (r1, r2) = ((c1 - shared.position).norm(), (c2 - shared.position).norm());
    let d = c2 - c1;
    if d.norm() < DEGENERATE * 0.5 * (r1 + r2) {
        return Err(VisionError::NotFound(format!(
            "the robot stands on the circle through the three marks (centres {:.1} mm apart, \
             radii {r1:.0} and {r2:.0} mm): the angles do not fix its position",
            d.norm()
        )));
    }
    let u = d / d.norm();
    let q = shared.position;
    let foot = c1 + u * (q - c1).dot(&u);
    let position = Point2::from(2.0 * foot.coords - q.coords);
    let heading_rad = heading(&position, &[*first, *shared, *last]);
    Ok(Resection {
        position,
        heading_rad,
    })
}

/// The heading from the bearings of marks seen from `position`: the circular mean of each mark's
/// world direction less its bearing.
pub fn heading(position: &Point2<f64>, marks: &[MarkBearing]) -> f64 {
    let sum: Vector2<f64> = marks
        .iter()
        .map(|m| {
            let v = m.position - position;
            let a = v.y.atan2(v.x) - m.bearing_rad;
            Vector2::new(a.cos(), a.sin())
        })
        .sum();
    sum.y.atan2(sum.x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The marks of the paper, mm: P(373, 303), Q(0, 333), O(0, 0) cm.
    fn marks() -> [Point2<f64>; 3] {
        [
            Point2::new(3730.0, 3030.0),
            Point2::new(0.0, 3330.0),
            Point2::new(0.0, 0.0),
        ]
    }

    fn seen_from(x: Point2<f64>, heading: f64) -> [MarkBearing; 3] {
        marks().map(|m| {
            let v = m - x;
            MarkBearing {
                position: m,
                bearing_rad: v.y.atan2(v.x) - heading,
            }
        })
    }

    #[test]
    fn exact_angles_give_the_position_and_heading() {
        let places = [
            (910.0, 610.0),
            (1640.0, 2450.0),
            (3400.0, 610.0),
            (2560.0, 1380.0),
            (-500.0, 4000.0),
            (5000.0, -1000.0),
        ];
        for (i, &(x, y)) in places.iter().enumerate() {
            let truth = Point2::new(x, y);
            let h = -2.0 + 0.7 * i as f64;
            let [p, q, o] = seen_from(truth, h);
            let r = resect(&p, &q, &o).unwrap();
            assert!(
                (r.position - truth).norm() < 1e-6,
                "{truth}: {}",
                r.position
            );
            let dh = (r.heading_rad - h + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            assert!(dh.abs() < 1e-9, "{truth}: heading off by {dh}");
        }
    }

    #[test]
    fn a_robot_on_the_circle_through_the_marks_has_no_solution() {
        let [p, q, o] = marks();
        // Circumcentre of P, Q, O.
        let centre = {
            let (a, b, c) = (p.coords, q.coords, o.coords);
            let d = 2.0 * (a.x * (b.y - c.y) + b.x * (c.y - a.y) + c.x * (a.y - b.y));
            let s = |v: Vector2<f64>| v.norm_squared();
            Point2::new(
                (s(a) * (b.y - c.y) + s(b) * (c.y - a.y) + s(c) * (a.y - b.y)) / d,
                (s(a) * (c.x - b.x) + s(b) * (a.x - c.x) + s(c) * (b.x - a.x)) / d,
            )
        };
        let radius = (p - centre).norm();
        for angle in [0.3f64, 2.0, 4.0] {
            let x = centre + radius * Vector2::new(angle.cos(), angle.sin());
            let [bp, bq, bo] = seen_from(x, 0.4);
            let err = resect(&bp, &bq, &bo).unwrap_err();
            assert!(
                err.to_string().contains("circle through the three marks"),
                "{err}"
            );
        }
    }

    #[test]
    fn the_error_grows_smoothly_with_the_bearing_error() {
        let truth = Point2::new(2560.0, 1380.0);
        let [mut p, q, o] = seen_from(truth, 0.0);
        let mut last = 0.0;
        for k in 1..=5 {
            p.bearing_rad = seen_from(truth, 0.0)[0].bearing_rad + (0.02 * k as f64).to_radians();
            let e = (resect(&p, &q, &o).unwrap().position - truth).norm();
            assert!(e > last && e < 10.0 * k as f64, "{k}: {e} mm");
            last = e;
        }
    }
}
