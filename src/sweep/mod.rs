//! Sweeps: one scenario run over a grid of `--set` values and seeds, in parallel, with one table
//! (`sweep.csv`, `sweep.md`) and one picture (`sweep.png`).
//!
//! Every combination is built and validated before anything runs ([`plan`]); the runs are
//! shared among workers ([`run_jobs`]), each run as deterministic as alone; the rows come back
//! in the plan's order whatever finished first.

pub mod files;
pub mod plan;
pub mod plot;
pub mod report;
pub mod set;
pub mod workers;

pub use files::{known_metric, write_outputs};
pub use plan::{Job, Plan, PlanError, Seeds, describe, plan, with_values};
pub use report::{Aggregate, Row, rows};
pub use set::{Set, SetError};
pub use workers::{Outcome, SweepOptions, run_jobs, shared_gpu};
