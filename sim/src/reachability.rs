//! Truth-side reachability: whether a robot's body, a disc, can roll on the true world from its
//! start through each of its targets (waypoints, then the goal), and how wide the widest such
//! route is. A run computes it once from the world's static solids, so that its summary tells
//! a goal no robot could have reached from one this robot failed to reach.
//!
//! The method:
//! - A grid of 10 mm cells (coarser only where that would make over 400 000 cells) covers the
//!   floor region (or, without one, the solids), the start and the targets, padded by a robot's
//!   diameter. Each cell holds the exact distance from its centre to the nearest solid
//!   ([`SolidShape::distance_mm`]; farther than [`FAR_MM`] counts as that), the solids a block
//!   of cells could be nearest to being picked first so that a cell measures only a few.
//! - A route moves between 8-connected cells whose clearance is at least the robot's radius.
//!   Its width is the least clearance of the cells it enters (its bottleneck); the margin is
//!   that width less the radius: the least distance from the body's edge to any solid.
//! - A target is reached when the body's centre enters its tolerance circle: its region is the
//!   cells whose centre lies within the tolerance (the cell holding the target when no centre
//!   does).
//! - Dijkstra's search (`pathfinding`) with the bottleneck as the cost finds the widest route
//!   from the start to each cell. The solids stand still, so the cells reachable at a width
//!   form one connected set, and a route through the targets in their order at that width
//!   exists exactly when every target's region meets the start's set: the margin of the whole
//!   route is the least of the targets' widest routes.
//! - The start: its cell is always open (a robot started against a wall is where it is), and
//!   its own clearance counts at its exact position, floored at the radius: a robot started
//!   touching a solid, or into it by less than about a cell, has a margin of 0, not an unreachable
//!   goal. The cells of the start's neighbourhood and of the targets' regions count like every
//!   other cell of the route.
//!
//! Other robots are not solids here: they move, and the route is about the world. The margin
//! is good to about a cell: a diagonal step between two open cells passes up to half a cell's
//! diagonal from both centres.

use crate::SimError;
use crate::layout::Layout;
use crate::shapes::SolidShape;
use nalgebra::{Point2, Vector2};
use pathfinding::num_traits::Zero;
use pathfinding::prelude::dijkstra_reach;
use std::ops::Add;

/// Side of a grid cell, mm (larger only for floors that would need over [`MAX_CELLS`]).
pub const CELL_MM: f64 = 10.0;
/// Most cells of the grid.
pub const MAX_CELLS: usize = 400_000;
/// Clearance beyond this counts as this, mm (a world without solids is this wide).
pub const FAR_MM: f64 = 10_000.0;
/// Side of the blocks of cells whose nearest solids are picked together, cells.
const BLOCK: usize = 8;

/// A place the robot must reach: its centre within `tolerance_mm` of `point_mm`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Target {
    /// The point, world mm.
    pub point_mm: Point2<f64>,
    /// How near the robot's centre must come, mm.
    pub tolerance_mm: f64,
}

/// Whether the route can be driven on the true world, and how wide it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reachability {
    /// The body can roll from the start through every target's region in order.
    pub reachable: bool,
    /// The widest route's least distance from the body's edge to a solid, mm (`None` when not
    /// reachable even touching).
    pub margin_mm: Option<f64>,
    /// Side of the grid's cells, mm: the margin's resolution.
    pub cell_mm: f64,
}

/// Whether a disc of `radius_mm` can roll from `start_mm` through `targets` in order (the last
/// the goal) among `layout`'s solids, and the widest route's margin (see the module's
/// documentation). Errors on a radius, point or tolerance that is not a finite number of the
/// right sign, or no target.
pub fn reachability(
    layout: &Layout,
    radius_mm: f64,
    start_mm: Point2<f64>,
    targets: &[Target],
) -> Result<Reachability, SimError> {
    check(radius_mm, start_mm, targets)?;
    let footprints: Vec<Footprint> = layout
        .solids()
        .iter()
        .map(|s| Footprint::of(&s.shape))
        .collect();
    let mut points = vec![start_mm];
    points.extend(targets.iter().map(|t| t.point_mm));
    let grid = Grid::new(
        layout,
        &points,
        2.0 * radius_mm + 2.0 * CELL_MM,
        &footprints,
    );
    let start = grid.index(start_mm);
    let regions: Vec<Vec<usize>> = targets.iter().map(|t| grid.region(t)).collect();
    let Some(widest_mm) = widest_mm(&grid, radius_mm, start, &regions) else {
        return Ok(Reachability {
            reachable: false,
            margin_mm: None,
            cell_mm: grid.cell_mm,
        });
    };
    let at_start = nearest_mm(&footprints, start_mm).max(radius_mm);
    Ok(Reachability {
        reachable: true,
        margin_mm: Some(widest_mm.min(at_start) - radius_mm),
        cell_mm: grid.cell_mm,
    })
}

/// The inputs' problems, the first found.
fn check(radius_mm: f64, start_mm: Point2<f64>, targets: &[Target]) -> Result<(), SimError> {
    let bad = |what: String| Err(SimError::Invalid(format!("reachability: {what}")));
    if !(radius_mm.is_finite() && radius_mm > 0.0) {
        return bad(format!("radius_mm = {radius_mm} must be > 0"));
    }
    if !(start_mm.x.is_finite() && start_mm.y.is_finite()) {
        return bad(format!("start {start_mm} is not a point"));
    }
    if targets.is_empty() {
        return bad("no target".into());
    }
    for (k, t) in targets.iter().enumerate() {
        let point = t.point_mm.x.is_finite() && t.point_mm.y.is_finite();
        if !(point && t.tolerance_mm.is_finite() && t.tolerance_mm >= 0.0) {
            return bad(format!(
                "target {k} at {} within {} mm: a point and a tolerance >= 0",
                t.point_mm, t.tolerance_mm
            ));
        }
    }
    Ok(())
}

/// A solid's footprint ready for many distance queries (a box's rotation computed once).
#[derive(Debug, Clone, Copy)]
enum Footprint {
    /// An oriented rectangle: centre, cosine and sine of its rotation, half sides.
    Box {
        center_mm: Point2<f64>,
        cos: f64,
        sin: f64,
        half_mm: Vector2<f64>,
    },
    /// Any other shape, measured by its own distance.
    Other(SolidShape),
}

impl Footprint {
    fn of(shape: &SolidShape) -> Self {
        match *shape {
            SolidShape::Box {
                center_mm,
                half_extents_mm,
                angle_rad,
            } => {
                let (sin, cos) = angle_rad.sin_cos();
                Self::Box {
                    center_mm,
                    cos,
                    sin,
                    half_mm: half_extents_mm,
                }
            }
            other => Self::Other(other),
        }
    }

    /// Signed distance from `p` to the footprint (negative inside), as
    /// [`SolidShape::distance_mm`].
    fn distance_mm(&self, p: Point2<f64>) -> f64 {
        match self {
            Self::Box {
                center_mm,
                cos,
                sin,
                half_mm,
            } => {
                let d = p - center_mm;
                let q = Vector2::new(
                    (cos * d.x + sin * d.y).abs() - half_mm.x,
                    (-sin * d.x + cos * d.y).abs() - half_mm.y,
                );
                Vector2::new(q.x.max(0.0), q.y.max(0.0)).norm() + q.x.max(q.y).min(0.0)
            }
            Self::Other(shape) => shape.distance_mm(p),
        }
    }

    /// The corners of a box around the footprint.
    fn bounds(&self) -> [Point2<f64>; 2] {
        let around = |c: Point2<f64>, h: Vector2<f64>| [c - h, c + h];
        match *self {
            Self::Box {
                center_mm,
                cos,
                sin,
                half_mm,
            } => around(
                center_mm,
                Vector2::new(
                    cos.abs() * half_mm.x + sin.abs() * half_mm.y,
                    sin.abs() * half_mm.x + cos.abs() * half_mm.y,
                ),
            ),
            Self::Other(SolidShape::Cylinder {
                center_mm,
                radius_mm,
            }) => around(center_mm, Vector2::repeat(radius_mm)),
            Self::Other(SolidShape::Quad { corners_mm }) => span(&corners_mm),
            Self::Other(SolidShape::Box { center_mm, .. }) => [center_mm, center_mm],
        }
    }
}

/// Distance from `p` to the nearest of `footprints`, at most [`FAR_MM`].
fn nearest_mm(footprints: &[Footprint], p: Point2<f64>) -> f64 {
    footprints
        .iter()
        .map(|f| f.distance_mm(p))
        .fold(FAR_MM, f64::min)
}

/// The corners of the box around `points` (`[+inf, -inf]` for none).
fn span(points: &[Point2<f64>]) -> [Point2<f64>; 2] {
    let inf = f64::INFINITY;
    points.iter().fold(
        [Point2::new(inf, inf), Point2::new(-inf, -inf)],
        |[lo, hi], p| {
            [
                Point2::new(lo.x.min(p.x), lo.y.min(p.y)),
                Point2::new(hi.x.max(p.x), hi.y.max(p.y)),
            ]
        },
    )
}

/// Cells over the world, each with its clearance: the distance from its centre to the nearest
/// solid.
struct Grid {
    /// Corner of cell (0, 0), world mm.
    min_mm: Point2<f64>,
    /// Side of a cell.
    cell_mm: f64,
    /// Cells along x.
    width: usize,
    /// Cells along y.
    height: usize,
    /// Clearance of each cell, row after row.
    clearance_mm: Vec<f64>,
}

impl Grid {
    /// The grid over `layout`'s floor region (its solids without one) and `points`, padded by
    /// `pad_mm`, with each cell's clearance among `footprints`.
    fn new(layout: &Layout, points: &[Point2<f64>], pad_mm: f64, footprints: &[Footprint]) -> Self {
        let mut corners: Vec<Point2<f64>> = points.to_vec();
        let floor = layout.all_floor_rects();
        for r in &floor {
            let (s, c) = r.angle_deg.to_radians().sin_cos();
            let h = Vector2::new(r.size_mm[0], r.size_mm[1]) / 2.0;
            let e = Vector2::new(c.abs() * h.x + s.abs() * h.y, s.abs() * h.x + c.abs() * h.y);
            let centre = Point2::from(r.center_mm);
            corners.extend([centre - e, centre + e]);
        }
        if floor.is_empty() {
            corners.extend(footprints.iter().flat_map(Footprint::bounds));
        }
        let [lo, hi] = span(&corners);
        let pad = Vector2::repeat(pad_mm);
        let (lo, size) = (lo - pad, hi - lo + 2.0 * pad);
        let cell_mm = CELL_MM.max((size.x * size.y / MAX_CELLS as f64).sqrt());
        let width = ((size.x / cell_mm).ceil() as usize).max(1);
        let height = ((size.y / cell_mm).ceil() as usize).max(1);
        let mut grid = Self {
            min_mm: lo,
            cell_mm,
            width,
            height,
            clearance_mm: vec![FAR_MM; width * height],
        };
        grid.measure(footprints);
        grid
    }

    /// Centre of cell (x, y).
    fn centre(&self, x: usize, y: usize) -> Point2<f64> {
        self.min_mm + Vector2::new(x as f64 + 0.5, y as f64 + 0.5) * self.cell_mm
    }

    /// The cell holding `p` (the nearest edge cell for a point outside).
    fn index(&self, p: Point2<f64>) -> usize {
        let at = (p - self.min_mm) / self.cell_mm;
        let x = at.x.floor().clamp(0.0, (self.width - 1) as f64) as usize;
        let y = at.y.floor().clamp(0.0, (self.height - 1) as f64) as usize;
        y * self.width + x
    }

    /// Each cell's clearance, block by block: the solids nearest the block's centre, and those
    /// within the block's diameter of being as near, are the only ones a cell of the block can
    /// be nearest to (a distance changes by at most the step).
    fn measure(&mut self, footprints: &[Footprint]) {
        for by in (0..self.height).step_by(BLOCK) {
            for bx in (0..self.width).step_by(BLOCK) {
                let (x1, y1) = ((bx + BLOCK).min(self.width), (by + BLOCK).min(self.height));
                let (a, b) = (self.centre(bx, by), self.centre(x1 - 1, y1 - 1));
                let mid = a + (b - a) / 2.0;
                let half = (b - a).norm() / 2.0;
                let d: Vec<f64> = footprints.iter().map(|f| f.distance_mm(mid)).collect();
                let least = d.iter().copied().fold(f64::INFINITY, f64::min);
                let near: Vec<Footprint> = footprints
                    .iter()
                    .zip(&d)
                    .filter(|&(_, &d)| d <= least + 2.0 * half)
                    .map(|(f, _)| *f)
                    .collect();
                for y in by..y1 {
                    for x in bx..x1 {
                        self.clearance_mm[y * self.width + x] =
                            nearest_mm(&near, self.centre(x, y));
                    }
                }
            }
        }
    }

    /// The cells of `target`'s region: those whose centre lies within its tolerance, or the
    /// cell holding it when none does; sorted.
    fn region(&self, target: &Target) -> Vec<usize> {
        let (p, r) = (target.point_mm, target.tolerance_mm);
        let lo = self.index(p - Vector2::repeat(r));
        let hi = self.index(p + Vector2::repeat(r));
        let mut cells = Vec::new();
        for y in lo / self.width..=hi / self.width {
            for x in lo % self.width..=hi % self.width {
                if (self.centre(x, y) - p).norm() <= r {
                    cells.push(y * self.width + x);
                }
            }
        }
        if cells.is_empty() {
            cells.push(self.index(p));
        }
        cells
    }

    /// The 8 neighbours of cell `i` that lie on the grid.
    fn neighbours(&self, i: usize) -> impl Iterator<Item = usize> + use<> {
        let (x, y) = ((i % self.width) as isize, (i / self.width) as isize);
        let (w, h) = (self.width as isize, self.height as isize);
        let mut out = [None; 8];
        let steps = [
            (-1, -1),
            (0, -1),
            (1, -1),
            (-1, 0),
            (1, 0),
            (-1, 1),
            (0, 1),
            (1, 1),
        ];
        for (slot, (dx, dy)) in out.iter_mut().zip(steps) {
            let (nx, ny) = (x + dx, y + dy);
            if (0..w).contains(&nx) && (0..h).contains(&ny) {
                *slot = Some((ny * w + nx) as usize);
            }
        }
        out.into_iter().flatten()
    }
}

/// How narrow a route is, as Dijkstra's cost: minus its least clearance in micrometres, so
/// that the widest route is the cheapest; a step "adds" by keeping the narrower. Zero is a
/// route with no cell yet (infinitely wide).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Narrowness(i64);

impl Narrowness {
    fn of_cell(clearance_mm: f64) -> Self {
        Self(-(clearance_mm * 1000.0).round() as i64)
    }

    /// The route's least clearance, mm ([`FAR_MM`] for a route with no cell).
    fn clearance_mm(self) -> f64 {
        if self.is_zero() {
            FAR_MM
        } else {
            -(self.0 as f64) / 1000.0
        }
    }
}

impl Add for Narrowness {
    type Output = Self;

    /// The route continued by a step: as narrow as its narrower part.
    fn add(self, step: Self) -> Self {
        self.max(step)
    }
}

impl Zero for Narrowness {
    fn zero() -> Self {
        Self(i64::MIN)
    }

    fn is_zero(&self) -> bool {
        self.0 == i64::MIN
    }
}

/// The least over `regions` of the widest route's clearance from cell `start` into the
/// region, through cells at least `radius_mm` clear (`None` when a region cannot be entered).
/// Dijkstra's search visits the cells widest route first, so a region's first cell visited
/// gives its widest route, and the search stops once every region has one.
fn widest_mm(grid: &Grid, radius_mm: f64, start: usize, regions: &[Vec<usize>]) -> Option<f64> {
    let open = |i: &usize| grid.clearance_mm[*i] >= radius_mm;
    let steps = |&i: &usize| {
        grid.neighbours(i)
            .filter(open)
            .map(|j| (j, Narrowness::of_cell(grid.clearance_mm[j])))
    };
    let mut found: Vec<Option<Narrowness>> = vec![None; regions.len()];
    let mut left = regions.len();
    for item in dijkstra_reach(&start, steps) {
        for (k, region) in regions.iter().enumerate() {
            if found[k].is_none() && region.binary_search(&item.node).is_ok() {
                found[k] = Some(item.total_cost);
                left -= 1;
            }
        }
        if left == 0 {
            break;
        }
    }
    let narrowest = found.into_iter().collect::<Option<Vec<_>>>()?;
    narrowest.into_iter().max().map(Narrowness::clearance_mm)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::Rgb;
    use crate::{Cube, FieldSpec, Wall};

    fn field(cubes: Vec<Cube>, walls: Vec<Wall>) -> Layout {
        Layout {
            field: Some(FieldSpec::default()),
            cubes,
            walls,
            ..Layout::default()
        }
    }

    fn cube(x: f64, y: f64) -> Cube {
        Cube {
            center_mm: [x, y],
            size_mm: 130.0,
            angle_deg: 0.0,
            rgb: Rgb([40, 40, 40]),
        }
    }

    fn goal(x: f64, y: f64) -> Target {
        Target {
            point_mm: Point2::new(x, y),
            tolerance_mm: 100.0,
        }
    }

    #[test]
    fn the_open_field_is_as_wide_as_half_the_field_less_the_radius() {
        // Along the centre line, farther than 762.5 mm from the ends' walls.
        let r = reachability(
            &field(vec![], vec![]),
            90.0,
            Point2::new(-500.0, 0.0),
            &[goal(500.0, 0.0)],
        )
        .unwrap();
        assert!(r.reachable);
        assert_eq!(r.cell_mm, CELL_MM);
        let m = r.margin_mm.unwrap();
        assert!((m - (762.5 - 90.0)).abs() <= CELL_MM, "{m}");
        // Started 30 mm from the side wall: the start caps the margin at 30 mm, honestly.
        let near = reachability(
            &field(vec![], vec![]),
            90.0,
            Point2::new(0.0, 642.5),
            &[goal(800.0, 0.0)],
        )
        .unwrap();
        assert!((near.margin_mm.unwrap() - 30.0).abs() < 1e-9, "{near:?}");
        // Started touching the wall, or into it by less than about a cell: reachable, no margin.
        for y in [672.5, 677.5] {
            let touching = reachability(
                &field(vec![], vec![]),
                90.0,
                Point2::new(0.0, y),
                &[goal(800.0, 0.0)],
            )
            .unwrap();
            assert_eq!(touching.margin_mm, Some(0.0), "{y}");
        }
    }

    /// A square ring of 16 touching cubes around the goal: closed, the goal cannot be reached;
    /// two side cubes taken out leave a door 260 mm wide, 40 mm on each side of the robot.
    #[test]
    fn a_goal_in_a_closed_ring_of_cubes_is_unreachable() {
        let mut ring = Vec::new();
        for k in -2i32..=2 {
            let s = 130.0 * f64::from(k);
            ring.extend([cube(s, -260.0), cube(s, 260.0)]);
            if k.abs() < 2 {
                ring.extend([cube(-260.0, s), cube(260.0, s)]);
            }
        }
        assert_eq!(ring.len(), 16);
        let start = Point2::new(-900.0, 0.0);
        let closed = reachability(&field(ring.clone(), vec![]), 90.0, start, &[goal(0.0, 0.0)]);
        assert_eq!(closed.unwrap().margin_mm, None);
        // The ring's cubes on x = 260 at y = 0 and 130: a door from y = -65 to 195.
        ring.retain(|c| !(c.center_mm[0] == 260.0 && [0.0, 130.0].contains(&c.center_mm[1])));
        let open = reachability(&field(ring, vec![]), 90.0, start, &[goal(0.0, 0.0)]).unwrap();
        assert!(open.reachable);
        let m = open.margin_mm.unwrap();
        assert!((m - 40.0).abs() <= CELL_MM, "{m}");
    }

    /// Walls across the field from each side, and two cubes closing it to a gap of `gap_mm`.
    fn barrier(gap_mm: f64) -> Layout {
        let g = gap_mm / 2.0;
        let wall = |from: f64, to: f64| Wall {
            from_mm: [0.0, from],
            to_mm: [0.0, to],
            thickness_mm: 130.0,
            height_mm: 150.0,
            rgb: Rgb([235, 235, 235]),
        };
        field(
            vec![cube(0.0, -g - 65.0), cube(0.0, g + 65.0)],
            vec![wall(-800.0, -g - 130.0), wall(g + 130.0, 800.0)],
        )
    }

    #[test]
    fn a_gap_as_the_only_route_sets_the_margin() {
        let start = Point2::new(-700.0, 300.0);
        for (gap, radius) in [(300.0, 90.0), (400.0, 90.0), (260.0, 60.0)] {
            let r = reachability(&barrier(gap), radius, start, &[goal(700.0, -300.0)]).unwrap();
            let m = r.margin_mm.unwrap();
            assert!((m - (gap / 2.0 - radius)).abs() <= CELL_MM, "{gap}: {m}");
        }
        let narrow = reachability(&barrier(170.0), 90.0, start, &[goal(700.0, -300.0)]);
        assert!(!narrow.unwrap().reachable, "a gap narrower than the robot");
        // The goal on the start's side: the gap is not on the way.
        let same_side = reachability(&barrier(170.0), 90.0, start, &[goal(-700.0, -300.0)]);
        assert!(same_side.unwrap().margin_mm.unwrap() > 200.0);
    }

    #[test]
    fn targets_are_taken_in_order_and_each_must_be_reached() {
        let start = Point2::new(-700.0, 300.0);
        let (beyond, here) = (goal(700.0, 0.0), goal(-700.0, -300.0));
        // A waypoint beyond a gap the robot cannot pass makes the goal on its side unreachable.
        let r = reachability(&barrier(170.0), 90.0, start, &[beyond, here]).unwrap();
        assert!(!r.reachable);
        // Beyond a gap of 300 mm and back: the gap sets the margin.
        let r = reachability(&barrier(300.0), 90.0, start, &[beyond, here]).unwrap();
        assert!((r.margin_mm.unwrap() - 60.0).abs() <= CELL_MM, "{r:?}");
        // A tolerance no cell centre lies within: the target's own cell.
        let point = Target {
            point_mm: Point2::new(703.0, 2.0),
            tolerance_mm: 0.0,
        };
        let r = reachability(&barrier(300.0), 90.0, start, &[point]).unwrap();
        assert!(r.reachable);
    }

    #[test]
    fn without_a_floor_the_grid_covers_the_solids_and_routes_go_round_them() {
        // A wall between start and goal on an open plane.
        let layout = Layout {
            walls: vec![Wall {
                from_mm: [0.0, -500.0],
                to_mm: [0.0, 500.0],
                thickness_mm: 100.0,
                height_mm: 150.0,
                rgb: Rgb([235, 235, 235]),
            }],
            ..Layout::default()
        };
        // The grid reaches a diameter and two cells beyond the wall's end: the way round is
        // that wide, 200 mm beyond the end, 110 mm beside the robot.
        let r = reachability(&layout, 90.0, Point2::new(-300.0, 0.0), &[goal(300.0, 0.0)]);
        let m = r.unwrap().margin_mm.unwrap();
        assert!((m - 110.0).abs() <= CELL_MM, "{m}");
        let empty = reachability(
            &Layout::default(),
            90.0,
            Point2::origin(),
            &[goal(1.0, 0.0)],
        );
        assert_eq!(empty.unwrap().margin_mm, Some(FAR_MM - 90.0));
    }

    #[test]
    fn bad_input_is_refused() {
        let l = field(vec![], vec![]);
        let p = Point2::origin();
        assert!(reachability(&l, 0.0, p, &[goal(1.0, 0.0)]).is_err());
        assert!(reachability(&l, f64::NAN, p, &[goal(1.0, 0.0)]).is_err());
        assert!(
            reachability(&l, 90.0, Point2::new(f64::INFINITY, 0.0), &[goal(1.0, 0.0)]).is_err()
        );
        assert!(reachability(&l, 90.0, p, &[]).is_err());
        let bad = Target {
            point_mm: p,
            tolerance_mm: -1.0,
        };
        assert!(reachability(&l, 90.0, p, &[bad]).is_err());
    }

    #[test]
    fn prepared_boxes_measure_as_the_shapes_do() {
        let shapes = [
            SolidShape::Box {
                center_mm: Point2::new(100.0, -40.0),
                half_extents_mm: Vector2::new(65.0, 20.0),
                angle_rad: 0.7,
            },
            SolidShape::Cylinder {
                center_mm: Point2::new(-50.0, 10.0),
                radius_mm: 30.0,
            },
        ];
        for s in shapes {
            let f = Footprint::of(&s);
            let [lo, hi] = f.bounds();
            for k in 0..400 {
                let p = Point2::new(
                    -300.0 + 1.5 * f64::from(k),
                    -200.0 + f64::from(k % 37) * 11.0,
                );
                assert!((f.distance_mm(p) - s.distance_mm(p)).abs() < 1e-9, "{p}");
                if s.distance_mm(p) <= 0.0 {
                    assert!(p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y);
                }
            }
        }
    }
}
