//! A sweep's plan as data, `plan.jsonl`, so that any engine can run its jobs (`omniloop sweep
//! --plan`): a first line with the sweep's arguments, then a line a job with its index,
//! combination, output name, seed, the `--set` values and the scenario's TOML after them. A job
//! is run by `omniloop run --plan FILE --job N` (or [`planned_job`] from Rust, Python and Ray
//! workers); `omniloop sweep --collect` builds the report from the runs' folders.

use super::plan::{Job, Plan, Seeds, plan};
use super::set::Set;
use crate::experiments::parse_scenario;
use crate::scenario::{LoadError, Scenario};
use serde::{Deserialize, Serialize};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};

/// The version of the plan's format, in its first line.
pub const PLAN_VERSION: u32 = 1;

/// The first line of `plan.jsonl`: what the sweep was asked.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanHeader {
    /// The format's version.
    pub omniloop_sweep_plan: u32,
    /// The scenario file, absolute.
    pub scenario_file: PathBuf,
    /// The `--set` arguments, in order.
    pub sets: Vec<String>,
    /// The seeds, as `--seeds` takes them.
    pub seeds: String,
    /// How many jobs follow.
    pub runs: usize,
}

/// One job of `plan.jsonl`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlannedJob {
    /// Its row of `sweep.csv`.
    pub index: usize,
    /// Its combination of values.
    pub combination: usize,
    /// The folder its outputs go to, under the sweep's `runs/`.
    pub name: String,
    /// Its seed.
    pub seed: u64,
    /// Each `--set` key and its value here.
    pub values: Vec<(String, toml::Value)>,
    /// The scenario's TOML with the values in (the seed is `seed`; run it with `omniloop run
    /// --plan`, which reads paths in it from the scenario file's folder).
    pub scenario: String,
}

/// Why a plan cannot be written or read.
#[derive(Debug, thiserror::Error)]
pub enum PlanFileError {
    /// A file cannot be read or written.
    #[error("{}: {reason}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// Why.
        reason: std::io::Error,
    },
    /// A line of the plan is not what it should be.
    #[error("{}:{line}: {message}", file.display())]
    Line {
        /// The plan.
        file: PathBuf,
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
}

/// Why a planned job given as its plan's lines ([`scenario_of_lines`]) cannot run.
#[derive(Debug, thiserror::Error)]
pub enum PlannedJobError {
    /// The header line is not a plan's first line.
    #[error("not a sweep plan's first line: {0}")]
    Header(serde_json::Error),
    /// The job's line is not a planned job.
    #[error("not a planned job: {0}")]
    Job(serde_json::Error),
    /// The job's scenario is not valid.
    #[error(transparent)]
    Scenario(#[from] LoadError),
}

/// The planned jobs of `plan`.
pub fn planned_jobs(plan: &Plan) -> Vec<PlannedJob> {
    plan.jobs
        .iter()
        .map(|job| PlannedJob {
            index: job.index,
            combination: job.combination,
            name: job.dir_name(&plan.sets),
            seed: job.seed,
            values: job_values(&plan.sets, job),
            scenario: job.toml.to_string(),
        })
        .collect()
}

/// Each `--set` key of `job` and its value.
fn job_values(sets: &[Set], job: &Job) -> Vec<(String, toml::Value)> {
    sets.iter()
        .zip(&job.values)
        .map(|(s, v)| (s.key.clone(), v.clone()))
        .collect()
}

/// Writes `plan` (asked with `seeds`) to `file` as JSON lines.
pub fn write_plan(plan: &Plan, seeds: &Seeds, file: &Path) -> Result<(), PlanFileError> {
    let io = |reason| PlanFileError::Io {
        file: file.to_path_buf(),
        reason,
    };
    let header = PlanHeader {
        omniloop_sweep_plan: PLAN_VERSION,
        scenario_file: std::path::absolute(&plan.file).map_err(io)?,
        sets: plan.sets.iter().map(|s| s.arg.clone()).collect(),
        seeds: seeds.to_string(),
        runs: plan.jobs.len(),
    };
    let mut text = json_line(&header);
    for job in planned_jobs(plan) {
        text.push_str(&json_line(&job));
    }
    if let Some(dir) = file.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    std::fs::File::create(file)
        .and_then(|mut f| f.write_all(text.as_bytes()))
        .map_err(io)
}

/// `value` as one line of JSON.
fn json_line(value: &impl Serialize) -> String {
    serde_json::to_string(value).unwrap_or_default() + "\n"
}

/// The lines of the plan `file`: its header and its jobs.
pub fn read_plan_lines(file: &Path) -> Result<(PlanHeader, Vec<PlannedJob>), PlanFileError> {
    let io = |reason| PlanFileError::Io {
        file: file.to_path_buf(),
        reason,
    };
    let bad = |line: usize, message: String| PlanFileError::Line {
        file: file.to_path_buf(),
        line,
        message,
    };
    let reader = BufReader::new(std::fs::File::open(file).map_err(io)?);
    let mut header: Option<PlanHeader> = None;
    let mut jobs = Vec::new();
    for (k, line) in reader.lines().enumerate() {
        let line = line.map_err(io)?;
        if line.trim().is_empty() {
            continue;
        }
        match &header {
            None => {
                let h: PlanHeader = serde_json::from_str(&line)
                    .map_err(|e| bad(k + 1, format!("not a sweep plan's first line: {e}")))?;
                if h.omniloop_sweep_plan != PLAN_VERSION {
                    return Err(bad(
                        k + 1,
                        format!("plan version {}", h.omniloop_sweep_plan),
                    ));
                }
                header = Some(h);
            }
            Some(_) => jobs.push(
                serde_json::from_str::<PlannedJob>(&line)
                    .map_err(|e| bad(k + 1, format!("not a planned job: {e}")))?,
            ),
        }
    }
    let header = header.ok_or_else(|| bad(1, "empty plan".into()))?;
    if jobs.len() != header.runs {
        return Err(bad(
            1,
            format!("{} jobs where it says {}", jobs.len(), header.runs),
        ));
    }
    Ok((header, jobs))
}

/// The sweep of the plan `file`, planned again from its scenario and arguments, and checked
/// against the file's jobs (the scenario must not have changed since).
pub fn read_plan(file: &Path) -> Result<(Plan, Vec<PlannedJob>), PlanFileError> {
    let (header, lines) = read_plan_lines(file)?;
    let bad = |message: String| PlanFileError::Line {
        file: file.to_path_buf(),
        line: 1,
        message,
    };
    let sets = header
        .sets
        .iter()
        .map(|a| Set::parse(a).map_err(|e| bad(e.to_string())))
        .collect::<Result<Vec<_>, _>>()?;
    let seeds = header
        .seeds
        .parse::<Seeds>()
        .map_err(|e| bad(e.to_string()))?;
    let plan = plan(&header.scenario_file, &sets, &seeds).map_err(|e| bad(e.to_string()))?;
    let again = planned_jobs(&plan);
    if again != lines {
        return Err(bad(format!(
            "its jobs are no longer what {} gives: the scenario changed since it was planned",
            header.scenario_file.display()
        )));
    }
    Ok((plan, lines))
}

/// Job `index` of the plan `file` and its scenario (the values and the seed in), validated.
pub fn planned_job(file: &Path, index: usize) -> Result<(PlannedJob, Scenario), PlanFileError> {
    let (header, mut lines) = read_plan_lines(file)?;
    let n = lines.len();
    let Some(pos) = lines.iter().position(|j| j.index == index) else {
        return Err(PlanFileError::Line {
            file: file.to_path_buf(),
            line: 1,
            message: format!(
                "no job {index} (the plan has jobs 0 to {})",
                n.saturating_sub(1)
            ),
        });
    };
    let job = lines.swap_remove(pos);
    let scenario = scenario_of(&header, &job).map_err(|e| PlanFileError::Line {
        file: file.to_path_buf(),
        line: pos + 2,
        message: e.to_string(),
    })?;
    Ok((job, scenario))
}

/// The scenario of a planned job: its TOML as the plan holds it (files it names are read from
/// the scenario file's folder), its seed.
pub fn scenario_of(header: &PlanHeader, job: &PlannedJob) -> Result<Scenario, LoadError> {
    let file = &header.scenario_file;
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut scenario = parse_scenario(&job.scenario, file, &stem)?;
    scenario.seed = job.seed;
    Ok(scenario)
}

/// The header and a job of a plan, each one JSON line of it (as a Ray task gets them): the
/// job's scenario.
pub fn scenario_of_lines(
    header: &str,
    job: &str,
) -> Result<(PlannedJob, Scenario), PlannedJobError> {
    let header: PlanHeader = serde_json::from_str(header).map_err(PlannedJobError::Header)?;
    let job: PlannedJob = serde_json::from_str(job).map_err(PlannedJobError::Job)?;
    let scenario = scenario_of(&header, &job)?;
    Ok((job, scenario))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// E1 over two speeds and two seeds, planned into a fresh folder: the plan file.
    fn planned(name: &str) -> (Plan, PathBuf) {
        let scenario =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/corner55_velocity_aware.toml");
        let sets = [Set::parse("robot.max_speed_mm_s=300,400").unwrap()];
        let seeds = Seeds::Count(2);
        let p = plan(&scenario, &sets, &seeds).unwrap();
        let dir = std::env::temp_dir().join(format!("omniloop_plan_file_{name}"));
        let _ = std::fs::remove_dir_all(&dir);
        let file = dir.join("plan.jsonl");
        write_plan(&p, &seeds, &file).unwrap();
        (p, file)
    }

    #[test]
    fn a_written_plan_reads_back_as_its_sweep_and_gives_each_job() {
        let (p, file) = planned("round_trip");
        let (again, lines) = read_plan(&file).unwrap();
        assert_eq!(lines.len(), 4);
        assert_eq!(again.jobs.len(), p.jobs.len());
        let (job, scenario) = planned_job(&file, 3).unwrap();
        assert_eq!((job.seed, scenario.seed), (p.jobs[3].seed, p.jobs[3].seed));
        assert_eq!(
            job.values,
            [("robot.max_speed_mm_s".into(), toml::Value::Integer(400))]
        );
        assert_eq!(scenario.robot.max_speed_mm_s, 400.0);
        assert!(job.scenario.contains("max_speed_mm_s = 400"));
    }

    #[test]
    fn a_broken_plan_names_its_line() {
        let (_, file) = planned("broken");
        let text = std::fs::read_to_string(&file).unwrap();
        let mut lines: Vec<&str> = text.lines().collect();
        lines[2] = "{\"index\": 1";
        std::fs::write(&file, lines.join("\n")).unwrap();
        let e = read_plan_lines(&file).unwrap_err().to_string();
        assert!(e.contains("plan.jsonl:3: not a planned job"), "{e}");
        let e = planned_job(&file.with_file_name("none.jsonl"), 0).unwrap_err();
        assert!(matches!(e, PlanFileError::Io { .. }));
    }
}
