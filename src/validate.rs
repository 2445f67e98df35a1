//! Validation of a parsed scenario: every rule a value must satisfy, checked once, each
//! failure naming the dotted path of the field it concerns.

use crate::scenario::{ControllerKind, PoseSpec, Scenario};
use nalgebra::Point2;
use omniloop_sim::Layout;
use std::fmt;

/// One step of a path into the scenario document.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PathSeg {
    /// A table key.
    Key(String),
    /// An array index.
    Index(usize),
}

/// A dotted path into the document, e.g. `world.cubes[2].size_mm`.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct FieldPath(pub Vec<PathSeg>);

impl FieldPath {
    /// Parses `a.b[3].c`.
    pub fn parse(s: &str) -> Self {
        let mut segs = Vec::new();
        for part in s.split('.') {
            let mut rest = part;
            if let Some(i) = rest.find('[') {
                segs.push(PathSeg::Key(rest[..i].to_string()));
                rest = &rest[i..];
                while let Some(end) = rest.find(']') {
                    if let Ok(n) = rest[1..end].parse() {
                        segs.push(PathSeg::Index(n));
                    }
                    rest = &rest[end + 1..];
                }
            } else if !rest.is_empty() {
                segs.push(PathSeg::Key(rest.to_string()));
            }
        }
        Self(segs)
    }
}

impl fmt::Display for FieldPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, s) in self.0.iter().enumerate() {
            match s {
                PathSeg::Key(k) if i == 0 => write!(f, "{k}")?,
                PathSeg::Key(k) => write!(f, ".{k}")?,
                PathSeg::Index(n) => write!(f, "[{n}]")?,
            }
        }
        Ok(())
    }
}

/// A value that breaks a rule.
#[derive(Debug, Clone, PartialEq)]
pub struct Violation {
    /// The field.
    pub path: FieldPath,
    /// What is wrong.
    pub message: String,
}

struct Checker {
    out: Vec<Violation>,
}

impl Checker {
    fn fail(&mut self, path: impl AsRef<str>, message: impl Into<String>) {
        self.out.push(Violation {
            path: FieldPath::parse(path.as_ref()),
            message: message.into(),
        });
    }

    fn positive(&mut self, path: impl AsRef<str>, v: f64) {
        if !(v.is_finite() && v > 0.0) {
            self.fail(path, format!("must be a finite number > 0 (got {v})"));
        }
    }

    fn finite(&mut self, path: impl AsRef<str>, v: f64) {
        if !v.is_finite() {
            self.fail(path, format!("must be a finite number (got {v})"));
        }
    }

    fn pose_in_world(&mut self, path: &str, pose: &PoseSpec, radius: f64, world: &Layout) {
        self.finite(format!("{path}.x_mm"), pose.x_mm);
        self.finite(format!("{path}.y_mm"), pose.y_mm);
        self.finite(format!("{path}.heading_deg"), pose.heading_deg);
        let p = pose.point();
        if !world.is_floor(p) {
            self.fail(
                format!("{path}.x_mm"),
                format!(
                    "start ({}, {}) mm is outside the floor region",
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

fn in_floor(world: &Layout, p: Point2<f64>) -> bool {
    world.is_floor(p)
}

/// Every rule the scenario breaks (empty when it is valid).
pub fn validate(s: &Scenario) -> Vec<Violation> {
    let mut c = Checker { out: Vec::new() };
    let r = &s.run;
    c.positive("run.duration_s", r.duration_s);
    c.positive("run.control_period_s", r.control_period_s);
    c.positive("run.physics_step_s", r.physics_step_s);
    if r.physics_step_s > 0.0 && r.control_period_s > 0.0 {
        let n = r.control_period_s / r.physics_step_s;
        if r.physics_step_s > r.control_period_s || (n - n.round()).abs() > 1e-6 {
            c.fail(
                "run.physics_step_s",
                format!(
                    "must divide run.control_period_s = {} s into a whole number of steps \
                     (got {} s)",
                    r.control_period_s, r.physics_step_s
                ),
            );
        }
    }

    let w = &s.world;
    if let Some(f) = &w.field {
        for (name, v) in [
            ("half_length_mm", f.half_length_mm),
            ("half_width_mm", f.half_width_mm),
            ("goal_depth_mm", f.goal_depth_mm),
            ("goal_width_mm", f.goal_width_mm),
            ("goal_wall_height_mm", f.goal_wall_height_mm),
            ("wall_height_mm", f.wall_height_mm),
            ("wall_thickness_mm", f.wall_thickness_mm),
            ("line_width_mm", f.line_width_mm),
            ("centre_circle_radius_mm", f.centre_circle_radius_mm),
        ] {
            c.positive(format!("world.field.{name}"), v);
        }
        if f.goal_width_mm >= 2.0 * f.half_width_mm {
            c.fail(
                "world.field.goal_width_mm",
                "must be narrower than the field (2 * half_width_mm)",
            );
        }
    }
    for (i, fr) in w.floor_rects.iter().enumerate() {
        c.positive(format!("world.floor_rects[{i}].size_mm"), fr.size_mm[0]);
        c.positive(format!("world.floor_rects[{i}].size_mm"), fr.size_mm[1]);
    }
    for (i, wall) in w.walls.iter().enumerate() {
        let p = format!("world.walls[{i}]");
        c.positive(format!("{p}.thickness_mm"), wall.thickness_mm);
        c.positive(format!("{p}.height_mm"), wall.height_mm);
        let len = ((wall.to_mm[0] - wall.from_mm[0]).powi(2)
            + (wall.to_mm[1] - wall.from_mm[1]).powi(2))
        .sqrt();
        if len.is_nan() || len <= 0.0 {
            c.fail(format!("{p}.to_mm"), "must differ from from_mm");
        }
    }
    for (i, cube) in w.cubes.iter().enumerate() {
        c.positive(format!("world.cubes[{i}].size_mm"), cube.size_mm);
    }
    for (i, p) in w.pillars.iter().enumerate() {
        c.positive(format!("world.pillars[{i}].radius_mm"), p.radius_mm);
        c.positive(format!("world.pillars[{i}].height_mm"), p.height_mm);
    }

    let rb = &s.robot;
    c.positive("robot.radius_mm", rb.radius_mm);
    c.positive("robot.height_mm", rb.height_mm);
    c.positive("robot.max_speed_mm_s", rb.max_speed_mm_s);
    c.positive("robot.accel_limit_mm_s2", rb.accel_limit_mm_s2);
    c.positive(
        "robot.angular_accel_limit_rad_s2",
        rb.angular_accel_limit_rad_s2,
    );
    c.pose_in_world("robot.start", &rb.start, rb.radius_mm, w);

    for (i, o) in s.other_robots.iter().enumerate() {
        let p = format!("other_robots[{i}]");
        c.positive(format!("{p}.radius_mm"), o.radius_mm);
        c.positive(format!("{p}.height_mm"), o.height_mm);
        c.positive(format!("{p}.max_speed_mm_s"), o.max_speed_mm_s);
        c.positive(format!("{p}.accel_limit_mm_s2"), o.accel_limit_mm_s2);
        c.pose_in_world(&format!("{p}.start"), &o.start, o.radius_mm, w);
        for (k, wp) in o.waypoints_mm.iter().enumerate() {
            if !in_floor(w, Point2::new(wp[0], wp[1])) {
                c.fail(
                    format!("{p}.waypoints_mm[{k}]"),
                    format!("({}, {}) mm is outside the floor region", wp[0], wp[1]),
                );
            }
        }
    }

    if let Some(g) = &s.goal {
        c.finite("goal.x_mm", g.x_mm);
        c.finite("goal.y_mm", g.y_mm);
        c.positive("goal.tolerance_mm", g.tolerance_mm);
        if !in_floor(w, g.point()) {
            c.fail(
                "goal.x_mm",
                format!(
                    "goal ({}, {}) mm is outside the floor region",
                    g.x_mm, g.y_mm
                ),
            );
        }
    }
    if s.control.kind != ControllerKind::Idle && s.goal.is_none() {
        c.fail(
            "control.kind",
            format!(
                "controller {:?} needs a [goal] table",
                crate::scenario::controller_name(s.control.kind)
            ),
        );
    }
    c.out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_round_trip() {
        for s in ["robot.radius_mm", "world.cubes[2].size_mm", "a[1][2].b"] {
            assert_eq!(FieldPath::parse(s).to_string(), s);
        }
    }
}
