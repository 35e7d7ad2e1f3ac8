//! The seabed: its height over the simulated area, from a bathymetry grid in a CF NetCDF file
//! (rectilinear or curvilinear) or a GeoTIFF on longitude and latitude ([`geotiff`]).
//!
//! Heights are measured from a datum, the deepest point of the seabed over the simulated area
//! (so the seabed is at `z >= 0` everywhere and `z = 0` at its deepest), and the surface is at
//! `z =` [`Seabed::surface_m`], that deepest water depth. Without a seabed grid the seabed is
//! flat at `z = 0`, as it always was: the flat case takes none of this code.
//!
//! The file's depth variable is found by its CF `standard_name`
//! (`sea_floor_depth_below_sea_surface` and its kin, positive down; or an elevation such as
//! GEBCO's `height_above_reference_ellipsoid`, negative below sea level) or by a usual name
//! (`depth`, `h`, `bathymetry`, `elevation`, `z`), on longitude and latitude or projected x and
//! y. It is sampled bilinearly onto an even grid over the simulated area. The op-area must lie
//! inside the file's grid, and every node near it must be water (no fill value, a depth above
//! zero); elsewhere a node outside the grid takes the nearest edge value, and land or a missing
//! value takes the shallowest water depth of the grid.

use crate::flow::cell_weight;
use crate::flow::cf::{axes, bilinear, err, expand, length_scale, place};
use crate::{EnvError, Rect};
use plumetrace_core::geo::LocalFrame;
use plumetrace_netcdf::{NcFile, Var, nearest};
use std::path::Path;

/// Standard names of a depth of the seabed below the surface (positive down).
const DEPTH_NAMES: &[&str] = &[
    "sea_floor_depth_below_sea_surface",
    "sea_floor_depth_below_geoid",
    "sea_floor_depth_below_mean_sea_level",
    "sea_floor_depth_below_reference_ellipsoid",
    "sea_floor_depth",
    "depth",
];

/// Standard names of a height of the ground (positive up, negative below sea level).
const ELEVATION_NAMES: &[&str] = &[
    "height_above_reference_ellipsoid",
    "height_above_mean_sea_level",
    "height_above_geoid",
    "altitude",
    "bedrock_altitude",
    "surface_altitude",
];

/// Variable names taken when no standard name says (first found), with whether they are depths.
const USUAL_NAMES: &[(&str, bool)] = &[
    ("depth", true),
    ("h", true),
    ("bathymetry", true),
    ("elevation", false),
    ("z", false),
    ("topo", false),
];

/// At most this many nodes a side in the seabed grid.
pub const MAX_NODES_PER_SIDE: usize = crate::flow::cf::MAX_NODES_PER_SIDE;

/// How to read a bathymetry file.
#[derive(Debug, Clone)]
pub struct SeabedOptions {
    /// The site's origin, for grids in longitude and latitude.
    pub frame: Option<LocalFrame>,
    /// The simulated area the seabed covers.
    pub area: Rect,
    /// The op-area: inside the file's grid, and water everywhere.
    pub must_cover: Rect,
    /// Node spacing, m (`None`: the file's own spacing near the origin).
    pub spacing_m: Option<f64>,
    /// The depth's variable (`None`: found by standard name or a usual name).
    pub variable: Option<String>,
}

/// The seabed's height above its datum on an even grid over the simulated area.
#[derive(Debug, Clone, PartialEq)]
pub struct Seabed {
    x0: f64,
    dx: f64,
    nx: usize,
    y0: f64,
    dy: f64,
    ny: usize,
    /// Heights above the datum, m, row by row from the south.
    height: Vec<f64>,
    /// The surface's height above the datum (the deepest water depth), m.
    surface_m: f64,
}

impl Seabed {
    /// The deepest water a seabed may hold, m: the deepest ocean. A deeper value in a file is a
    /// unit or a sign gone wrong (and its surface would be where no filament's height could be
    /// kept to the millimetre).
    pub const MAX_DEPTH_M: f64 = 11_000.0;

    /// A seabed from water depths (positive, m) at the `nx * ny` nodes of an even grid over
    /// `area`, row by row from the south. Errors name `depths[k]` or the grid's size.
    pub fn from_depths(area: Rect, nx: usize, ny: usize, depths: &[f64]) -> Result<Self, EnvError> {
        if nx < 2 || ny < 2 || nx > MAX_NODES_PER_SIDE || ny > MAX_NODES_PER_SIDE {
            return Err(EnvError::invalid(
                "nodes",
                format!("{nx} x {ny}: 2 to {MAX_NODES_PER_SIDE} nodes a side"),
            ));
        }
        if depths.len() != nx * ny {
            return Err(EnvError::invalid(
                "depths",
                format!("{} values for {nx} x {ny} nodes", depths.len()),
            ));
        }
        let valid = |d: f64| d.is_finite() && d > 0.0 && d <= Self::MAX_DEPTH_M;
        if let Some(k) = depths.iter().position(|&d| !valid(d)) {
            return Err(EnvError::invalid(
                format!("depths[{k}]"),
                format!(
                    "must be a finite depth > 0 m and at most {} m (the deepest ocean), got {:?}",
                    Self::MAX_DEPTH_M,
                    depths[k]
                ),
            ));
        }
        let surface_m = depths.iter().copied().fold(0.0, f64::max);
        Ok(Seabed {
            x0: area.x_min_m,
            dx: area.width_m() / (nx - 1) as f64,
            nx,
            y0: area.y_min_m,
            dy: area.height_m() / (ny - 1) as f64,
            ny,
            height: depths.iter().map(|d| surface_m - d).collect(),
            surface_m,
        })
    }

    /// The seabed's height above the datum at `(x, y)`, m: bilinear between the nodes, the edge
    /// value beyond the grid. Never below 0 nor above the surface.
    #[inline]
    pub fn height_at(&self, x: f64, y: f64) -> f64 {
        // The flow grid's cell lookup (a NaN position lands on node 0, so no query panics).
        let (i, tx) = cell_weight((x - self.x0) / self.dx, self.nx);
        let (j, ty) = cell_weight((y - self.y0) / self.dy, self.ny);
        let h = |a: usize, b: usize| self.height[b * self.nx + a];
        let south = h(i, j) + tx * (h(i + 1, j) - h(i, j));
        let north = h(i, j + 1) + tx * (h(i + 1, j + 1) - h(i, j + 1));
        south + ty * (north - south)
    }

    /// The water depth at `(x, y)`, m.
    pub fn depth_at(&self, x: f64, y: f64) -> f64 {
        self.surface_m - self.height_at(x, y)
    }

    /// The surface's height above the datum: the deepest water depth over the area, m.
    pub fn surface_m(&self) -> f64 {
        self.surface_m
    }

    /// The shallowest water depth over the area, m.
    pub fn shallowest_m(&self) -> f64 {
        self.surface_m - self.height.iter().copied().fold(0.0, f64::max)
    }

    /// Nodes a side, `(nx, ny)`.
    pub fn nodes(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// Reads a seabed from a CF NetCDF classic file (see the module docs).
    pub fn from_netcdf(path: &Path, o: &SeabedOptions) -> Result<Self, EnvError> {
        crate::input::check_file(path, crate::input::MAX_DATA_BYTES)
            .map_err(|e| err(path, e.to_string()))?;
        let bytes = std::fs::read(path).map_err(|e| err(path, e.to_string()))?;
        let file = NcFile::parse(bytes).map_err(|e| err(path, e.to_string()))?;
        let (var, is_depth) = depth_var(&file, o, path)?;
        let a = axes(&file, var, path)?;
        for (what, axis) in [("time", &a.time), ("depth", &a.depth)] {
            if let Some((pos, vals)) = axis
                && vals.len() > 1
            {
                return Err(err(
                    path,
                    format!(
                        "variable {}: dimension {} is a {what} axis of {} values; a seabed is one \
                         2-D grid (select one {what} first)",
                        var.name,
                        file.dims[var.dims[*pos]].name,
                        vals.len()
                    ),
                ));
            }
        }
        let depths = read_depths(&file, var, is_depth, path)?;
        let (px, py) = match (&a.x, &a.y) {
            (Some((px, _)), Some((py, _))) => (*px, *py),
            _ => return Err(err(path, "the bathymetry has no horizontal grid")),
        };
        let shape = file.shape(var);
        let mut strides = vec![1; shape.len()];
        for k in (0..shape.len().saturating_sub(1)).rev() {
            strides[k] = strides[k + 1] * shape[k + 1];
        }
        let at = |i: usize, j: usize| depths[i * strides[px] + j * strides[py]];
        sample(&format!("variable {}", var.name), &a, &at, o, path)
    }

    /// Reads a seabed from a bathymetry file: a GeoTIFF (by its first bytes, see [`geotiff`])
    /// or else a CF NetCDF classic file ([`Seabed::from_netcdf`]).
    pub fn from_file(path: &Path, o: &SeabedOptions) -> Result<Self, EnvError> {
        if geotiff::is_tiff(path) {
            geotiff::read(path, o)
        } else {
            Self::from_netcdf(path, o)
        }
    }
}

/// The depth variable and whether it is a depth (positive down) rather than an elevation.
fn depth_var<'f>(
    file: &'f NcFile,
    o: &SeabedOptions,
    path: &Path,
) -> Result<(&'f Var, bool), EnvError> {
    let names = || file.vars.iter().map(|v| v.name.as_str());
    let positive = |v: &Var, default: bool| match v.text("positive").map(str::trim) {
        Some(p) if p.eq_ignore_ascii_case("up") => false,
        Some(p) if p.eq_ignore_ascii_case("down") => true,
        _ => default,
    };
    if let Some(name) = &o.variable {
        let v = file.var(name).ok_or_else(|| {
            let hint = nearest(name, names())
                .map(|n| format!("; did you mean {n:?}?"))
                .unwrap_or_else(|| format!("; it has {}", names().collect::<Vec<_>>().join(", ")));
            err(
                path,
                format!("bathymetry.variable = {name:?}: no such variable{hint}"),
            )
        })?;
        let sn = v.text("standard_name").unwrap_or("").trim();
        let default = !ELEVATION_NAMES.contains(&sn)
            && USUAL_NAMES
                .iter()
                .find(|(n, _)| *n == v.name)
                .is_none_or(|(_, d)| *d);
        return Ok((v, positive(v, default)));
    }
    let grid = |v: &&Var| v.dims.len() >= 2;
    let by_standard = file.vars.iter().filter(grid).find_map(|v| {
        let sn = v.text("standard_name").unwrap_or("").trim();
        if DEPTH_NAMES.contains(&sn) {
            Some((v, positive(v, true)))
        } else if ELEVATION_NAMES.contains(&sn) {
            Some((v, positive(v, false)))
        } else {
            None
        }
    });
    let by_name = || {
        USUAL_NAMES.iter().find_map(|(n, d)| {
            file.var(n)
                .filter(|v| v.dims.len() >= 2)
                .map(|v| (v, positive(v, *d)))
        })
    };
    by_standard.or_else(by_name).ok_or_else(|| {
        let list: Vec<String> = file
            .vars
            .iter()
            .map(|v| match v.text("standard_name") {
                Some(sn) => format!("{} ({sn})", v.name),
                None => v.name.clone(),
            })
            .collect();
        err(
            path,
            format!(
                "no seabed depth: no variable with standard_name \
                 sea_floor_depth_below_sea_surface (or an elevation such as \
                 height_above_reference_ellipsoid), nor one named depth, h, bathymetry, \
                 elevation or z; the file has {}; name it with bathymetry.variable",
                list.join(", ")
            ),
        )
    })
}

/// The variable's values as water depths in metres (positive down), NaN where missing.
fn read_depths(
    file: &NcFile,
    var: &Var,
    is_depth: bool,
    path: &Path,
) -> Result<Vec<f64>, EnvError> {
    let raw = file.values(var).map_err(|e| err(path, e.to_string()))?;
    let num = |name: &str, finite: bool| -> Result<Option<Vec<f64>>, EnvError> {
        let Some(a) = var.attr(name) else {
            return Ok(None);
        };
        a.as_numbers()
            .filter(|v| !v.is_empty() && (!finite || v.iter().all(|x| x.is_finite())))
            .map(Some)
            .ok_or_else(|| {
                err(
                    path,
                    format!(
                        "variable {}: attribute {name} is not a finite number",
                        var.name
                    ),
                )
            })
    };
    let scale = num("scale_factor", true)?.map_or(1.0, |v| v[0]);
    let offset = num("add_offset", true)?.map_or(0.0, |v| v[0]);
    let mut missing = num("_FillValue", false)?.unwrap_or_default();
    missing.extend(num("missing_value", false)?.unwrap_or_default());
    if var.text("units").is_none() {
        return Err(err(
            path,
            format!(
                "variable {}: no attribute units (m or km expected)",
                var.name
            ),
        ));
    }
    let to_m = length_scale(var, path)? * if is_depth { 1.0 } else { -1.0 };
    Ok(raw
        .iter()
        .map(|&r| {
            // The netCDF default fill of floats and doubles is 9.97e36.
            if r.is_nan() || missing.contains(&r) || r.abs() > 1e30 {
                f64::NAN
            } else {
                (r * scale + offset) * to_m
            }
        })
        .collect())
}

/// The depths sampled onto an even grid over the simulated area.
/// `what` names the depths in a message (`variable h`); `at(i, j)` is the water depth at the
/// file's node `(i, j)` (positive down, NaN where missing).
fn sample(
    what: &str,
    a: &crate::flow::cf::Axes,
    at: &dyn Fn(usize, usize) -> f64,
    o: &SeabedOptions,
    path: &Path,
) -> Result<Seabed, EnvError> {
    let (g, cells) = place(
        a,
        o.frame.as_ref(),
        o.spacing_m,
        o.area,
        o.must_cover,
        "the bathymetry's",
        "the bathymetry is on a longitude/latitude grid: give the site's origin \
         ([origin] lat_deg and lon_deg) to place it in the local frame",
        path,
    )?;
    let (area, nx, ny, dx, dy) = (o.area, g.nx, g.ny, g.dx, g.dy);
    let reach = expand(&o.must_cover, dx.max(dy));
    let n = a.len_xy();
    let mut out = Vec::with_capacity(nx * ny);
    let mut dry = Vec::new();
    for (k, &cell) in cells.iter().enumerate() {
        let (x, y) = (
            area.x_min_m + (k % nx) as f64 * dx,
            area.y_min_m + (k / nx) as f64 * dy,
        );
        let d = bilinear(cell, n, at);
        if !(d.is_finite() && d > 0.0) {
            if reach.contains_xy(x, y) {
                return Err(err(
                    path,
                    if d.is_nan() {
                        format!(
                            "{what}: a missing value (_FillValue or missing_value) at \
                             ({x:.1}, {y:.1}) m, where the op-area needs the seabed"
                        )
                    } else {
                        format!(
                            "{what}: the seabed is at or above the surface (depth \
                             {d:.2} m: land) at ({x:.1}, {y:.1}) m, inside the op-area; \
                             check the sign (a depth is positive down, an elevation \
                             negative below sea level: attribute positive = \"up\" or \
                             \"down\" says which)"
                        )
                    },
                ));
            }
            dry.push(out.len());
        } else if d > Seabed::MAX_DEPTH_M {
            return Err(err(
                path,
                format!(
                    "{what}: a depth of {d:.1} m at ({x:.1}, {y:.1}) m, deeper than the deepest \
                     ocean ({} m): check the values' units (metres) and sign",
                    Seabed::MAX_DEPTH_M
                ),
            ));
        }
        out.push(d);
    }
    let shallowest = out
        .iter()
        .copied()
        .filter(|d| d.is_finite() && *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    for k in dry {
        out[k] = shallowest;
    }
    Seabed::from_depths(area, nx, ny, &out).map_err(|e| err(path, e.to_string()))
}

mod geotiff;

#[cfg(test)]
mod tests;
