//! The world as plain data: [`Layout`], which the registry of the kinds of things on the floor
//! makes ([`crate::kinds`]), and what the systems ask of all the kinds together:
//! the solids both the physics world and the renderer use, the floor region, the floor's
//! paint, the scenario's checks and the robot's map.

use crate::floor_marks::FloorMark;
use crate::floor_rect::FloorRect;
pub use crate::kinds::Layout;
use crate::kinds::{FieldLines, Kind, KindVisitor, MapFeature, Stripes, Surroundings, entry_path};
use crate::shapes::Solid;
use nalgebra::Point2;
use omniloop_problem::Problems;

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
                    e.check(&entries[..i], self.0, &mut p);
                    self.1.extend(p);
                }
            }
        }
        let mut v = Check(self, Problems::new());
        self.visit_kinds(&mut v);
        v.1
    }
}

impl Surroundings for Layout {
    fn is_floor(&self, p: Point2<f64>) -> bool {
        Layout::is_floor(self, p)
    }

    fn solids(&self) -> Vec<Solid> {
        Layout::solids(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FieldSpec;

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
    fn a_run_off_is_floor_to_the_walls_and_the_goals_stand_free_on_it() {
        // Division B: floor to x = +-4800, y = +-3300; goals from the goal line at 4500 to
        // their backs' inner faces at 4680, 500 mm either side of the axis, walls 50 mm thick.
        let f = crate::FieldPreset::DivisionB.spec();
        let layout = Layout {
            field: Some(f.clone()),
            ..Layout::default()
        };
        for p in [
            [4790.0, 3290.0],
            [-4790.0, 0.0],
            [4600.0, 0.0],
            [4760.0, 0.0],
        ] {
            assert!(layout.is_floor(Point2::from(p)), "{p:?}");
        }
        for p in [[4810.0, 0.0], [0.0, -3310.0]] {
            assert!(!layout.is_floor(Point2::from(p)), "{p:?}");
        }
        let solids = layout.solids();
        let solid_at = |p: [f64; 2]| {
            solids
                .iter()
                .any(|s| s.shape.distance_mm(Point2::from(p)) <= 0.0)
        };
        // In a wall: beyond the floor, the goal's back and sides.
        for p in [
            [4801.0, 0.0],
            [4801.0, 3000.0],
            [0.0, 3301.0],
            [-4801.0, -3301.0],
            [4705.0, 0.0],
            [4600.0, 525.0],
            [-4600.0, -525.0],
        ] {
            assert!(solid_at(p), "{p:?} not in a wall");
        }
        // Free: the run-off beside and behind the goals, the goal mouth and inside.
        for p in [
            [4799.0, 0.0],
            [4740.0, 0.0],
            [4799.0, 3299.0],
            [4600.0, 0.0],
            [4500.0, 499.0],
            [4600.0, 551.0],
            [0.0, 3299.0],
        ] {
            assert!(!solid_at(p), "{p:?} in a wall");
        }
        assert_eq!(f.walls().len(), 2 + 2 * 4);
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
