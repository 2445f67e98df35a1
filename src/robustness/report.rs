//! The robustness replay's outputs: `robustness.md` (per estimator, its error at every level of
//! every knob and the level from which its target fails), `robustness.csv` (one row a cell) and
//! `robustness.png` (one panel per estimator: its error against each knob's level).

use super::estimators::Estimator;
use super::grid::{Cell, Grid, Outcome};
use super::knobs::Knob;
use crate::report::charts::{Chart, PALETTE, Series, Style, charts_png};
use crate::report::topview::FigureError;
use std::fmt::Write as _;

/// The cells of one estimator and one knob, in level order.
fn row<'a>(grid: &'a Grid, e: &Estimator, k: &Knob) -> Vec<&'a Cell> {
    grid.cells
        .iter()
        .filter(|c| std::ptr::eq(c.estimator, e) && std::ptr::eq(c.knob, k))
        .collect()
}

/// The estimators and knobs of the grid, in its order.
fn axes(grid: &Grid) -> (Vec<&'static Estimator>, Vec<&'static Knob>) {
    let mut es: Vec<&'static Estimator> = Vec::new();
    let mut ks: Vec<&'static Knob> = Vec::new();
    for c in &grid.cells {
        if !es.iter().any(|e| std::ptr::eq(*e, c.estimator)) {
            es.push(c.estimator);
        }
        if !ks.iter().any(|k| std::ptr::eq(*k, c.knob)) {
            ks.push(c.knob);
        }
    }
    (es, ks)
}

/// A level as the tables write it.
fn level_text(v: f64) -> String {
    if v.fract() == 0.0 {
        format!("{v:.0}")
    } else {
        format!("{v}")
    }
}

/// An error as the tables write it, three significant digits or so.
fn error_text(v: f64) -> String {
    if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else if v.abs() >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// The first level where the target fails, as the table words it.
fn first_failure(cells: &[&Cell]) -> String {
    if cells
        .iter()
        .all(|c| matches!(c.outcome, Outcome::NotApplicable(_)))
    {
        return "n/a".into();
    }
    let failed = |c: &&&Cell| !matches!(&c.outcome, Outcome::Scored(s) if s.meets());
    match cells.iter().find(failed) {
        None => "holds".into(),
        Some(c) => level_text(c.level),
    }
}

/// `robustness.md`.
pub fn markdown(grid: &Grid, header: &str) -> String {
    let (es, ks) = axes(grid);
    let mut md = String::from("# Robustness: each estimator against each knob\n\n");
    md.push_str(header);
    md.push_str(
        "\nEach cell is one run's error; ✗ marks a run that misses the estimator's target (how, \
         below the table). \"First fails at\" is the lowest level where it misses.\n",
    );
    let mut reasons: Vec<String> = Vec::new();
    for e in es {
        let _ = write!(
            md,
            "\n## {}\n\nError: {}. Target: {}.\n\n| knob | levels | error at each level | first fails at |\n|---|---|---|---|\n",
            e.title, e.error_label, e.target
        );
        for &k in &ks {
            let cells = row(grid, e, k);
            let levels: Vec<String> = cells.iter().map(|c| level_text(c.level)).collect();
            let errors: Vec<String> = cells.iter().map(|c| cell_text(c, &mut reasons)).collect();
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} |",
                k.label,
                levels.join(", "),
                errors.join(", "),
                first_failure(&cells)
            );
        }
        let misses: Vec<String> = ks
            .iter()
            .flat_map(|k| row(grid, e, k))
            .filter_map(|c| match &c.outcome {
                Outcome::Scored(s) => s
                    .missed
                    .as_ref()
                    .map(|m| format!("{} {}: {m}", c.knob.name, level_text(c.level))),
                _ => None,
            })
            .collect();
        if !misses.is_empty() {
            let _ = writeln!(md, "\nMissed: {}.", misses.join("; "));
        }
    }
    if !reasons.is_empty() {
        md.push_str("\n## Notes\n\n");
        for (i, r) in reasons.iter().enumerate() {
            let _ = writeln!(md, "{}. {r}", i + 1);
        }
    }
    md
}

/// A cell's text; a reason (not applicable, failed) goes to the notes with its number.
fn cell_text(c: &Cell, reasons: &mut Vec<String>) -> String {
    let mut note = |why: &str| {
        let k = match reasons.iter().position(|r| r == why) {
            Some(k) => k,
            None => {
                reasons.push(why.to_string());
                reasons.len() - 1
            }
        };
        k + 1
    };
    match &c.outcome {
        Outcome::Scored(s) if s.meets() => error_text(s.error),
        Outcome::Scored(s) => format!("{} ✗", error_text(s.error)),
        Outcome::NotApplicable(why) => format!("n/a [{}]", note(&format!("n/a: {why}"))),
        Outcome::Failed(why) => format!("— ✗ [{}]", note(&format!("no result: {why}"))),
    }
}

/// `robustness.csv`: estimator, knob, level, error, whether the target was met, the note.
pub fn csv(grid: &Grid) -> String {
    let mut out = String::from("estimator,knob,level,error,meets_target,run,note\n");
    for c in &grid.cells {
        let (error, meets, note) = match &c.outcome {
            Outcome::Scored(s) => (
                s.error.to_string(),
                s.meets().to_string(),
                s.missed.clone().unwrap_or_default(),
            ),
            Outcome::NotApplicable(why) => (String::new(), String::new(), format!("n/a: {why}")),
            Outcome::Failed(why) => (String::new(), "false".into(), why.clone()),
        };
        let run = c.run.map_or(String::new(), |r| r.to_string());
        let _ = writeln!(
            out,
            "{},{},{},{error},{meets},{run},\"{}\"",
            c.estimator.name,
            c.knob.name,
            c.level,
            note.replace('"', "\"\"")
        );
    }
    out
}

/// `robustness.png`: one panel per estimator, each knob a line of its error against the
/// knob's level as a share of its largest (so all knobs share the axis), the target's bound
/// dashed, runs that miss the target crossed. Errors beyond four times the bound are drawn at
/// four times the bound.
pub fn figure(grid: &Grid) -> Result<Vec<u8>, FigureError> {
    let (es, ks) = axes(grid);
    let charts: Vec<Chart> = es
        .iter()
        .enumerate()
        .map(|(i, e)| panel(grid, e, &ks, i == 0))
        .collect();
    charts_png("robustness.png", &charts, charts.len().min(4), (430, 320))
}

fn panel(grid: &Grid, e: &Estimator, ks: &[&'static Knob], legend: bool) -> Chart {
    let cap = e.bound.map(|b| 4.0 * b);
    let shown = |v: f64| cap.map_or(v, |c| v.min(c));
    let mut series = Vec::new();
    let mut misses = Vec::new();
    let mut top: f64 = e.bound.unwrap_or(0.0);
    for (j, k) in ks.iter().enumerate() {
        let largest = k.levels.iter().copied().fold(0.0, f64::max).max(1e-9);
        let mut points = Vec::new();
        for c in row(grid, e, k) {
            if let Outcome::Scored(s) = &c.outcome {
                let p = (c.level / largest, shown(s.error));
                top = top.max(p.1);
                points.push(p);
                if !s.meets() {
                    misses.push(p);
                }
            }
        }
        let range = format!(
            "{} {}-{} {}",
            k.name,
            level_text(k.levels[0]),
            level_text(largest),
            k.unit
        );
        series.push(Series {
            label: if legend { range } else { String::new() },
            rgb: PALETTE[j % PALETTE.len()],
            points,
            style: Style::Line,
        });
    }
    if let Some(b) = e.bound {
        series.push(Series {
            label: String::new(),
            rgb: [0, 0, 0],
            points: (0..=20).map(|i| (f64::from(i) / 20.0, b)).collect(),
            style: Style::Dots,
        });
    }
    series.push(Series {
        label: if legend {
            "misses target".into()
        } else {
            String::new()
        },
        rgb: [200, 0, 0],
        points: misses,
        style: Style::Crosses,
    });
    Chart {
        title: e.title.to_string(),
        x_label: "knob level / its largest".into(),
        y_label: e.error_label.to_string(),
        x_range: (-0.03, 1.03),
        y_range: (0.0, (top * 1.1).max(1e-6)),
        series,
    }
}
