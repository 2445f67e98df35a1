//! What a run leaves behind: the trajectory (one row a control cycle) and the summary.

use super::outcome::GoalFigures;
use super::score::FloorRegionScore;
use nalgebra::{Isometry2, Point2};
use omniloop_robot::{Estimates, Fix, FixOutcome, Measurement, NavigationReport};
use omniloop_vision::{FreeSpace, LocalizationMode, LocalizationQuality};
use serde::{Deserialize, Serialize};
use std::io::Write;

/// One control cycle: truth, estimate (when an estimator ran) and command.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryRow {
    /// Simulated time at the start of the cycle.
    pub t_s: f64,
    /// True x.
    pub x_mm: f64,
    /// True y.
    pub y_mm: f64,
    /// True heading.
    pub theta_rad: f64,
    /// True velocity, x.
    pub vx_mm_s: f64,
    /// True velocity, y.
    pub vy_mm_s: f64,
    /// Commanded velocity, x (world frame).
    pub cmd_vx_mm_s: f64,
    /// Commanded velocity, y (world frame).
    pub cmd_vy_mm_s: f64,
    /// Estimated x, when an estimator ran this cycle.
    pub est_x_mm: Option<f64>,
    /// Estimated y.
    pub est_y_mm: Option<f64>,
    /// Estimated heading.
    pub est_theta_rad: Option<f64>,
}

/// Column names of `trajectory.csv`, in order.
pub const TRAJECTORY_HEADER: &str = "t_s,x_mm,y_mm,theta_rad,vx_mm_s,vy_mm_s,cmd_vx_mm_s,cmd_vy_mm_s,est_x_mm,est_y_mm,est_theta_rad";

/// Writes the trajectory as CSV; empty cells where no estimate exists. Numbers are written in
/// their shortest exact form, so equal runs give byte-identical files.
pub fn write_trajectory_csv(rows: &[TrajectoryRow], mut w: impl Write) -> std::io::Result<()> {
    writeln!(w, "{TRAJECTORY_HEADER}")?;
    let opt = |v: Option<f64>| v.map(|x| x.to_string()).unwrap_or_default();
    for r in rows {
        writeln!(
            w,
            "{},{},{},{},{},{},{},{},{},{},{}",
            r.t_s,
            r.x_mm,
            r.y_mm,
            r.theta_rad,
            r.vx_mm_s,
            r.vy_mm_s,
            r.cmd_vx_mm_s,
            r.cmd_vy_mm_s,
            opt(r.est_x_mm),
            opt(r.est_y_mm),
            opt(r.est_theta_rad)
        )?;
    }
    Ok(())
}

/// Writes a team's trajectories as one CSV: `robot` and then the columns of
/// [`TRAJECTORY_HEADER`], each robot's rows in turn (in the robots' order).
pub fn write_team_trajectory_csv(
    robots: &[(&str, &[TrajectoryRow])],
    mut w: impl Write,
) -> std::io::Result<()> {
    writeln!(w, "robot,{TRAJECTORY_HEADER}")?;
    for (name, rows) in robots {
        let mut one = Vec::new();
        write_trajectory_csv(rows, &mut one)?;
        let text = String::from_utf8_lossy(&one);
        for line in text.lines().skip(1) {
            writeln!(w, "{name},{line}")?;
        }
    }
    Ok(())
}

/// Reads a number that JSON wrote as `null` because it was infinite.
fn null_as_infinity<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::INFINITY))
}

/// The metrics of a run, written to `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Scenario name.
    pub scenario: String,
    /// Seed used.
    pub seed: u64,
    /// Controller that drove the robot.
    pub controller: String,
    /// Control cycles run.
    pub cycles: u64,
    /// Simulated time.
    pub sim_time_s: f64,
    /// Wall-clock time the run took, set-up included.
    pub wall_time_s: f64,
    /// Control cycles per wall-clock second of the cycles alone (set-up excluded).
    pub cycles_per_s: f64,
    /// How many times the robot started touching a wall, cube, pillar or robot (physics engine).
    pub wall_contacts: u32,
    /// Those touches by the class of what was touched (`wall`, `cube`, `robot`, ...; the ball
    /// is no wall and never in it), left out when there were none.
    #[serde(skip_serializing_if = "ContactCounts::is_empty", default)]
    pub contacts_by_class: ContactCounts,
    /// Largest speed of the robot.
    pub peak_speed_mm_s: f64,
    /// Largest acceleration between two physics steps.
    pub peak_accel_mm_s2: f64,
    /// Whether the robot centre came within the goal tolerance.
    pub reached_goal: bool,
    /// When it did.
    pub time_to_goal_s: Option<f64>,
    /// With a goal: how the run ended (`outcome`, `unreachable_reason`) and whether the goal
    /// could be reached on the true world (`goal_reachable`, `reachable_margin_mm`); for a
    /// team, its worst robot's outcome and its narrowest route.
    #[serde(flatten)]
    pub goal_figures: Option<GoalFigures>,
    /// Smallest distance from the robot's edge to a wall, cube, pillar or robot (infinite,
    /// written as `null`, when no cycle ran).
    #[serde(deserialize_with = "null_as_infinity")]
    pub min_clearance_mm: f64,
    /// Length of the path the robot centre travelled.
    pub path_length_mm: f64,
    /// The renderer that traced the sensors' images (adapter name or `cpu (...)`), if any.
    pub renderer: Option<String>,
    /// Median over the run of |detected free distance - true free distance| over all directions
    /// (truth ray-cast in the world, clipped at the template's range).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub freespace_error_mm: Option<f64>,
    /// With the truth traced (`--truth`): median over the run's cycles of the intersection over
    /// union of the free-space stage's floor region and the true one, pixel by pixel.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub floor_region_iou: Option<f64>,
    /// Median over the run of the distance between the controller's pose estimate and the
    /// truth.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub pose_error_mm: Option<f64>,
    /// With waypoints: how many of the targets (waypoints, then the goal) were reached.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub targets_reached: Option<usize>,
    /// With localization in the loop: how many localizations corrected the pose.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub localization_fixes: Option<usize>,
    /// With a planner: whether it found the goal unreachable (and stopped the robot).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub unreachable: Option<bool>,
    /// With a planner: how many times its progress watchdog fired.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub watchdog_fired: Option<usize>,
    /// With checkpoints: the heading error at the end of each visit (the estimate within the
    /// goal's `checkpoint_radius_mm` of a checkpoint), degrees.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub checkpoint_heading_error_deg: Option<Vec<f64>>,
    /// A team's own figures (`[[robots]]`): arrivals, contacts by what was touched, the least
    /// clearance between two robots, when the last arrived against the straight-line time.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub team: Option<TeamFigures>,
    /// A team's robots, a row each, in the scenario's order.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub robots: Option<Vec<RobotSummary>>,
    /// With a ball: the game's figures (kicks, goals, outs, touches, possession, dribbles,
    /// speeds), judged on the simulator's side.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub ball: Option<super::ball_record::BallSummary>,
    /// The experiment's own metrics (`turn_onset_mm`, `overshoot_mm` of E1, `places` of E2,
    /// ...), written as keys of the summary beside the others: each experiment's typed
    /// metrics as keys, read back as the type with `Metrics::of` (`crate::experiments`).
    #[serde(flatten)]
    pub experiment: serde_json::Map<String, serde_json::Value>,
}

/// The figures of one robot of a team (a row of `summary.json`'s `robots`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobotSummary {
    /// Its name.
    pub name: String,
    /// What drove it.
    pub controller: String,
    /// Whether it reached its goal (false without one).
    pub reached_goal: bool,
    /// When it did.
    pub time_to_goal_s: Option<f64>,
    /// With a goal: how its run ended and whether its goal could be reached (as the
    /// summary's).
    #[serde(flatten)]
    pub goal_figures: Option<GoalFigures>,
    /// How many times it started touching anything.
    pub contacts: u32,
    /// Of those, walls, cubes, pillars and boards.
    pub solid_contacts: u32,
    /// Of those, other robots.
    pub robot_contacts: u32,
    /// All of them by the class of what was touched, left out when there were none.
    #[serde(skip_serializing_if = "ContactCounts::is_empty", default)]
    pub contacts_by_class: ContactCounts,
    /// Least distance from its edge to anything (`null`: no step ran).
    #[serde(deserialize_with = "null_as_infinity")]
    pub min_clearance_mm: f64,
    /// Least distance from its edge to another robot's edge (`null`: none was there).
    #[serde(deserialize_with = "null_as_infinity")]
    pub min_robot_clearance_mm: f64,
    /// Length of the path its centre travelled.
    pub path_length_mm: f64,
    /// Length of the straight lines from its start through its waypoints to its goal.
    pub straight_mm: Option<f64>,
    /// Its largest speed.
    pub peak_speed_mm_s: f64,
    /// Its largest acceleration between two physics steps.
    pub peak_accel_mm_s2: f64,
    /// Median error of its free distances (with the free-space stage).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub freespace_error_mm: Option<f64>,
    /// Median intersection over union of its floor region with the truth's (with `--truth`).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub floor_region_iou: Option<f64>,
    /// Median error of its pose estimate.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub pose_error_mm: Option<f64>,
    /// With waypoints: targets reached.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub targets_reached: Option<usize>,
    /// With localization in the loop: fixes used.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub localization_fixes: Option<usize>,
    /// With a planner: whether it found its goal unreachable.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub unreachable: Option<bool>,
    /// With a planner: how often its progress watchdog fired.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub watchdog_fired: Option<usize>,
}

/// A team's figures (`summary.json`'s `team`; in a sweep's table as `team.KEY` columns).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TeamFigures {
    /// Robots with software.
    pub robots: usize,
    /// Robots with a goal.
    pub with_goal: usize,
    /// Robots that reached their goal.
    pub arrived: usize,
    /// Whether every robot with a goal reached it.
    pub all_arrived: bool,
    /// When the last robot with a goal arrived (`null` while one has not).
    pub last_arrival_s: Option<f64>,
    /// The longest straight-line time of a robot with a goal: its straight lines at its top
    /// speed, accelerating and braking at its limit, stopping at each target.
    pub straight_line_time_s: Option<f64>,
    /// `last_arrival_s / straight_line_time_s`.
    pub time_ratio: Option<f64>,
    /// Touches of a robot of the team with a wall, cube, pillar or board.
    pub solid_contacts: u32,
    /// Touches between two robots (one of the team at least), each counted once.
    pub robot_contacts: u32,
    /// Least distance between the edges of a robot of the team and any other robot
    /// (`null`: never two).
    #[serde(deserialize_with = "null_as_infinity")]
    pub min_robot_clearance_mm: f64,
    /// Total path of the robots with a goal over the total of their straight lines, each less
    /// its goal's tolerance (as the clutter benchmark's `path_ratio`).
    pub path_ratio: Option<f64>,
}

/// Touches by the name of the class of what was touched.
pub type ContactCounts = std::collections::BTreeMap<String, u32>;

/// The counts of `by_class` under their classes' names.
pub fn contact_counts(by_class: &omniloop_sim::ContactsByClass) -> ContactCounts {
    by_class
        .touched()
        .map(|(class, n)| (class.name().to_string(), n))
        .collect()
}

/// A planar pose as written in `estimates.jsonl`.
#[derive(Debug, Clone, Copy, Serialize)]
struct PoseRecord {
    x_mm: f64,
    y_mm: f64,
    theta_rad: f64,
}

impl PoseRecord {
    fn of(p: &Isometry2<f64>) -> Self {
        Self {
            x_mm: p.translation.x,
            y_mm: p.translation.y,
            theta_rad: p.rotation.angle(),
        }
    }
}

/// A fix as written in `estimates.jsonl`: what was measured (the parts a kind has) and what
/// the estimator did with it.
#[derive(Debug, Serialize)]
struct FixRecord<'a> {
    source: &'a str,
    kind: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    x_mm: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    y_mm: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    theta_rad: Option<f64>,
    outcome: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    why: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    quality: Option<QualityRecord<'a>>,
}

/// A fix's quality record as written in `estimates.jsonl`.
#[derive(Debug, Serialize)]
struct QualityRecord<'a> {
    mode: &'static str,
    rms_residual_mm: f64,
    points: usize,
    points_per_line: &'a [usize],
    lines: usize,
    boundary_points: usize,
    inlier_fraction: f64,
    sigma_x_mm: f64,
    sigma_y_mm: f64,
    sigma_deg: f64,
    hull_cut: bool,
    resolved_by_goals: bool,
    iterations: usize,
}

impl<'a> QualityRecord<'a> {
    fn of(q: &'a LocalizationQuality) -> Self {
        // NaN (the paper's method keeps no standard deviations) is written as null.
        Self {
            mode: match q.mode {
                LocalizationMode::Global => "global",
                LocalizationMode::Tracking => "tracking",
            },
            rms_residual_mm: q.rms_residual_mm,
            points: q.points,
            points_per_line: &q.points_per_line,
            lines: q.lines,
            boundary_points: q.boundary_points,
            inlier_fraction: q.inlier_fraction,
            sigma_x_mm: q.sigma[0],
            sigma_y_mm: q.sigma[1],
            sigma_deg: q.sigma[2].to_degrees(),
            hull_cut: q.hull_cut,
            resolved_by_goals: q.resolved_by_goals,
            iterations: q.iterations,
        }
    }
}

impl<'a> FixRecord<'a> {
    fn of(f: &'a Fix) -> Self {
        let (kind, x, y, t) = match &f.measurement {
            Measurement::Pose { pose, .. } => {
                let p = PoseRecord::of(pose);
                ("pose", Some(p.x_mm), Some(p.y_mm), Some(p.theta_rad))
            }
            Measurement::Heading { heading_rad } => ("heading", None, None, Some(*heading_rad)),
            Measurement::Position { position } => {
                ("position", Some(position.x), Some(position.y), None)
            }
            Measurement::Motion { delta } => {
                let p = PoseRecord::of(delta);
                ("motion", Some(p.x_mm), Some(p.y_mm), Some(p.theta_rad))
            }
        };
        let (outcome, why) = match &f.outcome {
            FixOutcome::Anchored => ("anchored", None),
            FixOutcome::Used => ("used", None),
            FixOutcome::Rejected(why) => ("rejected", Some(why.as_str())),
            FixOutcome::Ignored => ("ignored", None),
        };
        Self {
            source: f.source,
            kind,
            x_mm: x,
            y_mm: y,
            theta_rad: t,
            outcome,
            why,
            quality: f.quality.as_ref().map(QualityRecord::of),
        }
    }
}

/// One line of `estimates.jsonl`: the truth of a cycle beside what the robot believed.
#[derive(Debug, Serialize)]
struct EstimateLine<'a> {
    t_s: f64,
    truth: PoseRecord,
    estimate: Option<PoseRecord>,
    target: Option<usize>,
    fixes: Vec<FixRecord<'a>>,
    not_found: Vec<(&'a str, &'a str)>,
    free_mm: Option<&'a [f64]>,
    /// What the stages found, each entry as its stage records it (the landmarks ranged, the
    /// motion read, ...).
    #[serde(flatten)]
    percepts: serde_json::Map<String, serde_json::Value>,
    #[serde(skip_serializing_if = "Option::is_none")]
    plan: Option<PlanRecord>,
    /// With the truth traced: the free-space stage's floor region scored pixel by pixel.
    #[serde(skip_serializing_if = "Option::is_none")]
    floor_region: Option<&'a FloorRegionScore>,
}

/// What the planner did in one cycle: its plan, the point the controller headed for, the way
/// still to go, and the map's counts.
#[derive(Debug, Serialize)]
struct PlanRecord {
    path_mm: Vec<[f64; 2]>,
    lookahead_mm: Option<[f64; 2]>,
    remaining_mm: Option<f64>,
    replans: usize,
    watchdog: usize,
    closed: usize,
    unreachable: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    unreachable_reason: Option<&'static str>,
    cells_free: usize,
    cells_unknown: usize,
    cells_suspect: usize,
    cells_blocked: usize,
}

impl PlanRecord {
    fn of(n: &NavigationReport) -> Self {
        let xy = |p: &Point2<f64>| [round_mm(p.x), round_mm(p.y)];
        Self {
            path_mm: n.path_mm.iter().map(xy).collect(),
            lookahead_mm: n.lookahead_mm.as_ref().map(xy),
            remaining_mm: n.remaining_mm.map(round_mm),
            replans: n.replans,
            watchdog: n.watchdog,
            closed: n.closed,
            unreachable: n.unreachable.is_some(),
            unreachable_reason: n.unreachable.map(|u| u.as_str()),
            cells_free: n.cells[0],
            cells_unknown: n.cells[1],
            cells_suspect: n.cells[2],
            cells_blocked: n.cells[3],
        }
    }
}

/// To a tenth of a millimetre, for the record.
fn round_mm(v: f64) -> f64 {
    (v * 10.0).round() / 10.0
}

/// Writes one JSON line a control cycle ([`estimates_line`]), with the cycle's floor-region
/// score where `floor_scores` has one.
pub fn write_estimates_jsonl(
    rows: &[TrajectoryRow],
    estimates: &[Estimates],
    floor_scores: &[Option<FloorRegionScore>],
    mut w: impl Write,
) -> std::io::Result<()> {
    for (k, (r, e)) in rows.iter().zip(estimates).enumerate() {
        let floor = floor_scores.get(k).and_then(Option::as_ref);
        serde_json::to_writer(&mut w, &EstimateLine::of(r, e, floor))?;
        writeln!(w)?;
    }
    Ok(())
}

/// One line of `estimates.jsonl` (without its newline): time, true pose, the robot's pose
/// estimate, the target it headed for, its fixes with their outcomes, the stages that found
/// nothing (with why), its free distances, and (omnistereo) the landmarks it ranged and the
/// motion it read, (with a planner) its plan, and (with the truth traced) its floor region
/// scored pixel by pixel.
pub fn estimates_line(
    row: &TrajectoryRow,
    e: &Estimates,
    floor: Option<&FloorRegionScore>,
) -> String {
    // Serializing plain records of numbers, strings and options cannot fail.
    serde_json::to_string(&EstimateLine::of(row, e, floor)).unwrap_or_default()
}

impl<'a> EstimateLine<'a> {
    fn of(r: &TrajectoryRow, e: &'a Estimates, floor: Option<&'a FloorRegionScore>) -> Self {
        EstimateLine {
            t_s: e.t_s,
            truth: PoseRecord {
                x_mm: r.x_mm,
                y_mm: r.y_mm,
                theta_rad: r.theta_rad,
            },
            estimate: e.pose.as_ref().map(PoseRecord::of),
            target: e.target,
            fixes: e.fixes.iter().map(FixRecord::of).collect(),
            not_found: e
                .not_found
                .iter()
                .map(|n| (n.source, n.reason.as_str()))
                .collect(),
            free_mm: e.percept::<FreeSpace>().map(|f| f.free_mm.as_slice()),
            percepts: e
                .percepts
                .records()
                .map(|(key, value)| (key.to_string(), value))
                .collect(),
            plan: e.navigation.as_ref().map(PlanRecord::of),
            floor_region: floor,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_summary_without_cycles_reads_back() {
        // No cycle ran: no clearance was measured, and JSON has no infinity.
        let text = r#"{"scenario":"s","seed":1,"controller":"idle","cycles":0,"sim_time_s":0.0,
            "wall_time_s":0.1,"cycles_per_s":0.0,"wall_contacts":0,"peak_speed_mm_s":0.0,
            "peak_accel_mm_s2":0.0,"reached_goal":false,"time_to_goal_s":null,
            "min_clearance_mm":null,"path_length_mm":0.0,"places":[]}"#;
        let m: Summary = serde_json::from_str(text).unwrap();
        assert_eq!(m.min_clearance_mm, f64::INFINITY);
        assert!(m.experiment.contains_key("places"));
        let again: Summary = serde_json::from_str(&serde_json::to_string(&m).unwrap()).unwrap();
        assert_eq!(again, m);
    }

    /// A goal's figures sit among the summary's own keys, a margin of no route as `null`, and
    /// read back apart from the experiment's keys; without a goal there are none.
    #[test]
    fn goal_figures_are_keys_of_the_summary_and_read_back() {
        use super::super::outcome::GoalOutcome;
        let text = r#"{"scenario":"s","seed":1,"controller":"c","cycles":3,"sim_time_s":0.1,
            "wall_time_s":0.1,"cycles_per_s":30.0,"wall_contacts":0,"peak_speed_mm_s":0.0,
            "peak_accel_mm_s2":0.0,"reached_goal":false,"time_to_goal_s":null,
            "outcome":"unreachable","unreachable_reason":"too_narrow","goal_reachable":false,
            "reachable_margin_mm":null,"min_clearance_mm":5.0,"path_length_mm":0.0,
            "straight_mm":1500.0}"#;
        let m: Summary = serde_json::from_str(text).unwrap();
        let g = m.goal_figures.clone().unwrap();
        assert_eq!(g.outcome, GoalOutcome::Unreachable);
        assert_eq!(g.unreachable_reason.as_deref(), Some("too_narrow"));
        assert_eq!((g.goal_reachable, g.reachable_margin_mm), (false, None));
        let keys: Vec<&String> = m.experiment.keys().collect();
        assert_eq!(
            keys,
            ["straight_mm"],
            "the goal's keys are not the experiment's"
        );
        let json = serde_json::to_value(&m).unwrap();
        assert_eq!(json["reachable_margin_mm"], serde_json::Value::Null);
        assert_eq!(json["outcome"], "unreachable");
        let again: Summary = serde_json::from_value(json).unwrap();
        assert_eq!(again, m);
        let none = Summary {
            goal_figures: None,
            ..m
        };
        let json = serde_json::to_value(&none).unwrap();
        for key in [
            "outcome",
            "unreachable_reason",
            "goal_reachable",
            "reachable_margin_mm",
        ] {
            assert!(json.get(key).is_none(), "{key}");
        }
        assert_eq!(serde_json::from_value::<Summary>(json).unwrap(), none);
    }
}
