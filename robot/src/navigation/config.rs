//! The planner's settings, `[control.planner]`, and their check.

use crate::config::ControlSpec;
use omniloop_problem::{Problem, Problems};
use serde::{Deserialize, Serialize};

/// Which planner chooses where the controller heads (`control.planner.kind`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlannerKind {
    /// A* on the occupancy grid the robot builds (the default).
    #[default]
    Grid,
    /// None: the controller heads straight for the target (the papers' set-up: E1's scenario
    /// files say so).
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
    /// No progress for this long (the remaining way not shortened by `progress_mm`) closes the
    /// narrowest place ahead on the plan until the target changes: dearer after one failure
    /// there, impassable after two, so that the robot takes another route or, with none left,
    /// reports the goal unreachable (`no_progress`), s.
    pub stall_s: f64,
    /// The controller refusing, for this long, every step toward the point the plan heads for
    /// (its command makes no headway toward it while the robot stands) closes the narrowest
    /// place ahead the same way (`too_narrow` when no route is left), s.
    pub refuse_s: f64,
    /// The way still to go not once shorter, by `progress_mm`, than the least it has been
    /// for this long, whatever routes were tried: the goal is reported unreachable
    /// (`no_progress`), s. The bound on a run that wanders between routes it cannot drive.
    pub give_up_s: f64,
    /// Time constant with which what was seen fades to unknown, s.
    pub forget_s: f64,
    /// Seed the grid with the walls, goals and pillars of the map the robot is given.
    pub seed_map: bool,
    /// No route through free, unknown or suspect cells for this long in a row: the goal is
    /// reported unreachable, s.
    pub unreachable_s: f64,
    /// The map with every far mark taken as right has held the goal in a closed pocket for
    /// this long (net of the time it did not): the goal is reported unreachable, s.
    pub pocket_unreachable_s: f64,
    /// The largest pocket round the goal that marks from afar may close, mm^2 (a goal ringed
    /// by obstacles; far marks are not trusted to cut the field in two).
    pub pocket_area_mm2: f64,
    /// The pocket counts only while the robot is this near the goal, mm.
    pub pocket_sight_mm: f64,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        Self {
            kind: PlannerKind::Grid,
            cell_mm: 20.0,
            inflation_mm: 35.0,
            comfort_mm: 150.0,
            unknown_cost: 1.0,
            replan_period_s: 0.2,
            lookahead_mm: 400.0,
            watchdog_s: 4.0,
            progress_mm: 200.0,
            stall_s: 10.0,
            refuse_s: 4.0,
            give_up_s: 30.0,
            forget_s: 20.0,
            seed_map: true,
            unreachable_s: 2.0,
            pocket_unreachable_s: 4.0,
            pocket_area_mm2: 0.25e6,
            pocket_sight_mm: 700.0,
        }
    }
}

/// The table's name under `[control]`.
pub const TABLE: &str = "planner";

/// Parses and checks `[control.planner]`, naming each field at fault.
pub fn check_planner(spec: &ControlSpec) -> Vec<Problem> {
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
            p.positive("stall_s", c.stall_s);
            p.positive("refuse_s", c.refuse_s);
            p.positive("give_up_s", c.give_up_s);
            p.positive("forget_s", c.forget_s);
            p.positive("unreachable_s", c.unreachable_s);
            p.positive("pocket_unreachable_s", c.pocket_unreachable_s);
            p.non_negative("pocket_area_mm2", c.pocket_area_mm2);
            p.non_negative("pocket_sight_mm", c.pocket_sight_mm);
        })
}
