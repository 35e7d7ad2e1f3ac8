//! What the figure's tests share: a short demo mission, its layout and legend, and hand-made
//! trajectory rows and source maps.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use super::layout::{MapLayout, map_layout};
use super::model::rows_by_vehicle;
use plumetrace_core::{BehaviourKind, Vec2};
use plumetrace_mission::{EventKind, EventRecord, MissionRun, TrajectoryRow, run_mission};
use plumetrace_scenario::{Origin, build, load_preset};

/// The demo mission cut short: 600 s of spin-up, `limit_s` of mission, seed 3.
pub(super) fn demo(limit_s: f64) -> MissionRun {
    preset_run("demo", limit_s)
}

/// A preset's mission cut short: `limit_s` of mission after at most 600 s of spin-up, seed 3.
pub(super) fn preset_run(name: &str, limit_s: f64) -> MissionRun {
    let mut cfg = load_preset(name).unwrap();
    if let Some(m) = cfg.mission.as_mut() {
        m.spinup_s = m.spinup_s.min(600.0);
        m.time_limit_s = limit_s;
    }
    let sc = build(&cfg, &Origin::Preset(name.into()), Some(3)).unwrap();
    run_mission(sc, &mut |_, _| {}).unwrap()
}

pub(super) fn layout(run: &MissionRun) -> MapLayout {
    map_layout(run, &rows_by_vehicle(run), "test").unwrap()
}

pub(super) fn labels(lay: &MapLayout) -> Vec<String> {
    lay.legend.iter().map(|e| e.label.clone()).collect()
}

/// A row of vehicle 0 at `t_s`, true and estimated position `(x, y)`.
pub(super) fn row(t_s: f64, x: f64, y: f64, detection: bool) -> TrajectoryRow {
    TrajectoryRow {
        t_s,
        vehicle: 0,
        true_x_m: x,
        true_y_m: y,
        true_z_m: 2.0,
        est_x_m: Some(x),
        est_y_m: Some(y),
        heading_deg: 90.0,
        speed_mps: 1.0,
        behaviour: Some(BehaviourKind::TrackIn),
        reading_v: 1.0,
        detection,
    }
}

/// A 20 x 20 map of 5 m cells from (0, -50) peaked at cell `(i, j)`.
pub(super) fn raster_event(t_s: f64, i: usize, j: usize) -> EventRecord {
    let (nx, ny) = (20, 20);
    let log10_p = (0..nx * ny)
        .map(|k| {
            let (di, dj) = ((k % nx) as f32 - i as f32, (k / nx) as f32 - j as f32);
            -1.0 - 0.2 * (di * di + dj * dj)
        })
        .collect();
    EventRecord {
        t_s,
        vehicle: 0,
        event: EventKind::Telemetry(plumetrace_core::Telemetry::SourceMapRaster {
            origin_m: Vec2::new(0.0, -50.0),
            cell_m: 5.0,
            nx,
            ny,
            log10_p,
        }),
    }
}
