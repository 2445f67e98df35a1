//! The world as plain data: floor regions, the RoboCup Small-Size field, walls, cubes and
//! pillars. Scenario files embed these types directly; [`Layout::solids`] turns them into the
//! one list of solid shapes that both the physics world and the renderer use.

use crate::ball::BallSpec;
use crate::color::Rgb;
use crate::corridor::Corridor;
use crate::floor_marks::{FloorMark, MarkScatter};
use crate::floor_rect::FloorRect;
use crate::labels::{Class, ObjectId};
use crate::shapes::{Solid, SolidShape};
use nalgebra::{Point2, Vector2};
use serde::{Deserialize, Serialize};

/// The playing floor of the RoboCup Small-Size field (Fig. 6 of the corner paper, with the
/// project's choices for goals, walls and lines). The field centre is the world origin, its long
/// axis the world x axis; the yellow goal is at +x, the blue goal at -x.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FieldSpec {
    /// A1: half-length of the playing floor, to the goal lines.
    pub half_length_mm: f64,
    /// B: half-width of the playing floor.
    pub half_width_mm: f64,
    /// A2 - A1: how far the floor runs on into each goal.
    pub goal_depth_mm: f64,
    /// Width of the goal mouth.
    pub goal_width_mm: f64,
    /// Height of the goal walls.
    pub goal_wall_height_mm: f64,
    /// Height of the field walls around the floor region.
    pub wall_height_mm: f64,
    /// Thickness of field and goal walls (they stand outside the floor region).
    pub wall_thickness_mm: f64,
    /// Width of the white lines.
    pub line_width_mm: f64,
    /// Radius of the centre circle.
    pub centre_circle_radius_mm: f64,
    /// Colour of the field walls.
    pub wall_rgb: Rgb,
    /// Colour of the goal at +x.
    pub goal_pos_x_rgb: Rgb,
    /// Colour of the goal at -x.
    pub goal_neg_x_rgb: Rgb,
}

impl Default for FieldSpec {
    fn default() -> Self {
        Self {
            half_length_mm: 1370.0,
            half_width_mm: 762.5,
            goal_depth_mm: 180.0,
            goal_width_mm: 500.0,
            goal_wall_height_mm: 160.0,
            wall_height_mm: 100.0,
            wall_thickness_mm: 50.0,
            line_width_mm: 10.0,
            centre_circle_radius_mm: 250.0,
            wall_rgb: Rgb([235, 235, 235]),
            goal_pos_x_rgb: Rgb([235, 200, 20]),
            goal_neg_x_rgb: Rgb([25, 60, 220]),
        }
    }
}

impl FieldSpec {
    /// A2: half-length of the floor region to the goal backs.
    pub fn floor_half_length_mm(&self) -> f64 {
        self.half_length_mm + self.goal_depth_mm
    }

    /// The floor region: the playing rectangle and the two goal pockets.
    pub fn floor_rects(&self) -> [FloorRect; 3] {
        let a1 = self.half_length_mm;
        let gd = self.goal_depth_mm;
        [
            FloorRect {
                center_mm: [0.0, 0.0],
                size_mm: [2.0 * a1, 2.0 * self.half_width_mm],
                angle_deg: 0.0,
            },
            FloorRect {
                center_mm: [a1 + gd / 2.0, 0.0],
                size_mm: [gd, self.goal_width_mm],
                angle_deg: 0.0,
            },
            FloorRect {
                center_mm: [-(a1 + gd / 2.0), 0.0],
                size_mm: [gd, self.goal_width_mm],
                angle_deg: 0.0,
            },
        ]
    }

    /// Field walls and goal walls as wall segments whose inner faces lie on the floor boundary.
    pub fn walls(&self) -> Vec<Wall> {
        self.labelled_walls().into_iter().map(|(w, _)| w).collect()
    }

    /// [`FieldSpec::walls`], each with what it is: a field wall or goal 0 (+x) or 1 (-x).
    pub fn labelled_walls(&self) -> Vec<(Wall, ObjectId)> {
        let a1 = self.half_length_mm;
        let a2 = self.floor_half_length_mm();
        let b = self.half_width_mm;
        let g = self.goal_width_mm / 2.0;
        let t = self.wall_thickness_mm;
        let h = t / 2.0;
        let field = |from: [f64; 2], to: [f64; 2]| Wall {
            from_mm: from,
            to_mm: to,
            thickness_mm: t,
            height_mm: self.wall_height_mm,
            rgb: self.wall_rgb,
        };
        let goal = |from: [f64; 2], to: [f64; 2], rgb: Rgb| Wall {
            from_mm: from,
            to_mm: to,
            thickness_mm: t,
            height_mm: self.goal_wall_height_mm,
            rgb,
        };
        let wall = ObjectId::of(Class::FieldWall);
        let mut walls = vec![
            // Long sides, running over the corners so that no gap is left.
            (field([-a1 - t, b + h], [a1 + t, b + h]), wall),
            (field([-a1 - t, -b - h], [a1 + t, -b - h]), wall),
        ];
        for (k, s) in [1.0, -1.0].into_iter().enumerate() {
            // End walls beside each goal mouth.
            walls.push((field([s * (a1 + h), g], [s * (a1 + h), b]), wall));
            walls.push((field([s * (a1 + h), -g], [s * (a1 + h), -b]), wall));
            let rgb = if s > 0.0 {
                self.goal_pos_x_rgb
            } else {
                self.goal_neg_x_rgb
            };
            // Goal back and sides.
            let id = ObjectId::new(Class::Goal, k as u32);
            walls.push((goal([s * (a2 + h), -g - t], [s * (a2 + h), g + t], rgb), id));
            walls.push((goal([s * a1, g + h], [s * (a2 + t), g + h], rgb), id));
            walls.push((goal([s * a1, -g - h], [s * (a2 + t), -g - h], rgb), id));
        }
        walls
    }

    /// Is `p` on one of the white lines (boundary, centre line, centre circle)?
    pub fn on_line(&self, p: Point2<f64>) -> bool {
        let w = self.line_width_mm;
        let a1 = self.half_length_mm;
        let b = self.half_width_mm;
        let (ax, ay) = (p.x.abs(), p.y.abs());
        if ax > a1 || ay > b {
            return false;
        }
        let boundary = ax >= a1 - w || ay >= b - w;
        let centre_line = ax <= w / 2.0;
        let r = (p.x * p.x + p.y * p.y).sqrt();
        let circle = (r - self.centre_circle_radius_mm).abs() <= w / 2.0;
        boundary || centre_line || circle
    }
}

/// A free-standing wall: a segment with thickness, height and colour.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wall {
    /// One end of the wall's centre line.
    pub from_mm: [f64; 2],
    /// The other end of the wall's centre line.
    pub to_mm: [f64; 2],
    /// Thickness across the centre line.
    #[serde(default = "default_wall_thickness")]
    pub thickness_mm: f64,
    /// Height above the floor.
    #[serde(default = "default_wall_height")]
    pub height_mm: f64,
    /// Colour.
    #[serde(default = "default_wall_rgb")]
    pub rgb: Rgb,
}

fn default_wall_thickness() -> f64 {
    100.0
}
fn default_wall_height() -> f64 {
    150.0
}
fn default_wall_rgb() -> Rgb {
    Rgb([235, 235, 235])
}

/// A cube standing on the floor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cube {
    /// Centre of its footprint.
    pub center_mm: [f64; 2],
    /// Side length.
    #[serde(default = "default_cube_size")]
    pub size_mm: f64,
    /// Rotation about the vertical axis.
    #[serde(default)]
    pub angle_deg: f64,
    /// Colour.
    #[serde(default = "default_cube_rgb")]
    pub rgb: Rgb,
}

fn default_cube_size() -> f64 {
    130.0
}
fn default_cube_rgb() -> Rgb {
    Rgb([40, 40, 40])
}

/// An upright cylinder standing on the floor (a pillar, a post).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pillar {
    /// Centre of its footprint.
    pub center_mm: [f64; 2],
    /// Radius.
    pub radius_mm: f64,
    /// Height above the floor.
    pub height_mm: f64,
    /// Colour.
    pub rgb: Rgb,
}

/// A flat upright board carrying vertical stripes (a landmark), e.g. the marks of the
/// three-mark resection paper: black and white stripes with given width ratios.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Board {
    /// What the board is called (the mark's name, `P`), if anything.
    #[serde(default)]
    pub name: Option<String>,
    /// One end of the board.
    pub from_mm: [f64; 2],
    /// The other end.
    pub to_mm: [f64; 2],
    /// Height of its lower edge above the floor.
    #[serde(default)]
    pub bottom_mm: f64,
    /// Height of its upper edge above the floor.
    pub top_mm: f64,
    /// Thickness.
    #[serde(default = "default_board_thickness")]
    pub thickness_mm: f64,
    /// Relative widths of the stripes from `from_mm` to `to_mm`, alternating `rgb_a`, `rgb_b`.
    pub stripes: Vec<f64>,
    /// Colour of the first, third, ... stripe.
    #[serde(default = "default_board_a")]
    pub rgb_a: Rgb,
    /// Colour of the second, fourth, ... stripe.
    #[serde(default = "default_board_b")]
    pub rgb_b: Rgb,
}

fn default_board_thickness() -> f64 {
    10.0
}
fn default_board_a() -> Rgb {
    Rgb([15, 15, 15])
}
fn default_board_b() -> Rgb {
    Rgb([245, 245, 245])
}

impl Board {
    /// Cumulative stripe boundaries as fractions of the board's length, ending at 1.
    pub fn stripe_edges(&self) -> Vec<f64> {
        let total: f64 = self.stripes.iter().sum();
        let mut acc = 0.0;
        self.stripes
            .iter()
            .map(|w| {
                acc += w;
                acc / total
            })
            .collect()
    }
}

/// The static world: floor, field, walls and obstacles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Layout {
    /// The RoboCup Small-Size field, when present (`[world.field]`).
    pub field: Option<FieldSpec>,
    /// Extra rectangles of floor colour. With neither a field nor rectangles the whole plane is
    /// floor.
    pub floor_rects: Vec<FloorRect>,
    /// Colour of the floor region (field green).
    pub floor_rgb: Rgb,
    /// Colour of the floor outside the floor region.
    pub outside_rgb: Rgb,
    /// Colour of the field's white lines.
    pub line_rgb: Rgb,
    /// Corridors: floor and walls from a centre polyline and a width.
    pub corridors: Vec<Corridor>,
    /// Free-standing walls.
    pub walls: Vec<Wall>,
    /// Cubes.
    pub cubes: Vec<Cube>,
    /// Pillars.
    pub pillars: Vec<Pillar>,
    /// Striped boards (landmarks).
    pub boards: Vec<Board>,
    /// Marks painted on the floor.
    pub floor_marks: Vec<FloorMark>,
    /// Marks scattered at random over a rectangle of the floor.
    pub mark_scatter: Option<MarkScatter>,
    /// The ball (`[world.ball]`), when there is one.
    pub ball: Option<BallSpec>,
}

impl Default for Layout {
    fn default() -> Self {
        Self {
            field: None,
            floor_rects: Vec::new(),
            floor_rgb: Rgb([30, 130, 55]),
            outside_rgb: Rgb([120, 100, 80]),
            line_rgb: Rgb([240, 240, 240]),
            corridors: Vec::new(),
            walls: Vec::new(),
            cubes: Vec::new(),
            pillars: Vec::new(),
            boards: Vec::new(),
            floor_marks: Vec::new(),
            mark_scatter: None,
            ball: None,
        }
    }
}

impl Layout {
    /// Every mark painted on the floor: those given one by one, then the scattered ones.
    pub fn all_floor_marks(&self) -> Vec<FloorMark> {
        let mut marks = self.floor_marks.clone();
        marks.extend(self.mark_scatter.iter().flat_map(MarkScatter::marks));
        marks
    }

    /// Every floor-coloured rectangle: the field's, the corridors' legs and the extra ones.
    pub fn all_floor_rects(&self) -> Vec<FloorRect> {
        let mut rects: Vec<FloorRect> = self.field.iter().flat_map(|f| f.floor_rects()).collect();
        rects.extend(self.corridors.iter().flat_map(|c| c.floor_rects()));
        rects.extend(self.floor_rects.iter().cloned());
        rects
    }

    /// Is the floor at `p` floor-coloured (inside the floor region)?
    pub fn is_floor(&self, p: Point2<f64>) -> bool {
        if self.field.is_none() && self.floor_rects.is_empty() && self.corridors.is_empty() {
            return true;
        }
        self.all_floor_rects().iter().any(|r| r.contains(p))
    }

    /// Every wall, the field's included.
    pub fn all_walls(&self) -> Vec<Wall> {
        let mut walls: Vec<Wall> = self.field.iter().flat_map(|f| f.walls()).collect();
        walls.extend(self.walls.iter().cloned());
        walls
    }

    /// All solid obstacles as boxes, quads (corridor walls) and cylinders, in world
    /// coordinates.
    pub fn solids(&self) -> Vec<Solid> {
        let mut out = crate::corridor::walls(&self.corridors);
        let field_walls = self.field.iter().flat_map(|f| f.labelled_walls());
        let free_walls = (self.walls.iter().cloned()).map(|w| (w, ObjectId::of(Class::Wall)));
        for (w, object) in field_walls.chain(free_walls) {
            let a = Vector2::from(w.from_mm);
            let b = Vector2::from(w.to_mm);
            let d = b - a;
            let len = d.norm();
            let solid = Solid::standing(
                SolidShape::Box {
                    center_mm: Point2::from((a + b) / 2.0),
                    half_extents_mm: Vector2::new(len / 2.0, w.thickness_mm / 2.0),
                    angle_rad: d.y.atan2(d.x),
                },
                w.height_mm,
                w.rgb,
            );
            out.push(solid.as_object(object));
        }
        for (i, c) in self.cubes.iter().enumerate() {
            let cube = Solid::standing(
                SolidShape::Box {
                    center_mm: Point2::from(c.center_mm),
                    half_extents_mm: Vector2::new(c.size_mm / 2.0, c.size_mm / 2.0),
                    angle_rad: c.angle_deg.to_radians(),
                },
                c.size_mm,
                c.rgb,
            );
            out.push(cube.as_object(ObjectId::new(Class::Cube, i as u32)));
        }
        for (i, p) in self.pillars.iter().enumerate() {
            let pillar = Solid::standing(
                SolidShape::Cylinder {
                    center_mm: Point2::from(p.center_mm),
                    radius_mm: p.radius_mm,
                },
                p.height_mm,
                p.rgb,
            );
            out.push(pillar.as_object(ObjectId::new(Class::Pillar, i as u32)));
        }
        for (i, b) in self.boards.iter().enumerate() {
            let a = Vector2::from(b.from_mm);
            let e = Vector2::from(b.to_mm);
            let d = e - a;
            out.push(Solid {
                shape: SolidShape::Box {
                    center_mm: Point2::from((a + e) / 2.0),
                    half_extents_mm: Vector2::new(d.norm() / 2.0, b.thickness_mm / 2.0),
                    angle_rad: d.y.atan2(d.x),
                },
                base_mm: b.bottom_mm,
                height_mm: b.top_mm,
                rgb: b.rgb_a,
                top_rgb: None,
                board: Some(i),
                object: ObjectId::new(Class::Board, i as u32),
            });
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_floor_region_includes_goal_pockets_only_within_the_mouth() {
        let layout = Layout {
            field: Some(FieldSpec::default()),
            ..Layout::default()
        };
        assert!(layout.is_floor(Point2::new(0.0, 0.0)));
        assert!(layout.is_floor(Point2::new(1500.0, 200.0)));
        assert!(!layout.is_floor(Point2::new(1500.0, 300.0)));
        assert!(!layout.is_floor(Point2::new(1600.0, 0.0)));
        assert!(!layout.is_floor(Point2::new(0.0, 770.0)));
    }

    #[test]
    fn field_walls_enclose_the_floor_region() {
        let f = FieldSpec::default();
        let layout = Layout {
            field: Some(f.clone()),
            ..Layout::default()
        };
        let solids = layout.solids();
        // Points just outside the floor boundary are inside some wall; just inside are not.
        let outside = [
            Point2::new(0.0, 762.5 + 1.0),
            Point2::new(1370.0 + 1.0, 600.0),
            Point2::new(1550.0 + 1.0, 0.0),
            Point2::new(1450.0, 250.0 + 1.0),
            Point2::new(-1550.0 - 1.0, 100.0),
        ];
        for p in outside {
            assert!(
                solids.iter().any(|s| s.shape.distance_mm(p) <= 0.0),
                "{p} not in a wall"
            );
        }
        let inside = [
            Point2::new(0.0, 762.5 - 1.0),
            Point2::new(1549.0, 0.0),
            Point2::new(1369.0, 700.0),
        ];
        for p in inside {
            assert!(
                solids.iter().all(|s| s.shape.distance_mm(p) > 0.0),
                "{p} in a wall"
            );
        }
    }

    #[test]
    fn lines_are_ten_mm_wide() {
        let f = FieldSpec::default();
        assert!(f.on_line(Point2::new(0.0, 100.0)));
        assert!(f.on_line(Point2::new(4.9, 100.0)));
        assert!(!f.on_line(Point2::new(5.1, 100.0)));
        assert!(f.on_line(Point2::new(250.0, 0.0)));
        assert!(f.on_line(Point2::new(600.0, 755.0)));
        assert!(!f.on_line(Point2::new(600.0, 700.0)));
        assert!(!f.on_line(Point2::new(1400.0, 0.0)));
    }
}
