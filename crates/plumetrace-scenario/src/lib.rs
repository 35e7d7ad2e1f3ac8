//! Scenario files and built-in presets.
//!
//! Configuration is read in two phases. [`config`] mirrors the TOML file with serde
//! (`deny_unknown_fields`, units in key names) and only checks types; [`build`](mod@build)
//! turns it into models and checks values, naming the key path of anything wrong. Built-in
//! scenarios live in one registry, [`presets::PRESETS`], from which `plumetrace presets` and the
//! docs are made.

pub mod build;
pub mod config;
pub mod error;
pub mod family;
pub mod family_regions;
pub mod family_team;
mod geographic;
pub mod limits;
pub mod locate;
pub mod overrides;
pub mod presets;

pub use build::{
    BuiltScenario, DEFAULT_SUCCESS_RADIUS_M, MissionSpec, OutputSpec, PlannerRef, VehicleSetup,
    Warning, build,
};
pub use config::ScenarioConfig;
pub use error::ScenarioError;
pub use family::{Family, Site, builds, is_family_path};
pub use overrides::{OverrideError, set_key};
pub use presets::{PRESETS, Preset, find_preset};

use std::path::Path;

/// Where a scenario came from, for error messages and relative file paths.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Origin {
    /// A file on disk.
    File(std::path::PathBuf),
    /// A built-in preset, by name.
    Preset(String),
}

impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Origin::File(p) => write!(f, "{}", p.display()),
            Origin::Preset(n) => write!(f, "preset '{n}'"),
        }
    }
}

/// Parses scenario TOML text; errors name the key path and the line.
pub fn parse(text: &str, origin: &Origin) -> Result<ScenarioConfig, ScenarioError> {
    // No key takes a date or a time; say so with the key rather than as a type error.
    if let Ok(table) = text.parse::<toml::Table>()
        && let Some((key, value)) = first_datetime(&toml::Value::Table(table), "")
    {
        let message = if key == "flow.netcdf.start" {
            format!(
                "is a TOML date/time ({value}); write the date as a string: start = \"{value}\""
            )
        } else {
            format!("is a date/time ({value}); no scenario key takes one")
        };
        return Err(ScenarioError::Parse {
            origin: origin.to_string(),
            line: locate::line_of(text, &key),
            path: key,
            message,
        });
    }
    // Positions in latitude and longitude become metres first (a scenario without them is read
    // straight from the text, as always).
    let parse_error = match text.parse::<toml::Table>() {
        Ok(mut table) if geographic::any(&table) => {
            geographic::to_local(&mut table).map_err(|(path, message)| {
                ScenarioError::Parse {
                    origin: origin.to_string(),
                    line: None,
                    path,
                    message,
                }
                .located(text)
            })?;
            return from_local_table(&table, origin).map_err(|e| e.located(text));
        }
        Ok(_) => None,
        Err(e) => Some(e),
    };
    let de = toml::Deserializer::parse(text).map_err(|e| ScenarioError::Parse {
        origin: origin.to_string(),
        line: None,
        path: String::new(),
        message: e.to_string(),
    })?;
    let cfg = deserialize(de, origin, Report::Whole).map_err(|e| e.located(text))?;
    // A whole number a count takes but TOML's integers cannot hold (above 9223372036854775807)
    // cannot be checked against its bound later (the check reads the scenario back as TOML):
    // the parser's report shows where it is. Seeds, written back as strings, are not affected.
    let unbounded = parse_error.filter(|_| toml::Value::try_from(&cfg).is_err());
    match unbounded {
        None => Ok(cfg),
        Some(e) => Err(ScenarioError::Parse {
            origin: origin.to_string(),
            line: None,
            path: String::new(),
            message: format!(
                "{}\n(TOML's whole numbers go up to 9223372036854775807)",
                e.to_string().trim_end()
            ),
        }),
    }
}

/// Reads a scenario from an already parsed TOML table (e.g. a scenario with overrides applied);
/// errors name the key path.
pub fn from_table(
    mut table: toml::Table,
    origin: &Origin,
) -> Result<ScenarioConfig, ScenarioError> {
    if geographic::any(&table) {
        geographic::to_local(&mut table).map_err(|(path, message)| ScenarioError::Parse {
            origin: origin.to_string(),
            line: None,
            path,
            message,
        })?;
    }
    from_local_table(&table, origin)
}

/// Reads a table whose positions are already in metres. The table is written out as TOML text
/// and read back by the one deserializer a scenario file is read with: the serde code of every
/// section is then generated once (for the text) instead of twice (for the text and for a
/// `toml::Value`), which was the largest part of this crate's build. Writing and reading back
/// keeps every value as it was (TOML's floats round-trip exactly).
fn from_local_table(table: &toml::Table, origin: &Origin) -> Result<ScenarioConfig, ScenarioError> {
    let invalid = |message: String| ScenarioError::Parse {
        origin: origin.to_string(),
        line: None,
        path: String::new(),
        message,
    };
    let text = toml::to_string(table).map_err(|e| invalid(e.to_string()))?;
    let de = toml::Deserializer::parse(&text).map_err(|e| invalid(e.message().to_string()))?;
    deserialize(de, origin, Report::Message)
}

/// What an error without a key path says: the parser's whole report (which quotes the line,
/// for text the user wrote) or the message alone (for text written from a table, whose lines
/// the user never saw).
#[derive(Clone, Copy)]
enum Report {
    Whole,
    Message,
}

/// serde's path as a key path, a key that is not a bare TOML key quoted (`planners."a b"`,
/// `planners.""`), as [`locate::line_of`] reads it.
fn key_path(path: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    let mut out = String::new();
    for seg in path.iter() {
        let key = match seg {
            Segment::Seq { index } => {
                out.push_str(&format!("[{index}]"));
                continue;
            }
            Segment::Map { key } => plumetrace_core::params::quoted_key(key),
            Segment::Enum { variant } => plumetrace_core::params::quoted_key(variant),
            Segment::Unknown => "?".to_string(),
        };
        if !out.is_empty() {
            out.push('.');
        }
        out.push_str(&key);
    }
    if out.is_empty() { ".".to_string() } else { out }
}

/// Deserializes the scenario, turning serde's error into one that names the key path (and the
/// nearest known key or name, for an unknown one).
fn deserialize(
    de: toml::Deserializer<'_>,
    origin: &Origin,
    report: Report,
) -> Result<ScenarioConfig, ScenarioError> {
    serde_path_to_error::deserialize(de).map_err(|e| {
        let path = key_path(e.path());
        let inner = e.into_inner();
        // With a key path, the message alone (the line is added from the path); without one,
        // the parser's whole report, which shows where.
        let (path, message) = if path == "." {
            let message = match report {
                Report::Whole => inner.to_string(),
                // As the message of a `toml::Value`'s error read.
                Report::Message => format!("{}\n", inner.message()),
            };
            (String::new(), plumetrace_core::plain_types(&message))
        } else {
            (path, locate::suggest(inner.message()))
        };
        ScenarioError::Parse {
            origin: origin.to_string(),
            line: None,
            path,
            message,
        }
    })
}

/// Reads and parses a scenario file.
pub fn load_file(path: &Path) -> Result<ScenarioConfig, ScenarioError> {
    let origin = Origin::File(path.to_path_buf());
    let text = plumetrace_env::input::read_text(path, plumetrace_env::input::MAX_TEXT_BYTES)
        .map_err(|e| ScenarioError::Io {
            origin: origin.to_string(),
            message: e.to_string(),
        })?;
    parse(&text, &origin)
}

/// The built-in preset `name`, or an error naming the nearest one and every one.
pub fn preset(name: &str) -> Result<&'static Preset, ScenarioError> {
    find_preset(name).ok_or_else(|| {
        let names: Vec<&str> = PRESETS.iter().map(|p| p.name).collect();
        ScenarioError::UnknownPreset {
            name: name.to_string(),
            near: plumetrace_core::closest(name, &names).map(str::to_string),
            known: names.join(", "),
        }
    })
}

/// Parses a built-in preset by name.
pub fn load_preset(name: &str) -> Result<ScenarioConfig, ScenarioError> {
    parse(preset(name)?.toml, &Origin::Preset(name.to_string()))
}

/// The first date/time value in a TOML tree, with its key path.
pub fn first_datetime(v: &toml::Value, path: &str) -> Option<(String, String)> {
    let join = |k: &str| {
        // Keys that are not plain words are written quoted, as in TOML (`output.""`).
        let k = if !k.is_empty()
            && k.chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        {
            k.to_string()
        } else {
            format!("{k:?}")
        };
        if path.is_empty() {
            k
        } else {
            format!("{path}.{k}")
        }
    };
    match v {
        toml::Value::Datetime(d) => Some((path.to_string(), d.to_string())),
        toml::Value::Table(t) => t.iter().find_map(|(k, x)| first_datetime(x, &join(k))),
        toml::Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| first_datetime(x, &format!("{path}[{i}]"))),
        _ => None,
    }
}
