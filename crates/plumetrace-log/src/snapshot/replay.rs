//! Replaying a snapshot log: each logged planner rebuilt and fed the logged snapshots, and the
//! decisions that come out differently.

use super::{FORMAT, Header, Line, VERSION};
use plumetrace_core::{Decision, Planner};
use plumetrace_planner::PlannerConfig;
use std::collections::BTreeMap;
use std::io::BufRead;

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

impl Difference {
    /// The parts of the two decisions that differ, by the same test as the whole decision
    /// ([`same`]): any of "command", "status", "events", "telemetry" and "messages".
    pub fn parts(&self) -> Vec<&'static str> {
        let (a, b) = (&self.logged, &self.replayed);
        [
            ("command", same(&a.command, &b.command)),
            ("status", same(&a.status, &b.status)),
            ("events", same(&a.events, &b.events)),
            ("telemetry", same(&a.telemetry, &b.telemetry)),
            ("messages", same(&a.outbox, &b.outbox)),
        ]
        .into_iter()
        .filter_map(|(name, same)| (!same).then_some(name))
        .collect()
    }
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
    /// Per vehicle replayed with its logged table, the keys of its planner that the table does
    /// not give (a log writes every key, so a log from before a key existed): they replay with
    /// today's defaults, which may not be how the logged planner flew.
    pub defaulted: Vec<Defaulted>,
}

/// Keys a logged planner table does not give ([`ReplayReport::defaulted`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Defaulted {
    /// Vehicle index.
    pub vehicle: u32,
    /// Vehicle name, as logged.
    pub name: String,
    /// The keys, in the planner's table order.
    pub keys: Vec<String>,
}

impl ReplayReport {
    /// Differences kept in full.
    pub const KEEP: usize = 10;
}

/// Whether two decisions, or two parts of them, are the same to the bit, non-finite numbers
/// included: their text in the log (exact: numbers round-trip, non-finite ones are written as
/// words). How a replay compares what it decided with the log.
pub fn same<T: serde::Serialize + ?Sized>(a: &T, b: &T) -> bool {
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
    mut log: impl BufRead,
    tables: &dyn Fn(u32) -> Option<toml::Table>,
    on: &mut dyn FnMut(Replayed<'_>),
) -> Result<ReplayReport, ReplayError> {
    replay_dyn(&mut log, tables, on)
}

/// [`replay_with`]'s work, compiled here once at this crate's optimisation level (a generic body
/// would be compiled in each caller at the caller's level, and the command line is built at
/// `opt-level = 0`); only the reader's own calls stay the caller's.
fn replay_dyn(
    log: &mut dyn BufRead,
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
    let (mut planners, thresholds, defaulted) = build_planners(&header, tables)?;
    let mut report = ReplayReport {
        defaulted,
        ..ReplayReport::default()
    };
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

/// The rebuilt planners by vehicle, their detection thresholds, and the keys each logged table
/// left to today's defaults ([`ReplayReport::defaulted`]).
type Rebuilt = (
    BTreeMap<u32, Box<dyn Planner>>,
    BTreeMap<u32, Option<f64>>,
    Vec<Defaulted>,
);

/// Each logged vehicle's planner, rebuilt from the header (or from `tables`), its detection
/// threshold, and the keys its logged table does not give.
fn build_planners(
    header: &Header,
    tables: &dyn Fn(u32) -> Option<toml::Table>,
) -> Result<Rebuilt, ReplayError> {
    let mut planners: BTreeMap<u32, Box<dyn Planner>> = BTreeMap::new();
    let mut thresholds: BTreeMap<u32, Option<f64>> = BTreeMap::new();
    let mut defaulted = Vec::new();
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
        let (table, logged) = match tables(v.id) {
            Some(t) => (t, false),
            None => (
                v.planner.parse().map_err(|e| ReplayError::Planner {
                    vehicle: v.id,
                    message: format!("its planner table: {e}"),
                })?,
                true,
            ),
        };
        let rebuild_error = |e: plumetrace_core::params::ParamError| ReplayError::Planner {
            vehicle: v.id,
            message: e.to_string(),
        };
        let config = PlannerConfig::from_table(&table, &v.planner_key).map_err(rebuild_error)?;
        thresholds.insert(v.id, config.detection_threshold_v());
        // Every key a table written today would give that the logged one does not.
        let missing: Vec<String> = match (logged, config.to_table()) {
            (true, Ok(all)) => all
                .keys()
                .filter(|k| !table.contains_key(*k))
                .cloned()
                .collect(),
            _ => Vec::new(),
        };
        if !missing.is_empty() {
            defaulted.push(Defaulted {
                vehicle: v.id,
                name: v.name.clone(),
                keys: missing,
            });
        }
        let planner = config
            .build(&v.context, &v.planner_key)
            .map_err(rebuild_error)?;
        planners.insert(v.id, planner);
    }
    Ok((planners, thresholds, defaulted))
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

    #[test]
    fn a_difference_names_the_parts_that_differ() {
        let logged = Decision::new(
            Command {
                heading: Heading::from_deg(90.0),
                speed_mps: 1.5,
                vertical: VerticalCommand::Altitude(2.0),
            },
            PlanStatus::Running,
        );
        let diff = |replayed: Decision| Difference {
            line: 2,
            vehicle: 0,
            t_s: 1.0,
            logged: logged.clone(),
            replayed,
        };
        assert!(diff(logged.clone()).parts().is_empty());
        // The same command, an event more.
        let mut moved = logged.clone();
        moved
            .events
            .push(plumetrace_core::PlannerEvent::LostPointMoved {
                from_m: plumetrace_core::Vec2::new(1.0, 2.0),
                to_m: plumetrace_core::Vec2::new(1.5, 2.0),
            });
        assert_eq!(diff(moved.clone()).parts(), ["events"]);
        // A heading a hundredth of a degree off (the same to two decimals) and finished.
        moved.command.heading = Heading::from_deg(90.001);
        moved.status = PlanStatus::Finished;
        assert_eq!(diff(moved).parts(), ["command", "status", "events"]);
    }
}
