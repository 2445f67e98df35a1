//! What became of each job, kept as the sweep goes: `rows.jsonl` in the sweep's folder, a line
//! a finished job (its index, name, seed, and its summary or its error), written as each ends,
//! so a sweep stopped or lost part-way can go on (`--resume`) and any engine's results make the
//! same report. `omniloop sweep --collect` reads the runs' own folders instead.

use super::plan::Plan;
use super::plan_file::PlanFileError;
use super::workers::{JobError, Outcome};
use crate::run::Summary;
use serde::{Deserialize, Serialize};
use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The journal's file name in a sweep's folder.
pub const JOURNAL: &str = "rows.jsonl";

/// One finished job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// The job's index in the plan.
    pub index: usize,
    /// Its output name (checked against the plan when read back).
    pub name: String,
    /// Its seed.
    pub seed: u64,
    /// Its summary, when it ran to the end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub summary: Option<Summary>,
    /// Why it failed, when it did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

impl Record {
    /// The record of `outcome`, job `name` with `seed`.
    pub fn new(outcome: &Outcome, name: &str, seed: u64) -> Self {
        let (summary, error) = match &outcome.result {
            Ok(s) => (Some(s.clone()), None),
            Err(e) => (None, Some(e.to_string())),
        };
        Self {
            index: outcome.job,
            name: name.to_string(),
            seed,
            summary,
            error,
        }
    }

    /// The outcome it records.
    pub fn outcome(self) -> Outcome {
        Outcome {
            job: self.index,
            result: match (self.summary, self.error) {
                (Some(s), None) => Ok(s),
                (_, Some(e)) => Err(JobError::Recorded(e)),
                (None, None) => Err(JobError::Unrecorded),
            },
        }
    }

    /// As one line of JSON, with its newline.
    pub fn line(&self) -> String {
        serde_json::to_string(self).unwrap_or_default() + "\n"
    }
}

/// The journal of a sweep, appended to from every worker.
pub struct Journal {
    file: PathBuf,
    out: Mutex<File>,
}

impl Journal {
    /// Opens `dir/rows.jsonl`: kept, and its records of `plan`'s jobs returned, when `resume`;
    /// otherwise started empty.
    pub fn open(
        dir: &Path,
        plan: &Plan,
        resume: bool,
    ) -> Result<(Self, Vec<Option<Outcome>>), PlanFileError> {
        let file = dir.join(JOURNAL);
        let io = |reason| PlanFileError::Io {
            file: file.clone(),
            reason,
        };
        std::fs::create_dir_all(dir).map_err(io)?;
        let previous = if resume && file.exists() {
            read_journal(&file, plan)?
        } else {
            vec![None; plan.jobs.len()]
        };
        let out = OpenOptions::new()
            .create(true)
            .append(resume)
            .write(true)
            .truncate(!resume)
            .open(&file)
            .map_err(io)?;
        Ok((
            Self {
                file: file.clone(),
                out: Mutex::new(out),
            },
            previous,
        ))
    }

    /// Appends `record` (a whole line at once, flushed).
    pub fn record(&self, record: &Record) -> Result<(), PlanFileError> {
        let mut out = self.out.lock().unwrap_or_else(|e| e.into_inner());
        out.write_all(record.line().as_bytes())
            .and_then(|()| out.flush())
            .map_err(|reason| PlanFileError::Io {
                file: self.file.clone(),
                reason,
            })
    }
}

/// The outcomes `file` records of `plan`'s jobs, in the plan's order (`None`: not recorded);
/// a record of another plan's job is an error naming its line. A line cut short by a crash is
/// left out (its job runs again).
pub fn read_journal(file: &Path, plan: &Plan) -> Result<Vec<Option<Outcome>>, PlanFileError> {
    let io = |reason| PlanFileError::Io {
        file: file.to_path_buf(),
        reason,
    };
    let mut out: Vec<Option<Outcome>> = vec![None; plan.jobs.len()];
    let reader = BufReader::new(File::open(file).map_err(io)?);
    for (k, line) in reader.lines().enumerate() {
        let line = line.map_err(io)?;
        let Ok(record) = serde_json::from_str::<Record>(&line) else {
            continue;
        };
        let expected = plan.jobs.get(record.index).map(|j| j.dir_name(&plan.sets));
        if expected.as_deref() != Some(record.name.as_str()) {
            return Err(PlanFileError::Line {
                file: file.to_path_buf(),
                line: k + 1,
                message: format!(
                    "job {} `{}` is not this sweep's (its job {} is {:?}): resume the sweep it \
                     came from, or start afresh without resuming",
                    record.index, record.name, record.index, expected
                ),
            });
        }
        let index = record.index;
        out[index] = Some(record.outcome());
    }
    Ok(out)
}

/// The outcomes of `plan`'s jobs from their folders under `runs` (as `omniloop run --plan`
/// leaves them): `summary.json`, or `error.txt` for a run that failed; `None` for a job with
/// neither.
pub fn collect_runs(runs: &Path, plan: &Plan) -> Result<Vec<Option<Outcome>>, PlanFileError> {
    let mut out = Vec::with_capacity(plan.jobs.len());
    for job in &plan.jobs {
        let dir = runs.join(job.dir_name(&plan.sets));
        let summary = dir.join("summary.json");
        let error = dir.join(ERROR_FILE);
        let result = if summary.exists() {
            let text = std::fs::read_to_string(&summary).map_err(|reason| PlanFileError::Io {
                file: summary.clone(),
                reason,
            })?;
            Some(Ok(serde_json::from_str::<Summary>(&text).map_err(|e| {
                PlanFileError::Line {
                    file: summary.clone(),
                    line: e.line(),
                    message: e.to_string(),
                }
            })?))
        } else if error.exists() {
            let text = std::fs::read_to_string(&error).unwrap_or_default();
            Some(Err(JobError::Recorded(text.trim_end().to_string())))
        } else {
            None
        };
        out.push(result.map(|result| Outcome {
            job: job.index,
            result,
        }));
    }
    Ok(out)
}

/// The file a failed planned run leaves in its folder, with its error.
pub const ERROR_FILE: &str = "error.txt";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::{Seeds, Set, plan};

    fn small_plan() -> Plan {
        let scenario =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/corner55_velocity_aware.toml");
        let sets = [Set::parse("robot.max_speed_mm_s=300,400").unwrap()];
        plan(&scenario, &sets, &Seeds::Count(2)).unwrap()
    }

    #[test]
    fn records_read_back_in_the_plans_order_and_a_cut_line_is_left_out() {
        let p = small_plan();
        let dir = std::env::temp_dir().join("omniloop_journal_round_trip");
        let _ = std::fs::remove_dir_all(&dir);
        let (journal, previous) = Journal::open(&dir, &p, false).unwrap();
        assert!(previous.iter().all(Option::is_none));
        let failed = Outcome {
            job: 2,
            result: Err(JobError::Recorded("the renderer stopped".into())),
        };
        let job = &p.jobs[2];
        journal
            .record(&Record::new(&failed, &job.dir_name(&p.sets), job.seed))
            .unwrap();
        let mut text = std::fs::read_to_string(dir.join(JOURNAL)).unwrap();
        text.push_str("{\"index\": 3, \"na");
        std::fs::write(dir.join(JOURNAL), text).unwrap();
        let (_, read) = Journal::open(&dir, &p, true).unwrap();
        assert_eq!(read.iter().flatten().count(), 1);
        assert!(
            matches!(
                &read[2].as_ref().unwrap().result,
                Err(JobError::Recorded(why)) if why == "the renderer stopped"
            ),
            "{:?}",
            read[2]
        );
    }

    #[test]
    fn another_sweeps_record_is_refused_with_its_line() {
        let p = small_plan();
        let dir = std::env::temp_dir().join("omniloop_journal_other");
        std::fs::create_dir_all(&dir).unwrap();
        let other = Record {
            index: 1,
            name: "0001_speed=9_seed=1".into(),
            seed: 1,
            summary: None,
            error: Some("x".into()),
        };
        std::fs::write(dir.join(JOURNAL), other.line()).unwrap();
        let e = read_journal(&dir.join(JOURNAL), &p)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("rows.jsonl:1: job 1 `0001_speed=9_seed=1` is not this sweep's"),
            "{e}"
        );
    }
}
