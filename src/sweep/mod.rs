//! Sweeps: one scenario run over a grid of `--set` values and seeds, in parallel, with one table
//! (`sweep.csv`, `sweep.md`) and one picture (`sweep.png`).
//!
//! Every combination is built and validated before anything runs ([`plan`]); the runs are
//! shared among workers ([`run_jobs`]), each run as deterministic as alone; the rows come back
//! in the plan's order whatever finished first.

pub mod files;
pub mod journal;
pub mod plan;
pub mod plan_file;
pub mod plot;
pub mod report;
pub mod set;
pub mod workers;

pub use files::{
    known_metric, report as write_report, report_with as write_report_with, write_outputs,
};
pub use journal::{Journal, Record, collect_runs, read_journal};
pub use plan::{Job, Plan, PlanError, Seeds, SeedsError, describe, plan, with_values};
pub use plan_file::{
    PlanFileError, PlannedJob, PlannedJobError, planned_job, read_plan, write_plan,
};
pub use report::{Aggregate, DEFAULT_REACHABLE_MARGIN_MM, ReportSettings, Row, row_json, rows};
pub use set::{Set, SetError, SetProblem};
pub use workers::{JobError, Outcome, SweepOptions, run_job, run_jobs, run_remaining, shared_gpu};
