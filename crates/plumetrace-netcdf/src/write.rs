//! Writing NetCDF classic files: a [`Dataset`] of dimensions, attributes and variables encoded
//! as the specification lays them out.
//!
//! The file is the "64-bit offset" variant (CDF-2: magic `CDF\x02`, 8-byte data offsets), which
//! every classic reader reads (netCDF-C, netCDF-Java, `scipy.io.netcdf_file`). Variables hold
//! `double` values by default or any numeric type of the format ([`NcType`]); one dimension
//! may be the record (unlimited) dimension, whose variables are written record by record.

use crate::{MAX_NON_NEG, NcType};

/// What the classic format cannot hold.
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
    /// The record dimension is used other than as a variable's first dimension.
    #[error("NetCDF variable {0} has the record dimension other than first")]
    RecordNotFirst(String),
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
    /// A value of an integer variable is not a whole number in the type's range.
    #[error("NetCDF variable {name} of type {ty} cannot hold the value at {at}")]
    ValueType {
        /// The variable.
        name: String,
        /// Its type.
        ty: NcType,
        /// The value's index.
        at: usize,
    },
    /// A name outside the portable subset.
    #[error("{0:?} is not a NetCDF name (a letter or _, then letters, digits or _)")]
    Name(String),
    /// A count or size too large for the format.
    #[error("{0} is too large for a NetCDF classic file")]
    TooLarge(usize),
}

/// An attribute's value.
#[derive(Debug, Clone, PartialEq)]
pub enum AttrValue {
    /// Text (`char`).
    Text(String),
    /// 8-bit integers.
    Byte(Vec<i8>),
    /// 16-bit integers.
    Short(Vec<i16>),
    /// 32-bit integers.
    Int(Vec<i32>),
    /// Floats.
    Float(Vec<f32>),
    /// Doubles.
    Double(Vec<f64>),
}

impl AttrValue {
    /// The text of a `char` attribute.
    pub fn as_text(&self) -> Option<&str> {
        match self {
            AttrValue::Text(s) => Some(s),
            _ => None,
        }
    }

    /// The numbers of a numeric attribute, as doubles (`None` for text).
    pub fn as_numbers(&self) -> Option<Vec<f64>> {
        match self {
            AttrValue::Text(_) => None,
            AttrValue::Byte(v) => Some(v.iter().map(|&x| f64::from(x)).collect()),
            AttrValue::Short(v) => Some(v.iter().map(|&x| f64::from(x)).collect()),
            AttrValue::Int(v) => Some(v.iter().map(|&x| f64::from(x)).collect()),
            AttrValue::Float(v) => Some(v.iter().map(|&x| f64::from(x)).collect()),
            AttrValue::Double(v) => Some(v.clone()),
        }
    }

    /// The type the attribute is stored as.
    pub fn nc_type(&self) -> NcType {
        match self {
            AttrValue::Text(_) => NcType::Char,
            AttrValue::Byte(_) => NcType::Byte,
            AttrValue::Short(_) => NcType::Short,
            AttrValue::Int(_) => NcType::Int,
            AttrValue::Float(_) => NcType::Float,
            AttrValue::Double(_) => NcType::Double,
        }
    }
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

impl From<i16> for AttrValue {
    fn from(v: i16) -> Self {
        AttrValue::Short(vec![v])
    }
}

impl From<i32> for AttrValue {
    fn from(v: i32) -> Self {
        AttrValue::Int(vec![v])
    }
}

impl From<f32> for AttrValue {
    fn from(v: f32) -> Self {
        AttrValue::Float(vec![v])
    }
}

impl From<f64> for AttrValue {
    fn from(v: f64) -> Self {
        AttrValue::Double(vec![v])
    }
}

/// A variable over some of the dataset's dimensions, with its attributes; its values are kept
/// as doubles and stored as its type (`double` unless [`Variable::of_type`] says otherwise).
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    name: String,
    dims: Vec<usize>,
    attrs: Vec<(String, AttrValue)>,
    ty: NcType,
    data: Vec<f64>,
}

impl Variable {
    /// Adds an attribute.
    pub fn attr(&mut self, name: &str, value: impl Into<AttrValue>) -> &mut Self {
        self.attrs.push((name.to_string(), value.into()));
        self
    }

    /// Stores the values as `ty` (a numeric type; integers must be whole and in range).
    pub fn of_type(&mut self, ty: NcType) -> &mut Self {
        self.ty = ty;
        self
    }
}

/// A dataset: dimensions, global attributes and variables, in the order they are written.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Dataset {
    dims: Vec<(String, usize)>,
    record: Option<usize>,
    attrs: Vec<(String, AttrValue)>,
    vars: Vec<Variable>,
}

impl Dataset {
    /// Adds a dimension of `len` (>= 1) and returns its id.
    pub fn dim(&mut self, name: &str, len: usize) -> usize {
        self.dims.push((name.to_string(), len));
        self.dims.len() - 1
    }

    /// Adds the record (unlimited) dimension holding `records` records and returns its id (a
    /// later call replaces which dimension is the record one).
    pub fn record_dim(&mut self, name: &str, records: usize) -> usize {
        let id = self.dim(name, records);
        self.record = Some(id);
        id
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
            ty: NcType::Double,
            data,
        });
        let last = self.vars.len() - 1;
        &mut self.vars[last]
    }

    fn is_record(&self, v: &Variable) -> bool {
        self.record.is_some() && v.dims.first() == self.record.as_ref()
    }

    /// Bytes of one record (or of the whole variable when it has no record dimension), before
    /// padding.
    fn slab_bytes(&self, v: &Variable) -> usize {
        let records = if self.is_record(v) {
            self.record.map_or(1, |r| self.dims[r].1.max(1))
        } else {
            1
        };
        v.data.len() / records * v.ty.size()
    }

    /// The file's bytes; a name the format does not allow, a dimension of length 0, values that
    /// do not fill their variable or do not fit its type, a number that is not finite or a size
    /// the format cannot hold is an error.
    pub fn to_bytes(&self) -> Result<Vec<u8>, NetcdfError> {
        self.check()?;
        let numrecs = self.record.map_or(0, |r| self.dims[r].1);
        let mut h = Vec::new();
        h.extend_from_slice(crate::MAGIC_CDF2);
        put_len(&mut h, numrecs)?;
        if self.dims.is_empty() {
            put_u64(&mut h, 0); // ABSENT
        } else {
            put_u32(&mut h, crate::NC_DIMENSION);
            put_len(&mut h, self.dims.len())?;
            for (k, (name, len)) in self.dims.iter().enumerate() {
                put_name(&mut h, name)?;
                put_len(&mut h, if Some(k) == self.record { 0 } else { *len })?;
            }
        }
        put_attrs(&mut h, &self.attrs)?;
        // Offsets are patched once the header's length is known.
        let mut begins = Vec::with_capacity(self.vars.len());
        if self.vars.is_empty() {
            put_u64(&mut h, 0);
        } else {
            put_u32(&mut h, crate::NC_VARIABLE);
            put_len(&mut h, self.vars.len())?;
            for v in &self.vars {
                put_name(&mut h, &v.name)?;
                put_len(&mut h, v.dims.len())?;
                for &d in &v.dims {
                    put_len(&mut h, d)?;
                }
                put_attrs(&mut h, &v.attrs)?;
                put_u32(&mut h, v.ty as u32);
                put_len(&mut h, padded(self.slab_bytes(v)))?; // vsize
                begins.push(h.len());
                put_u64(&mut h, 0);
            }
        }
        let (fixed, records): (Vec<_>, Vec<_>) =
            (0..self.vars.len()).partition(|&k| !self.is_record(&self.vars[k]));
        let mut offset = h.len() as u64;
        for &k in &fixed {
            let at = begins[k];
            h[at..at + 8].copy_from_slice(&offset.to_be_bytes());
            offset += padded(self.slab_bytes(&self.vars[k])) as u64;
        }
        // One record holds a slab of every record variable; a lone record variable is not
        // padded between records (as netCDF-C lays it out).
        for &k in &records {
            let at = begins[k];
            h[at..at + 8].copy_from_slice(&offset.to_be_bytes());
            offset += padded(self.slab_bytes(&self.vars[k])) as u64;
        }
        for &k in &fixed {
            let v = &self.vars[k];
            put_values(&mut h, v.ty, &v.data);
            pad(&mut h);
        }
        for r in 0..numrecs {
            for &k in &records {
                let v = &self.vars[k];
                let per = v.data.len() / numrecs.max(1);
                put_values(&mut h, v.ty, &v.data[r * per..(r + 1) * per]);
                if records.len() > 1 {
                    pad(&mut h);
                }
            }
        }
        Ok(h)
    }

    fn check(&self) -> Result<(), NetcdfError> {
        for (k, (name, len)) in self.dims.iter().enumerate() {
            check_name(name)?;
            // A length of 0 would make it the record dimension.
            let ok = if Some(k) == self.record {
                *len <= MAX_NON_NEG
            } else {
                (1..=MAX_NON_NEG).contains(len)
            };
            if !ok {
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
            let finite = match value {
                AttrValue::Double(xs) => xs.iter().all(|x| x.is_finite()),
                AttrValue::Float(xs) => xs.iter().all(|x| x.is_finite()),
                _ => true,
            };
            if !finite {
                return Err(NetcdfError::AttributeNotFinite(name.clone()));
            }
        }
        for v in &self.vars {
            self.check_var(v)?;
        }
        Ok(())
    }

    fn check_var(&self, v: &Variable) -> Result<(), NetcdfError> {
        check_name(&v.name)?;
        let mut n = 1usize;
        for (i, &d) in v.dims.iter().enumerate() {
            let Some((_, len)) = self.dims.get(d) else {
                return Err(NetcdfError::UnknownDimension {
                    name: v.name.clone(),
                    dim: d,
                });
            };
            if i > 0 && Some(d) == self.record {
                return Err(NetcdfError::RecordNotFirst(v.name.clone()));
            }
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
        let range = match v.ty {
            NcType::Byte => Some(f64::from(i8::MIN)..=f64::from(i8::MAX)),
            NcType::Short => Some(f64::from(i16::MIN)..=f64::from(i16::MAX)),
            NcType::Int => Some(f64::from(i32::MIN)..=f64::from(i32::MAX)),
            NcType::Char => Some(0.0..=255.0),
            NcType::Float | NcType::Double => None,
        };
        if let Some(range) = range
            && let Some(at) = v
                .data
                .iter()
                .position(|x| x.fract() != 0.0 || !range.contains(x))
        {
            return Err(NetcdfError::ValueType {
                name: v.name.clone(),
                ty: v.ty,
                at,
            });
        }
        Ok(())
    }
}

/// A size rounded up to a multiple of 4.
fn padded(n: usize) -> usize {
    n.div_ceil(4) * 4
}

/// Values as `ty`, big-endian (integers checked whole and in range by `check_var`).
fn put_values(out: &mut Vec<u8>, ty: NcType, data: &[f64]) {
    for &x in data {
        match ty {
            NcType::Byte => out.extend_from_slice(&(x as i8).to_be_bytes()),
            NcType::Char => out.push(x as u8),
            NcType::Short => out.extend_from_slice(&(x as i16).to_be_bytes()),
            NcType::Int => out.extend_from_slice(&(x as i32).to_be_bytes()),
            NcType::Float => out.extend_from_slice(&(x as f32).to_be_bytes()),
            NcType::Double => out.extend_from_slice(&x.to_be_bytes()),
        }
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
    put_u32(out, crate::NC_ATTRIBUTE);
    put_len(out, attrs.len())?;
    for (name, value) in attrs {
        put_name(out, name)?;
        put_u32(out, value.nc_type() as u32);
        match value {
            AttrValue::Text(s) => {
                put_len(out, s.len())?;
                out.extend_from_slice(s.as_bytes());
            }
            AttrValue::Byte(xs) => {
                put_len(out, xs.len())?;
                xs.iter()
                    .for_each(|x| out.extend_from_slice(&x.to_be_bytes()));
            }
            AttrValue::Short(xs) => {
                put_len(out, xs.len())?;
                xs.iter()
                    .for_each(|x| out.extend_from_slice(&x.to_be_bytes()));
            }
            AttrValue::Int(xs) => {
                put_len(out, xs.len())?;
                xs.iter()
                    .for_each(|x| out.extend_from_slice(&x.to_be_bytes()));
            }
            AttrValue::Float(xs) => {
                put_len(out, xs.len())?;
                xs.iter()
                    .for_each(|x| out.extend_from_slice(&x.to_be_bytes()));
            }
            AttrValue::Double(xs) => {
                put_len(out, xs.len())?;
                xs.iter()
                    .for_each(|x| out.extend_from_slice(&x.to_be_bytes()));
            }
        }
        pad(out);
    }
    Ok(())
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
