//! Sweeps: one scenario run over a grid of `--set` values and seeds, in parallel, with one table
//! (`sweep.csv`, `sweep.md`) and one picture (`sweep.png`).
//!
//! Every combination is built and validated before anything runs ([`plan`]); the runs are
//! shared among workers ([`run_jobs`]), each run as deterministic as alone; the rows come back
//! in the plan's order whatever finished first.
//!
//! The smoke scenario at two top speeds, two seeds each:
//!
//! ```
//! use omniloop::sweep::{Seeds, Set, SweepOptions, plan, rows, run_jobs};
//! use omniloop_sim::RendererChoice;
//! use std::sync::atomic::AtomicBool;
//!
//! # fn main() -> anyhow::Result<()> {
//! let sets = [Set::parse("robot.max_speed_mm_s=300,500")?];
//! let plan = plan("scenarios/smoke.toml".as_ref(), &sets, &Seeds::Count(2))?;
//! assert_eq!(plan.jobs.len(), 4, "two values, two seeds each");
//! let options = SweepOptions {
//!     workers: 2,
//!     threads: 2,
//!     renderer: RendererChoice::Cpu,
//!     keep_runs: None,
//!     shared_gpu: None,
//!     truth: false,
//! };
//! let outcomes = run_jobs(&plan, &options, &AtomicBool::new(false), |_| {});
//! let rows = rows(&plan, &outcomes);
//! assert!(rows.iter().all(|r| r.error.is_none()));
//! let fast: Vec<_> = rows.iter().filter(|r| r.combination == 1).collect();
//! assert_eq!(fast.len(), 2);
//! # Ok(())
//! # }
//! ```

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
