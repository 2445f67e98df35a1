//! Helpers of the controllers' tests: a wall seen as vision reports it, and a closed loop
//! against it.

use crate::{AccelLimitedDrive, Surroundings, Vec2};
use std::f64::consts::TAU;

/// The drive of the corner paper: alpha = 300 mm/s^2.
pub fn drive() -> AccelLimitedDrive {
    AccelLimitedDrive::new(300.0, 10.0).unwrap()
}

/// What vision reports: directions, free distances, obstacle points, horizon points.
pub struct Seen {
    pub dirs: Vec<f64>,
    pub free: Vec<f64>,
    pub obstacles: Vec<Vec2>,
    pub clear: Vec<Vec2>,
}

impl Seen {
    /// Nothing seen yet in `n` directions evenly spaced from 0.
    pub fn in_directions(n: usize) -> Self {
        Self {
            dirs: (0..n).map(|j| j as f64 * TAU / n as f64).collect(),
            free: Vec::new(),
            obstacles: Vec::new(),
            clear: Vec::new(),
        }
    }
}

/// The surroundings of `seen` with a 1000 mm template.
pub fn surroundings(seen: &Seen) -> Surroundings<'_> {
    Surroundings {
        direction_rad: &seen.dirs,
        free_mm: &seen.free,
        range_mm: 1000.0,
        obstacle_points: &seen.obstacles,
        clear_points: &seen.clear,
        blind_points: &[],
        moving_points: &[],
        horizon_points: &[],
    }
}

/// A wall across the robot's path at x = `x_mm`, seen in 32 directions up to 1000 mm.
pub fn wall_ahead(x_mm: f64) -> Seen {
    let mut seen = Seen::in_directions(32);
    for a in seen.dirs.clone() {
        let c = a.cos();
        let d = if c > 1e-9 { x_mm / c } else { f64::INFINITY };
        let u = Vec2::new(c, a.sin());
        // Exact perception: the surely free space ends at the wall, or at the template's edge.
        if d < 1000.0 {
            seen.free.push(d);
            seen.obstacles.push(u * d);
        } else {
            seen.free.push(1000.0);
        }
        seen.clear.push(u * d.min(1000.0));
    }
    seen
}

/// Closed loop against a wall at x = 600 starting at `v0` mm/s along +x toward a goal beyond
/// it: `decide(surroundings, goal, velocity)` every 40 ms on what the wall looks like from where
/// the robot is, the drive of eq. (8) in 1 ms steps. Returns the largest x reached and the final
/// position.
pub fn rush_at_wall(
    v0: f64,
    decide: impl Fn(&Surroundings<'_>, Vec2, Vec2) -> Vec2,
) -> (f64, Vec2) {
    let mut p = Vec2::zeros();
    let mut v = Vec2::new(v0, 0.0);
    let mut max_x: f64 = f64::MIN;
    for _ in 0..200 {
        let seen = wall_ahead(600.0 - p.x);
        let goal = Vec2::new(3000.0, 50.0) - p;
        let cmd = decide(&surroundings(&seen), goal, v);
        for _ in 0..40 {
            let v1 = drive().step(v, cmd, 0.001);
            p += (v + v1) * 0.0005;
            v = v1;
            max_x = max_x.max(p.x);
        }
    }
    (max_x, p)
}
