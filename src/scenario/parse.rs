//! Parsing a scenario: TOML, schema, the rules, with every problem located by file, line,
//! column and field. The experiments' own preparation and checks come in as arguments from
//! the layer that knows them ([`crate::experiments::parse_scenario`]).

use super::check::{FieldPath, Location, PathSeg, Problem, Problems};
use super::rules::validate;
use super::schema::{RobotSpec, Scenario};
use super::team;
use omniloop_robot::VisionSpec;
use omniloop_sim::optics::Optics;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::de::{DeTable, DeValue};

/// Why a scenario could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file could not be read.
    #[error("cannot read scenario {}: {reason}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// Why (in the message, not a separate cause).
        reason: std::io::Error,
    },
    /// The file is not a valid scenario.
    #[error("{}", problems.iter().map(|p| p.to_string()).collect::<Vec<_>>().join("\n"))]
    Invalid {
        /// Every problem found, in file order, each located in the file.
        problems: Vec<Problem>,
    },
}

/// Reads, parses and validates a scenario file with the experiments' `prepare` and `check`
/// (see [`parse_scenario_with`]). The scenario's name defaults to the file stem.
pub fn load_scenario_with(
    path: &Path,
    prepare: impl FnOnce(&mut Scenario),
    check: impl FnOnce(&Scenario, &mut Problems),
) -> Result<Scenario, LoadError> {
    let text = std::fs::read_to_string(path).map_err(|reason| LoadError::Io {
        file: path.to_path_buf(),
        reason,
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
    check: impl FnOnce(&Scenario, &mut Problems),
) -> Result<Scenario, LoadError> {
    let doc = DeTable::parse(text).ok();
    let at = Locator {
        text,
        file,
        doc: doc.as_ref().map(|d| d.get_ref()),
    };
    let mut scenario = Scenario::from_toml(text).map_err(|e| at.syntax_error(&e))?;
    if scenario.name.is_empty() {
        scenario.name = default_name.to_string();
    }
    // A team's robots: each entry of [[robots]] over the shared tables.
    if !scenario.robots.is_empty() {
        let raw: toml::Table = toml::from_str(text).unwrap_or_default();
        scenario.team = team::resolve(&raw).map_err(|p| at.invalid(p))?;
    }
    // An experiment may build part of the world (the corner's corridor, start and goal).
    prepare(&mut scenario);
    resolve_scenario_files(&mut scenario, file);
    let mut problems = Problems::new();
    problems.extend(if scenario.is_team() {
        team::validate_team(&scenario)
    } else {
        validate(&scenario)
    });
    let mut own = Problems::new();
    check(&scenario, &mut own);
    problems.extend(own);
    if problems.is_empty() {
        return Ok(scenario);
    }
    Err(at.invalid(problems.into_vec()))
}

/// Locates problems in the scenario's text (its parsed document, when it parses as TOML).
struct Locator<'a> {
    text: &'a str,
    file: &'a Path,
    doc: Option<&'a DeTable<'a>>,
}

impl Locator<'_> {
    /// The location of a byte span (the start of the file without one).
    fn location(&self, span: Option<Range<usize>>) -> Location {
        let (line, column) = span.map_or((1, 1), |s| line_col(self.text, s.start));
        Location {
            file: self.file.to_path_buf(),
            line,
            column,
        }
    }

    /// A text that is no scenario (TOML syntax, an unknown key, a wrong type), named by the
    /// field at the error's place when there is one.
    fn syntax_error(&self, e: &toml::de::Error) -> LoadError {
        let span = e.span();
        let field = match (self.doc, &span) {
            (Some(d), Some(s)) => path_at(d, s.start).unwrap_or_default(),
            _ => FieldPath::default(),
        };
        let problem = Problem::new(field, e.message().trim()).located(self.location(span));
        LoadError::Invalid {
            problems: vec![problem],
        }
    }

    /// The scenario's problems, each located at its field, in file order.
    fn invalid(&self, problems: Vec<Problem>) -> LoadError {
        let mut problems: Vec<Problem> = problems
            .into_iter()
            .map(|p| {
                let span = self.doc.and_then(|d| span_of(d, &p.field));
                let at = self.location(span);
                p.located(at)
            })
            .collect();
        problems.sort_by_key(|p| p.location.as_ref().map(|l| (l.line, l.column)));
        LoadError::Invalid { problems }
    }
}

/// Paths in a scenario are relative to its file; calibrated cameras read their files now
/// (what fails is reported with the rules).
fn resolve_scenario_files(scenario: &mut Scenario, file: &Path) {
    let dir = file.parent().unwrap_or(Path::new(""));
    resolve_files(&mut scenario.vision, &mut scenario.robot, dir);
    for m in &mut scenario.team {
        resolve_files(&mut m.vision, &mut m.robot, dir);
    }
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

    fn line_col_of(p: &Problem) -> (usize, usize) {
        let at = p.location.as_ref().expect("a located problem");
        assert_eq!(at.file, Path::new("t.toml"));
        (at.line, at.column)
    }

    #[test]
    fn a_syntax_error_is_located_without_a_field() {
        let p = &problems("[robot\n")[0];
        assert!(p.field.is_empty(), "{p}");
        assert!(p.to_string().starts_with("t.toml:1:"), "{p}");
        assert!(!p.to_string().contains("field `"), "{p}");
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
        assert_eq!(line_col_of(p), (6, 1), "{p}");
        assert_eq!(p.field.to_string(), "goal.speed");
        assert!(p.message.contains("unknown field"), "{p}");
    }

    #[test]
    fn wrong_types_are_located() {
        let text = GOOD.replace("x_mm = 500.0", "x_mm = \"far\"");
        let p = &problems(&text)[0];
        assert_eq!(line_col_of(p), (6, 8), "{p}");
        assert_eq!(p.field.to_string(), "goal.x_mm");
    }

    #[test]
    fn rule_violations_name_the_field_and_its_line() {
        let text = GOOD.replace(
            "start = { x_mm = 0.0, y_mm = 0.0 }",
            "start = { x_mm = 0.0, y_mm = 0.0 }\nradius_mm = -90.0",
        );
        let p = &problems(&text)[0];
        assert_eq!(p.field.to_string(), "robot.radius_mm");
        assert_eq!(line_col_of(p), (4, 1), "{p}");
        assert!(p.message.contains("> 0"));
    }

    #[test]
    fn a_field_left_at_its_default_points_at_its_table() {
        let text = "[run]\nphysics_step_s = 0.003\n[robot]\nstart = { x_mm = 0.0, y_mm = 0.0 }\n[goal]\nx_mm = 1.0\ny_mm = 0.0\n";
        let p = &problems(text)[0];
        assert_eq!(p.field.to_string(), "run.physics_step_s");
        assert_eq!(line_col_of(p).0, 2);
    }
}
