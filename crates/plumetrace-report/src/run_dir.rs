//! A flown mission's output directory: the files `plumetrace run` writes and Python's
//! `RunResult.save` writes, from one function so the two never differ.
//!
//! [`write_mission_outputs`] writes `trajectory.csv`, `events.jsonl`, `summary.json` (with the
//! run's wall-clock fields), `plot.svg`, `team.svg` (a team mission) and `replay.html`; the
//! snapshot log (`snapshots.jsonl.gz`) is written while the mission flies, by the mission crate's
//! observer, under [`SNAPSHOT_LOG`]. Every file goes through a temporary file and a rename.

use crate::decimal::{push_fixed, push_whole};
use plumetrace_mission::MissionRun;
use plumetrace_mission::output::{first_non_finite, write_atomic};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The replay page's file name in a run's output directory.
pub const REPLAY_PAGE: &str = "replay.html";

/// The snapshot log's file name in a run's output directory.
pub const SNAPSHOT_LOG: &str = "snapshots.jsonl.gz";

/// What can go wrong writing a run's outputs.
#[derive(Debug, thiserror::Error)]
pub enum RunDirError {
    /// A vehicle's recorded state has a number that is not finite.
    #[error("vehicle {vehicle} at t = {t_s} s has a state that is not finite; nothing written")]
    NotFiniteState {
        /// The vehicle's index.
        vehicle: u32,
        /// Mission time of the step, s.
        t_s: f64,
    },
    /// The summary has a number that is not finite (at this key path).
    #[error("the mission's summary has a number that is not finite ({0}); nothing written")]
    NotFiniteSummary(String),
    /// A file could not be written.
    #[error("writing {}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// An event or the summary could not be encoded.
    #[error("encoding {what}")]
    Encode {
        /// What was being encoded.
        what: &'static str,
        /// Why.
        #[source]
        source: serde_json::Error,
    },
    /// A figure or the replay page could not be drawn.
    #[error(transparent)]
    Report(#[from] crate::ReportError),
}

/// `summary.json`: the summary with the run's wall-clock fields.
#[derive(Serialize)]
struct SummaryFile<'a> {
    #[serde(flatten)]
    summary: &'a plumetrace_mission::Summary,
    wall_s: f64,
    real_time_factor: f64,
    spinup_wall_s: f64,
    stage_times: plumetrace_sim::StageTimes,
}

/// `trajectory.csv`: every step of every vehicle.
pub fn trajectory_csv(run: &MissionRun) -> Result<String, RunDirError> {
    let mut csv = String::from(
        "t_s,vehicle,true_x_m,true_y_m,true_z_m,est_x_m,est_y_m,heading_deg,speed_mps,behaviour,reading_v,detection\n",
    );
    for r in &run.trajectory {
        let numbers = [
            r.t_s,
            r.true_x_m,
            r.true_y_m,
            r.true_z_m,
            r.heading_deg,
            r.speed_mps,
            r.reading_v,
        ];
        if numbers
            .iter()
            .chain(r.est_x_m.iter())
            .chain(r.est_y_m.iter())
            .any(|v| !v.is_finite())
        {
            return Err(RunDirError::NotFiniteState {
                vehicle: r.vehicle,
                t_s: r.t_s,
            });
        }
        let fixed = |csv: &mut String, v: f64, places: usize| {
            push_fixed(csv, v, places);
            csv.push(',');
        };
        fixed(&mut csv, r.t_s, 1);
        push_whole(&mut csv, u64::from(r.vehicle));
        csv.push(',');
        fixed(&mut csv, r.true_x_m, 2);
        fixed(&mut csv, r.true_y_m, 2);
        fixed(&mut csv, r.true_z_m, 2);
        for est in [r.est_x_m, r.est_y_m] {
            if let Some(v) = est {
                push_fixed(&mut csv, v, 2);
            }
            csv.push(',');
        }
        fixed(&mut csv, r.heading_deg, 1);
        fixed(&mut csv, r.speed_mps, 2);
        let behaviour = r.behaviour.and_then(|b| plumetrace_core::variant_name(&b));
        csv.push_str(behaviour.unwrap_or(""));
        csv.push(',');
        fixed(&mut csv, r.reading_v, 3);
        csv.push(if r.detection { '1' } else { '0' });
        csv.push('\n');
    }
    Ok(csv)
}

/// `events.jsonl`: one event per line.
pub fn events_jsonl(run: &MissionRun) -> Result<String, RunDirError> {
    let mut jsonl = String::new();
    for e in &run.events {
        let line = serde_json::to_string(e).map_err(|source| RunDirError::Encode {
            what: "an event",
            source,
        })?;
        jsonl.push_str(&line);
        jsonl.push('\n');
    }
    Ok(jsonl)
}

/// `summary.json`: the summary and the run's wall-clock fields (`wall_s` is the whole run's
/// wall time, spin-up included).
pub fn summary_json(run: &MissionRun, wall_s: f64) -> Result<String, RunDirError> {
    let file = SummaryFile {
        summary: &run.summary,
        wall_s,
        real_time_factor: run.summary.sim_time_s / (wall_s - run.spinup_wall_s).max(1e-9),
        spinup_wall_s: run.spinup_wall_s,
        stage_times: run.stage_times,
    };
    if let Some(at) = first_non_finite(&file) {
        return Err(RunDirError::NotFiniteSummary(at));
    }
    serde_json::to_string_pretty(&file).map_err(|source| RunDirError::Encode {
        what: "the summary",
        source,
    })
}

/// The figures' and the replay page's title: the scenario, the seed and the verdict (located or
/// not, with the error), and the outcome where a vehicle failed (the verdict tells the others).
pub fn title(run: &MissionRun, name: &str) -> String {
    use plumetrace_mission::Outcome;
    let s = &run.summary;
    let failed = !matches!(
        s.outcome,
        Outcome::Declared | Outcome::NoDeclaration | Outcome::TimedOut
    );
    let outcome = if failed {
        format!("; {}", s.outcome.name())
    } else {
        String::new()
    };
    format!("{name} (seed {}): {}{outcome}", s.seed, s.verdict())
}

fn write(path: PathBuf, bytes: &[u8]) -> Result<(), RunDirError> {
    write_atomic(&path, bytes).map_err(|source| RunDirError::Write { path, source })
}

/// Writes a flown mission's files into `out` (which must exist): `trajectory.csv`,
/// `events.jsonl`, `summary.json`, `plot.svg`, `team.svg` (a team mission) and `replay.html`.
/// `name` is the scenario's name, `wall_s` the run's wall time.
pub fn write_mission_outputs(
    run: &MissionRun,
    out: &Path,
    name: &str,
    wall_s: f64,
) -> Result<(), RunDirError> {
    write(out.join("trajectory.csv"), trajectory_csv(run)?.as_bytes())?;
    write(out.join("events.jsonl"), events_jsonl(run)?.as_bytes())?;
    write(
        out.join("summary.json"),
        summary_json(run, wall_s)?.as_bytes(),
    )?;
    let title = title(run, name);
    let svg = crate::mission_figure(run, &title)?;
    write(out.join("plot.svg"), svg.as_bytes())?;
    if let Some(team) = crate::team_figure(run, &title) {
        write(out.join("team.svg"), team?.as_bytes())?;
    }
    let page = crate::replay_page(run, &title)?;
    write(out.join(REPLAY_PAGE), page.as_bytes())?;
    Ok(())
}
