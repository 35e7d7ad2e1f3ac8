//! `runs.csv`: one row per finished run, appended as runs finish, sorted when the campaign ends.
//!
//! Each row is written with a single `write` of a complete line to a file opened for appending,
//! so a process killed at any moment leaves every finished run on disk and at most one partial
//! last line, which the next start cuts off (that run is simply run again).

use crate::error::CampaignError;
use crate::spec::{Campaign, RunKey};
use plumetrace_mission::{Outcome, Summary};
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

/// One run's keys and results. Missing numbers (no declaration, no detection) are empty fields.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct RunRow {
    /// Scenario label.
    pub scenario: String,
    /// Configuration name.
    pub config: String,
    /// Sweep point (`key=value;...`, empty without a sweep).
    pub point: String,
    /// Seed index within the group.
    pub seed_index: u64,
    /// Run seed (the same for every group at this seed index).
    pub seed: u64,
    /// Outcome (`declared`, `no_declaration`, `timed_out`, ..., or `error`).
    pub outcome: RunOutcome,
    /// Single source: declared (within the success radius, if the campaign sets one). Several
    /// sources: every source located (`sources_located == sources`).
    pub success: bool,
    /// Declared at all.
    pub declared: bool,
    /// Number of declarations (several on multi-source missions).
    pub declarations: u32,
    /// Number of true sources.
    pub sources: u32,
    /// Sources with a declaration within the success radius (the mission's 50 m without one).
    pub sources_located: u32,
    /// First declared position, m.
    pub declared_x: Option<f64>,
    /// First declared position, m.
    pub declared_y: Option<f64>,
    /// Nearest true source, m.
    pub source_x: Option<f64>,
    /// Nearest true source, m.
    pub source_y: Option<f64>,
    /// Declaration error, m.
    pub error_m: Option<f64>,
    /// Along-flow error (positive downflow), m.
    pub error_along_m: Option<f64>,
    /// Crossflow error (positive to the right looking downflow), m.
    pub error_cross_m: Option<f64>,
    /// Time of the first detection, s.
    pub first_detection_s: Option<f64>,
    /// Time of the first declaration, s.
    pub declaration_s: Option<f64>,
    /// Distance over ground, m.
    pub path_length_m: Option<f64>,
    /// Distance over ground from the first detection to the first declaration, m.
    pub trace_length_m: Option<f64>,
    /// Straight line from the first detection to the source, m.
    pub detection_to_source_m: Option<f64>,
    /// `trace_length_m / detection_to_source_m`.
    pub path_ratio: Option<f64>,
    /// Mission time, s.
    pub sim_time_s: Option<f64>,
    /// Distance from each true source to its nearest declaration, m, `;`-separated in the
    /// scenario's source order (empty entries for sources without one).
    pub source_errors_m: String,
    /// The longest any vehicle spent in one behaviour without a detection, s.
    pub longest_quiet_s: Option<f64>,
    /// The farthest any vehicle went outside the op-area (true position), m.
    pub max_outside_m: Option<f64>,
    /// Team (two or more planners): when the formation first held its ranges within 20 %, s.
    pub team_converged_s: Option<f64>,
    /// Team: median absolute range error after convergence, m.
    pub team_range_error_median_m: Option<f64>,
    /// Team: 90th percentile of the absolute range error after convergence, m.
    pub team_range_error_p90_m: Option<f64>,
    /// Team: the range set-point, m.
    pub team_range_setpoint_m: Option<f64>,
    /// Team: median cross-flow distance of the centroid from the plume's centre line, m.
    pub team_centroid_cross_median_m: Option<f64>,
    /// Team: path to the first declaration over the straight line from start to source.
    pub team_distance_overhead: Option<f64>,
    /// Team: largest cross-flow scale reported.
    pub team_scale_max: Option<f64>,
    /// Team: last cross-flow scale reported.
    pub team_scale_final: Option<f64>,
    /// Team: acoustic messages lost (per recipient).
    pub team_acoustic_lost: Option<u64>,
    /// Team: acoustic messages delivered.
    pub team_acoustic_delivered: Option<u64>,
    /// Team: commands refused for a non-finite number.
    pub team_non_finite_commands: Option<u64>,
    /// Drawn site (family scenarios; empty otherwise): flow direction, deg.
    pub site_flow_toward_deg: Option<f64>,
    /// Drawn site: flow speed, m/s.
    pub site_flow_speed_mps: Option<f64>,
    /// Drawn site: tidal swing of the flow direction, deg.
    pub site_tidal_swing_deg: Option<f64>,
    /// Drawn site: op-area shape.
    pub site_shape: String,
    /// Drawn site: flow direction from the op-area's main axis, 0-90 deg.
    pub site_flow_to_axis_deg: Option<f64>,
    /// Drawn site: op-area extent along its axis, m.
    pub site_length_m: Option<f64>,
    /// Drawn site: op-area extent across its axis, m.
    pub site_width_m: Option<f64>,
    /// Drawn site: the source's distance from the nearest op-area edge, m.
    pub site_source_edge_m: Option<f64>,
    /// Drawn site: source release rate.
    pub site_mass_rate_per_s: Option<f64>,
    /// Drawn site: where the vehicle started.
    pub site_start: String,
    /// Drawn site: navigation fix interval, s.
    pub site_fix_interval_s: Option<f64>,
    /// Drawn site: navigation fix error, m.
    pub site_fix_sigma_m: Option<f64>,
    /// Drawn site: the flow sensor had a fault window.
    pub site_flow_fault: Option<bool>,
    /// Why a run failed (outcome `error`), else empty.
    pub message: String,
}

impl RunRow {
    /// The row of a finished mission.
    pub fn from_summary(c: &Campaign, key: &RunKey, s: &Summary) -> Self {
        let declared = s.declared;
        let radius = c.located_radius_m();
        let located = s
            .sources
            .iter()
            .filter(|src| src.nearest_error_m.is_some_and(|e| e <= radius))
            .count();
        let first = s.first_declaration.as_ref();
        let success = if s.sources.len() > 1 {
            located == s.sources.len()
        } else {
            declared
                && c.success_radius_m()
                    .is_none_or(|r| first.is_some_and(|d| d.error_m <= r))
        };
        let ratio = s
            .trace_length_m
            .zip(s.detection_to_source_m)
            .filter(|(_, d)| *d > 0.0)
            .map(|(t, d)| t / d);
        RunRow {
            outcome: RunOutcome::Mission(s.outcome),
            success,
            declared,
            declarations: u32::try_from(s.declarations.len()).unwrap_or(u32::MAX),
            sources: u32::try_from(s.sources.len()).unwrap_or(u32::MAX),
            sources_located: u32::try_from(located).unwrap_or(u32::MAX),
            declared_x: first.map(|d| d.x_m),
            declared_y: first.map(|d| d.y_m),
            source_x: first
                .map(|d| d.source_x_m)
                .or_else(|| s.sources.first().map(|src| src.x_m)),
            source_y: first
                .map(|d| d.source_y_m)
                .or_else(|| s.sources.first().map(|src| src.y_m)),
            error_m: first.map(|d| d.error_m),
            error_along_m: first.map(|d| d.error_along_m),
            error_cross_m: first.map(|d| d.error_cross_m),
            first_detection_s: s.first_detection_s,
            declaration_s: first.map(|d| d.t_s),
            path_length_m: Some(s.path_length_m).filter(|v| v.is_finite()),
            trace_length_m: s.trace_length_m,
            detection_to_source_m: s.detection_to_source_m,
            path_ratio: ratio,
            sim_time_s: Some(s.sim_time_s),
            longest_quiet_s: s.longest_quiet_s,
            max_outside_m: Some(s.max_outside_m),
            source_errors_m: s
                .sources
                .iter()
                .map(|src| {
                    src.nearest_error_m
                        .map_or(String::new(), |e| format!("{e:.3}"))
                })
                .collect::<Vec<_>>()
                .join(";"),
            team_converged_s: s.team.as_ref().and_then(|t| t.converged_s),
            team_range_error_median_m: s.team.as_ref().and_then(|t| t.range_error_median_m),
            team_range_error_p90_m: s.team.as_ref().and_then(|t| t.range_error_p90_m),
            team_range_setpoint_m: s.team.as_ref().and_then(|t| t.range_setpoint_m),
            team_centroid_cross_median_m: s.team.as_ref().and_then(|t| t.centroid_cross_median_m),
            team_distance_overhead: s.team.as_ref().and_then(|t| t.distance_overhead),
            team_scale_max: s.team.as_ref().and_then(|t| t.scale_max),
            team_scale_final: s.team.as_ref().and_then(|t| t.scale_final),
            team_acoustic_lost: s.team.as_ref().map(|t| t.acoustic_lost),
            team_acoustic_delivered: s.team.as_ref().map(|t| t.acoustic_delivered),
            team_non_finite_commands: s.team.as_ref().map(|t| t.non_finite_commands),
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
        let row = RunRow {
            scenario: c.scenarios[key.scenario].label.clone(),
            config: c.configs[key.config].name.clone(),
            point: c.points[key.point].label(),
            seed_index: key.seed_index,
            seed: c.run_seed(key),
            ..RunRow::default()
        };
        match c.site(key) {
            Some(site) => row.with_site(&site),
            None => row,
        }
    }

    /// The row with a drawn site's columns filled in (rounded as the site file writes them).
    fn with_site(self, s: &plumetrace_scenario::Site) -> Self {
        let r = |v: f64, d: i32| {
            let k = 10f64.powi(d);
            Some((v * k).round() / k)
        };
        RunRow {
            site_flow_toward_deg: r(s.flow_toward_deg, 2),
            site_flow_speed_mps: r(s.flow_speed_mps, 4),
            site_tidal_swing_deg: r(s.tidal_swing_deg, 2),
            site_shape: plumetrace_core::variant_name(&s.shape)
                .unwrap_or("?")
                .into(),
            site_flow_to_axis_deg: r(s.flow_to_axis_deg, 2),
            site_length_m: r(s.length_m, 1),
            site_width_m: r(s.width_m, 1),
            site_source_edge_m: r(s.source_edge_m, 1),
            site_mass_rate_per_s: s.mass_rate_per_s.and_then(|q| r(q, 4)),
            site_start: plumetrace_core::variant_name(&s.start)
                .unwrap_or("?")
                .into(),
            site_fix_interval_s: s.fix_interval_s.and_then(|q| r(q, 2)),
            site_fix_sigma_m: s.fix_sigma_m.and_then(|q| r(q, 3)),
            site_flow_fault: Some(s.flow_fault_s.is_some()),
            ..self
        }
    }

    /// The row as one CSV line (with its newline).
    pub fn to_line(&self) -> Result<Vec<u8>, String> {
        let mut w = csv::WriterBuilder::new()
            .has_headers(false)
            .from_writer(Vec::new());
        w.serialize(self).map_err(|e| e.to_string())?;
        w.into_inner().map_err(|e| e.to_string())
    }
}

/// The header line of `runs.csv` (without its newline).
pub fn header() -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let probe = RunRow::default();
    let _ = w.serialize(&probe);
    let bytes = w.into_inner().unwrap_or_default();
    String::from_utf8_lossy(&bytes)
        .lines()
        .next()
        .unwrap_or_default()
        .to_string()
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
            message: e,
        })?;
        out.push_str(&String::from_utf8_lossy(&line));
    }
    Ok(out)
}
