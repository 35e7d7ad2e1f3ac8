//! NetCDF classic files written without a C library (feature `netcdf`): `plume.nc`, the probe
//! series and the time-averaged map of a plume run, following the CF conventions 1.8.
//!
//! The classic format (Unidata's "NetCDF Classic Format Specification") is a big-endian header,
//! `magic numrecs dim_list gatt_list var_list`, followed by the values of every variable in the
//! order of the list. Strings and values are padded to 4 bytes. The file is the "64-bit offset"
//! variant (CDF-2: magic `CDF\x02`, 8-byte data offsets), which every classic reader reads
//! (netCDF-C, netCDF-Java, `scipy.io.netcdf_file`). Only what `plume.nc` needs is written: fixed
//! dimensions (no record dimension, so `numrecs` is 0), `double` variables, and text, `int` and
//! `double` attributes.
//!
//! Time: the simulation has no date, so `time` is in seconds since the start of the run, which
//! the file writes as the CF reference time `1970-01-01 00:00:00` (CF wants `seconds since
//! <date>`; a plain `s` would not be read as time).

use crate::series::ProbeSeries;
use plumetrace_env::GridSpec;

const MAGIC: &[u8; 4] = b"CDF\x02";
const NC_DIMENSION: u32 = 0x0A;
const NC_VARIABLE: u32 = 0x0B;
const NC_ATTRIBUTE: u32 = 0x0C;
const NC_CHAR: u32 = 2;
const NC_INT: u32 = 4;
const NC_DOUBLE: u32 = 6;
/// The largest count or size of the classic format (a non-negative 32-bit integer).
const MAX_NON_NEG: usize = i32::MAX as usize;

/// What the classic format cannot hold, or a time average that does not fit its grid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NetcdfError {
    /// A dimension's length is 0 (which would make it the record dimension) or too large.
    #[error("NetCDF dimension {name} has length {len}; it needs 1..={MAX_NON_NEG}")]
    DimensionLength {
        /// The dimension.
        name: String,
        /// Its length.
        len: usize,
    },
    /// A `double` attribute holds a number that is not finite.
    #[error("NetCDF attribute {0} has a number that is not finite")]
    AttributeNotFinite(String),
    /// A variable names a dimension id that is not defined.
    #[error("NetCDF variable {name} names dimension {dim}, which is not defined")]
    UnknownDimension {
        /// The variable.
        name: String,
        /// The dimension id.
        dim: usize,
    },
    /// A variable's values do not fill it.
    #[error("NetCDF variable {name} has {values} values for {places} places")]
    ValueCount {
        /// The variable.
        name: String,
        /// Values given.
        values: usize,
        /// Places of its dimensions.
        places: usize,
    },
    /// A variable is larger than a classic file holds.
    #[error(
        "NetCDF variable {name} has {values} values; a classic file holds at most {} per variable",
        MAX_NON_NEG / 8
    )]
    TooManyValues {
        /// The variable.
        name: String,
        /// Its values.
        values: usize,
    },
    /// A variable's value is not finite.
    #[error("NetCDF variable {name} has a value that is not finite at {at}")]
    ValueNotFinite {
        /// The variable.
        name: String,
        /// The value's index.
        at: usize,
    },
    /// A name outside the portable subset.
    #[error("{0:?} is not a NetCDF name (a letter or _, then letters, digits or _)")]
    Name(String),
    /// A count or size too large for the format.
    #[error("{0} is too large for a NetCDF classic file")]
    TooLarge(usize),
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

/// An attribute's value.
#[derive(Debug, Clone, PartialEq)]
pub enum AttrValue {
    /// Text (`char`).
    Text(String),
    /// 32-bit integers.
    Int(Vec<i32>),
    /// Doubles.
    Double(Vec<f64>),
}

impl From<&str> for AttrValue {
    fn from(s: &str) -> Self {
        AttrValue::Text(s.to_string())
    }
}

impl From<String> for AttrValue {
    fn from(s: String) -> Self {
        AttrValue::Text(s)
    }
}

impl From<i32> for AttrValue {
    fn from(v: i32) -> Self {
        AttrValue::Int(vec![v])
    }
}

impl From<f64> for AttrValue {
    fn from(v: f64) -> Self {
        AttrValue::Double(vec![v])
    }
}

/// A `double` variable over some of the dataset's dimensions, with its attributes.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    name: String,
    dims: Vec<usize>,
    attrs: Vec<(String, AttrValue)>,
    data: Vec<f64>,
}

impl Variable {
    /// Adds an attribute.
    pub fn attr(&mut self, name: &str, value: impl Into<AttrValue>) -> &mut Self {
        self.attrs.push((name.to_string(), value.into()));
        self
    }
}

/// A dataset: dimensions, global attributes and variables, in the order they are written.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Dataset {
    dims: Vec<(String, usize)>,
    attrs: Vec<(String, AttrValue)>,
    vars: Vec<Variable>,
}

impl Dataset {
    /// Adds a dimension of `len` (>= 1) and returns its id.
    pub fn dim(&mut self, name: &str, len: usize) -> usize {
        self.dims.push((name.to_string(), len));
        self.dims.len() - 1
    }

    /// Adds a global attribute.
    pub fn attr(&mut self, name: &str, value: impl Into<AttrValue>) -> &mut Self {
        self.attrs.push((name.to_string(), value.into()));
        self
    }

    /// Adds a variable over dimensions `dims` (ids, slowest first; none: a scalar) with its
    /// values in row-major order.
    pub fn var(&mut self, name: &str, dims: &[usize], data: Vec<f64>) -> &mut Variable {
        self.vars.push(Variable {
            name: name.to_string(),
            dims: dims.to_vec(),
            attrs: Vec::new(),
            data,
        });
        let last = self.vars.len() - 1;
        &mut self.vars[last]
    }

    /// The file's bytes; a name the format does not allow, a dimension of length 0, values that
    /// do not fill their variable, a number that is not finite or a size the format cannot hold
    /// is an error.
    pub fn to_bytes(&self) -> Result<Vec<u8>, NetcdfError> {
        self.check()?;
        let mut h = Vec::new();
        h.extend_from_slice(MAGIC);
        put_u32(&mut h, 0); // numrecs: no record dimension
        if self.dims.is_empty() {
            put_u64(&mut h, 0); // ABSENT
        } else {
            put_u32(&mut h, NC_DIMENSION);
            put_len(&mut h, self.dims.len())?;
            for (name, len) in &self.dims {
                put_name(&mut h, name)?;
                put_len(&mut h, *len)?;
            }
        }
        put_attrs(&mut h, &self.attrs)?;
        // Offsets are patched once the header's length is known.
        let mut begins = Vec::with_capacity(self.vars.len());
        if self.vars.is_empty() {
            put_u64(&mut h, 0);
        } else {
            put_u32(&mut h, NC_VARIABLE);
            put_len(&mut h, self.vars.len())?;
            for v in &self.vars {
                put_name(&mut h, &v.name)?;
                put_len(&mut h, v.dims.len())?;
                for &d in &v.dims {
                    put_len(&mut h, d)?;
                }
                put_attrs(&mut h, &v.attrs)?;
                put_u32(&mut h, NC_DOUBLE);
                put_len(&mut h, v.data.len() * 8)?; // vsize: doubles are 4-byte aligned
                begins.push(h.len());
                put_u64(&mut h, 0);
            }
        }
        let mut offset = h.len() as u64;
        for (v, &at) in self.vars.iter().zip(&begins) {
            h[at..at + 8].copy_from_slice(&offset.to_be_bytes());
            offset += v.data.len() as u64 * 8;
        }
        h.reserve(self.vars.iter().map(|v| v.data.len() * 8).sum());
        for v in &self.vars {
            for x in &v.data {
                h.extend_from_slice(&x.to_be_bytes());
            }
        }
        Ok(h)
    }

    fn check(&self) -> Result<(), NetcdfError> {
        for (name, len) in &self.dims {
            check_name(name)?;
            // A length of 0 would make it the record dimension.
            if !(1..=MAX_NON_NEG).contains(len) {
                return Err(NetcdfError::DimensionLength {
                    name: name.clone(),
                    len: *len,
                });
            }
        }
        for (name, value) in self
            .attrs
            .iter()
            .chain(self.vars.iter().flat_map(|v| &v.attrs))
        {
            check_name(name)?;
            if let AttrValue::Double(xs) = value
                && xs.iter().any(|x| !x.is_finite())
            {
                return Err(NetcdfError::AttributeNotFinite(name.clone()));
            }
        }
        for v in &self.vars {
            check_name(&v.name)?;
            let mut n = 1usize;
            for &d in &v.dims {
                let Some((_, len)) = self.dims.get(d) else {
                    return Err(NetcdfError::UnknownDimension {
                        name: v.name.clone(),
                        dim: d,
                    });
                };
                n = n.saturating_mul(*len);
            }
            if v.data.len() != n {
                return Err(NetcdfError::ValueCount {
                    name: v.name.clone(),
                    values: v.data.len(),
                    places: n,
                });
            }
            if n > MAX_NON_NEG / 8 {
                return Err(NetcdfError::TooManyValues {
                    name: v.name.clone(),
                    values: n,
                });
            }
            if let Some(at) = v.data.iter().position(|x| !x.is_finite()) {
                return Err(NetcdfError::ValueNotFinite {
                    name: v.name.clone(),
                    at,
                });
            }
        }
        Ok(())
    }
}

/// Names of the classic format, kept to the portable subset: a letter or `_`, then letters,
/// digits and `_`.
fn check_name(name: &str) -> Result<(), NetcdfError> {
    let mut chars = name.chars();
    let first_ok = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
    if first_ok && chars.all(|c| c.is_ascii_alphanumeric() || c == '_') {
        Ok(())
    } else {
        Err(NetcdfError::Name(name.to_string()))
    }
}

fn put_u32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_be_bytes());
}

fn put_u64(out: &mut Vec<u8>, v: u64) {
    out.extend_from_slice(&v.to_be_bytes());
}

/// A count or size (`NON_NEG`).
fn put_len(out: &mut Vec<u8>, n: usize) -> Result<(), NetcdfError> {
    if n > MAX_NON_NEG {
        return Err(NetcdfError::TooLarge(n));
    }
    put_u32(out, n as u32);
    Ok(())
}

/// Zero bytes up to the next multiple of 4.
fn pad(out: &mut Vec<u8>) {
    while !out.len().is_multiple_of(4) {
        out.push(0);
    }
}

/// `name = nelems namestring`, padded.
fn put_name(out: &mut Vec<u8>, name: &str) -> Result<(), NetcdfError> {
    put_len(out, name.len())?;
    out.extend_from_slice(name.as_bytes());
    pad(out);
    Ok(())
}

/// `att_list = ABSENT | NC_ATTRIBUTE nelems [attr ...]`.
fn put_attrs(out: &mut Vec<u8>, attrs: &[(String, AttrValue)]) -> Result<(), NetcdfError> {
    if attrs.is_empty() {
        put_u64(out, 0);
        return Ok(());
    }
    put_u32(out, NC_ATTRIBUTE);
    put_len(out, attrs.len())?;
    for (name, value) in attrs {
        put_name(out, name)?;
        match value {
            AttrValue::Text(s) => {
                put_u32(out, NC_CHAR);
                put_len(out, s.len())?;
                out.extend_from_slice(s.as_bytes());
            }
            AttrValue::Int(xs) => {
                put_u32(out, NC_INT);
                put_len(out, xs.len())?;
                for x in xs {
                    out.extend_from_slice(&x.to_be_bytes());
                }
            }
            AttrValue::Double(xs) => {
                put_u32(out, NC_DOUBLE);
                put_len(out, xs.len())?;
                for x in xs {
                    out.extend_from_slice(&x.to_be_bytes());
                }
            }
        }
        pad(out);
    }
    Ok(())
}

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
    d.to_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bytes of a tiny file, assembled by hand from the specification.
    #[test]
    fn a_small_dataset_is_laid_out_as_the_specification_says() {
        let mut d = Dataset::default();
        let t = d.dim("t", 2);
        d.attr("a", "xy");
        d.var("t", &[t], vec![0.5, 1.0])
            .attr("units", "s")
            .attr("k", 7);
        let bytes = d.to_bytes().unwrap_or_default();
        let mut want: Vec<u8> = b"CDF\x02".to_vec();
        let w = |v: &mut Vec<u8>, x: u32| v.extend_from_slice(&x.to_be_bytes());
        w(&mut want, 0); // numrecs
        w(&mut want, 0x0A); // dim_list
        w(&mut want, 1);
        w(&mut want, 1);
        want.extend_from_slice(b"t\0\0\0");
        w(&mut want, 2);
        w(&mut want, 0x0C); // gatt_list
        w(&mut want, 1);
        w(&mut want, 1);
        want.extend_from_slice(b"a\0\0\0");
        w(&mut want, 2); // NC_CHAR
        w(&mut want, 2);
        want.extend_from_slice(b"xy\0\0");
        w(&mut want, 0x0B); // var_list
        w(&mut want, 1);
        w(&mut want, 1);
        want.extend_from_slice(b"t\0\0\0");
        w(&mut want, 1); // rank
        w(&mut want, 0); // dimid
        w(&mut want, 0x0C); // vatt_list
        w(&mut want, 2);
        w(&mut want, 5);
        want.extend_from_slice(b"units\0\0\0");
        w(&mut want, 2);
        w(&mut want, 1);
        want.extend_from_slice(b"s\0\0\0");
        w(&mut want, 1);
        want.extend_from_slice(b"k\0\0\0");
        w(&mut want, 4); // NC_INT
        w(&mut want, 1);
        w(&mut want, 7);
        w(&mut want, 6); // NC_DOUBLE
        w(&mut want, 16); // vsize
        let begin = want.len() as u64 + 8;
        want.extend_from_slice(&begin.to_be_bytes());
        want.extend_from_slice(&0.5f64.to_be_bytes());
        want.extend_from_slice(&1.0f64.to_be_bytes());
        assert_eq!(bytes, want);
    }

    #[test]
    fn what_the_format_cannot_hold_is_refused() {
        let refused = |f: &dyn Fn(&mut Dataset)| {
            let mut d = Dataset::default();
            f(&mut d);
            d.to_bytes().unwrap_err().to_string()
        };
        let e = refused(&|d| {
            d.dim("time", 0);
        });
        assert!(e.contains("length 0"), "{e}");
        let e = refused(&|d| {
            let t = d.dim("time", 2);
            d.var("c", &[t], vec![1.0]);
        });
        assert!(e.contains("1 values for 2 places"), "{e}");
        let e = refused(&|d| {
            let t = d.dim("time", 1);
            d.var("c", &[t], vec![f64::NAN]);
        });
        assert!(e.contains("not finite"), "{e}");
        let e = refused(&|d| {
            d.attr("2nd", "x");
        });
        assert!(e.contains("not a NetCDF name"), "{e}");
        let e = refused(&|d| {
            d.var("c", &[3], vec![1.0]);
        });
        assert!(e.contains("not defined"), "{e}");
    }
}
