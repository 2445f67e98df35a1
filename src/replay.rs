//! Replays of the papers' experiments: several scenario runs and the figure and table that
//! compare them.

use crate::load::{LoadError, parse_scenario};
use crate::output::write_run;
use crate::record::Summary;
use crate::runner::{RunOptions, RunOutput, run_scenario};
use crate::scenario::Scenario;
use crate::topview::{Marker, Panel, PathLayer, draw_panels};
use anyhow::Context;
use nalgebra::Point2;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The experiments `omniloop replay` knows.
pub const EXPERIMENTS: &[(&str, &str)] = &[
    (
        "corner55",
        "E1: the 55-degree corner, goal-direction vs velocity-aware avoidance (Fig. 7)",
    ),
    (
        "selfloc",
        "E2: floor-region self-localization at six places on the field (Fig. 8)",
    ),
];

/// The E2 scenario file, built into the binary.
pub const SELFLOC: &str = include_str!("../scenarios/selfloc_field.toml");

/// The E1 scenario files, built into the binary so the replay runs from anywhere.
pub const CORNER55: [(&str, &str); 2] = [
    (
        "goal_direction",
        include_str!("../scenarios/corner55_goal_direction.toml"),
    ),
    (
        "velocity_aware",
        include_str!("../scenarios/corner55_velocity_aware.toml"),
    ),
];

/// Parses one of the built-in corner scenarios (`goal_direction`, `velocity_aware`).
pub fn builtin_scenario(name: &str, text: &str) -> Result<Scenario, LoadError> {
    let file = PathBuf::from(format!("scenarios/corner55_{name}.toml"));
    parse_scenario(text, &file, &format!("corner55_{name}"))
}

/// Runs E2 (`scenarios/selfloc_field.toml`), writes the run into `out/` and the figure of the
/// places with their errors (like Fig. 8) and a table into `out/places.png`, `out/places.md`.
pub fn replay_selfloc(
    out: &Path,
    options: &RunOptions,
    seed: Option<u64>,
    mut progress: impl FnMut(&str, u64, u64),
    notice: &mut dyn FnMut(&str),
) -> anyhow::Result<ReplayRun> {
    let mut scenario = parse_scenario(
        SELFLOC,
        Path::new("scenarios/selfloc_field.toml"),
        "selfloc_field",
    )?;
    if let Some(seed) = seed {
        scenario.seed = seed;
    }
    let output = run_scenario(&scenario, options, &mut *notice, |k, n| {
        progress("selfloc_field", k, n)
    })
    .context("running selfloc_field")?;
    write_run(out, &scenario, &output)?;
    draw_places(&out.join("places.png"), &scenario, &output)?;
    std::fs::write(out.join("places.md"), places_table(&output.summary))
        .with_context(|| format!("writing {}", out.join("places.md").display()))?;
    Ok(ReplayRun {
        name: "selfloc_field".into(),
        scenario,
        output,
    })
}

/// Fig. 8: the field with its cubes, each place with the robot's outline, its estimates, and
/// its RMS errors written beside it.
fn draw_places(file: &Path, scenario: &Scenario, out: &RunOutput) -> anyhow::Result<()> {
    let estimates: Vec<Point2<f64>> = out
        .trajectory
        .iter()
        .filter_map(|r| Some(Point2::new(r.est_x_mm?, r.est_y_mm?)))
        .collect();
    let places = out.summary.places.clone().unwrap_or_default();
    let mut markers = Vec::new();
    for (k, p) in places.iter().enumerate() {
        markers.push(Marker {
            at: Point2::new(p.true_pose[0], p.true_pose[1]),
            radius_mm: scenario.robot.radius_mm,
            rgb: [20, 20, 20],
            label: format!(
                "{}: {:.1} mm, {:.2} deg",
                k + 1,
                p.rms_position_mm,
                p.rms_heading_deg
            ),
        });
    }
    let panel = Panel {
        title: format!("{}: RMS error at each place", scenario.name),
        layout: &scenario.world,
        paths: vec![PathLayer {
            label: "estimates".into(),
            rgb: [30, 80, 230],
            points: &estimates,
            dots: true,
            discs: None,
        }],
        markers,
    };
    draw_panels(file, &[panel], 1100)?;
    Ok(())
}

/// E2 per place as a Markdown table.
pub fn places_table(m: &Summary) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# E2: self-localization on the field
"
    );
    let _ = writeln!(
        s,
        "Renderer: {}. Seed {}. Paper: errors of \"dozens of mm\" at each place.\n",
        m.renderer.clone().unwrap_or_else(|| "-".into()),
        m.seed
    );
    let _ = writeln!(
        s,
        "| place | x_mm | y_mm | theta_deg | frames | not localized | RMS position (mm) | RMS heading (deg) | ambiguity errors |"
    );
    let _ = writeln!(s, "|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (k, p) in m.places.iter().flatten().enumerate() {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {:.1} | {:.2} | {} |",
            k + 1,
            p.true_pose[0],
            p.true_pose[1],
            p.true_pose[2],
            p.frames,
            p.not_localized,
            p.rms_position_mm,
            p.rms_heading_deg,
            p.ambiguity_errors
        );
    }
    s
}

/// One run of a replay.
pub struct ReplayRun {
    /// Short name (`goal_direction`).
    pub name: String,
    /// The scenario.
    pub scenario: Scenario,
    /// What it produced.
    pub output: RunOutput,
}

/// Runs E1's two scenarios, writes each run into `out/<name>/` and the comparison figure and
/// table into `out/`.
pub fn replay_corner55(
    out: &Path,
    options: &RunOptions,
    seed: Option<u64>,
    mut progress: impl FnMut(&str, u64, u64),
    notice: &mut dyn FnMut(&str),
) -> anyhow::Result<Vec<ReplayRun>> {
    let mut runs = Vec::new();
    for (name, text) in CORNER55 {
        let mut scenario = builtin_scenario(name, text)?;
        if let Some(seed) = seed {
            scenario.seed = seed;
        }
        let output = run_scenario(&scenario, options, &mut *notice, |k, n| {
            progress(name, k, n)
        })
        .with_context(|| format!("running corner55_{name}"))?;
        write_run(&out.join(name), &scenario, &output)?;
        runs.push(ReplayRun {
            name: name.to_string(),
            scenario,
            output,
        });
    }
    draw_corner_comparison(&out.join("comparison.png"), &runs)?;
    let md = corner_table(&runs);
    std::fs::write(out.join("comparison.md"), &md)
        .with_context(|| format!("writing {}", out.join("comparison.md").display()))?;
    Ok(runs)
}

/// Fig. 7 (a)/(b): each run's path over the corridor, with the robot's outline every 0.5 s.
fn draw_corner_comparison(file: &Path, runs: &[ReplayRun]) -> anyhow::Result<()> {
    let paths: Vec<Vec<Point2<f64>>> = runs
        .iter()
        .map(|r| {
            r.output
                .trajectory
                .iter()
                .map(|t| Point2::new(t.x_mm, t.y_mm))
                .collect()
        })
        .collect();
    let panels: Vec<Panel<'_>> = runs
        .iter()
        .zip(&paths)
        .enumerate()
        .map(|(k, (r, path))| {
            let every = (0.5 / r.scenario.run.control_period_s).round() as usize;
            let mut markers = Vec::new();
            if let Some(g) = &r.scenario.goal {
                markers.push(Marker {
                    at: g.point(),
                    radius_mm: g.tolerance_mm,
                    rgb: [250, 130, 0],
                    label: "goal".into(),
                });
            }
            Panel {
                title: format!(
                    "({}) {}",
                    (b'a' + k as u8) as char,
                    r.name.replace('_', "-")
                ),
                layout: &r.scenario.world,
                paths: vec![PathLayer {
                    label: format!(
                        "robot path (outline every {:.1} s)",
                        every as f64 * r.scenario.run.control_period_s
                    ),
                    rgb: [220, 30, 30],
                    points: path,
                    dots: false,
                    discs: Some((every, r.scenario.robot.radius_mm)),
                }],
                markers,
            }
        })
        .collect();
    draw_panels(file, &panels, 900)?;
    Ok(())
}

fn fmt_opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".to_string(), |x| format!("{x:.digits$}"))
}

/// The E1 metrics of the runs as a Markdown table, with the comparisons E1 asks for.
pub fn corner_table(runs: &[ReplayRun]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# E1: the 55-degree corner\n");
    let _ = writeln!(
        s,
        "Metrics as defined in shared/EXPERIMENTS.md (E1). Renderer: {}.\n",
        runs.first()
            .and_then(|r| r.output.summary.renderer.clone())
            .unwrap_or_else(|| "-".into())
    );
    let _ = write!(s, "| metric |");
    for r in runs {
        let _ = write!(s, " {} |", r.name);
    }
    let _ = write!(s, "\n|---|");
    for _ in runs {
        let _ = write!(s, "---:|");
    }
    let _ = writeln!(s);
    type Row = (&'static str, fn(&Summary) -> String);
    let rows: [Row; 13] = [
        ("reached_goal", |m| m.reached_goal.to_string()),
        ("wall_contacts", |m| m.wall_contacts.to_string()),
        ("time_to_goal_s", |m| fmt_opt(m.time_to_goal_s, 2)),
        ("turn_onset_mm", |m| fmt_opt(m.turn_onset_mm, 1)),
        ("overshoot_mm", |m| fmt_opt(m.overshoot_mm, 1)),
        ("min_clearance_mm", |m| format!("{:.1}", m.min_clearance_mm)),
        ("path_length_mm", |m| format!("{:.1}", m.path_length_mm)),
        ("peak_speed_mm_s", |m| format!("{:.1}", m.peak_speed_mm_s)),
        ("peak_accel_mm_s2", |m| format!("{:.2}", m.peak_accel_mm_s2)),
        ("freespace_error_mm", |m| fmt_opt(m.freespace_error_mm, 1)),
        ("cycles", |m| m.cycles.to_string()),
        ("cycles_per_s", |m| format!("{:.0}", m.cycles_per_s)),
        ("seed", |m| m.seed.to_string()),
    ];
    for (name, f) in rows {
        let _ = write!(s, "| `{name}` |");
        for r in runs {
            let _ = write!(s, " {} |", f(&r.output.summary));
        }
        let _ = writeln!(s);
    }
    if let [gd, va] = runs {
        let (a, b) = (&gd.output.summary, &va.output.summary);
        let _ = writeln!(s);
        let yes = |c: bool| if c { "yes" } else { "NO" };
        if let (Some(x), Some(y)) = (a.turn_onset_mm, b.turn_onset_mm) {
            let _ = writeln!(
                s,
                "- velocity-aware turns earlier: {} ({y:.1} vs {x:.1} mm before K)",
                yes(y > x)
            );
        }
        if let (Some(x), Some(y)) = (a.overshoot_mm, b.overshoot_mm) {
            let _ = writeln!(
                s,
                "- velocity-aware overshoots less: {} ({y:.1} vs {x:.1} mm past K)",
                yes(y < x)
            );
        }
        let _ = writeln!(
            s,
            "- both reach the goal without wall contact: {}",
            yes(a.reached_goal && b.reached_goal && a.wall_contacts == 0 && b.wall_contacts == 0)
        );
    }
    s
}
