//! The planner's settings, `[control.planner]`, and their check.

use crate::config::ControlSpec;
use crate::tables::{ConfigProblem, Problems};
use serde::{Deserialize, Serialize};

/// Which planner chooses where the controller heads (`control.planner.kind`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlannerKind {
    /// A* on the occupancy grid the robot builds.
    Grid,
    /// None: the controller heads straight for the target (the papers' set-up; the default
    /// until the grid planner meets its navigation benchmark, see docs/navigation.md).
    #[default]
    None,
}

/// Settings of the planner (`[control.planner]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlannerConfig {
    /// The planner.
    pub kind: PlannerKind,
    /// Side of a grid cell, mm (20-25 mm resolve a 250 mm gap for a 180 mm robot).
    pub cell_mm: f64,
    /// Added to the robot's radius: cells nearer than that to a blocked one are impassable, mm.
    pub inflation_mm: f64,
    /// Beyond that, the band in which paths pay to keep off obstacles, mm.
    pub comfort_mm: f64,
    /// The extra cost factor of an unknown cell (1: crossing it costs twice a free one).
    pub unknown_cost: f64,
    /// Replanning period, s (also whenever the robot strays from its path).
    pub replan_period_s: f64,
    /// How far along the path the controller's goal point lies, mm.
    pub lookahead_mm: f64,
    /// Progress watchdog: no progress for this long marks the region ahead costly, s.
    pub watchdog_s: f64,
    /// What counts as progress: moving this far, or the remaining path shortening this much, mm.
    pub progress_mm: f64,
    /// Time constant with which what was seen fades to unknown, s.
    pub forget_s: f64,
    /// Seed the grid with the walls, goals and pillars of the map the robot is given.
    pub seed_map: bool,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        Self {
            kind: PlannerKind::None,
            cell_mm: 20.0,
            inflation_mm: 30.0,
            comfort_mm: 150.0,
            unknown_cost: 1.0,
            replan_period_s: 0.2,
            lookahead_mm: 400.0,
            watchdog_s: 4.0,
            progress_mm: 200.0,
            forget_s: 20.0,
            seed_map: true,
        }
    }
}

/// The table's name under `[control]`.
pub const TABLE: &str = "planner";

/// Parses and checks `[control.planner]`, naming each field at fault.
pub fn check_planner(spec: &ControlSpec) -> Vec<ConfigProblem> {
    spec.tables
        .check("control", TABLE, |c: &PlannerConfig, p: &mut Problems| {
            if !(c.cell_mm.is_finite() && (5.0..=200.0).contains(&c.cell_mm)) {
                p.fail(
                    "cell_mm",
                    format!("must lie in [5, 200] mm (got {})", c.cell_mm),
                );
            }
            p.non_negative("inflation_mm", c.inflation_mm);
            p.non_negative("comfort_mm", c.comfort_mm);
            p.non_negative("unknown_cost", c.unknown_cost);
            p.positive("replan_period_s", c.replan_period_s);
            p.positive("lookahead_mm", c.lookahead_mm);
            p.positive("watchdog_s", c.watchdog_s);
            p.positive("progress_mm", c.progress_mm);
            p.positive("forget_s", c.forget_s);
        })
}
