//! The settings tables of registered controllers and perception stages, kept as written
//! (`[control.avoidance]`, `[control.wander]`, ...) and parsed by the code that owns them.

use omniloop_problem::{Problem, Problems};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

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
    ) -> Result<T, Problem> {
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
    ) -> Result<T, Problem> {
        let value = self
            .0
            .get(name)
            .ok_or_else(|| Problem::new(format!("{section}.{name}"), "missing"))?;
        deserialize(value, section, name)
    }

    /// Parses table `name` of section `section` and runs `check` on it: the problems of either,
    /// each naming its field.
    pub fn check<T: DeserializeOwned + Default>(
        &self,
        section: &str,
        name: &str,
        check: impl FnOnce(&T, &mut Problems),
    ) -> Vec<Problem> {
        match self.parse::<T>(section, name) {
            Ok(t) => {
                let mut p = Problems::under(format!("{section}.{name}"));
                check(&t, &mut p);
                p.into_vec()
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
    pub fn set<T: Serialize>(&mut self, name: &str, value: &T) -> Result<(), Problem> {
        let v = toml::Value::try_from(value)
            .map_err(|e| Problem::new(name.to_string(), e.to_string()))?;
        self.0.insert(name.to_string(), v);
        Ok(())
    }
}

/// `value`, table `name` of section `section`, as `T`; the problem names the field at fault.
fn deserialize<T: DeserializeOwned>(
    value: &toml::Value,
    section: &str,
    name: &str,
) -> Result<T, Problem> {
    serde_path_to_error::deserialize(value.clone()).map_err(|e| {
        let inner = e.path().to_string();
        let field = match inner.as_str() {
            "." | "" => format!("{section}.{name}"),
            path => format!("{section}.{name}.{path}"),
        };
        Problem::new(field, e.into_inner().message().trim().to_string())
    })
}
