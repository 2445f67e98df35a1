//! Checking a parsed scenario: the dotted path of a field, a value that breaks a rule, and the
//! checker that collects them (the rules and every experiment's own checks use it).

use super::schema::PoseSpec;
use omniloop_robot::ConfigProblem;
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

/// Collects the violations of a scenario (experiments check their own sections with it).
pub struct Checker {
    pub(crate) out: Vec<Violation>,
}

impl Checker {
    /// Field `path` (dotted) breaks a rule.
    pub fn fail(&mut self, path: impl AsRef<str>, message: impl Into<String>) {
        self.out.push(Violation {
            path: FieldPath::parse(path.as_ref()),
            message: message.into(),
        });
    }

    /// Field `path` must be a finite number > 0.
    pub fn positive(&mut self, path: impl AsRef<str>, v: f64) {
        if !(v.is_finite() && v > 0.0) {
            self.fail(path, format!("must be a finite number > 0 (got {v})"));
        }
    }

    /// Field `path` must be a finite number.
    pub fn finite(&mut self, path: impl AsRef<str>, v: f64) {
        if !v.is_finite() {
            self.fail(path, format!("must be a finite number (got {v})"));
        }
    }

    /// The pose at `path` must be finite, on the floor region, and leave a robot of `radius`
    /// clear of every obstacle.
    pub fn pose_in_world(&mut self, path: &str, pose: &PoseSpec, radius: f64, world: &Layout) {
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

impl Checker {
    /// Records the problems a registered part's own checks found (each once).
    pub fn problems(&mut self, list: Vec<ConfigProblem>) {
        for p in list {
            let dup = self
                .out
                .iter()
                .any(|v| v.path.to_string() == p.field && v.message == p.message);
            if !dup {
                self.fail(p.field, p.message);
            }
        }
    }
}

impl Checker {
    /// A checker with nothing found yet.
    pub fn new() -> Self {
        Self { out: Vec::new() }
    }

    /// What was found.
    pub fn into_violations(self) -> Vec<Violation> {
        self.out
    }
}

impl Default for Checker {
    fn default() -> Self {
        Self::new()
    }
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
