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
}

/// Lines painted on the floor region after the Small-Size field's markings (its boundary, the
/// centre line and the centre circle), which the renderers and the top view paint from these
/// figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldLines {
    /// Half-length of the boundary.
    pub half_length_mm: f64,
    /// Half-width of the boundary.
    pub half_width_mm: f64,
    /// Width of each line.
    pub line_width_mm: f64,
    /// Radius of the centre circle.
    pub centre_circle_radius_mm: f64,
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
