//! The RoboCup Small-Size field (`[world.field]`): its floor region (the playing rectangle and
//! the goal pockets), its walls and goals, its white lines (painted by the renderer from its
//! figures).

use crate::floor_rect::FloorRect;
use super::wall::Wall;
use super::kind::{FieldLines, Kind, MapFeature, Surroundings};
use crate::color::Rgb;
use crate::labels::{Class, ObjectId};
use crate::shapes::Solid;
use nalgebra::Point2;
use omniloop_problem::Problems;
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

impl Kind for FieldSpec {
    fn check(&self, _: &[Self], _: &dyn Surroundings, c: &mut Problems) {
        for (name, v) in [
            ("half_length_mm", self.half_length_mm),
            ("half_width_mm", self.half_width_mm),
            ("goal_depth_mm", self.goal_depth_mm),
            ("goal_width_mm", self.goal_width_mm),
            ("goal_wall_height_mm", self.goal_wall_height_mm),
            ("wall_height_mm", self.wall_height_mm),
            ("wall_thickness_mm", self.wall_thickness_mm),
            ("line_width_mm", self.line_width_mm),
            ("centre_circle_radius_mm", self.centre_circle_radius_mm),
        ] {
            c.positive(name, v);
        }
        if self.goal_width_mm >= 2.0 * self.half_width_mm {
            c.fail(
                "goal_width_mm",
                "must be narrower than the field (2 * half_width_mm)",
            );
        }
    }

    fn solids(&self, _index: u32, out: &mut Vec<Solid>) {
        out.extend(
            self.labelled_walls()
                .into_iter()
                .map(|(w, object)| w.solid().as_object(object)),
        );
    }

    fn floor_rects(&self, out: &mut Vec<FloorRect>) {
        out.extend(self.floor_rects());
    }

    fn field_lines(&self, out: &mut Vec<FieldLines>) {
        out.push(FieldLines {
            half_length_mm: self.half_length_mm,
            half_width_mm: self.half_width_mm,
            line_width_mm: self.line_width_mm,
            centre_circle_radius_mm: self.centre_circle_radius_mm,
        });
    }

    fn map(&self, out: &mut Vec<MapFeature>) {
        out.extend(self.walls().iter().map(|w| MapFeature::Bound {
            from_mm: Point2::from(w.from_mm),
            to_mm: Point2::from(w.to_mm),
            half_thickness_mm: 0.5 * w.thickness_mm,
        }));
    }
}
