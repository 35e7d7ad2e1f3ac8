//! Currents from a CF-convention NetCDF classic file (an ocean model's output) sampled into a
//! [`GriddedFlow`].
//!
//! The eastward and northward velocities are found by their CF `standard_name`
//! (`eastward_sea_water_velocity` and `northward_sea_water_velocity`, or `sea_water_x_velocity`
//! and `sea_water_y_velocity` on a projected grid) or named by the caller. Their dimensions are
//! recognised by their coordinate variables: longitude and latitude (degrees) or projected `x`
//! and `y` (metres or kilometres), or 2-D longitude and latitude arrays of a curvilinear grid
//! ([`curvilinear`]), depth (a level axis, interpolated linearly to the asked depth, or
//! terrain-following levels placed column by column, [`sigma`]), time (CF `units = "<unit> since <date>"`, frames kept from the mission's start to its
//! end). Values are unpacked (`scale_factor`, `add_offset`), converted to m/s from their
//! `units` (m s-1, cm s-1, mm s-1, knots), and `_FillValue` / `missing_value` are missing.
//!
//! A projected grid in a `transverse_mercator` grid mapping (UTM and the rest, [`mapping`])
//! holds eastings and northings and is placed through the site's origin as a longitude/latitude
//! grid is. A projected grid without one is in the local frame: evenly spaced, it is used node
//! for node (so a file holding the same numbers as a CSV grid gives the same flow, bit for
//! bit); otherwise the field is resampled,
//! bilinearly, onto an even grid in the local frame over the simulated area, each node placed in
//! latitude and longitude through the site's origin. The op-area must lie inside the file's grid
//! and may touch no missing value; elsewhere in the simulated area a node outside the grid takes
//! the nearest edge value and a missing value (land) is still water. The direction of east at a
//! node is taken as the local `x` (the meridians' convergence over a few kilometres is a few
//! hundredths of a degree).

use super::gridded::{Frame, GriddedFlow};
use crate::{EnvError, Rect};
use plumetrace_core::Vec2;
use plumetrace_core::geo::{LocalFrame, ProjectionError, TransverseMercator};
use plumetrace_netcdf::time::TimeUnits;
use plumetrace_netcdf::{NcFile, Var, nearest};
use std::path::Path;

/// The standard names of velocity pairs, east then north.
const STANDARD_NAMES: &[(&str, &str)] = &[
    (
        "eastward_sea_water_velocity",
        "northward_sea_water_velocity",
    ),
    ("sea_water_x_velocity", "sea_water_y_velocity"),
    ("x_sea_water_velocity", "y_sea_water_velocity"),
    (
        "surface_eastward_sea_water_velocity",
        "surface_northward_sea_water_velocity",
    ),
];

/// At most this many nodes a side in a resampled grid.
pub const MAX_NODES_PER_SIDE: usize = 2000;

/// How to read and sample a CF currents file.
#[derive(Debug, Clone)]
pub struct CfOptions {
    /// The site's origin, for grids in longitude and latitude.
    pub frame: Option<LocalFrame>,
    /// The mission's start, seconds since 1970-01-01 UTC (`None`: the file's first time).
    pub start_s: Option<f64>,
    /// The mission's length, s: the file's frames must reach its end.
    pub duration_s: f64,
    /// Depth below the surface to sample at, m (needed when the file has several levels).
    pub depth_m: Option<f64>,
    /// The simulated area, resampled when the grid is not used node for node.
    pub area: Rect,
    /// The op-area: inside the grid and free of missing values.
    pub must_cover: Rect,
    /// Spacing of a resampled grid, m (`None`: the file's own spacing near the origin).
    pub spacing_m: Option<f64>,
    /// The eastward velocity's variable (`None`: found by standard name).
    pub u_variable: Option<String>,
    /// The northward velocity's variable (`None`: found by standard name).
    pub v_variable: Option<String>,
}

/// What a dimension of the velocity is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Axis {
    Time,
    Depth,
    Lon,
    Lat,
    X,
    Y,
    /// A dimension of length 1 with no coordinate.
    Single,
}

/// The velocity's axes: for each kind, its position in the variable's dimensions and values.
#[derive(Debug, Default)]
pub(crate) struct Axes {
    /// (position, values in epoch seconds)
    pub(crate) time: Option<(usize, Vec<f64>)>,
    /// (position, depths in metres, positive down)
    pub(crate) depth: Option<(usize, Vec<f64>)>,
    /// (position, values: degrees or metres)
    pub(crate) x: Option<(usize, Vec<f64>)>,
    pub(crate) y: Option<(usize, Vec<f64>)>,
    pub(crate) geographic: bool,
    /// The projection of a projected grid in a mapped frame (a UTM GeoTIFF, a CF
    /// `transverse_mercator` grid mapping): `x` and `y` hold eastings and northings, placed
    /// through the site's origin; `None` for a grid in the local frame itself.
    pub(crate) projection: Option<TransverseMercator>,
    /// A curvilinear grid's 2-D coordinates (then `x` and `y` hold node indices).
    pub(crate) curvi: Option<curvilinear::Curvilinear>,
    /// Terrain-following levels (then `depth` holds the level coordinate).
    pub(crate) sigma: Option<sigma::Sigma>,
}

/// Where in the vertical a field is read: a level and the weight towards the next, or a depth
/// in terrain-following levels (found column by column).
#[derive(Debug, Clone, Copy)]
enum Levels<'a> {
    Fixed((usize, f64)),
    Sigma(&'a sigma::Sigma, f64),
}

/// A located error in the file.
pub(crate) fn err(path: &Path, message: impl Into<String>) -> EnvError {
    EnvError::File {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

impl GriddedFlow {
    /// Reads currents from a CF NetCDF classic file (see the module docs).
    pub fn from_netcdf(path: &Path, o: &CfOptions) -> Result<Self, EnvError> {
        crate::input::check_file(path, crate::input::MAX_DATA_BYTES)
            .map_err(|e| err(path, e.to_string()))?;
        let bytes = std::fs::read(path).map_err(|e| err(path, e.to_string()))?;
        let file = NcFile::parse(bytes).map_err(|e| err(path, e.to_string()))?;
        let (u, v) = velocity_vars(&file, o, path)?;
        let axes = axes(&file, u, path)?;
        if file.shape(v) != file.shape(u) || v.dims != u.dims {
            return Err(err(
                path,
                format!(
                    "variables {} and {} have different dimensions; both need the same grid",
                    u.name, v.name
                ),
            ));
        }
        let uf = Field::read(&file, u, path)?;
        let vf = Field::read(&file, v, path)?;
        let (times, keep) = frames_kept(&axes, o, path)?;
        // Velocities along a mapped grid's axes are turned to east and north at the origin.
        let along_grid = ["sea_water_x_velocity", "x_sea_water_velocity"]
            .contains(&u.text("standard_name").unwrap_or("").trim());
        let turn = match (&axes.projection, o.frame.as_ref()) {
            (Some(tm), Some(f)) if along_grid => mapping::grid_turn(tm, f),
            _ => None,
        };
        sample(&axes, &uf, &vf, &times, keep, turn, o, path)
    }
}

/// The u and v variables: named, or found by standard name.
fn velocity_vars<'f>(
    file: &'f NcFile,
    o: &CfOptions,
    path: &Path,
) -> Result<(&'f Var, &'f Var), EnvError> {
    let names = || file.vars.iter().map(|v| v.name.as_str());
    let by_name = |name: &str, key: &str| {
        file.var(name).ok_or_else(|| {
            let hint = nearest(name, names())
                .map(|n| format!("; did you mean {n:?}?"))
                .unwrap_or_else(|| format!("; it has {}", names().collect::<Vec<_>>().join(", ")));
            err(
                path,
                format!("flow.netcdf.{key} = {name:?}: no such variable{hint}"),
            )
        })
    };
    let by_standard = |sn: &str| {
        file.vars
            .iter()
            .find(|v| v.text("standard_name").map(str::trim) == Some(sn))
    };
    let found = STANDARD_NAMES
        .iter()
        .find_map(|(e, n)| Some((by_standard(e)?, by_standard(n)?)));
    let (u, v) = match (&o.u_variable, &o.v_variable, found) {
        (Some(a), Some(b), _) => (by_name(a, "u_variable")?, by_name(b, "v_variable")?),
        (Some(a), None, Some((_, v))) => (by_name(a, "u_variable")?, v),
        (None, Some(b), Some((u, _))) => (u, by_name(b, "v_variable")?),
        (None, None, Some(pair)) => pair,
        _ => {
            let list: Vec<String> = file
                .vars
                .iter()
                .map(|v| match v.text("standard_name") {
                    Some(sn) => format!("{} ({sn})", v.name),
                    None => v.name.clone(),
                })
                .collect();
            return Err(err(
                path,
                format!(
                    "no variables with standard_name eastward_sea_water_velocity and \
                     northward_sea_water_velocity (or sea_water_x_velocity and \
                     sea_water_y_velocity); the file has {}; name them with \
                     flow.netcdf.u_variable and v_variable",
                    list.join(", ")
                ),
            ));
        }
    };
    Ok((u, v))
}

/// Classifies a coordinate variable.
fn axis_of(c: &Var) -> Option<Axis> {
    let sn = c.text("standard_name").unwrap_or("").trim();
    let units = c.text("units").unwrap_or("").trim().to_ascii_lowercase();
    let axis = c.text("axis").unwrap_or("").trim().to_ascii_uppercase();
    let degrees_east = ["degrees_east", "degree_east", "degree_e", "degrees_e"];
    let degrees_north = ["degrees_north", "degree_north", "degree_n", "degrees_n"];
    Some(
        if sn == "time" || units.contains(" since ") || axis == "T" {
            Axis::Time
        } else if sn == "longitude" || degrees_east.contains(&units.as_str()) {
            Axis::Lon
        } else if sn == "latitude" || degrees_north.contains(&units.as_str()) {
            Axis::Lat
        } else if sn == "projection_x_coordinate" || axis == "X" {
            Axis::X
        } else if sn == "projection_y_coordinate" || axis == "Y" {
            Axis::Y
        } else if sn == "depth" || sn == "height" || axis == "Z" || c.text("positive").is_some() {
            Axis::Depth
        } else {
            return None;
        },
    )
}

/// Metres per unit of a projected or depth coordinate.
pub(crate) fn length_scale(c: &Var, path: &Path) -> Result<f64, EnvError> {
    match c
        .text("units")
        .map(|u| u.trim().to_ascii_lowercase())
        .as_deref()
    {
        None | Some("m" | "meter" | "meters" | "metre" | "metres") => Ok(1.0),
        Some("km" | "kilometer" | "kilometers" | "kilometre" | "kilometres") => Ok(1000.0),
        Some(other) => Err(err(
            path,
            format!(
                "variable {}: attribute units = {other:?} is not a length (m or km)",
                c.name
            ),
        )),
    }
}

/// What dimension `d` of `u` is, from its coordinate variable `coord`.
fn dim_kind(
    file: &NcFile,
    u: &Var,
    d: usize,
    coord: Option<&Var>,
    path: &Path,
) -> Result<Axis, EnvError> {
    let dim = &file.dims[d];
    Ok(match coord {
        Some(c) => {
            let sn = c.text("standard_name").unwrap_or("");
            if sigma::is_known(sn) {
                return Ok(Axis::Depth);
            }
            if sn.contains("sigma") || sn.contains("s_coordinate") {
                return Err(err(
                    path,
                    format!(
                        "dimension {}: variable {} is a terrain-following level of \
                         standard_name {sn}, which is not read (ocean_sigma_coordinate, \
                         ocean_s_coordinate_g1 and ocean_s_coordinate_g2 are): interpolate the \
                         file to depth levels first",
                        dim.name, c.name
                    ),
                ));
            }
            axis_of(c).ok_or_else(|| {
                err(
                    path,
                    format!(
                        "dimension {} of variable {}: its coordinate variable has no \
                         standard_name, units or axis that says time, depth, longitude, \
                         latitude, x or y",
                        dim.name, u.name
                    ),
                )
            })?
        }
        None if dim.len == 1 => Axis::Single,
        None => {
            return Err(err(
                path,
                format!(
                    "dimension {} of variable {} has no coordinate variable (a 1-D variable of \
                     the same name), and no 2-D longitude and latitude span it",
                    dim.name, u.name
                ),
            ));
        }
    })
}

/// The velocity's axes, from the coordinate variables of its dimensions.
pub(crate) fn axes(file: &NcFile, u: &Var, path: &Path) -> Result<Axes, EnvError> {
    let mut a = Axes {
        curvi: curvilinear::find(file, u, path)?,
        ..Axes::default()
    };
    let mut kinds = Vec::new();
    let mut sigma_level = None;
    for (pos, &d) in u.dims.iter().enumerate() {
        let dim = &file.dims[d];
        if let Some(c) = &a.curvi
            && c.dims.contains(&d)
        {
            // Node indices stand for the coordinates; the grid holds the rest.
            let (is_x, geo) = (d == c.dims[1], c.geographic);
            kinds.push(match (is_x, geo) {
                (true, true) => Axis::Lon,
                (false, true) => Axis::Lat,
                (true, false) => Axis::X,
                (false, false) => Axis::Y,
            });
            a.geographic = geo;
            let idx = (0..dim.len).map(|k| k as f64).collect();
            *(if is_x { &mut a.x } else { &mut a.y }) = Some((pos, idx));
            continue;
        }
        let coord = file
            .var(&dim.name)
            .filter(|c| c.dims.len() == 1 && c.dims[0] == d);
        let kind = dim_kind(file, u, d, coord, path)?;
        if kind != Axis::Single && kinds.contains(&kind) {
            return Err(err(
                path,
                format!("variable {}: two of its dimensions are {kind:?}", u.name),
            ));
        }
        kinds.push(kind);
        let Some(c) = coord else { continue };
        let vals = file.values(c).map_err(|e| err(path, e.to_string()))?;
        let finite = |vals: Vec<f64>| -> Result<Vec<f64>, EnvError> {
            if vals.iter().all(|x| x.is_finite()) {
                Ok(vals)
            } else {
                Err(err(
                    path,
                    format!("variable {}: a value is not finite", c.name),
                ))
            }
        };
        match kind {
            Axis::Time => {
                let units = c.text("units").unwrap_or("");
                let tu = TimeUnits::parse(units)
                    .map_err(|e| err(path, format!("variable {}: attribute {e}", c.name)))?;
                a.time = Some((
                    pos,
                    finite(vals)?.iter().map(|&t| tu.to_epoch_s(t)).collect(),
                ));
            }
            Axis::Depth if sigma::is_known(c.text("standard_name").unwrap_or("")) => {
                a.depth = Some((pos, finite(vals)?));
                sigma_level = Some(c);
            }
            Axis::Depth => {
                let up = c
                    .text("positive")
                    .is_some_and(|p| p.trim().eq_ignore_ascii_case("up"));
                let s = length_scale(c, path)? * if up { -1.0 } else { 1.0 };
                a.depth = Some((pos, finite(vals)?.iter().map(|z| z * s).collect()));
            }
            Axis::Lon | Axis::Lat => {
                a.geographic = true;
                let slot = if kind == Axis::Lon {
                    &mut a.x
                } else {
                    &mut a.y
                };
                *slot = Some((pos, finite(vals)?));
            }
            Axis::X | Axis::Y => {
                let s = length_scale(c, path)?;
                let slot = if kind == Axis::X { &mut a.x } else { &mut a.y };
                *slot = Some((pos, finite(vals)?.iter().map(|x| x * s).collect()));
            }
            Axis::Single => {}
        }
    }
    let mixed = kinds.contains(&Axis::Lon) != kinds.contains(&Axis::Lat)
        || (a.geographic && (kinds.contains(&Axis::X) || kinds.contains(&Axis::Y)));
    if a.x.is_none() || a.y.is_none() || mixed {
        return Err(err(
            path,
            format!(
                "variable {}: its dimensions ({}) need longitude and latitude, or projected x \
                 and y",
                u.name,
                u.dims
                    .iter()
                    .map(|&d| file.dims[d].name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    if !a.geographic && a.curvi.is_none() {
        a.projection = mapping::read(file, u, path)?;
    }
    if let (Some(level), Some((px, _)), Some((py, _))) = (sigma_level, &a.x, &a.y) {
        let roles = sigma::Roles {
            time: a.time.as_ref().map(|(p, _)| u.dims[*p]),
            x: u.dims[*px],
            y: u.dims[*py],
        };
        a.sigma = Some(sigma::Sigma::read(file, level, u, &roles, path)?);
    }
    for (name, axis) in [
        ("x", &a.x),
        ("y", &a.y),
        ("depth", &a.depth),
        ("time", &a.time),
    ] {
        if let Some((pos, vals)) = axis {
            let mono = vals.windows(2).all(|w| w[1] > w[0]) || vals.windows(2).all(|w| w[1] < w[0]);
            if !mono || (name == "time" && vals.windows(2).any(|w| w[1] <= w[0])) {
                return Err(err(
                    path,
                    format!(
                        "dimension {}: its coordinate values are not strictly {}",
                        file.dims[u.dims[*pos]].name,
                        if name == "time" {
                            "increasing"
                        } else {
                            "monotonic"
                        }
                    ),
                ));
            }
        }
    }
    Ok(a)
}

/// One velocity component in m/s, NaN where missing, with its dimension strides.
struct Field {
    values: Vec<f64>,
    strides: Vec<usize>,
}

impl Field {
    fn read(file: &NcFile, var: &Var, path: &Path) -> Result<Self, EnvError> {
        let raw = file.values(var).map_err(|e| err(path, e.to_string()))?;
        // Numbers of an attribute; a scale or offset must be one finite number.
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
        let units = var.text("units").ok_or_else(|| {
            err(
                path,
                format!(
                    "variable {}: no attribute units (m s-1 or cm s-1 expected)",
                    var.name
                ),
            )
        })?;
        let to_mps = velocity_scale(units).ok_or_else(|| {
            err(
                path,
                format!(
                    "variable {}: attribute units = {units:?} is not a velocity unit (m s-1, \
                     cm s-1, mm s-1 or knots)",
                    var.name
                ),
            )
        })?;
        let values: Vec<f64> = raw
            .iter()
            .map(|&r| {
                // The netCDF default fill of floats and doubles is 9.97e36.
                if r.is_nan() || missing.contains(&r) || r.abs() > 1e30 {
                    f64::NAN
                } else {
                    (r * scale + offset) * to_mps
                }
            })
            .collect();
        if let Some(k) = values.iter().position(|x| x.abs() > 10.0) {
            return Err(err(
                path,
                format!(
                    "variable {}: value {} m/s at index {k}; ocean currents are below 10 m/s \
                     (check its units, scale_factor and add_offset)",
                    var.name, values[k]
                ),
            ));
        }
        let shape = file.shape(var);
        let mut strides = vec![1; shape.len()];
        for k in (0..shape.len().saturating_sub(1)).rev() {
            strides[k] = strides[k + 1] * shape[k + 1];
        }
        Ok(Field { values, strides })
    }

    /// The value at time index `t`, depth `d` (level and weight towards the next), node `(i, j)`.
    fn at(&self, axes: &Axes, t: usize, d: Levels, i: usize, j: usize) -> f64 {
        let d = match d {
            Levels::Fixed(d) => d,
            Levels::Sigma(s, z) => match s.weight(z, t, i, j) {
                Some(d) => d,
                None => return f64::NAN,
            },
        };
        let mut base = 0;
        if let Some((p, _)) = axes.time {
            base += t * self.strides[p];
        }
        base += i * self.strides[axes.x.as_ref().map_or(0, |a| a.0)];
        base += j * self.strides[axes.y.as_ref().map_or(0, |a| a.0)];
        match axes.depth {
            Some((p, _)) => {
                let a = self.values[base + d.0 * self.strides[p]];
                if d.1 == 0.0 {
                    a
                } else {
                    let b = self.values[base + (d.0 + 1) * self.strides[p]];
                    a + d.1 * (b - a)
                }
            }
            None => self.values[base],
        }
    }
}

/// Metres per second of a velocity unit.
fn velocity_scale(units: &str) -> Option<f64> {
    let u: String = units
        .to_ascii_lowercase()
        .replace(['.', '*'], " ")
        .replace("^", "")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    let per_s = |len: &str| {
        [
            format!("{len} s-1"),
            format!("{len}/s"),
            format!("{len} / s"),
            format!("{len} sec-1"),
            format!("{len} second-1"),
            format!("{len}/sec"),
        ]
    };
    for (names, scale) in [
        (&["m", "meter", "meters", "metre", "metres"][..], 1.0),
        (
            &[
                "cm",
                "centimeter",
                "centimeters",
                "centimetre",
                "centimetres",
            ][..],
            0.01,
        ),
        (&["mm"][..], 0.001),
    ] {
        if names.iter().any(|n| per_s(n).contains(&u)) || (scale == 1.0 && u == "mps") {
            return Some(scale);
        }
    }
    matches!(u.as_str(), "knots" | "knot" | "kt" | "kts").then_some(1852.0 / 3600.0)
}

/// The level at or above `depth_m` and the weight towards the next level.
fn depth_weight<'a>(axes: &'a Axes, o: &CfOptions, path: &Path) -> Result<Levels<'a>, EnvError> {
    let Some((_, levels)) = &axes.depth else {
        return Ok(Levels::Fixed((0, 0.0)));
    };
    let n = levels.len();
    if let Some(s) = &axes.sigma {
        return match o.depth_m {
            Some(z) => Ok(Levels::Sigma(s, z)),
            None => Err(err(
                path,
                format!(
                    "the currents have {n} terrain-following levels: give the depth to sample \
                     at (flow.netcdf.depth_m, or [domain] depth_m and a source height)"
                ),
            )),
        };
    }
    if n == 1 {
        return Ok(Levels::Fixed((0, 0.0)));
    }
    let (shallow, deep) = if levels[0] < levels[n - 1] {
        (0, n - 1)
    } else {
        (n - 1, 0)
    };
    let Some(z) = o.depth_m else {
        return Err(err(
            path,
            format!(
                "the currents have {n} depth levels ({} to {} m): give the depth to sample at \
                 (flow.netcdf.depth_m, or [domain] depth_m and a source height)",
                levels[shallow], levels[deep]
            ),
        ));
    };
    if z > levels[deep] {
        return Err(err(
            path,
            format!(
                "depth {z} m is below the deepest level of the currents ({} m)",
                levels[deep]
            ),
        ));
    }
    if z <= levels[shallow] {
        return Ok(Levels::Fixed((shallow, 0.0)));
    }
    for k in 0..n - 1 {
        let (a, b) = (levels[k], levels[k + 1]);
        if (a.min(b)..=a.max(b)).contains(&z) {
            let w = (z - a) / (b - a);
            return Ok(Levels::Fixed(if w >= 1.0 { (k + 1, 0.0) } else { (k, w) }));
        }
    }
    Ok(Levels::Fixed((shallow, 0.0)))
}

/// The frames' times relative to the start, and the range of frames kept.
fn frames_kept(
    axes: &Axes,
    o: &CfOptions,
    path: &Path,
) -> Result<(Vec<f64>, std::ops::Range<usize>), EnvError> {
    let Some((_, times)) = &axes.time else {
        return Ok((vec![0.0], 0..1));
    };
    let start = o.start_s.unwrap_or(times[0]);
    let rel: Vec<f64> = times.iter().map(|t| t - start).collect();
    if rel.len() == 1 {
        return Ok((vec![0.0], 0..1));
    }
    let end = o.duration_s;
    if rel[0] > 0.0 || rel[rel.len() - 1] < end {
        return Err(err(
            path,
            format!(
                "the currents' frames span {} s to {} s of the run (its time 0 is the start of \
                 the plume's spin-up, mission.spinup_s before flow.netcdf.start); the run needs \
                 0 s to {end} s",
                rel[0],
                rel[rel.len() - 1]
            ),
        ));
    }
    let first = rel.partition_point(|&t| t <= 0.0).saturating_sub(1);
    let last = rel.partition_point(|&t| t < end).min(rel.len() - 1);
    Ok((rel, first..last + 1))
}

/// Evenly spaced ascending axis: (first, step) if `vals` are evenly spaced.
fn even(vals: &[f64]) -> Option<(f64, f64)> {
    let mut v = vals.to_vec();
    v.sort_by(f64::total_cmp);
    if v.len() < 2 {
        return None;
    }
    // The same arithmetic as a CSV grid's axis, so equal numbers give an equal grid.
    let step = (v[v.len() - 1] - v[0]) / (v.len() - 1) as f64;
    v.iter()
        .enumerate()
        .all(|(k, w)| (w - (v[0] + k as f64 * step)).abs() <= 1e-6 * step.abs().max(1.0))
        .then_some((v[0], step))
}

/// Builds the flow: node for node on an even projected grid, else resampled (velocities turned
/// by `turn`, a sine and cosine, when along a mapped grid's axes).
#[allow(clippy::too_many_arguments)]
fn sample(
    axes: &Axes,
    u: &Field,
    v: &Field,
    times: &[f64],
    keep: std::ops::Range<usize>,
    turn: Option<(f64, f64)>,
    o: &CfOptions,
    path: &Path,
) -> Result<GriddedFlow, EnvError> {
    let d = depth_weight(axes, o, path)?;
    let (xs, ys) = match (&axes.x, &axes.y) {
        (Some((_, xs)), Some((_, ys))) => (xs, ys),
        _ => return Err(err(path, "the currents have no horizontal grid")),
    };
    let node_for_node = !axes.geographic
        && axes.projection.is_none()
        && o.spacing_m.is_none()
        && axes.curvi.is_none();
    if let (true, Some((x0, dx)), Some((y0, dy))) = (node_for_node, even(xs), even(ys)) {
        let (nx, ny) = (xs.len(), ys.len());
        check_cover(
            &o.must_cover,
            x0,
            x0 + dx * (nx - 1) as f64,
            y0,
            y0 + dy * (ny - 1) as f64,
            "",
            path,
        )?;
        let ix = |k: usize| if xs[0] > xs[nx - 1] { nx - 1 - k } else { k };
        let jy = |k: usize| if ys[0] > ys[ny - 1] { ny - 1 - k } else { k };
        let reach = expand(&o.must_cover, dx.abs().max(dy.abs()));
        let mut frames = Vec::new();
        for t in keep {
            let (mut fu, mut fv) = (vec![0.0; nx * ny], vec![0.0; nx * ny]);
            for j in 0..ny {
                for i in 0..nx {
                    let (a, b) = (
                        u.at(axes, t, d, ix(i), jy(j)),
                        v.at(axes, t, d, ix(i), jy(j)),
                    );
                    let (x, y) = (x0 + i as f64 * dx, y0 + j as f64 * dy);
                    fill_or_fail(
                        &mut fu[j * nx + i],
                        &mut fv[j * nx + i],
                        a,
                        b,
                        reach.contains_xy(x, y),
                        x,
                        y,
                        path,
                    )?;
                }
            }
            frames.push(Frame {
                t_s: times[t],
                u: fu,
                v: fv,
            });
        }
        return Ok(GriddedFlow::from_frames_unchecked(
            x0, dx, nx, y0, dy, ny, frames,
        ));
    }
    resample(axes, u, v, times, keep, d, turn, o, path)
}

/// A missing value: an error within reach of the op-area, else still water.
#[allow(clippy::too_many_arguments)]
fn fill_or_fail(
    u: &mut f64,
    v: &mut f64,
    a: f64,
    b: f64,
    in_reach: bool,
    x: f64,
    y: f64,
    path: &Path,
) -> Result<(), EnvError> {
    if a.is_finite() && b.is_finite() {
        (*u, *v) = (a, b);
    } else if in_reach {
        return Err(err(
            path,
            format!(
                "the currents have a missing value (_FillValue or missing_value: land, or below \
                 the seabed) at ({x:.1}, {y:.1}) m, where the op-area needs them; move the \
                 op-area or sample shallower (flow.netcdf.depth_m)"
            ),
        ));
    } else {
        (*u, *v) = (0.0, 0.0);
    }
    Ok(())
}

/// `r` grown by `m` on every side.
pub(crate) fn expand(r: &Rect, m: f64) -> Rect {
    Rect {
        x_min_m: r.x_min_m - m,
        x_max_m: r.x_max_m + m,
        y_min_m: r.y_min_m - m,
        y_max_m: r.y_max_m + m,
    }
}

/// Whether the op-area lies inside the grid's extent.
fn check_cover(
    area: &Rect,
    x_min: f64,
    x_max: f64,
    y_min: f64,
    y_max: f64,
    unit: &str,
    path: &Path,
) -> Result<(), EnvError> {
    let (lo_x, hi_x) = (x_min.min(x_max), x_min.max(x_max));
    let (lo_y, hi_y) = (y_min.min(y_max), y_min.max(y_max));
    let eps = 1e-9 * (1.0 + hi_x.abs().max(hi_y.abs()));
    if area.x_min_m < lo_x - eps
        || area.x_max_m > hi_x + eps
        || area.y_min_m < lo_y - eps
        || area.y_max_m > hi_y + eps
    {
        return Err(err(
            path,
            format!(
                "the currents' grid (x {lo_x} to {hi_x} m, y {lo_y} to {hi_y} m{unit}) does not \
                 cover the op-area (x {} to {} m, y {} to {} m)",
                area.x_min_m, area.x_max_m, area.y_min_m, area.y_max_m
            ),
        ));
    }
    Ok(())
}

/// Index of the cell holding `p` on a monotonic axis and the weight towards its next node;
/// `None` outside.
pub(crate) fn locate(axis: &[f64], p: f64) -> Option<(usize, f64)> {
    let n = axis.len();
    if n < 2 {
        return (n == 1).then_some((0, 0.0));
    }
    let asc = axis[1] > axis[0];
    let (lo, hi) = if asc {
        (axis[0], axis[n - 1])
    } else {
        (axis[n - 1], axis[0])
    };
    if !(lo..=hi).contains(&p) {
        return None;
    }
    let k = if asc {
        axis.partition_point(|&a| a <= p)
    } else {
        axis.partition_point(|&a| a >= p)
    };
    let k = k.clamp(1, n - 1) - 1;
    Some((k, ((p - axis[k]) / (axis[k + 1] - axis[k])).clamp(0.0, 1.0)))
}

/// The nearest in-range position on an axis (for nodes outside the op-area's reach).
pub(crate) fn clamp_to(axis: &[f64], p: f64) -> f64 {
    let (a, b) = (axis[0], axis[axis.len() - 1]);
    p.clamp(a.min(b), a.max(b))
}

/// Resamples onto an even grid over the simulated area in the local frame.
#[allow(clippy::too_many_arguments)]
fn resample(
    axes: &Axes,
    u: &Field,
    v: &Field,
    times: &[f64],
    keep: std::ops::Range<usize>,
    d: Levels,
    turn: Option<(f64, f64)>,
    o: &CfOptions,
    path: &Path,
) -> Result<GriddedFlow, EnvError> {
    let (g, cells) = place(
        axes,
        o.frame.as_ref(),
        o.spacing_m,
        o.area,
        o.must_cover,
        "the currents'",
        "the currents are on a longitude/latitude grid: give the site's origin \
         ([origin] lat_deg and lon_deg) to place them in the local frame",
        path,
    )?;
    let (area, nx, ny, dx, dy) = (o.area, g.nx, g.ny, g.dx, g.dy);
    let reach = expand(&o.must_cover, dx.max(dy));
    let n = axes.len_xy();
    let mut frames = Vec::new();
    for t in keep {
        let (mut fu, mut fv) = (vec![0.0; nx * ny], vec![0.0; nx * ny]);
        for (k, &cell) in cells.iter().enumerate() {
            let (x, y) = (
                area.x_min_m + (k % nx) as f64 * dx,
                area.y_min_m + (k / nx) as f64 * dy,
            );
            let a = bilinear(cell, n, |i, j| u.at(axes, t, d, i, j));
            let b = bilinear(cell, n, |i, j| v.at(axes, t, d, i, j));
            let (a, b) = turn.map_or((a, b), |r| mapping::turn((a, b), r));
            fill_or_fail(
                &mut fu[k],
                &mut fv[k],
                a,
                b,
                reach.contains_xy(x, y),
                x,
                y,
                path,
            )?;
        }
        frames.push(Frame {
            t_s: times[t],
            u: fu,
            v: fv,
        });
    }
    Ok(GriddedFlow::from_frames_unchecked(
        area.x_min_m,
        dx,
        nx,
        area.y_min_m,
        dy,
        ny,
        frames,
    ))
}

/// A node's place in the file's grid: `((i, weight towards i + 1), (j, weight towards j + 1))`.
pub(crate) type Cell = ((usize, f64), (usize, f64));

/// The value at `cell` of a field on an `n = (nx, ny)` grid read by `at(i, j)`: bilinear, a
/// node of zero weight not read (so a missing value there does not spread).
pub(crate) fn bilinear(
    ((i, tx), (j, ty)): Cell,
    n: (usize, usize),
    at: impl Fn(usize, usize) -> f64,
) -> f64 {
    let (i1, j1) = ((i + 1).min(n.0 - 1), (j + 1).min(n.1 - 1));
    let g = |a: usize, b: usize, w: f64| if w == 0.0 { 0.0 } else { w * at(a, b) };
    g(i, j, (1.0 - tx) * (1.0 - ty))
        + g(i1, j, tx * (1.0 - ty))
        + g(i, j1, (1.0 - tx) * ty)
        + g(i1, j1, tx * ty)
}

impl Axes {
    /// Nodes along the horizontal axes, `(x, y)`.
    pub(crate) fn len_xy(&self) -> (usize, usize) {
        let n = |a: &Option<(usize, Vec<f64>)>| a.as_ref().map_or(1, |(_, v)| v.len());
        (n(&self.x), n(&self.y))
    }
}

/// The even grid over `area` and each of its nodes' cell in the file (row by row from the
/// south), once the op-area `must_cover` is found inside the file's grid. `what` names the
/// grid's owner in a message (`the currents'`); `on_lon_lat` is the message for a
/// longitude/latitude grid without an origin. Outside the grid a node takes its nearest edge.
#[allow(clippy::too_many_arguments)]
pub(crate) fn place<'a>(
    axes: &Axes,
    frame: Option<&'a LocalFrame>,
    spacing_m: Option<f64>,
    area: Rect,
    must_cover: Rect,
    what: &str,
    on_lon_lat: &str,
    path: &Path,
) -> Result<(EvenGrid<'a>, Vec<Cell>), EnvError> {
    let (xs, ys) = match (&axes.x, &axes.y) {
        (Some((_, xs)), Some((_, ys))) => (xs.as_slice(), ys.as_slice()),
        _ => return Err(err(path, format!("{what} file has no horizontal grid"))),
    };
    if let Some(c) = &axes.curvi {
        return curvilinear::place(
            c, frame, spacing_m, area, must_cover, what, on_lon_lat, path,
        );
    }
    if let Some(tm) = &axes.projection {
        check_projected_origin(tm, frame, what, path)?;
    }
    let mut g = EvenGrid::new(
        xs,
        ys,
        axes.geographic || axes.projection.is_some(),
        frame,
        spacing_m,
        area,
        on_lon_lat,
        path,
    )?;
    if let Some(tm) = &axes.projection {
        g.set_projection(tm.clone(), xs, ys, spacing_m, area);
    }
    let to_file = |x: f64, y: f64| g.to_file(x, y);
    check_cover_points(
        what,
        must_cover,
        xs,
        ys,
        g.axis_names(),
        g.spacing,
        &to_file,
        path,
    )?;
    let mut cells = Vec::with_capacity(g.nx * g.ny);
    for j in 0..g.ny {
        for i in 0..g.nx {
            let (x, y) = (
                area.x_min_m + i as f64 * g.dx,
                area.y_min_m + j as f64 * g.dy,
            );
            let (fx, fy) = to_file(x, y);
            let a = locate(xs, clamp_to(xs, fx)).unwrap_or((0, 0.0));
            let b = locate(ys, clamp_to(ys, fy)).unwrap_or((0, 0.0));
            cells.push((a, b));
        }
    }
    Ok((g, cells))
}

/// Whether the site's origin can place a grid in the projection `tm`: an origin is given, and
/// the projection takes it (a UTM zone's latitudes, its central meridian near enough).
fn check_projected_origin(
    tm: &TransverseMercator,
    frame: Option<&LocalFrame>,
    what: &str,
    path: &Path,
) -> Result<(), EnvError> {
    let Some(f) = frame else {
        return Err(err(
            path,
            format!(
                "{what} grid is projected ({}): give the site's origin ([origin] lat_deg and \
                 lon_deg) to place it in the local frame",
                tm.name()
            ),
        ));
    };
    let o = f.origin();
    tm.forward(o.lat_deg, o.lon_deg).map(|_| ()).map_err(|e| {
        // Beyond UTM's latitudes no zone helps.
        let or_zone = if matches!(e, ProjectionError::Latitude { .. }) {
            ""
        } else {
            " or to the site's own UTM zone"
        };
        err(
            path,
            format!(
                "{what} grid is projected ({}), which cannot place the site's origin ({}, {}): \
                 {e}; reproject it to longitude and latitude (`gdalwarp -t_srs \
                 EPSG:4326`){or_zone}",
                tm.name(),
                o.lat_deg,
                o.lon_deg
            ),
        )
    })
}

/// An even grid in the local frame over `area` for a file's horizontal axes `xs`, `ys`: the
/// frame that places a longitude/latitude or mapped grid (none for one in the local frame), the
/// spacing (the file's own unless one is given, at most [`MAX_NODES_PER_SIDE`] nodes a side)
/// and the nodes.
pub(crate) struct EvenGrid<'a> {
    /// The file's longitude range (for wrapping), lowest first.
    lon_range: (f64, f64),
    frame: Option<&'a LocalFrame>,
    /// The projection of a mapped grid (eastings and northings from latitude and longitude).
    projection: Option<TransverseMercator>,
    /// The spacing asked for or the file's, widened to at most the nodes a side allows.
    pub(crate) spacing: f64,
    pub(crate) nx: usize,
    pub(crate) ny: usize,
    pub(crate) dx: f64,
    pub(crate) dy: f64,
}

impl<'a> EvenGrid<'a> {
    /// The grid; `on_lon_lat` is the message for a longitude/latitude grid without an origin.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        xs: &[f64],
        ys: &[f64],
        geographic: bool,
        frame: Option<&'a LocalFrame>,
        spacing_m: Option<f64>,
        area: Rect,
        on_lon_lat: &str,
        path: &Path,
    ) -> Result<Self, EnvError> {
        let frame = match (geographic, frame) {
            (false, _) => None,
            (true, Some(f)) => Some(f),
            (true, None) => return Err(err(path, on_lon_lat)),
        };
        let spacing = spacing_m
            .unwrap_or_else(|| native_spacing(xs, ys, frame))
            .max(area.width_m() / (MAX_NODES_PER_SIDE - 1) as f64)
            .max(area.height_m() / (MAX_NODES_PER_SIDE - 1) as f64);
        let nx = ((area.width_m() / spacing).ceil() as usize + 1).max(2);
        let ny = ((area.height_m() / spacing).ceil() as usize + 1).max(2);
        Ok(EvenGrid {
            lon_range: (xs[0].min(xs[xs.len() - 1]), xs[0].max(xs[xs.len() - 1])),
            frame,
            projection: None,
            spacing,
            nx,
            ny,
            dx: area.width_m() / (nx - 1) as f64,
            dy: area.height_m() / (ny - 1) as f64,
        })
    }

    /// Makes the grid a mapped one: its file coordinates are eastings and northings of `tm`,
    /// and its own spacing is in metres (before [`EvenGrid::new`] took it as degrees).
    fn set_projection(
        &mut self,
        tm: TransverseMercator,
        xs: &[f64],
        ys: &[f64],
        spacing_m: Option<f64>,
        area: Rect,
    ) {
        self.projection = Some(tm);
        if spacing_m.is_none() {
            self.spacing = native_spacing(xs, ys, None)
                .max(area.width_m() / (MAX_NODES_PER_SIDE - 1) as f64)
                .max(area.height_m() / (MAX_NODES_PER_SIDE - 1) as f64);
            self.nx = ((area.width_m() / self.spacing).ceil() as usize + 1).max(2);
            self.ny = ((area.height_m() / self.spacing).ceil() as usize + 1).max(2);
            self.dx = area.width_m() / (self.nx - 1) as f64;
            self.dy = area.height_m() / (self.ny - 1) as f64;
        }
    }

    /// The names of the file's horizontal coordinates in a message.
    pub(crate) fn axis_names(&self) -> (&'static str, &'static str) {
        match (self.frame, &self.projection) {
            (_, Some(_)) => ("easting", "northing"),
            (Some(_), None) => ("lon", "lat"),
            (None, None) => ("x", "y"),
        }
    }

    /// Where a local position is in the file's coordinates (longitudes wrapped to its range;
    /// a mapped grid's eastings and northings, NaN where the projection does not reach).
    pub(crate) fn to_file(&self, x: f64, y: f64) -> (f64, f64) {
        match self.frame {
            None => (x, y),
            Some(f) => {
                let (lat, mut lon) = f.to_geographic(Vec2::new(x, y));
                if let Some(tm) = &self.projection {
                    return tm.forward(lat, lon).unwrap_or((f64::NAN, f64::NAN));
                }
                let (lo, hi) = self.lon_range;
                if lon < lo && lon + 360.0 <= hi {
                    lon += 360.0;
                } else if lon > hi && lon - 360.0 >= lo {
                    lon -= 360.0;
                }
                (lon, lat)
            }
        }
    }
}

/// Whether every point of the op-area `r`'s edge (every `spacing`, and its corners) lies in the
/// file's grid; `what` names the grid's owner in the message (`the currents'`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn check_cover_points(
    what: &str,
    r: Rect,
    xs: &[f64],
    ys: &[f64],
    (nx_name, ny_name): (&str, &str),
    spacing: f64,
    to_file: &dyn Fn(f64, f64) -> (f64, f64),
    path: &Path,
) -> Result<(), EnvError> {
    let edge = edge_points(r, spacing);
    let range = |a: &[f64]| (a[0].min(a[a.len() - 1]), a[0].max(a[a.len() - 1]));
    for (x, y) in edge {
        let (fx, fy) = to_file(x, y);
        if locate(xs, fx).is_none() || locate(ys, fy).is_none() {
            let ((x0, x1), (y0, y1)) = (range(xs), range(ys));
            return Err(err(
                path,
                format!(
                    "{what} grid ({nx_name} {x0} to {x1}, {ny_name} {y0} to {y1}) does not \
                     cover the op-area: its point ({x:.1}, {y:.1}) m is at {nx_name} {fx:.6}, \
                     {ny_name} {fy:.6}"
                ),
            ));
        }
    }
    Ok(())
}

/// Points along the edge of `r`, every `spacing` or closer, and its corners.
pub(crate) fn edge_points(r: Rect, spacing: f64) -> Vec<(f64, f64)> {
    let steps = |len: f64| ((len / spacing).ceil() as usize).clamp(1, MAX_NODES_PER_SIDE);
    let (nx, ny) = (steps(r.width_m()), steps(r.height_m()));
    let mut edge = Vec::new();
    for k in 0..=nx {
        let x = r.x_min_m + r.width_m() * k as f64 / nx as f64;
        edge.push((x, r.y_min_m));
        edge.push((x, r.y_max_m));
    }
    for k in 0..=ny {
        let y = r.y_min_m + r.height_m() * k as f64 / ny as f64;
        edge.push((r.x_min_m, y));
        edge.push((r.x_max_m, y));
    }
    edge
}

/// The file's smallest node spacing in metres (near the origin for a geographic grid).
pub(crate) fn native_spacing(xs: &[f64], ys: &[f64], frame: Option<&LocalFrame>) -> f64 {
    let step = |a: &[f64]| {
        a.windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(f64::INFINITY, f64::min)
    };
    let (sx, sy) = (step(xs), step(ys));
    let s = match frame {
        None => sx.min(sy),
        Some(f) => {
            let o = f.origin();
            let east = f.to_local(o.lat_deg, o.lon_deg + sx).x.abs();
            let north = f.to_local(o.lat_deg + sy, o.lon_deg).y.abs();
            east.min(north)
        }
    };
    if s.is_finite() && s > 0.0 { s } else { 1.0 }
}

mod curvilinear;
mod mapping;
mod sigma;

#[cfg(test)]
mod tests;
