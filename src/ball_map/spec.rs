//! `[experiment.ball_map]`: where the ball is placed, how many frames at each place, and how
//! many ball-free frames are taken.

use crate::scenario::{Problems, Scenario};
use nalgebra::{Point2, Vector2};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// The map's placements (`[experiment.ball_map]`).
///
/// With a ball in the world (`[world.ball]`) the robot stands at its start and the ball is put
/// at every distance in every direction, `draws` frames each; without one the robot is carried
/// to `empty_frames` seeded random poses on the floor and every frame should show no ball.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BallMapSpec {
    /// Distances of the ball's centre from the robot's centre, mm (the map's rings).
    pub distances_mm: Vec<f64>,
    /// Directions around the robot, evenly spread; each frame's direction is turned on by a
    /// seeded random part of the step, so that the directions do not line up with the pixels.
    pub directions: usize,
    /// Frames (noise draws, robot headings) at each distance and direction.
    pub draws: usize,
    /// Ball-free frames at seeded random poses (a scenario without `[world.ball]`).
    pub empty_frames: usize,
    /// The targets are judged on the frames within this distance, mm.
    pub target_range_mm: f64,
    /// Ball-free poses keep the robot's body this far from walls and obstacles, mm.
    pub clearance_mm: f64,
}

impl Default for BallMapSpec {
    fn default() -> Self {
        Self {
            distances_mm: default_distances(),
            directions: 24,
            draws: 3,
            empty_frames: 0,
            target_range_mm: 1000.0,
            clearance_mm: 20.0,
        }
    }
}

/// The replay's rings: 50 mm apart by the body, 100 mm to 1 m, 200 mm to 2 m, 250 mm to 3 m.
fn default_distances() -> Vec<f64> {
    let near = (3..=8).map(|k| 50.0 * f64::from(k));
    let mid = (5..=10).map(|k| 100.0 * f64::from(k));
    let far = (6..=10).map(|k| 200.0 * f64::from(k));
    let farthest = (9..=12).map(|k| 250.0 * f64::from(k));
    near.chain(mid).chain(far).chain(farthest).collect()
}

impl BallMapSpec {
    /// Frames the run takes: placed balls with a ball in the world, ball-free ones without.
    pub fn frames(&self, with_ball: bool) -> usize {
        if with_ball {
            self.distances_mm.len() * self.directions * self.draws
        } else {
            self.empty_frames
        }
    }

    /// The section's checks against the scenario.
    pub fn validate(&self, s: &Scenario, c: &mut Problems) {
        let at = "experiment.ball_map";
        for (name, n) in [("directions", self.directions), ("draws", self.draws)] {
            if n == 0 {
                c.fail(format!("{at}.{name}"), "must be >= 1");
            }
        }
        c.positive(format!("{at}.target_range_mm"), self.target_range_mm);
        c.non_negative(format!("{at}.clearance_mm"), self.clearance_mm);
        match &s.world.ball {
            Some(ball) => self.validate_rings(s, ball.radius_mm, c),
            None if self.empty_frames == 0 => c.fail(
                format!("{at}.empty_frames"),
                "without a ball ([world.ball]) the map takes ball-free frames: set it >= 1",
            ),
            None => {}
        }
        if !mirror_camera(s) {
            c.fail(
                at,
                "the ball map needs vision's camera to be a mirror camera",
            );
        }
    }

    /// The rings: finite, beyond the ball's own radius, and on the floor all round the start.
    fn validate_rings(&self, s: &Scenario, ball_radius_mm: f64, c: &mut Problems) {
        let at = "experiment.ball_map";
        if self.empty_frames > 0 {
            c.fail(
                format!("{at}.empty_frames"),
                "ball-free frames need a scenario without a ball ([world.ball])",
            );
        }
        if self.distances_mm.is_empty() {
            c.fail(format!("{at}.distances_mm"), "needs at least one distance");
        }
        let centre = s.start().point();
        for (i, d) in self.distances_mm.iter().enumerate() {
            if !(d.is_finite() && *d > ball_radius_mm) {
                let why = format!("must be a finite distance beyond the ball's radius (got {d})");
                c.fail(format!("{at}.distances_mm[{i}]"), why);
            } else if let Some(p) = off_floor(&s.world, centre, *d) {
                let why = format!(
                    "the ring of {d} mm around the start leaves the floor region at \
                     ({:.0}, {:.0}) mm",
                    p.x, p.y
                );
                c.fail(format!("{at}.distances_mm[{i}]"), why);
            }
        }
    }
}

/// A point of the circle of radius `d` about `centre` off the floor region, if any (every
/// degree).
fn off_floor(world: &omniloop_sim::Layout, centre: Point2<f64>, d: f64) -> Option<Point2<f64>> {
    (0..360)
        .map(|k| {
            let a = f64::from(k) / 360.0 * TAU;
            centre + Vector2::new(a.cos(), a.sin()) * d
        })
        .find(|p| !world.is_floor(*p))
}

/// Whether vision's camera is a mirror camera.
fn mirror_camera(s: &Scenario) -> bool {
    let Ok(i) = s.vision_sensor_index() else {
        return false;
    };
    s.robot.sensors[i].build().optics.mirror_frame().is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_rings_are_finer_near_the_robot() {
        let d = default_distances();
        assert_eq!(d.first(), Some(&150.0));
        assert_eq!(d.last(), Some(&3000.0));
        assert!(d.windows(2).all(|w| w[1] > w[0]), "{d:?}");
        assert!(d.contains(&300.0) && d.contains(&1000.0) && d.contains(&2250.0));
        assert_eq!(BallMapSpec::default().frames(true), d.len() * 24 * 3);
    }
}
