//! `[bathymetry]`: a seabed that is not flat, read from a CF NetCDF file.

use super::Invalid;
use super::domain::DEPTH_KEY;
use crate::config::{PlumeKind, ScenarioConfig, SeabedKind};
use plumetrace_core::geo::LocalFrame;
use plumetrace_env::{Rect, Seabed, SeabedOptions};
use std::path::Path;
use std::sync::Arc;

/// The key path of the section.
const KEY: &str = "bathymetry";

/// The seabed of `[bathymetry]`, if given (its file read relative to `base_dir`).
pub(super) fn seabed(
    cfg: &ScenarioConfig,
    domain: Rect,
    base_dir: &Path,
) -> Result<Option<Arc<Seabed>>, Invalid> {
    let Some(b) = &cfg.bathymetry else {
        return Ok(None);
    };
    if cfg.domain.depth_m.is_some() {
        return Err(Invalid::new(
            DEPTH_KEY,
            "with [bathymetry] the water depth is the bathymetry's (the surface lies at the \
             deepest water over the domain); remove domain.depth_m",
        ));
    }
    if cfg.plume.model != PlumeKind::Filaments {
        return Err(Invalid::new(
            KEY,
            "a seabed that is not flat applies to the filament plume (plume.model = \
             \"filaments\") only",
        ));
    }
    if cfg.plume.seabed == SeabedKind::None {
        return Err(Invalid::new(
            KEY,
            "plume.seabed = \"none\" lets filaments through the seabed; a bathymetry needs the \
             reflecting seabed (remove plume.seabed)",
        ));
    }
    let frame = cfg
        .origin
        .map(LocalFrame::new)
        .transpose()
        .map_err(|e| Invalid::new("origin", e.to_string()))?;
    let o = SeabedOptions {
        frame,
        area: domain,
        must_cover: super::flow::op_area_rect(cfg, domain),
        spacing_m: b.spacing_m,
        variable: b.variable.clone(),
    };
    let seabed = Seabed::from_file(&base_dir.join(&b.file), &o)
        .map_err(|e| Invalid::new(format!("{KEY}.file"), e.to_string()))?;
    Ok(Some(Arc::new(seabed)))
}
