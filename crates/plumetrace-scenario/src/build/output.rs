//! `[output]`: what a plume run writes (the snapshot and time-average grid, probe and filament
//! series) and how often it samples.

use super::timing::Timing;
use super::{Invalid, OutputSpec};
use crate::config::{OutputConfig, PlumeKind, ScenarioConfig};
use crate::limits::{MAX_FILAMENT_SNAPSHOTS, MAX_PROBE_ROWS, show};
use plumetrace_core::Vec3;
use plumetrace_env::{GridSpec, Rect};

/// The output settings, checked against the run's clock.
pub(super) fn output(
    cfg: &ScenarioConfig,
    domain: &Rect,
    timing: &Timing,
) -> Result<OutputSpec, Invalid> {
    let o = &cfg.output;
    let dt_s = timing.dt_s;
    let grid = GridSpec {
        x_min_m: domain.x_min_m,
        x_max_m: domain.x_max_m,
        y_min_m: domain.y_min_m,
        y_max_m: domain.y_max_m,
        nx: o.nx,
        ny: o.ny,
        z_m: o.z_m,
    };
    grid.validate().map_err(|e| Invalid::env("output", e))?;
    if !(o.average_interval_s.is_finite() && o.average_interval_s >= dt_s) {
        return Err(Invalid::new(
            "output.average_interval_s",
            format!(
                "must be >= sim.dt_s ({dt_s}), got {:?}",
                o.average_interval_s
            ),
        ));
    }
    if !(o.average_start_s.is_finite()
        && o.average_start_s >= 0.0
        && o.average_start_s < timing.duration_s)
    {
        return Err(Invalid::new(
            "output.average_start_s",
            format!(
                "must be in [0, sim.duration_s), got {:?}",
                o.average_start_s
            ),
        ));
    }
    if cfg.mission.is_some() {
        plume_run_only(o)?;
    }
    let probes = probes(o, domain, cfg.domain.depth_m)?;
    let probe_every_steps = probe_every_steps(o, timing, probes.len())?;
    let filaments_every_steps = filaments_every_steps(o, cfg.plume.model, timing)?;
    Ok(OutputSpec {
        grid,
        average_every_steps: steps_of(o.average_interval_s, dt_s),
        average_start_step: (o.average_start_s / dt_s).round() as u64,
        threshold: o.threshold,
        probes,
        probe_every_steps,
        filaments_every_steps,
    })
}

/// Steps of `dt_s` in an interval of `s` seconds, at least one.
fn steps_of(s: f64, dt_s: f64) -> u64 {
    ((s / dt_s).round() as u64).max(1)
}

/// Refuses the probe and filament series in a mission, which records its own outputs.
fn plume_run_only(o: &OutputConfig) -> Result<(), Invalid> {
    let given = [
        ("output.probes", !o.probes.is_empty()),
        ("output.probe_interval_s", o.probe_interval_s.is_some()),
        (
            "output.filaments_interval_s",
            o.filaments_interval_s.is_some_and(|s| s != 0.0),
        ),
    ];
    match given.iter().find(|(_, g)| *g) {
        Some((key, _)) => Err(Invalid::new(
            *key,
            "probe and filament series are written by plume runs only (a scenario without \
             [mission]); a mission records its own outputs",
        )),
        None => Ok(()),
    }
}

/// `output.probes`: points inside the domain, between the seabed and the surface.
fn probes(o: &OutputConfig, domain: &Rect, depth_m: Option<f64>) -> Result<Vec<Vec3>, Invalid> {
    let mut probes = Vec::with_capacity(o.probes.len());
    for (k, &[x, y, z]) in o.probes.iter().enumerate() {
        let key = format!("output.probes[{k}]");
        let at = format!("[{}, {}, {}]", show(x), show(y), show(z));
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            return Err(Invalid::new(
                key,
                format!("{at} is not a point (every coordinate finite)"),
            ));
        }
        if !domain.contains_xy(x, y) {
            return Err(Invalid::new(
                key,
                format!(
                    "{at} is outside the domain ({}..{} East, {}..{} North)",
                    show(domain.x_min_m),
                    show(domain.x_max_m),
                    show(domain.y_min_m),
                    show(domain.y_max_m)
                ),
            ));
        }
        if z < 0.0 || depth_m.is_some_and(|h| z > h) {
            return Err(Invalid::new(
                key,
                match depth_m {
                    Some(h) => format!(
                        "{at}: z_m (height above the seabed) must be in [0, domain.depth_m = {}]",
                        show(h)
                    ),
                    None => format!("{at}: z_m (height above the seabed) must be >= 0"),
                },
            ));
        }
        probes.push(Vec3::new(x, y, z));
    }
    Ok(probes)
}

/// `output.probe_interval_s` (by default `output.average_interval_s`) in steps, checked when
/// there are probes or it is given: sampled at least once, and probes.csv within its bound.
fn probe_every_steps(o: &OutputConfig, timing: &Timing, probes: usize) -> Result<u64, Invalid> {
    let (dt_s, duration_s, steps) = (timing.dt_s, timing.duration_s, timing.steps);
    let probe_interval_s = o.probe_interval_s.unwrap_or(o.average_interval_s);
    let every = steps_of(probe_interval_s, dt_s);
    if o.probe_interval_s.is_none() && probes == 0 {
        return Ok(every);
    }
    let default = if o.probe_interval_s.is_none() {
        " (its default, output.average_interval_s)".to_string()
    } else {
        String::new()
    };
    if !(probe_interval_s.is_finite() && probe_interval_s >= dt_s && probe_interval_s <= duration_s)
    {
        return Err(Invalid::new(
            "output.probe_interval_s",
            format!(
                "must be in [sim.dt_s, sim.duration_s] = [{}, {}] so that the probes are sampled \
                 at least once, got {}{default}",
                show(dt_s),
                show(duration_s),
                show(probe_interval_s)
            ),
        ));
    }
    let rows = (steps / every).saturating_mul(probes as u64);
    if rows > MAX_PROBE_ROWS {
        return Err(Invalid::new(
            "output.probe_interval_s",
            format!(
                "{} samples x {probes} probes = {rows} rows of probes.csv; at most \
                 {MAX_PROBE_ROWS}: lengthen the interval{default} or use fewer probes",
                steps / every,
            ),
        ));
    }
    Ok(every)
}

/// `output.filaments_interval_s` in steps: `None` (no snapshots) when absent or 0; otherwise
/// within the run, for a filament plume, and at most [`MAX_FILAMENT_SNAPSHOTS`] snapshots.
fn filaments_every_steps(
    o: &OutputConfig,
    model: PlumeKind,
    timing: &Timing,
) -> Result<Option<u64>, Invalid> {
    let Some(s) = o.filaments_interval_s.filter(|&s| s != 0.0) else {
        return Ok(None);
    };
    let (dt_s, duration_s) = (timing.dt_s, timing.duration_s);
    let key = "output.filaments_interval_s";
    if !(s.is_finite() && s >= dt_s && s <= duration_s) {
        return Err(Invalid::new(
            key,
            format!(
                "must be 0 (no snapshots) or in [sim.dt_s, sim.duration_s] = [{}, {}], got {}",
                show(dt_s),
                show(duration_s),
                show(s)
            ),
        ));
    }
    if model != PlumeKind::Filaments {
        return Err(Invalid::new(
            key,
            "a steady plume (plume.model = \"gaussian\" or \"gridded\") has no filaments; \
             remove it or use plume.model = \"filaments\"",
        ));
    }
    let every = steps_of(s, dt_s);
    let snapshots = timing.steps / every;
    if snapshots > MAX_FILAMENT_SNAPSHOTS {
        return Err(Invalid::new(
            key,
            format!(
                "sim.duration_s / {} = {snapshots} snapshots of every filament; at most \
                 {MAX_FILAMENT_SNAPSHOTS}: lengthen the interval",
                show(s)
            ),
        ));
    }
    Ok(Some(every))
}
