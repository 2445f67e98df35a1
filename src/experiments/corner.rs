//! E1, the corridor corner (Sekimori et al., Sect. 5.1, Fig. 7): the robot drives round a
//! corner of any angle and width to a goal; the turn is measured along the first leg. Its replay, `corner55`, runs the
//! 55-degree corner with both avoidance controllers.

use super::experiment::{Experiment, ExperimentEntry, ExperimentSetup, MetricKeys, Metrics, setup};
use super::replay::{Replay, ReplayContext, ReplayRun, write_text};
use crate::report::topview::{Marker, Panel, PathLayer, draw_panels};
use crate::run::record::{Summary, TrajectoryRow};
use crate::run::{RunError, RunOutput};
use crate::scenario::Problems;
use crate::scenario::{PoseSpec, Scenario};
use nalgebra::{Point2, Vector2};
use omniloop_robot::GoalSpec;
use omniloop_sim::{Corridor, Rgb};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;

/// The corner (`[experiment.corner]`): two straight corridor legs meeting at the corner point
/// K = (0, 0) at `angle_deg`. Leg 1 runs along u1 = +x from the start S = (-leg1_mm, 0) to K,
/// leg 2 from K along u2 = (cos(180 - angle), sin(180 - angle)) for `leg2_mm`; each leg's floor
/// is `width_mm` wide, extended half the width past both ends, and walls follow the outline of
/// their union. The robot starts at rest at S facing +x; the goal lies on leg 2's centre line
/// `goal_mm` from K (a scenario's own `[robot] start` or `[goal]` take precedence).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CornerSpec {
    /// Angle between the legs (the direction of travel changes by 180 minus this).
    pub angle_deg: f64,
    /// Width of both legs' floor.
    pub width_mm: f64,
    /// Length of leg 1, start to K.
    pub leg1_mm: f64,
    /// Length of leg 2 from K.
    pub leg2_mm: f64,
    /// Distance of the goal from K along leg 2.
    pub goal_mm: f64,
    /// Reached when the robot centre is this close to the goal.
    pub goal_tolerance_mm: f64,
    /// Wall thickness.
    pub wall_thickness_mm: f64,
    /// Wall height.
    pub wall_height_mm: f64,
}

impl Default for CornerSpec {
    /// E1 of the corner paper: 55 degrees, 800 mm wide, legs of 2500 and 2000 mm, the goal
    /// 1500 mm along leg 2.
    fn default() -> Self {
        Self {
            angle_deg: 55.0,
            width_mm: 800.0,
            leg1_mm: 2500.0,
            leg2_mm: 2000.0,
            goal_mm: 1500.0,
            goal_tolerance_mm: 100.0,
            wall_thickness_mm: 100.0,
            wall_height_mm: 150.0,
        }
    }
}

impl CornerSpec {
    /// Unit direction of leg 2.
    pub fn u2(&self) -> Vector2<f64> {
        let a = (180.0 - self.angle_deg).to_radians();
        Vector2::new(a.cos(), a.sin())
    }

    /// The corridor of the two legs.
    pub fn corridor(&self) -> Corridor {
        let end = self.u2() * self.leg2_mm;
        Corridor {
            points_mm: vec![[-self.leg1_mm, 0.0], [0.0, 0.0], [end.x, end.y]],
            width_mm: self.width_mm,
            wall_thickness_mm: self.wall_thickness_mm,
            wall_height_mm: self.wall_height_mm,
            wall_rgb: Rgb([235, 235, 235]),
        }
    }

    /// Builds the corner into the scenario: its corridor, and the start and goal unless the
    /// scenario gives its own.
    fn prepare(&self, s: &mut Scenario) {
        s.world.corridors.push(self.corridor());
        s.robot.start.get_or_insert(PoseSpec {
            x_mm: -self.leg1_mm,
            y_mm: 0.0,
            heading_deg: 0.0,
        });
        if s.goal.is_none() {
            let g = self.u2() * self.goal_mm;
            s.goal = Some(GoalSpec::to([g.x, g.y], self.goal_tolerance_mm));
        }
    }

    fn validate(&self, c: &mut Problems) {
        let p = "experiment.corner";
        if !(self.angle_deg > 0.0 && self.angle_deg < 180.0) {
            c.fail(
                format!("{p}.angle_deg"),
                format!("must lie in (0, 180) (got {})", self.angle_deg),
            );
        }
        for (key, v) in [
            ("width_mm", self.width_mm),
            ("leg1_mm", self.leg1_mm),
            ("leg2_mm", self.leg2_mm),
            ("goal_mm", self.goal_mm),
            ("goal_tolerance_mm", self.goal_tolerance_mm),
            ("wall_thickness_mm", self.wall_thickness_mm),
            ("wall_height_mm", self.wall_height_mm),
        ] {
            c.positive(format!("{p}.{key}"), v);
        }
        if self.goal_mm > self.leg2_mm {
            c.fail(
                format!("{p}.goal_mm"),
                format!(
                    "must not exceed leg2_mm = {} (got {})",
                    self.leg2_mm, self.goal_mm
                ),
            );
        }
    }
}

/// The registry's entry: `[experiment.corner]`.
pub const ENTRY: ExperimentEntry = ExperimentEntry {
    name: "corner",
    summary: "E1 of the corner paper (Sect. 5.1): a corridor corner, its turn metrics",
    setup: |t| setup::<CornerSpec>(t, "corner"),
};

impl ExperimentSetup for CornerSpec {
    fn prepare(&self, s: &mut Scenario) {
        CornerSpec::prepare(self, s);
    }

    fn check(&self, _s: &Scenario, c: &mut Problems) {
        self.validate(c);
    }

    fn procedure(&self, _s: &Scenario) -> Result<Box<dyn Experiment>, RunError> {
        Ok(Box::new(Corner))
    }
}

/// The E1 metrics of a trajectory (`summary.json`: `turn_onset_mm`, left out when `None`, and
/// `overshoot_mm`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CornerMetrics {
    /// `(K - p).u1` at the first cycle, after `v.u1` exceeded 200 mm/s, where `v.u1` falls below
    /// 75% of its running maximum; `None` if that never happens.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub turn_onset_mm: Option<f64>,
    /// `max (p - K).u1` over the run (`None`, written as `null`: no trajectory).
    pub overshoot_mm: Option<f64>,
}

impl Metrics for CornerMetrics {}

/// The E1 metrics of a trajectory around the corner `k` with first-leg direction `u1` (unit).
pub fn corner_metrics(rows: &[TrajectoryRow], k: Vector2<f64>, u1: Vector2<f64>) -> CornerMetrics {
    let mut running_max = f64::NEG_INFINITY;
    let mut armed = false;
    let mut onset = None;
    let mut overshoot = f64::NEG_INFINITY;
    for r in rows {
        let p = Vector2::new(r.x_mm, r.y_mm);
        let v = Vector2::new(r.vx_mm_s, r.vy_mm_s);
        let along = v.dot(&u1);
        overshoot = overshoot.max((p - k).dot(&u1));
        running_max = running_max.max(along);
        if along > 200.0 {
            armed = true;
        }
        if onset.is_none() && armed && along < 0.75 * running_max {
            onset = Some((k - p).dot(&u1));
        }
    }
    CornerMetrics {
        turn_onset_mm: onset,
        overshoot_mm: overshoot.is_finite().then_some(overshoot),
    }
}

/// The procedure (drive to the goal) and metrics of E1, in the corner's frame: K at the
/// origin, leg 1 along +x.
pub struct Corner;

impl Experiment for Corner {
    fn metrics(&self, out: &RunOutput) -> MetricKeys {
        // The metric frame: K at the origin, leg 1 along +x.
        corner_metrics(&out.trajectory, Vector2::zeros(), Vector2::x()).keys()
    }
}

/// `omniloop replay corner55`.
pub const REPLAY: Replay = Replay {
    name: "corner55",
    title: "E1: the 55-degree corner, goal-direction vs velocity-aware avoidance (Fig. 7)",
    run: replay,
};

/// The E1 scenario files, built into the binary so the replay runs from anywhere.
pub const SCENARIOS: [(&str, &str, &str); 2] = [
    (
        "goal_direction",
        "scenarios/corner55_goal_direction.toml",
        include_str!("../../scenarios/corner55_goal_direction.toml"),
    ),
    (
        "velocity_aware",
        "scenarios/corner55_velocity_aware.toml",
        include_str!("../../scenarios/corner55_velocity_aware.toml"),
    ),
];

/// Runs both controllers, writes each run into `out/<controller>/`, the paths side by side into
/// `comparison.png` and the table into `comparison.md`.
fn replay(ctx: &mut ReplayContext<'_>) -> anyhow::Result<String> {
    let mut runs = Vec::new();
    for (name, file, text) in SCENARIOS {
        let dir = ctx.out.join(name);
        runs.push(ctx.run(name, file, text, &dir)?);
    }
    draw_comparison(&ctx.out.join("comparison.png"), &runs)?;
    let md = corner_table(&runs);
    write_text(&ctx.out.join("comparison.md"), &md)?;
    Ok(md)
}

/// Fig. 7 (a)/(b): each run's path over the corridor, with the robot's outline every 0.5 s.
fn draw_comparison(file: &Path, runs: &[ReplayRun]) -> anyhow::Result<()> {
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
            let markers = r
                .scenario
                .goal
                .iter()
                .map(|g| Marker {
                    at: g.point(),
                    radius_mm: g.tolerance_mm,
                    rgb: [250, 130, 0],
                    label: "goal".into(),
                })
                .collect();
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
                spots: Vec::new(),
                grid: None,
            }
        })
        .collect();
    draw_panels(file, &panels, 900)?;
    Ok(())
}

/// The turn onset of a run's summary, if it has one.
fn onset(m: &Summary) -> Option<f64> {
    CornerMetrics::of(m)?.turn_onset_mm
}

/// The overshoot of a run's summary, if it has one.
fn overshoot(m: &Summary) -> Option<f64> {
    CornerMetrics::of(m)?.overshoot_mm
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
        "Metrics as defined in docs/experiments.md (E1). Renderer: {}.\n",
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
        ("turn_onset_mm", |m| fmt_opt(onset(m), 1)),
        ("overshoot_mm", |m| fmt_opt(overshoot(m), 1)),
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
        if let (Some(x), Some(y)) = (onset(a), onset(b)) {
            let _ = writeln!(
                s,
                "- velocity-aware turns earlier: {} ({y:.1} vs {x:.1} mm before K)",
                yes(y > x)
            );
        }
        if let (Some(x), Some(y)) = (overshoot(a), overshoot(b)) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::experiment::tests::round_trip;

    fn row(x: f64, y: f64, vx: f64, vy: f64) -> TrajectoryRow {
        TrajectoryRow {
            t_s: 0.0,
            x_mm: x,
            y_mm: y,
            theta_rad: 0.0,
            vx_mm_s: vx,
            vy_mm_s: vy,
            cmd_vx_mm_s: 0.0,
            cmd_vy_mm_s: 0.0,
            est_x_mm: None,
            est_y_mm: None,
            est_theta_rad: None,
        }
    }

    #[test]
    fn onset_and_overshoot_follow_their_definitions() {
        let rows = vec![
            row(-2500.0, 0.0, 0.0, 0.0),
            row(-2000.0, 0.0, 150.0, 0.0), // below 200: not armed yet
            row(-1500.0, 0.0, 400.0, 0.0),
            row(-1000.0, 0.0, 350.0, 50.0),  // 87.5% of the maximum
            row(-700.0, 50.0, 290.0, 100.0), // 72.5%: onset at (K - p).u1 = 700
            row(-300.0, 200.0, 100.0, 300.0),
            row(120.0, 300.0, -50.0, 300.0),
            row(60.0, 500.0, -200.0, 300.0),
        ];
        let m = corner_metrics(&rows, Vector2::zeros(), Vector2::new(1.0, 0.0));
        assert_eq!(m.turn_onset_mm, Some(700.0));
        assert_eq!(m.overshoot_mm, Some(120.0));
    }

    #[test]
    fn the_metrics_are_the_summary_keys_and_read_back() {
        let rows = vec![
            row(-1500.0, 0.0, 400.0, 0.0),
            row(-700.0, 50.0, 290.0, 100.0),
            row(120.0, 300.0, -50.0, 300.0),
        ];
        let m = corner_metrics(&rows, Vector2::zeros(), Vector2::x());
        let summary = round_trip(&m);
        assert_eq!(
            serde_json::to_string(&summary.experiment).unwrap(),
            r#"{"turn_onset_mm":700.0,"overshoot_mm":120.0}"#
        );
        assert_eq!(
            (onset(&summary), overshoot(&summary)),
            (Some(700.0), Some(120.0))
        );
        // No onset: the key is left out; no trajectory: the overshoot is null.
        let none = corner_metrics(&[], Vector2::zeros(), Vector2::x());
        let summary = round_trip(&none);
        assert_eq!(
            serde_json::to_string(&summary.experiment).unwrap(),
            r#"{"overshoot_mm":null}"#
        );
        assert_eq!((onset(&summary), overshoot(&summary)), (None, None));
    }
}
