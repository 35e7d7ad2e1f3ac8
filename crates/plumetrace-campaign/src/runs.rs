//! `runs.csv`: one row per finished run, appended as runs finish, sorted when the campaign ends.
//!
//! Each row is written with a single `write` of a complete line to a file opened for appending,
//! so a process killed at any moment leaves every finished run on disk and at most one partial
//! last line, which the next start cuts off (that run is simply run again).

use crate::error::CampaignError;
use crate::spec::{Campaign, RunKey};
use plumetrace_mission::metrics::columns_of;
use plumetrace_mission::{Column, Outcome, RunMetrics, Summary};
use plumetrace_scenario::Site;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

/// The name of the results file in a campaign directory.
pub const RUNS_FILE: &str = "runs.csv";

/// A run that could not run (a diverging flow, an internal error): outcome `error`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RunFailed {
    /// The run failed; its message says why.
    Error,
}

/// A run's outcome: the mission's, or `error` when it could not run. Written by serde as the
/// mission outcome's name or `error`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(untagged)]
pub enum RunOutcome {
    /// The mission ran to this outcome.
    Mission(Outcome),
    /// The run failed.
    Failed(RunFailed),
}

impl RunOutcome {
    /// The outcome of a failed run.
    pub const ERROR: RunOutcome = RunOutcome::Failed(RunFailed::Error);

    /// Every outcome, in table order: the mission's, then `error`.
    pub fn all() -> Vec<RunOutcome> {
        Outcome::ALL
            .into_iter()
            .map(RunOutcome::Mission)
            .chain([RunOutcome::ERROR])
            .collect()
    }

    /// The name in files (serde's).
    pub fn name(self) -> &'static str {
        plumetrace_core::variant_name(&self).unwrap_or("?")
    }
}

impl Default for RunOutcome {
    fn default() -> Self {
        RunOutcome::ERROR
    }
}

impl plumetrace_mission::Leaf for RunOutcome {
    const KIND: plumetrace_mission::ColumnKind = plumetrace_mission::ColumnKind::Text;
    fn value(&self) -> plumetrace_mission::Value<'_> {
        plumetrace_mission::Value::Text(self.name())
    }
}

plumetrace_mission::columns! {
    /// One run's keys and results: the columns of `runs.csv` and `runs.parquet`, in order (the
    /// mission's metrics and the drawn site take the place of their fields). Missing numbers
    /// (no declaration, no detection) are empty fields.
    pub struct RunRow {
        /// Scenario label.
        scenario: String;
        /// Configuration name.
        config: String;
        /// Sweep point (`key=value;...`, empty without a sweep).
        point: String;
        /// Seed index within the group.
        seed_index: u64;
        /// Run seed (the same for every group at this seed index).
        seed: u64;
        /// Outcome (`declared`, `no_declaration`, `timed_out`, ..., or `error`).
        outcome: RunOutcome;
        /// The mission's metrics (empty for a run that could not run).
        metrics: RunMetrics;
        /// The drawn site (family scenarios; empty otherwise).
        site: SiteColumns;
        /// Why a run failed (outcome `error`), else empty.
        message: String;
    }
}

plumetrace_mission::columns! {
    /// The site a run of a family flew, rounded as the site file writes it.
    pub struct SiteColumns from (s: &Site) {
        /// Drawn site (family scenarios; empty otherwise): flow direction, deg.
        site_flow_toward_deg: Option<f64> ["deg"] = round(s.flow_toward_deg, 2);
        /// Drawn site: flow speed, m/s.
        site_flow_speed_mps: Option<f64> ["m/s"] = round(s.flow_speed_mps, 4);
        /// Drawn site: tidal swing of the flow direction, deg.
        site_tidal_swing_deg: Option<f64> ["deg"] = round(s.tidal_swing_deg, 2);
        /// Drawn site: op-area shape.
        site_shape: String = name(&s.shape);
        /// Drawn site: flow direction from the op-area's main axis, 0-90 deg.
        site_flow_to_axis_deg: Option<f64> ["deg"] = round(s.flow_to_axis_deg, 2);
        /// Drawn site: op-area extent along its axis, m.
        site_length_m: Option<f64> ["m"] = round(s.length_m, 1);
        /// Drawn site: op-area extent across its axis, m.
        site_width_m: Option<f64> ["m"] = round(s.width_m, 1);
        /// Drawn site: the source's distance from the nearest op-area edge, m.
        site_source_edge_m: Option<f64> ["m"] = round(s.source_edge_m, 1);
        /// Drawn site: source release rate.
        site_mass_rate_per_s: Option<f64> = s.mass_rate_per_s.and_then(|q| round(q, 4));
        /// Drawn site: where the vehicle started.
        site_start: String = name(&s.start);
        /// Drawn site: navigation fix interval, s.
        site_fix_interval_s: Option<f64> ["s"] = s.fix_interval_s.and_then(|q| round(q, 2));
        /// Drawn site: navigation fix error, m.
        site_fix_sigma_m: Option<f64> ["m"] = s.fix_sigma_m.and_then(|q| round(q, 3));
        /// Drawn site: the flow sensor had a fault window.
        site_flow_fault: Option<bool> = Some(s.flow_fault_s.is_some());
    }
}

/// `v` rounded to `digits` decimals.
fn round(v: f64, digits: i32) -> Option<f64> {
    let k = 10f64.powi(digits);
    Some((v * k).round() / k)
}

/// A value's name in files (serde's).
fn name<T: Serialize>(v: &T) -> String {
    plumetrace_core::variant_name(v).unwrap_or("?").into()
}

/// Every column of `runs.csv`, in order: the keys, the outcome, the mission's metrics
/// ([`RunMetrics`]), the drawn site and the failure message.
pub fn columns() -> Vec<Column> {
    columns_of::<RunRow>()
}

impl RunRow {
    /// The row of a finished mission.
    pub fn from_summary(c: &Campaign, key: &RunKey, s: &Summary) -> Self {
        RunRow {
            outcome: RunOutcome::Mission(s.outcome),
            metrics: RunMetrics::new(s, &c.metric_context()),
            ..RunRow::empty(c, key)
        }
    }

    /// The row of a run that could not run.
    pub fn failed(c: &Campaign, key: &RunKey, message: String) -> Self {
        RunRow {
            outcome: RunOutcome::ERROR,
            message,
            ..RunRow::empty(c, key)
        }
    }

    fn empty(c: &Campaign, key: &RunKey) -> Self {
        RunRow {
            scenario: c.scenarios[key.scenario].label.clone(),
            config: c.configs[key.config].name.clone(),
            point: c.points[key.point].label(),
            seed_index: key.seed_index,
            seed: c.run_seed(key),
            site: c
                .site(key)
                .map_or_else(SiteColumns::default, |s| SiteColumns::new(&s)),
            ..RunRow::default()
        }
    }

    /// The row as one CSV line (with its newline).
    pub fn to_line(&self) -> Result<Vec<u8>, csv::Error> {
        let mut w = csv::WriterBuilder::new()
            .has_headers(false)
            .from_writer(Vec::new());
        w.serialize(self)?;
        w.into_inner().map_err(|e| e.into_error().into())
    }
}

/// The header line of `runs.csv` (without its newline): the column names.
pub fn header() -> String {
    columns()
        .iter()
        .map(|c| c.name)
        .collect::<Vec<_>>()
        .join(",")
}

/// What was found in an existing results file.
#[derive(Debug, Default)]
pub struct Existing {
    /// Complete rows.
    pub rows: Vec<RunRow>,
    /// A partial last line was cut off (a run killed while its row was being written).
    pub cut_partial_line: bool,
}

/// Parses the complete lines of a results file; `text` must start with the header.
pub fn parse_rows(path: &Path, text: &str) -> Result<Vec<RunRow>, CampaignError> {
    let want = header();
    let first = text.lines().next().unwrap_or_default();
    if first != want {
        let message = if first.starts_with("scenario,config,point,") {
            format!(
                "its columns are not this version's (written by another plumetrace version?); \
                 the file is left as it is: run the campaign into a new directory. Found '{first}', \
                 expected '{want}'"
            )
        } else {
            format!("unexpected header (is it a plumetrace runs file?): '{first}'")
        };
        return Err(CampaignError::Results {
            path: path.display().to_string(),
            line: Some(1),
            message,
        });
    }
    let mut rd = csv::ReaderBuilder::new()
        .has_headers(true)
        .from_reader(text.as_bytes());
    let mut rows = Vec::new();
    for r in rd.deserialize::<RunRow>() {
        let row = r.map_err(|e| CampaignError::Results {
            path: path.display().to_string(),
            line: e.position().map(|p| p.line()),
            message: e.to_string(),
        })?;
        rows.push(row);
    }
    Ok(rows)
}

/// The complete lines of a results file (up to and including the last newline).
fn complete_lines(text: &str) -> &str {
    text.rfind('\n').map_or("", |i| &text[..=i])
}

/// Reads a results file, ignoring a partial last line (reported in [`Existing`]).
pub fn read_rows(path: &Path) -> Result<Existing, CampaignError> {
    let text = std::fs::read_to_string(path).map_err(|e| CampaignError::io(path, e))?;
    let complete = complete_lines(&text);
    if complete.is_empty() {
        return Err(CampaignError::Results {
            path: path.display().to_string(),
            line: Some(1),
            message: "no header line".into(),
        });
    }
    Ok(Existing {
        rows: parse_rows(path, complete)?,
        cut_partial_line: complete.len() < text.len(),
    })
}

/// Appends rows to `runs.csv`, one `write` per row.
#[derive(Debug)]
pub struct Appender {
    file: std::fs::File,
    path: PathBuf,
}

impl Appender {
    /// Opens (or creates) `path` for appending: checks the header, cuts off a partial last line,
    /// and returns the rows already there.
    pub fn open(path: &Path) -> Result<(Appender, Existing), CampaignError> {
        let io = |e: std::io::Error| CampaignError::io(path, e);
        let mut file = std::fs::OpenOptions::new()
            .read(true)
            .append(true)
            .create(true)
            .open(path)
            .map_err(io)?;
        let mut text = String::new();
        file.read_to_string(&mut text).map_err(io)?;
        let complete = complete_lines(&text);
        // Check what is there before changing anything: a damaged file is left as it is.
        let rows = if complete.is_empty() {
            Vec::new()
        } else {
            parse_rows(path, complete)?
        };
        let cut_partial_line = complete.len() < text.len();
        if cut_partial_line {
            file.set_len(complete.len() as u64).map_err(io)?;
            file.seek(std::io::SeekFrom::End(0)).map_err(io)?;
        }
        if complete.is_empty() {
            // A new file, or not even a full header: nothing was recorded yet.
            file.write_all(format!("{}\n", header()).as_bytes())
                .map_err(io)?;
        }
        let existing = Existing {
            rows,
            cut_partial_line,
        };
        Ok((
            Appender {
                file,
                path: path.to_path_buf(),
            },
            existing,
        ))
    }

    /// Appends one row as one write and hands it to the operating system (which keeps it even
    /// if this process is killed).
    pub fn append(&mut self, row: &RunRow) -> Result<(), CampaignError> {
        let line = row
            .to_line()
            .map_err(|e| CampaignError::io(&self.path, e))?;
        self.file
            .write_all(&line)
            .and_then(|()| self.file.flush())
            .map_err(|e| CampaignError::io(&self.path, e))
    }
}

/// The canonical position of a row in its campaign, or an error naming the row.
pub fn row_key(c: &Campaign, row: &RunRow, path: &Path) -> Result<RunKey, CampaignError> {
    let not_ours = |what: String| CampaignError::Results {
        path: path.display().to_string(),
        line: None,
        message: format!("a row of another campaign: {what}; use a new output directory"),
    };
    let scenario = c
        .scenarios
        .iter()
        .position(|s| s.label == row.scenario)
        .ok_or_else(|| not_ours(format!("unknown scenario '{}'", row.scenario)))?;
    let config = c
        .configs
        .iter()
        .position(|s| s.name == row.config)
        .ok_or_else(|| not_ours(format!("unknown config '{}'", row.config)))?;
    let point = c
        .points
        .iter()
        .position(|p| p.label() == row.point)
        .ok_or_else(|| not_ours(format!("unknown sweep point '{}'", row.point)))?;
    let key = RunKey {
        scenario,
        config,
        point,
        seed_index: row.seed_index,
    };
    if c.run_seed(&key) != row.seed {
        return Err(not_ours(format!(
            "seed {} at seed index {} (expected {})",
            row.seed,
            row.seed_index,
            c.run_seed(&key)
        )));
    }
    Ok(key)
}

/// Rows in canonical order, one per run. Exact duplicates (the same run recorded twice) collapse;
/// two different results for one run are an error.
pub fn sorted_unique(
    c: &Campaign,
    rows: Vec<RunRow>,
    path: &Path,
) -> Result<Vec<(RunKey, RunRow)>, CampaignError> {
    let mut by_key: BTreeMap<RunKey, RunRow> = BTreeMap::new();
    for row in rows {
        let key = row_key(c, &row, path)?;
        if let Some(old) = by_key.get(&key) {
            if *old != row {
                return Err(CampaignError::Results {
                    path: path.display().to_string(),
                    line: None,
                    message: format!(
                        "two different results for {} seed index {}",
                        c.group_name(key.scenario, key.config, key.point),
                        key.seed_index
                    ),
                });
            }
            continue;
        }
        by_key.insert(key, row);
    }
    Ok(by_key.into_iter().collect())
}

/// The text of a sorted results file.
pub fn rows_text(rows: &[(RunKey, RunRow)]) -> Result<String, CampaignError> {
    let mut out = header();
    out.push('\n');
    for (_, r) in rows {
        let line = r.to_line().map_err(|e| CampaignError::Results {
            path: RUNS_FILE.into(),
            line: None,
            message: e.to_string(),
        })?;
        out.push_str(&String::from_utf8_lossy(&line));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn a_row_is_its_columns_in_order_and_reads_back() {
        let row = RunRow {
            scenario: "demo".into(),
            config: "a,b".into(),
            seed_index: 3,
            seed: u64::MAX,
            outcome: RunOutcome::Mission(Outcome::Declared),
            metrics: RunMetrics {
                success: true,
                declarations: 2,
                error_m: Some(0.1 + 0.2),
                sim_time_s: Some(1e16),
                source_errors_m: "1.000;".into(),
                team_acoustic_lost: Some(7),
                ..RunMetrics::default()
            },
            site: SiteColumns {
                site_shape: "convex".into(),
                site_flow_fault: Some(false),
                ..SiteColumns::default()
            },
            ..RunRow::default()
        };
        let line = String::from_utf8(row.to_line().unwrap()).unwrap();
        let fields: Vec<&str> = line.trim_end().split(',').collect();
        let at = |name: &str| {
            let i = columns().iter().position(|c| c.name == name).unwrap();
            // The quoted config `"a,b"` is two pieces after a naive split.
            fields[if i > 1 { i + 1 } else { i }]
        };
        assert_eq!(fields.len(), columns().len() + 1);
        assert_eq!(at("outcome"), "declared");
        assert_eq!(at("success"), "true");
        assert_eq!(at("error_m"), "0.30000000000000004");
        assert_eq!(at("sim_time_s"), "1e16");
        assert_eq!(at("team_acoustic_lost"), "7");
        assert_eq!(at("team_scale_max"), "");
        assert_eq!(at("site_flow_fault"), "false");
        assert_eq!(at("message"), "");
        let text = format!("{}\n{line}", header());
        let back = parse_rows(Path::new(RUNS_FILE), &text).unwrap();
        assert_eq!(back, vec![row]);
    }
}
