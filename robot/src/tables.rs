//! The settings tables of registered controllers and perception stages, kept as written
//! (`[control.avoidance]`, `[control.wander]`, ...) and parsed by the code that owns them.

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;

/// A value that breaks a rule: the dotted path of its field in the scenario and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ConfigProblem {
    /// The field, e.g. `control.avoidance.margin_mm`.
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl ConfigProblem {
    /// A problem with `field`.
    pub fn new(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            field: field.into(),
            message: message.into(),
        }
    }
}

impl std::error::Error for ConfigProblem {}

impl fmt::Display for ConfigProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "field `{}`: {}", self.field, self.message)
    }
}

/// Collects the problems of a table, each naming its field (`section.table.key`).
#[derive(Debug, Default)]
pub struct Problems {
    prefix: String,
    /// What was found.
    pub list: Vec<ConfigProblem>,
}

impl Problems {
    /// Problems of the fields under `prefix` (e.g. `control.wander`).
    pub fn under(prefix: &str) -> Self {
        Self {
            prefix: prefix.to_string(),
            list: Vec::new(),
        }
    }

    /// Field `key` (relative to the prefix) breaks a rule.
    pub fn fail(&mut self, key: &str, message: impl Into<String>) {
        let field = if key.is_empty() {
            self.prefix.clone()
        } else {
            format!("{}.{key}", self.prefix)
        };
        self.list.push(ConfigProblem::new(field, message));
    }

    /// Field `key` must be a finite number > 0.
    pub fn positive(&mut self, key: &str, v: f64) {
        if !(v.is_finite() && v > 0.0) {
            self.fail(key, format!("must be a finite number > 0 (got {v})"));
        }
    }

    /// Field `key` must be a finite number >= 0.
    pub fn non_negative(&mut self, key: &str, v: f64) {
        if !(v.is_finite() && v >= 0.0) {
            self.fail(key, format!("must be >= 0 (got {v})"));
        }
    }
}

/// The tables of a section that belong to registered parts, by name, as written.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Tables(pub BTreeMap<String, toml::Value>);

impl Tables {
    /// Table `name` of section `section` parsed as its owner's settings (their defaults when
    /// the table is not written); the problem names the field that does not parse.
    pub fn parse<T: DeserializeOwned + Default>(
        &self,
        section: &str,
        name: &str,
    ) -> Result<T, ConfigProblem> {
        match self.0.get(name) {
            None => Ok(T::default()),
            Some(value) => deserialize(value, section, name),
        }
    }

    /// Table `name` of section `section` parsed as `T`, which must be written; the problem
    /// names the field that does not parse, or the table when it is missing.
    pub fn parse_present<T: DeserializeOwned>(
        &self,
        section: &str,
        name: &str,
    ) -> Result<T, ConfigProblem> {
        let value = self
            .0
            .get(name)
            .ok_or_else(|| ConfigProblem::new(format!("{section}.{name}"), "missing"))?;
        deserialize(value, section, name)
    }

    /// Parses table `name` of section `section` and runs `check` on it: the problems of either,
    /// each naming its field.
    pub fn check<T: DeserializeOwned + Default>(
        &self,
        section: &str,
        name: &str,
        check: impl FnOnce(&T, &mut Problems),
    ) -> Vec<ConfigProblem> {
        match self.parse::<T>(section, name) {
            Ok(t) => {
                let mut p = Problems::under(&format!("{section}.{name}"));
                check(&t, &mut p);
                p.list
            }
            Err(e) => vec![e],
        }
    }

    /// Whether no table is written.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The names of the tables written.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.0.keys().map(String::as_str)
    }

    /// Replaces table `name` with `value`'s serialization (an edit made in code).
    pub fn set<T: Serialize>(&mut self, name: &str, value: &T) -> Result<(), ConfigProblem> {
        let v = toml::Value::try_from(value)
            .map_err(|e| ConfigProblem::new(name.to_string(), e.to_string()))?;
        self.0.insert(name.to_string(), v);
        Ok(())
    }
}

/// `value`, table `name` of section `section`, as `T`; the problem names the field at fault.
fn deserialize<T: DeserializeOwned>(
    value: &toml::Value,
    section: &str,
    name: &str,
) -> Result<T, ConfigProblem> {
    serde_path_to_error::deserialize(value.clone()).map_err(|e| {
        let inner = e.path().to_string();
        let field = match inner.as_str() {
            "." | "" => format!("{section}.{name}"),
            path => format!("{section}.{name}.{path}"),
        };
        ConfigProblem::new(field, e.into_inner().message().trim().to_string())
    })
}
