//! `--set KEY=V1,V2,...`: a dotted path into the scenario's TOML and the values it takes.
//!
//! KEY is a dotted path (`robot.max_speed_mm_s`, `experiment.corner.angle_deg`), an item of an
//! array of tables written `name[2]` (`robot.sensors[0].noise_sigma`). Each value is a TOML
//! literal (`400`, `0.5`, `true`, `"cpu"`, `[1, 2]`), a bare word standing for a string
//! (`wander`: a letter or `_` first), or a range `A..B:STEP` (both ends included; STEP 1 when left out; integers when
//! all three are).

use toml::{Table, Value};

/// A `--set` that cannot be read or applied, located in its argument like a file position.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("--set {arg}:1:{column}: {problem}")]
pub struct SetError {
    /// The argument as given.
    pub arg: String,
    /// 1-based column in the argument.
    pub column: usize,
    /// What is wrong.
    pub problem: SetProblem,
}

/// What is wrong with a `--set`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SetProblem {
    /// No `=`.
    #[error("expected KEY=VALUE[,VALUE...]")]
    NoValue,
    /// Nothing between two commas.
    #[error("an empty value")]
    EmptyValue,
    /// More values than a sweep takes.
    #[error("more than {} values", MAX_VALUES)]
    TooManyValues,
    /// Nothing before the `=`.
    #[error("an empty key")]
    EmptyKey,
    /// A part of the key that is not `NAME` or `NAME[INDEX]`.
    #[error("`{part}` in `{key}`: expected NAME or NAME[INDEX]")]
    BadKeyPart {
        /// The part.
        part: String,
        /// The key.
        key: String,
    },
    /// A value that is neither a TOML literal, a bare word nor a range.
    #[error("`{text}` is not a TOML value: {reason}")]
    NotToml {
        /// The value as written.
        text: String,
        /// What the TOML parser said.
        reason: String,
    },
    /// A range whose end or step is not a number.
    #[error("range `{range}`: `{part}` is not a number")]
    RangeNotNumber {
        /// The range as written.
        range: String,
        /// The part that is not a number.
        part: String,
    },
    /// A range whose step is not positive.
    #[error("range `{0}`: the step must be positive")]
    RangeStep(String),
    /// A range whose end is below its start.
    #[error("range `{0}`: the end is below the start")]
    RangeReversed(String),
    /// A range of more values than a sweep takes.
    #[error("range `{range}`: {count} values (most {})", MAX_VALUES)]
    RangeTooLong {
        /// The range as written.
        range: String,
        /// The values it has.
        count: usize,
    },
    /// A key through a value where a table should be.
    #[error("`{name}` in `{key}` is a value, not a table")]
    NotATable {
        /// The part of the key.
        name: String,
        /// The key.
        key: String,
    },
    /// An item of something that is not an array.
    #[error("`{name}` in `{key}` is not an array in the scenario")]
    NotAnArray {
        /// The part of the key.
        name: String,
        /// The key.
        key: String,
    },
    /// An item past the array's end.
    #[error("`{name}` in `{key}`: item {index} of {len} (counted from 0)")]
    NoItem {
        /// The array.
        name: String,
        /// The key.
        key: String,
        /// The item asked for.
        index: usize,
        /// The array's length.
        len: usize,
    },
    /// A key through an array item that is a value, not a table.
    #[error("`{name}` in `{key}`[{index}] is a value, not a table")]
    ItemNotATable {
        /// The array.
        name: String,
        /// The key.
        key: String,
        /// The item.
        index: usize,
    },
}

/// One step of a key path.
#[derive(Debug, Clone, PartialEq)]
enum Segment {
    /// A table's key.
    Key(String),
    /// An item of the array under a table's key.
    Item(String, usize),
}

/// One parsed `--set`.
#[derive(Debug, Clone, PartialEq)]
pub struct Set {
    /// The argument as given (`KEY=V1,V2`).
    pub arg: String,
    /// The key as written.
    pub key: String,
    /// The values, in order.
    pub values: Vec<Value>,
    /// 1-based column in the argument of each value (a range's values share its column).
    pub columns: Vec<usize>,
    path: Vec<Segment>,
}

/// Most values one `--set` may expand to.
const MAX_VALUES: usize = 10_000;

impl Set {
    /// Parses `KEY=V1,V2,...`.
    pub fn parse(arg: &str) -> Result<Self, SetError> {
        let fail = |column: usize, problem: SetProblem| SetError {
            arg: arg.to_string(),
            column,
            problem,
        };
        let Some((key, values)) = arg.split_once('=') else {
            return Err(fail(1, SetProblem::NoValue));
        };
        let key = key.trim();
        let path = parse_path(key).map_err(|m| fail(1, m))?;
        let start = arg.find('=').unwrap_or(0) + 2;
        let (mut out, mut columns) = (Vec::new(), Vec::new());
        for (offset, piece) in split_values(values) {
            let column = start + offset + (piece.len() - piece.trim_start().len());
            let piece = piece.trim();
            if piece.is_empty() {
                return Err(fail(column, SetProblem::EmptyValue));
            }
            let vals = parse_value(piece).map_err(|m| fail(column, m))?;
            columns.extend(std::iter::repeat_n(column, vals.len()));
            out.extend(vals);
            if out.len() > MAX_VALUES {
                return Err(fail(column, SetProblem::TooManyValues));
            }
        }
        Ok(Self {
            arg: arg.to_string(),
            key: key.to_string(),
            values: out,
            columns,
            path,
        })
    }

    /// One key with one value, as `--set KEY=VALUE` would give it (the library's and Python's
    /// way to set a value without writing it as text).
    pub fn single(key: &str, value: Value) -> Result<Self, SetError> {
        let arg = format!("{key}={value}");
        let path = parse_path(key.trim()).map_err(|problem| SetError {
            arg: arg.clone(),
            column: 1,
            problem,
        })?;
        Ok(Self {
            arg,
            key: key.trim().to_string(),
            values: vec![value],
            columns: vec![key.len() + 2],
            path,
        })
    }

    /// Writes `value` at the key into `doc`, creating missing tables on the way; the error is
    /// at the argument's first column.
    pub fn apply(&self, doc: &mut Table, value: &Value) -> Result<(), SetError> {
        let fail = |problem| SetError {
            arg: self.arg.clone(),
            column: 1,
            problem,
        };
        let mut table = doc;
        let last = self.path.len() - 1;
        for (i, seg) in self.path.iter().enumerate() {
            let key = || self.key.clone();
            match seg {
                Segment::Key(name) if i == last => {
                    table.insert(name.clone(), value.clone());
                }
                Segment::Key(name) => {
                    let next = table
                        .entry(name.clone())
                        .or_insert_with(|| Value::Table(Table::new()));
                    table = next.as_table_mut().ok_or_else(|| {
                        fail(SetProblem::NotATable {
                            name: name.clone(),
                            key: key(),
                        })
                    })?;
                }
                Segment::Item(name, k) => {
                    let items = table
                        .get_mut(name)
                        .and_then(Value::as_array_mut)
                        .ok_or_else(|| {
                            fail(SetProblem::NotAnArray {
                                name: name.clone(),
                                key: key(),
                            })
                        })?;
                    let len = items.len();
                    let item = items.get_mut(*k).ok_or_else(|| {
                        fail(SetProblem::NoItem {
                            name: name.clone(),
                            key: key(),
                            index: *k,
                            len,
                        })
                    })?;
                    if i == last {
                        *item = value.clone();
                        return Ok(());
                    }
                    table = item.as_table_mut().ok_or_else(|| {
                        fail(SetProblem::ItemNotATable {
                            name: name.clone(),
                            key: key(),
                            index: *k,
                        })
                    })?;
                }
            }
        }
        Ok(())
    }

    /// The column of `value` in the argument (the first value's when it is not one of them).
    pub fn column_of(&self, value: &Value) -> usize {
        let k = self.values.iter().position(|v| v == value).unwrap_or(0);
        self.columns.get(k).copied().unwrap_or(1)
    }

    /// Whether the scenario field `field` (as validation names it) lies at or under this key,
    /// or this key under it.
    pub fn covers(&self, field: &str) -> bool {
        let under = |a: &str, b: &str| {
            a == b || a.strip_prefix(b).is_some_and(|r| r.starts_with(['.', '[']))
        };
        under(field, &self.key) || under(&self.key, field)
    }
}

/// `a.b[2].c` as segments.
fn parse_path(key: &str) -> Result<Vec<Segment>, SetProblem> {
    if key.is_empty() {
        return Err(SetProblem::EmptyKey);
    }
    key.split('.')
        .map(|part| {
            let bad = || SetProblem::BadKeyPart {
                part: part.to_string(),
                key: key.to_string(),
            };
            let (name, item) = match part.split_once('[') {
                Some((name, rest)) => {
                    let k = rest.strip_suffix(']').ok_or_else(bad)?;
                    (name, Some(k.parse::<usize>().map_err(|_| bad())?))
                }
                None => (part, None),
            };
            let ok = !name.is_empty()
                && name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
            if !ok {
                return Err(bad());
            }
            Ok(match item {
                Some(k) => Segment::Item(name.to_string(), k),
                None => Segment::Key(name.to_string()),
            })
        })
        .collect()
}

/// The comma-separated values with their byte offsets, commas inside brackets, braces or
/// quotes left alone.
fn split_values(text: &str) -> Vec<(usize, &str)> {
    let (mut out, mut depth, mut quote, mut start) = (Vec::new(), 0i32, None, 0);
    for (i, c) in text.char_indices() {
        match (c, quote) {
            ('"' | '\'', None) => quote = Some(c),
            (q, Some(open)) if q == open => quote = None,
            (_, Some(_)) => {}
            ('[' | '{', None) => depth += 1,
            (']' | '}', None) => depth -= 1,
            (',', None) if depth == 0 => {
                out.push((start, &text[start..i]));
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push((start, &text[start..]));
    out
}

/// One value: a range, a TOML literal or a bare word.
fn parse_value(text: &str) -> Result<Vec<Value>, SetProblem> {
    if let Some(range) = parse_range(text)? {
        return Ok(range);
    }
    match toml::from_str::<Table>(&format!("v = {text}")) {
        Ok(mut t) => Ok(t.remove("v").into_iter().collect()),
        Err(_)
            if text.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
                && text
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') =>
        {
            Ok(vec![Value::String(text.to_string())])
        }
        Err(e) => Err(SetProblem::NotToml {
            text: text.to_string(),
            reason: e.message().to_string(),
        }),
    }
}

/// `A..B` or `A..B:STEP`, both ends included; `None` when `text` is not a range.
fn parse_range(text: &str) -> Result<Option<Vec<Value>>, SetProblem> {
    let Some((a, rest)) = text.split_once("..") else {
        return Ok(None);
    };
    let (b, step) = match rest.split_once(':') {
        Some((b, s)) => (b, Some(s)),
        None => (rest, None),
    };
    let num = |s: &str| -> Result<f64, SetProblem> {
        s.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| SetProblem::RangeNotNumber {
                range: text.to_string(),
                part: s.to_string(),
            })
    };
    let (lo, hi) = (num(a)?, num(b)?);
    let step_v = step.map(num).transpose()?.unwrap_or(1.0);
    if step_v <= 0.0 {
        return Err(SetProblem::RangeStep(text.to_string()));
    }
    if hi < lo {
        return Err(SetProblem::RangeReversed(text.to_string()));
    }
    let count = ((hi - lo) / step_v + 1e-9).floor() as usize + 1;
    if count > MAX_VALUES {
        return Err(SetProblem::RangeTooLong {
            range: text.to_string(),
            count,
        });
    }
    let integer = |s: &str| s.trim().parse::<i64>().is_ok();
    let ints = integer(a) && integer(b) && step.is_none_or(integer);
    Ok(Some(
        (0..count)
            .map(|k| {
                let v = lo + k as f64 * step_v;
                if ints {
                    Value::Integer(v.round() as i64)
                } else {
                    // Rounded to 1e-9 so that 0.1 steps print as written.
                    Value::Float((v * 1e9).round() / 1e9)
                }
            })
            .collect(),
    ))
}

/// A value as a short text for tables and file names (strings unquoted).
pub fn value_text(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_lists_and_literals_expand_in_order() {
        let s = Set::parse("experiment.corner.angle_deg=40..130:15").unwrap();
        let v: Vec<i64> = s.values.iter().map(|v| v.as_integer().unwrap()).collect();
        assert_eq!(v, [40, 55, 70, 85, 100, 115, 130]);
        let s = Set::parse("a.b=0.1..0.3:0.1, 2, wander, \"x,y\", [1, 2]").unwrap();
        assert_eq!(s.values.len(), 7);
        assert_eq!(s.values[2].as_float(), Some(0.3));
        assert_eq!(s.values[3].as_integer(), Some(2));
        assert_eq!(s.values[4].as_str(), Some("wander"));
        assert_eq!(s.values[5].as_str(), Some("x,y"));
        assert!(s.values[6].is_array());
    }

    #[test]
    fn a_bad_set_names_its_column() {
        let e = Set::parse("robot.max_speed_mm_s=400,1e,1000").unwrap_err();
        assert_eq!(e.column, 26, "{e}");
        assert!(
            e.to_string()
                .starts_with("--set robot.max_speed_mm_s=400,1e,1000:1:26:")
        );
        assert!(Set::parse("robot..x=1").is_err());
        assert_eq!(
            Set::parse("robot.x").unwrap_err().problem,
            SetProblem::NoValue
        );
        assert_eq!(
            Set::parse("a=5..1").unwrap_err().problem,
            SetProblem::RangeReversed("5..1".into())
        );
        assert!(Set::parse("a=1..5:0").is_err());
        assert!(Set::parse("a[x].b=1").is_err());
    }

    #[test]
    fn apply_writes_nested_keys_and_array_items() {
        let mut doc: Table = toml::from_str("[robot]\n[[robot.sensors]]\nname = \"a\"\n").unwrap();
        let s = Set::parse("robot.sensors[0].noise_sigma=2.5").unwrap();
        s.apply(&mut doc, &s.values[0]).unwrap();
        let t = Set::parse("vision.freespace.directions=36").unwrap();
        t.apply(&mut doc, &t.values[0]).unwrap();
        let text = toml::to_string(&doc).unwrap();
        assert!(text.contains("noise_sigma = 2.5"), "{text}");
        assert!(text.contains("directions = 36"), "{text}");
        let u = Set::parse("robot.sensors[3].x=1").unwrap();
        let e = u.apply(&mut doc, &u.values[0]).unwrap_err();
        assert!(
            matches!(
                e.problem,
                SetProblem::NoItem {
                    index: 3,
                    len: 1,
                    ..
                }
            ),
            "{e}"
        );
        assert_eq!(
            e.to_string(),
            "--set robot.sensors[3].x=1:1:1: `sensors` in `robot.sensors[3].x`: item 3 of 1 \
             (counted from 0)"
        );
        assert!(t.covers("vision.freespace.directions"));
        assert!(s.covers("robot.sensors[0]"));
        assert!(!s.covers("robot.sensors[0].noise"));
    }
}
