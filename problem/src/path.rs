//! The dotted path of a field in a scenario document, e.g. `world.cubes[2].size_mm`.

use std::fmt;

/// One step of a path into the scenario document.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PathSeg {
    /// A table key.
    Key(String),
    /// An array index.
    Index(usize),
}

/// A dotted path into the document, e.g. `world.cubes[2].size_mm` (empty: the whole document,
/// or no field at all, as for a TOML syntax error).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct FieldPath(pub Vec<PathSeg>);

impl FieldPath {
    /// Parses `a.b[3].c` (the empty string is the empty path).
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

    /// Whether the path names no field.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// This path followed by `rest` (itself a path relative to this one).
    pub fn join(&self, rest: &FieldPath) -> FieldPath {
        let mut segs = self.0.clone();
        segs.extend(rest.0.iter().cloned());
        FieldPath(segs)
    }
}

impl From<&str> for FieldPath {
    fn from(s: &str) -> Self {
        Self::parse(s)
    }
}

impl From<String> for FieldPath {
    fn from(s: String) -> Self {
        Self::parse(&s)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_round_trip() {
        for s in ["robot.radius_mm", "world.cubes[2].size_mm", "a[1][2].b", ""] {
            assert_eq!(FieldPath::parse(s).to_string(), s);
        }
    }

    #[test]
    fn joined_paths_read_as_one() {
        let p = FieldPath::parse("robot.sensors[1]").join(&FieldPath::parse("hyperbolic.c_mm"));
        assert_eq!(p.to_string(), "robot.sensors[1].hyperbolic.c_mm");
        assert_eq!(p.0[2], PathSeg::Index(1));
        assert!(FieldPath::parse("").is_empty());
    }
}
