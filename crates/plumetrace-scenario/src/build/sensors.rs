//! A vehicle's navigation and sensors: `[vehicles.nav]`, `[vehicles.chem_sensor]`,
//! `[vehicles.flow_sensor]` and `[vehicles.range_sensor]`, over their defaults; `key` is the
//! vehicle's (`vehicles[k]`).

use super::Invalid;
use crate::config::{
    ChemModel, ChemSensorConfig, FlowSensorConfig, RangeSensorConfig, VehicleConfig,
};
use plumetrace_core::VehicleKind;
use plumetrace_sim::sensors::SalinityParams;
use plumetrace_sim::{ChemSensorParams, FlowFault, FlowSensorParams, NavParams, RangeSensorParams};

/// `[vehicles.nav]` over its kind's defaults (an AUV's LBL, a surface craft's GPS).
pub(super) fn nav(v: &VehicleConfig, key: &str) -> Result<NavParams, Invalid> {
    let nb = match v.kind {
        VehicleKind::Auv => NavParams::lbl(),
        VehicleKind::Surface => NavParams::gps(),
    };
    let n = &v.nav;
    let nav = NavParams {
        fix_interval_s: n.fix_interval_s.unwrap_or(nb.fix_interval_s),
        fix_sigma_m: n.fix_sigma_m.unwrap_or(nb.fix_sigma_m),
        velocity_error_sd_mps: n.velocity_error_sd_mps.unwrap_or(nb.velocity_error_sd_mps),
        velocity_error_tau_s: n.velocity_error_tau_s.unwrap_or(nb.velocity_error_tau_s),
        heading_sd_deg: n.heading_sd_deg.unwrap_or(nb.heading_sd_deg),
        position_estimate: n.position_estimate.unwrap_or(nb.position_estimate),
        speed_sd_mps: n.speed_sd_mps.unwrap_or(nb.speed_sd_mps),
        altimeter_sd_m: n.altimeter_sd_m.unwrap_or(nb.altimeter_sd_m),
        flow_check: n.flow_check.unwrap_or(nb.flow_check),
    };
    nav.validate()
        .map_err(|e| Invalid::env(&format!("{key}.nav"), e))?;
    Ok(nav)
}

/// `[vehicles.chem_sensor]` over the defaults.
pub(super) fn chem_sensor(c: &ChemSensorConfig, key: &str) -> Result<ChemSensorParams, Invalid> {
    let key = format!("{key}.chem_sensor");
    let cb = ChemSensorParams::default();
    let chem_sensor = ChemSensorParams {
        rate_hz: c.rate_hz.unwrap_or(cb.rate_hz),
        volts_per_unit: c.volts_per_unit.unwrap_or(cb.volts_per_unit),
        full_scale_v: c.full_scale_v.unwrap_or(cb.full_scale_v),
        noise_sd_v: c.noise_sd_v.unwrap_or(cb.noise_sd_v),
        lag_time_constant_s: c.lag_time_constant_s.unwrap_or(cb.lag_time_constant_s),
        salinity: salinity(c, &key)?,
    };
    chem_sensor.validate().map_err(|e| Invalid::env(&key, e))?;
    Ok(chem_sensor)
}

/// The salinity probe of a chemical sensor, if its model is "salinity" or "salinity_deficit";
/// the salinity keys without it are an error (they would be ignored).
fn salinity(c: &ChemSensorConfig, key: &str) -> Result<Option<SalinityParams>, Invalid> {
    let d = SalinityParams::default();
    let model = c.model.unwrap_or(ChemModel::Voltage);
    match model {
        ChemModel::Salinity | ChemModel::SalinityDeficit => Ok(Some(SalinityParams {
            medium_ppt: c.medium_salinity_ppt.unwrap_or(d.medium_ppt),
            fresh_density_kgpm3: c.fresh_density_kgpm3.unwrap_or(d.fresh_density_kgpm3),
            noise_sd_ppt: c.noise_sd_ppt.unwrap_or(d.noise_sd_ppt),
            deficit: model == ChemModel::SalinityDeficit,
        })),
        ChemModel::Voltage => {
            let given = [
                ("medium_salinity_ppt", c.medium_salinity_ppt),
                ("fresh_density_kgpm3", c.fresh_density_kgpm3),
                ("noise_sd_ppt", c.noise_sd_ppt),
            ];
            match given.iter().find(|(_, v)| v.is_some()) {
                Some((name, _)) => Err(Invalid::new(
                    format!("{key}.{name}"),
                    "only a salinity sensor has it (set model = \"salinity\" or \"salinity_deficit\")",
                )),
                None => Ok(None),
            }
        }
    }
}

/// `[vehicles.flow_sensor]` over the defaults, with its fault window if given.
pub(super) fn flow_sensor(f: &FlowSensorConfig, key: &str) -> Result<FlowSensorParams, Invalid> {
    let key = format!("{key}.flow_sensor");
    let fb = FlowSensorParams::default();
    let fault = match (f.fault_start_s, f.fault_end_s) {
        (Some(start_s), Some(end_s)) => Some(FlowFault { start_s, end_s }),
        (None, None) => None,
        _ => {
            return Err(Invalid::new(
                format!("{key}.fault_end_s"),
                "give both fault_start_s and fault_end_s",
            ));
        }
    };
    let flow_sensor = FlowSensorParams {
        rate_hz: f.rate_hz.unwrap_or(fb.rate_hz),
        noise_sd_mps: f.noise_sd_mps.unwrap_or(fb.noise_sd_mps),
        bias_mps: f.bias_mps.unwrap_or(fb.bias_mps),
        fault,
    };
    flow_sensor.validate().map_err(|e| Invalid::env(&key, e))?;
    Ok(flow_sensor)
}

/// `[vehicles.range_sensor]` over the defaults, if fitted.
pub(super) fn range_sensor(
    r: Option<&RangeSensorConfig>,
    key: &str,
) -> Result<Option<RangeSensorParams>, Invalid> {
    let Some(r) = r else {
        return Ok(None);
    };
    let rb = RangeSensorParams::default();
    let p = RangeSensorParams {
        max_range_m: r.max_range_m.unwrap_or(rb.max_range_m),
        rays_per_group: r.rays_per_group.unwrap_or(rb.rays_per_group),
        front_half_angle_deg: r.front_half_angle_deg.unwrap_or(rb.front_half_angle_deg),
        side_outer_angle_deg: r.side_outer_angle_deg.unwrap_or(rb.side_outer_angle_deg),
        rate_hz: r.rate_hz.unwrap_or(rb.rate_hz),
        noise_sd_m: r.noise_sd_m.unwrap_or(rb.noise_sd_m),
        detection_probability: r.detection_probability.unwrap_or(rb.detection_probability),
    };
    p.validate()
        .map_err(|e| Invalid::env(&format!("{key}.range_sensor"), e))?;
    Ok(Some(p))
}
