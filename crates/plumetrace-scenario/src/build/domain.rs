//! `[domain]`: the rectangle the simulation covers and the water depth.

use super::Invalid;
use crate::config::DomainConfig;
use plumetrace_env::Rect;

/// The key path of the water depth (the plumes' surface).
pub(super) const DEPTH_KEY: &str = "domain.depth_m";

/// The domain's rectangle (`domain.depth_m` is the limits table's to bound).
pub(super) fn domain(d: &DomainConfig) -> Result<Rect, Invalid> {
    Rect::new(d.x_min_m, d.x_max_m, d.y_min_m, d.y_max_m).map_err(|e| Invalid::env("domain", e))
}
