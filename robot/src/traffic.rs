//! What the controller's traffic rule ([`omniloop_control::traffic`]) needs of the free space:
//! which directions end on something that may move, and where the unknown begins.
//!
//! The robot tells a wall from a robot by its map: a direction whose obstacle lies where the
//! map has a wall, a goal, a board, a pillar or a cube (by the pose estimate, within the
//! uncertainty of the template's cell and [`TOLERANCE_MM`]) ends on something that stays put;
//! any other obstacle may be another robot, or hide one. Without a pose estimate, every
//! obstacle may move. A direction free throughout ends on the horizon.
//!
//! With [`TrafficConfig::moved_s`] set, an obstacle the map does not explain counts as moving
//! only when it has been seen to move: when it now stands where the robot saw the floor surely
//! free within that time ([`SeenFree`], the floor seen free kept in the odometry frame, so
//! the robot's own motion is taken out). Its face lies no farther than the direction's
//! `front_mm` (it fills at least `1 - r_th` of the first blocked cell), so the floor just
//! beyond that ([`PROBE_MM`]) is under the obstacle; seen surely free a moment ago, the
//! obstacle came there. A robot that stands (one that arrived, or waits its turn) has stood on
//! floor nobody saw free, and is kept at the normal clearance like a wall: the reciprocal
//! half-gap and the rule of the road are for what comes nearer on its own. This is frame
//! differencing with ego-motion compensation (moving-object detection from a moving
//! platform, e.g. Jung and Sukhatme, "Detecting moving objects using a single camera on a
//! mobile robot in an outdoor environment", IAS 2004), on the free-space cells instead of
//! pixels. It errs both ways: a robot moving across the line of sight onto floor that its own
//! body hid is taken to stand until it has moved by about its size (hence [`HOLD_MM`]: near
//! where one was seen to move, an obstacle counts as moving for `moved_s`), and one standing
//! near the blind zone is now and then taken to move (a cell judged free may hold part of a
//! robot; the outer rings' cells, larger than a robot, are not taken as seen free at all).

use crate::config::{MapSegment, WorldMap};
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_control::TrafficConfig;
use omniloop_vision::FreeSpace;
use std::f64::consts::TAU;

/// How far from the map's walls an obstacle seen may lie and still be that wall, mm: room for
/// the pose estimate's error.
pub const TOLERANCE_MM: f64 = 80.0;

/// Where a direction blocked at the template's inner edge puts its point, mm from the centre:
/// at the body, so that the rule keeps the robot from coming any nearer.
const BLIND_MM: f64 = 1.0;

/// Step of the samples along a direction's obstacle band, mm.
const STEP_MM: f64 = 20.0;

/// The free space split for the traffic rule, robot frame.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TrafficPoints {
    /// Points where an obstacle the map does not explain may begin.
    pub moving: Vec<Vector2<f64>>,
    /// Where the unknown begins in the directions free throughout.
    pub horizon: Vec<Vector2<f64>>,
}

/// The robot's map as the traffic rule reads it: everything on it stays put.
#[derive(Debug, Clone, Default)]
pub struct StaticMap {
    segments: Vec<MapSegment>,
    discs: Vec<(Point2<f64>, f64)>,
}

impl StaticMap {
    /// The walls, bounds, boards, boxes and landmarks of `map`.
    pub fn new(map: &WorldMap) -> Self {
        let segments = map
            .segments
            .iter()
            .chain(&map.bounds)
            .chain(&map.boxes)
            .copied()
            .collect();
        let discs = map
            .landmarks
            .iter()
            .map(|l| (l.centre_mm, l.radius_mm))
            .collect();
        Self { segments, discs }
    }

    /// Distance from `p` (world frame) to the nearest surface of the map, mm.
    fn distance_mm(&self, p: Point2<f64>) -> f64 {
        let walls = self.segments.iter().map(|s| {
            let ab = s.to_mm - s.from_mm;
            let len2 = ab.norm_squared();
            let u = if len2 > 0.0 {
                ((p - s.from_mm).dot(&ab) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (p - (s.from_mm + ab * u)).norm() - s.half_thickness_mm
        });
        let discs = self.discs.iter().map(|(c, r)| (p - c).norm() - r);
        walls.chain(discs).fold(f64::INFINITY, f64::min)
    }

    /// The free space `fs` split (see [`TrafficPoints`]), the robot at `pose` (world frame) by
    /// its estimate, or every obstacle taken as one that may move without one; of the
    /// obstacles the map does not explain, only those of the directions `moved` holds for.
    pub fn split(
        &self,
        fs: &FreeSpace,
        pose: Option<&Isometry2<f64>>,
        mut moved: impl FnMut(usize) -> bool,
    ) -> TrafficPoints {
        let mut out = TrafficPoints::default();
        let n = fs.direction_rad.len();
        for j in 0..n {
            let points = fs.clear_points.get(3 * j..3 * j + 3).unwrap_or(&[]);
            let a = fs.direction_rad[j];
            let along = Vector2::new(a.cos(), a.sin());
            if fs.free_mm[j] >= fs.range_mm {
                out.horizon.extend(points.iter().map(|p| p.coords));
                continue;
            }
            let mapped = pose.is_some_and(|pose| {
                self.explains(pose, fs.axis_mm, along, fs.clear_mm[j], fs.front_mm[j])
            });
            if mapped || !moved(j) {
                continue;
            }
            if fs.a[j] == 0 {
                // Blocked at the template's inner edge: something stands in the blind zone, as
                // near as the body's edge for all the camera tells.
                out.moving.push(along * BLIND_MM);
            } else {
                out.moving.extend(points.iter().map(|p| p.coords));
            }
        }
        out
    }

    /// Whether a surface of the map lies along `along` (robot frame, from the sensor axis
    /// `axis`) between `from_mm` and `to_mm` (within the tolerance), the robot at `pose`.
    fn explains(
        &self,
        pose: &Isometry2<f64>,
        axis: Point2<f64>,
        along: Vector2<f64>,
        from_mm: f64,
        to_mm: f64,
    ) -> bool {
        let (lo, hi) = ((from_mm - TOLERANCE_MM).max(0.0), to_mm + TOLERANCE_MM);
        let steps = ((hi - lo) / STEP_MM).ceil().max(1.0) as usize;
        (0..=steps).any(|k| {
            let d = lo + (hi - lo) * k as f64 / steps as f64;
            let p = pose * (axis + along * d);
            self.distance_mm(p) <= TOLERANCE_MM
        })
    }
}

/// Floor farther than this from the sensor axis is not taken as seen free, mm: the outer
/// rings' cells are larger than a robot's footprint (the last, 680 to 1000 mm, holds one
/// whole in less than half of its area), so a robot there may sit in a cell judged free.
pub const SEEN_REACH_MM: f64 = 650.0;
/// Side of a cell of the floor seen free, mm.
const SEEN_CELL_MM: f64 = 25.0;
/// Cells a side of its grid. It wraps round (a cell lives at its indices modulo this), so it
/// follows the robot: 3.2 m a side, more than the 2 m across the template sees.
const SEEN_SIDE: i32 = 128;
/// How deep beyond the farthest place of an obstacle's face its direction is probed, mm: under
/// the obstacle (a robot is 180 mm across), beyond the odometry's drift over a second or two.
pub const PROBE_MM: f64 = 60.0;
/// The probe begins this far beyond the face's farthest place, mm: a cell of the grid whose
/// centre is seen free reaches this far beyond it.
const PROBE_FROM_MM: f64 = 50.0;
/// Step of the probe, mm.
const PROBE_STEP_MM: f64 = 10.0;
/// Samples of the probe that must lie on floor seen free: one alone may be a grid cell
/// at the edge of what was seen.
const PROBE_HITS: usize = 2;

/// The floor seen surely free lately, on a grid in the odometry frame: when each cell was last
/// seen free (each unblocked direction's sector from the template's inner edge to its clear
/// distance).
#[derive(Debug, Clone)]
pub struct SeenFree {
    cells: Vec<(Option<[i32; 2]>, f64)>,
}

impl Default for SeenFree {
    fn default() -> Self {
        Self::new()
    }
}

impl SeenFree {
    /// Nothing seen yet.
    pub fn new() -> Self {
        Self {
            cells: vec![(None, f64::NEG_INFINITY); (SEEN_SIDE * SEEN_SIDE) as usize],
        }
    }

    fn slot(cell: [i32; 2]) -> usize {
        (cell[0].rem_euclid(SEEN_SIDE) * SEEN_SIDE + cell[1].rem_euclid(SEEN_SIDE)) as usize
    }

    fn cell_of(p: Point2<f64>) -> [i32; 2] {
        [
            (p.x / SEEN_CELL_MM).floor() as i32,
            (p.y / SEEN_CELL_MM).floor() as i32,
        ]
    }

    /// Marks the cells whose centres lie surely free in both directions of `fs` whose centre
    /// lines bracket them, the robot at `odo` (odometry frame) at `t_s`.
    pub fn see(&mut self, fs: &FreeSpace, odo: &Isometry2<f64>, t_s: f64) {
        let n = fs.direction_rad.len();
        let reach = (0..n)
            .filter(|&j| fs.a[j] > 0)
            .map(|j| fs.clear_mm[j])
            .fold(0.0, f64::max)
            .min(SEEN_REACH_MM);
        if reach <= 0.0 {
            return;
        }
        let step = TAU / n as f64;
        let axis = odo * fs.axis_mm;
        let lo = Self::cell_of(axis - Vector2::repeat(reach));
        let hi = Self::cell_of(axis + Vector2::repeat(reach));
        for i in lo[0]..=hi[0] {
            for k in lo[1]..=hi[1] {
                let centre = Point2::new(
                    (i as f64 + 0.5) * SEEN_CELL_MM,
                    (k as f64 + 0.5) * SEEN_CELL_MM,
                );
                let rel = odo.inverse_transform_point(&centre) - fs.axis_mm;
                let r = rel.norm();
                if r < fs.inner_mm || r > reach {
                    continue;
                }
                // The two directions whose centre lines bracket the cell's: an obstacle may
                // fill a side of a cell judged free (less than half of it), but then stands in
                // the neighbouring direction too.
                let turns = (rel.y.atan2(rel.x) - fs.direction_rad[0]) / step;
                let lo = turns.floor() as i64;
                let free = [lo, lo + 1].iter().all(|&j| {
                    let j = j.rem_euclid(n as i64) as usize;
                    fs.a[j] > 0 && r <= fs.clear_mm[j]
                });
                if free {
                    self.cells[Self::slot([i, k])] = (Some([i, k]), t_s);
                }
            }
        }
    }

    /// Whether the floor at `p` (odometry frame) was seen free at `since_s` or later.
    fn free_since(&self, p: Point2<f64>, since_s: f64) -> bool {
        let cell = Self::cell_of(p);
        let (c, t) = self.cells[Self::slot(cell)];
        c == Some(cell) && t >= since_s
    }

    /// Whether the obstacle of direction `j` of `fs` (the robot at `odo` at `t_s`) stands where
    /// the floor was seen surely free within `moved_s`: along the direction's centre line,
    /// from the farthest place of its face (`front_mm`) [`PROBE_MM`] on.
    pub fn moved(
        &self,
        fs: &FreeSpace,
        j: usize,
        odo: &Isometry2<f64>,
        t_s: f64,
        moved_s: f64,
    ) -> bool {
        let a = fs.direction_rad[j];
        let u = Vector2::new(a.cos(), a.sin());
        let from = fs.front_mm[j] + PROBE_FROM_MM;
        let steps = (PROBE_MM / PROBE_STEP_MM).ceil() as usize;
        (0..=steps)
            .filter(|&k| {
                let d = from + PROBE_MM * k as f64 / steps as f64;
                self.free_since(odo * (fs.axis_mm + u * d), t_s - moved_s)
            })
            .count()
            >= PROBE_HITS
    }
}

/// An obstacle whose face lies this near a place where one was seen to move within
/// [`TrafficConfig::moved_s`] counts as moving too, mm: a robot seen moving stays one while it
/// slows, stops a moment, or moves where the floor was not seen free (along a wall, or out
/// of the shadow of its own body), as long as it is seen again within that time.
pub const HOLD_MM: f64 = 150.0;
/// Places seen moving nearer than this to one remembered refresh it, mm.
const MERGE_MM: f64 = 30.0;

/// What the traffic rule reads from each cycle's free space: the map, and (with
/// [`TrafficConfig::moved_s`]) the floor seen free lately.
#[derive(Debug, Clone)]
pub struct TrafficSense {
    map: StaticMap,
    seen: Option<SeenFree>,
    moved_s: f64,
    /// Where obstacles were seen to move (odometry frame, the farthest place of the face) and
    /// when, within the last `moved_s`.
    recent: Vec<(Point2<f64>, f64)>,
}

impl TrafficSense {
    /// For a robot with the map `map`, under the settings `config`.
    pub fn new(map: &WorldMap, config: &TrafficConfig) -> Self {
        Self {
            map: StaticMap::new(map),
            seen: (config.moved_s > 0.0).then(SeenFree::new),
            moved_s: config.moved_s,
            recent: Vec::new(),
        }
    }

    /// This cycle's free space `fs` split (see [`StaticMap::split`]), the robot at `pose` by its
    /// estimate (world frame) and at `odo` by its odometry at `t_s`; the floor `fs` sees free
    /// is remembered after.
    pub fn update(
        &mut self,
        fs: &FreeSpace,
        pose: Option<&Isometry2<f64>>,
        odo: &Isometry2<f64>,
        t_s: f64,
    ) -> TrafficPoints {
        let Some(seen) = &mut self.seen else {
            return self.map.split(fs, pose, |_| true);
        };
        let moved_s = self.moved_s;
        self.recent.retain(|(_, t)| t_s - t <= moved_s);
        let front = |j: usize| {
            let a = fs.direction_rad[j];
            odo * (fs.axis_mm + Vector2::new(a.cos(), a.sin()) * fs.front_mm[j])
        };
        let mut seen_moving = Vec::new();
        let recent = &self.recent;
        let out = self.map.split(fs, pose, |j| {
            if seen.moved(fs, j, odo, t_s, moved_s) {
                seen_moving.push(front(j));
                return true;
            }
            let p = front(j);
            recent.iter().any(|(q, _)| (q - p).norm() <= HOLD_MM)
        });
        for p in seen_moving {
            match self
                .recent
                .iter_mut()
                .find(|(q, _)| (q - p).norm() < MERGE_MM)
            {
                Some(entry) => *entry = (p, t_s),
                None => self.recent.push((p, t_s)),
            }
        }
        seen.see(fs, odo, t_s);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Free space in 8 directions from the origin: free to 1000 mm but for direction 0
    /// (blocked at 500 mm) and direction 2 (blocked at 700 mm).
    fn seen() -> FreeSpace {
        let n = 8;
        let dirs: Vec<f64> = (0..n).map(|j| j as f64 * TAU / n as f64).collect();
        let free: Vec<f64> = (0..n)
            .map(|j| match j {
                0 => 500.0,
                2 => 700.0,
                _ => 1000.0,
            })
            .collect();
        let clear_points = dirs
            .iter()
            .zip(&free)
            .flat_map(|(a, d)| {
                let p = Point2::new(a.cos(), a.sin()) * *d;
                [p, p, p]
            })
            .collect();
        FreeSpace {
            a: vec![1; n],
            ratio: Vec::new(),
            obstacle_points: Vec::new(),
            range_mm: 1000.0,
            inner_mm: 200.0,
            clear_mm: free.clone(),
            clear_points,
            front_mm: free.iter().map(|d| d + 50.0).collect(),
            axis_mm: Point2::origin(),
            direction_rad: dirs,
            free_mm: free,
            pixels: None,
        }
    }

    #[test]
    fn a_wall_on_the_map_stays_put_and_anything_else_may_move() {
        // The map has a wall across +x at 520 mm (its face at 500): direction 0 is that wall;
        // direction 2 (+y) ends on something the map does not have.
        let map = WorldMap {
            segments: vec![MapSegment {
                from_mm: Point2::new(520.0, -500.0),
                to_mm: Point2::new(520.0, 500.0),
                half_thickness_mm: 20.0,
            }],
            ..WorldMap::default()
        };
        let split = StaticMap::new(&map).split(&seen(), Some(&Isometry2::identity()), |_| true);
        assert_eq!(split.moving.len(), 3);
        assert!(
            split
                .moving
                .iter()
                .all(|p| (p - Vector2::new(0.0, 700.0)).norm() < 1e-9)
        );
        assert_eq!(split.horizon.len(), 6 * 3);
        // Without a pose estimate, the wall may be a robot too.
        let blind = StaticMap::new(&map).split(&seen(), None, |_| true);
        assert_eq!(blind.moving.len(), 6);
    }

    /// Free space in 32 directions from the origin: free to `open_mm` (surely free that far)
    /// but for the directions within `half_deg` of `at_deg`, blocked at `face_mm` (surely
    /// free to 20 mm before it, the face no farther than 20 mm beyond it).
    fn blocked(open_mm: f64, at_deg: f64, half_deg: f64, face_mm: f64) -> FreeSpace {
        let n = 32;
        let dirs: Vec<f64> = (0..n).map(|j| j as f64 * TAU / n as f64).collect();
        let hit: Vec<bool> = dirs
            .iter()
            .map(|a| {
                let off = (a.to_degrees() - at_deg + 540.0).rem_euclid(360.0) - 180.0;
                off.abs() <= half_deg
            })
            .collect();
        let pick = |h: bool, a: f64, b: f64| if h { a } else { b };
        let free: Vec<f64> = hit.iter().map(|&h| pick(h, face_mm, 1000.0)).collect();
        let clear: Vec<f64> = hit
            .iter()
            .map(|&h| pick(h, face_mm - 20.0, open_mm))
            .collect();
        let clear_points = dirs
            .iter()
            .zip(&clear)
            .flat_map(|(a, d)| {
                let p = Point2::new(a.cos(), a.sin()) * *d;
                [p, p, p]
            })
            .collect();
        FreeSpace {
            a: hit.iter().map(|&h| pick(h, 1.0, 6.0) as usize).collect(),
            ratio: Vec::new(),
            obstacle_points: Vec::new(),
            range_mm: 1000.0,
            inner_mm: 200.0,
            clear_mm: clear,
            clear_points,
            front_mm: hit
                .iter()
                .map(|&h| pick(h, face_mm + 20.0, 1000.0))
                .collect(),
            axis_mm: Point2::origin(),
            direction_rad: dirs,
            free_mm: free,
            pixels: None,
        }
    }

    #[test]
    fn an_obstacle_on_floor_seen_free_lately_moved_and_one_never_seen_free_stands() {
        let here = Isometry2::identity();
        let mut seen = SeenFree::new();
        // Open floor, surely free to 600 mm, at 0 s.
        seen.see(&blocked(600.0, 0.0, -1.0, 0.0), &here, 0.0);
        // At 0.5 s something stands ahead at 300 mm: where the floor was free.
        let now = blocked(600.0, 0.0, 1.0, 300.0);
        assert!(seen.moved(&now, 0, &here, 0.5, 1.0));
        // Longer ago than moved_s, it may have stood there since.
        assert!(!seen.moved(&now, 0, &here, 1.6, 1.0));
        // Never seen free there: it stands.
        assert!(!SeenFree::new().moved(&now, 0, &here, 0.5, 1.0));
        // Floor beyond SEEN_REACH_MM is never taken as seen free (a robot may hide in a far
        // cell judged free).
        let mut far = SeenFree::new();
        far.see(&blocked(900.0, 0.0, -1.0, 0.0), &here, 0.0);
        assert!(!far.moved(&blocked(900.0, 0.0, 1.0, 700.0), 0, &here, 0.5, 1.0));
        // The robot's own motion is taken out: 200 mm on, the same obstacle (now 100 mm
        // ahead of it) still stands where the floor was free.
        let on = Isometry2::new(Vector2::new(200.0, 0.0), 0.0);
        let mut moving = SeenFree::new();
        moving.see(&blocked(600.0, 0.0, -1.0, 0.0), &here, 0.0);
        assert!(moving.moved(&blocked(600.0, 0.0, 1.0, 250.0), 0, &on, 0.5, 1.0));
    }

    #[test]
    fn floor_beside_a_direction_blocked_next_to_it_is_not_taken_as_seen_free() {
        // Direction 1 (11.25 degrees) blocked at 250 mm, direction 0 free to 600: an obstacle
        // may fill the side of direction 0's cells toward it, so the floor between the two
        // centre lines beyond 230 mm is not marked free.
        let here = Isometry2::identity();
        let mut seen = SeenFree::new();
        seen.see(&blocked(600.0, 11.25, 1.0, 250.0), &here, 0.0);
        let at = |deg: f64, r: f64| {
            let a = deg.to_radians();
            Point2::new(r * a.cos(), r * a.sin())
        };
        assert!(!seen.free_since(at(5.0, 400.0), -1.0));
        assert!(seen.free_since(at(-5.0, 400.0), -1.0));
    }

    #[test]
    fn an_obstacle_seen_moving_stays_moving_where_it_goes_on_and_others_stand() {
        let config = TrafficConfig {
            rule: omniloop_control::TrafficRule::Reciprocal,
            moved_s: 1.0,
            ..TrafficConfig::default()
        };
        let here = Isometry2::identity();
        // At 0 s, the floor free all round but for something 300 mm behind; at 0.2 s
        // something 300 mm ahead too (where the floor was free: it moved there).
        let mut both = blocked(600.0, 0.0, 1.0, 300.0);
        let behind = blocked(600.0, 180.0, 1.0, 300.0);
        let j = 16;
        both.a[j] = behind.a[j];
        both.free_mm[j] = behind.free_mm[j];
        both.clear_mm[j] = behind.clear_mm[j];
        both.front_mm[j] = behind.front_mm[j];
        let mut sense = TrafficSense::new(&WorldMap::default(), &config);
        sense.update(&behind, None, &here, 0.0);
        let out = sense.update(&both, None, &here, 0.2);
        assert_eq!(out.moving.len(), 3, "{out:?}");
        assert!(out.moving.iter().all(|p| p.x > 0.0));
        // It stopped where it came, on floor last seen free at 0 s: at 1.1 s that is too long
        // ago, but it was seen moving there within moved_s, so it still moves.
        let out = sense.update(&both, None, &here, 1.1);
        assert_eq!(out.moving.len(), 3, "{out:?}");
        // Not seen moving for longer than moved_s: it stands.
        let out = sense.update(&both, None, &here, 2.3);
        assert!(out.moving.is_empty(), "{out:?}");
        // Without moved_s, everything the map does not explain may move.
        let all = TrafficConfig {
            moved_s: 0.0,
            ..config
        };
        let out = TrafficSense::new(&WorldMap::default(), &all).update(&both, None, &here, 0.2);
        assert_eq!(out.moving.len(), 6);
    }
}
