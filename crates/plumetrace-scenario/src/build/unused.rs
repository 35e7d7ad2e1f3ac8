//! Keys that have no effect in this kind of run (a mission or a plume run): the run goes on, and
//! `check` and `run` print a warning for each, so that no key is silently ignored.

use super::Warning;
use crate::config::{OutputConfig, ScenarioConfig};

/// The warnings of a scenario that is a mission (`mission`) or a plume run.
pub(super) fn unused_keys(cfg: &ScenarioConfig, mission: bool) -> Vec<Warning> {
    let mut out = Vec::new();
    match (&cfg.mission, mission) {
        (Some(m), true) => {
            if cfg.sim.duration_s != m.time_limit_s {
                out.push(Warning::new(
                    "sim.duration_s",
                    format!(
                        "{} s has no effect on a mission, which runs until its vehicles are done \
                         or mission.time_limit_s ({} s); set that instead (or make the two equal)",
                        cfg.sim.duration_s, m.time_limit_s
                    ),
                ));
            }
            let (o, d) = (&cfg.output, OutputConfig::default());
            let plume_run_only = [
                ("nx", o.nx != d.nx),
                ("ny", o.ny != d.ny),
                ("z_m", o.z_m != d.z_m),
                (
                    "average_interval_s",
                    o.average_interval_s != d.average_interval_s,
                ),
                ("average_start_s", o.average_start_s != d.average_start_s),
            ];
            for (key, _) in plume_run_only.iter().filter(|(_, given)| *given) {
                out.push(Warning::new(
                    format!("output.{key}"),
                    "has no effect on a mission: the [output] grid and time average are written \
                     by plume runs only (a scenario without [mission]); remove it",
                ));
            }
        }
        _ => {
            if !cfg.vehicles.is_empty() {
                out.push(Warning::new(
                    "vehicles",
                    format!(
                        "{} vehicle(s) not flown: a scenario without [mission] is a plume run \
                         (give [mission] and a planner to fly them)",
                        cfg.vehicles.len()
                    ),
                ));
            }
            let c = &cfg.comms;
            if c.acoustic.is_some() || c.radio.is_some() || c.ranging.is_some() {
                out.push(Warning::new(
                    "comms",
                    "has no effect on a plume run (a scenario without [mission]): no vehicle \
                     sends messages",
                ));
            }
        }
    }
    if cfg.bathymetry.is_none() {
        for (i, v) in cfg.vehicles.iter().enumerate() {
            let d = &v.dynamics;
            for (key, given) in [
                ("dvl_beam_angle_deg", d.dvl_beam_angle_deg.is_some()),
                ("look_ahead_m", d.look_ahead_m.is_some()),
                ("min_altitude_m", d.min_altitude_m.is_some()),
            ] {
                if given {
                    out.push(Warning::new(
                        format!("vehicles[{i}].dynamics.{key}"),
                        "has no effect over a flat seabed: altitude hold uses its seabed \
                         sensors and minimum altitude only over a [bathymetry] grid",
                    ));
                }
            }
        }
    }
    out
}
