//! The report layer: a run's files ([`output`]: `summary.json`, `trajectory.csv`,
//! `estimates.jsonl`, `topview.png`) and the figures ([`topview`], [`charts`]).

pub mod charts;
pub mod output;
pub mod topview;

pub use output::{default_out_dir, run_topview_image, write_run};
