//! The RoboCup Small-Size field (`[world.field]`): a preset of the league's fields or the
//! corner paper's, its floor region (the playing rectangle and the goal pockets, or the
//! playing rectangle grown by its run-off), its walls and goals, its white lines (painted by the
//! renderer from its figures, told to the robot in its map).

use super::kind::{FieldLines, Kind, MapFeature, Surroundings};
use super::wall::Wall;
use crate::color::Rgb;
use crate::floor_rect::FloorRect;
use crate::labels::{Class, ObjectId};
use crate::shapes::Solid;
use nalgebra::Point2;
use omniloop_problem::Problems;
use omniloop_vision::FieldModel;
use serde::{Deserialize, Serialize};

/// Depth of the goal pockets in [`FieldSpec::floor_outline`] of a field with a run-off, mm:
/// vision's model needs pockets (A2 > A1), the floor region has none.
pub const RUN_OFF_POCKET_MM: f64 = 1.0;

/// The field a `[world.field]` table starts from; every other key of the table overrides the
/// preset's value. Figures in mm (the league's rules give them; where they are silent, the
/// project's choice, see `docs/field.md`):
///
/// | preset | playing area | goal width x depth | defense area depth x width | circle | run-off |
/// |---|---|---|---|---|---|
/// | `corner_paper` | 2740 x 1525 | 500 x 180 | none | radius 250 | 0 |
/// | `division_b` | 9000 x 6000 | 1000 x 180 | 1000 x 2000 | radius 500 | 300 |
/// | `division_a` | 12000 x 9000 | 1800 x 180 | 1800 x 3600 | radius 500 | 300 |
/// | `hardware_challenge` | 4000 x 3000 | 700 x 180 | 800 x 2000 | radius 500 | 300 |
///
/// All have 10 mm lines, 160 mm goal walls, 100 mm field walls 50 mm thick.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FieldPreset {
    /// The small field of the corner paper (Fig. 6): walls on the outer lines, goal pockets
    /// behind the goal lines, no defense areas.
    #[default]
    CornerPaper,
    /// Division B of the Small-Size League: 9 m x 6 m.
    DivisionB,
    /// Division A: 12 m x 9 m.
    DivisionA,
    /// The remote field of the vision-blackout technical challenge: 4 m x 3 m.
    HardwareChallenge,
}

impl FieldPreset {
    /// Every preset, in the order the docs list them.
    pub const ALL: [FieldPreset; 4] = [
        Self::CornerPaper,
        Self::DivisionB,
        Self::DivisionA,
        Self::HardwareChallenge,
    ];

    /// Its name in scenario files (`preset = "division_b"`).
    pub fn name(self) -> &'static str {
        match self {
            Self::CornerPaper => "corner_paper",
            Self::DivisionB => "division_b",
            Self::DivisionA => "division_a",
            Self::HardwareChallenge => "hardware_challenge",
        }
    }

    /// The field's figures (see the table of [`FieldPreset`]).
    pub fn spec(self) -> FieldSpec {
        // Playing area half length and width, goal width, defense area depth and width.
        let (a1, b, goal, defense) = match self {
            Self::CornerPaper => return FieldSpec::default(),
            Self::DivisionB => (4500.0, 3000.0, 1000.0, [1000.0, 2000.0]),
            Self::DivisionA => (6000.0, 4500.0, 1800.0, [1800.0, 3600.0]),
            Self::HardwareChallenge => (2000.0, 1500.0, 700.0, [800.0, 2000.0]),
        };
        FieldSpec {
            half_length_mm: a1,
            half_width_mm: b,
            goal_width_mm: goal,
            centre_circle_radius_mm: 500.0,
            boundary_width_mm: 300.0,
            defense_area_depth_mm: defense[0],
            defense_area_width_mm: defense[1],
            ..FieldSpec::default()
        }
    }
}

impl From<FieldPreset> for FieldSpec {
    fn from(preset: FieldPreset) -> Self {
        preset.spec()
    }
}

impl std::fmt::Display for FieldPreset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The playing floor of the RoboCup Small-Size field (Fig. 6 of the corner paper, with the
/// project's choices for goals, walls and lines; or a field of today's rules, see
/// [`FieldPreset`]). The field centre is the world origin, its long axis the world x axis; the
/// yellow goal is at +x, the blue goal at -x.
///
/// Scenario files give it as `[world.field]`: a `preset` (default `corner_paper`) and any of
/// these figures, which override the preset's. It is written back as every figure and no
/// preset, which reads back as the same field.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "FieldInput")]
pub struct FieldSpec {
    /// A1: half-length of the playing area, to the goal lines.
    pub half_length_mm: f64,
    /// B: half-width of the playing area.
    pub half_width_mm: f64,
    /// A2 - A1: how far each goal reaches behind its goal line (inner face of its back).
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
    /// Width of the run-off between the outer lines and the field walls: 0 puts the walls on
    /// the lines with the goals as pockets of the floor behind the goal lines (the corner
    /// paper's field); more grows the floor region by it on every side, the walls standing at
    /// its edge and each goal a free-standing box behind its goal line (then it must be at least
    /// `goal_depth_mm + wall_thickness_mm`).
    pub boundary_width_mm: f64,
    /// Depth of each defense area from its goal line (0: no defense areas).
    pub defense_area_depth_mm: f64,
    /// Width of each defense area, centred on the goal (0: none).
    pub defense_area_width_mm: f64,
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
            boundary_width_mm: 0.0,
            defense_area_depth_mm: 0.0,
            defense_area_width_mm: 0.0,
            wall_rgb: Rgb([235, 235, 235]),
            goal_pos_x_rgb: Rgb([235, 200, 20]),
            goal_neg_x_rgb: Rgb([25, 60, 220]),
        }
    }
}

/// `[world.field]` as written: a preset and the figures that override the preset's.
macro_rules! field_input {
    ($($name:ident: $ty:ty,)*) => {
        /// `[world.field]` as written: a preset and the figures that override its own.
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields)]
        struct FieldInput {
            /// The field the figures start from.
            #[serde(default)]
            preset: FieldPreset,
            $($name: Option<$ty>,)*
        }

        impl From<FieldInput> for FieldSpec {
            fn from(input: FieldInput) -> Self {
                let mut spec = input.preset.spec();
                $(if let Some(v) = input.$name {
                    spec.$name = v;
                })*
                spec
            }
        }
    };
}

field_input! {
    half_length_mm: f64,
    half_width_mm: f64,
    goal_depth_mm: f64,
    goal_width_mm: f64,
    goal_wall_height_mm: f64,
    wall_height_mm: f64,
    wall_thickness_mm: f64,
    line_width_mm: f64,
    centre_circle_radius_mm: f64,
    boundary_width_mm: f64,
    defense_area_depth_mm: f64,
    defense_area_width_mm: f64,
    wall_rgb: Rgb,
    goal_pos_x_rgb: Rgb,
    goal_neg_x_rgb: Rgb,
}

impl FieldSpec {
    /// A2: field centre to the inner face of each goal's back (A1 + goal depth).
    pub fn goal_back_mm(&self) -> f64 {
        self.half_length_mm + self.goal_depth_mm
    }

    /// Half the floor region's extent along x and y: to the field walls' inner faces (A1 and
    /// B grown by the run-off), and along x at least to the goal backs (the pockets of a field
    /// with no run-off).
    pub fn floor_half_extent_mm(&self) -> [f64; 2] {
        let bw = self.boundary_width_mm;
        [
            (self.half_length_mm + bw).max(self.goal_back_mm()),
            self.half_width_mm + bw,
        ]
    }

    /// Whether the field has a run-off: walls beyond the outer lines, free-standing goals.
    pub fn has_run_off(&self) -> bool {
        self.boundary_width_mm > 0.0
    }

    /// The floor region: with no run-off, the playing rectangle and the two goal pockets; with
    /// one, the playing rectangle grown by it (the goals stand on that floor).
    pub fn floor_rects(&self) -> Vec<FloorRect> {
        let a1 = self.half_length_mm;
        let gd = self.goal_depth_mm;
        if self.has_run_off() {
            let [x, y] = self.floor_half_extent_mm();
            return vec![FloorRect {
                center_mm: [0.0, 0.0],
                size_mm: [2.0 * x, 2.0 * y],
                angle_deg: 0.0,
            }];
        }
        vec![
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

    /// Field walls and goal walls as wall segments whose inner faces lie on the floor boundary
    /// (a free-standing goal's inner faces on its own floor).
    pub fn walls(&self) -> Vec<Wall> {
        self.labelled_walls().into_iter().map(|(w, _)| w).collect()
    }

    /// [`FieldSpec::walls`], each with what it is: a field wall or goal 0 (+x) or 1 (-x). The
    /// field walls' inner faces stand at x = +-(A1 + run-off) and y = +-(B + run-off); with no
    /// run-off the end walls leave the goal mouths open. Each goal is a back at A2 and two
    /// sides from the goal line, their inner faces on the mouth's edges.
    pub fn labelled_walls(&self) -> Vec<(Wall, ObjectId)> {
        let a1 = self.half_length_mm;
        let a2 = self.goal_back_mm();
        let (fx, fy) = (
            a1 + self.boundary_width_mm,
            self.half_width_mm + self.boundary_width_mm,
        );
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
            (field([-fx - t, fy + h], [fx + t, fy + h]), wall),
            (field([-fx - t, -fy - h], [fx + t, -fy - h]), wall),
        ];
        for (k, s) in [1.0, -1.0].into_iter().enumerate() {
            if self.has_run_off() {
                // One end wall behind the goal.
                walls.push((field([s * (fx + h), -fy], [s * (fx + h), fy]), wall));
            } else {
                // End walls beside each goal mouth.
                walls.push((field([s * (fx + h), g], [s * (fx + h), fy]), wall));
                walls.push((field([s * (fx + h), -g], [s * (fx + h), -fy]), wall));
            }
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

    /// The figures of the lines painted on the field.
    pub fn lines(&self) -> FieldLines {
        FieldLines {
            half_length_mm: self.half_length_mm,
            half_width_mm: self.half_width_mm,
            line_width_mm: self.line_width_mm,
            centre_circle_radius_mm: self.centre_circle_radius_mm,
            defense_area_depth_mm: self.defense_area_depth_mm,
            defense_area_width_mm: self.defense_area_width_mm,
        }
    }

    /// Is `p` on one of the white lines (boundary, halfway line, centre circle, defense
    /// areas)? See [`FieldLines::on_line`].
    pub fn on_line(&self, p: Point2<f64>) -> bool {
        self.lines().on_line(p)
    }

    /// The floor region's outline as vision's self-localization models it (the figures to
    /// write in `[vision.localization.field]`). With no run-off: A1, A2, B, half the goal
    /// mouth and the line width (the floor colour ends at the painted outer lines; the corner
    /// paper's field gives vision's defaults). With a run-off the floor region is a rectangle
    /// to the walls, A1 + run-off by B + run-off with no line along its edge; vision's model
    /// has goal pockets, so they are made [`RUN_OFF_POCKET_MM`] deep, and the free-standing
    /// goals it does not model (see `docs/field.md`).
    pub fn floor_outline(&self) -> FieldModel {
        let goal_half_width_mm = 0.5 * self.goal_width_mm;
        if !self.has_run_off() {
            return FieldModel {
                a1_mm: self.half_length_mm,
                a2_mm: self.goal_back_mm(),
                b_mm: self.half_width_mm,
                goal_half_width_mm,
                boundary_line_mm: self.line_width_mm,
            };
        }
        let [x, y] = self.floor_half_extent_mm();
        FieldModel {
            a1_mm: x,
            a2_mm: x + RUN_OFF_POCKET_MM,
            b_mm: y,
            goal_half_width_mm,
            boundary_line_mm: 0.0,
        }
    }

    /// The problems of the run-off and defense-area figures, each naming its field.
    fn check_areas(&self, c: &mut Problems) {
        let figures = [
            ("boundary_width_mm", self.boundary_width_mm),
            ("defense_area_depth_mm", self.defense_area_depth_mm),
            ("defense_area_width_mm", self.defense_area_width_mm),
        ];
        for (name, v) in figures {
            c.non_negative(name, v);
        }
        if figures.iter().any(|(_, v)| !(v.is_finite() && *v >= 0.0)) {
            return;
        }
        let goal_box = self.goal_depth_mm + self.wall_thickness_mm;
        if self.has_run_off() && self.boundary_width_mm < goal_box {
            c.fail(
                "boundary_width_mm",
                format!(
                    "must be 0 (walls on the lines) or at least goal_depth_mm + \
                     wall_thickness_mm = {goal_box} (the goals stand in the run-off; got {})",
                    self.boundary_width_mm
                ),
            );
        }
        let (d, w) = (self.defense_area_depth_mm, self.defense_area_width_mm);
        if (d > 0.0) != (w > 0.0) {
            let (key, other) = if d > 0.0 {
                ("defense_area_width_mm", "defense_area_depth_mm")
            } else {
                ("defense_area_depth_mm", "defense_area_width_mm")
            };
            c.fail(
                key,
                format!("must be > 0 with {other} > 0 (0 for both: none)"),
            );
        }
        if w > 0.0 && w >= 2.0 * self.half_width_mm {
            c.fail(
                "defense_area_width_mm",
                format!(
                    "must be narrower than the field (2 * half_width_mm = {})",
                    2.0 * self.half_width_mm
                ),
            );
        }
        if d > 0.0 && d >= self.half_length_mm {
            c.fail(
                "defense_area_depth_mm",
                format!("must be less than half_length_mm = {}", self.half_length_mm),
            );
        }
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
        self.check_areas(c);
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
        out.push(self.lines());
    }

    fn map(&self, out: &mut Vec<MapFeature>) {
        out.extend(self.walls().iter().map(|w| MapFeature::Bound {
            from_mm: Point2::from(w.from_mm),
            to_mm: Point2::from(w.to_mm),
            half_thickness_mm: 0.5 * w.thickness_mm,
        }));
        out.push(MapFeature::Lines(self.lines()));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::Layout;
    use crate::render::Scene;
    use crate::render::trace::{FloorPaint, floor_paint};

    fn layout(field: FieldSpec) -> Layout {
        Layout {
            field: Some(field),
            ..Layout::default()
        }
    }

    /// The fields of the check's problems, in order.
    fn problems(field: FieldSpec) -> Vec<String> {
        layout(field)
            .check()
            .iter()
            .map(|p| p.field.to_string())
            .collect()
    }

    #[test]
    fn the_presets_give_the_rules_figures() {
        // Half length, half width, goal width, defense depth and width, circle, run-off.
        let want = [
            (
                FieldPreset::CornerPaper,
                [1370.0, 762.5, 500.0, 0.0, 0.0, 250.0, 0.0],
            ),
            (
                FieldPreset::DivisionB,
                [4500.0, 3000.0, 1000.0, 1000.0, 2000.0, 500.0, 300.0],
            ),
            (
                FieldPreset::DivisionA,
                [6000.0, 4500.0, 1800.0, 1800.0, 3600.0, 500.0, 300.0],
            ),
            (
                FieldPreset::HardwareChallenge,
                [2000.0, 1500.0, 700.0, 800.0, 2000.0, 500.0, 300.0],
            ),
        ];
        for (preset, figures) in want {
            let f = preset.spec();
            let got = [
                f.half_length_mm,
                f.half_width_mm,
                f.goal_width_mm,
                f.defense_area_depth_mm,
                f.defense_area_width_mm,
                f.centre_circle_radius_mm,
                f.boundary_width_mm,
            ];
            assert_eq!(got, figures, "{preset}");
            assert_eq!(
                (f.goal_depth_mm, f.line_width_mm),
                (180.0, 10.0),
                "{preset}"
            );
            assert_eq!(f.goal_wall_height_mm, 160.0, "{preset}");
            assert_eq!(f.wall_height_mm, 100.0, "{preset}");
            assert!(problems(f).is_empty(), "{preset}");
        }
        assert_eq!(FieldPreset::default().spec(), FieldSpec::default());
        assert_eq!(FieldPreset::ALL.len(), 4);
    }

    #[test]
    fn the_corner_papers_outline_is_visions_default_model() {
        assert_eq!(FieldSpec::default().floor_outline(), FieldModel::default());
        let b = FieldPreset::DivisionB.spec().floor_outline();
        assert_eq!([b.a1_mm, b.b_mm, b.boundary_line_mm], [4800.0, 3300.0, 0.0]);
        assert_eq!(b.a2_mm, 4800.0 + RUN_OFF_POCKET_MM);
    }

    #[test]
    fn a_run_off_is_one_floor_rectangle_and_no_run_off_keeps_the_pockets() {
        let rects = FieldSpec::default().floor_rects();
        assert_eq!(rects.len(), 3);
        assert_eq!(rects[1].center_mm, [1460.0, 0.0]);
        assert_eq!(rects[1].size_mm, [180.0, 500.0]);
        let b = FieldPreset::DivisionB.spec().floor_rects();
        assert_eq!(b.len(), 1);
        assert_eq!(b[0].size_mm, [9600.0, 6600.0]);
        assert_eq!(b[0].center_mm, [0.0, 0.0]);
    }

    #[test]
    fn bad_figures_name_their_field() {
        let b = FieldPreset::DivisionB.spec();
        let cases = [
            (
                FieldSpec {
                    boundary_width_mm: 200.0,
                    ..b.clone()
                },
                "world.field.boundary_width_mm",
            ),
            (
                FieldSpec {
                    boundary_width_mm: -1.0,
                    ..b.clone()
                },
                "world.field.boundary_width_mm",
            ),
            (
                FieldSpec {
                    defense_area_width_mm: 6000.0,
                    ..b.clone()
                },
                "world.field.defense_area_width_mm",
            ),
            (
                FieldSpec {
                    defense_area_depth_mm: 4500.0,
                    ..b.clone()
                },
                "world.field.defense_area_depth_mm",
            ),
            (
                FieldSpec {
                    defense_area_depth_mm: f64::NAN,
                    ..b.clone()
                },
                "world.field.defense_area_depth_mm",
            ),
            (
                FieldSpec {
                    defense_area_width_mm: 0.0,
                    ..b.clone()
                },
                "world.field.defense_area_width_mm",
            ),
        ];
        for (field, name) in cases {
            let got = problems(field);
            assert_eq!(got, vec![name.to_string()], "{name}");
        }
        // The goal box just fits: goal depth + wall thickness.
        let fits = FieldSpec {
            boundary_width_mm: 230.0,
            ..b
        };
        assert!(problems(fits).is_empty());
    }

    #[test]
    fn defense_lines_lie_inside_the_areas() {
        let f = FieldPreset::DivisionB.spec();
        // Front line |x| in [3500, 3510] for |y| <= 1000; sides |y| in [990, 1000].
        for (x, y, on) in [
            (3500.0, 0.0, true),
            (3509.0, 500.0, true),
            (-3505.0, -999.0, true),
            (3511.0, 500.0, false),
            (3499.0, 500.0, false),
            (4000.0, 995.0, true),
            (-4400.0, -990.0, true),
            (4000.0, 989.0, false),
            (4000.0, 1001.0, false),
            (3400.0, 995.0, false),
            (4000.0, 0.0, false),
        ] {
            assert_eq!(f.on_line(Point2::new(x, y)), on, "({x}, {y})");
        }
        // The corner paper's field has none.
        assert!(!FieldSpec::default().on_line(Point2::new(1000.0, 0.0)));
        assert!(!FieldSpec::default().lines().has_defense_areas());
    }

    #[test]
    fn the_renderer_paints_a_line_where_on_line_says() {
        // Every 7.3 mm over a quarter of each preset's floor (no point within rounding of an
        // edge), the scalar tracer's paint against the field's own test.
        for preset in FieldPreset::ALL {
            let f = preset.spec();
            let scene = Scene::new(&layout(f.clone()), &[]);
            let [hx, hy] = f.floor_half_extent_mm();
            let (mut lines, mut n) = (0, 0);
            let mut x = 0.05;
            while x < hx {
                let mut y = 0.05;
                while y < hy {
                    let p = Point2::new(x, y);
                    let paint = floor_paint(&scene, x as f32, y as f32);
                    assert_eq!(paint == FloorPaint::Line, f.on_line(p), "{preset} at {p}");
                    lines += usize::from(paint == FloorPaint::Line);
                    n += 1;
                    y += 7.3;
                }
                x += 7.3;
            }
            assert!(lines > n / 500, "{preset}: {lines} of {n}");
        }
    }
}
