//! Teams (`[[robots]]`): each robot's entry written over the shared one-robot tables, and the
//! team checked robot by robot, every problem named at the key that caused it.
//!
//! An entry holds the keys of `[robot]` (`name`, `start`, `rgb`, `marking_rgb`, `sensors`,
//! `timing`, ...) and its own `goal`, `vision`, `control` and `odometry` tables. Each is
//! written over the shared table of the same name, key by key, tables inside tables too
//! (`[robots.control.avoidance] margin_mm = 40` changes that one key of the shared
//! `[control.avoidance]`); an array (`sensors`, `waypoints_mm`) replaces the shared one whole.
//! A problem in a key the entry writes is named `robots[K].KEY`; in a key it takes from the
//! shared tables, by that table's path (`control.kind`), once for the whole team.

use super::rules::validate;
use super::schema::{OdometrySpec, RobotSpec, Scenario, TeamMember};
use omniloop_problem::{FieldPath, PathSeg, Problem, Problems};
use omniloop_robot::{ControlSpec, GoalSpec, VisionSpec};
use serde::de::DeserializeOwned;
use toml::{Table, Value};

/// The tables of an entry that are written over the shared tables of the same name; every
/// other key of an entry is a key of `[robot]`.
pub const SECTIONS: [&str; 4] = ["goal", "vision", "control", "odometry"];

/// Keys every robot writes for itself: a problem with one is the robot's even where the
/// entry leaves it out.
const OWN_KEYS: [&str; 2] = ["name", "start"];

/// The team of a scenario document: each entry of `[[robots]]` over the shared tables (empty
/// without `[[robots]]`).
pub fn resolve(doc: &Table) -> Result<Vec<TeamMember>, Vec<Problem>> {
    let Some(Value::Array(entries)) = doc.get("robots") else {
        return Ok(Vec::new());
    };
    let mut team = Vec::with_capacity(entries.len());
    let mut problems = Vec::new();
    for (k, entry) in entries.iter().enumerate() {
        let Value::Table(entry) = entry else {
            problems.push(violation(
                FieldPath::parse(&format!("robots[{k}]")),
                "must be a table ([[robots]])",
            ));
            continue;
        };
        match member(doc, k, entry) {
            Ok(m) => team.push(m),
            Err(v) => problems.push(v),
        }
    }
    if problems.is_empty() {
        Ok(team)
    } else {
        Err(problems)
    }
}

/// Robot `k` of the team: `entry` over the shared tables of `doc`.
fn member(doc: &Table, k: usize, entry: &Table) -> Result<TeamMember, Problem> {
    let robot_keys: Table = entry
        .iter()
        .filter(|(key, _)| !SECTIONS.contains(&key.as_str()))
        .map(|(key, v)| (key.clone(), v.clone()))
        .collect();
    let robot: RobotSpec = section(doc, k, entry, "robot", Some(&robot_keys))?;
    let goal_written = doc.contains_key("goal") || entry.contains_key("goal");
    let goal: Option<GoalSpec> = if goal_written {
        Some(section(doc, k, entry, "goal", None)?)
    } else {
        None
    };
    Ok(TeamMember {
        name: robot.name.clone().unwrap_or_default(),
        robot,
        goal,
        vision: section::<VisionSpec>(doc, k, entry, "vision", None)?,
        control: section::<ControlSpec>(doc, k, entry, "control", None)?,
        odometry: section::<OdometrySpec>(doc, k, entry, "odometry", None)?,
    })
}

/// Section `name` of robot `k`: the entry's keys (`own`, or its table `name`) over the shared
/// table, parsed as `T`; a problem is named where its key is written.
fn section<T: DeserializeOwned>(
    doc: &Table,
    k: usize,
    entry: &Table,
    name: &str,
    own: Option<&Table>,
) -> Result<T, Problem> {
    let mut merged = match doc.get(name) {
        Some(Value::Table(t)) => t.clone(),
        _ => Table::new(),
    };
    let over = match (own, entry.get(name)) {
        (Some(t), _) => Some(t),
        (None, Some(Value::Table(t))) => Some(t),
        (None, Some(other)) => {
            return Err(violation(
                FieldPath::parse(&format!("robots[{k}].{name}")),
                &format!("must be a table (got {})", other.type_str()),
            ));
        }
        (None, None) => None,
    };
    if let Some(t) = over {
        write_over(&mut merged, t);
    }
    serde_path_to_error::deserialize(Value::Table(merged)).map_err(|e| {
        let message = e.inner().to_string();
        // The path names an unknown key itself.
        let path = match e.path().to_string().as_str() {
            "." | "" => FieldPath::default(),
            p => FieldPath::parse(p),
        };
        let mut full = FieldPath(vec![PathSeg::Key(name.to_string())]);
        full.0.extend(path.0);
        violation(
            attribute(entry, k, &full),
            message.trim().lines().next().unwrap_or_default(),
        )
    })
}

/// Writes `over` over `base` key by key, tables inside tables too; any other value (an array
/// among them) replaces the base's.
pub fn write_over(base: &mut Table, over: &Table) {
    for (key, value) in over {
        match (base.get_mut(key), value) {
            (Some(Value::Table(b)), Value::Table(o)) => write_over(b, o),
            _ => {
                base.insert(key.clone(), value.clone());
            }
        }
    }
}

fn violation(path: FieldPath, message: &str) -> Problem {
    Problem::new(path, message)
}

/// Where a problem of robot `k` at `path` (in its one-robot form: `robot.KEY`,
/// `control.KEY`, ...) is written: in its entry (`robots[k].KEY`, `robots[k].control.KEY`)
/// when the entry writes the key or the key is one every robot writes for itself, else in the
/// shared table (the path as it is). Paths outside the robot's tables are left as they are.
pub fn attribute(entry: &Table, k: usize, path: &FieldPath) -> FieldPath {
    let Some(PathSeg::Key(first)) = path.0.first() else {
        return path.clone();
    };
    let within: &[PathSeg] = match first.as_str() {
        "robot" => &path.0[1..],
        s if SECTIONS.contains(&s) => &path.0,
        _ => return path.clone(),
    };
    let own = first == "robot"
        && matches!(within.first(), Some(PathSeg::Key(key)) if OWN_KEYS.contains(&key.as_str()));
    let writes = writes_path(entry, within);
    if !(own || writes) {
        return path.clone();
    }
    let mut out = vec![PathSeg::Key("robots".into()), PathSeg::Index(k)];
    out.extend(within.iter().cloned());
    FieldPath(out)
}

/// Whether `table` writes `path`: every key down to it is there, or an array or value on the
/// way (an array the entry writes replaces the shared one whole).
fn writes_path(table: &Table, path: &[PathSeg]) -> bool {
    let Some(PathSeg::Key(key)) = path.first() else {
        return true;
    };
    match (table.get(key), path.get(1)) {
        (None, _) => false,
        (Some(Value::Table(t)), Some(PathSeg::Key(_))) => writes_path(t, &path[1..]),
        _ => true,
    }
}

/// Every rule a team scenario breaks: each robot's, in its one-robot form, named where it is
/// written (a shared table's problem once), and the team's own: names, starts apart, no
/// experiment.
pub fn validate_team(s: &Scenario) -> Vec<Problem> {
    let mut out = Problems::new();
    for (k, entry) in s.robots.iter().enumerate() {
        // `[ssl]` names the team's robots: checked once below, against every robot's name.
        let member = Scenario {
            ssl: None,
            ..s.member(k)
        };
        out.merge(validate(&member).into_iter().map(|p| Problem {
            field: attribute(entry, k, &p.field),
            ..p
        }));
    }
    if let Some(ssl) = &s.ssl {
        out.extend(ssl.check(&s.robot_names()).into_vec());
    }
    team_rules(s, &mut out);
    out.into_vec()
}

/// The team's own rules: every robot named once, with a name fit for files and topics; no
/// two robots overlapping at the start; no experiment.
fn team_rules(s: &Scenario, c: &mut Problems) {
    for (k, m) in s.team.iter().enumerate() {
        let field = format!("robots[{k}].name");
        if m.name.is_empty() {
            c.fail(
                &field,
                "missing: every robot of a team is named, e.g. name = \"blue1\"",
            );
        } else if !m
            .name
            .chars()
            .all(|ch| ch.is_ascii_alphanumeric() || ch == '_' || ch == '-')
        {
            c.fail(
                &field,
                format!(
                    "{:?}: a robot's name is letters, digits, `_` and `-` (it names its files \
                     and channels)",
                    m.name
                ),
            );
        } else if let Some(j) = s.team[..k].iter().position(|o| o.name == m.name) {
            c.fail(
                &field,
                format!("robot name {:?} is used twice (robots[{j}] has it)", m.name),
            );
        }
    }
    starts_apart(s, c);
    if let Some(name) = s.experiment_name() {
        c.fail(
            "experiment",
            format!(
                "a team ([[robots]]) runs no experiment (found `{name}`): the experiments are \
                 procedures for one robot"
            ),
        );
    }
}

/// No robot of the team starts overlapping another robot of the team or a scripted one.
fn starts_apart(s: &Scenario, c: &mut Problems) {
    let others = s
        .other_robots
        .iter()
        .enumerate()
        .map(|(i, o)| (format!("other_robots[{i}]"), o.start.point(), o.radius_mm));
    let team: Vec<(String, nalgebra::Point2<f64>, f64)> = s
        .team
        .iter()
        .filter_map(|m| Some((m.name.clone(), m.robot.start?.point(), m.robot.radius_mm)))
        .collect();
    let all: Vec<_> = team.iter().cloned().chain(others).collect();
    for (k, m) in s.team.iter().enumerate() {
        let Some(start) = m.robot.start else { continue };
        let p = start.point();
        for (j, (other, q, r)) in all.iter().enumerate() {
            let earlier = j < k;
            let scripted = j >= team.len();
            if !(earlier || scripted) || j == k {
                continue;
            }
            let gap = (p - q).norm() - r - m.robot.radius_mm;
            if gap < 0.0 {
                c.fail(
                    format!("robots[{k}].start"),
                    format!(
                        "robot {:?} starts overlapping {other} ({:.0} mm between the centres, \
                         radii {} + {} mm)",
                        m.name,
                        (p - q).norm(),
                        m.robot.radius_mm,
                        r
                    ),
                );
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> Table {
        toml::from_str(text).unwrap()
    }

    #[test]
    fn an_entry_is_written_over_the_shared_tables_key_by_key() {
        let doc = table(
            r#"
[robot]
max_speed_mm_s = 500.0
[control]
kind = "velocity_aware"
[control.avoidance]
margin_mm = 30.0
candidates = 32
[[robots]]
name = "a"
start = { x_mm = 0.0, y_mm = 0.0 }
[robots.control.avoidance]
margin_mm = 45.0
[[robots]]
name = "b"
start = { x_mm = 500.0, y_mm = 0.0 }
max_speed_mm_s = 300.0
goal = { x_mm = 1.0, y_mm = 2.0 }
"#,
        );
        let team = resolve(&doc).unwrap();
        assert_eq!(team.len(), 2);
        assert_eq!(team[0].robot.max_speed_mm_s, 500.0);
        assert_eq!(team[1].robot.max_speed_mm_s, 300.0);
        let avoid = |m: &TeamMember| m.control.tables.0["avoidance"].clone();
        assert_eq!(avoid(&team[0])["margin_mm"].as_float(), Some(45.0));
        assert_eq!(avoid(&team[0])["candidates"].as_integer(), Some(32));
        assert_eq!(avoid(&team[1])["margin_mm"].as_float(), Some(30.0));
        assert!(team[0].goal.is_none());
        assert_eq!(team[1].goal.as_ref().map(|g| g.y_mm), Some(2.0));
        assert_eq!(team[1].name, "b");
    }

    #[test]
    fn a_bad_key_is_named_where_it_is_written() {
        let doc = table(
            "[robot]\nradius_mm = \"wide\"\n[[robots]]\nname = \"a\"\n[[robots]]\nname = \"b\"\nheight_mm = \"tall\"\n",
        );
        let problems = resolve(&doc).unwrap_err();
        let paths: Vec<String> = problems.iter().map(|p| p.field.to_string()).collect();
        assert_eq!(
            paths,
            ["robot.radius_mm", "robots[1].height_mm"],
            "{problems:?}"
        );
        let doc = table("[[robots]]\nname = \"a\"\nspeed = 3\n");
        let problems = resolve(&doc).unwrap_err();
        assert_eq!(problems[0].field.to_string(), "robots[0].speed");
        assert!(problems[0].message.contains("unknown field"));
    }

    #[test]
    fn attribution_follows_what_the_entry_writes() {
        let entry = table("name = \"a\"\n[control]\nkind = \"wander\"\n");
        let at = |p: &str| attribute(&entry, 2, &FieldPath::parse(p)).to_string();
        assert_eq!(at("control.kind"), "robots[2].control.kind");
        assert_eq!(at("control.pose_source"), "control.pose_source");
        assert_eq!(at("robot.start"), "robots[2].start");
        assert_eq!(at("robot.radius_mm"), "robot.radius_mm");
        assert_eq!(at("world.cubes[0].size_mm"), "world.cubes[0].size_mm");
    }

    #[test]
    fn seeds_differ_between_robots_but_the_first_keeps_the_scenarios() {
        use super::super::schema::member_seed;
        assert_eq!(member_seed(7, 0), 7);
        let seeds: Vec<u64> = (0..12).map(|k| member_seed(7, k)).collect();
        for (i, a) in seeds.iter().enumerate() {
            assert!(!seeds[..i].contains(a));
        }
    }
}
