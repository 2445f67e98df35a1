//! The global planner: A* (Hart, Nilsson and Raphael 1968, by the `pathfinding` crate) over the
//! occupancy grid inflated by the robot's radius, then the path pulled taut.
//!
//! The cost of a step between neighbouring cells (8-connected) is its length times the mean of
//! the two cells' factors; a cell's factor is
//!
//! `f = 1 + u [cell unknown] + w (1 - (d - r_i) / c)^2 [d < r_i + c] + s [d_s < r_i] + p`
//!
//! with `d` the distance from the cell's centre to the nearest blocked cell's centre (the
//! exact Euclidean distance transform of Felzenszwalb and Huttenlocher, [`super::distances`]), `d_s`
//! the same to the nearest suspect cell (seen occupied only from afar, see
//! [`super::grid`]) and `s` its factor `SUSPECT_FACTOR`, `r_i`
//! the robot's radius plus `inflation_mm` (nearer is impassable), `c` the comfort band
//! `comfort_mm` in which paths pay `w` to keep off obstacles (the middle of a gap is cheapest),
//! `u` the `unknown_cost` and `p` the watchdog's penalty on the cell (infinite: a place the
//! navigator closed, impassable). The heuristic is the
//! octile distance, admissible since every factor is at least 1. A cell within `r_i` of the
//! robot itself stays passable (at a high factor), so that a robot already too near an obstacle
//! can leave. The goal is any passable cell whose centre lies within the goal's acceptance
//! radius.

use super::distances::{DistanceFields, Field};
use super::grid::{CellState, GridGeometry, OccupancyGrid};
use nalgebra::Point2;
use pathfinding::prelude::astar;

/// The factor of a cell the robot must cross to leave a too-near obstacle.
const ESCAPE_FACTOR: f32 = 6.0;
/// The factor `s` of a cell within `r_i` of a suspect one: crossing a suspect obstacle's
/// inflated band (about 200 mm) costs as much as two metres of free floor, so the robot goes
/// to look only where the way round is longer.
const SUSPECT_FACTOR: f32 = 10.0;
/// Half the width of a 32-direction sector at 600 mm: how far from its mark an obstacle seen
/// from afar may stand, mm.
const SUSPECT_SPREAD_MM: f32 = 60.0;
/// Weight `w` of the comfort band.
const COMFORT_WEIGHT: f32 = 3.0;
/// Step costs are integers: this many units a millimetre.
const UNITS_PER_MM: f64 = 8.0;

/// What the planner makes of a suspect cell (seen occupied only from afar).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Suspects {
    /// Passable at the factor `SUSPECT_FACTOR` within `r_i` of it: the way the robot drives.
    Costly,
    /// Blocked like a confirmed cell, and spread by `SUSPECT_SPREAD_MM`: the map as it would
    /// be if every far mark stood for an obstacle anywhere within half a sector of it.
    Blocked,
}

/// How the planner weighs the map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostSettings {
    /// `r_i`: nearer than this to a blocked cell is impassable, mm.
    pub inflated_mm: f64,
    /// `c`: the band beyond `r_i` where paths pay to keep off obstacles, mm.
    pub comfort_mm: f64,
    /// `u`: the extra factor of an unknown cell.
    pub unknown_cost: f64,
}

/// The grid priced for planning: each cell's factor, `None` where impassable.
#[derive(Debug, Clone)]
pub struct CostMap {
    geometry: GridGeometry,
    factor: Vec<Option<f32>>,
    /// Each cell's distance to the nearest blocked cell and to the nearest suspect cell, mm
    /// (`None`: there is none).
    blocked_mm: Field,
    suspect_mm: Field,
}

impl CostMap {
    /// Prices `grid` for a robot at `robot` (world mm), adding `penalty` (one value a cell),
    /// with its suspect cells taken as `suspects` says.
    pub fn new(
        grid: &OccupancyGrid,
        settings: &CostSettings,
        penalty: &[f32],
        robot: Point2<f64>,
        suspects: Suspects,
    ) -> Self {
        let fields = DistanceFields::of(grid);
        Self::priced(grid, &fields, settings, penalty, robot, suspects)
    }

    /// [`Self::new`] with the grid's distance fields already made (`fields`, up to date with
    /// `grid`): a navigator keeps them between replans.
    pub fn priced(
        grid: &OccupancyGrid,
        fields: &DistanceFields,
        settings: &CostSettings,
        penalty: &[f32],
        robot: Point2<f64>,
        suspects: Suspects,
    ) -> Self {
        let g = *grid.geometry();
        let ri = settings.inflated_mm as f32;
        let blocked = fields.blocked_mm().clone();
        let suspect = fields.suspect_mm().clone();
        let at = |v: &Field, i: usize| v.as_ref().map_or(f32::INFINITY, |v| v[i]);
        let comfort = settings.comfort_mm.max(1e-6) as f32;
        let escape2 =
            ((settings.inflated_mm + g.cell_mm) * (settings.inflated_mm + g.cell_mm)) as f32;
        let factor = (0..g.len())
            .map(|i| {
                let mut d = at(&blocked, i);
                if suspects == Suspects::Blocked {
                    d = d.min((at(&suspect, i) - SUSPECT_SPREAD_MM).max(0.0));
                }
                let p = penalty.get(i).copied().unwrap_or(0.0);
                if p.is_infinite() {
                    return None;
                }
                let mut f = 1.0 + p;
                if grid.state(i) == CellState::Unknown {
                    f += settings.unknown_cost as f32;
                }
                if suspects == Suspects::Costly && at(&suspect, i) < ri {
                    f += SUSPECT_FACTOR;
                }
                if d < ri {
                    let near_robot = (g.centre(i) - robot).norm_squared() as f32 <= escape2;
                    return (near_robot && d > 0.0).then_some(f + ESCAPE_FACTOR);
                }
                let x = 1.0 - (d - ri) / comfort;
                if x > 0.0 {
                    f += COMFORT_WEIGHT * x * x;
                }
                Some(f)
            })
            .collect();
        Self {
            geometry: g,
            factor,
            blocked_mm: blocked,
            suspect_mm: suspect,
        }
    }

    /// The distance from the cell holding `p` to the nearest blocked or suspect cell, mm
    /// (infinite outside the grid or where none is).
    pub fn room_at(&self, p: Point2<f64>) -> f64 {
        let at = |v: &Field, i: usize| v.as_ref().map_or(f32::INFINITY, |v| v[i]);
        self.geometry.cell_of(p).map_or(f64::INFINITY, |i| {
            f64::from(at(&self.blocked_mm, i).min(at(&self.suspect_mm, i)))
        })
    }

    /// Where the grid lies.
    pub fn geometry(&self) -> &GridGeometry {
        &self.geometry
    }

    /// Whether cell `i` can be crossed.
    pub fn passable(&self, i: usize) -> bool {
        self.factor[i].is_some()
    }

    /// The factor of the cell holding `p` (`None` outside the grid or impassable).
    pub fn factor_at(&self, p: Point2<f64>) -> Option<f32> {
        self.geometry.cell_of(p).and_then(|i| self.factor[i])
    }

    /// Whether the straight line `a`-`b` crosses only passable cells (sampled every half cell).
    pub fn line_clear(&self, a: Point2<f64>, b: Point2<f64>) -> bool {
        let len = (b - a).norm();
        let n = (len / (0.5 * self.geometry.cell_mm)).ceil().max(1.0) as usize;
        (0..=n).all(|k| {
            self.factor_at(a + (b - a) * (k as f64 / n as f64))
                .is_some()
        })
    }

    /// Whether the goal `to` lies in a closed pocket of fewer than `limit` passable cells (the
    /// cells within `accept_mm` of it and every cell connected to them, 8-connected) that does
    /// not hold `from`: false when the pocket is larger, holds `from`, or no cell near the goal
    /// is passable (nothing to say then).
    pub fn goal_in_pocket(
        &self,
        from: Point2<f64>,
        to: Point2<f64>,
        accept_mm: f64,
        limit: usize,
    ) -> bool {
        let g = self.geometry;
        let accept = accept_mm.max(0.5 * g.cell_mm);
        let r = nalgebra::Vector2::repeat(accept);
        let (Some(lo), Some(hi)) = (g.coords_of(to - r), g.coords_of(to + r)) else {
            return false;
        };
        let mut seen = std::collections::HashSet::new();
        let mut queue: std::collections::VecDeque<usize> = (lo.1..=hi.1)
            .flat_map(|y| (lo.0..=hi.0).map(move |x| y * g.width + x))
            .filter(|&i| self.factor[i].is_some() && (g.centre(i) - to).norm() <= accept)
            .collect();
        if queue.is_empty() {
            return false;
        }
        seen.extend(queue.iter().copied());
        let robot = g.cell_of(from);
        while let Some(i) = queue.pop_front() {
            if Some(i) == robot || seen.len() >= limit {
                return false;
            }
            let (x, y) = ((i % g.width) as i64, (i / g.width) as i64);
            for (dx, dy) in NEIGHBOURS {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= g.width as i64 || ny >= g.height as i64 {
                    continue;
                }
                let j = (ny * g.width as i64 + nx) as usize;
                if self.factor[j].is_some() && seen.insert(j) {
                    queue.push_back(j);
                }
            }
        }
        true
    }

    /// The cheapest path from `from` to within `accept_mm` of `to`: cell centres from the
    /// robot's cell to the last, with its cost in mm-equivalents; `None` when no passable
    /// route exists.
    pub fn plan(
        &self,
        from: Point2<f64>,
        to: Point2<f64>,
        accept_mm: f64,
    ) -> Option<(Vec<usize>, f64)> {
        let g = self.geometry;
        let start = g.cell_of(from)?;
        let (w, h) = (g.width as i64, g.height as i64);
        let accept = accept_mm.max(0.5 * g.cell_mm);
        let straight = (g.cell_mm * UNITS_PER_MM).round() as u64;
        let diagonal = (g.cell_mm * std::f64::consts::SQRT_2 * UNITS_PER_MM).round() as u64;
        let goal_cells = |i: usize| {
            let c = g.centre(i);
            (((to.x - c.x).abs(), (to.y - c.y).abs()), c)
        };
        let heuristic = |i: &usize| {
            let ((dx, dy), _) = goal_cells(*i);
            let (lo, hi) = (dx.min(dy), dx.max(dy));
            let octile = (hi - lo) + lo * std::f64::consts::SQRT_2 - accept;
            (octile.max(0.0) * UNITS_PER_MM) as u64
        };
        let factor = &self.factor;
        let successors = |&i: &usize| {
            let (x, y) = ((i % g.width) as i64, (i / g.width) as i64);
            let fi = factor[i].unwrap_or(ESCAPE_FACTOR);
            NEIGHBOURS.iter().filter_map(move |&(dx, dy)| {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w || ny >= h {
                    return None;
                }
                let j = (ny * w + nx) as usize;
                let fj = factor[j]?;
                let step = if dx != 0 && dy != 0 {
                    diagonal
                } else {
                    straight
                };
                Some((j, (step as f32 * 0.5 * (fi + fj)).round() as u64))
            })
        };
        let success = |i: &usize| (g.centre(*i) - to).norm() <= accept && factor[*i].is_some();
        let (cells, cost) = astar(&start, successors, heuristic, success)?;
        Some((cells, cost as f64 / UNITS_PER_MM))
    }

    /// The path through `cells` pulled taut: from `from`, each vertex the farthest later cell
    /// centre the straight line reaches over passable cells, ending at `to` when the last cell
    /// sees it.
    pub fn taut(&self, from: Point2<f64>, cells: &[usize], to: Point2<f64>) -> Vec<Point2<f64>> {
        let g = self.geometry;
        let mut points: Vec<Point2<f64>> = cells.iter().map(|&i| g.centre(i)).collect();
        if let Some(&last) = points.last()
            && self.line_clear(last, to)
        {
            points.push(to);
        }
        let mut out = vec![from];
        let mut k = 0;
        while k < points.len() {
            let here = *out.last().unwrap_or(&from);
            let mut far = k;
            for m in (k..points.len()).rev() {
                if self.line_clear(here, points[m]) {
                    far = m;
                    break;
                }
            }
            out.push(points[far]);
            k = far + 1;
        }
        out
    }
}

/// The 8 neighbours of a cell.
const NEIGHBOURS: [(i64, i64); 8] = [
    (1, 0),
    (-1, 0),
    (0, 1),
    (0, -1),
    (1, 1),
    (1, -1),
    (-1, 1),
    (-1, -1),
];

/// The length of a polyline, mm.
pub fn length(points: &[Point2<f64>]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{MapSegment, WorldMap};
    use crate::navigation::config::PlannerConfig;
    use nalgebra::Vector2;

    fn settings() -> CostSettings {
        CostSettings {
            inflated_mm: 100.0,
            comfort_mm: 150.0,
            unknown_cost: 1.0,
        }
    }

    /// `grid` priced the way the robot drives, for a robot at `robot`.
    fn costly(grid: &OccupancyGrid, robot: Point2<f64>) -> CostMap {
        CostMap::new(grid, &settings(), &[], robot, Suspects::Costly)
    }

    fn walled(walls: &[([f64; 2], [f64; 2])]) -> OccupancyGrid {
        let map = WorldMap {
            bounds: walls
                .iter()
                .map(|(a, b)| MapSegment {
                    from_mm: Point2::new(a[0], a[1]),
                    to_mm: Point2::new(b[0], b[1]),
                    half_thickness_mm: 10.0,
                })
                .collect(),
            ..WorldMap::default()
        };
        let geo = GridGeometry::covering(
            Point2::new(-1500.0, -1500.0),
            Point2::new(1500.0, 1500.0),
            20.0,
        );
        OccupancyGrid::new(geo, &map, &PlannerConfig::default())
    }

    #[test]
    fn goes_round_a_wall_and_keeps_its_inflated_distance() {
        // A wall across x = 0 from y = -1500 to y = 600: the way is round its end.
        let grid = walled(&[([0.0, -1500.0], [0.0, 600.0])]);
        let costs = costly(&grid, Point2::new(-800.0, 0.0));
        let from = Point2::new(-800.0, 0.0);
        let to = Point2::new(800.0, 0.0);
        let (cells, cost) = costs
            .plan(from, to, 50.0)
            .expect("a route round the wall's end");
        let path = costs.taut(from, &cells, to);
        assert!(
            path.iter().any(|p| p.y > 600.0 + 100.0),
            "passes beyond the wall's end: {path:?}"
        );
        for p in &path {
            assert!(
                p.x.abs() >= 100.0 || p.y >= 600.0 + 100.0,
                "every vertex keeps the inflated distance: {p:?}"
            );
        }
        assert!(
            cost >= length(&path) - 1.0,
            "cost {cost} below the path's length"
        );
        assert_eq!(*path.last().unwrap(), to);
    }

    #[test]
    fn a_gap_narrower_than_the_inflated_robot_is_closed_and_a_wider_one_open() {
        // A wall across x = 0 with a gap between y = -g/2 and y = g/2, nothing else.
        for (gap, open) in [(180.0, false), (260.0, true)] {
            let h = gap / 2.0 + 10.0;
            let grid = walled(&[([0.0, -1500.0], [0.0, -h]), ([0.0, h], [0.0, 1500.0])]);
            let costs = costly(&grid, Point2::new(-800.0, 0.0));
            let found = costs.plan(Point2::new(-800.0, 0.0), Point2::new(800.0, 0.0), 50.0);
            assert_eq!(found.is_some(), open, "gap {gap} mm");
        }
    }

    /// A grid free of walls with cells marked occupied along the segment `a`-`b`.
    fn marked(a: [f64; 2], b: [f64; 2], confirmed: bool) -> OccupancyGrid {
        let mut grid = walled(&[]);
        let (a, b) = (Point2::new(a[0], a[1]), Point2::new(b[0], b[1]));
        for k in 0..=200 {
            grid.mark_occupied(a + (b - a) * (k as f64 / 200.0), confirmed);
        }
        grid
    }

    #[test]
    fn a_wall_seen_only_from_afar_is_crossed_at_a_cost_and_blocks_on_the_strict_map() {
        // A line of suspect cells across x = 0 from y = -1500 to 1500.
        let grid = marked([0.0, -1500.0], [0.0, 1500.0], false);
        let from = Point2::new(-800.0, 0.0);
        let to = Point2::new(800.0, 0.0);
        let (_, cost) = costly(&grid, from)
            .plan(from, to, 50.0)
            .expect("through the suspect wall");
        assert!(
            cost > 1600.0 + 1000.0,
            "crossing the suspect band costs: {cost}"
        );
        let strict = CostMap::new(&grid, &settings(), &[], from, Suspects::Blocked);
        assert!(strict.plan(from, to, 50.0).is_none());
        // Seen from near, the same wall blocks the robot's own map.
        let grid = marked([0.0, -1500.0], [0.0, 1500.0], true);
        let costs = costly(&grid, from);
        assert!(costs.plan(from, to, 50.0).is_none());
    }

    #[test]
    fn a_goal_ringed_by_marks_is_in_a_pocket_and_one_behind_a_long_barrier_is_not() {
        let to = Point2::new(600.0, 0.0);
        let from = Point2::new(-800.0, 0.0);
        let mut grid = walled(&[]);
        for k in 0..360 {
            let a = (k as f64).to_radians();
            grid.mark_occupied(to + Vector2::new(a.cos(), a.sin()) * 300.0, false);
        }
        let strict = CostMap::new(&grid, &settings(), &[], from, Suspects::Blocked);
        assert!(strict.goal_in_pocket(from, to, 50.0, 2500));
        assert!(
            !strict.goal_in_pocket(to + Vector2::new(50.0, 0.0), to, 50.0, 2500),
            "the robot inside the ring"
        );
        // A barrier across the whole grid: no route, but the goal's side is no pocket.
        let grid = marked([0.0, -1500.0], [0.0, 1500.0], false);
        let strict = CostMap::new(&grid, &settings(), &[], from, Suspects::Blocked);
        assert!(strict.plan(from, to, 50.0).is_none());
        assert!(!strict.goal_in_pocket(from, to, 50.0, 2500));
    }

    #[test]
    fn unknown_cells_cost_more_than_known_free_ones() {
        let geo =
            GridGeometry::covering(Point2::new(-500.0, -500.0), Point2::new(500.0, 500.0), 20.0);
        let grid = OccupancyGrid::new(geo, &WorldMap::default(), &PlannerConfig::default());
        let robot = Point2::new(-400.0, 0.0);
        let cheap = CostMap::new(
            &grid,
            &CostSettings {
                unknown_cost: 0.0,
                ..settings()
            },
            &[],
            robot,
            Suspects::Costly,
        );
        let dear = costly(&grid, robot);
        let to = Point2::new(400.0, 0.0);
        let (_, c0) = cheap.plan(robot, to, 20.0).unwrap();
        let (_, c1) = dear.plan(robot, to, 20.0).unwrap();
        assert!(c1 > 1.8 * c0, "unknown {c1} vs free {c0}");
    }
}
