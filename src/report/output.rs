//! Writing a run's results: `summary.json`, `trajectory.csv`, `estimates.jsonl` and
//! `topview.png`.

use super::charts::PALETTE;
use super::topview::{FigureError, Marker, Panel, PathLayer, render_panels};
use crate::run::RunOutput;
use crate::run::ball_record::write_ball_csv;
use crate::run::record::{write_estimates_jsonl, write_team_trajectory_csv, write_trajectory_csv};
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
///
/// ```
/// use omniloop::report::write_run;
/// use omniloop::{Runner, load_scenario};
///
/// # fn main() -> anyhow::Result<()> {
/// let scenario = load_scenario("scenarios/smoke.toml".as_ref())?;
/// let output = Runner::new(&scenario).run()?;
/// let dir = std::env::temp_dir().join("omniloop-doc-write-run");
/// write_run(&dir, &scenario, &output)?;
/// for file in ["summary.json", "trajectory.csv", "estimates.jsonl", "topview.png"] {
///     assert!(dir.join(file).is_file(), "{file}");
/// }
/// let lines = std::fs::read_to_string(dir.join("trajectory.csv"))?.lines().count();
/// assert_eq!(lines, output.trajectory.len() + 1, "a header and a row a cycle");
/// # Ok(())
/// # }
/// ```
pub fn write_run(dir: &Path, scenario: &Scenario, out: &RunOutput) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let summary_path = dir.join("summary.json");
    let text = serde_json::to_string_pretty(&out.summary)?;
    std::fs::write(&summary_path, text + "\n")
        .with_context(|| format!("writing {}", summary_path.display()))?;
    if out.robots.is_empty() {
        write_records(dir, &out.trajectory, &out.estimates, &out.floor_scores)?;
    } else {
        write_team_records(dir, out)?;
    }
    if let Some(ball) = &out.ball {
        write_ball_records(dir, ball)?;
    }
    draw_run_topview(&dir.join("topview.png"), scenario, out)?;
    for f in &out.files {
        let path = dir.join(&f.name);
        std::fs::write(&path, &f.bytes).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// Writes the ball's `ball.csv` and the game's `events.jsonl` into `dir`.
fn write_ball_records(dir: &Path, ball: &crate::run::BallOutput) -> anyhow::Result<()> {
    let path = dir.join("ball.csv");
    let f = File::create(&path).with_context(|| format!("writing {}", path.display()))?;
    write_ball_csv(&ball.rows, BufWriter::new(f))
        .with_context(|| format!("writing {}", path.display()))?;
    let path = dir.join("events.jsonl");
    let text: String = (ball.events.iter()).map(|e| format!("{e}\n")).collect();
    std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))
}

/// Writes a robot's `trajectory.csv` and `estimates.jsonl` into `dir`.
fn write_records(
    dir: &Path,
    trajectory: &[crate::run::TrajectoryRow],
    estimates: &[omniloop_robot::Estimates],
    floor_scores: &[Option<crate::run::score::FloorRegionScore>],
) -> anyhow::Result<()> {
    let traj_path = dir.join("trajectory.csv");
    let f = File::create(&traj_path).with_context(|| format!("writing {}", traj_path.display()))?;
    write_trajectory_csv(trajectory, BufWriter::new(f))
        .with_context(|| format!("writing {}", traj_path.display()))?;
    let est_path = dir.join("estimates.jsonl");
    let f = File::create(&est_path).with_context(|| format!("writing {}", est_path.display()))?;
    write_estimates_jsonl(trajectory, estimates, floor_scores, BufWriter::new(f))
        .with_context(|| format!("writing {}", est_path.display()))
}

/// A team's records: every robot's `robots/NAME/trajectory.csv` and `estimates.jsonl`, and
/// all of them in one `trajectory.csv` with the robot's name in a first column `robot`.
fn write_team_records(dir: &Path, out: &RunOutput) -> anyhow::Result<()> {
    for r in &out.robots {
        let own = dir.join("robots").join(&r.name);
        std::fs::create_dir_all(&own).with_context(|| format!("creating {}", own.display()))?;
        write_records(&own, &r.trajectory, &r.estimates, &r.floor_scores)?;
    }
    let traj_path = dir.join("trajectory.csv");
    let f = File::create(&traj_path).with_context(|| format!("writing {}", traj_path.display()))?;
    let rows: Vec<(&str, &[crate::run::TrajectoryRow])> = out
        .robots
        .iter()
        .map(|r| (r.name.as_str(), r.trajectory.as_slice()))
        .collect();
    write_team_trajectory_csv(&rows, BufWriter::new(f))
        .with_context(|| format!("writing {}", traj_path.display()))
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
    if !out.robots.is_empty() {
        return team_topview_image(name, scenario, out, width);
    }
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
    let plan: Vec<Point2<f64>> = out
        .estimates
        .iter()
        .rev()
        .find_map(|e| e.navigation.as_ref())
        .map(|n| n.path_mm.clone())
        .unwrap_or_default();
    let title = match out.map {
        Some(_) => format!(
            "{}  (robot's map: green free, orange suspect, red blocked, clear unknown)",
            scenario.name
        ),
        None => scenario.name.clone(),
    };
    let ball = ball_path(out);
    let mut paths = run_paths(&truth, &estimate, &out.other_paths, &plan);
    paths.extend(ball_layer(&ball));
    let panel = Panel {
        title,
        layout: &scenario.world,
        paths,
        markers: run_markers(scenario),
        spots: Vec::new(),
        grid: out.map.as_ref(),
    };
    render_panels(name, &[panel], width)
}

/// The ball's path over the run (empty without a ball).
fn ball_path(out: &RunOutput) -> Vec<Point2<f64>> {
    (out.ball.iter())
        .flat_map(|b| b.rows.iter().map(crate::run::BallRow::point))
        .collect()
}

/// The ball's path as a layer (orange), when it moved.
fn ball_layer(points: &[Point2<f64>]) -> Option<PathLayer<'_>> {
    (points.len() > 1).then(|| PathLayer {
        label: "ball".into(),
        rgb: [255, 120, 0],
        points,
        dots: false,
        discs: None,
    })
}

/// A run's paths, in drawing order: the estimated one (dots, when there is one), the other
/// robots', the last plan (when it has two points or more) and the true one on top.
fn run_paths<'a>(
    truth: &'a [Point2<f64>],
    estimate: &'a [Point2<f64>],
    others: &'a [Vec<Point2<f64>>],
    plan: &'a [Point2<f64>],
) -> Vec<PathLayer<'a>> {
    let mut layers = Vec::new();
    if !estimate.is_empty() {
        layers.push(PathLayer {
            label: "estimated".into(),
            rgb: [30, 80, 230],
            points: estimate,
            dots: true,
            discs: None,
        });
    }
    for (k, p) in others.iter().enumerate() {
        layers.push(PathLayer {
            label: format!("robot {}", k + 1),
            rgb: [200, 40, 160],
            points: p,
            dots: false,
            discs: None,
        });
    }
    if plan.len() > 1 {
        layers.push(PathLayer {
            label: "last plan".into(),
            rgb: [20, 140, 60],
            points: plan,
            dots: false,
            discs: None,
        });
    }
    layers.push(PathLayer {
        label: "true path".into(),
        rgb: [220, 30, 30],
        points: truth,
        dots: false,
        discs: None,
    });
    layers
}

/// The robot's start (a circle of its size), and the goal's waypoints and the goal (circles of
/// its tolerance).
fn run_markers(scenario: &Scenario) -> Vec<Marker> {
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
    markers
}

/// The top view of a team's run: each robot's true path in its colour, from its start (a
/// circle of its size, named) to where it is (a filled one), its goal a circle of the goal's
/// tolerance; the other robots' paths in magenta.
fn team_topview_image(
    name: &str,
    scenario: &Scenario,
    out: &RunOutput,
    width: u32,
) -> Result<image::RgbImage, FigureError> {
    let paths: Vec<Vec<Point2<f64>>> = out
        .robots
        .iter()
        .map(|r| {
            r.trajectory
                .iter()
                .map(|p| Point2::new(p.x_mm, p.y_mm))
                .collect()
        })
        .collect();
    let ball = ball_path(out);
    let mut layers: Vec<PathLayer<'_>> = ball_layer(&ball).into_iter().collect();
    for (k, p) in out.other_paths.iter().enumerate() {
        layers.push(PathLayer {
            label: format!("scripted {}", k + 1),
            rgb: [200, 40, 160],
            points: p,
            dots: false,
            discs: None,
        });
    }
    let mut markers = Vec::new();
    for (k, (robot, path)) in out.robots.iter().zip(&paths).enumerate() {
        let rgb = PALETTE[k % PALETTE.len()];
        let member = scenario.member(k);
        let radius_mm = member.robot.radius_mm;
        layers.push(PathLayer {
            label: robot.name.clone(),
            rgb,
            points: path,
            dots: false,
            discs: None,
        });
        markers.push(Marker {
            at: member.start().point(),
            radius_mm,
            rgb,
            label: robot.name.clone(),
        });
        if let Some(g) = &member.goal {
            markers.push(Marker {
                at: g.point(),
                radius_mm: g.tolerance_mm,
                rgb,
                label: String::new(),
            });
        }
        if let Some(end) = path.last() {
            markers.push(Marker {
                at: *end,
                radius_mm: 0.5 * radius_mm,
                rgb,
                label: String::new(),
            });
        }
    }
    let panel = Panel {
        title: format!(
            "{}  ({} robots: start named, goal circled, path to where each is)",
            scenario.name,
            out.robots.len()
        ),
        layout: &scenario.world,
        paths: layers,
        markers,
        spots: Vec::new(),
        grid: None,
    };
    render_panels(name, &[panel], width)
}
