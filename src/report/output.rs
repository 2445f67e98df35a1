//! Writing a run's results: `summary.json`, `trajectory.csv`, `estimates.jsonl` and
//! `topview.png`.

use super::topview::{FigureError, Marker, Panel, PathLayer, render_panels};
use crate::run::RunOutput;
use crate::run::record::{write_estimates_jsonl, write_trajectory_csv};
use crate::scenario::Scenario;
use anyhow::Context;
use nalgebra::Point2;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// The default output folder of a scenario: `runs/<name>`.
pub fn default_out_dir(scenario: &Scenario) -> PathBuf {
    Path::new("runs").join(&scenario.name)
}

/// Writes `summary.json`, `trajectory.csv`, `estimates.jsonl`, `topview.png` and the
/// experiment's own files into `dir` (created if needed).
pub fn write_run(dir: &Path, scenario: &Scenario, out: &RunOutput) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let summary_path = dir.join("summary.json");
    let text = serde_json::to_string_pretty(&out.summary)?;
    std::fs::write(&summary_path, text + "\n")
        .with_context(|| format!("writing {}", summary_path.display()))?;
    let traj_path = dir.join("trajectory.csv");
    let f = File::create(&traj_path).with_context(|| format!("writing {}", traj_path.display()))?;
    write_trajectory_csv(&out.trajectory, BufWriter::new(f))
        .with_context(|| format!("writing {}", traj_path.display()))?;
    let est_path = dir.join("estimates.jsonl");
    let f = File::create(&est_path).with_context(|| format!("writing {}", est_path.display()))?;
    write_estimates_jsonl(&out.trajectory, &out.estimates, BufWriter::new(f))
        .with_context(|| format!("writing {}", est_path.display()))?;
    draw_run_topview(&dir.join("topview.png"), scenario, out)?;
    for f in &out.files {
        let path = dir.join(&f.name);
        std::fs::write(&path, &f.bytes).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// The top view of one run: world, true path, estimated path, other robots, start and goal.
pub fn draw_run_topview(file: &Path, scenario: &Scenario, out: &RunOutput) -> anyhow::Result<()> {
    let name = file.display().to_string();
    run_topview_image(&name, scenario, out, 1000)?
        .save(file)
        .with_context(|| format!("writing {name}"))
}

/// [`draw_run_topview`] into an image `width` pixels wide (`name` names it in errors).
pub fn run_topview_image(
    name: &str,
    scenario: &Scenario,
    out: &RunOutput,
    width: u32,
) -> Result<image::RgbImage, FigureError> {
    let truth: Vec<Point2<f64>> = out
        .trajectory
        .iter()
        .map(|r| Point2::new(r.x_mm, r.y_mm))
        .collect();
    let estimate: Vec<Point2<f64>> = out
        .trajectory
        .iter()
        .filter_map(|r| Some(Point2::new(r.est_x_mm?, r.est_y_mm?)))
        .collect();
    let mut layers = Vec::new();
    if !estimate.is_empty() {
        layers.push(PathLayer {
            label: "estimated".into(),
            rgb: [30, 80, 230],
            points: &estimate,
            dots: true,
            discs: None,
        });
    }
    for (k, p) in out.other_paths.iter().enumerate() {
        layers.push(PathLayer {
            label: format!("robot {}", k + 1),
            rgb: [200, 40, 160],
            points: p,
            dots: false,
            discs: None,
        });
    }
    let plan: Vec<Point2<f64>> = out
        .estimates
        .iter()
        .rev()
        .find_map(|e| e.navigation.as_ref())
        .map(|n| n.path_mm.clone())
        .unwrap_or_default();
    if plan.len() > 1 {
        layers.push(PathLayer {
            label: "last plan".into(),
            rgb: [20, 140, 60],
            points: &plan,
            dots: false,
            discs: None,
        });
    }
    layers.push(PathLayer {
        label: "true path".into(),
        rgb: [220, 30, 30],
        points: &truth,
        dots: false,
        discs: None,
    });
    let mut markers = vec![Marker {
        at: scenario.start().point(),
        radius_mm: scenario.robot.radius_mm,
        rgb: [20, 20, 20],
        label: "start".into(),
    }];
    if let Some(g) = &scenario.goal {
        for (k, w) in g.waypoints_mm.iter().enumerate() {
            markers.push(Marker {
                at: Point2::new(w[0], w[1]),
                radius_mm: g.tolerance_mm,
                rgb: [250, 200, 0],
                label: format!("waypoint {}", k + 1),
            });
        }
        markers.push(Marker {
            at: g.point(),
            radius_mm: g.tolerance_mm,
            rgb: [250, 130, 0],
            label: "goal".into(),
        });
    }
    let title = match out.map {
        Some(_) => format!(
            "{}  (robot's map: green free, orange suspect, red blocked, clear unknown)",
            scenario.name
        ),
        None => scenario.name.clone(),
    };
    let panel = Panel {
        title,
        layout: &scenario.world,
        paths: layers,
        markers,
        spots: Vec::new(),
        grid: out.map.as_ref(),
    };
    render_panels(name, &[panel], width)
}
