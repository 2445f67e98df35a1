//! The one type every layer of omniloop uses to say which field of a scenario is at fault.
//!
//! A [`Problem`] is a value that breaks a rule: the dotted [`FieldPath`] of its field
//! (`control.avoidance.margin_mm`, `robot.sensors[1].hyperbolic.c_mm`), what is wrong, and —
//! once the scenario layer has found it in the file — its [`Location`] (file, line, column).
//! The optics check their own numbers, the robot's controllers and perception stages their own
//! settings tables, the scenario its rules and every experiment its section; each collects what
//! it finds with [`Problems`], whose prefix names the table it checks, and hands the list up.
//! The scenario layer locates each one in the file, and the command line prints them as
//!
//! ```text
//! scenarios/x.toml:13:1: field `control.avoidance.margin_mm`: must be >= 0 (got -5)
//! ```
//!
//! (without the location when a problem is found outside a file). This crate depends on
//! nothing, so that every crate can use it.

mod path;

pub use path::{FieldPath, PathSeg};
use std::fmt;
use std::path::PathBuf;

/// Where a problem is in a scenario file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The file.
    pub file: PathBuf,
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
}

/// A value that breaks a rule: its field, what is wrong and, when found in a file, where.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// The field, e.g. `control.avoidance.margin_mm` (empty when the problem is in the TOML
    /// syntax, before any field).
    pub field: FieldPath,
    /// What is wrong.
    pub message: String,
    /// Where it is in the scenario file, once located there.
    pub location: Option<Location>,
}

impl Problem {
    /// A problem with `field` (dotted, e.g. `world.cubes[2].size_mm`), not located yet.
    pub fn new(field: impl Into<FieldPath>, message: impl Into<String>) -> Self {
        Self {
            field: field.into(),
            message: message.into(),
            location: None,
        }
    }

    /// The same problem, its field taken as relative to `prefix`.
    pub fn under(mut self, prefix: &FieldPath) -> Self {
        self.field = prefix.join(&self.field);
        self
    }

    /// The same problem at `location` in the scenario file.
    pub fn located(mut self, location: Location) -> Self {
        self.location = Some(location);
        self
    }
}

impl std::error::Error for Problem {}

impl fmt::Display for Problem {
    /// `FILE:LINE:COLUMN: field `a.b`: message` (the location when it is known, the field when
    /// there is one).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(at) = &self.location {
            write!(f, "{}:{}:{}: ", at.file.display(), at.line, at.column)?;
        }
        if !self.field.is_empty() {
            write!(f, "field `{}`: ", self.field)?;
        }
        write!(f, "{}", self.message)
    }
}

/// Collects the problems of the fields under a prefix (a table such as `control.wander`, or
/// the whole scenario for the empty prefix), in the order found.
#[derive(Debug, Clone, Default)]
pub struct Problems {
    prefix: FieldPath,
    list: Vec<Problem>,
}

impl Problems {
    /// A collector for the whole scenario, nothing found yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// A collector for the fields under `prefix` (dotted, e.g. `control.wander`).
    pub fn under(prefix: impl AsRef<str>) -> Self {
        Self {
            prefix: FieldPath::parse(prefix.as_ref()),
            list: Vec::new(),
        }
    }

    /// Field `key` (dotted, relative to the prefix; empty: the prefix itself) breaks a rule.
    pub fn fail(&mut self, key: impl AsRef<str>, message: impl Into<String>) {
        let field = self.prefix.join(&FieldPath::parse(key.as_ref()));
        self.list.push(Problem::new(field, message));
    }

    /// Field `key` must be a finite number > 0.
    pub fn positive(&mut self, key: impl AsRef<str>, v: f64) {
        if !(v.is_finite() && v > 0.0) {
            self.fail(key, format!("must be a finite number > 0 (got {v})"));
        }
    }

    /// Field `key` must be a finite number >= 0.
    pub fn non_negative(&mut self, key: impl AsRef<str>, v: f64) {
        if !(v.is_finite() && v >= 0.0) {
            self.fail(key, format!("must be >= 0 (got {v})"));
        }
    }

    /// Field `key` must be a finite number.
    pub fn finite(&mut self, key: impl AsRef<str>, v: f64) {
        if !v.is_finite() {
            self.fail(key, format!("must be a finite number (got {v})"));
        }
    }

    /// Adds the problems another part found, their fields relative to the prefix.
    pub fn extend(&mut self, problems: impl IntoIterator<Item = Problem>) {
        let prefix = &self.prefix;
        self.list
            .extend(problems.into_iter().map(|p| p.under(prefix)));
    }

    /// Adds the problems another part found (fields relative to the prefix), each once: a
    /// problem already collected is not added again.
    pub fn merge(&mut self, problems: impl IntoIterator<Item = Problem>) {
        for p in problems {
            let p = p.under(&self.prefix);
            if !self.list.contains(&p) {
                self.list.push(p);
            }
        }
    }

    /// Whether nothing was found.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// How many problems were found.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// What was found, in the order found.
    pub fn iter(&self) -> std::slice::Iter<'_, Problem> {
        self.list.iter()
    }

    /// What was found, in the order found.
    pub fn into_vec(self) -> Vec<Problem> {
        self.list
    }
}

impl IntoIterator for Problems {
    type Item = Problem;
    type IntoIter = std::vec::IntoIter<Problem>;

    fn into_iter(self) -> Self::IntoIter {
        self.list.into_iter()
    }
}

impl<'a> IntoIterator for &'a Problems {
    type Item = &'a Problem;
    type IntoIter = std::slice::Iter<'a, Problem>;

    fn into_iter(self) -> Self::IntoIter {
        self.list.iter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_problem_reads_with_its_field_and_location() {
        let p = Problem::new(
            "control.wander.turn_s",
            "must be a finite number > 0 (got 0)",
        );
        assert_eq!(
            p.to_string(),
            "field `control.wander.turn_s`: must be a finite number > 0 (got 0)"
        );
        let at = Location {
            file: PathBuf::from("s.toml"),
            line: 4,
            column: 1,
        };
        assert_eq!(
            p.located(at).to_string(),
            "s.toml:4:1: field `control.wander.turn_s`: must be a finite number > 0 (got 0)"
        );
    }

    #[test]
    fn a_syntax_error_names_no_field() {
        let at = Location {
            file: PathBuf::from("s.toml"),
            line: 2,
            column: 7,
        };
        let p = Problem::new("", "expected `=`").located(at);
        assert_eq!(p.to_string(), "s.toml:2:7: expected `=`");
    }

    #[test]
    fn problems_name_their_fields_under_the_prefix() {
        let mut p = Problems::under("control.wander");
        p.positive("turn_s", 0.0);
        p.positive("speed_mm_s", 1.0);
        p.non_negative("margin_mm", -5.0);
        p.finite("x_mm", f64::NAN);
        p.fail("", "missing");
        let fields: Vec<String> = p.iter().map(|q| q.field.to_string()).collect();
        assert_eq!(
            fields,
            [
                "control.wander.turn_s",
                "control.wander.margin_mm",
                "control.wander.x_mm",
                "control.wander"
            ]
        );
        assert_eq!(p.len(), 4);
        assert_eq!(p.into_vec()[1].message, "must be >= 0 (got -5)");
    }

    #[test]
    fn merged_problems_are_kept_once() {
        let mut all = Problems::new();
        all.fail("robot.sensors[0].c_mm", "too small");
        let mut optics = Problems::new();
        optics.fail("c_mm", "too small");
        all.merge(
            optics
                .clone()
                .into_vec()
                .into_iter()
                .map(|p| p.under(&FieldPath::parse("robot.sensors[0]"))),
        );
        assert_eq!(all.len(), 1);
        all.extend(
            optics
                .into_vec()
                .into_iter()
                .map(|p| p.under(&FieldPath::parse("robot.sensors[1]"))),
        );
        assert_eq!(all.len(), 2);
        assert_eq!(
            all.iter().nth(1).map(|p| p.to_string()).as_deref(),
            Some("field `robot.sensors[1].c_mm`: too small")
        );
    }
}
