//! `plume.nc` (feature `netcdf`): the probe series and the time-averaged map of a plume run as a
//! NetCDF classic file following the CF conventions 1.8, encoded by `plumetrace-netcdf` (no C
//! library). Only what `plume.nc` needs is written: fixed dimensions, `double` variables, and
//! text, `int` and `double` attributes.
//!
//! Time: the simulation has no date, so `time` is in seconds since the start of the run, which
//! the file writes as the CF reference time `1970-01-01 00:00:00` (CF wants `seconds since
//! <date>`; a plain `s` would not be read as time).

use crate::series::ProbeSeries;
use plumetrace_env::GridSpec;
use plumetrace_netcdf::Dataset;
pub use plumetrace_netcdf::NetcdfError as FormatError;

/// What `plume.nc` cannot hold, or a time average that does not fit its grid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NetcdfError {
    /// The classic format cannot hold something.
    #[error(transparent)]
    Format(#[from] FormatError),
    /// The time average does not fit its grid.
    #[error("the time average has {points} points for a {nx} x {ny} grid")]
    GridMismatch {
        /// Points of the time average.
        points: usize,
        /// Grid columns.
        nx: usize,
        /// Grid rows.
        ny: usize,
    },
}

/// The units of `time`.
pub const TIME_UNITS: &str = "seconds since 1970-01-01 00:00:00";

/// What `plume.nc` holds.
#[derive(Debug)]
pub struct PlumeFile<'a> {
    /// Scenario name.
    pub scenario: &'a str,
    /// Run seed.
    pub seed: u64,
    /// The probe series (at least one probe and one sample).
    pub probes: &'a ProbeSeries,
    /// The time-average grid.
    pub grid: &'a GridSpec,
    /// The time-averaged concentration on it, row-major (x fastest).
    pub mean: &'a [f64],
    /// Samples in the time average.
    pub mean_samples: u32,
}

/// `plume.nc`: dimensions `time`, `probe`, `grid_x`, `grid_y`; variables `time(time)`,
/// `x(probe)`, `y(probe)`, `z(probe)`, `concentration(time, probe)`, `grid_x(grid_x)`,
/// `grid_y(grid_y)`, `grid_z` and `mean_concentration(grid_y, grid_x)`.
pub fn plume_file(f: &PlumeFile<'_>) -> Result<Vec<u8>, NetcdfError> {
    let p = f.probes;
    let (nx, ny) = (f.grid.nx, f.grid.ny);
    if f.mean.len() != nx * ny {
        return Err(NetcdfError::GridMismatch {
            points: f.mean.len(),
            nx,
            ny,
        });
    }
    let grid_points = f.grid.points();
    let mut d = Dataset::default();
    let time = d.dim("time", p.times_s().len());
    let probe = d.dim("probe", p.points().len());
    let gx = d.dim("grid_x", nx);
    let gy = d.dim("grid_y", ny);
    d.attr("Conventions", "CF-1.8")
        .attr("title", format!("plumetrace plume run: {}", f.scenario))
        .attr("source", concat!("plumetrace ", env!("CARGO_PKG_VERSION")))
        .attr("scenario", f.scenario)
        // Classic files have no 64-bit integers: the seed is written as text.
        .attr("seed", f.seed.to_string())
        .attr(
            "comment",
            "x East, y North, z height above the seabed, metres, in the scenario's local frame; \
             concentration in the sources' mass unit per cubic metre",
        );
    d.var("time", &[time], p.times_s().to_vec())
        .attr("standard_name", "time")
        .attr("long_name", "time since the start of the simulation")
        .attr("units", TIME_UNITS)
        .attr("calendar", "standard")
        .attr("axis", "T")
        .attr(
            "comment",
            "the simulation has no date: its start is written as 1970-01-01 00:00:00",
        );
    let coord = |pick: fn(&plumetrace_core::Vec3) -> f64| p.points().iter().map(pick).collect();
    d.var("x", &[probe], coord(|q| q.x))
        .attr("standard_name", "projection_x_coordinate")
        .attr("long_name", "probe position East")
        .attr("units", "m");
    d.var("y", &[probe], coord(|q| q.y))
        .attr("standard_name", "projection_y_coordinate")
        .attr("long_name", "probe position North")
        .attr("units", "m");
    d.var("z", &[probe], coord(|q| q.z))
        .attr("standard_name", "height_above_sea_floor")
        .attr("long_name", "probe height above the seabed")
        .attr("units", "m")
        .attr("positive", "up");
    d.var("concentration", &[time, probe], p.values().to_vec())
        .attr("long_name", "tracer concentration at the probes")
        .attr("units", "m-3")
        .attr("coordinates", "x y z");
    d.var(
        "grid_x",
        &[gx],
        grid_points.iter().take(nx).map(|q| q.x).collect(),
    )
    .attr("standard_name", "projection_x_coordinate")
    .attr("long_name", "grid position East")
    .attr("units", "m")
    .attr("axis", "X");
    d.var(
        "grid_y",
        &[gy],
        grid_points.iter().step_by(nx.max(1)).map(|q| q.y).collect(),
    )
    .attr("standard_name", "projection_y_coordinate")
    .attr("long_name", "grid position North")
    .attr("units", "m")
    .attr("axis", "Y");
    d.var("grid_z", &[], vec![f.grid.z_m])
        .attr("standard_name", "height_above_sea_floor")
        .attr("long_name", "height of the grid above the seabed")
        .attr("units", "m")
        .attr("positive", "up");
    d.var("mean_concentration", &[gy, gx], f.mean.to_vec())
        .attr(
            "long_name",
            "time-averaged tracer concentration on the output grid",
        )
        .attr("units", "m-3")
        .attr("coordinates", "grid_z")
        .attr("cell_methods", "time: mean")
        .attr("samples", i32::try_from(f.mean_samples).unwrap_or(i32::MAX));
    Ok(d.to_bytes()?)
}
