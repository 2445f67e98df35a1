//! Navigation among obstacles: the occupancy grid the robot builds from what it sees
//! ([`grid`]), a global planner on it ([`planner`], pricing the grid by [`distances`]) and the navigator that replans, follows the
//! plan by a lookahead point and watches the progress ([`navigator`]). The velocity-aware
//! controller stays the safety layer: the plan only chooses where it heads.
//!
//! Its settings are `[control.planner]` ([`PlannerConfig`]).

pub mod config;
pub mod distances;
pub mod grid;
pub mod navigator;
pub mod planner;

pub use config::{PlannerConfig, PlannerKind, TABLE, check_planner};
pub use grid::{CellState, GridGeometry, MapSnapshot, OccupancyGrid};
pub use navigator::{NavigationReport, Navigator, Unreachable};
