//! Solid obstacles in the plane (boxes, upright cylinders and convex quadrilaterals with a
//! height), with the exact 2-D distance and ray-cast queries used for clearance and free-space
//! ground truth.

use crate::color::Rgb;
use crate::labels::{Class, ObjectId};
use nalgebra::{Point2, Vector2};

/// The footprint of a solid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SolidShape {
    /// An oriented rectangle.
    Box {
        /// Centre.
        center_mm: Point2<f64>,
        /// Half side lengths along the box's own axes.
        half_extents_mm: Vector2<f64>,
        /// Rotation of the box's x axis from the world x axis.
        angle_rad: f64,
    },
    /// A disc.
    Cylinder {
        /// Centre.
        center_mm: Point2<f64>,
        /// Radius.
        radius_mm: f64,
    },
    /// A convex quadrilateral, corners counter-clockwise (a triangle repeats a corner): the
    /// mitred pieces of corridor walls.
    Quad {
        /// Corners.
        corners_mm: [Point2<f64>; 4],
    },
}

/// The edges of a convex polygon as (start, unit direction, length), zero-length ones left out.
fn edges(
    corners: &[Point2<f64>; 4],
) -> impl Iterator<Item = (Point2<f64>, Vector2<f64>, f64)> + '_ {
    (0..4).filter_map(move |i| {
        let a = corners[i];
        let e = corners[(i + 1) % 4] - a;
        let len = e.norm();
        (len > 1e-9).then(|| (a, e / len, len))
    })
}

/// Signed distance from `p` to a convex polygon (negative inside).
fn polygon_distance(corners: &[Point2<f64>; 4], p: Point2<f64>) -> f64 {
    // Outward normal of a counter-clockwise edge with direction u: (u.y, -u.x).
    let mut inside = f64::NEG_INFINITY;
    let mut outside = f64::INFINITY;
    for (a, u, len) in edges(corners) {
        let ap = p - a;
        inside = inside.max(ap.x * u.y - ap.y * u.x);
        let along = ap.dot(&u).clamp(0.0, len);
        outside = outside.min((ap - u * along).norm());
    }
    if inside <= 0.0 { inside } else { outside }
}

/// Entry distance of a ray into a convex polygon (Cyrus-Beck), for an origin outside.
fn polygon_ray(corners: &[Point2<f64>; 4], o: Point2<f64>, dir: Vector2<f64>) -> Option<f64> {
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for (a, u, _) in edges(corners) {
        let n = Vector2::new(u.y, -u.x);
        let num = (o - a).dot(&n);
        let den = dir.dot(&n);
        if den.abs() < 1e-15 {
            if num > 0.0 {
                return None;
            }
            continue;
        }
        let t = -num / den;
        if den < 0.0 {
            t0 = t0.max(t);
        } else {
            t1 = t1.min(t);
        }
    }
    (t0 <= t1 && t1 >= 0.0).then_some(t0.max(0.0))
}

/// A solid standing on the floor: footprint, vertical extent and colour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solid {
    /// Footprint.
    pub shape: SolidShape,
    /// Height of its bottom above the floor (0 for everything but raised boards).
    pub base_mm: f64,
    /// Height of its top above the floor.
    pub height_mm: f64,
    /// Colour.
    pub rgb: Rgb,
    /// Colour of its top face when it differs (a robot's team marking).
    pub top_rgb: Option<Rgb>,
    /// Index of the stripe board in [`crate::Layout::boards`] it carries, if any.
    pub board: Option<usize>,
    /// What it is, for the per-pixel labels.
    pub object: ObjectId,
}

impl Solid {
    /// A solid standing on the floor, plain-coloured: a wall until [`Solid::as_object`] says
    /// otherwise.
    pub fn standing(shape: SolidShape, height_mm: f64, rgb: Rgb) -> Self {
        Self {
            shape,
            base_mm: 0.0,
            height_mm,
            rgb,
            top_rgb: None,
            board: None,
            object: ObjectId::of(Class::Wall),
        }
    }

    /// The same solid as `object`.
    pub fn as_object(mut self, object: ObjectId) -> Self {
        self.object = object;
        self
    }

    /// The same solid with its top face painted `top_rgb` (a robot's marking).
    pub fn with_top(mut self, top_rgb: Option<Rgb>) -> Self {
        self.top_rgb = top_rgb;
        self
    }
}

/// Rotates a world vector into the frame of a box turned by `angle_rad`.
fn to_box_frame(angle_rad: f64, v: Vector2<f64>) -> Vector2<f64> {
    let (s, c) = angle_rad.sin_cos();
    Vector2::new(c * v.x + s * v.y, -s * v.x + c * v.y)
}

impl SolidShape {
    /// Signed distance from `p` to the footprint's boundary (negative inside).
    pub fn distance_mm(&self, p: Point2<f64>) -> f64 {
        match *self {
            SolidShape::Box {
                center_mm,
                half_extents_mm,
                angle_rad,
            } => {
                let q = to_box_frame(angle_rad, p - center_mm).abs() - half_extents_mm;
                let outside = Vector2::new(q.x.max(0.0), q.y.max(0.0)).norm();
                outside + q.x.max(q.y).min(0.0)
            }
            SolidShape::Cylinder {
                center_mm,
                radius_mm,
            } => (p - center_mm).norm() - radius_mm,
            SolidShape::Quad { corners_mm } => polygon_distance(&corners_mm, p),
        }
    }

    /// A circle that holds the footprint: its centre and radius (mm). The signed distance
    /// from a point `p` to the footprint is at least `|p - centre| - radius`.
    pub fn bounding_circle(&self) -> (Point2<f64>, f64) {
        match *self {
            SolidShape::Box {
                center_mm,
                half_extents_mm,
                ..
            } => (center_mm, half_extents_mm.norm()),
            SolidShape::Cylinder {
                center_mm,
                radius_mm,
            } => (center_mm, radius_mm),
            SolidShape::Quad { corners_mm } => {
                let sum = corners_mm
                    .iter()
                    .fold(Vector2::zeros(), |s, c| s + c.coords);
                let centre = Point2::from(sum / 4.0);
                let radius = corners_mm
                    .iter()
                    .map(|c| (c - centre).norm())
                    .fold(0.0, f64::max);
                (centre, radius)
            }
        }
    }

    /// Whether a ray from `origin` along the unit direction `dir` may meet the footprint
    /// within `max_mm`, judged by its bounding circle `bounds` ([`Self::bounding_circle`],
    /// widened by a micrometre for rounding): false only where [`Self::ray_cast_mm`] finds
    /// nothing.
    pub fn ray_may_meet(
        bounds: (Point2<f64>, f64),
        origin: Point2<f64>,
        dir: Vector2<f64>,
        max_mm: f64,
    ) -> bool {
        let (centre, radius) = (bounds.0, bounds.1 + 1e-3);
        let m = origin - centre;
        let c = m.norm_squared() - radius * radius;
        if c <= 0.0 {
            return true;
        }
        let b = m.dot(&dir);
        let disc = b * b - c;
        b < 0.0 && disc >= 0.0 && -b - disc.sqrt() <= max_mm + 1e-3
    }

    /// Distance along the unit direction `dir` from `origin` to the first point of the
    /// footprint, if it is hit within `max_mm`. An origin inside the footprint gives 0.
    pub fn ray_cast_mm(&self, origin: Point2<f64>, dir: Vector2<f64>, max_mm: f64) -> Option<f64> {
        if self.distance_mm(origin) <= 0.0 {
            return Some(0.0);
        }
        let t = match *self {
            SolidShape::Box {
                center_mm,
                half_extents_mm,
                angle_rad,
            } => {
                let o = to_box_frame(angle_rad, origin - center_mm);
                let v = to_box_frame(angle_rad, dir);
                let h = [half_extents_mm.x, half_extents_mm.y];
                let mut t0 = f64::NEG_INFINITY;
                let mut t1 = f64::INFINITY;
                for k in 0..2 {
                    if v[k].abs() < 1e-15 {
                        if o[k].abs() > h[k] {
                            return None;
                        }
                    } else {
                        let a = (-h[k] - o[k]) / v[k];
                        let b = (h[k] - o[k]) / v[k];
                        t0 = t0.max(a.min(b));
                        t1 = t1.min(a.max(b));
                    }
                }
                if t0 > t1 || t1 < 0.0 {
                    return None;
                }
                t0.max(0.0)
            }
            SolidShape::Cylinder {
                center_mm,
                radius_mm,
            } => {
                let m = origin - center_mm;
                let b = m.dot(&dir);
                let c = m.norm_squared() - radius_mm * radius_mm;
                let disc = b * b - c;
                if disc < 0.0 {
                    return None;
                }
                let t = -b - disc.sqrt();
                if t < 0.0 {
                    return None;
                }
                t
            }
            SolidShape::Quad { corners_mm } => polygon_ray(&corners_mm, origin, dir)?,
        };
        (t <= max_mm).then_some(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box() -> SolidShape {
        SolidShape::Box {
            center_mm: Point2::new(100.0, 0.0),
            half_extents_mm: Vector2::new(10.0, 20.0),
            angle_rad: std::f64::consts::FRAC_PI_2,
        }
    }

    #[test]
    fn no_point_or_ray_meets_a_footprint_nearer_than_its_bounding_circle_allows() {
        let shapes = [
            unit_box(),
            SolidShape::Cylinder {
                center_mm: Point2::new(-40.0, 25.0),
                radius_mm: 35.0,
            },
            SolidShape::Quad {
                corners_mm: [
                    Point2::new(0.0, 0.0),
                    Point2::new(90.0, -30.0),
                    Point2::new(60.0, 40.0),
                    Point2::new(60.0, 40.0),
                ],
            },
        ];
        let (mut inside, mut tight, mut spared, mut hits) = (0, 0, 0, 0);
        for shape in &shapes {
            let (centre, radius) = shape.bounding_circle();
            for k in 0..4000 {
                // A spiral of points in and around every footprint.
                let a = k as f64 * 2.399_963;
                let rho = 0.06 * k as f64;
                let p = Point2::new(20.0 + rho * a.cos(), rho * a.sin());
                let d = shape.distance_mm(p);
                let bound = (p - centre).norm() - radius;
                assert!(d >= bound - 1e-9, "{shape:?} at {p}: {d} < {bound}");
                // Rays from the point: none meets the footprint where the circle says none can.
                for j in 0..8 {
                    let a = j as f64 * std::f64::consts::FRAC_PI_4 + 0.1;
                    let dir = Vector2::new(a.cos(), a.sin());
                    let max = 20.0 + (k % 7) as f64 * 15.0;
                    let may = SolidShape::ray_may_meet((centre, radius), p, dir, max);
                    let hit = shape.ray_cast_mm(p, dir, max);
                    assert!(
                        may || hit.is_none(),
                        "{shape:?} from {p} along {dir}: {hit:?}"
                    );
                    spared += usize::from(!may);
                    hits += usize::from(hit.is_some());
                }
                inside += usize::from(d < 0.0);
                tight += usize::from(d - bound < 5.0);
            }
        }
        assert!(
            inside > 100 && tight > 100,
            "inside {inside}, tight {tight}"
        );
        assert!(spared > 1000 && hits > 1000, "spared {spared}, hits {hits}");
    }

    #[test]
    fn box_distance_is_signed_and_respects_rotation() {
        let b = unit_box();
        // Rotated by 90 degrees: extends 20 along world x, 10 along world y.
        assert!((b.distance_mm(Point2::new(50.0, 0.0)) - 30.0).abs() < 1e-9);
        assert!((b.distance_mm(Point2::new(100.0, 30.0)) - 20.0).abs() < 1e-9);
        assert!((b.distance_mm(Point2::new(100.0, 0.0)) + 10.0).abs() < 1e-9);
        let corner = b.distance_mm(Point2::new(123.0, 14.0));
        assert!((corner - 5.0).abs() < 1e-9);
    }

    #[test]
    fn quads_measure_distance_and_take_rays_like_a_box_of_the_same_shape() {
        // The unit box above as a quad: 20 along x, 10 along y around (100, 0).
        let q = SolidShape::Quad {
            corners_mm: [
                Point2::new(80.0, -10.0),
                Point2::new(120.0, -10.0),
                Point2::new(120.0, 10.0),
                Point2::new(80.0, 10.0),
            ],
        };
        let b = unit_box();
        for p in [
            (50.0, 0.0),
            (100.0, 30.0),
            (100.0, 0.0),
            (123.0, 14.0),
            (85.0, 7.0),
        ] {
            let p = Point2::new(p.0, p.1);
            assert!((q.distance_mm(p) - b.distance_mm(p)).abs() < 1e-9, "{p}");
        }
        for dir in [(1.0, 0.0), (0.0, 1.0), (0.8, 0.6), (0.9, -0.1)] {
            let d = Vector2::new(dir.0, dir.1).normalize();
            let (a, c) = (
                q.ray_cast_mm(Point2::origin(), d, 1e4),
                b.ray_cast_mm(Point2::origin(), d, 1e4),
            );
            assert_eq!(a.is_some(), c.is_some(), "{d}");
            if let (Some(a), Some(c)) = (a, c) {
                assert!((a - c).abs() < 1e-9, "{d}: {a} vs {c}");
            }
        }
        // A triangle (a repeated corner).
        let t = SolidShape::Quad {
            corners_mm: [
                Point2::new(0.0, 0.0),
                Point2::new(100.0, 0.0),
                Point2::new(0.0, 100.0),
                Point2::new(0.0, 100.0),
            ],
        };
        assert!((t.distance_mm(Point2::new(100.0, 100.0)) - 50.0 * 2f64.sqrt()).abs() < 1e-9);
        assert!((t.distance_mm(Point2::new(10.0, 20.0)) + 10.0).abs() < 1e-9);
        let hit = t.ray_cast_mm(
            Point2::new(100.0, 100.0),
            Vector2::new(-1.0, -1.0).normalize(),
            1e3,
        );
        assert!((hit.unwrap() - 50.0 * 2f64.sqrt()).abs() < 1e-9);
    }

    #[test]
    fn ray_casts_hit_the_near_face() {
        let b = unit_box();
        let t = b
            .ray_cast_mm(Point2::origin(), Vector2::new(1.0, 0.0), 1e4)
            .unwrap();
        assert!((t - 80.0).abs() < 1e-9);
        assert!(
            b.ray_cast_mm(Point2::origin(), Vector2::new(0.0, 1.0), 1e4)
                .is_none()
        );
        assert!(
            b.ray_cast_mm(Point2::origin(), Vector2::new(1.0, 0.0), 50.0)
                .is_none()
        );
        let c = SolidShape::Cylinder {
            center_mm: Point2::new(0.0, 200.0),
            radius_mm: 50.0,
        };
        let t = c
            .ray_cast_mm(Point2::origin(), Vector2::new(0.0, 1.0), 1e4)
            .unwrap();
        assert!((t - 150.0).abs() < 1e-9);
        assert!(
            c.ray_cast_mm(Point2::origin(), Vector2::new(0.0, -1.0), 1e4)
                .is_none()
        );
    }
}
