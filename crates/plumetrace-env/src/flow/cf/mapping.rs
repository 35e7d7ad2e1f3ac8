//! A CF grid mapping on a projected grid: `transverse_mercator` (UTM and the rest, on WGS 84)
//! places the grid's eastings and northings through the core's transverse Mercator; another
//! mapping is refused by name. A projected grid with no `grid_mapping` is in the local frame.

use super::err;
use crate::EnvError;
use plumetrace_core::Vec2;
use plumetrace_core::geo::{LocalFrame, TmParams, TransverseMercator};
use plumetrace_netcdf::{NcFile, Var};
use std::path::Path;

/// WGS 84's semi-major axis, m, and inverse flattening, as a grid mapping may state them.
const WGS84: (f64, f64) = (6_378_137.0, 298.257_223_563);

/// The transverse Mercator of `var`'s `grid_mapping`, if it names one; `None` without one.
pub(crate) fn read(
    file: &NcFile,
    var: &Var,
    path: &Path,
) -> Result<Option<TransverseMercator>, EnvError> {
    let Some(attr) = var.text("grid_mapping") else {
        return Ok(None);
    };
    // The name alone, or CF's extended form `crs: x y`.
    let name = attr
        .split_whitespace()
        .next()
        .unwrap_or("")
        .trim_end_matches(':');
    let gm = file.var(name).ok_or_else(|| {
        err(
            path,
            format!(
                "variable {}: attribute grid_mapping = {attr:?} names no variable of the file",
                var.name
            ),
        )
    })?;
    let kind = gm.text("grid_mapping_name").unwrap_or("").trim();
    if kind != "transverse_mercator" {
        return Err(err(
            path,
            format!(
                "variable {}: its grid mapping {} is {kind:?}, which is not read (a projected \
                 grid is read in transverse_mercator, UTM among them, or with no grid_mapping \
                 as the local frame's x and y): regrid it to longitude and latitude or to the \
                 site's UTM zone",
                var.name, gm.name
            ),
        ));
    }
    let num = |key: &str, default: Option<f64>| -> Result<f64, EnvError> {
        match gm.attr(key).and_then(|a| a.as_numbers()) {
            Some(v) if v.len() == 1 && v[0].is_finite() => Ok(v[0]),
            Some(v) => Err(err(
                path,
                format!(
                    "variable {}: attribute {key} = {v:?} is not one finite number",
                    gm.name
                ),
            )),
            None => default.ok_or_else(|| {
                err(
                    path,
                    format!(
                        "variable {}: a transverse_mercator grid mapping needs attribute {key}",
                        gm.name
                    ),
                )
            }),
        }
    };
    let a = num("semi_major_axis", Some(WGS84.0))?;
    let inv_f = num("inverse_flattening", Some(WGS84.1))?;
    if (a - WGS84.0).abs() > 0.01 || (inv_f - WGS84.1).abs() > 1e-6 {
        return Err(err(
            path,
            format!(
                "variable {}: semi_major_axis = {a}, inverse_flattening = {inv_f} is not WGS 84 \
                 ({}, {}), the only ellipsoid read: reproject the grid to WGS 84",
                gm.name, WGS84.0, WGS84.1
            ),
        ));
    }
    let p = TmParams {
        central_meridian_deg: num("longitude_of_central_meridian", None)?,
        origin_lat_deg: num("latitude_of_projection_origin", None)?,
        scale: num("scale_factor_at_central_meridian", None)?,
        false_easting_m: num("false_easting", Some(0.0))?,
        false_northing_m: num("false_northing", Some(0.0))?,
    };
    // UTM's parameters are named as its zone.
    let zone = (p.central_meridian_deg + 183.0) / 6.0;
    let utm = p.origin_lat_deg == 0.0
        && p.scale == 0.9996
        && p.false_easting_m == 500_000.0
        && (p.false_northing_m == 0.0 || p.false_northing_m == 10_000_000.0)
        && zone == zone.round()
        && (1.0..=60.0).contains(&zone);
    let label = if utm {
        let h = if p.false_northing_m == 0.0 { 'N' } else { 'S' };
        format!("UTM zone {zone}{h}, grid mapping {}", gm.name)
    } else {
        format!("the transverse Mercator of grid mapping {}", gm.name)
    };
    let tm = if utm {
        TransverseMercator::utm(zone as i64, p.false_northing_m == 0.0)
    } else {
        TransverseMercator::new(p)
    };
    tm.map(|tm| Some(tm.named(&label)))
        .map_err(|e| err(path, format!("variable {}: {e}", gm.name)))
}

/// The turn from the local frame's east to the grid's `x` at the site's origin, as its sine
/// and cosine (the grid's convergence: UTM's grid north is up to a few degrees off true north).
pub(crate) fn grid_turn(tm: &TransverseMercator, frame: &LocalFrame) -> Option<(f64, f64)> {
    let o = frame.origin();
    let (e, n) = tm.forward(o.lat_deg, o.lon_deg).ok()?;
    let (lat, lon) = tm.inverse(e + 100.0, n).ok()?;
    let p = frame.to_local(lat, lon);
    let len = p.x.hypot(p.y);
    (len > 0.0).then(|| (p.y / len, p.x / len))
}

/// `(u, v)` along the grid's axes turned into the local frame by `(sin, cos)`.
pub(crate) fn turn((u, v): (f64, f64), (s, c): (f64, f64)) -> (f64, f64) {
    let r = Vec2::new(u * c - v * s, u * s + v * c);
    (r.x, r.y)
}

#[cfg(test)]
mod tests;
