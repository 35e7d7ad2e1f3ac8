//! NetCDF classic files without a C library: the writer of plumetrace's outputs and the reader
//! of ocean-model currents share one codec here.
//!
//! The classic format (Unidata's "NetCDF Classic Format Specification") is a big-endian header,
//! `magic numrecs dim_list gatt_list var_list`, followed by the values of every variable: the
//! fixed-size variables one after another, then the record variables interleaved record by
//! record. Strings and values are padded to 4 bytes. [`Dataset`] writes the 64-bit offset
//! variant (CDF-2); [`NcFile`] reads CDF-1 (classic) and CDF-2. The 64-bit data variant (CDF-5)
//! and NetCDF-4 (HDF5) files are recognised and refused with the way to convert them
//! (`nccopy -k classic`). [`time`] reads CF time units (`seconds since 2026-03-01 06:00:00`)
//! and dates.

pub mod read;
pub mod time;
pub mod write;

pub use read::{Dim, NcFile, ReadError, Var};
pub use write::{AttrValue, Dataset, NetcdfError, Variable};

/// The magic of the 64-bit offset variant.
pub(crate) const MAGIC_CDF2: &[u8; 4] = b"CDF\x02";
pub(crate) const NC_DIMENSION: u32 = 0x0A;
pub(crate) const NC_VARIABLE: u32 = 0x0B;
pub(crate) const NC_ATTRIBUTE: u32 = 0x0C;
/// The largest count or size of the classic format (a non-negative 32-bit integer).
pub(crate) const MAX_NON_NEG: usize = i32::MAX as usize;

/// The value types of the classic format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NcType {
    /// 8-bit signed integer.
    Byte = 1,
    /// 8-bit character (text).
    Char = 2,
    /// 16-bit signed integer.
    Short = 3,
    /// 32-bit signed integer.
    Int = 4,
    /// 32-bit IEEE float.
    Float = 5,
    /// 64-bit IEEE float.
    Double = 6,
}

impl NcType {
    /// The type of a tag, if the classic format defines it.
    pub fn from_tag(tag: u32) -> Option<Self> {
        Some(match tag {
            1 => NcType::Byte,
            2 => NcType::Char,
            3 => NcType::Short,
            4 => NcType::Int,
            5 => NcType::Float,
            6 => NcType::Double,
            _ => return None,
        })
    }

    /// Bytes per value.
    pub fn size(self) -> usize {
        match self {
            NcType::Byte | NcType::Char => 1,
            NcType::Short => 2,
            NcType::Int | NcType::Float => 4,
            NcType::Double => 8,
        }
    }
}

impl std::fmt::Display for NcType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            NcType::Byte => "byte",
            NcType::Char => "char",
            NcType::Short => "short",
            NcType::Int => "int",
            NcType::Float => "float",
            NcType::Double => "double",
        })
    }
}

/// The candidate nearest to `name` by edit distance (case-insensitive), if it is close enough to
/// be a likely typo: at most a third of the longer name's length, and at least 1 edit allowed.
pub fn nearest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let name = name.to_ascii_lowercase();
    candidates
        .into_iter()
        .filter(|c| c.len() <= 256)
        .map(|c| (edit_distance(&name, &c.to_ascii_lowercase()), c))
        .filter(|(d, c)| *d <= (name.len().max(c.len()) / 3).max(1))
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().take(256).collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != cb))
                .min(prev[j + 1] + 1)
                .min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_typo_finds_its_name_and_a_stranger_finds_none() {
        let names = ["uo", "vo", "longitude", "latitude", "time"];
        assert_eq!(nearest("u0", names), Some("uo"));
        assert_eq!(nearest("lattitude", names), Some("latitude"));
        assert_eq!(nearest("salinity", names), None);
    }
}
