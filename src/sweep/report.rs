//! The sweep's table: `sweep.csv` (one row a run: the swept values, the seed, every scalar of
//! its `summary.json`, the error if any) and `sweep.md` (one row a combination: runs, success
//! rate, contacts, mean and worst of the main metrics; for runs with a goal, the outcomes of
//! each group of swept values over the seeds, and success and honesty against the truth).

use super::plan::{Plan, describe};
use super::set::value_text;
use super::workers::Outcome;
use serde_json::Value as Json;
use std::fmt::Write as _;

/// One run's row: its values as text, its scalars by column name, its error.
#[derive(Debug, Clone)]
pub struct Row {
    /// The job's index.
    pub run: usize,
    /// Which combination.
    pub combination: usize,
    /// The seed.
    pub seed: u64,
    /// Every scalar of the summary (nested keys joined by dots), in the summary's order.
    pub scalars: Vec<(String, Json)>,
    /// Why the run failed, or "not run" when it never started.
    pub error: Option<String>,
    /// Whether the run succeeded: no error, no contact, and its goal reached when it had one.
    pub success: bool,
}

impl Row {
    /// A scalar as text, when it is a string.
    pub fn text(&self, key: &str) -> Option<&str> {
        self.scalars
            .iter()
            .find(|(k, _)| k == key)
            .and_then(|(_, v)| v.as_str())
    }

    /// A scalar as a number (booleans as 0 and 1).
    pub fn number(&self, key: &str) -> Option<f64> {
        self.scalars
            .iter()
            .find(|(k, _)| k == key)
            .and_then(|(_, v)| match v {
                Json::Bool(b) => Some(if *b { 1.0 } else { 0.0 }),
                v => v.as_f64(),
            })
    }
}

/// The rows of a sweep, in the plan's order.
pub fn rows(plan: &Plan, outcomes: &[Option<Outcome>]) -> Vec<Row> {
    plan.jobs
        .iter()
        .zip(outcomes)
        .map(|(job, o)| {
            let (scalars, error) = match o.as_ref().map(|o| &o.result) {
                Some(Ok(summary)) => {
                    let mut out = Vec::new();
                    let json = serde_json::to_value(summary).unwrap_or(Json::Null);
                    flatten("", &json, &mut out);
                    (out, None)
                }
                Some(Err(e)) => (Vec::new(), Some(e.to_string())),
                None => (
                    Vec::new(),
                    Some("not run (the sweep was stopped)".to_string()),
                ),
            };
            let mut row = Row {
                run: job.index,
                combination: job.combination,
                seed: job.seed,
                scalars,
                error,
                success: false,
            };
            let has_goal = job.scenario.has_goal();
            row.success = row.error.is_none()
                && row.number("wall_contacts") == Some(0.0)
                && (!has_goal || row.number("reached_goal") == Some(1.0));
            row
        })
        .collect()
}

/// A row as one JSON object, the columns of `sweep.csv`: `run`, each swept key and its value,
/// `seed`, `success`, `error` (null when none), then every scalar of the run's summary.
pub fn row_json(plan: &Plan, row: &Row) -> Json {
    let mut m = serde_json::Map::new();
    m.insert("run".into(), row.run.into());
    if let Some(job) = plan.jobs.get(row.run) {
        for (s, v) in plan.sets.iter().zip(&job.values) {
            m.insert(s.key.clone(), serde_json::to_value(v).unwrap_or(Json::Null));
        }
    }
    m.insert("seed".into(), row.seed.into());
    m.insert("success".into(), row.success.into());
    m.insert("error".into(), row.error.clone().into());
    for (k, v) in &row.scalars {
        m.entry(k.clone()).or_insert_with(|| v.clone());
    }
    Json::Object(m)
}

/// The scalars of `v` under `prefix`: objects flattened with dots, arrays left out.
fn flatten(prefix: &str, v: &Json, out: &mut Vec<(String, Json)>) {
    match v {
        Json::Object(map) => {
            for (k, v) in map {
                let key = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                flatten(&key, v, out);
            }
        }
        Json::Array(_) => {}
        scalar => out.push((prefix.to_string(), scalar.clone())),
    }
}

/// The metric columns of `rows`: every scalar key, in the order first met.
fn columns(rows: &[Row]) -> Vec<String> {
    let mut cols: Vec<String> = Vec::new();
    for r in rows {
        for (k, _) in &r.scalars {
            if !cols.contains(k) {
                cols.push(k.clone());
            }
        }
    }
    cols
}

/// A CSV field, quoted when it needs to be.
fn field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// `sweep.csv`: `run`, the swept keys, `seed`, `success`, `error`, then every scalar.
pub fn csv(plan: &Plan, rows: &[Row]) -> String {
    let cols = columns(rows);
    let mut head: Vec<String> = vec!["run".into()];
    head.extend(plan.sets.iter().map(|s| s.key.clone()));
    head.extend(["seed", "success", "error"].map(String::from));
    head.extend(cols.iter().cloned());
    let mut out = head.iter().map(|h| field(h)).collect::<Vec<_>>().join(",") + "\n";
    for (r, job) in rows.iter().zip(&plan.jobs) {
        let mut line = vec![r.run.to_string()];
        line.extend(job.values.iter().map(value_text));
        line.push(r.seed.to_string());
        line.push(r.success.to_string());
        line.push(r.error.clone().unwrap_or_default());
        for c in &cols {
            let v = r.scalars.iter().find(|(k, _)| k == c).map(|(_, v)| v);
            line.push(match v {
                None | Some(Json::Null) => String::new(),
                Some(Json::String(s)) => s.clone(),
                Some(v) => v.to_string(),
            });
        }
        out.push_str(&line.iter().map(|f| field(f)).collect::<Vec<_>>().join(","));
        out.push('\n');
    }
    out
}

/// One combination over its seeds.
#[derive(Debug, Clone)]
pub struct Aggregate {
    /// Which combination.
    pub combination: usize,
    /// Runs that finished (with or without error).
    pub runs: usize,
    /// Runs that failed with an error.
    pub errors: usize,
    /// Successes over runs.
    pub success_rate: f64,
    /// Contacts over all runs.
    pub contacts: u64,
    /// Rows of the combination.
    pub rows: Vec<Row>,
}

impl Aggregate {
    /// The mean of a metric over the runs that have it (`success_rate` is the rate).
    pub fn mean(&self, metric: &str) -> Option<f64> {
        if metric == "success_rate" {
            return Some(self.success_rate);
        }
        let v: Vec<f64> = self.rows.iter().filter_map(|r| r.number(metric)).collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
    }

    /// The worst of a metric: the largest, or the smallest where less is worse.
    pub fn worst(&self, metric: &str) -> Option<f64> {
        let v = self.rows.iter().filter_map(|r| r.number(metric));
        if LESS_IS_WORSE.contains(&metric) {
            v.reduce(f64::min)
        } else {
            v.reduce(f64::max)
        }
    }
}

/// Metrics whose smallest value is the worst.
const LESS_IS_WORSE: [&str; 2] = ["min_clearance_mm", "cycles_per_s"];

/// The combinations' aggregates, in order.
pub fn aggregates(rows: &[Row]) -> Vec<Aggregate> {
    let mut out: Vec<Aggregate> = Vec::new();
    for r in rows {
        match out.last_mut() {
            Some(a) if a.combination == r.combination => a.rows.push(r.clone()),
            _ => out.push(Aggregate {
                combination: r.combination,
                runs: 0,
                errors: 0,
                success_rate: 0.0,
                contacts: 0,
                rows: vec![r.clone()],
            }),
        }
    }
    for a in &mut out {
        let ran: Vec<&Row> = a
            .rows
            .iter()
            .filter(|r| !r.error.as_deref().is_some_and(|e| e.starts_with("not run")))
            .collect();
        a.runs = ran.len();
        a.errors = ran.iter().filter(|r| r.error.is_some()).count();
        a.contacts = ran
            .iter()
            .filter_map(|r| r.number("wall_contacts"))
            .sum::<f64>() as u64;
        let ok = ran.iter().filter(|r| r.success).count();
        a.success_rate = if a.runs == 0 {
            0.0
        } else {
            ok as f64 / a.runs as f64
        };
    }
    out
}

/// The main metrics of `sweep.md`, those any run has.
const MAIN: [(&str, &str); 5] = [
    ("time_to_goal_s", "time to goal (s)"),
    ("min_clearance_mm", "clearance (mm)"),
    ("peak_speed_mm_s", "peak speed (mm/s)"),
    ("pose_error_mm", "pose error (mm)"),
    ("freespace_error_mm", "free-space error (mm)"),
];

/// What the report is asked for beyond the runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReportSettings {
    /// Goals reachable on the true world with at least this margin count as ones the robot
    /// should reach (the success figure); the others as ones it should reach or report
    /// unreachable (the honesty figure), mm.
    pub reachable_margin_mm: f64,
}

/// The default of [`ReportSettings::reachable_margin_mm`]: 40 mm, the clutter generator's
/// passage (260 mm) less a robot of 90 mm, on each side.
pub const DEFAULT_REACHABLE_MARGIN_MM: f64 = 40.0;

impl Default for ReportSettings {
    fn default() -> Self {
        Self {
            reachable_margin_mm: DEFAULT_REACHABLE_MARGIN_MM,
        }
    }
}

/// `sweep.md`: one row a combination; with goals, the section of their outcomes.
pub fn markdown(plan: &Plan, rows: &[Row], header: &str, settings: &ReportSettings) -> String {
    let aggs = aggregates(rows);
    let main: Vec<(&str, &str)> = MAIN
        .into_iter()
        .filter(|(k, _)| rows.iter().any(|r| r.number(k).is_some()))
        .collect();
    let mut md = format!(
        "# Sweep of {} ({})\n\n{header}\n\n",
        plan.name,
        plan.file.display()
    );
    md.push_str("Success: the run ended without error and without a contact, at its goal when it has one. Each metric: mean / worst over the runs that have it (worst clearance is the smallest).\n\n");
    let mut head: Vec<String> = plan.sets.iter().map(|s| s.key.clone()).collect();
    head.extend(["runs", "success", "contacts"].map(String::from));
    head.extend(main.iter().map(|(_, t)| t.to_string()));
    let _ = writeln!(md, "| {} |", head.join(" | "));
    let _ = writeln!(md, "|{}", "---|".repeat(head.len()));
    for a in &aggs {
        let job = &plan.jobs[a.rows[0].run];
        let mut cells: Vec<String> = job.values.iter().map(value_text).collect();
        cells.extend([
            if a.errors > 0 {
                format!("{} ({} failed)", a.runs, a.errors)
            } else {
                a.runs.to_string()
            },
            format!("{:.0}%", 100.0 * a.success_rate),
            a.contacts.to_string(),
        ]);
        for (k, _) in &main {
            cells.push(match (a.mean(k), a.worst(k)) {
                (Some(m), Some(w)) => format!("{} / {}", one_place(m), one_place(w)),
                _ => "-".into(),
            });
        }
        let _ = writeln!(md, "| {} |", cells.join(" | "));
    }
    if let Some(section) = outcomes(plan, rows, settings) {
        md.push('\n');
        md.push_str(&section);
    }
    let failed: Vec<&Row> = rows.iter().filter(|r| r.error.is_some()).collect();
    if !failed.is_empty() {
        md.push_str("\n## Runs that did not finish\n\n");
        for r in failed.iter().take(50) {
            let job = &plan.jobs[r.run];
            let _ = writeln!(
                md,
                "- run {} ({}, seed {}): {}",
                r.run,
                describe(&plan.sets, &job.values),
                r.seed,
                r.error.as_deref().unwrap_or_default()
            );
        }
        if failed.len() > 50 {
            let _ = writeln!(md, "- ... and {} more (sweep.csv)", failed.len() - 50);
        }
    }
    md
}

/// Whether a swept key draws seeds (`seed`, or a key ending in `.seed` such as
/// `experiment.clutter.seed`): the outcome table counts over them.
fn is_seed_key(key: &str) -> bool {
    key == "seed" || key.ends_with(".seed")
}

/// The rows of each group of swept values other than seeds, in the order first met: the
/// group's values as text and its rows.
fn groups<'a>(plan: &Plan, rows: &'a [Row]) -> Vec<(Vec<String>, Vec<&'a Row>)> {
    let mut out: Vec<(Vec<String>, Vec<&Row>)> = Vec::new();
    for r in rows {
        let Some(job) = plan.jobs.get(r.run) else {
            continue;
        };
        let values: Vec<String> = plan
            .sets
            .iter()
            .zip(&job.values)
            .filter(|(s, _)| !is_seed_key(&s.key))
            .map(|(_, v)| value_text(v))
            .collect();
        match out.iter_mut().find(|(v, _)| *v == values) {
            Some((_, members)) => members.push(r),
            None => out.push((values, vec![r])),
        }
    }
    out
}

/// A group's runs by how they ended, and its two figures against the truth.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct Outcomes {
    /// Runs that finished, with or without error.
    runs: usize,
    reached: usize,
    unreachable: usize,
    time_up: usize,
    stuck: usize,
    /// Runs that failed with an error.
    failed: usize,
    /// Runs that touched anything (`wall_contacts > 0`).
    contacts: usize,
    /// Of the runs whose goal is reachable with the margin asked: successes, and how many.
    success: (usize, usize),
    /// Of the other runs with a goal: reached or reported unreachable, and how many.
    honest: (usize, usize),
}

impl Outcomes {
    /// The counts of `rows` against goals reachable with `margin_mm`.
    fn of(rows: &[&Row], margin_mm: f64) -> Self {
        let mut o = Self::default();
        for r in rows {
            if r.error.as_deref().is_some_and(|e| e.starts_with("not run")) {
                continue;
            }
            o.runs += 1;
            if r.error.is_some() {
                o.failed += 1;
                continue;
            }
            o.contacts += usize::from(r.number("wall_contacts").is_some_and(|c| c > 0.0));
            let outcome = r.text("outcome");
            match outcome {
                Some("reached") => o.reached += 1,
                Some("unreachable") => o.unreachable += 1,
                Some("time_up") => o.time_up += 1,
                Some("stuck") => o.stuck += 1,
                _ => continue,
            }
            let wide = r.number("goal_reachable") == Some(1.0)
                && r.number("reachable_margin_mm")
                    .is_some_and(|m| m >= margin_mm);
            let (k, n) = if wide {
                (&mut o.success.0, &mut o.success.1)
            } else {
                (&mut o.honest.0, &mut o.honest.1)
            };
            *n += 1;
            let good = if wide {
                r.success
            } else {
                matches!(outcome, Some("reached" | "unreachable"))
            };
            *k += usize::from(good);
        }
        o
    }
}

/// `k of n (x%)`, `-` for the share of none.
fn share((k, n): (usize, usize)) -> String {
    if n == 0 {
        format!("{k} of {n} (-)")
    } else {
        format!("{k} of {n} ({:.0}%)", 100.0 * k as f64 / n as f64)
    }
}

/// The outcomes section of `sweep.md`, when some run has a goal's outcome: a row a group of
/// swept values other than seeds (runs by outcome, failed, with a contact, and the two figures),
/// then the figures over the whole sweep.
fn outcomes(plan: &Plan, rows: &[Row], settings: &ReportSettings) -> Option<String> {
    if !rows.iter().any(|r| r.text("outcome").is_some()) {
        return None;
    }
    let m = settings.reachable_margin_mm;
    let mut md = format!(
        "## Outcomes\n\nHow each run with a goal ended, on the truth: reached (every target), \
         unreachable (its planner reported it), time_up (time ran out while it made progress), \
         stuck (time ran out with no progress in its last 15 s); contacts: runs that touched \
         anything. Success (the goal reached without a contact) is counted over the goals \
         reachable on the true world with a margin >= {m} mm; honesty (reached, or reported \
         unreachable) over the others.\n\n"
    );
    let mut head: Vec<String> = plan
        .sets
        .iter()
        .filter(|s| !is_seed_key(&s.key))
        .map(|s| s.key.clone())
        .collect();
    let keys = head.len();
    if keys == 0 {
        head.push("runs of".into());
    }
    head.extend(
        [
            "runs",
            "reached",
            "unreachable",
            "time_up",
            "stuck",
            "failed",
            "contacts",
        ]
        .map(String::from),
    );
    head.extend([format!("success (>= {m} mm)"), "honesty".into()]);
    let _ = writeln!(md, "| {} |", head.join(" | "));
    let _ = writeln!(md, "|{}", "---|".repeat(head.len()));
    for (values, members) in groups(plan, rows) {
        let o = Outcomes::of(&members, m);
        let mut cells = if keys == 0 {
            vec!["all".into()]
        } else {
            values
        };
        cells.extend(
            [
                o.runs,
                o.reached,
                o.unreachable,
                o.time_up,
                o.stuck,
                o.failed,
                o.contacts,
            ]
            .map(|n| n.to_string()),
        );
        cells.extend([share(o.success), share(o.honest)]);
        let _ = writeln!(md, "| {} |", cells.join(" | "));
    }
    let all = Outcomes::of(&rows.iter().collect::<Vec<_>>(), m);
    let _ = writeln!(
        md,
        "\n- success over goals reachable with >= {m} mm: {}\n- honesty over the others \
         (reached or reported unreachable): {}",
        share(all.success),
        share(all.honest)
    );
    Some(md)
}

/// `v` to one decimal, a rounded-away sign left out (`-0.0` reads `0.0`).
fn one_place(v: f64) -> String {
    let s = format!("{v:.1}");
    if s == "-0.0" { "0.0".into() } else { s }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nested_scalars_flatten_with_dots_and_arrays_are_left_out() {
        let v = serde_json::json!({"a": 1, "b": {"c": 2.5, "d": [1, 2]}, "e": null});
        let mut out = Vec::new();
        flatten("", &v, &mut out);
        let keys: Vec<&str> = out.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(keys, ["a", "b.c", "e"]);
    }

    /// A run that failed keeps its row with its error; one that never started says so; neither
    /// counts as a success, and only the failed one counts as run.
    #[test]
    fn failed_and_unstarted_runs_keep_their_rows() {
        let scenario = crate::Scenario::from_toml("[robot]\n").expect("a bare scenario parses");
        let set = crate::sweep::set::Set::parse("robot.max_speed_mm_s=400").unwrap();
        let job = |index| crate::sweep::plan::Job {
            index,
            combination: 0,
            values: set.values.clone(),
            seed: index as u64,
            scenario: scenario.clone(),
            toml: "[robot]\n".into(),
        };
        let plan = Plan {
            file: "x.toml".into(),
            name: "x".into(),
            sets: vec![set.clone()],
            jobs: vec![job(0), job(1)],
        };
        let outcomes = vec![
            Some(Outcome {
                job: 0,
                result: Err(crate::sweep::JobError::Recorded(
                    "GPU device error: lost, badly".into(),
                )),
            }),
            None,
        ];
        let rows = rows(&plan, &outcomes);
        assert!(rows.iter().all(|r| !r.success));
        let text = csv(&plan, &rows);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "run,robot.max_speed_mm_s,seed,success,error");
        assert_eq!(lines[1], "0,400,0,false,\"GPU device error: lost, badly\"");
        assert!(
            lines[2].ends_with("not run (the sweep was stopped)"),
            "{}",
            lines[2]
        );
        let a = &aggregates(&rows)[0];
        assert_eq!((a.runs, a.errors, a.success_rate), (1, 1, 0.0));
        let md = markdown(&plan, &rows, "", &ReportSettings::default());
        assert!(md.contains("| 400 | 1 (1 failed) | 0% | 0 |"), "{md}");
    }

    #[test]
    fn csv_fields_with_commas_or_quotes_are_quoted() {
        assert_eq!(field("a,b"), "\"a,b\"");
        assert_eq!(field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(field("plain"), "plain");
    }

    /// A run's row with a goal: its outcome, its route, its contacts.
    fn goal_row(run: usize, outcome: &str, margin_mm: Option<f64>, contacts: u32) -> Row {
        let mut row = Row {
            run,
            combination: run / 3,
            seed: 7,
            scalars: vec![
                ("wall_contacts".into(), contacts.into()),
                ("reached_goal".into(), (outcome == "reached").into()),
                ("outcome".into(), outcome.into()),
                ("goal_reachable".into(), margin_mm.is_some().into()),
                ("reachable_margin_mm".into(), margin_mm.into()),
            ],
            error: None,
            success: false,
        };
        row.success = contacts == 0 && outcome == "reached";
        row
    }

    /// Six runs: cubes 16 and 20, three layout seeds each; the seed key is counted over.
    fn outcome_plan() -> Plan {
        let scenario = crate::Scenario::from_toml("[robot]\n").expect("a bare scenario parses");
        let cubes = crate::sweep::set::Set::parse("experiment.clutter.cubes=16,20").unwrap();
        let seeds = crate::sweep::set::Set::parse("experiment.clutter.seed=1..3:1").unwrap();
        let jobs = (0..6)
            .map(|index| crate::sweep::plan::Job {
                index,
                combination: index,
                values: vec![
                    cubes.values[index / 3].clone(),
                    seeds.values[index % 3].clone(),
                ],
                seed: 7,
                scenario: scenario.clone(),
                toml: "[robot]\n".into(),
            })
            .collect();
        Plan {
            file: "clutter.toml".into(),
            name: "clutter".into(),
            sets: vec![cubes, seeds],
            jobs,
        }
    }

    #[test]
    fn outcomes_are_counted_per_group_of_swept_values_over_the_seeds() {
        let plan = outcome_plan();
        let mut failed = goal_row(4, "reached", None, 0);
        (failed.scalars, failed.error) = (Vec::new(), Some("renderer lost".into()));
        let rows = vec![
            goal_row(0, "reached", Some(80.0), 0),
            goal_row(1, "stuck", Some(45.0), 0),
            goal_row(2, "unreachable", Some(20.0), 1),
            goal_row(3, "time_up", None, 0),
            failed,
            goal_row(5, "reached", Some(39.0), 0),
        ];
        let md = markdown(&plan, &rows, "", &ReportSettings::default());
        assert!(
            md.contains("| experiment.clutter.cubes | runs | reached | unreachable | time_up | stuck | failed | contacts | success (>= 40 mm) | honesty |"),
            "{md}"
        );
        assert!(
            md.contains("| 16 | 3 | 1 | 1 | 0 | 1 | 0 | 1 | 1 of 2 (50%) | 1 of 1 (100%) |"),
            "{md}"
        );
        assert!(
            md.contains("| 20 | 3 | 1 | 0 | 1 | 0 | 1 | 0 | 0 of 0 (-) | 1 of 2 (50%) |"),
            "{md}"
        );
        assert!(
            md.contains("- success over goals reachable with >= 40 mm: 1 of 2 (50%)"),
            "{md}"
        );
        assert!(
            md.contains(
                "- honesty over the others (reached or reported unreachable): 2 of 3 (67%)"
            ),
            "{md}"
        );
        // A lower margin moves the goal of 39 mm to the success figure.
        let low = ReportSettings {
            reachable_margin_mm: 30.0,
        };
        let md = markdown(&plan, &rows, "", &low);
        assert!(
            md.contains("- success over goals reachable with >= 30 mm: 2 of 3 (67%)"),
            "{md}"
        );
        // A sweep whose runs have no goal has no outcomes.
        let bare: Vec<Row> = rows
            .iter()
            .map(|r| Row {
                scalars: vec![("wall_contacts".into(), 0.into())],
                ..r.clone()
            })
            .collect();
        let md = markdown(&plan, &bare, "", &ReportSettings::default());
        assert!(!md.contains("## Outcomes"), "{md}");
    }

    #[test]
    fn a_sweep_over_seeds_alone_is_one_group() {
        let mut plan = outcome_plan();
        plan.sets.remove(0);
        for j in &mut plan.jobs {
            j.values.remove(0);
        }
        let rows: Vec<Row> = (0..6)
            .map(|k| goal_row(k, "reached", Some(60.0), 0))
            .collect();
        let md = markdown(&plan, &rows, "", &ReportSettings::default());
        assert!(md.contains("| runs of | runs | reached |"), "{md}");
        assert!(
            md.contains("| all | 6 | 6 | 0 | 0 | 0 | 0 | 0 | 6 of 6 (100%) | 0 of 0 (-) |"),
            "{md}"
        );
        assert!(is_seed_key("seed") && is_seed_key("experiment.clutter.seed"));
        assert!(!is_seed_key("robot.seeding") && !is_seed_key("experiment.clutter.cubes"));
    }

    #[test]
    fn goal_columns_come_into_the_csv_from_the_summary() {
        let plan = outcome_plan();
        let summary: crate::run::Summary = serde_json::from_str(
            r#"{"scenario":"clutter","seed":7,"controller":"c","cycles":3,"sim_time_s":60.0,
            "wall_time_s":0.1,"cycles_per_s":30.0,"wall_contacts":0,"peak_speed_mm_s":0.0,
            "peak_accel_mm_s2":0.0,"reached_goal":false,"time_to_goal_s":null,
            "outcome":"unreachable","unreachable_reason":"no_route","goal_reachable":false,
            "reachable_margin_mm":null,"min_clearance_mm":5.0,"path_length_mm":0.0}"#,
        )
        .unwrap();
        let outcomes: Vec<Option<Outcome>> = (0..6)
            .map(|job| {
                Some(Outcome {
                    job,
                    result: Ok(summary.clone()),
                })
            })
            .collect();
        let rows = rows(&plan, &outcomes);
        let text = csv(&plan, &rows);
        let mut lines = text.lines().map(|l| l.split(',').collect::<Vec<_>>());
        let head = lines.next().unwrap();
        let first = lines.next().unwrap();
        let cell = |col: &str| {
            let k = head
                .iter()
                .position(|h| *h == col)
                .unwrap_or_else(|| panic!("{col}"));
            first[k]
        };
        assert_eq!(cell("outcome"), "unreachable");
        assert_eq!(cell("unreachable_reason"), "no_route");
        assert_eq!(cell("goal_reachable"), "false");
        assert_eq!(cell("reachable_margin_mm"), "");
        let md = markdown(&plan, &rows, "", &ReportSettings::default());
        assert!(
            md.contains(
                "- honesty over the others (reached or reported unreachable): 6 of 6 (100%)"
            ),
            "{md}"
        );
    }
}
