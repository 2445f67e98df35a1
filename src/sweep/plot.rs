//! `sweep.png`: a metric's mean over the seeds, as a heat map over the first two swept keys
//! (averaged over any further ones), a line over the one swept key, or a line over the seeds.

use super::plan::Plan;
use super::report::{Aggregate, Row, aggregates};
use super::set::value_text;
use crate::report::charts::{Chart, Series, Style, charts_png};
use crate::report::topview::{FigureError, PlotError, png_bytes, register_font};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

/// The figure of `metric` (`success_rate` or a column of `sweep.csv`).
pub fn sweep_png(plan: &Plan, rows: &[Row], metric: &str) -> Result<Vec<u8>, FigureError> {
    let aggs = aggregates(rows);
    match plan.sets.len() {
        0 => seeds_line(plan, rows, metric),
        1 => key_line(plan, &aggs, metric),
        _ => heat_map(plan, &aggs, metric),
    }
}

/// A metric's value as a label in the figure.
fn label(metric: &str, v: f64) -> String {
    if metric == "success_rate" {
        format!("{:.0}%", 100.0 * v)
    } else if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.2}")
    }
}

/// The range of `values` with a margin (a unit wide when they are all equal).
fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    if lo > hi {
        return (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.08).max(if hi == lo { 0.5 } else { 0.0 });
    (lo - pad, hi + pad)
}

/// One key swept: the metric's mean against the key (numbers), or against the values' order.
fn key_line(plan: &Plan, aggs: &[Aggregate], metric: &str) -> Result<Vec<u8>, FigureError> {
    let set = &plan.sets[0];
    let numeric = set
        .values
        .iter()
        .all(|v| v.as_float().or(v.as_integer().map(|i| i as f64)).is_some());
    let x = |a: &Aggregate, k: usize| -> f64 {
        let v = &plan.jobs[a.rows[0].run].values[0];
        match (numeric, v.as_float(), v.as_integer()) {
            (true, Some(f), _) => f,
            (true, _, Some(i)) => i as f64,
            _ => k as f64,
        }
    };
    let points: Vec<(f64, f64)> = aggs
        .iter()
        .enumerate()
        .filter_map(|(k, a)| Some((x(a, k), a.mean(metric)?)))
        .collect();
    let x_label = if numeric {
        set.key.clone()
    } else {
        let names: Vec<String> = set.values.iter().map(value_text).collect();
        format!("{} (0..: {})", set.key, names.join(", "))
    };
    line_png(plan, metric, x_label, points)
}

/// No key swept: the metric against the seed.
fn seeds_line(plan: &Plan, rows: &[Row], metric: &str) -> Result<Vec<u8>, FigureError> {
    let points: Vec<(f64, f64)> = rows
        .iter()
        .filter_map(|r| {
            let v = if metric == "success_rate" {
                Some(if r.success { 1.0 } else { 0.0 })
            } else {
                r.number(metric)
            };
            Some((r.seed as f64, v?))
        })
        .collect();
    line_png(plan, metric, "seed".into(), points)
}

fn line_png(
    plan: &Plan,
    metric: &str,
    x_label: String,
    points: Vec<(f64, f64)>,
) -> Result<Vec<u8>, FigureError> {
    let chart = Chart {
        title: format!("{}: {metric} (mean over seeds)", plan.name),
        x_label,
        y_label: metric.to_string(),
        x_range: span(points.iter().map(|p| p.0)),
        y_range: if metric == "success_rate" {
            (-0.05, 1.05)
        } else {
            span(points.iter().map(|p| p.1))
        },
        series: vec![
            Series {
                label: String::new(),
                rgb: [40, 90, 200],
                points: points.clone(),
                style: Style::Line,
            },
            Series {
                label: String::new(),
                rgb: [40, 90, 200],
                points,
                style: Style::Dots,
            },
        ],
    };
    charts_png("sweep.png", &[chart], 1, (760, 520))
}

/// A colour of the map for `t` in [0, 1]: dark blue through teal to yellow (viridis-like).
fn colour(t: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [68.0, 1.0, 84.0]),
        (0.25, [59.0, 82.0, 139.0]),
        (0.5, [33.0, 145.0, 140.0]),
        (0.75, [94.0, 201.0, 98.0]),
        (1.0, [253.0, 231.0, 37.0]),
    ];
    let t = t.clamp(0.0, 1.0);
    let k = STOPS.iter().position(|s| s.0 >= t).unwrap_or(4).max(1);
    let (a, b) = (STOPS[k - 1], STOPS[k]);
    let f = (t - a.0) / (b.0 - a.0);
    let c = |i: usize| (a.1[i] + f * (b.1[i] - a.1[i])).round() as u8;
    RGBColor(c(0), c(1), c(2))
}

/// Two or more keys: a grid over the first two keys' values, each cell the metric's mean over
/// the seeds (and over the further keys), its value written in it.
fn heat_map(plan: &Plan, aggs: &[Aggregate], metric: &str) -> Result<Vec<u8>, FigureError> {
    let cells = cell_means(plan, aggs, metric);
    register_font();
    let (w, h) = (820u32, 600u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        draw_heat_map(&root, plan, metric, &cells).map_err(FigureError::plot("sweep.png"))?;
    }
    let img = image::RgbImage::from_raw(w, h, buf).ok_or_else(|| FigureError::Buffer {
        file: "sweep.png".into(),
    })?;
    png_bytes("sweep.png", &img)
}

/// The heat map of `cells` (from [`cell_means`]) into `root`: the title, the first two keys'
/// values along the axes, a coloured cell for each pair.
fn draw_heat_map(
    root: &DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>,
    plan: &Plan,
    metric: &str,
    cells: &[Option<f64>],
) -> Result<(), PlotError> {
    let (xs, ys) = (&plan.sets[0], &plan.sets[1]);
    let (nx, ny) = (xs.values.len(), ys.values.len());
    let (lo, hi) = colour_range(metric, cells);
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(root)
        .caption(heat_title(plan, metric, lo, hi), ("sans-serif", 16))
        .margin(14)
        .x_label_area_size(46)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..nx as f64, 0.0..ny as f64)?;
    let x_names: Vec<String> = xs.values.iter().map(value_text).collect();
    let y_names: Vec<String> = ys.values.iter().map(value_text).collect();
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(xs.key.as_str())
        .y_desc(ys.key.as_str())
        .x_labels(nx * 2 + 1)
        .y_labels(ny * 2 + 1)
        .x_label_formatter(&|v| name_at(&x_names, *v))
        .y_label_formatter(&|v| name_at(&y_names, *v))
        .label_style(("sans-serif", 13))
        .draw()?;
    for iy in 0..ny {
        for ix in 0..nx {
            let value = cells[iy * nx + ix].map(|v| ((v - lo) / (hi - lo), label(metric, v)));
            draw_cell(&mut chart, (ix as f64, iy as f64), value)?;
        }
    }
    root.present()?;
    Ok(())
}

/// Each cell's mean of `metric` over its combinations (`None`: no run has it), row by row of
/// the second key's values, the first key's along each row.
fn cell_means(plan: &Plan, aggs: &[Aggregate], metric: &str) -> Vec<Option<f64>> {
    let (xs, ys) = (&plan.sets[0], &plan.sets[1]);
    let nx = xs.values.len();
    let mut sum = vec![(0.0, 0usize); nx * ys.values.len()];
    for a in aggs {
        let values = &plan.jobs[a.rows[0].run].values;
        let ix = xs.values.iter().position(|v| *v == values[0]);
        let iy = ys.values.iter().position(|v| *v == values[1]);
        if let (Some(ix), Some(iy), Some(m)) = (ix, iy, a.mean(metric)) {
            sum[iy * nx + ix].0 += m;
            sum[iy * nx + ix].1 += 1;
        }
    }
    sum.iter()
        .map(|&(s, n)| (n > 0).then(|| s / n as f64))
        .collect()
}

/// The values at the ends of the colour scale: 0 to 1 for the success rate, else the cells'
/// range.
fn colour_range(metric: &str, cells: &[Option<f64>]) -> (f64, f64) {
    if metric == "success_rate" {
        return (0.0, 1.0);
    }
    let (lo, hi) = cells
        .iter()
        .flatten()
        .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    if lo > hi {
        (0.0, 1.0)
    } else {
        (lo, hi.max(lo + 1e-9))
    }
}

/// The heat map's title: the metric, the keys averaged over and the colour scale's ends.
fn heat_title(plan: &Plan, metric: &str, lo: f64, hi: f64) -> String {
    let more = if plan.sets.len() > 2 {
        format!(
            ", averaged over {}",
            plan.sets[2..]
                .iter()
                .map(|s| s.key.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        )
    } else {
        String::new()
    };
    format!(
        "{}: {metric} (mean over seeds{more}; {} to {})",
        plan.name,
        label(metric, lo),
        label(metric, hi)
    )
}

/// The name of the value whose cell is centred on axis position `v` (cells are a unit wide
/// from 0), blank between cells.
fn name_at(names: &[String], v: f64) -> String {
    let k = (v - 0.5).round();
    if (v - 0.5 - k).abs() < 1e-6 && k >= 0.0 {
        names.get(k as usize).cloned().unwrap_or_default()
    } else {
        String::new()
    }
}

/// The heat map's cell with lower corner `at`: coloured for its value's place on the scale
/// (from 0 to 1) with the value's text in it, or grey with a dash when it has none.
fn draw_cell(
    chart: &mut ChartContext<'_, BitMapBackend<'_>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    at: (f64, f64),
    value: Option<(f64, String)>,
) -> Result<(), PlotError> {
    let (x0, y0) = at;
    let (fill, text) = match value {
        Some((t, text)) => (colour(t), text),
        None => (RGBColor(220, 220, 220), "-".to_string()),
    };
    let corners = [(x0, y0), (x0 + 1.0, y0 + 1.0)];
    chart.draw_series([
        Rectangle::new(corners, fill.filled()),
        Rectangle::new(corners, WHITE.stroke_width(2)),
    ])?;
    let dark = fill.0 as u32 + fill.1 as u32 + fill.2 as u32 > 380;
    let ink = if dark { BLACK } else { WHITE };
    let style = TextStyle::from(("sans-serif", 15).into_font())
        .color(&ink)
        .pos(plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Center,
            plotters::style::text_anchor::VPos::Center,
        ));
    chart.draw_series(std::iter::once(Text::new(
        text,
        (x0 + 0.5, y0 + 0.5),
        style,
    )))?;
    Ok(())
}
