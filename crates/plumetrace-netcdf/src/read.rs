//! Reading NetCDF classic files (CDF-1 and CDF-2) from their bytes: the header parsed into
//! dimensions, attributes and variables, a variable's values read as doubles on request.
//!
//! Every count, size and offset in the header is checked against the file's length before it is
//! used, so a damaged or hostile file is an error naming the byte offset and what was being read,
//! never a panic or an allocation larger than the file. CDF-5 and NetCDF-4 (HDF5) files are
//! recognised by their magic and refused with the conversion that makes them readable.

use crate::{AttrValue, MAX_NON_NEG, NC_ATTRIBUTE, NC_DIMENSION, NC_VARIABLE, NcType};

/// Why a file cannot be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReadError {
    /// The file is NetCDF-4 (an HDF5 file).
    #[error(
        "this is a NetCDF-4 (HDF5) file, which is not read; convert it to NetCDF classic with \
         `nccopy -k classic IN.nc OUT.nc`"
    )]
    Netcdf4,
    /// The file is the 64-bit data variant (CDF-5).
    #[error(
        "this is a NetCDF CDF-5 (64-bit data) file, which is not read; convert it to NetCDF \
         classic with `nccopy -k classic IN.nc OUT.nc`"
    )]
    Cdf5,
    /// The file is not NetCDF at all.
    #[error("not a NetCDF file: it starts with {0:?}, not \"CDF\" (a NetCDF classic file)")]
    NotNetcdf(String),
    /// The file ends before what the header says.
    #[error("truncated at byte {at}: {what} needs {need} more bytes than the file has")]
    Truncated {
        /// Byte offset.
        at: usize,
        /// What was being read.
        what: String,
        /// Bytes missing.
        need: usize,
    },
    /// A header field does not hold what the format allows there.
    #[error("bad header at byte {at}: {what}")]
    Header {
        /// Byte offset.
        at: usize,
        /// What is wrong.
        what: String,
    },
    /// A variable's values lie outside the file.
    #[error(
        "variable {name}: its values ({bytes} bytes from byte {begin}) lie beyond the file's {len} bytes"
    )]
    DataOutside {
        /// The variable.
        name: String,
        /// Where they start.
        begin: u64,
        /// How many bytes.
        bytes: u64,
        /// The file's length.
        len: usize,
    },
    /// A text variable was asked for numbers.
    #[error("variable {0} holds text, not numbers")]
    TextVariable(String),
}

/// Which classic variant a file is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Version {
    /// CDF-1: 32-bit offsets.
    Classic,
    /// CDF-2: 64-bit offsets.
    Offset64,
}

/// A dimension.
#[derive(Debug, Clone, PartialEq)]
pub struct Dim {
    /// Its name.
    pub name: String,
    /// Its length (for the record dimension: the number of records).
    pub len: usize,
    /// Whether it is the record (unlimited) dimension.
    pub is_record: bool,
}

/// A variable's header entry.
#[derive(Debug, Clone, PartialEq)]
pub struct Var {
    /// Its name.
    pub name: String,
    /// Its dimension ids, slowest first.
    pub dims: Vec<usize>,
    /// Its attributes.
    pub attrs: Vec<(String, AttrValue)>,
    /// Its type.
    pub ty: NcType,
    begin: u64,
    is_record: bool,
}

impl Var {
    /// An attribute by name.
    pub fn attr(&self, name: &str) -> Option<&AttrValue> {
        self.attrs.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }

    /// A text attribute by name.
    pub fn text(&self, name: &str) -> Option<&str> {
        self.attr(name).and_then(AttrValue::as_text)
    }
}

/// A parsed classic file: its header and its bytes.
#[derive(Debug, Clone)]
pub struct NcFile {
    /// CDF-1 or CDF-2.
    pub version: Version,
    /// Dimensions, by id.
    pub dims: Vec<Dim>,
    /// Global attributes.
    pub attrs: Vec<(String, AttrValue)>,
    /// Variables.
    pub vars: Vec<Var>,
    numrecs: usize,
    recsize: u64,
    bytes: Vec<u8>,
}

/// A cursor over the header.
struct Cursor<'a> {
    b: &'a [u8],
    at: usize,
}

impl Cursor<'_> {
    fn take(&mut self, n: usize, what: &str) -> Result<&[u8], ReadError> {
        let left = self.b.len() - self.at;
        if n > left {
            return Err(ReadError::Truncated {
                at: self.at,
                what: what.to_string(),
                need: n - left,
            });
        }
        let s = &self.b[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }

    fn u32(&mut self, what: &str) -> Result<u32, ReadError> {
        let s = self.take(4, what)?;
        Ok(u32::from_be_bytes([s[0], s[1], s[2], s[3]]))
    }

    fn u64(&mut self, what: &str) -> Result<u64, ReadError> {
        let s = self.take(8, what)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(s);
        Ok(u64::from_be_bytes(a))
    }

    fn bad(&self, what: impl Into<String>) -> ReadError {
        ReadError::Header {
            at: self.at,
            what: what.into(),
        }
    }

    /// A `NON_NEG` count, at most what the rest of the file could hold at `min_bytes` each.
    fn count(&mut self, what: &str, min_bytes: usize) -> Result<usize, ReadError> {
        let n = self.u32(what)? as usize;
        if n > MAX_NON_NEG {
            return Err(self.bad(format!("{what} is {n}, larger than the format allows")));
        }
        if n.saturating_mul(min_bytes) > self.b.len() - self.at {
            return Err(ReadError::Truncated {
                at: self.at,
                what: format!("{what} ({n})"),
                need: n.saturating_mul(min_bytes) - (self.b.len() - self.at),
            });
        }
        Ok(n)
    }

    fn pad(&mut self, n: usize, what: &str) -> Result<(), ReadError> {
        let p = (4 - n % 4) % 4;
        self.take(p, what).map(|_| ())
    }

    fn name(&mut self, what: &str) -> Result<String, ReadError> {
        let n = self.count(&format!("length of the {what} name"), 1)?;
        let at = self.at;
        let s = self.take(n, what)?;
        let name = String::from_utf8(s.to_vec()).map_err(|_| ReadError::Header {
            at,
            what: format!("the {what} name is not UTF-8"),
        })?;
        self.pad(n, what)?;
        Ok(name)
    }

    /// The list tag: `ABSENT` (two zeros) or `tag nelems`; returns the element count.
    fn list(&mut self, tag: u32, what: &str, min_bytes: usize) -> Result<usize, ReadError> {
        let t = self.u32(what)?;
        if t == 0 {
            let n = self.u32(what)?;
            return if n == 0 {
                Ok(0)
            } else {
                Err(self.bad(format!("{what} is absent but counts {n} elements")))
            };
        }
        if t != tag {
            return Err(self.bad(format!("expected the {what} tag {tag:#x}, found {t:#x}")));
        }
        self.count(&format!("number of {what} entries"), min_bytes)
    }

    fn attrs(&mut self, owner: &str) -> Result<Vec<(String, AttrValue)>, ReadError> {
        let n = self.list(NC_ATTRIBUTE, &format!("{owner} attribute list"), 12)?;
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            let name = self.name(&format!("{owner} attribute"))?;
            let what = format!("attribute {owner}:{name}");
            let tag = self.u32(&what)?;
            let ty = NcType::from_tag(tag)
                .ok_or_else(|| self.bad(format!("{what} has type {tag}, not a classic type")))?;
            let count = self.count(&format!("{what} length"), ty.size())?;
            let raw = self.take(count * ty.size(), &what)?.to_vec();
            self.pad(count * ty.size(), &what)?;
            out.push((name, attr_value(ty, &raw)));
        }
        Ok(out)
    }
}

fn attr_value(ty: NcType, raw: &[u8]) -> AttrValue {
    match ty {
        NcType::Char => AttrValue::Text(
            String::from_utf8_lossy(raw)
                .trim_end_matches('\0')
                .to_string(),
        ),
        NcType::Byte => AttrValue::Byte(raw.iter().map(|&b| b as i8).collect()),
        NcType::Short => AttrValue::Short(
            raw.chunks_exact(2)
                .map(|c| i16::from_be_bytes([c[0], c[1]]))
                .collect(),
        ),
        NcType::Int => AttrValue::Int(
            raw.chunks_exact(4)
                .map(|c| i32::from_be_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        ),
        NcType::Float => AttrValue::Float(
            raw.chunks_exact(4)
                .map(|c| f32::from_be_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        ),
        NcType::Double => AttrValue::Double(
            raw.chunks_exact(8)
                .map(|c| f64::from_be_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]))
                .collect(),
        ),
    }
}

impl NcFile {
    /// Parses a file's bytes (the header now, the values on request).
    pub fn parse(bytes: Vec<u8>) -> Result<Self, ReadError> {
        let version = match bytes.get(..4) {
            Some(b"CDF\x01") => Version::Classic,
            Some(b"CDF\x02") => Version::Offset64,
            Some(b"CDF\x05") => return Err(ReadError::Cdf5),
            _ if bytes.starts_with(b"\x89HDF\r\n\x1a\n") => return Err(ReadError::Netcdf4),
            _ => {
                let head: String = bytes
                    .iter()
                    .take(8)
                    .map(|&b| {
                        if b.is_ascii_graphic() || b == b' ' {
                            b as char
                        } else {
                            '.'
                        }
                    })
                    .collect();
                return Err(ReadError::NotNetcdf(head));
            }
        };
        let mut c = Cursor { b: &bytes, at: 4 };
        let numrecs_raw = c.u32("number of records")?;
        let (dims, record) = Self::dims(&mut c)?;
        let attrs = c.attrs("global")?;
        let nvars = c.list(NC_VARIABLE, "variable list", 16)?;
        let mut vars = Vec::with_capacity(nvars);
        for _ in 0..nvars {
            vars.push(Self::read_var(&mut c, &dims, record, version)?);
        }
        let mut file = NcFile {
            version,
            dims,
            attrs,
            vars,
            numrecs: 0,
            recsize: 0,
            bytes: Vec::new(),
        };
        file.set_records(numrecs_raw, record, bytes.len())?;
        file.bytes = bytes;
        Ok(file)
    }

    fn dims(c: &mut Cursor<'_>) -> Result<(Vec<Dim>, Option<usize>), ReadError> {
        let n = c.list(NC_DIMENSION, "dimension list", 8)?;
        let mut dims = Vec::with_capacity(n);
        let mut record = None;
        for k in 0..n {
            let name = c.name("dimension")?;
            let len = c.u32(&format!("length of dimension {name}"))? as usize;
            if len > MAX_NON_NEG {
                return Err(c.bad(format!("dimension {name} has length {len}")));
            }
            if len == 0 {
                if record.is_some() {
                    return Err(c.bad(format!(
                        "dimension {name} is a second record (unlimited) dimension"
                    )));
                }
                record = Some(k);
            }
            dims.push(Dim {
                name,
                len,
                is_record: len == 0,
            });
        }
        Ok((dims, record))
    }

    fn read_var(
        c: &mut Cursor<'_>,
        dims: &[Dim],
        record: Option<usize>,
        version: Version,
    ) -> Result<Var, ReadError> {
        let name = c.name("variable")?;
        let rank = c.count(&format!("rank of variable {name}"), 4)?;
        let mut ids = Vec::with_capacity(rank);
        for i in 0..rank {
            let d = c.u32(&format!("dimension of variable {name}"))? as usize;
            if d >= dims.len() {
                return Err(c.bad(format!(
                    "variable {name} names dimension id {d}; the file has {}",
                    dims.len()
                )));
            }
            if i > 0 && Some(d) == record {
                return Err(c.bad(format!(
                    "variable {name} has the record dimension other than first"
                )));
            }
            ids.push(d);
        }
        let attrs = c.attrs(&name)?;
        let tag = c.u32(&format!("type of variable {name}"))?;
        let ty = NcType::from_tag(tag).ok_or_else(|| {
            c.bad(format!(
                "variable {name} has type {tag}, not a classic type"
            ))
        })?;
        let _vsize = c.u32(&format!("size of variable {name}"))?;
        let begin = match version {
            Version::Classic => u64::from(c.u32(&format!("offset of variable {name}"))?),
            Version::Offset64 => c.u64(&format!("offset of variable {name}"))?,
        };
        let is_record = record.is_some() && ids.first() == record.as_ref();
        Ok(Var {
            name,
            dims: ids,
            attrs,
            ty,
            begin,
            is_record,
        })
    }

    /// Bytes of one slab of `v` (one record of a record variable, else all of it).
    fn slab_bytes(&self, v: &Var) -> u64 {
        let skip = usize::from(v.is_record);
        v.dims.iter().skip(skip).fold(v.ty.size() as u64, |n, &d| {
            n.saturating_mul(self.dims[d].len as u64)
        })
    }

    fn set_records(
        &mut self,
        numrecs_raw: u32,
        record: Option<usize>,
        len: usize,
    ) -> Result<(), ReadError> {
        let rec: Vec<&Var> = self.vars.iter().filter(|v| v.is_record).collect();
        self.recsize = match rec.as_slice() {
            [] => 0,
            // A lone record variable is not padded between records.
            [v] => self.slab_bytes(v),
            many => many
                .iter()
                .map(|v| self.slab_bytes(v).div_ceil(4).saturating_mul(4))
                .fold(0u64, u64::saturating_add),
        };
        self.numrecs = if numrecs_raw == u32::MAX {
            // Streaming: as many whole records as the file holds.
            let start = rec.iter().map(|v| v.begin).min().unwrap_or(0);
            ((len as u64).saturating_sub(start))
                .checked_div(self.recsize)
                .map_or(0, |n| n.min(MAX_NON_NEG as u64) as usize)
        } else if numrecs_raw as usize > MAX_NON_NEG {
            return Err(ReadError::Header {
                at: 4,
                what: format!("number of records is {numrecs_raw}"),
            });
        } else {
            numrecs_raw as usize
        };
        if let Some(r) = record {
            self.dims[r].len = self.numrecs;
        }
        Ok(())
    }

    /// A variable by name.
    pub fn var(&self, name: &str) -> Option<&Var> {
        self.vars.iter().find(|v| v.name == name)
    }

    /// A global attribute by name.
    pub fn attr(&self, name: &str) -> Option<&AttrValue> {
        self.attrs.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }

    /// The lengths of a variable's dimensions.
    pub fn shape(&self, v: &Var) -> Vec<usize> {
        v.dims.iter().map(|&d| self.dims[d].len).collect()
    }

    /// A variable's values as doubles, row-major, exactly as stored (no scale, offset or fill
    /// handling); an error for text or values beyond the file.
    pub fn values(&self, v: &Var) -> Result<Vec<f64>, ReadError> {
        if v.ty == NcType::Char {
            return Err(ReadError::TextVariable(v.name.clone()));
        }
        let slab = self.slab_bytes(v);
        let (records, stride) = if v.is_record {
            (self.numrecs as u64, self.recsize)
        } else {
            (1, 0)
        };
        let outside = |bytes: u64| ReadError::DataOutside {
            name: v.name.clone(),
            begin: v.begin,
            bytes,
            len: self.bytes.len(),
        };
        // The last slab's end bounds every slab's; checked before anything is allocated.
        let last_end = records
            .checked_sub(1)
            .map_or(Some(v.begin), |r| {
                r.checked_mul(stride)
                    .and_then(|o| o.checked_add(v.begin))
                    .and_then(|o| o.checked_add(slab))
            })
            .ok_or_else(|| outside(slab))?;
        if records > 0 && last_end > self.bytes.len() as u64 {
            return Err(outside(slab.saturating_mul(records)));
        }
        let mut out = Vec::with_capacity((slab / v.ty.size() as u64 * records) as usize);
        for r in 0..records {
            let at = (v.begin + r * stride) as usize;
            let raw = &self.bytes[at..at + slab as usize];
            decode(v.ty, raw, &mut out);
        }
        Ok(out)
    }
}

fn decode(ty: NcType, raw: &[u8], out: &mut Vec<f64>) {
    match ty {
        NcType::Byte | NcType::Char => out.extend(raw.iter().map(|&b| f64::from(b as i8))),
        NcType::Short => out.extend(
            raw.chunks_exact(2)
                .map(|c| f64::from(i16::from_be_bytes([c[0], c[1]]))),
        ),
        NcType::Int => out.extend(
            raw.chunks_exact(4)
                .map(|c| f64::from(i32::from_be_bytes([c[0], c[1], c[2], c[3]]))),
        ),
        NcType::Float => out.extend(
            raw.chunks_exact(4)
                .map(|c| f64::from(f32::from_be_bytes([c[0], c[1], c[2], c[3]]))),
        ),
        NcType::Double => out.extend(
            raw.chunks_exact(8)
                .map(|c| f64::from_be_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]])),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Dataset;

    fn sample() -> Dataset {
        let mut d = Dataset::default();
        let t = d.record_dim("time", 3);
        let y = d.dim("lat", 2);
        let x = d.dim("lon", 2);
        d.attr("Conventions", "CF-1.8");
        d.var("time", &[t], vec![0.0, 3600.0, 7200.0])
            .attr("units", "seconds since 2026-03-01 00:00:00");
        d.var("lat", &[y], vec![50.0, 50.01]).of_type(NcType::Float);
        d.var("lon", &[x], vec![-4.0, -3.99]);
        d.var("u", &[t, y, x], (0..12).map(f64::from).collect())
            .of_type(NcType::Short)
            .attr("scale_factor", 0.01f32)
            .attr("_FillValue", -32767i16);
        d.var("b", &[t], vec![1.0, -2.0, 3.0]).of_type(NcType::Byte);
        d
    }

    #[test]
    fn a_written_file_reads_back_with_its_types_records_and_attributes() {
        let bytes = sample().to_bytes().unwrap();
        let f = NcFile::parse(bytes).unwrap();
        assert_eq!(f.version, Version::Offset64);
        assert_eq!(f.dims[0].len, 3);
        assert!(f.dims[0].is_record);
        let u = f.var("u").unwrap();
        assert_eq!(u.ty, NcType::Short);
        assert_eq!(f.shape(u), vec![3, 2, 2]);
        assert_eq!(
            f.values(u).unwrap(),
            (0..12).map(f64::from).collect::<Vec<_>>()
        );
        assert_eq!(
            f.values(f.var("time").unwrap()).unwrap(),
            vec![0.0, 3600.0, 7200.0]
        );
        assert_eq!(f.values(f.var("b").unwrap()).unwrap(), vec![1.0, -2.0, 3.0]);
        assert_eq!(
            f.values(f.var("lat").unwrap()).unwrap(),
            vec![50.0f32 as f64, 50.01f32 as f64]
        );
        assert_eq!(u.attr("scale_factor"), Some(&AttrValue::Float(vec![0.01])));
        assert_eq!(
            f.var("time").unwrap().text("units"),
            Some("seconds since 2026-03-01 00:00:00")
        );
        assert_eq!(
            f.attr("Conventions"),
            Some(&AttrValue::Text("CF-1.8".into()))
        );
    }

    #[test]
    fn a_lone_record_variable_of_short_values_is_not_padded_between_records() {
        let mut d = Dataset::default();
        let t = d.record_dim("time", 3);
        d.var("s", &[t], vec![1.0, 2.0, 3.0]).of_type(NcType::Short);
        let f = NcFile::parse(d.to_bytes().unwrap()).unwrap();
        assert_eq!(f.values(f.var("s").unwrap()).unwrap(), vec![1.0, 2.0, 3.0]);
    }

    #[test]
    fn a_classic_cdf1_file_reads_with_32_bit_offsets() {
        // CDF-1 differs from CDF-2 only in the magic and 4-byte offsets: rewrite one.
        let mut d = Dataset::default();
        let x = d.dim("x", 2);
        d.var("v", &[x], vec![1.5, -2.5]);
        let b2 = d.to_bytes().unwrap();
        let begin_at = b2.len() - 16 - 8;
        let begin = u64::from_be_bytes(b2[begin_at..begin_at + 8].try_into().unwrap());
        let mut b1 = b"CDF\x01".to_vec();
        b1.extend_from_slice(&b2[4..begin_at]);
        b1.extend_from_slice(&((begin - 4) as u32).to_be_bytes());
        b1.extend_from_slice(&b2[begin_at + 8..]);
        let f = NcFile::parse(b1).unwrap();
        assert_eq!(f.version, Version::Classic);
        assert_eq!(f.values(f.var("v").unwrap()).unwrap(), vec![1.5, -2.5]);
    }

    #[test]
    fn other_formats_are_named_with_the_way_to_convert_them() {
        let e = NcFile::parse(b"\x89HDF\r\n\x1a\nrest".to_vec()).unwrap_err();
        assert!(e.to_string().contains("NetCDF-4 (HDF5)"), "{e}");
        assert!(e.to_string().contains("nccopy -k classic"), "{e}");
        let e = NcFile::parse(b"CDF\x05\0\0\0\0".to_vec()).unwrap_err();
        assert!(e.to_string().contains("CDF-5"), "{e}");
        let e = NcFile::parse(b"x_m,y_m,u_mps\n".to_vec()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "not a NetCDF file: it starts with \"x_m,y_m,\", not \"CDF\" (a NetCDF classic file)"
        );
    }

    #[test]
    fn every_truncation_and_every_flipped_byte_is_an_error_or_a_file_never_a_panic() {
        let bytes = sample().to_bytes().unwrap();
        for n in 0..bytes.len() {
            if let Ok(f) = NcFile::parse(bytes[..n].to_vec()) {
                for v in &f.vars {
                    let _ = f.values(v);
                }
            }
        }
        for k in 0..bytes.len() {
            for flip in [0x01u8, 0x80, 0xFF] {
                let mut b = bytes.clone();
                b[k] ^= flip;
                if let Ok(f) = NcFile::parse(b) {
                    for v in &f.vars {
                        let _ = f.values(v);
                    }
                }
            }
        }
    }
}
