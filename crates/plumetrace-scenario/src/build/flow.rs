//! `[flow]`: the mean flow (`[flow.mean]`, steady or tidal) and the flow model over it.

use super::Invalid;
use crate::config::{FlowConfig, FlowKind, MeanFlowConfig, ScenarioConfig};
use plumetrace_core::geo::LocalFrame;
use plumetrace_env::flow::{CfOptions, FarrellFlow, GriddedFlow, MeanFlow, UniformFlow};
use plumetrace_env::{EnvError, FlowModel, Rect, Seabed};
use std::io::Read as _;
use std::path::Path;

/// The key path of the mean flow.
pub(super) const MEAN_KEY: &str = "flow.mean";

/// The flow model of `[flow]`; a gridded flow's file is read relative to `base_dir`.
pub(super) fn flow(
    cfg: &ScenarioConfig,
    domain: Rect,
    base_dir: &Path,
    seabed: Option<&Seabed>,
) -> Result<FlowModel, Invalid> {
    let f = &cfg.flow;
    if f.netcdf.is_some() && f.model != FlowKind::Gridded {
        return Err(Invalid::new(
            "flow.netcdf",
            "only applies to model = \"gridded\" with a NetCDF file",
        ));
    }
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
            let path = base_dir.join(file);
            let grid = if is_netcdf(&path) {
                GriddedFlow::from_netcdf(&path, &cf_options(cfg, domain, seabed)?)
            } else if f.netcdf.is_some() {
                return Err(Invalid::new(
                    "flow.netcdf",
                    format!(
                        "only applies to a NetCDF file; {} is not one (it does not start with \
                         \"CDF\")",
                        path.display()
                    ),
                ));
            } else {
                GriddedFlow::from_csv(&path)
            };
            let mut grid = grid.map_err(|e| Invalid::new("flow.file", e.to_string()))?;
            if let Some(strength) = f.meander.filter(|s| *s > 0.0) {
                grid = grid
                    .with_meander(domain, f.farrell.unwrap_or_default(), strength)
                    .map_err(|e| match e {
                        EnvError::InvalidParameter { ref key, .. } if key == "meander" => {
                            Invalid::env("flow", e)
                        }
                        e => Invalid::env("flow.farrell", e),
                    })?;
            }
            FlowModel::Gridded(Box::new(grid))
        }
    };
    if f.meander.is_some() && f.model != FlowKind::Gridded {
        return Err(Invalid::new(
            "flow.meander",
            "only applies to model = \"gridded\" (the farrell model meanders by itself)",
        ));
    }
    if f.file.is_some() && f.model != FlowKind::Gridded {
        return Err(Invalid::new(
            "flow.file",
            "only applies to model = \"gridded\"",
        ));
    }
    Ok(model)
}

/// Whether a file is to be read as NetCDF: it starts as one does (classic `CDF`, or HDF5 for
/// NetCDF-4, which the reader then names) or is named `.nc`, `.nc4`, `.cdf` or `.netcdf` (so a
/// damaged one is told it is not NetCDF rather than read as CSV); anything else is read as CSV.
fn is_netcdf(path: &Path) -> bool {
    let named = path.extension().and_then(|e| e.to_str()).is_some_and(|e| {
        ["nc", "nc4", "cdf", "netcdf"]
            .iter()
            .any(|n| e.eq_ignore_ascii_case(n))
    });
    let mut head = [0u8; 4];
    named
        || std::fs::File::open(path)
            .and_then(|mut f| f.read_exact(&mut head))
            .is_ok_and(|()| head.starts_with(b"CDF") || head == *b"\x89HDF")
}

/// How `[flow.netcdf]` and the scenario read CF currents: the site's origin, the date and span
/// of the run, the plume's layer depth, the simulated area and the op-area.
fn cf_options(
    cfg: &ScenarioConfig,
    domain: Rect,
    seabed: Option<&Seabed>,
) -> Result<CfOptions, Invalid> {
    let n = cfg.flow.netcdf.clone().unwrap_or_default();
    let frame = cfg
        .origin
        .map(LocalFrame::new)
        .transpose()
        .map_err(|e| Invalid::new("origin", e.to_string()))?;
    // Time 0 of the run is the start of the plume's spin-up; `start` is when the vehicles start.
    let (spinup_s, run_s) = match &cfg.mission {
        Some(m) => (m.spinup_s, m.spinup_s + m.time_limit_s),
        None => (0.0, cfg.sim.duration_s),
    };
    let start_s = n
        .start
        .as_deref()
        .map(plumetrace_netcdf::time::parse_date)
        .transpose()
        .map_err(|e| Invalid::new("flow.netcdf.start", e.to_string()))?
        .map(|t| t - spinup_s);
    let depth_m = n.depth_m.or_else(|| {
        let first = cfg.sources.first();
        let water = match seabed {
            // Over a seabed, the water's depth at the first source.
            Some(sb) => first.map_or(sb.surface_m(), |s| sb.depth_at(s.x_m, s.y_m)),
            None => cfg.domain.depth_m?,
        };
        let z = first.map_or(0.0, |s| s.z_m);
        Some((water - z).max(0.0))
    });
    let must_cover = op_area_rect(cfg, domain);
    Ok(CfOptions {
        frame,
        start_s,
        duration_s: run_s,
        depth_m,
        area: domain,
        must_cover,
        spacing_m: n.spacing_m,
        u_variable: n.u_variable,
        v_variable: n.v_variable,
    })
}

/// The op-area's bounding rectangle (the domain without one): where a file's grid must reach.
pub(super) fn op_area_rect(cfg: &ScenarioConfig, domain: Rect) -> Rect {
    match cfg.mission.as_ref().and_then(|m| m.op_area.as_ref()) {
        Some(pts) if !pts.is_empty() => {
            let fold = |k: usize, f: fn(f64, f64) -> f64, init: f64| {
                pts.iter().map(|p| p[k]).fold(init, f)
            };
            Rect {
                x_min_m: fold(0, f64::min, f64::INFINITY),
                x_max_m: fold(0, f64::max, f64::NEG_INFINITY),
                y_min_m: fold(1, f64::min, f64::INFINITY),
                y_max_m: fold(1, f64::max, f64::NEG_INFINITY),
            }
        }
        _ => domain,
    }
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
