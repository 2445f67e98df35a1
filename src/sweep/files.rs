//! A sweep's files: `sweep.csv`, `sweep.md` and `sweep.png`.

use super::plan::Plan;
use super::plot;
use super::report::{self, ReportSettings, Row};
use super::workers::Outcome;
use std::path::Path;

/// The report of `outcomes` into `dir`: `sweep.csv`, `sweep.md` (after `header` and the
/// figure's name) and `sweep.png` of `plot` (success_rate when no run has that number, with a
/// warning on standard error); the markdown and the rows. The report's settings are the
/// defaults ([`report_with`] takes them).
pub fn report(
    dir: &Path,
    plan: &Plan,
    outcomes: &[Option<Outcome>],
    plot: &str,
    header: &str,
) -> anyhow::Result<(String, Vec<Row>)> {
    report_with(
        dir,
        plan,
        outcomes,
        plot,
        header,
        &ReportSettings::default(),
    )
}

/// [`report`] with the report's `settings`.
pub fn report_with(
    dir: &Path,
    plan: &Plan,
    outcomes: &[Option<Outcome>],
    plot: &str,
    header: &str,
    settings: &ReportSettings,
) -> anyhow::Result<(String, Vec<Row>)> {
    let rows = report::rows(plan, outcomes);
    let mut metric = plot.to_string();
    if !known_metric(&rows, &metric) {
        eprintln!("--plot {metric}: no run has this number; plotting success_rate");
        metric = "success_rate".into();
    }
    let header = format!("{header} Figure: sweep.png ({metric}).");
    let md = write_outputs(dir, plan, &rows, &metric, &header, settings)?;
    Ok((md, rows))
}

/// Writes `sweep.csv`, `sweep.md` (after `header`, as `settings` ask) and `sweep.png` of
/// `metric` into `dir`; returns the markdown.
pub fn write_outputs(
    dir: &Path,
    plan: &Plan,
    rows: &[Row],
    metric: &str,
    header: &str,
    settings: &ReportSettings,
) -> anyhow::Result<String> {
    use anyhow::Context;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let write = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).with_context(|| format!("writing {}", path.display()))
    };
    write("sweep.csv", report::csv(plan, rows).as_bytes())?;
    let md = report::markdown(plan, rows, header, settings);
    write("sweep.md", md.as_bytes())?;
    write("sweep.png", &plot::sweep_png(plan, rows, metric)?)?;
    Ok(md)
}

/// Whether `metric` can be plotted: `success_rate` or a numeric column some run has.
pub fn known_metric(rows: &[Row], metric: &str) -> bool {
    metric == "success_rate" || rows.iter().any(|r| r.number(metric).is_some())
}
