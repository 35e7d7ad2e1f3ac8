//! `[plume]` and `[[sources]]`: the filament plume, the steady Gaussian plume or a gridded
//! concentration.

use super::Invalid;
use super::domain::DEPTH_KEY;
use super::flow::{MEAN_KEY, required_mean};
use crate::config::{PlumeKind, ScenarioConfig, SeabedKind};
use plumetrace_core::Vec3;
use plumetrace_env::plume::Dispersion;
use plumetrace_env::steady::{GaussianPlume, GriddedConcentration};
use plumetrace_env::{
    EnvError, FilamentParams, FilamentPlume, Plume, Rect, Seabed, Source, VerticalBoundary,
};
use std::path::Path;
use std::sync::Arc;

/// The plume of `[plume]` from the sources; a gridded concentration's file is read relative to
/// `base_dir`.
///
/// Over a seabed (`[bathymetry]`) a source's `z_m` is its height above the seabed where it is,
/// and the surface is the seabed's deepest water.
pub(super) fn plume(
    cfg: &ScenarioConfig,
    domain: Rect,
    base_dir: &Path,
    seabed: Option<Arc<Seabed>>,
) -> Result<Plume, Invalid> {
    let floor = |x: f64, y: f64| seabed.as_ref().map_or(0.0, |sb| sb.height_at(x, y));
    let sources: Vec<Source> = cfg
        .sources
        .iter()
        .map(|s| Source {
            pos_m: Vec3::new(s.x_m, s.y_m, s.z_m + floor(s.x_m, s.y_m)),
            mass_rate_per_s: s.mass_rate_per_s,
            filament_rate_hz: s.filament_rate_hz,
        })
        .collect();
    if sources.is_empty() && cfg.plume.model != PlumeKind::Gridded {
        return Err(Invalid::new(
            "sources",
            "at least one [[sources]] entry is needed",
        ));
    }
    match cfg.plume.model {
        PlumeKind::Filaments => filaments(cfg, domain, sources, seabed),
        PlumeKind::Gaussian => gaussian(cfg, &sources),
        PlumeKind::Gridded => {
            let Some(file) = &cfg.plume.file else {
                return Err(Invalid::new(
                    "plume.file",
                    "model = \"gridded\" needs a file (CSV: x_m,y_m[,z_m],concentration)",
                ));
            };
            let g = GriddedConcentration::from_csv(&base_dir.join(file))
                .map_err(|e| Invalid::new("plume.file", e.to_string()))?;
            Ok(Plume::Steady(Box::new(g)))
        }
    }
}

/// The filament plume, with its initial filaments released.
fn filaments(
    cfg: &ScenarioConfig,
    domain: Rect,
    sources: Vec<Source>,
    seabed: Option<Arc<Seabed>>,
) -> Result<Plume, Invalid> {
    let p = &cfg.plume;
    let dispersion = if p.pompy_compatible {
        Dispersion::PompyCompatible {
            scale_mps: [p.pompy_diff_scale_mps; 3],
        }
    } else {
        Dispersion::Physical {
            horizontal_m2ps: p.horizontal_diffusivity_m2ps,
            vertical_m2ps: p.vertical_diffusivity_m2ps,
        }
    };
    let vertical = match p.seabed {
        SeabedKind::Reflecting => VerticalBoundary::Reflecting {
            depth_m: match &seabed {
                Some(sb) => Some(sb.surface_m()),
                None => cfg.domain.depth_m,
            },
        },
        SeabedKind::None => VerticalBoundary::Unbounded,
    };
    let params = FilamentParams {
        dispersion,
        init_radius_m: p.init_radius_m,
        growth_rate_m2ps: p.growth_rate_m2ps,
        cutoff_radii: p.cutoff_radii,
        max_filaments: p.max_filaments,
        vertical,
    };
    if p.initial_filaments.saturating_mul(sources.len() as u64) > p.max_filaments as u64 {
        return Err(Invalid::new(
            "plume.initial_filaments",
            format!(
                "{} per source for {} sources is more than plume.max_filaments ({})",
                p.initial_filaments,
                sources.len(),
                p.max_filaments
            ),
        ));
    }
    let mut fp = FilamentPlume::new(domain, sources, params).map_err(plume_error)?;
    if seabed.is_some() {
        fp.set_seabed(seabed);
    }
    for k in 0..fp.sources().len() {
        fp.release_at_source(k, p.initial_filaments);
    }
    Ok(Plume::Filaments(Box::new(fp)))
}

/// The steady Gaussian plume of the one source in the mean flow.
fn gaussian(cfg: &ScenarioConfig, sources: &[Source]) -> Result<Plume, Invalid> {
    let p = &cfg.plume;
    let m = required_mean(&cfg.flow)?;
    let v = m.velocity_at(0.0);
    let toward = plumetrace_core::Heading::of_vector(v)
        .ok_or_else(|| Invalid::new(MEAN_KEY, "the gaussian plume needs a non-zero current"))?;
    if sources.len() > 1 {
        return Err(Invalid::new(
            "sources",
            "the gaussian plume takes exactly one source",
        ));
    }
    let s = sources[0];
    let g = GaussianPlume::new(
        s.pos_m,
        s.mass_rate_per_s,
        v.norm(),
        toward.deg(),
        p.horizontal_diffusivity_m2ps,
        p.vertical_diffusivity_m2ps,
        cfg.domain.depth_m,
    )
    .map_err(plume_error)?;
    Ok(Plume::Steady(Box::new(g)))
}

/// A plume model's error at its key: the plume's parameters under `plume`, its sources as
/// `sources[k]` (the Gaussian plume's one `source` as `sources[0]`), the current under
/// `flow.mean` and the water depth at `domain.depth_m`.
fn plume_error(e: EnvError) -> Invalid {
    let EnvError::InvalidParameter { key, message } = e else {
        return Invalid::new("plume", e.to_string());
    };
    let path = if let Some(field) = key.strip_prefix("source.") {
        format!("sources[0].{field}")
    } else if key.starts_with("sources") {
        key
    } else {
        match key.as_str() {
            "depth_m" => DEPTH_KEY.to_string(),
            "speed_mps" | "toward_deg" => format!("{MEAN_KEY}.{key}"),
            _ => format!("plume.{key}"),
        }
    };
    Invalid::new(path, message)
}
