//! `plumetrace run` on a mission scenario: fly it and write its outputs.

use crate::output::write_atomic;
use anyhow::{Context, Result};
use plumetrace_mission::{MissionRun, run_mission};
use plumetrace_scenario::BuiltScenario;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

#[derive(Serialize)]
struct SummaryFile<'a> {
    #[serde(flatten)]
    summary: &'a plumetrace_mission::Summary,
    wall_s: f64,
    real_time_factor: f64,
    spinup_wall_s: f64,
    stage_times: plumetrace_sim::StageTimes,
}

/// Flies the mission and writes `summary.json`, `trajectory.csv`, `events.jsonl`, `plot.svg`.
pub fn run(sc: BuiltScenario, out: &Path, stats: bool) -> Result<()> {
    let name = sc.name.clone();
    let started = Instant::now();
    let limit = sc.mission.as_ref().map_or(1.0, |m| m.time_limit_s);
    let progress = crate::progress::Progress::new(limit.round() as u64, "s");
    let mut spinup_wall = None;
    let run = run_mission(sc, &mut |t, _| {
        spinup_wall.get_or_insert_with(|| started.elapsed().as_secs_f64());
        progress.tick(t.round() as u64);
    })?;
    progress.finish();
    let wall = started.elapsed().as_secs_f64();
    write_outputs(&run, out, &name, wall, spinup_wall.unwrap_or(0.0))?;
    let s = &run.summary;
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
            spinup_wall.unwrap_or(0.0)
        );
    }
    let result = if s.sources.len() > 1 || s.declarations.len() > 1 {
        let nearest: Vec<String> = s
            .sources
            .iter()
            .map(|r| {
                if r.nearest_error_m.is_finite() {
                    format!("{:.1} m", r.nearest_error_m)
                } else {
                    "none".to_string()
                }
            })
            .collect();
        format!(
            "{} declarations; {} of {} sources located within {:.0} m (nearest declaration per source: {})",
            s.declarations.len(),
            s.sources_located,
            s.sources.len(),
            plumetrace_mission::LOCATED_RADIUS_M,
            nearest.join(", ")
        )
    } else if s.declared {
        format!(
            "declared at ({:.1}, {:.1}), {:.1} m from the source ({:+.1} m along, {:+.1} m across the flow)",
            s.declared_x, s.declared_y, s.error_m, s.error_along_m, s.error_cross_m
        )
    } else {
        "no source declared".to_string()
    };
    println!(
        "{name}: {} after {:.0} s of mission in {wall:.1} s; {result}; wrote {}",
        s.outcome,
        s.sim_time_s,
        out.display()
    );
    Ok(())
}

fn write_outputs(
    run: &MissionRun,
    out: &Path,
    name: &str,
    wall: f64,
    spinup_wall: f64,
) -> Result<()> {
    let mut csv = String::from(
        "t_s,vehicle,true_x_m,true_y_m,true_z_m,est_x_m,est_y_m,heading_deg,speed_mps,behaviour,reading_v,detection\n",
    );
    for r in &run.trajectory {
        let _ = writeln!(
            csv,
            "{:.1},{},{:.2},{:.2},{:.2},{:.2},{:.2},{:.1},{:.2},{},{:.3},{}",
            r.t_s,
            r.vehicle,
            r.true_x_m,
            r.true_y_m,
            r.true_z_m,
            r.est_x_m,
            r.est_y_m,
            r.heading_deg,
            r.speed_mps,
            r.behaviour,
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
        real_time_factor: run.summary.sim_time_s / (wall - spinup_wall).max(1e-9),
        spinup_wall_s: spinup_wall,
        stage_times: run.stage_times,
    };
    write_atomic(
        &out.join("summary.json"),
        serde_json::to_string_pretty(&file)?.as_bytes(),
    )?;
    let svg = plumetrace_mission::plot::mission_figure(
        run,
        &if run.summary.sources.len() > 1 {
            format!(
                "{name}: {}, {} of {} sources located (seed {})",
                run.summary.outcome,
                run.summary.sources_located,
                run.summary.sources.len(),
                run.summary.seed
            )
        } else {
            format!(
                "{name}: {} (seed {})",
                run.summary.outcome, run.summary.seed
            )
        },
    )
    .map_err(anyhow::Error::msg)?;
    write_atomic(&out.join("plot.svg"), svg.as_bytes())?;
    Ok(())
}
