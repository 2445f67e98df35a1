//! What a kind of thing on the floor is to the systems: the [`Kind`] trait and what its
//! methods give (map features, painted lines, stripes).

use crate::color::Rgb;
use crate::floor_marks::FloorMark;
use crate::floor_rect::FloorRect;
use crate::shapes::Solid;
use nalgebra::Point2;
use omniloop_problem::Problems;

/// What the map a robot is told holds of a thing on the floor (its world's map: the robot
/// knows its world's plan, never where the moving things are).
#[derive(Debug, Clone, PartialEq)]
pub enum MapFeature {
    /// A landmark known by its colour (a pillar).
    Landmark {
        /// Centre of its footprint.
        centre_mm: Point2<f64>,
        /// Radius.
        radius_mm: f64,
        /// Colour.
        rgb: Rgb,
    },
    /// A straight obstacle that stays where it is (a wall, a board).
    Segment {
        /// One end of its centre line.
        from_mm: Point2<f64>,
        /// The other end.
        to_mm: Point2<f64>,
        /// Half its thickness.
        half_thickness_mm: f64,
    },
    /// A piece of the floor's boundary (a field wall, a corridor's inner face).
    Bound {
        /// One end of its centre line.
        from_mm: Point2<f64>,
        /// The other end.
        to_mm: Point2<f64>,
        /// Half its thickness (0 for a face).
        half_thickness_mm: f64,
    },
    /// An edge of a box that may be moved (a cube).
    BoxEdge {
        /// One end.
        from_mm: Point2<f64>,
        /// The other end.
        to_mm: Point2<f64>,
    },
    /// A named striped mark (a board with a name).
    Mark {
        /// Its name.
        name: String,
        /// Centre of the board.
        centre_mm: Point2<f64>,
        /// Relative stripe widths.
        stripes: Vec<f64>,
    },
    /// The lines painted on a Small-Size field: its outer lines, the halfway line, the centre
    /// circle and the defense areas.
    Lines(FieldLines),
}

/// Lines painted on the floor region after the Small-Size field's markings (its outer lines,
/// the halfway line, the centre circle and the defense areas), which the renderers and the top
/// view paint from these figures. Each line lies inside what it bounds: the outer lines inside
/// the playing area, a defense area's lines inside the area.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldLines {
    /// Half-length of the playing area: its goal lines' outer edges at x = +-A1.
    pub half_length_mm: f64,
    /// Half-width of the playing area: its touchlines' outer edges at y = +-B.
    pub half_width_mm: f64,
    /// Width of each line.
    pub line_width_mm: f64,
    /// Radius of the centre circle (the line's middle).
    pub centre_circle_radius_mm: f64,
    /// Depth of each defense area from its goal line (0: no defense areas).
    pub defense_area_depth_mm: f64,
    /// Width of each defense area, centred on the goal (0: none).
    pub defense_area_width_mm: f64,
}

impl FieldLines {
    /// Whether the field has defense areas.
    pub fn has_defense_areas(&self) -> bool {
        self.defense_area_depth_mm > 0.0 && self.defense_area_width_mm > 0.0
    }

    /// Is `p` on one of the lines? With A1, B, w the half length, half width and line width,
    /// W and D a defense area's width and depth: the outer lines are `|x| in [A1 - w, A1]` or
    /// `|y| in [B - w, B]` within the playing area, the halfway line `|x| <= w / 2`, the centre
    /// circle `|r - radius| <= w / 2`; a defense area's lines are `|y| in [W/2 - w, W/2]` for
    /// `|x| in [A1 - D, A1]` and `|x| in [A1 - D, A1 - D + w]` for `|y| <= W/2`.
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
        let [front, front_in, side, side_in] = self.defense_edges_mm();
        let defense = ax >= front && ay <= side && (ax <= front_in || ay >= side_in);
        boundary || centre_line || circle || defense
    }

    /// The edges of the defense areas' lines: `|x|` of the front line's outer and inner edges
    /// (A1 - D, A1 - D + w), `|y|` of the side lines' outer and inner edges (W/2, W/2 - w). With
    /// no defense areas the sides' edges are -1, which no `|y|` reaches.
    pub fn defense_edges_mm(&self) -> [f64; 4] {
        if !self.has_defense_areas() {
            return [0.0, 0.0, -1.0, -1.0];
        }
        let w = self.line_width_mm;
        let front = self.half_length_mm - self.defense_area_depth_mm;
        let side = 0.5 * self.defense_area_width_mm;
        [front, front + w, side, side - w]
    }
}

/// The vertical stripes on a striped solid (a board), from one end to the other.
#[derive(Debug, Clone, PartialEq)]
pub struct Stripes {
    /// Cumulative stripe boundaries as fractions of the length, ending at 1.
    pub edges: Vec<f64>,
    /// Colour of the first, third, ... stripe.
    pub rgb_a: Rgb,
    /// Colour of the second, fourth, ... stripe.
    pub rgb_b: Rgb,
}

/// What an entry's check may ask of the world around it.
pub trait Surroundings {
    /// Is the floor at `p` floor-coloured (inside the floor region)?
    fn is_floor(&self, p: Point2<f64>) -> bool;

    /// Every solid thing on the floor.
    fn solids(&self) -> Vec<Solid>;
}

/// A kind of thing on the floor, as the systems see it. Every method has a default that adds
/// nothing, so that a kind says only what it is.
pub trait Kind: Sized {
    /// The problems of this entry, its fields named relative to the entry (`size_mm` for
    /// `world.cubes[2].size_mm`): `earlier` are the entries of its kind before it, `around`
    /// the rest of the world.
    fn check(&self, _earlier: &[Self], _around: &dyn Surroundings, _problems: &mut Problems) {}

    /// The solids entry `index` (its rank among the entries of its kind) puts on the floor, each
    /// with its truth object: what the physics world collides with and the renderer draws.
    fn solids(&self, _index: u32, _out: &mut Vec<Solid>) {}

    /// The solids of all entries of the kind; a kind whose entries join (corridors) overrides it.
    fn solids_of_all(all: &[Self], out: &mut Vec<Solid>) {
        for (i, entry) in all.iter().enumerate() {
            entry.solids(i as u32, out);
        }
    }

    /// The floor-coloured rectangles it adds to the floor region.
    fn floor_rects(&self, _out: &mut Vec<FloorRect>) {}

    /// The marks it paints on the floor.
    fn floor_marks(&self, _out: &mut Vec<FloorMark>) {}

    /// The lines it paints on the floor region.
    fn field_lines(&self, _out: &mut Vec<FieldLines>) {}

    /// The stripes of its striped solids, one for each solid whose `board` is `Some`: that
    /// solid's `board` is the rank of its stripes among those of its kind's entries (the layout
    /// numbers them across the kinds).
    fn stripes(&self, _out: &mut Vec<Stripes>) {}

    /// What the robot's map holds of it.
    fn map(&self, _out: &mut Vec<MapFeature>) {}

    /// The map of all entries of the kind; a kind whose entries join (corridors) overrides it.
    fn map_of_all(all: &[Self], out: &mut Vec<MapFeature>) {
        for entry in all {
            entry.map(out);
        }
    }
}

/// Something that goes through the registry's kinds, each with its entries (see
/// [`Layout::visit_kinds`]).
pub trait KindVisitor {
    /// The entries of one kind: `key` its scenario path (`world.cubes`), `list` whether the
    /// scenario gives it as a list (`[[world.cubes]]`) rather than one table.
    fn visit<K: Kind>(&mut self, key: &'static str, list: bool, entries: &[K]);
}

/// The scenario path of entry `index` of a kind (`world.cubes[2]`, or `world.field`).
pub fn entry_path(key: &str, list: bool, index: usize) -> String {
    if list {
        format!("{key}[{index}]")
    } else {
        key.to_string()
    }
}
