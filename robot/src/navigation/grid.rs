//! The occupancy grid the robot builds in its estimated (world) frame from what the free-space
//! stage sees each cycle, seeded with the map it is given.
//!
//! Each cell holds the log-odds of being occupied (the standard update of occupancy-grid
//! mapping, Thrun, Burgard and Fox, *Probabilistic Robotics*, eq. (9.7)), with the inverse
//! sensor model of the polar template (ours):
//!
//! - a cell of direction j's sector nearer than its surely free distance `clear_mm[j]` is free
//!   (`L_FREE`), and so is the robot's own disc;
//! - where the direction ends on an obstacle (`free_mm[j]` short of the template's range) the
//!   obstacle's near face lies between the first blocked cell's near edge `free_mm[j]` and the
//!   farthest it can be, `front_mm[j]` (it fills at least `1 - r_th` of the cell): the band
//!   `[front_mm[j] - depth, front_mm[j]]` is occupied (`L_OCC`) along the sector's centre line
//!   only (cells within `STRIP_CELLS` of it), and whatever lies beyond is not seen. The far
//!   bound: a mark there lies on or behind a face turned to the robot (inside the obstacle, or
//!   just behind a thin one, which the robot's inflated radius still covers), while a face
//!   seen obliquely lies beyond the near bound at the sector's centre and a mark there would
//!   stand in the floor. The centre line, not the whole arc: an obstacle
//!   filling half the cell spans its middle, but the arc at a metre is 200 mm wide and, marked
//!   whole, closes every gap beside a cube; a thin mark is inflated by the robot's radius for
//!   planning anyway, and a wider obstacle is hit by several sectors and views. Only cells
//!   nearer than `TRUST_MM` are marked so: farther, the cells are too long to place a face.
//!   A cell marked only from farther than `CONFIRM_MM` is *suspect*, not blocked: at that range
//!   a sector is over 70 mm wide (32 directions), and its centre-line mark may stand that far
//!   into the floor beside an obstacle's edge, enough to close a 300 mm gap beside a cube.
//!   The planner may cross a suspect cell at a cost, so the robot goes to look from nearer,
//!   where a sighting either confirms the cell (blocked) or clears it (free); only confirmed
//!   cells make a goal unreachable. For the same reason a confirmed cell is cleared only by
//!   floor seen from nearer than `CONFIRM_MM`: a sector seen free from afar may hold the edge
//!   of the cube beside it, and a gap closed from near and reopened from afar would send a
//!   robot back and forth between two routes for the rest of its run.
//!   An obstacle whose cell holds a wall of the map (anywhere across the sector, between
//!   `free_mm[j]` and `front_mm[j] + depth`) is that wall (the map explains it) and is not
//!   marked again: a wall seen obliquely through a long cell would otherwise be marked up to a
//!   hundred millimetres inside the floor and close the gaps beside it.
//!
//! The evidence decays toward "unknown" with the time constant `forget_s`
//! (`L <- L exp(-dt / forget_s)`), so that a thing that moved away is forgotten; what the robot
//! keeps seeing keeps its evidence. The walls of the map it is given are a fixed layer,
//! blocked for good.

use super::config::PlannerConfig;
use crate::config::{MapSegment, WorldMap};
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_vision::FreeSpace;
use std::f64::consts::TAU;

/// Log-odds added by a sighting of free floor.
const L_FREE: f32 = -0.4;
/// Log-odds added by a sighting of an obstacle's near face.
const L_OCC: f32 = 0.85;
/// Bounds of the log-odds, so that a cell seen long one way can be re-seen the other way.
const L_MIN: f32 = -3.0;
/// See [`L_MIN`].
const L_MAX: f32 = 3.5;
/// Above this a cell is blocked (one sighting of an obstacle is enough).
const BLOCKED_ABOVE: f32 = 0.6;
/// Below this a cell is free (one sighting of floor is enough).
const FREE_BELOW: f32 = -0.3;
/// Occupied marks lie within this many cells of a sector's centre line.
const STRIP_CELLS: f64 = 0.75;
/// Obstacles farther than this are not marked (the template's far cells are too long), mm.
const TRUST_MM: f64 = 800.0;
/// A mark from nearer than this confirms a cell blocked; from farther it is only suspect, mm.
pub const CONFIRM_MM: f64 = 450.0;
/// Most cells a grid may have (a 30 m x 30 m world at 25 mm cells).
pub const MAX_CELLS: usize = 1_440_000;

/// What the planner makes of a cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellState {
    /// Seen free, recently enough.
    Free,
    /// Never seen, or forgotten.
    Unknown,
    /// Seen occupied, but only from farther than [`CONFIRM_MM`]: passable at a cost.
    Suspect,
    /// Seen occupied from near enough to place the face, or a wall of the map.
    Blocked,
}

/// A cell's state from its evidence: a wall of the map (`fixed`) is blocked; log-odds `l` above
/// [`BLOCKED_ABOVE`] are blocked where a near sighting `confirmed` them, suspect otherwise;
/// below [`FREE_BELOW`] free; between them (or never seen) unknown.
fn classify(fixed: bool, l: f32, confirmed: bool) -> CellState {
    if fixed {
        CellState::Blocked
    } else if l > BLOCKED_ABOVE {
        if confirmed {
            CellState::Blocked
        } else {
            CellState::Suspect
        }
    } else if l < FREE_BELOW {
        CellState::Free
    } else {
        CellState::Unknown
    }
}

/// Sums of [`classify`]'s free, suspect and blocked outcomes over many cells, added without
/// branches in 32-bit lanes so that whole-grid passes vectorise.
#[derive(Debug, Clone, Copy, Default)]
struct Tally {
    free: u32,
    suspect: u32,
    blocked: u32,
}

impl Tally {
    /// Adds a cell. The sums cannot wrap (at most [`MAX_CELLS`] each); adding them wrapping
    /// keeps a build with overflow checks (the tests') from checking every cell, which stops
    /// the pass from vectorising.
    fn add(&mut self, fixed: bool, l: f32, confirmed: bool) {
        let occupied = l > BLOCKED_ABOVE;
        let free = u32::from(!fixed & (l < FREE_BELOW));
        let suspect = u32::from(!fixed & occupied & !confirmed);
        let blocked = u32::from(fixed | (occupied & confirmed));
        self.free = self.free.wrapping_add(free);
        self.suspect = self.suspect.wrapping_add(suspect);
        self.blocked = self.blocked.wrapping_add(blocked);
    }

    /// Counts by [`CellState`] of a grid of `cells` cells.
    fn counts(self, cells: usize) -> [usize; 4] {
        let [free, suspect, blocked] = [self.free, self.suspect, self.blocked].map(|n| n as usize);
        [free, cells - free - suspect - blocked, suspect, blocked]
    }
}

/// Where the grid lies: its lower-left corner, cell size and extent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridGeometry {
    /// World position of the lower-left corner of cell (0, 0), mm.
    pub origin_mm: Point2<f64>,
    /// Side of a cell, mm.
    pub cell_mm: f64,
    /// Cells along x.
    pub width: usize,
    /// Cells along y.
    pub height: usize,
}

impl GridGeometry {
    /// A grid of `cell_mm` cells covering the box `lo..hi` (world mm).
    pub fn covering(lo: Point2<f64>, hi: Point2<f64>, cell_mm: f64) -> Self {
        let cells = |a: f64, b: f64| ((b - a) / cell_mm).ceil().max(1.0) as usize;
        Self {
            origin_mm: lo,
            cell_mm,
            width: cells(lo.x, hi.x),
            height: cells(lo.y, hi.y),
        }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    /// Whether the grid has no cell.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The cell holding world point `p`, if inside the grid.
    pub fn cell_of(&self, p: Point2<f64>) -> Option<usize> {
        let (x, y) = self.coords_of(p)?;
        Some(y * self.width + x)
    }

    /// Column and row of world point `p`, if inside the grid.
    pub fn coords_of(&self, p: Point2<f64>) -> Option<(usize, usize)> {
        let fx = ((p.x - self.origin_mm.x) / self.cell_mm).floor();
        let fy = ((p.y - self.origin_mm.y) / self.cell_mm).floor();
        let inside = fx >= 0.0 && fy >= 0.0 && fx < self.width as f64 && fy < self.height as f64;
        inside.then_some((fx as usize, fy as usize))
    }

    /// World centre of cell `i`.
    pub fn centre(&self, i: usize) -> Point2<f64> {
        let (x, y) = (i % self.width, i / self.width);
        self.origin_mm + Vector2::new(x as f64 + 0.5, y as f64 + 0.5) * self.cell_mm
    }
}

/// The robot's occupancy grid.
#[derive(Debug, Clone)]
pub struct OccupancyGrid {
    geometry: GridGeometry,
    log_odds: Vec<f32>,
    /// Whether the cell's occupied evidence includes a sighting from within `CONFIRM_MM`.
    confirmed: Vec<bool>,
    fixed: Vec<bool>,
    forget_s: f64,
    last_t_s: Option<f64>,
    /// Cells by [`CellState`] (its discriminant the index), kept as the cells change.
    counts: [usize; 4],
}

impl OccupancyGrid {
    /// A grid of `geometry`, unknown everywhere but on the map's walls, goals and pillars (the
    /// boxes of the map may have been moved, and are not trusted).
    pub fn new(geometry: GridGeometry, map: &WorldMap, config: &PlannerConfig) -> Self {
        let n = geometry.len();
        let mut grid = Self {
            geometry,
            log_odds: vec![0.0; n],
            confirmed: vec![false; n],
            fixed: vec![false; n],
            forget_s: config.forget_s,
            last_t_s: None,
            counts: [0, n, 0, 0],
        };
        if config.seed_map {
            for s in map.bounds.iter().chain(&map.segments) {
                grid.fix_segment(s);
            }
            for l in &map.landmarks {
                grid.fix_disc(l.centre_mm, l.radius_mm);
            }
        }
        grid.counts = grid.tally();
        grid
    }

    /// Where the grid lies.
    pub fn geometry(&self) -> &GridGeometry {
        &self.geometry
    }

    /// The state of cell `i`.
    pub fn state(&self, i: usize) -> CellState {
        classify(self.fixed[i], self.log_odds[i], self.confirmed[i])
    }

    /// Every cell's state, row-major from the lower-left cell.
    pub fn states(&self) -> impl Iterator<Item = CellState> + '_ {
        self.fixed
            .iter()
            .zip(&self.log_odds)
            .zip(&self.confirmed)
            .map(|((&fixed, &l), &confirmed)| classify(fixed, l, confirmed))
    }

    /// Counts of free, unknown, suspect and blocked cells. The record reads them every cycle,
    /// so the grid keeps them as it goes: tallied in the pass that ages every cell, moved cell
    /// by cell where an observation changes a cell.
    pub fn counts(&self) -> [usize; 4] {
        self.counts
    }

    /// Counts of free, unknown, suspect and blocked cells, tallied over the whole grid.
    fn tally(&self) -> [usize; 4] {
        let mut tally = Tally::default();
        let cells = self.fixed.iter().zip(&self.log_odds).zip(&self.confirmed);
        for ((&fixed, &l), &confirmed) in cells {
            tally.add(fixed, l, confirmed);
        }
        tally.counts(self.geometry.len())
    }

    /// Sets cell `i`'s evidence, moving it between the counts if its state changes.
    fn set_cell(&mut self, i: usize, l: f32, confirmed: bool) {
        let before = self.state(i);
        self.log_odds[i] = l;
        self.confirmed[i] = confirmed;
        let after = self.state(i);
        self.counts[before as usize] -= 1;
        self.counts[after as usize] += 1;
    }

    /// Marks every cell whose centre lies within half a cell of segment `s`'s body.
    fn fix_segment(&mut self, s: &MapSegment) {
        let g = self.geometry;
        let reach = s.half_thickness_mm + 0.5 * g.cell_mm;
        let lo = s.from_mm.inf(&s.to_mm) - Vector2::repeat(reach);
        let hi = s.from_mm.sup(&s.to_mm) + Vector2::repeat(reach);
        self.each_cell_in(lo, hi, |grid, i, c| {
            let ab = s.to_mm - s.from_mm;
            let t = ((c - s.from_mm).dot(&ab) / ab.norm_squared().max(1e-9)).clamp(0.0, 1.0);
            if (c - (s.from_mm + ab * t)).norm() <= reach {
                grid.fixed[i] = true;
            }
        });
    }

    /// Marks every cell whose centre lies within half a cell of a disc.
    fn fix_disc(&mut self, centre: Point2<f64>, radius_mm: f64) {
        let reach = radius_mm + 0.5 * self.geometry.cell_mm;
        let r = Vector2::repeat(reach);
        self.each_cell_in(centre - r, centre + r, |grid, i, c| {
            if (c - centre).norm() <= reach {
                grid.fixed[i] = true;
            }
        });
    }

    /// Calls `f(grid, index, centre)` for every cell of the box `lo..hi` inside the grid.
    fn each_cell_in(
        &mut self,
        lo: Point2<f64>,
        hi: Point2<f64>,
        mut f: impl FnMut(&mut Self, usize, Point2<f64>),
    ) {
        let g = self.geometry;
        let span = |a: f64, o: f64, n: usize| {
            let k = ((a - o) / g.cell_mm).floor();
            k.clamp(0.0, n as f64 - 1.0) as usize
        };
        let (x0, x1) = (
            span(lo.x, g.origin_mm.x, g.width),
            span(hi.x, g.origin_mm.x, g.width),
        );
        let (y0, y1) = (
            span(lo.y, g.origin_mm.y, g.height),
            span(hi.y, g.origin_mm.y, g.height),
        );
        for y in y0..=y1 {
            for x in x0..=x1 {
                let i = y * g.width + x;
                f(self, i, g.centre(i));
            }
        }
    }

    /// Lets the evidence fade toward "unknown" up to time `t_s`.
    fn age(&mut self, t_s: f64) {
        if let Some(t0) = self.last_t_s {
            let dt = t_s - t0;
            if dt > 0.0 {
                let k = (-dt / self.forget_s).exp() as f32;
                let mut tally = Tally::default();
                let cells = self.log_odds.iter_mut().zip(&mut self.confirmed);
                for ((l, near), &fixed) in cells.zip(&self.fixed) {
                    *l *= k;
                    *near &= *l > BLOCKED_ABOVE;
                    tally.add(fixed, *l, *near);
                }
                self.counts = tally.counts(self.geometry.len());
            }
        }
        self.last_t_s = Some(t_s);
    }

    /// Takes one cycle's free space, seen from `pose` (the robot's estimate, world frame) by a
    /// robot of `body_radius_mm`, at time `t_s`.
    pub fn observe(
        &mut self,
        fs: &FreeSpace,
        pose: &Isometry2<f64>,
        body_radius_mm: f64,
        t_s: f64,
    ) {
        self.age(t_s);
        let n = fs.direction_rad.len();
        if n == 0 || fs.a.len() != n || fs.free_mm.len() != n || fs.clear_mm.len() != n {
            return;
        }
        let front_of = |j: usize| {
            fs.front_mm
                .get(j)
                .map_or(fs.free_mm[j], |f| f.max(fs.free_mm[j]))
        };
        let depth = self.geometry.cell_mm.max(30.0);
        let strip = STRIP_CELLS * self.geometry.cell_mm;
        let reach = (0..n).map(front_of).fold(body_radius_mm, f64::max);
        let axis = pose * fs.axis_mm;
        let here = Point2::from(pose.translation.vector);
        let heading = pose.rotation.angle();
        let step = TAU / n as f64;
        let first = fs.direction_rad[0];
        let explained: Vec<bool> = (0..n)
            .map(|j| self.holds_wall(fs, j, pose, axis, front_of(j) + depth))
            .collect();
        let r = Vector2::repeat(reach);
        self.each_cell_in(axis - r, axis + r, |grid, i, c| {
            if grid.fixed[i] {
                return;
            }
            let v = c - axis;
            let d = v.norm();
            if d > reach {
                return;
            }
            let mut near = false;
            let delta = if (c - here).norm() <= body_radius_mm {
                L_FREE
            } else {
                let bearing = v.y.atan2(v.x) - heading - first;
                let k = (bearing / step).round();
                let j = (k as i64).rem_euclid(n as i64) as usize;
                let open = fs.a[j] > 0;
                let obstacle = (fs.free_mm[j] < fs.range_mm || !open)
                    && fs.free_mm[j] <= TRUST_MM
                    && !explained[j];
                // How far the cell's centre lies off the sector's centre line: worked out
                // only for a cell that may be marked (most are cleared).
                let lateral = || d * (bearing - k * step).sin().abs();
                if open && d <= fs.clear_mm[j] {
                    // A cell confirmed blocked from near is cleared only from near: from
                    // afar a sector seen free may hold the edge of a cube beside it.
                    if d > CONFIRM_MM && grid.confirmed[i] {
                        return;
                    }
                    L_FREE
                } else if obstacle
                    && lateral() <= strip
                    && d <= front_of(j)
                    && d >= (front_of(j) - depth).min(fs.free_mm[j])
                {
                    near = d <= CONFIRM_MM;
                    L_OCC
                } else {
                    return;
                }
            };
            let l = (grid.log_odds[i] + delta).clamp(L_MIN, L_MAX);
            let confirmed = (grid.confirmed[i] || near) && l > BLOCKED_ABOVE;
            grid.set_cell(i, l, confirmed);
        });
    }

    /// Whether a wall of the map stands in direction `j`'s sector between its first blocked
    /// cell's near edge and `far_mm` (rays across the sector, every half cell).
    fn holds_wall(
        &self,
        fs: &FreeSpace,
        j: usize,
        pose: &Isometry2<f64>,
        axis: Point2<f64>,
        far_mm: f64,
    ) -> bool {
        let n = fs.direction_rad.len();
        let half = 0.5 * TAU / n as f64;
        let near = fs.free_mm[j];
        let steps = ((far_mm - near) / (0.5 * self.geometry.cell_mm))
            .ceil()
            .max(1.0) as usize;
        [-1.0, -0.5, 0.0, 0.5, 1.0].iter().any(|f| {
            let a = fs.direction_rad[j] + f * half;
            let u = pose.rotation * Vector2::new(a.cos(), a.sin());
            (0..=steps).any(|k| {
                let d = near + (far_mm - near) * k as f64 / steps as f64;
                self.geometry
                    .cell_of(axis + u * d)
                    .is_some_and(|i| self.fixed[i])
            })
        })
    }

    /// Marks the cell holding `p` occupied, as a sighting from near (`confirmed`) or from afar
    /// would: for the planner's tests.
    #[cfg(test)]
    pub(crate) fn mark_occupied(&mut self, p: Point2<f64>, confirmed: bool) {
        if let Some(i) = self.geometry.cell_of(p) {
            self.set_cell(i, L_MAX, confirmed);
        }
    }

    /// The cells as free, unknown or blocked, for figures and records.
    pub fn snapshot(&self) -> MapSnapshot {
        MapSnapshot {
            geometry: self.geometry,
            cells: self.states().collect(),
        }
    }
}

/// The robot's map at one moment: each cell's state.
#[derive(Debug, Clone, PartialEq)]
pub struct MapSnapshot {
    /// Where the grid lies.
    pub geometry: GridGeometry,
    /// Row-major from the lower-left cell.
    pub cells: Vec<CellState>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Free space of `n` directions around a robot at the origin: free to `clear(angle)`.
    fn seen(n: usize, free: impl Fn(f64) -> f64) -> FreeSpace {
        let dirs: Vec<f64> = (0..n).map(|j| j as f64 * TAU / n as f64).collect();
        let free_mm: Vec<f64> = dirs.iter().map(|&a| free(a)).collect();
        FreeSpace {
            a: free_mm
                .iter()
                .map(|&f| if f > 200.0 { 3 } else { 0 })
                .collect(),
            clear_mm: free_mm.iter().map(|f| f - 40.0).collect(),
            front_mm: free_mm.iter().map(|f| f + 20.0).collect(),
            free_mm,
            direction_rad: dirs,
            range_mm: 1000.0,
            ..FreeSpace::default()
        }
    }

    fn grid() -> OccupancyGrid {
        let g = GridGeometry::covering(
            Point2::new(-2000.0, -2000.0),
            Point2::new(2000.0, 2000.0),
            20.0,
        );
        OccupancyGrid::new(g, &WorldMap::default(), &PlannerConfig::default())
    }

    #[test]
    fn a_wall_ahead_is_blocked_the_floor_before_it_free_and_behind_it_unknown() {
        let mut g = grid();
        // A wall 400 mm ahead (x = 400) across the robot's front, near enough to be placed
        // (CONFIRM_MM).
        let fs = seen(64, |a| {
            let c = a.cos();
            if c > 0.6 { 400.0 / c } else { 1000.0 }
        });
        g.observe(&fs, &Isometry2::identity(), 90.0, 0.0);
        let at = |x: f64, y: f64| {
            let i = g.geometry().cell_of(Point2::new(x, y)).unwrap();
            g.state(i)
        };
        assert_eq!(at(300.0, 0.0), CellState::Free);
        assert_eq!(at(410.0, 0.0), CellState::Blocked);
        assert_eq!(
            at(600.0, 0.0),
            CellState::Unknown,
            "behind the wall is not seen"
        );
        assert_eq!(at(0.0, 500.0), CellState::Free);
        assert_eq!(
            at(0.0, 1500.0),
            CellState::Unknown,
            "beyond the template's range"
        );
    }

    #[test]
    fn the_counts_are_the_states_tallied_cell_by_cell() {
        // A map's wall (fixed), a wall seen from afar (suspect), one from near (blocked), the
        // floor before them (free) and the rest unknown: every state occurs.
        let map = WorldMap {
            bounds: vec![MapSegment {
                from_mm: Point2::new(-1900.0, -1900.0),
                to_mm: Point2::new(-1900.0, 1900.0),
                half_thickness_mm: 10.0,
            }],
            ..WorldMap::default()
        };
        let geometry = *grid().geometry();
        let mut g = OccupancyGrid::new(geometry, &map, &PlannerConfig::default());
        let tally = |g: &OccupancyGrid| {
            let mut tally = [0; 4];
            for state in g.states() {
                tally[state as usize] += 1;
            }
            tally
        };
        assert_eq!(g.counts(), tally(&g), "the map's walls alone");
        g.observe(&wall(700.0), &Isometry2::identity(), 90.0, 0.0);
        let behind = Isometry2::new(Vector2::new(-1000.0, 0.0), std::f64::consts::PI);
        g.observe(&wall(300.0), &behind, 90.0, 0.04);
        let all = tally(&g);
        assert!(all.iter().all(|&n| n > 0), "{all:?}");
        assert_eq!(g.counts(), all);
        // The counts are kept as the grid goes: cells seen free, seen occupied, confirmed,
        // and fading between sightings, on a walk past the walls with seconds between looks.
        for k in 0..40 {
            let x = -1200.0 + 60.0 * f64::from(k);
            let pose = Isometry2::new(Vector2::new(x, 100.0), 0.3 * f64::from(k));
            let t_s = 0.04 + 0.5 * f64::from(k % 7) + 2.0 * f64::from(k / 7);
            g.observe(&wall(250.0 + 40.0 * f64::from(k % 5)), &pose, 90.0, t_s);
            assert_eq!(g.counts(), tally(&g), "after look {k}");
        }
    }

    #[test]
    fn an_obstacle_seen_only_from_afar_is_suspect_and_seen_from_near_blocked() {
        // A wall across the robot's front, seen from 700 mm, then from 300 mm.
        let mut g = grid();
        let pose = Isometry2::identity();
        g.observe(&wall(700.0), &pose, 90.0, 0.0);
        let i = g.geometry().cell_of(Point2::new(710.0, 0.0)).unwrap();
        assert_eq!(g.state(i), CellState::Suspect, "seen from 700 mm");
        let counts = g.counts();
        assert!(counts[2] > 0 && counts[3] == 0, "{counts:?}");
        // The robot drives up to 300 mm of it and sees it there: confirmed.
        let near = Isometry2::new(Vector2::new(400.0, 0.0), 0.0);
        g.observe(&wall(300.0), &near, 90.0, 0.04);
        assert_eq!(g.state(i), CellState::Blocked, "seen from 300 mm");
        // Seen free again from near, it clears; marked again from afar, only suspect.
        for k in 1..=8 {
            g.observe(&seen(32, |_| 1000.0), &near, 90.0, 0.04 + 0.04 * k as f64);
        }
        assert_eq!(g.state(i), CellState::Free);
        for k in 0..4 {
            g.observe(&wall(700.0), &pose, 90.0, 0.5 + 0.04 * k as f64);
        }
        assert_eq!(g.state(i), CellState::Suspect);
    }

    /// A wall across the robot's front, `x` mm ahead, seen in 32 directions.
    fn wall(x: f64) -> FreeSpace {
        seen(32, move |a: f64| {
            let c = a.cos();
            if c > 0.6 { x / c } else { 1000.0 }
        })
    }

    #[test]
    fn a_cell_confirmed_from_near_is_cleared_from_near_only() {
        let mut g = grid();
        let near = Isometry2::new(Vector2::new(400.0, 0.0), 0.0);
        g.observe(&wall(300.0), &near, 90.0, 0.0);
        let i = g.geometry().cell_of(Point2::new(710.0, 0.0)).unwrap();
        assert_eq!(g.state(i), CellState::Blocked, "seen from 300 mm");
        // Floor seen there from 700 mm away (a sector that may hold the cube's edge): it
        // stays blocked...
        let far = Isometry2::identity();
        for k in 1..=8 {
            g.observe(&seen(32, |_| 1000.0), &far, 90.0, 0.04 * k as f64);
        }
        assert_eq!(g.state(i), CellState::Blocked, "cleared from afar");
        // ...and floor seen there from 300 mm clears it.
        for k in 1..=8 {
            g.observe(&seen(32, |_| 1000.0), &near, 90.0, 0.4 + 0.04 * k as f64);
        }
        assert_eq!(g.state(i), CellState::Free, "not cleared from near");
    }

    #[test]
    fn seen_again_free_an_obstacle_that_moved_is_cleared_and_unseen_evidence_fades() {
        let mut g = grid();
        let wall = seen(64, |a| {
            if a.cos() > 0.9 {
                400.0 / a.cos()
            } else {
                1000.0
            }
        });
        let open = seen(64, |_| 1000.0);
        let pose = Isometry2::identity();
        g.observe(&wall, &pose, 90.0, 0.0);
        let i = g.geometry().cell_of(Point2::new(410.0, 0.0)).unwrap();
        assert_eq!(g.state(i), CellState::Blocked);
        for k in 1..=5 {
            g.observe(&open, &pose, 90.0, 0.04 * k as f64);
        }
        assert_eq!(g.state(i), CellState::Free, "seen free again");
        // Seen once blocked, then not seen for long: forgotten.
        let mut g = grid();
        g.observe(&wall, &pose, 90.0, 0.0);
        let away = Isometry2::new(Vector2::new(-1900.0, -1900.0), 0.0);
        g.observe(&seen(64, |_| 100.0), &away, 90.0, 60.0);
        assert_eq!(
            g.state(i),
            CellState::Unknown,
            "forgotten after a minute unseen"
        );
    }

    #[test]
    fn the_maps_walls_and_pillars_are_blocked_and_its_boxes_are_not() {
        let seg = |a: [f64; 2], b: [f64; 2], t: f64| MapSegment {
            from_mm: Point2::new(a[0], a[1]),
            to_mm: Point2::new(b[0], b[1]),
            half_thickness_mm: t,
        };
        let map = WorldMap {
            bounds: vec![seg([-1000.0, 1000.0], [1000.0, 1000.0], 25.0)],
            landmarks: vec![crate::config::MapLandmark {
                centre_mm: Point2::new(500.0, 0.0),
                radius_mm: 60.0,
                rgb: [200, 0, 0],
            }],
            boxes: vec![seg([-500.0, -500.0], [-400.0, -500.0], 0.0)],
            ..WorldMap::default()
        };
        let geo = GridGeometry::covering(
            Point2::new(-1200.0, -1200.0),
            Point2::new(1200.0, 1200.0),
            20.0,
        );
        let g = OccupancyGrid::new(geo, &map, &PlannerConfig::default());
        let at = |x: f64, y: f64| g.state(g.geometry().cell_of(Point2::new(x, y)).unwrap());
        assert_eq!(at(0.0, 1010.0), CellState::Blocked);
        assert_eq!(at(540.0, 0.0), CellState::Blocked);
        assert_eq!(
            at(-450.0, -500.0),
            CellState::Unknown,
            "boxes may have moved"
        );
        assert_eq!(at(0.0, 0.0), CellState::Unknown);
    }
}
