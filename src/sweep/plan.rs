//! The plan of a sweep: every combination of the `--set` values and seeds, each built into a
//! scenario and validated before anything runs.

use super::set::{self, Set};
use crate::experiments::{load_scenario, parse_scenario};
use crate::scenario::LoadError;
use crate::scenario::Scenario;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::Arc;
use toml::{Table, Value};

/// The seeds of each combination: `N` (the scenario's seed and the N - 1 after it) or `A..B`
/// (both ends included).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Seeds {
    /// This many seeds from the scenario's.
    Count(u64),
    /// From, to (included).
    Range(u64, u64),
}

impl Default for Seeds {
    fn default() -> Self {
        Self::Count(1)
    }
}

/// Why a text is not `--seeds`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SeedsError {
    /// A part that is not a whole number.
    #[error("`{0}` is not a seed (a whole number >= 0)")]
    NotASeed(String),
    /// A range whose end is below its start.
    #[error("`{0}`: the last seed is below the first")]
    Reversed(String),
    /// A count of 0.
    #[error("at least one seed")]
    None,
    /// More seeds than a sweep takes.
    #[error("`{0}`: too many")]
    TooMany(String),
}

impl FromStr for Seeds {
    type Err = SeedsError;

    fn from_str(s: &str) -> Result<Self, SeedsError> {
        let num = |t: &str| {
            t.trim()
                .parse::<u64>()
                .map_err(|_| SeedsError::NotASeed(t.to_string()))
        };
        let seeds = match s.split_once("..") {
            Some((a, b)) => {
                let (a, b) = (num(a)?, num(b)?);
                if b < a {
                    return Err(SeedsError::Reversed(s.to_string()));
                }
                Self::Range(a, b)
            }
            None => Self::Count(num(s)?),
        };
        match seeds {
            Self::Count(0) => Err(SeedsError::None),
            Self::Count(n) if n > 100_000 => Err(SeedsError::TooMany(s.to_string())),
            Self::Range(a, b) if b - a >= 100_000 => Err(SeedsError::TooMany(s.to_string())),
            ok => Ok(ok),
        }
    }
}

impl std::fmt::Display for Seeds {
    /// As `--seeds` takes them: `N` or `A..B`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Count(n) => write!(f, "{n}"),
            Self::Range(a, b) => write!(f, "{a}..{b}"),
        }
    }
}

impl Seeds {
    /// The seeds, given the scenario's.
    pub fn list(&self, base: u64) -> Vec<u64> {
        match *self {
            Self::Count(n) => (0..n).map(|k| base.wrapping_add(k)).collect(),
            Self::Range(a, b) => (a..=b).collect(),
        }
    }
}

/// One run of a sweep.
#[derive(Debug, Clone)]
pub struct Job {
    /// Position in the plan (the row of `sweep.csv`).
    pub index: usize,
    /// Which combination (the same for every seed of it).
    pub combination: usize,
    /// The value of each `--set`, in the order given.
    pub values: Vec<Value>,
    /// The seed.
    pub seed: u64,
    /// The scenario with the values and the seed in.
    pub scenario: Scenario,
    /// The scenario's TOML with the values in (the seed is `seed`), shared by the seeds of a
    /// combination.
    pub toml: Arc<str>,
}

impl Job {
    /// A folder name: run number, the values and the seed.
    pub fn dir_name(&self, sets: &[Set]) -> String {
        let mut name = format!("{:04}", self.index);
        for (s, v) in sets.iter().zip(&self.values) {
            let key = s.key.rsplit('.').next().unwrap_or(&s.key);
            name.push_str(&format!("_{key}={}", set::value_text(v)));
        }
        name.push_str(&format!("_seed={}", self.seed));
        name.chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || "._=-".contains(c) {
                    c
                } else {
                    '-'
                }
            })
            .collect()
    }
}

/// A checked sweep: the scenario file, the `--set`s and every run.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The scenario file.
    pub file: PathBuf,
    /// The scenario's name.
    pub name: String,
    /// The `--set`s, in the order given.
    pub sets: Vec<Set>,
    /// Every run: combinations in order (the first `--set` slowest), seeds within each.
    pub jobs: Vec<Job>,
}

/// Why a sweep cannot start.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// The scenario file itself does not load.
    #[error(transparent)]
    Scenario(#[from] LoadError),
    /// Combinations that are not valid scenarios, each message naming the `--set`.
    #[error("{}", .0.join("\n"))]
    Invalid(Vec<String>),
}

/// Most runs one sweep may plan.
const MAX_RUNS: usize = 100_000;

/// Builds and validates every run of `sets` x `seeds` over the scenario `file`.
pub fn plan(file: &Path, sets: &[Set], seeds: &Seeds) -> Result<Plan, PlanError> {
    let base = load_scenario(file)?;
    let text = std::fs::read_to_string(file).map_err(|reason| LoadError::Io {
        file: file.to_path_buf(),
        reason,
    })?;
    let doc: Table = toml::from_str(&text)
        .map_err(|e| PlanError::Invalid(vec![format!("{}: {}", file.display(), e.message())]))?;
    let combos = combinations(sets);
    let seed_list = seeds.list(base.seed);
    if combos.len().saturating_mul(seed_list.len()) > MAX_RUNS {
        return Err(PlanError::Invalid(vec![format!(
            "{} combinations x {} seeds: more than {MAX_RUNS} runs",
            combos.len(),
            seed_list.len()
        )]));
    }
    let mut errors: Vec<String> = Vec::new();
    let mut jobs = Vec::new();
    for (c, values) in combos.into_iter().enumerate() {
        let (scenario, toml) = match combination(file, &doc, sets, &values) {
            Ok((s, t)) => (s, Arc::<str>::from(t)),
            Err(e) => {
                errors.extend(
                    e.into_iter()
                        .filter(|m| !errors.contains(m))
                        .collect::<Vec<_>>(),
                );
                continue;
            }
        };
        for &seed in &seed_list {
            let mut scenario = scenario.clone();
            scenario.seed = seed;
            jobs.push(Job {
                index: jobs.len(),
                combination: c,
                values: values.clone(),
                seed,
                scenario,
                toml: toml.clone(),
            });
        }
    }
    errors.dedup();
    if !errors.is_empty() {
        return Err(PlanError::Invalid(errors));
    }
    Ok(Plan {
        file: file.to_path_buf(),
        name: base.name,
        sets: sets.to_vec(),
        jobs,
    })
}

/// The scenario `text` (read from `file`, named in messages) with each key set to its value,
/// validated as a sweep's combination is: each problem names the key it came from
/// (`--set KEY=VALUE:1:COL: ...`). Returns the scenario and its text with the values in.
pub fn with_values(
    file: &Path,
    text: &str,
    values: &[(String, Value)],
) -> Result<(Scenario, String), Vec<String>> {
    let doc: Table =
        toml::from_str(text).map_err(|e| vec![format!("{}: {}", file.display(), e.message())])?;
    let mut sets = Vec::with_capacity(values.len());
    for (key, value) in values {
        sets.push(Set::single(key, value.clone()).map_err(|e| vec![e.to_string()])?);
    }
    let vals: Vec<Value> = values.iter().map(|(_, v)| v.clone()).collect();
    combination(file, &doc, &sets, &vals)
}

/// Every combination of the sets' values, the first set slowest.
fn combinations(sets: &[Set]) -> Vec<Vec<Value>> {
    let mut out: Vec<Vec<Value>> = vec![Vec::new()];
    for s in sets {
        out = out
            .into_iter()
            .flat_map(|prefix| {
                s.values.iter().map(move |v| {
                    let mut p = prefix.clone();
                    p.push(v.clone());
                    p
                })
            })
            .collect();
    }
    out
}

/// The scenario with `values` written in, validated, and its TOML; each problem names the
/// `--set` it came from (`--set ARG:1:COL: field ...`), or the whole combination when none
/// covers its field.
fn combination(
    file: &Path,
    doc: &Table,
    sets: &[Set],
    values: &[Value],
) -> Result<(Scenario, String), Vec<String>> {
    let mut doc = doc.clone();
    for (s, v) in sets.iter().zip(values) {
        s.apply(&mut doc, v).map_err(|e| vec![e.to_string()])?;
    }
    let text = toml::to_string(&doc).map_err(|e| vec![format!("{}: {e}", file.display())])?;
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    match parse_scenario(&text, file, &stem) {
        Ok(s) => Ok((s, text)),
        Err(LoadError::Invalid { problems }) => Err(problems
            .into_iter()
            .map(|p| {
                let what = if p.field.is_empty() {
                    p.message.clone()
                } else {
                    format!("field `{}`: {}", p.field, p.message)
                };
                match sets
                    .iter()
                    .position(|s| !p.field.is_empty() && s.covers(&p.field.to_string()))
                {
                    Some(k) => format!(
                        "--set {}:1:{}: {} = {}: {what}",
                        sets[k].arg,
                        sets[k].column_of(&values[k]),
                        sets[k].key,
                        values[k]
                    ),
                    None => format!("{} with {}: {what}", file.display(), describe(sets, values)),
                }
            })
            .collect()),
        Err(e) => Err(vec![e.to_string()]),
    }
}

/// `key=value, key=value` of one combination.
pub fn describe(sets: &[Set], values: &[Value]) -> String {
    sets.iter()
        .zip(values)
        .map(|(s, v)| format!("{}={}", s.key, set::value_text(v)))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_read_as_a_count_or_a_range() {
        assert_eq!("3".parse::<Seeds>().unwrap().list(7), [7, 8, 9]);
        assert_eq!("2..4".parse::<Seeds>().unwrap().list(7), [2, 3, 4]);
        assert_eq!("0".parse::<Seeds>(), Err(SeedsError::None));
        assert_eq!(
            "4..2".parse::<Seeds>(),
            Err(SeedsError::Reversed("4..2".into()))
        );
        assert_eq!(
            "x".parse::<Seeds>().unwrap_err().to_string(),
            "`x` is not a seed (a whole number >= 0)"
        );
        for s in ["3", "2..4"] {
            assert_eq!(s.parse::<Seeds>().unwrap().to_string(), s);
        }
    }

    #[test]
    fn combinations_put_the_first_set_slowest() {
        let a = Set::parse("a=1,2").unwrap();
        let b = Set::parse("b=x,y,z").unwrap();
        let c = combinations(&[a, b]);
        assert_eq!(c.len(), 6);
        assert_eq!(c[1], [Value::Integer(1), Value::String("y".into())]);
        assert_eq!(c[3], [Value::Integer(2), Value::String("x".into())]);
        assert_eq!(combinations(&[]).len(), 1);
    }
}
