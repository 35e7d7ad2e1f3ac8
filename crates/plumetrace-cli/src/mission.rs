//! `plumetrace run` on a mission scenario: fly it and write its outputs.

use anyhow::{Context, Result};
use plumetrace_log::snapshot::Header;
use plumetrace_mission::snapshot_log::SnapshotLogWriter;
use plumetrace_mission::{Mission, MissionOptions, MissionRun, MissionSetup};
use plumetrace_scenario::BuiltScenario;
use std::path::Path;
use std::time::Instant;

pub use plumetrace_report::run_dir::{REPLAY_PAGE, SNAPSHOT_LOG};

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
    let site = sc.site;
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
    plumetrace_report::write_mission_outputs(&run, out, &name, wall)?;
    if let Some(origin) = site {
        plumetrace_report::geo_outputs::write_geographic_outputs(&run, out, origin, &name)?;
    }
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
