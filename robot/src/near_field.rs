//! Near-field memory: where obstacles are when they are too near for the camera to see.
//!
//! The robot's own body hides the floor within the template's inner edge, so an obstacle nearer
//! than that only shows as a blocked first ring: vision knows it is there, not how near. A robot
//! that takes such an obstacle to be at the inner edge creeps into it a little every cycle. It
//! saw the obstacle, though, while it approached: this memory keeps, in the odometry frame,
//! the surely-free boundary points of near obstacles and the floor seen surely free near the
//! robot (each unblocked direction's sector from the template's inner edge to its clear
//! distance, on a 10 mm grid). In a direction whose first ring is blocked it hands the
//! controller the remembered points there (moved by the odometry since); where it remembers
//! none, each of the direction's three rays ends where the floor remembered free along it
//! ends, or, where the floor by the body was never seen free, on a blind point at the body's
//! edge (something is there at a distance nobody knows: the robot may pass it at a slant or
//! move away from it, never head into it).
//!
//! Blind points are remembered too, where they were first placed: the slant at which the
//! controller may pass one lets the robot come nearer to it once, by a few millimetres, not a
//! few millimetres every cycle (placed afresh at the body's edge each cycle, they let a robot
//! creep into a cube's corner at a slant, one cycle at a time).
//!
//! A point or a cell is forgotten once it is older than `KEEP_S` *and* the robot has travelled
//! more than `KEEP_TRAVEL_MM` since it was last seen: odometry drifts with the way driven, not
//! with the time, and a robot creeping past a cube's corner (at the slowest turning speed,
//! 80 mm/s for a 400 mm/s robot) must not forget the corner half-way along and slide into it.

use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_vision::FreeSpace;
use std::f64::consts::TAU;

/// Obstacle points farther than this are not remembered (fresh vision covers them), mm.
const NEAR_MM: f64 = 450.0;
/// How long a point is remembered at least, s.
const KEEP_S: f64 = 2.0;
/// How far the robot may drive, at least, before a point is forgotten, mm (a 4% odometry
/// scale error moves it by 10 mm over that).
const KEEP_TRAVEL_MM: f64 = 250.0;
/// Points closer than this to a remembered one refresh it instead of adding another, mm.
const MERGE_MM: f64 = 12.0;

/// The surely free space's boundary handed to the controller (robot frame).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct NearSpace {
    /// Seen this cycle, or remembered where the first ring is blocked, mm.
    pub clear: Vec<Vector2<f64>>,
    /// Where the first ring is blocked and nothing is remembered: at the body's edge, mm.
    pub blind: Vec<Vector2<f64>>,
}

/// Remembered obstacle points near the robot.
#[derive(Debug, Clone)]
pub struct NearField {
    /// Points in the odometry frame, with the time and the odometer when they were last seen.
    points: Vec<(Point2<f64>, f64, f64)>,
    /// Blind points placed so far (odometry frame), kept and forgotten as `points`: a blind
    /// point stays where it was first placed while the robot moves, so the slant at which the
    /// controller may pass one lets the robot come nearer to it once, by a few millimetres,
    /// not a few millimetres every cycle.
    blind: Vec<(Point2<f64>, f64, f64)>,
    /// The floor seen free near the robot.
    floor: SeenFloor,
    radius_mm: f64,
    /// The way driven so far, mm, and where the robot was last cycle (odometry frame).
    odometer_mm: f64,
    last: Option<Point2<f64>>,
}

impl NearField {
    /// A memory for a robot of radius `radius_mm`.
    pub fn new(radius_mm: f64) -> Self {
        Self {
            points: Vec::new(),
            blind: Vec::new(),
            floor: SeenFloor::new(),
            radius_mm,
            odometer_mm: 0.0,
            last: None,
        }
    }

    /// Takes this cycle's free space, seen at odometry pose `odo` at time `t_s`, and returns
    /// the boundary of the surely free space (robot frame): fresh where the first ring is clear,
    /// remembered (or blind points at the body's edge) where it is blocked.
    pub fn update(&mut self, fs: &FreeSpace, odo: &Isometry2<f64>, t_s: f64) -> NearSpace {
        let here = Point2::from(odo.translation.vector);
        self.odometer_mm += self.last.map_or(0.0, |l| (here - l).norm());
        self.last = Some(here);
        let odometer = self.odometer_mm;
        let kept = |&(p, t, o): &(Point2<f64>, f64, f64)| {
            (t_s - t <= KEEP_S || odometer - o <= KEEP_TRAVEL_MM)
                && (p - here).norm() <= 2.0 * NEAR_MM
        };
        self.points.retain(kept);
        self.blind.retain(kept);
        let now = Stamp {
            t_s,
            odometer_mm: odometer,
        };
        self.floor.see(fs, odo, now);
        // Until the robot has driven from its start past the template's inner edge, the floor
        // by its body was never in view: blind points there are placed afresh each cycle,
        // not remembered (remembered, phantoms at the body's edge would pin it to its start).
        let settled = odometer >= fs.inner_mm - self.radius_mm;
        let n = fs.direction_rad.len();
        let half = 0.5 * TAU / n as f64;
        let mut out = NearSpace {
            clear: Vec::with_capacity(3 * n),
            blind: Vec::new(),
        };
        for j in 0..n {
            let fresh = &fs.clear_points[3 * j..3 * j + 3];
            if fs.a[j] > 0 {
                out.clear.extend(fresh.iter().map(|p| p.coords));
                // An obstacle, not the template's edge, and near: its point on the direction's
                // centre line is remembered (the points at the sector's edges stand in for the
                // whole cell and, at a wall seen at a grazing angle, lie well inside the floor).
                if fs.free_mm[j] < fs.range_mm && fs.clear_mm[j] <= NEAR_MM {
                    self.remember(odo * fresh[1], t_s);
                }
                continue;
            }
            // The first ring is blocked: the obstacle may be nearer than vision can tell.
            let c = fs.direction_rad[j];
            let before = out.clear.len();
            for (p, _, _) in &self.points {
                let q = odo.inverse_transform_point(p).coords;
                let off = (q.y.atan2(q.x) - c + TAU / 2.0).rem_euclid(TAU) - TAU / 2.0;
                if off.abs() <= half {
                    out.clear.push(q);
                }
            }
            if out.clear.len() == before {
                for phi in [c - half, c, c + half] {
                    let u = Vector2::new(phi.cos(), phi.sin());
                    // Floor seen free beside the body: the obstacle stands beyond it.
                    let seen = self
                        .floor
                        .free_along(odo, u, self.radius_mm, fs.inner_mm, now);
                    if seen > self.radius_mm {
                        out.clear.push(u * seen);
                        continue;
                    }
                    let at_edge = u * self.radius_mm;
                    if settled {
                        remember(&mut self.blind, odo * Point2::from(at_edge), t_s, odometer);
                    } else {
                        out.blind.push(at_edge);
                    }
                }
                for (p, _, _) in &self.blind {
                    let q = odo.inverse_transform_point(p).coords;
                    let off = (q.y.atan2(q.x) - c + TAU / 2.0).rem_euclid(TAU) - TAU / 2.0;
                    if off.abs() <= half {
                        out.blind.push(q);
                    }
                }
            }
        }
        out
    }

    fn remember(&mut self, p: Point2<f64>, t_s: f64) {
        let seen = (p, t_s, self.odometer_mm);
        match self
            .points
            .iter_mut()
            .find(|(q, _, _)| (q - p).norm() < MERGE_MM)
        {
            Some(entry) => *entry = seen,
            None => self.points.push(seen),
        }
    }
}

/// Floor farther than this from the sensor axis is not remembered, mm.
const FLOOR_MM: f64 = 350.0;
/// Side of a cell of the remembered floor, mm.
const CELL_MM: f64 = 10.0;
/// Cells a side of the floor's grid. It wraps round (a cell lives at its indices modulo
/// this), so it follows the robot: 1.28 m a side, more than the 0.7 m across what it keeps.
const SIDE: i32 = 128;

/// The floor vision found surely free near the robot (each unblocked direction's sector from
/// the template's inner edge to its clear distance), on a fine grid in the odometry frame,
/// kept and forgotten as the remembered points. A ray of a blocked direction that starts on
/// such floor is not blind: its obstacle stands beyond the floor seen free.
#[derive(Debug, Clone)]
struct SeenFloor {
    /// Per slot: the cell's indices (`None` for a slot never written), when it was last seen
    /// free and the odometer then.
    cells: Vec<(Option<[i32; 2]>, f64, f64)>,
}

/// When something was seen: the time and the odometer then.
#[derive(Debug, Clone, Copy)]
struct Stamp {
    t_s: f64,
    odometer_mm: f64,
}

impl SeenFloor {
    fn new() -> Self {
        Self {
            cells: vec![(None, 0.0, 0.0); (SIDE * SIDE) as usize],
        }
    }

    fn slot(cell: [i32; 2]) -> usize {
        (cell[0].rem_euclid(SIDE) * SIDE + cell[1].rem_euclid(SIDE)) as usize
    }

    fn cell_of(p: Point2<f64>) -> [i32; 2] {
        [
            (p.x / CELL_MM).floor() as i32,
            (p.y / CELL_MM).floor() as i32,
        ]
    }

    /// Marks the cells whose centres lie in a sector seen surely free this cycle.
    fn see(&mut self, fs: &FreeSpace, odo: &Isometry2<f64>, now: Stamp) {
        let n = fs.direction_rad.len();
        if n == 0 {
            return;
        }
        let step = TAU / n as f64;
        let axis = odo * fs.axis_mm;
        let lo = Self::cell_of(axis - Vector2::repeat(FLOOR_MM));
        let hi = Self::cell_of(axis + Vector2::repeat(FLOOR_MM));
        for i in lo[0]..=hi[0] {
            for k in lo[1]..=hi[1] {
                let centre = Point2::new((i as f64 + 0.5) * CELL_MM, (k as f64 + 0.5) * CELL_MM);
                let rel = odo.inverse_transform_point(&centre) - fs.axis_mm;
                let r = rel.norm();
                if r < fs.inner_mm || r > FLOOR_MM {
                    continue;
                }
                let turns = (rel.y.atan2(rel.x) - fs.direction_rad[0]) / step;
                let j = (turns.round() as i64).rem_euclid(n as i64) as usize;
                if fs.a[j] > 0 && r <= fs.clear_mm[j] {
                    self.cells[Self::slot([i, k])] = (Some([i, k]), now.t_s, now.odometer_mm);
                }
            }
        }
    }

    fn is_free(&self, p: Point2<f64>, now: Stamp) -> bool {
        let cell = Self::cell_of(p);
        let (c, t, o) = self.cells[Self::slot(cell)];
        c == Some(cell) && (now.t_s - t <= KEEP_S || now.odometer_mm - o <= KEEP_TRAVEL_MM)
    }

    /// How far along the ray `u` (robot frame, from the robot's centre) the floor is
    /// remembered free without a break, from the body's edge `from_mm` out to `to_mm`; `from_mm`
    /// when the floor by the body was not seen free.
    fn free_along(
        &self,
        odo: &Isometry2<f64>,
        u: Vector2<f64>,
        from_mm: f64,
        to_mm: f64,
        now: Stamp,
    ) -> f64 {
        let mut d = from_mm;
        while d + CELL_MM <= to_mm && self.is_free(odo * Point2::from(u * (d + CELL_MM)), now) {
            d += CELL_MM;
        }
        d
    }
}

/// Remembers a blind point at `p`, or, when one is remembered within `MERGE_MM`, refreshes that
/// one where it is.
fn remember(blind: &mut Vec<(Point2<f64>, f64, f64)>, p: Point2<f64>, t_s: f64, odometer: f64) {
    match blind.iter_mut().find(|(q, _, _)| (q - p).norm() < MERGE_MM) {
        Some(entry) => (entry.1, entry.2) = (t_s, odometer),
        None => blind.push((p, t_s, odometer)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point2;

    /// Free space of 8 directions with a wall at x = `wall` seen as vision would: the first
    /// ring blocked when the wall is within 200 mm, else surely free to the wall.
    fn seen(wall: f64) -> FreeSpace {
        let n = 8;
        let dirs: Vec<f64> = (0..n).map(|j| j as f64 * TAU / n as f64).collect();
        let mut fs = FreeSpace {
            direction_rad: dirs.clone(),
            range_mm: 1000.0,
            inner_mm: 200.0,
            ..FreeSpace::default()
        };
        for &c in &dirs {
            let d = if c.cos() > 0.1 {
                wall / c.cos()
            } else {
                1000.0
            };
            let (a, free, clear) = if d < 200.0 {
                (0, 200.0, 200.0)
            } else if d < 1000.0 {
                (3, d, d)
            } else {
                (6, 1000.0, 900.0)
            };
            fs.a.push(a);
            fs.free_mm.push(free);
            fs.clear_mm.push(clear);
            let half = 0.5 * TAU / n as f64;
            for phi in [c - half, c, c + half] {
                fs.clear_points
                    .push(Point2::new(clear * phi.cos(), clear * phi.sin()));
            }
        }
        fs
    }

    #[test]
    fn a_wall_that_comes_into_the_blind_zone_stays_where_it_was_seen() {
        let mut m = NearField::new(90.0);
        // At 300 mm the wall is seen where it is.
        let ahead = |pts: &[Vector2<f64>]| {
            pts.iter()
                .filter(|p| p.y.abs() < 1.0 && p.x > 0.0)
                .map(|p| p.x)
                .fold(f64::INFINITY, f64::min)
        };
        let out = m.update(&seen(300.0), &Isometry2::identity(), 0.0);
        assert!((ahead(&out.clear) - 300.0).abs() < 1e-9);
        assert!(out.blind.is_empty());
        // The robot moves 150 mm toward it: vision only says "blocked within 200 mm"; the
        // memory puts the wall at 150 mm, where it is.
        let odo = Isometry2::new(Vector2::new(150.0, 0.0), 0.0);
        let out = m.update(&seen(150.0), &odo, 0.5);
        assert!(
            (ahead(&out.clear) - 150.0).abs() < 1e-9,
            "{}",
            ahead(&out.clear)
        );
        assert!(out.blind.is_empty());
        // Without a memory of it, a blocked first ring means a blind point at the body's edge.
        let mut fresh = NearField::new(90.0);
        let out = fresh.update(&seen(150.0), &odo, 0.5);
        assert!((ahead(&out.blind) - 90.0).abs() < 1e-9);
        assert_eq!(ahead(&out.clear), f64::INFINITY);
        // Kept while the robot creeps on (old, but driven less than KEEP_TRAVEL_MM since)...
        let out = m.update(&seen(150.0), &odo, 3.0);
        assert!((ahead(&out.clear) - 150.0).abs() < 1e-9);
        assert!(out.blind.is_empty());
        // ...and forgotten once it is old and the robot has driven on: 200 mm away, boxed in
        // where it sees no floor, and back, its memory of the wall ahead is gone.
        let away = Isometry2::new(Vector2::new(150.0, 200.0), 0.0);
        m.update(&boxed(), &away, 3.5);
        let out = m.update(&seen(150.0), &odo, 4.0);
        assert!((ahead(&out.blind) - 90.0).abs() < 1e-9);
    }

    /// Every direction's first ring blocked.
    fn boxed() -> FreeSpace {
        let mut fs = seen(150.0);
        fs.a = vec![0; fs.a.len()];
        fs
    }

    /// The nearest of `pts` on the ray straight ahead.
    fn nearest_ahead(pts: &[Vector2<f64>]) -> f64 {
        pts.iter()
            .filter(|p| p.y.abs() < 1e-6 && p.x > 0.0)
            .map(|p| p.x)
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn a_blind_point_stays_where_it_was_first_placed() {
        let at = |x: f64| Isometry2::new(Vector2::new(x, 0.0), 0.0);
        let mut m = NearField::new(90.0);
        // Near its start (driven less than the template's inner edge minus the radius,
        // 110 mm), the floor by the body was never in view: blind points are placed afresh at
        // the body's edge each cycle.
        let out = m.update(&boxed(), &at(0.0), 0.0);
        assert!((nearest_ahead(&out.blind) - 90.0).abs() < 1e-9);
        let out = m.update(&boxed(), &at(10.0), 0.04);
        assert!((nearest_ahead(&out.blind) - 90.0).abs() < 1e-9);
        // Past that, one stays where it was placed: 10 mm on, the blind point ahead is 80 mm
        // away, not at the body's edge again (the controller holds the robot off it there).
        m.update(&boxed(), &at(120.0), 0.5);
        let out = m.update(&boxed(), &at(130.0), 0.54);
        assert!((nearest_ahead(&out.blind) - 80.0).abs() < 1e-9, "{out:?}");
    }

    #[test]
    fn floor_seen_free_by_the_body_is_not_blind() {
        // Open floor all round: nothing near to remember but the floor itself.
        let mut m = NearField::new(90.0);
        m.update(&seen(5000.0), &Isometry2::identity(), 0.0);
        // 150 mm on, something blocks the first ring ahead: the floor from the body's edge
        // to the template's inner edge was seen free on the way, so the rays ahead end at
        // the inner edge, not on blind points at the body's edge.
        let on = Isometry2::new(Vector2::new(150.0, 0.0), 0.0);
        let out = m.update(&seen(150.0), &on, 0.4);
        assert!(out.blind.is_empty(), "{out:?}");
        let d = nearest_ahead(&out.clear);
        assert!((190.0..=200.0).contains(&d), "{d}");
    }
}
