//! One example track per group (its seed index 0), kept for the trajectory chart.

use crate::spec::{Campaign, RunKey};
use plumetrace_mission::{MissionRun, Outcome, lost_points};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Directory of the example files inside a campaign directory.
pub const EXAMPLES_DIR: &str = "examples";

/// Longest track kept, in points.
const MAX_TRACK_POINTS: usize = 3000;

/// What the chart needs of one run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExampleRun {
    /// Scenario label.
    pub scenario: String,
    /// Configuration name.
    pub config: String,
    /// Sweep point label.
    pub point: String,
    /// Run seed.
    pub seed: u64,
    /// Outcome.
    pub outcome: Outcome,
    /// Declaration error, m.
    pub error_m: Option<f64>,
    /// Op-area corners.
    pub op_area: Vec<[f64; 2]>,
    /// Subregions.
    pub subregions: Vec<Vec<[f64; 2]>>,
    /// True sources.
    pub sources: Vec<[f64; 2]>,
    /// Declared positions.
    pub declared: Vec<[f64; 2]>,
    /// Lost points.
    pub lost_points: Vec<[f64; 2]>,
    /// The lead vehicle's track as it logged it (navigation estimate), thinned: the vehicle of
    /// the first declaration, or the first with a planner.
    pub track: Vec<[f64; 2]>,
    /// The other vehicles with planners (a team's members), true tracks, thinned alike (some
    /// have no position estimate to log).
    #[serde(default)]
    pub others: Vec<Vec<[f64; 2]>>,
}

impl ExampleRun {
    /// Extracts the example from a finished run.
    pub fn from_run(c: &Campaign, key: &RunKey, run: &MissionRun) -> Self {
        let xy = |p: &plumetrace_core::Vec2| [p.x, p.y];
        let lead = run
            .summary
            .first_declaration
            .as_ref()
            .map(|d| d.vehicle)
            .or_else(|| {
                run.vehicles
                    .iter()
                    .position(|v| v.planner.is_some())
                    .map(|k| k as u32)
            })
            .unwrap_or(0);
        let rows: Vec<_> = run
            .trajectory
            .iter()
            .filter(|r| r.vehicle == lead)
            .collect();
        let step = rows.len().div_ceil(MAX_TRACK_POINTS).max(1);
        ExampleRun {
            scenario: c.scenarios[key.scenario].label.clone(),
            config: c.configs[key.config].name.clone(),
            point: c.points[key.point].label(),
            seed: c.run_seed(key),
            outcome: run.outcome,
            error_m: run.summary.first_declaration.as_ref().map(|d| d.error_m),
            op_area: run.op_area.iter().map(xy).collect(),
            subregions: run
                .subregions
                .iter()
                .map(|r| r.iter().map(xy).collect())
                .collect(),
            sources: run.sources.iter().map(|s| [s.x, s.y]).collect(),
            declared: run
                .summary
                .declarations
                .iter()
                .map(|d| [d.x_m, d.y_m])
                .collect(),
            lost_points: lost_points(&run.events)
                .iter()
                .map(|l| xy(&l.now_m()))
                .collect(),
            track: rows
                .iter()
                .step_by(step)
                .filter_map(|r| Some([r.est_x_m?, r.est_y_m?]))
                .collect(),
            others: run
                .vehicles
                .iter()
                .enumerate()
                .filter(|(k, v)| v.planner.is_some() && *k as u32 != lead)
                .map(|(k, _)| {
                    run.trajectory
                        .iter()
                        .filter(|r| r.vehicle == k as u32)
                        .step_by(step)
                        .map(|r| [r.true_x_m, r.true_y_m])
                        .collect()
                })
                .collect(),
        }
    }

    /// Writes it into a campaign directory (atomically).
    pub fn write(&self, dir: &Path) -> std::io::Result<()> {
        let json = serde_json::to_string(self).map_err(std::io::Error::other)?;
        let path = example_file(dir, &self.scenario, &self.config, &self.point);
        plumetrace_mission::output::write_atomic(&path, json.as_bytes())
    }

    /// Reads a group's example from a campaign directory, if it is there.
    pub fn read(dir: &Path, scenario: &str, config: &str, point: &str) -> Option<Self> {
        let text = std::fs::read_to_string(example_file(dir, scenario, config, point)).ok()?;
        serde_json::from_str(&text).ok()
    }
}

/// The example file of a group: `examples/<scenario>__<config>__<point>.json`.
fn example_file(dir: &Path, scenario: &str, config: &str, point: &str) -> PathBuf {
    dir.join(EXAMPLES_DIR)
        .join(format!("{}.json", slug(&[scenario, config, point])))
}

/// The replay page of a group's example run: `examples/<scenario>__<config>__<point>.html`.
pub fn page_file(dir: &Path, scenario: &str, config: &str, point: &str) -> PathBuf {
    example_file(dir, scenario, config, point).with_extension("html")
}

/// Why the replay page of an example run was not written.
#[derive(Debug, thiserror::Error)]
pub enum PageError {
    /// The page could not be made.
    #[error("{0}")]
    Draw(plumetrace_report::ReportError),
    /// The page could not be written.
    #[error("writing {path}: {error}")]
    Write {
        /// The page's file.
        path: String,
        /// What failed.
        error: std::io::Error,
    },
}

/// Writes the replay page of a group's example run (atomically).
pub fn write_page(
    c: &Campaign,
    key: &RunKey,
    run: &MissionRun,
    dir: &Path,
) -> Result<(), PageError> {
    let (scenario, config, point) = (
        &c.scenarios[key.scenario].label,
        &c.configs[key.config].name,
        c.points[key.point].label(),
    );
    let group = if point.is_empty() {
        format!("{scenario} / {config}")
    } else {
        format!("{scenario} / {config} / {point}")
    };
    let title = format!(
        "{}: {group}, example run (seed {})",
        c.file.name, run.summary.seed
    );
    let page = plumetrace_report::replay_page(run, &title).map_err(PageError::Draw)?;
    let path = page_file(dir, scenario, config, &point);
    plumetrace_mission::output::write_atomic(&path, page.as_bytes()).map_err(|error| {
        PageError::Write {
            path: path.display().to_string(),
            error,
        }
    })
}

/// A file name from labels, short, safe and unique: each label's letters, digits, `-`, `.` and
/// `_` (the rest `_`), cut to 32 characters, joined by `__`, then a digest of the labels as they
/// are (so `a/b` and `a_b`, or two long names alike in their first 32 characters, differ).
pub fn slug(parts: &[&str]) -> String {
    let readable = parts
        .iter()
        .map(|p| {
            p.chars()
                .take(32)
                .map(|ch| {
                    if ch.is_ascii_alphanumeric() || matches!(ch, '-' | '.' | '_') {
                        ch
                    } else {
                        '_'
                    }
                })
                .collect::<String>()
        })
        .collect::<Vec<_>>()
        .join("__");
    let digest = crate::spec::fnv1a(parts.join("\u{0}").as_bytes());
    format!("{readable}-{digest:016x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_names_are_short_safe_and_unique() {
        let a = slug(&["demo", "a/b", ""]);
        let b = slug(&["demo", "a_b", ""]);
        assert_ne!(a, b, "{a} {b}");
        assert!(a.starts_with("demo__a_b__-"), "{a}");
        let long = "x".repeat(500);
        let l1 = slug(&["demo", &long, "beta_deg=1e300"]);
        let l2 = slug(&["demo", &format!("{long}y"), "beta_deg=1e300"]);
        assert!(l1.len() < 120 && l1 != l2, "{l1}");
        assert!(
            l1.chars()
                .all(|c| c.is_ascii_alphanumeric() || "-._".contains(c))
        );
    }
}
