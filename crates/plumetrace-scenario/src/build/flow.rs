//! `[flow]`: the mean flow (`[flow.mean]`, steady or tidal) and the flow model over it.

use super::Invalid;
use crate::config::{FlowConfig, FlowKind, MeanFlowConfig};
use plumetrace_env::flow::{FarrellFlow, GriddedFlow, MeanFlow, UniformFlow};
use plumetrace_env::{EnvError, FlowModel, Rect};
use std::path::Path;

/// The key path of the mean flow.
pub(super) const MEAN_KEY: &str = "flow.mean";

/// The flow model of `[flow]`; a gridded flow's file is read relative to `base_dir`.
pub(super) fn flow(f: &FlowConfig, domain: Rect, base_dir: &Path) -> Result<FlowModel, Invalid> {
    let model = match f.model {
        FlowKind::Uniform => {
            if f.farrell.is_some() {
                return Err(Invalid::new(
                    "flow.farrell",
                    "only applies to model = \"farrell\"",
                ));
            }
            let m = required_mean(f)?;
            FlowModel::Uniform(UniformFlow::new(m).map_err(|e| Invalid::env("flow", e))?)
        }
        FlowKind::Farrell => {
            let m = required_mean(f)?;
            let params = f.farrell.unwrap_or_default();
            // The field names its parameters by their key in `[flow.farrell]`, the mean flow's
            // under `mean`.
            let farrell = FarrellFlow::substepped(domain, m, params).map_err(|e| match e {
                EnvError::InvalidParameter { ref key, .. } if key.starts_with("mean") => {
                    Invalid::env("flow", e)
                }
                e => Invalid::env("flow.farrell", e),
            })?;
            FlowModel::Farrell(Box::new(farrell))
        }
        FlowKind::Gridded => {
            let Some(file) = &f.file else {
                return Err(Invalid::new(
                    "flow.file",
                    "model = \"gridded\" needs a file (CSV: x_m,y_m,u_mps,v_mps[,t_s])",
                ));
            };
            FlowModel::Gridded(Box::new(
                GriddedFlow::from_csv(&base_dir.join(file))
                    .map_err(|e| Invalid::new("flow.file", e.to_string()))?,
            ))
        }
    };
    if f.file.is_some() && f.model != FlowKind::Gridded {
        return Err(Invalid::new(
            "flow.file",
            "only applies to model = \"gridded\"",
        ));
    }
    Ok(model)
}

/// The mean flow of `[flow.mean]`, if the table is given.
pub(super) fn mean(f: &FlowConfig) -> Result<Option<MeanFlow>, Invalid> {
    f.mean.as_ref().map(mean_flow).transpose()
}

/// The mean flow of `[flow.mean]`, which the flow model needs.
pub(super) fn required_mean(f: &FlowConfig) -> Result<MeanFlow, Invalid> {
    mean(f)?.ok_or_else(|| {
        Invalid::new(
            MEAN_KEY,
            format!("flow model '{:?}' needs a [flow.mean] table", f.model).to_lowercase(),
        )
    })
}

/// Interprets `[flow.mean]`: steady or tidal.
fn mean_flow(m: &MeanFlowConfig) -> Result<MeanFlow, Invalid> {
    let key = |k: &str| format!("{MEAN_KEY}.{k}");
    let tidal_keys = [
        m.speed_min_mps,
        m.speed_max_mps,
        m.toward_min_deg,
        m.toward_max_deg,
        m.period_s,
        m.phase_deg,
    ];
    let any_tidal = tidal_keys.iter().any(Option::is_some);
    let any_steady = m.speed_mps.is_some() || m.toward_deg.is_some();
    let mean = match (any_steady, any_tidal) {
        (true, true) => {
            return Err(Invalid::new(
                key("speed_mps"),
                "give either speed_mps and toward_deg (steady) or the tidal keys, not both",
            ));
        }
        (false, false) => {
            return Err(Invalid::new(
                key("speed_mps"),
                "give speed_mps and toward_deg (steady) or speed_min_mps, speed_max_mps, \
                 toward_min_deg, toward_max_deg, period_s (tidal)",
            ));
        }
        (true, false) => MeanFlow::Steady {
            speed_mps: m
                .speed_mps
                .ok_or_else(|| Invalid::new(key("speed_mps"), "missing"))?,
            toward_deg: m
                .toward_deg
                .ok_or_else(|| Invalid::new(key("toward_deg"), "missing"))?,
        },
        (false, true) => {
            let need = |v: Option<f64>, k: &str| {
                v.ok_or_else(|| Invalid::new(key(k), "missing (needed for a tidal mean flow)"))
            };
            MeanFlow::Tidal {
                speed_min_mps: need(m.speed_min_mps, "speed_min_mps")?,
                speed_max_mps: need(m.speed_max_mps, "speed_max_mps")?,
                toward_min_deg: need(m.toward_min_deg, "toward_min_deg")?,
                toward_max_deg: need(m.toward_max_deg, "toward_max_deg")?,
                period_s: need(m.period_s, "period_s")?,
                phase_deg: m.phase_deg.unwrap_or(0.0),
            }
        }
    };
    mean.validate().map_err(|e| Invalid::env(MEAN_KEY, e))?;
    Ok(mean)
}
