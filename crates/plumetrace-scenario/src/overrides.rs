//! Overrides of a scenario's keys (a campaign's `set` and sweep, `plumetrace bench --set`,
//! Python's keyword arguments): a value set at a key path of the scenario's TOML table before
//! it is read, so it is checked like a value of the file.

use plumetrace_core::params::quoted_key;

/// Why an override could not be set.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OverrideError {
    /// A bare key names the planner's, and the scenario has no planner table.
    #[error("the scenario has no planner table")]
    NoPlanner,
    /// A bare key names the planner's, and the scenario has several.
    #[error(
        "the scenario has several planners ({0}): name one with a dotted key (planners.NAME.KEY)"
    )]
    SeveralPlanners(String),
    /// A key path with an empty segment.
    #[error("'{0}' is not a key path")]
    NotAKeyPath(String),
    /// No key at all.
    #[error("empty key")]
    EmptyKey,
    /// A segment that indexes an array is not a whole number.
    #[error("'{at}': '{segment}' is not an index of an array")]
    NotAnIndex {
        /// The path up to and with the segment.
        at: String,
        /// The segment.
        segment: String,
    },
    /// An index past the end of an array.
    #[error("'{at}': index {index} is past the end: {}", entries(*len))]
    PastTheEnd {
        /// The path up to and with the index.
        at: String,
        /// The index.
        index: usize,
        /// The array's length.
        len: usize,
    },
    /// A value on the way that is neither a table nor an array.
    #[error("'{at}' is a {kind}, not a table")]
    NotATable {
        /// Its path.
        at: String,
        /// Its TOML type.
        kind: &'static str,
    },
}

/// Why a `KEY=VALUE` override (`--set` of `run`, `check` and `bench missions`) could not be
/// applied.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SetError {
    /// No `=`.
    #[error("--set {0:?}: expected KEY=VALUE")]
    Syntax(String),
    /// The value is not TOML.
    #[error("--set {set:?}: the value is not TOML{hint}")]
    Value {
        /// The override.
        set: String,
        /// What to do: for a bare word, that a string is quoted; otherwise the parser's
        /// message (its line and column would point into the parser's own wrapping).
        hint: String,
    },
    /// Nothing after `=`.
    #[error("--set {0:?}: no value")]
    NoValue(String),
    /// The key cannot be set in this scenario.
    #[error("--set {set:?}: {error}")]
    Key {
        /// The override.
        set: String,
        /// Why the key was refused.
        error: OverrideError,
    },
}

/// Applies `KEY=VALUE` overrides in order, each as a campaign's `set` ([`set_key`]); VALUE is
/// TOML (`0.5`, `"moth"`, `[1, 2]`). Returns the key paths set, as written.
pub fn apply_sets(table: &mut toml::Table, sets: &[String]) -> Result<Vec<String>, SetError> {
    let mut keys = Vec::with_capacity(sets.len());
    for s in sets {
        let (key, value) = s
            .split_once('=')
            .ok_or_else(|| SetError::Syntax(s.clone()))?;
        let value = value.trim();
        let value: toml::Value = toml::from_str::<toml::Table>(&format!("v = {value}"))
            .map_err(|error| SetError::Value {
                set: s.clone(),
                hint: if !value.is_empty()
                    && value
                        .chars()
                        .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
                {
                    format!(" (a string is quoted: {}='\"{value}\"')", key.trim())
                } else {
                    format!(": {}", error.message().trim_end())
                },
            })?
            .remove("v")
            .ok_or_else(|| SetError::NoValue(s.clone()))?;
        set_key(table, key.trim(), value).map_err(|error| SetError::Key {
            set: s.clone(),
            error,
        })?;
        keys.push(key.trim().to_string());
    }
    Ok(keys)
}

/// Replaces the scenario's single planner table ([`planner_path`]) by `kind = KIND` alone: the
/// planner at its defaults, as a campaign's `[configs.planner]` with only `kind`. Returns the
/// table's key path. A scenario with several planner tables (a team, a formation) is refused.
pub fn set_planner_kind(table: &mut toml::Table, kind: &str) -> Result<String, OverrideError> {
    let path = planner_path(table)?;
    let segments: Vec<&str> = path.split('.').map(|s| s.trim_matches('"')).collect();
    let mut planner = toml::Table::new();
    planner.insert("kind".into(), toml::Value::String(kind.to_string()));
    set_path(table, &segments, toml::Value::Table(planner))?;
    Ok(path)
}

/// The key path of a scenario's single planner table: `planner`, or `planners.NAME` when it has
/// exactly one named planner.
pub fn planner_path(table: &toml::Table) -> Result<String, OverrideError> {
    let named: Vec<&String> = table
        .get("planners")
        .and_then(toml::Value::as_table)
        .map(|t| t.keys().collect())
        .unwrap_or_default();
    match (table.contains_key("planner"), named.as_slice()) {
        (true, []) => Ok("planner".into()),
        (false, [one]) => Ok(format!("planners.{}", quoted_key(one))),
        (false, []) => Err(OverrideError::NoPlanner),
        _ => Err(OverrideError::SeveralPlanners(
            table
                .contains_key("planner")
                .then_some("planner".to_string())
                .into_iter()
                .chain(named.iter().map(|n| format!("planners.{}", quoted_key(n))))
                .collect::<Vec<_>>()
                .join(", "),
        )),
    }
}

/// How many entries an array has, and its indices, in words.
fn entries(len: usize) -> String {
    match len {
        0 => "the array is empty".into(),
        1 => "the array has 1 entry, index 0".into(),
        n => format!("the array has {n} entries, indices 0 to {}", n - 1),
    }
}

/// Sets `key` in a scenario table: a bare name is a key of the scenario's planner (see
/// [`planner_path`]); a dotted path walks tables, and whole-number segments index arrays
/// (`sources.0.mass_rate_per_s`).
pub fn set_key(
    table: &mut toml::Table,
    key: &str,
    value: toml::Value,
) -> Result<(), OverrideError> {
    let planner;
    let path: Vec<&str> = if key.contains('.') {
        key.split('.').collect()
    } else {
        planner = planner_path(table)?;
        planner.split('.').chain([key]).collect()
    };
    set_path(table, &path, value)
}

/// Sets the value at `path` (table keys, or whole numbers indexing arrays), making tables on
/// the way.
pub fn set_path(
    table: &mut toml::Table,
    path: &[&str],
    value: toml::Value,
) -> Result<(), OverrideError> {
    let key = path.join(".");
    if path.iter().any(|s| s.is_empty()) {
        return Err(OverrideError::NotAKeyPath(key));
    }
    let (last, walk) = path.split_last().ok_or(OverrideError::EmptyKey)?;
    let mut here = TableOrArray::Table(table);
    let mut walked = String::new();
    for seg in walk {
        if !walked.is_empty() {
            walked.push('.');
        }
        walked.push_str(seg);
        here = match here {
            TableOrArray::Table(t) => {
                let next = t
                    .entry(seg.to_string())
                    .or_insert_with(|| toml::Value::Table(toml::Table::new()));
                TableOrArray::from_value(next, &walked)?
            }
            TableOrArray::Array(a) => TableOrArray::from_value(entry(a, seg, &walked)?, &walked)?,
        };
    }
    match here {
        TableOrArray::Table(t) => {
            t.insert(last.to_string(), value);
        }
        TableOrArray::Array(a) => *entry(a, last, &key)? = value,
    }
    Ok(())
}

/// The entry of `a` at index `segment` (the path `at` names it in errors).
fn entry<'a>(
    a: &'a mut [toml::Value],
    segment: &str,
    at: &str,
) -> Result<&'a mut toml::Value, OverrideError> {
    let len = a.len();
    let index: usize = segment.parse().map_err(|_| OverrideError::NotAnIndex {
        at: at.to_string(),
        segment: segment.to_string(),
    })?;
    a.get_mut(index).ok_or_else(|| OverrideError::PastTheEnd {
        at: at.to_string(),
        index,
        len,
    })
}

enum TableOrArray<'a> {
    Table(&'a mut toml::Table),
    Array(&'a mut Vec<toml::Value>),
}

impl<'a> TableOrArray<'a> {
    fn from_value(v: &'a mut toml::Value, at: &str) -> Result<Self, OverrideError> {
        match v {
            toml::Value::Table(t) => Ok(TableOrArray::Table(t)),
            toml::Value::Array(a) => Ok(TableOrArray::Array(a)),
            other => Err(OverrideError::NotATable {
                at: at.to_string(),
                kind: other.type_str(),
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(s: &str) -> toml::Table {
        s.parse().unwrap_or_default()
    }

    #[test]
    fn bare_keys_go_to_the_planner_and_paths_walk_tables_and_arrays() {
        let set = |t: &mut toml::Table, k: &str, v: f64| {
            set_key(t, k, toml::Value::Float(v)).map_err(|e| e.to_string())
        };
        let mut t = table("[planner]\nstrategy = \"amp\"\n[[sources]]\nx_m = 1.0\n");
        assert!(set(&mut t, "beta_deg", 30.0).is_ok());
        assert!(set(&mut t, "sources.0.x_m", 5.0).is_ok());
        assert!(set(&mut t, "plume.growth_rate_m2ps", 0.01).is_ok());
        assert_eq!(t["planner"]["beta_deg"].as_float(), Some(30.0));
        assert_eq!(t["sources"][0]["x_m"].as_float(), Some(5.0));
        assert_eq!(t["plume"]["growth_rate_m2ps"].as_float(), Some(0.01));
        let cases = [
            (
                "sources.3.x_m",
                "'sources.3': index 3 is past the end: the array has 1 entry, index 0",
            ),
            (
                "sources.a.x_m",
                "'sources.a': 'a' is not an index of an array",
            ),
            (
                "planner.strategy.x",
                "'planner.strategy' is a string, not a table",
            ),
            ("a..b", "'a..b' is not a key path"),
        ];
        for (key, want) in cases {
            let mut t = t.clone();
            assert_eq!(set(&mut t, key, 1.0), Err(want.to_string()), "{key}");
        }
        // A scenario with one named planner: bare keys go there; with two they are ambiguous.
        let mut named = table("[planners.tracer]\nkind = \"amp\"\n");
        assert!(set(&mut named, "beta_deg", 25.0).is_ok());
        assert_eq!(
            named["planners"]["tracer"]["beta_deg"].as_float(),
            Some(25.0)
        );
        let mut two = table("[planners.a]\nkind = \"amp\"\n[planners.b]\nkind = \"amp\"\n");
        assert_eq!(
            set(&mut two, "beta_deg", 25.0),
            Err(
                "the scenario has several planners (planners.a, planners.b): name one with a \
                 dotted key (planners.NAME.KEY)"
                    .to_string()
            )
        );
        assert!(set(&mut two, "planners.b.beta_deg", 25.0).is_ok());
        assert_eq!(
            set(&mut table(""), "beta_deg", 1.0),
            Err("the scenario has no planner table".to_string())
        );
    }
}
