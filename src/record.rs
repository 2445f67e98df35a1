//! What a run leaves behind: the trajectory (one row a control cycle) and the summary.

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
    /// Largest speed of the robot.
    pub peak_speed_mm_s: f64,
    /// Largest acceleration between two physics steps.
    pub peak_accel_mm_s2: f64,
    /// Whether the robot centre came within the goal tolerance.
    pub reached_goal: bool,
    /// When it did.
    pub time_to_goal_s: Option<f64>,
    /// Smallest distance from the robot's edge to a wall, cube, pillar or robot.
    pub min_clearance_mm: f64,
    /// Length of the path the robot centre travelled.
    pub path_length_mm: f64,
    /// The renderer that traced the sensors' images (adapter name or `cpu (...)`), if any.
    pub renderer: Option<String>,
    /// E1: `(K - p).u1` where the robot starts giving up speed along the first leg.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub turn_onset_mm: Option<f64>,
    /// E1: how far past the corner point the robot centre went along the first leg.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub overshoot_mm: Option<f64>,
    /// Median over the run of |detected free distance - true free distance| over all directions
    /// (truth ray-cast in the world, clipped at the template's range).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub freespace_error_mm: Option<f64>,
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
    /// Experiment mode: the results at each place.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub places: Option<Vec<PlaceResult>>,
}

/// Self-localization at one place of an experiment (E2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlaceResult {
    /// The true pose: x_mm, y_mm, theta_deg.
    pub true_pose: [f64; 3],
    /// RMS distance of the localized estimates from the true position.
    pub rms_position_mm: f64,
    /// RMS heading error of the localized estimates.
    pub rms_heading_deg: f64,
    /// Estimates that took the wrong one of the two half-turn solutions.
    pub ambiguity_errors: usize,
    /// Frames taken here.
    pub frames: usize,
    /// Frames that gave no estimate.
    pub not_localized: usize,
}
