//! What the controller's traffic rule ([`omniloop_control::traffic`]) needs of the free space:
//! which directions end on something that may move, and where the unknown begins.
//!
//! The robot tells a wall from a robot by its map: a direction whose obstacle lies where the
//! map has a wall, a goal, a board, a pillar or a cube (by the pose estimate, within the
//! uncertainty of the template's cell and [`TOLERANCE_MM`]) ends on something that stays put;
//! any other obstacle may be another robot, or hide one. Without a pose estimate, every
//! obstacle may move. A direction free throughout ends on the horizon.

use crate::config::{MapSegment, WorldMap};
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_vision::FreeSpace;

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
    /// its estimate, or every obstacle taken as one that may move without one.
    pub fn split(&self, fs: &FreeSpace, pose: Option<&Isometry2<f64>>) -> TrafficPoints {
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
            if mapped {
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

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
        let split = StaticMap::new(&map).split(&seen(), Some(&Isometry2::identity()));
        assert_eq!(split.moving.len(), 3);
        assert!(
            split
                .moving
                .iter()
                .all(|p| (p - Vector2::new(0.0, 700.0)).norm() < 1e-9)
        );
        assert_eq!(split.horizon.len(), 6 * 3);
        // Without a pose estimate, the wall may be a robot too.
        let blind = StaticMap::new(&map).split(&seen(), None);
        assert_eq!(blind.moving.len(), 6);
    }
}
