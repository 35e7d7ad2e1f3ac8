//! The snapshot log: every snapshot a planner received and every decision it returned, one JSON
//! object per line, so that a mission can be replayed through a planner.
//!
//! Format (`snapshots.jsonl.gz`: gzip-compressed JSON lines, `zcat` reads it; version 1):
//! - line 1, the header: `{"format": "plumetrace-snapshots", "version": 1, "scenario": NAME,
//!   "seed": N, "vehicles": [{"id": 0, "name": "auv", "planner_key": "planner",
//!   "planner": "<the planner's table as TOML, every key>", "context": {...}}]}`, one entry per
//!   vehicle with a planner (`context` is the planner's build context: mission geometry, vehicle
//!   id and kind);
//! - then one line per decision, in the order they were made:
//!   `{"vehicle": 0, "snapshot": {...}, "decision": {...}}` (the core `SensorSnapshot` and
//!   `Decision`, serde's field names; numbers round-trip exactly).
//!
//! The format lives on the onboard side, so a vehicle process writes the same log as a simulated
//! mission. [`replay`] builds a fresh planner per vehicle from the header (or from other tables) and feeds
//! it the logged snapshots; [`ReplayReport`] says which decisions differ.

use flate2::Compression;
use flate2::read::MultiGzDecoder;
use flate2::write::GzEncoder;
use plumetrace_core::{Decision, Planner, SensorSnapshot};
use plumetrace_planner::{BuildContext, PlannerConfig};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufRead, BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

/// What the header needs of one vehicle's planner (the mission's planned vehicles and the
/// onboard runner's planner both give it).
pub trait LoggablePlanner {
    /// The planner table's key path (`planner` or `planners.NAME`).
    fn key(&self) -> &str;
    /// The planner's configuration.
    fn config(&self) -> &PlannerConfig;
    /// What it is built with.
    fn context(&self) -> &BuildContext;
}

/// The header's `format` value.
pub const FORMAT: &str = "plumetrace-snapshots";
/// The format version this code writes and reads.
pub const VERSION: u32 = 1;

/// One vehicle's planner in the header.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LoggedPlanner {
    /// Vehicle index.
    pub id: u32,
    /// Vehicle name.
    pub name: String,
    /// The planner table's key path in the scenario.
    pub planner_key: String,
    /// The planner's table as TOML (every key, defaults included).
    pub planner: String,
    /// What it was built with.
    pub context: BuildContext,
}

/// The first line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`VERSION`].
    pub version: u32,
    /// Scenario name.
    pub scenario: String,
    /// Run seed.
    pub seed: u64,
    /// The vehicles with planners.
    pub vehicles: Vec<LoggedPlanner>,
}

impl Header {
    /// The header of a mission's planners; an error if a planner's table cannot be written.
    pub fn new<P: LoggablePlanner>(
        scenario: &str,
        seed: u64,
        names: &[String],
        planners: &[Option<P>],
    ) -> Result<Self, String> {
        let mut vehicles = Vec::new();
        for (k, p) in planners.iter().enumerate() {
            let Some(p) = p else { continue };
            let table = p
                .config()
                .to_table()
                .map_err(|e| format!("{}: {e}", p.key()))?;
            vehicles.push(LoggedPlanner {
                id: k as u32,
                name: names.get(k).cloned().unwrap_or_default(),
                planner_key: p.key().to_string(),
                planner: toml::to_string(&table).map_err(|e| format!("{}: {e}", p.key()))?,
                context: p.context().clone(),
            });
        }
        Ok(Header {
            format: FORMAT.into(),
            version: VERSION,
            scenario: scenario.into(),
            seed,
            vehicles,
        })
    }
}

/// One decision line (borrowed, for writing).
#[derive(Serialize)]
struct LineRef<'a> {
    vehicle: u32,
    snapshot: &'a SensorSnapshot,
    decision: &'a Decision,
}

/// One decision line.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct Line {
    /// Vehicle index.
    pub vehicle: u32,
    /// What the planner received.
    pub snapshot: SensorSnapshot,
    /// What it returned.
    pub decision: Decision,
}

/// Writes the log: gzip-compressed into a temporary file beside `path`, renamed to `path` by
/// [`SnapshotLogFile::finish`] (a crash leaves no partial log under the name).
pub struct SnapshotLogFile {
    // serde_json writes token by token; the encoder is fed in large blocks (it clears its
    // output buffer at every write).
    out: Option<BufWriter<GzEncoder<BufWriter<File>>>>,
    tmp: PathBuf,
    path: PathBuf,
}

impl SnapshotLogFile {
    /// Starts the log at `path` (conventionally `snapshots.jsonl.gz`) with `header`.
    pub fn create(path: &Path, header: &Header) -> std::io::Result<Self> {
        let tmp = path.with_extension("gz.tmp");
        let file = File::create(&tmp)?;
        let gz = GzEncoder::new(BufWriter::new(file), Compression::fast());
        let mut out = BufWriter::with_capacity(1 << 16, gz);
        serde_json::to_writer(&mut out, header)?;
        out.write_all(b"\n")?;
        Ok(SnapshotLogFile {
            out: Some(out),
            tmp,
            path: path.to_path_buf(),
        })
    }

    /// Where the log goes.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Appends one decision line.
    pub fn write(
        &mut self,
        vehicle: u32,
        snapshot: &SensorSnapshot,
        decision: &Decision,
    ) -> Result<(), String> {
        let Some(out) = self.out.as_mut() else {
            return Err("the log is already finished".into());
        };
        let line = LineRef {
            vehicle,
            snapshot,
            decision,
        };
        serde_json::to_writer(&mut *out, &line)
            .map_err(|e| e.to_string())
            .and_then(|()| out.write_all(b"\n").map_err(|e| e.to_string()))
    }

    /// Completes the file and gives it its name.
    pub fn finish(&mut self) -> Result<(), String> {
        let what = |e: &dyn std::fmt::Display| format!("{}: {e}", self.path.display());
        let Some(out) = self.out.take() else {
            return Ok(());
        };
        let gz = out.into_inner().map_err(|e| what(&e.into_error()))?;
        let mut inner = gz.finish().map_err(|e| what(&e))?;
        inner.flush().map_err(|e| what(&e))?;
        drop(inner);
        std::fs::rename(&self.tmp, &self.path).map_err(|e| what(&e))
    }
}

impl Drop for SnapshotLogFile {
    /// A log that was never finished is removed, not left half-written.
    fn drop(&mut self) {
        if self.out.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Opens a snapshot log for reading, gzip-compressed or plain.
pub fn open(path: &Path) -> std::io::Result<Box<dyn BufRead>> {
    let mut file = File::open(path)?;
    let mut magic = [0u8; 2];
    let n = file.read(&mut magic)?;
    let file = File::open(path)?;
    Ok(if n == 2 && magic == [0x1f, 0x8b] {
        Box::new(BufReader::new(MultiGzDecoder::new(file)))
    } else {
        Box::new(BufReader::new(file))
    })
}

/// Why a log could not be read or replayed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// A line could not be read or parsed.
    #[error("line {line}: {message}")]
    Line {
        /// 1-based line number.
        line: u64,
        /// What is wrong.
        message: String,
    },
    /// A logged planner could not be rebuilt.
    #[error("vehicle {vehicle}: {message}")]
    Planner {
        /// Vehicle index.
        vehicle: u32,
        /// What is wrong.
        message: String,
    },
}

/// A decision that came out differently.
#[derive(Debug, Clone, PartialEq)]
pub struct Difference {
    /// 1-based line number in the log.
    pub line: u64,
    /// Vehicle index.
    pub vehicle: u32,
    /// Snapshot time, s.
    pub t_s: f64,
    /// What the log says.
    pub logged: Decision,
    /// What the replayed planner decided.
    pub replayed: Decision,
}

/// What a replay found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReplayReport {
    /// Decisions replayed.
    pub decisions: u64,
    /// How many differ.
    pub differing: u64,
    /// The first differences (at most [`ReplayReport::KEEP`]).
    pub first: Vec<Difference>,
}

impl ReplayReport {
    /// Differences kept in full.
    pub const KEEP: usize = 10;
}

/// Whether two decisions are the same to the bit, non-finite numbers included (their text in the
/// log is exact: numbers round-trip, non-finite ones are written as words).
fn same(a: &Decision, b: &Decision) -> bool {
    match (serde_json::to_string(a), serde_json::to_string(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

/// Reads the header of a log.
pub fn read_header(line: &str) -> Result<Header, ReplayError> {
    let header: Header = serde_json::from_str(line).map_err(|e| ReplayError::Line {
        line: 1,
        message: format!("not a snapshot log header: {e}"),
    })?;
    if header.format != FORMAT || header.version != VERSION {
        return Err(ReplayError::Line {
            line: 1,
            message: format!(
                "format '{}' version {}; this reads '{FORMAT}' version {VERSION}",
                header.format, header.version
            ),
        });
    }
    Ok(header)
}

/// One replayed decision, as [`replay_with`] shows it.
pub struct Replayed<'a> {
    /// The log's header.
    pub header: &'a Header,
    /// The logged line (snapshot and logged decision).
    pub line: &'a Line,
    /// The replayed planner's decision.
    pub replayed: &'a Decision,
    /// The replayed planner's detection threshold, if it has one.
    pub threshold_v: Option<f64>,
}

/// Replays a log: each vehicle's planner is rebuilt from the header, or from `tables` where it
/// gives one for the vehicle (another configuration), and fed the logged snapshots in order.
pub fn replay(
    log: impl BufRead,
    tables: &dyn Fn(u32) -> Option<toml::Table>,
) -> Result<ReplayReport, ReplayError> {
    replay_with(log, tables, &mut |_| {})
}

/// [`replay`], showing every replayed decision to `on` (e.g. to draw the replay page).
pub fn replay_with(
    log: impl BufRead,
    tables: &dyn Fn(u32) -> Option<toml::Table>,
    on: &mut dyn FnMut(Replayed<'_>),
) -> Result<ReplayReport, ReplayError> {
    let mut lines = log.lines();
    let first = lines
        .next()
        .ok_or(ReplayError::Line {
            line: 1,
            message: "the log is empty".into(),
        })?
        .map_err(|e| ReplayError::Line {
            line: 1,
            message: e.to_string(),
        })?;
    let header = read_header(&first)?;
    let mut planners: BTreeMap<u32, Box<dyn Planner>> = BTreeMap::new();
    let mut thresholds: BTreeMap<u32, Option<f64>> = BTreeMap::new();
    for v in &header.vehicles {
        if planners.contains_key(&v.id) {
            return Err(ReplayError::Line {
                line: 1,
                message: format!("vehicle {} is listed twice in the header", v.id),
            });
        }
        if !v.context.geometry.prior_flow_toward_deg.is_finite() {
            return Err(ReplayError::Planner {
                vehicle: v.id,
                message: "its prior flow direction is not a finite number".into(),
            });
        }
        let table = match tables(v.id) {
            Some(t) => t,
            None => v.planner.parse().map_err(|e| ReplayError::Planner {
                vehicle: v.id,
                message: format!("its planner table: {e}"),
            })?,
        };
        let planner = PlannerConfig::from_table(&table, &v.planner_key)
            .and_then(|c| {
                thresholds.insert(v.id, c.detection_threshold_v());
                c.build(&v.context, &v.planner_key)
            })
            .map_err(|e| ReplayError::Planner {
                vehicle: v.id,
                message: e.to_string(),
            })?;
        planners.insert(v.id, planner);
    }
    let mut report = ReplayReport::default();
    for (n, line) in lines.enumerate() {
        let number = n as u64 + 2;
        let text = line.map_err(|e| ReplayError::Line {
            line: number,
            message: e.to_string(),
        })?;
        if text.trim().is_empty() {
            continue;
        }
        let l: Line = serde_json::from_str(&text).map_err(|e| ReplayError::Line {
            line: number,
            message: e.to_string(),
        })?;
        let planner = planners.get_mut(&l.vehicle).ok_or(ReplayError::Line {
            line: number,
            message: format!("vehicle {} has no planner in the header", l.vehicle),
        })?;
        let replayed = planner.decide(&l.snapshot);
        on(Replayed {
            header: &header,
            line: &l,
            replayed: &replayed,
            threshold_v: thresholds.get(&l.vehicle).copied().flatten(),
        });
        report.decisions += 1;
        if !same(&replayed, &l.decision) {
            report.differing += 1;
            if report.first.len() < ReplayReport::KEEP {
                report.first.push(Difference {
                    line: number,
                    vehicle: l.vehicle,
                    t_s: l.snapshot.time_s,
                    logged: l.decision,
                    replayed,
                });
            }
        }
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use plumetrace_core::{Command, Heading, PlanStatus, VerticalCommand};

    #[test]
    fn decisions_with_non_finite_numbers_read_back_the_same() {
        let d = Decision::new(
            Command {
                heading: Heading::from_rad(f64::NAN),
                speed_mps: f64::INFINITY,
                vertical: VerticalCommand::Altitude(2.0),
            },
            PlanStatus::Running,
        );
        let text = serde_json::to_string(&d).unwrap_or_default();
        let back: Decision = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}: {text}"));
        assert_ne!(back, d, "NaN is not equal to itself");
        assert!(same(&back, &d), "but the replay compares them as the same");
        let other = Decision::new(
            Command {
                speed_mps: 1.0,
                ..d.command
            },
            PlanStatus::Running,
        );
        assert!(!same(&other, &d));
    }
}
