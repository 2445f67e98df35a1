//! Near-field memory: where obstacles are when they are too near for the camera to see.
//!
//! The robot's own body hides the floor within the template's inner edge, so an obstacle nearer
//! than that only shows as a blocked first ring: vision knows it is there, not how near. A robot
//! that takes such an obstacle to be at the inner edge creeps into it a little every cycle. It
//! saw the obstacle, though, while it approached: this memory keeps the surely-free boundary
//! points of near obstacles in the odometry frame for a few seconds and, in a direction whose
//! first ring is blocked, hands the controller the remembered points there (moved by the
//! odometry since), or, when it remembers none, a blind point at the body's edge (something is
//! there at a distance nobody knows: the robot may pass it at a slant or move away from it,
//! never head into it).
//!
//! A point is forgotten once it is older than `KEEP_S` *and* the robot has travelled more than
//! `KEEP_TRAVEL_MM` since it was last seen: odometry drifts with the way driven, not with the
//! time, and a robot creeping past a cube's corner (at the slowest turning speed, 80 mm/s
//! for a 400 mm/s robot) must not forget the corner half-way along and slide into it at a
//! slant (a blind point allows that).

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
        self.points.retain(|&(p, t, o)| {
            (t_s - t <= KEEP_S || odometer - o <= KEEP_TRAVEL_MM)
                && (p - here).norm() <= 2.0 * NEAR_MM
        });
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
                    out.blind
                        .push(Vector2::new(phi.cos(), phi.sin()) * self.radius_mm);
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
        // ...and forgotten once it is old and the robot has driven on: 200 mm away, where it
        // sees nothing near, and back, its memory of the wall ahead is gone.
        let away = Isometry2::new(Vector2::new(150.0, 200.0), 0.0);
        m.update(&seen(5000.0), &away, 3.5);
        let out = m.update(&seen(150.0), &odo, 4.0);
        assert!((ahead(&out.blind) - 90.0).abs() < 1e-9);
    }
}
