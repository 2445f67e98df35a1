//! Parsing a scenario: TOML, schema, the rules, with every problem located by file, line,
//! column and field. The experiments' own preparation and checks come in as arguments from
//! the layer that knows them ([`crate::experiments::parse_scenario`]).

use super::check::Violation;
use super::check::{Checker, FieldPath, PathSeg};
use super::rules::validate;
use super::schema::{RobotSpec, Scenario};
use super::team;
use omniloop_robot::VisionSpec;
use omniloop_sim::optics::Optics;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::de::{DeTable, DeValue};

/// One problem in a scenario file.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// The file.
    pub file: PathBuf,
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
    /// The dotted path of the field (empty when the problem is in the TOML syntax).
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}: ", self.file.display(), self.line, self.column)?;
        if !self.field.is_empty() {
            write!(f, "field `{}`: ", self.field)?;
        }
        write!(f, "{}", self.message)
    }
}

/// Why a scenario could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file could not be read.
    #[error("cannot read scenario {}: {source}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not a valid scenario.
    #[error("{}", problems.iter().map(|p| p.to_string()).collect::<Vec<_>>().join("\n"))]
    Invalid {
        /// Every problem found, in file order.
        problems: Vec<Problem>,
    },
}

/// Reads, parses and validates a scenario file with the experiments' `prepare` and `check`
/// (see [`parse_scenario_with`]). The scenario's name defaults to the file stem.
pub fn load_scenario_with(
    path: &Path,
    prepare: impl FnOnce(&mut Scenario),
    check: impl FnOnce(&Scenario, &mut Checker),
) -> Result<Scenario, LoadError> {
    let text = std::fs::read_to_string(path).map_err(|source| LoadError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    parse_scenario_with(&text, path, &stem, prepare, check)
}

/// Parses and validates scenario text; `file` is used in messages only. `prepare` builds what
/// the scenario's experiment owns into it before the rules run (the corner's corridor); `check`
/// adds the experiment's own rules.
pub fn parse_scenario_with(
    text: &str,
    file: &Path,
    default_name: &str,
    prepare: impl FnOnce(&mut Scenario),
    check: impl FnOnce(&Scenario, &mut Checker),
) -> Result<Scenario, LoadError> {
    let doc = DeTable::parse(text).ok();
    let locate = |span: Option<Range<usize>>| -> (usize, usize) {
        span.map(|s| line_col(text, s.start)).unwrap_or((1, 1))
    };
    let mut scenario = match Scenario::from_toml(text) {
        Ok(s) => s,
        Err(e) => {
            let span = e.span();
            let field = match (&doc, &span) {
                (Some(d), Some(s)) => path_at(d.get_ref(), s.start)
                    .map(|p| p.to_string())
                    .unwrap_or_default(),
                _ => String::new(),
            };
            let (line, column) = locate(span);
            return Err(LoadError::Invalid {
                problems: vec![Problem {
                    file: file.to_path_buf(),
                    line,
                    column,
                    field,
                    message: e.message().trim().to_string(),
                }],
            });
        }
    };
    if scenario.name.is_empty() {
        scenario.name = default_name.to_string();
    }
    let located = |violations: Vec<Violation>| {
        let mut problems: Vec<Problem> = violations
            .into_iter()
            .map(|v| {
                let span = doc.as_ref().and_then(|d| span_of(d.get_ref(), &v.path));
                let (line, column) = locate(span);
                Problem {
                    file: file.to_path_buf(),
                    line,
                    column,
                    field: v.path.to_string(),
                    message: v.message,
                }
            })
            .collect();
        problems.sort_by_key(|p| (p.line, p.column));
        LoadError::Invalid { problems }
    };
    // A team's robots: each entry of [[robots]] over the shared tables.
    if !scenario.robots.is_empty() {
        let raw: toml::Table = toml::from_str(text).unwrap_or_default();
        scenario.team = team::resolve(&raw).map_err(&located)?;
    }
    // An experiment may build part of the world (the corner's corridor, start and goal).
    prepare(&mut scenario);
    // Paths in a scenario are relative to its file; calibrated cameras read their files now
    // (what fails is reported with the rules).
    let dir = file.parent().unwrap_or(Path::new(""));
    resolve_files(&mut scenario.vision, &mut scenario.robot, dir);
    for m in &mut scenario.team {
        resolve_files(&mut m.vision, &mut m.robot, dir);
    }
    let mut violations = if scenario.is_team() {
        team::validate_team(&scenario)
    } else {
        validate(&scenario)
    };
    let mut c = Checker::new();
    check(&scenario, &mut c);
    violations.extend(c.into_violations());
    if violations.is_empty() {
        return Ok(scenario);
    }
    Err(located(violations))
}

/// Makes a robot's file paths relative to the scenario's folder `dir` (vision's calibration
/// table) and reads its calibrated cameras' model files.
fn resolve_files(vision: &mut VisionSpec, robot: &mut RobotSpec, dir: &Path) {
    if let Some(f) = vision.calibration_file.as_ref().filter(|f| f.is_relative()) {
        vision.calibration_file = Some(dir.join(f));
    }
    for sensor in &mut robot.sensors {
        if let Optics::Calibrated(cam) = &mut sensor.optics {
            cam.load(dir).ok();
        }
    }
}

/// 1-based line and column of a byte offset.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// The span of the deepest part of `path` present in the document: the key of a field that is
/// written, else the nearest enclosing table or array element.
fn span_of(doc: &DeTable<'_>, path: &FieldPath) -> Option<Range<usize>> {
    let mut table = Some(doc);
    let mut value: Option<&DeValue<'_>> = None;
    let mut best = None;
    for seg in &path.0 {
        match seg {
            PathSeg::Key(k) => {
                let t = table?;
                let (key, v) = t.get_key_value(k.as_str())?;
                best = Some(key.span());
                value = Some(v.get_ref());
                table = v.get_ref().as_table();
            }
            PathSeg::Index(i) => {
                let arr = value?.as_array()?;
                let item = arr.get(*i)?;
                best = Some(item.span());
                value = Some(item.get_ref());
                table = item.get_ref().as_table();
            }
        }
    }
    best
}

/// The path of the innermost key or value whose span holds `offset`.
fn path_at(doc: &DeTable<'_>, offset: usize) -> Option<FieldPath> {
    fn walk(t: &DeTable<'_>, offset: usize, path: &mut Vec<PathSeg>) -> bool {
        for (k, v) in t.iter() {
            let ks = k.span();
            let vs = v.span();
            if ks.contains(&offset) || vs.contains(&offset) || ks.start == offset {
                path.push(PathSeg::Key(k.get_ref().to_string()));
                descend(v.get_ref(), offset, path);
                return true;
            }
        }
        // Tables written as headers span only their header; look inside every one.
        for (k, v) in t.iter() {
            path.push(PathSeg::Key(k.get_ref().to_string()));
            if descend_inner(v.get_ref(), offset, path) {
                return true;
            }
            path.pop();
        }
        false
    }
    fn descend(v: &DeValue<'_>, offset: usize, path: &mut Vec<PathSeg>) {
        descend_inner(v, offset, path);
    }
    fn descend_inner(v: &DeValue<'_>, offset: usize, path: &mut Vec<PathSeg>) -> bool {
        if let Some(t) = v.as_table() {
            return walk(t, offset, path);
        }
        if let Some(a) = v.as_array() {
            for (i, item) in a.iter().enumerate() {
                path.push(PathSeg::Index(i));
                if item.span().contains(&offset) {
                    descend_inner(item.get_ref(), offset, path);
                    return true;
                }
                if descend_inner(item.get_ref(), offset, path) {
                    return true;
                }
                path.pop();
            }
        }
        false
    }
    let mut path = Vec::new();
    walk(doc, offset, &mut path).then_some(FieldPath(path))
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
[robot]
start = { x_mm = 0.0, y_mm = 0.0 }

[goal]
x_mm = 500.0
y_mm = 0.0
"#;

    fn problems(text: &str) -> Vec<Problem> {
        match parse_scenario_with(text, Path::new("t.toml"), "t", |_| {}, |_, _| {}) {
            Err(LoadError::Invalid { problems }) => problems,
            other => panic!("expected problems, got {other:?}"),
        }
    }

    #[test]
    fn a_minimal_scenario_is_valid_and_named_after_its_file() {
        let s = parse_scenario_with(GOOD, Path::new("t.toml"), "t", |_| {}, |_, _| {}).unwrap();
        assert_eq!(s.name, "t");
        assert_eq!(s.robot.radius_mm, 90.0);
    }

    #[test]
    fn unknown_keys_are_located() {
        let text = GOOD.replace("[goal]\n", "[goal]\nspeed = 3\n");
        let p = &problems(&text)[0];
        assert_eq!((p.line, p.column), (6, 1), "{p}");
        assert_eq!(p.field, "goal.speed");
        assert!(p.message.contains("unknown field"), "{p}");
    }

    #[test]
    fn wrong_types_are_located() {
        let text = GOOD.replace("x_mm = 500.0", "x_mm = \"far\"");
        let p = &problems(&text)[0];
        assert_eq!((p.line, p.column), (6, 8), "{p}");
        assert_eq!(p.field, "goal.x_mm");
    }

    #[test]
    fn rule_violations_name_the_field_and_its_line() {
        let text = GOOD.replace(
            "start = { x_mm = 0.0, y_mm = 0.0 }",
            "start = { x_mm = 0.0, y_mm = 0.0 }\nradius_mm = -90.0",
        );
        let p = &problems(&text)[0];
        assert_eq!(p.field, "robot.radius_mm");
        assert_eq!((p.line, p.column), (4, 1), "{p}");
        assert!(p.message.contains("> 0"));
    }

    #[test]
    fn a_field_left_at_its_default_points_at_its_table() {
        let text = "[run]\nphysics_step_s = 0.003\n[robot]\nstart = { x_mm = 0.0, y_mm = 0.0 }\n[goal]\nx_mm = 1.0\ny_mm = 0.0\n";
        let p = &problems(text)[0];
        assert_eq!(p.field, "run.physics_step_s");
        assert_eq!(p.line, 2);
    }
}
