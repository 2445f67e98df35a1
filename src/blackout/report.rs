//! The blackout replay's outputs: `blackout.md` (the rates of each block, then a score sheet
//! like the rules' for every trial), `blackout.png` (each block's paths of robot and ball) and
//! `summary.json`.

use super::trials::{Field, Stage};
use super::{Block, BlockResult};
use crate::experiments::replay::write_text;
use crate::report::topview::{Marker, Panel, PathLayer, render_panels};
use anyhow::Context;
use nalgebra::Point2;
use omniloop_sim::{FieldSpec, Layout};
use serde_json::json;
use std::fmt::Write as _;
use std::path::Path;

/// A block's name: stage, field, and "latency and blur" when it has them.
pub fn block_name(b: &Block) -> String {
    let realism = if b.realism { ", latency and blur" } else { "" };
    format!("{}, {}{realism}", b.stage.name(), b.field.preset)
}

/// The share of trials for which `f` holds.
fn rate(r: &BlockResult, f: impl Fn(&super::score::TrialScore) -> bool) -> f64 {
    r.trials.iter().filter(|t| f(t)).count() as f64 / r.trials.len().max(1) as f64
}

/// The rate the targets read for a block: full points (stage 1), a goal (stages 2
/// and 3), the dribbler's touch (the moving ball).
pub fn success_rate(r: &BlockResult) -> f64 {
    match r.block.stage {
        Stage::Grab => rate(r, |t| t.points == Stage::Grab.full_points()),
        Stage::EmptyGoal | Stage::Defended => rate(r, |t| t.goal),
        Stage::MovingBall => rate(r, |t| t.dribbler),
    }
}

/// The median of the trials' times, s.
fn median_time(r: &BlockResult) -> Option<f64> {
    let mut t: Vec<f64> = r.trials.iter().filter_map(|t| t.time_s).collect();
    t.sort_by(f64::total_cmp);
    (!t.is_empty()).then(|| t[t.len() / 2])
}

/// The table of rates, one row a block.
pub fn rates_table(results: &[BlockResult]) -> String {
    let mut s = String::from(
        "| block | trials | success | what counts | mean points | robot in defense area | median time |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for r in results {
        let counts = match r.block.stage {
            Stage::Grab => "full points (3)",
            Stage::EmptyGoal | Stage::Defended => "a goal",
            Stage::MovingBall => "dribbler touch",
        };
        let mean = r.trials.iter().map(|t| f64::from(t.points)).sum::<f64>()
            / r.trials.len().max(1) as f64;
        let entries = r.trials.iter().filter(|t| t.robot_in_defense_area).count();
        let time = median_time(r).map_or("-".to_string(), |t| format!("{t:.1} s"));
        let _ = writeln!(
            s,
            "| {} | {} | {:.0}% | {counts} | {mean:.2} / {} | {entries} | {time} |",
            block_name(&r.block),
            r.trials.len(),
            100.0 * success_rate(r),
            r.block.stage.full_points(),
        );
    }
    s
}

/// The score sheet of one block, a row a trial.
fn sheet(r: &BlockResult) -> String {
    let yes = |b: bool| if b { "+1" } else { "" };
    let mut s = format!(
        "### {}\n\n| seed | touch | dribbler | held at end | ball in defense area | goal | robot in defense area | points | time |\n\
         |---|---|---|---|---|---|---|---|---|\n",
        block_name(&r.block)
    );
    for t in &r.trials {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            t.seed,
            yes(t.touched),
            yes(t.dribbler),
            yes(t.held_at_end),
            yes(t.ball_in_defense_area),
            yes(t.goal),
            if t.robot_in_defense_area { "-1" } else { "" },
            t.points,
            t.time_s.map_or("-".to_string(), |v| format!("{v:.2} s")),
        );
    }
    s
}

/// The field of a block as a layout, for the figure.
fn layout_of(field: &Field) -> anyhow::Result<Layout> {
    let text = format!("preset = \"{}\"", field.preset);
    let spec: FieldSpec = toml::from_str(&text).context("the field preset")?;
    Ok(Layout {
        field: Some(spec),
        ..Layout::default()
    })
}

/// Each block's paths: the robots' in blue, the balls' in orange, starts marked; a row of
/// panels for each field (the blocks with latency and blur beside the clean ones).
fn figure(file: &Path, results: &[BlockResult]) -> anyhow::Result<()> {
    let layouts: Vec<Layout> = results
        .iter()
        .map(|r| layout_of(&r.block.field))
        .collect::<Result<_, _>>()?;
    let mut fields: Vec<&'static str> = results.iter().map(|r| r.block.field.preset).collect();
    fields.dedup();
    let mut rows = Vec::new();
    for preset in fields {
        let panels: Vec<Panel<'_>> = results
            .iter()
            .zip(&layouts)
            .filter(|(r, _)| r.block.field.preset == preset)
            .map(|(r, layout)| panel(r, layout))
            .collect();
        let name = file.display().to_string();
        rows.push(render_panels(&name, &panels, 420)?);
    }
    let width = rows.iter().map(|r| r.width()).max().unwrap_or(1);
    let height = rows.iter().map(|r| r.height()).sum::<u32>().max(1);
    let mut img = image::RgbImage::from_pixel(width, height, image::Rgb([255, 255, 255]));
    let mut y = 0;
    for row in &rows {
        image::imageops::replace(&mut img, row, 0, i64::from(y));
        y += row.height();
    }
    img.save(file)
        .with_context(|| format!("writing {}", file.display()))
}

/// One block's panel: every trial's paths, the first of each kind in the legend.
fn panel<'a>(r: &'a BlockResult, layout: &'a Layout) -> Panel<'a> {
    let label = |k: usize, name: &'static str| if k == 0 { name } else { "" };
    Panel {
        title: block_name(&r.block),
        layout,
        paths: r
            .trials
            .iter()
            .enumerate()
            .flat_map(|(k, t)| {
                [
                    path(label(k, "robot"), [40, 90, 200], &t.robot_path),
                    path(label(k, "ball"), [255, 110, 20], &t.ball_path),
                ]
            })
            .collect(),
        markers: r
            .trials
            .iter()
            .filter_map(|t| t.ball_path.first())
            .map(|&at| Marker {
                at,
                radius_mm: 21.5,
                rgb: [255, 110, 20],
                label: String::new(),
            })
            .collect(),
        spots: Vec::new(),
        grid: None,
    }
}

/// A path layer.
fn path<'a>(label: &str, rgb: [u8; 3], points: &'a [Point2<f64>]) -> PathLayer<'a> {
    PathLayer {
        label: label.to_string(),
        rgb,
        points,
        dots: false,
        discs: None,
    }
}

/// Writes `blackout.md`, `blackout.png` and `summary.json` into `out`; returns the rates table.
pub fn write(out: &Path, results: &[BlockResult], wall_s: f64) -> anyhow::Result<String> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let table = rates_table(results);
    let mut md = format!(
        "# Vision blackout, replayed\n\nE1's robot (256 x 220 hyperbolic camera, E1's noise) plays \
         the striker from its own camera; {} trials a block, scored by the rules' points. Run \
         time {wall_s:.0} s.\n\n{table}\n## Score sheets\n\n",
        results.first().map_or(0, |r| r.trials.len())
    );
    for r in results {
        md += &sheet(r);
        md.push('\n');
    }
    write_text(&out.join("blackout.md"), &md)?;
    figure(&out.join("blackout.png"), results)?;
    let blocks: Vec<serde_json::Value> = results
        .iter()
        .map(|r| {
            json!({
                "stage": r.block.stage.key(),
                "field": r.block.field.preset,
                "realism": r.block.realism,
                "success_rate": success_rate(r),
                "trials": r.trials,
            })
        })
        .collect();
    let summary = json!({ "replay": "blackout", "wall_time_s": wall_s, "blocks": blocks });
    write_text(
        &out.join("summary.json"),
        &(serde_json::to_string_pretty(&summary)? + "\n"),
    )?;
    Ok(table)
}
