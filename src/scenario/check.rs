//! Checking a parsed scenario: the rules and every experiment's own checks collect what they
//! find with [`Problems`], the one type every layer uses to say which field is at fault
//! (`omniloop_problem`); [`PoseChecks`] adds the checks only a scenario can make, those that
//! need its world.

use super::schema::PoseSpec;
pub use omniloop_problem::{FieldPath, Location, PathSeg, Problem, Problems};
use omniloop_sim::Layout;

/// The checks of a pose against the scenario's world.
pub trait PoseChecks {
    /// The pose at `path` must be finite, on the floor region, and leave a robot of `radius`
    /// clear of every obstacle.
    fn pose_in_world(&mut self, path: &str, pose: &PoseSpec, radius: f64, world: &Layout);
}

impl PoseChecks for Problems {
    fn pose_in_world(&mut self, path: &str, pose: &PoseSpec, radius: f64, world: &Layout) {
        self.finite(format!("{path}.x_mm"), pose.x_mm);
        self.finite(format!("{path}.y_mm"), pose.y_mm);
        self.finite(format!("{path}.heading_deg"), pose.heading_deg);
        let p = pose.point();
        if !world.is_floor(p) {
            let noun = if path.ends_with("start") {
                "start"
            } else {
                "place"
            };
            self.fail(
                format!("{path}.x_mm"),
                format!(
                    "{noun} ({}, {}) mm is outside the floor region",
                    pose.x_mm, pose.y_mm
                ),
            );
            return;
        }
        let nearest = world
            .solids()
            .iter()
            .map(|s| s.shape.distance_mm(p))
            .min_by(f64::total_cmp);
        if let Some(d) = nearest.filter(|&d| radius > 0.0 && d < radius) {
            self.fail(
                format!("{path}.x_mm"),
                format!(
                    "a robot of radius {radius} mm at ({}, {}) overlaps an obstacle \
                     ({d:.1} mm from its centre)",
                    pose.x_mm, pose.y_mm
                ),
            );
        }
    }
}
