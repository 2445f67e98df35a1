//! The world as plain data: the registry of the kinds of things on the floor
//! ([`crate::kinds`]), which makes [`Layout`], and what the systems ask of all of them together:
//! the solids both the physics world and the renderer use, the floor region, the floor's
//! paint, the scenario's checks and the robot's map.

use crate::kinds::ball::BallSpec;
use crate::kinds::board::Board;
use crate::kinds::corridor::Corridor;
use crate::kinds::cube::Cube;
use crate::kinds::field::FieldSpec;
use crate::kinds::floor_marks::{FloorMark, MarkScatter};
use crate::kinds::floor_rect::FloorRect;
use crate::kinds::pillar::Pillar;
use crate::kinds::wall::Wall;
use crate::kinds::{
    FieldLines, Kind, KindVisitor, MapFeature, Stripes, entry_path, things_on_the_floor,
};
use crate::shapes::Solid;
use nalgebra::Point2;
use omniloop_problem::Problems;

// The registry: a kind's line gives `Layout` its field, in the order every system goes through
// the kinds (the order of the solids, of the floor's rectangles and of the map's features).
things_on_the_floor! {
    /// Corridors: floor and walls from a centre polyline and a width (`[[world.corridors]]`).
    corridors: Vec<Corridor>,
    /// The RoboCup Small-Size field, when present (`[world.field]`).
    field: Option<FieldSpec>,
    /// Extra rectangles of floor colour (`[[world.floor_rects]]`). With no floor rectangle of
    /// any kind the whole plane is floor.
    floor_rects: Vec<FloorRect>,
    /// Free-standing walls (`[[world.walls]]`).
    walls: Vec<Wall>,
    /// Cubes (`[[world.cubes]]`).
    cubes: Vec<Cube>,
    /// Pillars (`[[world.pillars]]`).
    pillars: Vec<Pillar>,
    /// Striped boards, the landmarks (`[[world.boards]]`).
    boards: Vec<Board>,
    /// Marks painted on the floor (`[[world.floor_marks]]`).
    floor_marks: Vec<FloorMark>,
    /// Marks scattered at random over a rectangle of the floor (`[world.mark_scatter]`).
    mark_scatter: Option<MarkScatter>,
    /// The ball (`[world.ball]`), when there is one.
    ball: Option<BallSpec>,
}

impl Layout {
    /// Every mark painted on the floor, kind by kind.
    pub fn all_floor_marks(&self) -> Vec<FloorMark> {
        struct Marks(Vec<FloorMark>);
        impl KindVisitor for Marks {
            fn visit<K: Kind>(&mut self, _: &'static str, _: bool, entries: &[K]) {
                entries.iter().for_each(|e| e.floor_marks(&mut self.0));
            }
        }
        let mut v = Marks(Vec::new());
        self.visit_kinds(&mut v);
        v.0
    }

    /// Every floor-coloured rectangle, kind by kind.
    pub fn all_floor_rects(&self) -> Vec<FloorRect> {
        struct Rects(Vec<FloorRect>);
        impl KindVisitor for Rects {
            fn visit<K: Kind>(&mut self, _: &'static str, _: bool, entries: &[K]) {
                entries.iter().for_each(|e| e.floor_rects(&mut self.0));
            }
        }
        let mut v = Rects(Vec::new());
        self.visit_kinds(&mut v);
        v.0
    }

    /// Is the floor at `p` floor-coloured (inside the floor region)? With no floor rectangle
    /// the whole plane is.
    pub fn is_floor(&self, p: Point2<f64>) -> bool {
        let rects = self.all_floor_rects();
        rects.is_empty() || rects.iter().any(|r| r.contains(p))
    }

    /// Every solid thing on the floor (boxes, quad prisms, cylinders) in world coordinates,
    /// each with its truth object, kind by kind; a striped solid's `board` numbers its stripes
    /// in [`Layout::stripes`].
    pub fn solids(&self) -> Vec<Solid> {
        struct Solids(Vec<Solid>, usize);
        impl KindVisitor for Solids {
            fn visit<K: Kind>(&mut self, _: &'static str, _: bool, entries: &[K]) {
                let first = self.0.len();
                K::solids_of_all(entries, &mut self.0);
                for s in &mut self.0[first..] {
                    s.board = s.board.map(|b| b + self.1);
                }
                let mut stripes = Vec::new();
                entries.iter().for_each(|e| e.stripes(&mut stripes));
                self.1 += stripes.len();
            }
        }
        let mut v = Solids(Vec::new(), 0);
        self.visit_kinds(&mut v);
        v.0
    }

    /// The stripes of every striped solid, kind by kind.
    pub fn stripes(&self) -> Vec<Stripes> {
        struct All(Vec<Stripes>);
        impl KindVisitor for All {
            fn visit<K: Kind>(&mut self, _: &'static str, _: bool, entries: &[K]) {
                entries.iter().for_each(|e| e.stripes(&mut self.0));
            }
        }
        let mut v = All(Vec::new());
        self.visit_kinds(&mut v);
        v.0
    }

    /// The lines painted on the floor region, if a kind paints them (the renderers paint one
    /// set: the first).
    pub fn field_lines(&self) -> Option<FieldLines> {
        struct Lines(Vec<FieldLines>);
        impl KindVisitor for Lines {
            fn visit<K: Kind>(&mut self, _: &'static str, _: bool, entries: &[K]) {
                entries.iter().for_each(|e| e.field_lines(&mut self.0));
            }
        }
        let mut v = Lines(Vec::new());
        self.visit_kinds(&mut v);
        v.0.first().copied()
    }

    /// What the map a robot is told holds, kind by kind.
    pub fn map_features(&self) -> Vec<MapFeature> {
        struct Map(Vec<MapFeature>);
        impl KindVisitor for Map {
            fn visit<K: Kind>(&mut self, _: &'static str, _: bool, entries: &[K]) {
                K::map_of_all(entries, &mut self.0);
            }
        }
        let mut v = Map(Vec::new());
        self.visit_kinds(&mut v);
        v.0
    }

    /// Every entry's problems, each named by its scenario path (`world.cubes[2].size_mm`).
    pub fn check(&self) -> Problems {
        struct Check<'a>(&'a Layout, Problems);
        impl KindVisitor for Check<'_> {
            fn visit<K: Kind>(&mut self, key: &'static str, list: bool, entries: &[K]) {
                for (i, e) in entries.iter().enumerate() {
                    let mut p = Problems::under(entry_path(key, list, i));
                    e.check(self.0, &mut p);
                    self.1.extend(p);
                }
            }
        }
        let mut v = Check(self, Problems::new());
        self.visit_kinds(&mut v);
        v.1
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
