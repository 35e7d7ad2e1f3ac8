//! `plumetrace run` on a mission scenario: fly it and write its outputs.

use crate::output::write_atomic;
use anyhow::{Context, Result};
use plumetrace_log::snapshot::Header;
use plumetrace_mission::snapshot_log::SnapshotLogWriter;
use plumetrace_mission::{Mission, MissionOptions, MissionRun, MissionSetup, Outcome};
use plumetrace_scenario::BuiltScenario;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// The replay page's file name in a run's output directory.
pub const REPLAY_PAGE: &str = "replay.html";

/// The snapshot log's file name in a run's output directory.
pub const SNAPSHOT_LOG: &str = "snapshots.jsonl.gz";

#[derive(Serialize)]
struct SummaryFile<'a> {
    #[serde(flatten)]
    summary: &'a plumetrace_mission::Summary,
    wall_s: f64,
    real_time_factor: f64,
    spinup_wall_s: f64,
    stage_times: plumetrace_sim::StageTimes,
}

/// Flies the mission and writes `summary.json`, `trajectory.csv`, `events.jsonl`, `plot.svg`,
/// `replay.html` and (unless `snapshot_log` is false) `snapshots.jsonl.gz`.
pub fn run(
    sc: BuiltScenario,
    out: &Path,
    stats: bool,
    snapshot_log: bool,
    alog: bool,
) -> Result<()> {
    let name = sc.name.clone();
    let started = Instant::now();
    let setup = MissionSetup::new(sc)?;
    for w in &setup.warnings {
        eprintln!("warning: {}: {w}", setup.origin);
    }
    let mut mission = Mission::new(setup, MissionOptions::default())?;
    if snapshot_log {
        let header = Header::new(
            &name,
            mission.seed(),
            &mission.vehicle_names(),
            mission.planned(),
        )
        .context("writing the snapshot log's header")?;
        let path = out.join(SNAPSHOT_LOG);
        let writer = SnapshotLogWriter::create(&path, &header)
            .with_context(|| format!("creating {}", path.display()))?;
        mission.observe(Box::new(writer))?;
    }
    if alog {
        let planned: Vec<bool> = mission.planned().iter().map(Option::is_some).collect();
        let writer =
            plumetrace_mission::alog::AlogObserver::create(out, &mission.vehicle_names(), &planned)
                .with_context(|| format!("creating the .alog files in {}", out.display()))?;
        mission.observe(Box::new(writer))?;
    }
    let progress = crate::progress::Progress::new(mission.time_limit_s().round() as u64, "s");
    mission.run(&mut |t, _| progress.tick(t.round() as u64))?;
    progress.finish();
    let run = mission.finish()?;
    let wall = started.elapsed().as_secs_f64();
    write_outputs(&run, out, &name, wall)?;
    if stats {
        let t = run.stage_times;
        eprintln!(
            "stage times (s): advance environment {:.2}, sense {:.2}, communicate {:.3}, decide {:.2}, control {:.3}, integrate {:.2}, check {:.3}, record {:.3}; spin-up {:.2}",
            t.advance_environment_s,
            t.sense_s,
            t.communicate_s,
            t.decide_s,
            t.control_s,
            t.integrate_s,
            t.check_s,
            t.record_s,
            run.spinup_wall_s
        );
    }
    crate::outln!("{}; wrote {}", run_line(&run, &name, wall), out.display());
    Ok(())
}

/// The one-line result: whether the mission located the source (within the scenario's success
/// radius, with the error), the declarations, the outcome and when and why the mission ended.
pub fn run_line(run: &MissionRun, name: &str, wall: f64) -> String {
    let s = &run.summary;
    let detail = if s.sources.len() > 1 || s.declarations.len() > 1 {
        let nearest: Vec<String> = s
            .sources
            .iter()
            .map(|r| {
                r.nearest_error_m
                    .map_or("none".into(), |e| format!("{e:.1} m"))
            })
            .collect();
        format!(
            "; {} declarations, nearest declaration per source: {}",
            s.declarations.len(),
            nearest.join(", ")
        )
    } else if let Some(d) = &s.first_declaration {
        format!(
            "; declared at {:.0} s at ({:.1}, {:.1}), {:+.1} m along and {:+.1} m across the flow",
            d.t_s, d.x_m, d.y_m, d.error_along_m, d.error_cross_m
        )
    } else {
        String::new()
    };
    let ended = plumetrace_core::variant_name(&s.ended.reason).unwrap_or("?");
    format!(
        "{name}: {}{detail}; outcome {}, mission ended at {:.0} s ({ended}), {wall:.1} s of wall time",
        s.verdict(),
        s.outcome.name(),
        s.ended.t_s,
    )
}

/// `x` with `digits` decimals, or an empty field.
fn opt(x: Option<f64>, digits: usize) -> String {
    x.map_or(String::new(), |v| format!("{v:.digits$}"))
}

fn write_outputs(run: &MissionRun, out: &Path, name: &str, wall: f64) -> Result<()> {
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
            anyhow::bail!(
                "vehicle {} at t = {} s has a state that is not finite; nothing written",
                r.vehicle,
                r.t_s
            );
        }
        let _ = writeln!(
            csv,
            "{:.1},{},{:.2},{:.2},{:.2},{},{},{:.1},{:.2},{},{:.3},{}",
            r.t_s,
            r.vehicle,
            r.true_x_m,
            r.true_y_m,
            r.true_z_m,
            opt(r.est_x_m, 2),
            opt(r.est_y_m, 2),
            r.heading_deg,
            r.speed_mps,
            r.behaviour
                .and_then(|b| plumetrace_core::variant_name(&b))
                .unwrap_or(""),
            r.reading_v,
            u8::from(r.detection)
        );
    }
    write_atomic(&out.join("trajectory.csv"), csv.as_bytes())?;
    let mut jsonl = String::new();
    for e in &run.events {
        jsonl.push_str(&serde_json::to_string(e).context("encoding an event")?);
        jsonl.push('\n');
    }
    write_atomic(&out.join("events.jsonl"), jsonl.as_bytes())?;
    let file = SummaryFile {
        summary: &run.summary,
        wall_s: wall,
        real_time_factor: run.summary.sim_time_s / (wall - run.spinup_wall_s).max(1e-9),
        spinup_wall_s: run.spinup_wall_s,
        stage_times: run.stage_times,
    };
    if let Some(at) = plumetrace_mission::output::first_non_finite(&file) {
        anyhow::bail!(
            "the mission's summary has a number that is not finite ({at}); nothing written"
        );
    }
    write_atomic(
        &out.join("summary.json"),
        serde_json::to_string_pretty(&file)?.as_bytes(),
    )?;
    let s = &run.summary;
    // The verdict, and the outcome where a vehicle failed (the verdict tells the others).
    let failed = !matches!(
        s.outcome,
        Outcome::Declared | Outcome::NoDeclaration | Outcome::TimedOut
    );
    let outcome = if failed {
        format!("; {}", s.outcome.name())
    } else {
        String::new()
    };
    let title = format!("{name} (seed {}): {}{outcome}", s.seed, s.verdict());
    let svg = plumetrace_report::mission_figure(run, &title)?;
    write_atomic(&out.join("plot.svg"), svg.as_bytes())?;
    if let Some(team) = plumetrace_report::team_figure(run, &title) {
        write_atomic(&out.join("team.svg"), team?.as_bytes())?;
    }
    let page = plumetrace_report::replay_page(run, &title)?;
    write_atomic(&out.join(REPLAY_PAGE), page.as_bytes())?;
    Ok(())
}
