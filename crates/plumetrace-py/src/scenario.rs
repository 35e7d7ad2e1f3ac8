//! Scenarios from Python: a preset name or a file, with overrides given as keyword arguments.
//!
//! Overrides use the campaign `set` keys: a bare name is a key of the scenario's planner
//! (`declaration = "along_flow"`), a dotted path walks the scenario's tables
//! (`"sources.0.mass_rate_per_s"`).

use crate::error::{msg, to_py};
use plumetrace_scenario::{BuiltScenario, Origin};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use std::path::{Path, PathBuf};

/// How to open a scenario again elsewhere (a pickled `Plume`): a preset by name, a scenario
/// file by its text, a family file by its path.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub enum Recipe {
    /// A preset.
    Preset(String),
    /// A scenario file's table, as TOML text, and its path (for messages).
    File(PathBuf, String),
    /// A family file (read again where it is re-created).
    Family(PathBuf),
}

/// Where a scenario comes from: a preset, a scenario file or a family file (a site per seed).
pub enum Source {
    /// A scenario table and where it came from.
    Table(toml::Table, Origin),
    /// A scenario family: each seed draws a site.
    Family(Box<plumetrace_scenario::Family>, PathBuf),
}

impl Source {
    /// Reads `name`: a preset name, a `*.family.toml` file or a scenario file.
    pub fn open(name: &str) -> PyResult<Self> {
        if let Some(p) = plumetrace_scenario::find_preset(name) {
            let table = p
                .toml
                .parse::<toml::Table>()
                .map_err(|e| msg(format!("preset '{name}': {e}")))?;
            return Ok(Source::Table(table, Origin::Preset(name.to_string())));
        }
        let path = Path::new(name);
        if !path.exists() {
            let names: Vec<&str> = plumetrace_scenario::PRESETS
                .iter()
                .map(|p| p.name)
                .collect();
            let hint = plumetrace_core::closest(name, &names)
                .map(|n| format!("; did you mean {n}?"))
                .unwrap_or_default();
            return Err(msg(format!(
                "'{name}' is neither a preset ({}) nor a file{hint}",
                names.join(", ")
            )));
        }
        if plumetrace_scenario::is_family_path(name) {
            let f = plumetrace_scenario::Family::load(path).map_err(to_py)?;
            return Ok(Source::Family(Box::new(f), path.to_path_buf()));
        }
        let text = std::fs::read_to_string(path)
            .map_err(|e| msg(format!("reading {}: {e}", path.display())))?;
        let table = text
            .parse::<toml::Table>()
            .map_err(|e| msg(format!("{}: {e}", path.display())))?;
        Ok(Source::Table(table, Origin::File(path.to_path_buf())))
    }

    /// How to open it again.
    pub fn recipe(&self) -> Recipe {
        match self {
            Source::Table(_, Origin::Preset(name)) => Recipe::Preset(name.clone()),
            Source::Table(t, Origin::File(path)) => Recipe::File(path.clone(), t.to_string()),
            Source::Family(_, path) => Recipe::Family(path.clone()),
        }
    }

    /// Opens a recipe.
    pub fn from_recipe(r: &Recipe) -> PyResult<Self> {
        match r {
            Recipe::Preset(name) => Source::open(name),
            Recipe::File(path, text) => {
                let table = text
                    .parse::<toml::Table>()
                    .map_err(|e| msg(format!("{}: {e}", path.display())))?;
                Ok(Source::Table(table, Origin::File(path.clone())))
            }
            Recipe::Family(path) => Source::open(&path.to_string_lossy()),
        }
    }

    /// The scenario table of a run with `seed` (a family draws its site from it).
    pub fn table(&self, seed: u64) -> (toml::Table, Origin) {
        match self {
            Source::Table(t, o) => (t.clone(), o.clone()),
            Source::Family(f, path) => (f.scenario(seed), Origin::File(path.clone())),
        }
    }

    /// Builds the scenario with `overrides` applied; `seed` overrides the scenario's (a family
    /// needs one: it draws the site).
    pub fn build(
        &self,
        seed: Option<u64>,
        overrides: &[(String, toml::Value)],
    ) -> PyResult<BuiltScenario> {
        let (mut table, origin) = self.table(seed.unwrap_or(0));
        for (k, v) in overrides {
            plumetrace_scenario::set_key(&mut table, k, v.clone())
                .map_err(|m| msg(format!("{origin}: override '{k}': {m}")))?;
        }
        let cfg = plumetrace_scenario::from_table(table, &origin).map_err(to_py)?;
        plumetrace_scenario::build(&cfg, &origin, seed).map_err(to_py)
    }
}

/// Overrides from a Python dict (`set=`) and keyword arguments, in that order.
pub fn overrides(
    set: Option<&Bound<'_, PyDict>>,
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<(String, toml::Value)>> {
    let mut out = Vec::new();
    for d in [set, kwargs].into_iter().flatten() {
        for (k, v) in d.iter() {
            let key: String = k
                .extract()
                .map_err(|_| msg(format!("override key {k} is not a string")))?;
            let value = to_toml(&v, &key)?;
            out.push((key, value));
        }
    }
    Ok(out)
}

/// A Python value as a TOML value (`key` names it in errors).
pub fn to_toml(v: &Bound<'_, PyAny>, key: &str) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        let i: i64 = v
            .extract()
            .map_err(|_| msg(format!("override '{key}': {v} does not fit in 64 bits")))?;
        return Ok(toml::Value::Integer(i));
    }
    if v.is_instance_of::<PyFloat>() {
        let x: f64 = v.extract()?;
        if !x.is_finite() {
            return Err(msg(format!("override '{key}': {x} is not a finite number")));
        }
        return Ok(toml::Value::Float(x));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut a = Vec::new();
        for (i, item) in v.try_iter()?.enumerate() {
            a.push(to_toml(&item?, &format!("{key}[{i}]"))?);
        }
        return Ok(toml::Value::Array(a));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, item) in d.iter() {
            let name: String = k
                .extract()
                .map_err(|_| msg(format!("override '{key}': key {k} is not a string")))?;
            let value = to_toml(&item, &format!("{key}.{name}"))?;
            t.insert(name, value);
        }
        return Ok(toml::Value::Table(t));
    }
    // numpy scalars and anything else that converts to a float.
    if let Ok(x) = v.extract::<f64>() {
        if !x.is_finite() {
            return Err(msg(format!("override '{key}': {x} is not a finite number")));
        }
        return Ok(toml::Value::Float(x));
    }
    Err(msg(format!(
        "override '{key}': a {} is not a scenario value (give a bool, int, float, str, list or dict)",
        v.get_type().name()?
    )))
}

/// A seed from Python: a whole number from 0 to 2^64 - 1, as on the command line.
pub fn seed(v: Option<&Bound<'_, PyAny>>) -> PyResult<Option<u64>> {
    let Some(v) = v else { return Ok(None) };
    if v.is_none() {
        return Ok(None);
    }
    if let Ok(u) = v.extract::<u64>() {
        return Ok(Some(u));
    }
    Err(msg(format!(
        "seed {v} is not a whole number from 0 to 18446744073709551615"
    )))
}
