//! Corridors: a centre polyline and a width give a floor (the union of one rectangle a leg,
//! each extended by half the width past its ends) and walls along the whole outline of that
//! floor.
//!
//! The outline is the polygon union of the legs (`i_overlay`), each contour with the floor on
//! its left. Every outline edge gets one wall piece: its inner face is the edge itself, its
//! outer face the edge moved out by the wall thickness. Where the floor has a reflex corner (an
//! inner tip between two legs, acute or not) the two pieces are mitred along the bisector of the
//! outside wedge, so neither face crosses into the floor however sharp the tip; at convex corners
//! they are mitred too while the mitre stays short, else each piece runs on squarely past the
//! corner by the thickness (the outside of a convex corner is never floor).

use crate::color::Rgb;
use crate::floor_rect::FloorRect;
use super::kind::{Kind, MapFeature, Surroundings};
use crate::shapes::{Solid, SolidShape};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::single::SingleFloatOverlay;
use nalgebra::{Point2, Vector2};
use omniloop_problem::Problems;
use serde::{Deserialize, Serialize};

/// A corridor (`[[world.corridors]]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Corridor {
    /// The centre polyline, at least two points.
    pub points_mm: Vec<[f64; 2]>,
    /// Width of the floor between the walls.
    pub width_mm: f64,
    /// Thickness of the walls.
    #[serde(default = "default_thickness")]
    pub wall_thickness_mm: f64,
    /// Height of the walls.
    #[serde(default = "default_height")]
    pub wall_height_mm: f64,
    /// Colour of the walls.
    #[serde(default = "default_rgb")]
    pub wall_rgb: Rgb,
}

fn default_thickness() -> f64 {
    100.0
}
fn default_height() -> f64 {
    150.0
}
fn default_rgb() -> Rgb {
    Rgb([235, 235, 235])
}

/// A mitre longer than this many thicknesses at a convex corner is replaced by a square end.
const MAX_CONVEX_MITRE: f64 = 2.0;

impl Corridor {
    /// One floor rectangle a leg: the leg's segment, extended by half the width at both ends.
    pub fn floor_rects(&self) -> Vec<FloorRect> {
        self.points_mm
            .windows(2)
            .map(|w| {
                let (a, b) = (Vector2::from(w[0]), Vector2::from(w[1]));
                let d = b - a;
                let c = (a + b) / 2.0;
                FloorRect {
                    center_mm: [c.x, c.y],
                    size_mm: [d.norm() + self.width_mm, self.width_mm],
                    angle_deg: d.y.atan2(d.x).to_degrees(),
                }
            })
            .collect()
    }
}

/// The corners of a floor rectangle, counter-clockwise.
fn rect_corners(r: &FloorRect) -> Vec<[f64; 2]> {
    let (s, c) = r.angle_deg.to_radians().sin_cos();
    let (hx, hy) = (r.size_mm[0] / 2.0, r.size_mm[1] / 2.0);
    [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)]
        .iter()
        .map(|&(x, y)| {
            [
                r.center_mm[0] + c * x - s * y,
                r.center_mm[1] + s * x + c * y,
            ]
        })
        .collect()
}

impl Kind for Corridor {
    fn check(&self, _: &[Self], _: &dyn Surroundings, c: &mut Problems) {
        c.positive("width_mm", self.width_mm);
        c.positive("wall_thickness_mm", self.wall_thickness_mm);
        c.positive("wall_height_mm", self.wall_height_mm);
        if self.points_mm.len() < 2 {
            c.fail(
                "points_mm",
                format!("needs at least two points (got {})", self.points_mm.len()),
            );
        }
        for (k, pair) in self.points_mm.windows(2).enumerate() {
            let len = (pair[1][0] - pair[0][0]).hypot(pair[1][1] - pair[0][1]);
            if !(len.is_finite() && len > 0.0) {
                c.fail(
                    format!("points_mm[{}]", k + 1),
                    "must differ from the point before it",
                );
            }
        }
    }

    /// The corridors' walls run along the outline of all their floors together.
    fn solids_of_all(all: &[Self], out: &mut Vec<Solid>) {
        out.extend(walls(all));
    }

    fn floor_rects(&self, out: &mut Vec<FloorRect>) {
        out.extend(Corridor::floor_rects(self));
    }

    /// The floor's boundary: the walls' inner faces, the outline of all the corridors' floor.
    fn map_of_all(all: &[Self], out: &mut Vec<MapFeature>) {
        for contour in outline(all) {
            let n = contour.len();
            out.extend((0..n).map(|k| MapFeature::Bound {
                from_mm: contour[k],
                to_mm: contour[(k + 1) % n],
                half_thickness_mm: 0.0,
            }));
        }
    }
}

/// The outline of the union of the corridors' floors: closed contours, each with the floor on
/// its left, with the corridor whose wall look each contour takes (the first corridor's leg
/// nearest to the contour's first edge).
pub fn outline(corridors: &[Corridor]) -> Vec<Vec<Point2<f64>>> {
    let rects: Vec<FloorRect> = corridors.iter().flat_map(|c| c.floor_rects()).collect();
    let legs: Vec<Vec<[f64; 2]>> = rects.iter().map(rect_corners).collect();
    if legs.is_empty() {
        return Vec::new();
    }
    let none: Vec<Vec<[f64; 2]>> = Vec::new();
    let shapes = legs.overlay(&none, OverlayRule::Subject, FillRule::NonZero);
    let on_floor = |p: Point2<f64>| rects.iter().any(|r| r.contains(p));
    shapes
        .into_iter()
        .flatten()
        .map(|contour| {
            let mut c: Vec<Point2<f64>> = contour.iter().map(|p| Point2::new(p[0], p[1])).collect();
            // The floor goes on the left: look just left of the middle of the longest edge.
            let longest = (0..c.len())
                .max_by(|&i, &j| {
                    let len = |k: usize| (c[(k + 1) % c.len()] - c[k]).norm();
                    len(i).total_cmp(&len(j))
                })
                .unwrap_or(0);
            let d = direction(&c, longest);
            let mid = c[longest] + (c[(longest + 1) % c.len()] - c[longest]) / 2.0;
            if !on_floor(mid - outward(d)) {
                c.reverse();
            }
            c
        })
        .collect()
}

/// The wall pieces along the outline of the corridors' floor.
pub fn walls(corridors: &[Corridor]) -> Vec<Solid> {
    let Some(look) = corridors.first() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for contour in outline(corridors) {
        for corners in contour_pieces(&contour, look.wall_thickness_mm) {
            out.push(Solid::standing(
                SolidShape::Quad {
                    corners_mm: corners,
                },
                look.wall_height_mm,
                look.wall_rgb,
            ));
        }
    }
    out
}

/// Unit direction of edge `i` of a closed contour.
fn direction(c: &[Point2<f64>], i: usize) -> Vector2<f64> {
    (c[(i + 1) % c.len()] - c[i]).normalize()
}

/// Outward normal (right of the direction, away from the floor).
fn outward(d: Vector2<f64>) -> Vector2<f64> {
    Vector2::new(d.y, -d.x)
}

/// The outer corner of the piece along edge `i` at its end vertex (`at_end`) or its start, and
/// the inner corner there (moved past the vertex when the end is square).
fn piece_end(c: &[Point2<f64>], i: usize, at_end: bool, t: f64) -> (Point2<f64>, Point2<f64>) {
    let n = c.len();
    let d = direction(c, i);
    // The edge on the other side of this end's vertex.
    let (v, other) = if at_end {
        (c[(i + 1) % n], direction(c, (i + 1) % n))
    } else {
        (c[i], direction(c, (i + n - 1) % n))
    };
    let (n_i, n_o) = (outward(d), outward(other));
    let turn = if at_end {
        d.perp(&other)
    } else {
        other.perp(&d)
    };
    let reflex = turn < 0.0;
    let cos = n_i.dot(&n_o);
    // The offset lines of the two edges meet at v + t (n_i + n_o) / (1 + cos).
    let mitre_len = t * (2.0 / (1.0 + cos)).sqrt();
    if reflex || mitre_len <= MAX_CONVEX_MITRE * t {
        (v, v + (n_i + n_o) * (t / (1.0 + cos)))
    } else {
        let past = if at_end { d * t } else { -d * t };
        (v + past, v + past + n_i * t)
    }
}

/// The corners (counter-clockwise) of the wall piece of every edge of a contour.
fn contour_pieces(c: &[Point2<f64>], t: f64) -> Vec<[Point2<f64>; 4]> {
    (0..c.len())
        .map(|i| {
            let d = direction(c, i);
            let (a_in, a_out) = piece_end(c, i, false, t);
            let (b_in, b_out) = piece_end(c, i, true, t);
            if (b_out - a_out).dot(&d) >= 0.0 {
                [b_in, a_in, a_out, b_out]
            } else {
                // The two mitres cross before the outer face: a triangle up to where they meet.
                let apex = crossing(a_in, a_out, b_in, b_out).unwrap_or(a_out);
                [b_in, a_in, apex, apex]
            }
        })
        .collect()
}

/// Where the line through `p0`, `p1` meets the line through `q0`, `q1`.
fn crossing(
    p0: Point2<f64>,
    p1: Point2<f64>,
    q0: Point2<f64>,
    q1: Point2<f64>,
) -> Option<Point2<f64>> {
    let (r, s) = (p1 - p0, q1 - q0);
    let den = r.perp(&s);
    (den.abs() > 1e-12).then(|| p0 + r * ((q0 - p0).perp(&s) / den))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::Layout;

    /// The corner of the corner paper's E1: 800 mm wide, legs at 55 degrees.
    fn corner(angle_deg: f64, width: f64) -> Corridor {
        let a = (180.0 - angle_deg).to_radians();
        Corridor {
            points_mm: vec![
                [-2500.0, 0.0],
                [0.0, 0.0],
                [2000.0 * a.cos(), 2000.0 * a.sin()],
            ],
            width_mm: width,
            wall_thickness_mm: 100.0,
            wall_height_mm: 150.0,
            wall_rgb: default_rgb(),
        }
    }

    /// Samples every outline edge every 10 mm and checks that the point 1 mm outside (where it
    /// is not floor: near a reflex corner it can be the other leg's) lies in a wall, and that
    /// the floor point 1 mm inside lies in none.
    fn enclosed_without_intrusion(c: &Corridor) {
        let layout = Layout {
            corridors: vec![c.clone()],
            ..Layout::default()
        };
        let solids = layout.solids();
        for contour in outline(std::slice::from_ref(c)) {
            for i in 0..contour.len() {
                let a = contour[i];
                let b = contour[(i + 1) % contour.len()];
                let d = (b - a).normalize();
                let n = outward(d);
                let len = (b - a).norm();
                let mut s = 0.5;
                while s < len {
                    let p = a + d * s;
                    let (out, inside) = (p + n, p - n);
                    assert!(layout.is_floor(inside), "{inside}");
                    assert!(
                        layout.is_floor(out)
                            || solids.iter().any(|w| w.shape.distance_mm(out) <= 0.0),
                        "{out} outside the floor is in no wall"
                    );
                    assert!(
                        solids.iter().all(|w| w.shape.distance_mm(inside) > 0.0),
                        "{inside} on the floor is inside a wall"
                    );
                    s += 10.0;
                }
            }
        }
    }

    #[test]
    fn walls_enclose_every_corner_without_a_face_in_the_floor() {
        for angle in [35.0, 55.0, 90.0, 120.0, 135.0] {
            for width in [600.0, 800.0, 1000.0] {
                enclosed_without_intrusion(&corner(angle, width));
            }
        }
    }

    #[test]
    fn the_e1_corner_has_its_inner_tip_866_mm_from_k_on_the_bisector() {
        let outline = outline(&[corner(55.0, 800.0)]);
        assert_eq!(outline.len(), 1);
        // The tip is a reflex vertex of the outline (the floor's union has six, where the legs'
        // sides cross), on the bisector of the legs, where the legs' inner sides meet.
        let c = &outline[0];
        let bisector = (180.0f64 - 55.0 / 2.0).to_radians();
        let tips: Vec<Point2<f64>> = (0..c.len())
            .filter(|&i| direction(c, (i + c.len() - 1) % c.len()).perp(&direction(c, i)) < 0.0)
            .map(|i| c[i])
            .collect();
        assert_eq!(tips.len(), 6, "{tips:?}");
        let tip = tips
            .iter()
            .find(|t| (t.y.atan2(t.x) - bisector).abs() < 1e-6)
            .expect("a tip on the bisector");
        assert!((tip.y - 400.0).abs() < 1e-3, "{tip}");
        assert!((tip.coords.norm() - 866.0).abs() < 1.0, "{tip}");
    }
}
