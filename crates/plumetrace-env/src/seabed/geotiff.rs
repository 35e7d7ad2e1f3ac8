//! Bathymetry from a single-band GeoTIFF on longitude and latitude (WGS 84, EPSG:4326), as
//! GEBCO and EMODnet deliver their grids, or in WGS 84 / UTM (EPSG:32601 to 32660 north, 32701
//! to 32760 south), as surveys do; placed by its ModelTiepoint and ModelPixelScale tags.
//!
//! The raster's frame comes from its GeoKeys: a geographic model (`GTModelTypeGeoKey` 2) in WGS
//! 84 is read, and a projected one (`GTModelTypeGeoKey` 1) whose `ProjectedCSTypeGeoKey` is a
//! WGS 84 / UTM zone, in metres, is read through the core's transverse Mercator (each node of
//! the local grid placed in latitude and longitude by the site's origin, then in the zone);
//! another projection, a rotated raster (ModelTransformation) or another datum is refused with
//! the conversion to use. Pixels are areas (their centres are the nodes) unless
//! `GTRasterTypeGeoKey` says points. GDAL's no-data tag marks missing values. The
//! values' sign says what they are: a raster with any value below zero holds elevations (as
//! GEBCO's: negative below sea level), one with none holds depths (positive down).

use super::{Seabed, SeabedOptions, sample};
use crate::EnvError;
use crate::flow::cf::{Axes, err};
use plumetrace_core::geo::TransverseMercator;
use std::io::{Cursor, Read};
use std::path::Path;
use tiff::decoder::{Decoder, DecodingResult};
use tiff::tags::Tag;

/// GeoKey ids (GeoTIFF 1.0, section 6.2).
const MODEL_TYPE: u16 = 1024;
const RASTER_TYPE: u16 = 1025;
const GEOGRAPHIC_TYPE: u16 = 2048;
const PROJECTED_CS_TYPE: u16 = 3072;
const PROJ_LINEAR_UNITS: u16 = 3076;
/// `ProjLinearUnitsGeoKey`'s metre.
const LINEAR_METER: u16 = 9001;
/// `GTModelTypeGeoKey` values.
const MODEL_PROJECTED: u16 = 1;
const MODEL_GEOGRAPHIC: u16 = 2;
/// WGS 84.
const EPSG_WGS84: u16 = 4326;
/// A GeoKey value saying the frame is described by other keys.
const USER_DEFINED: u16 = 32767;
/// GDAL's no-data tag.
const GDAL_NODATA: u16 = 42113;

/// The conversions a message suggests.
const CONVERT: &str = "reproject it to longitude and latitude (`gdalwarp -t_srs EPSG:4326 IN.tif \
                       OUT.tif`) or convert it to NetCDF (`gdal_translate -of netCDF IN.tif \
                       OUT.nc`)";

/// Whether the file starts as a TIFF (classic or BigTIFF, either byte order).
pub(crate) fn is_tiff(path: &Path) -> bool {
    let mut magic = [0u8; 4];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut magic))
        .is_ok()
        && matches!(&magic, b"II*\0" | b"MM\0*" | b"II+\0" | b"MM\0+")
}

/// The GeoKeys of a GeoKeyDirectory: (key id, value) for keys stored in the directory itself.
fn geokeys(dir: &[u16]) -> Vec<(u16, u16)> {
    dir.get(4..)
        .unwrap_or_default()
        .chunks_exact(4)
        .take(usize::from(dir.get(3).copied().unwrap_or(0)))
        .filter(|k| k[1] == 0)
        .map(|k| (k[0], k[3]))
        .collect()
}

/// Reads the seabed from a GeoTIFF (see the module docs).
pub(crate) fn read(path: &Path, o: &SeabedOptions) -> Result<Seabed, EnvError> {
    crate::input::check_file(path, crate::input::MAX_DATA_BYTES)
        .map_err(|e| err(path, e.to_string()))?;
    if let Some(v) = &o.variable {
        return Err(err(
            path,
            format!(
                "bathymetry.variable = {v:?} names a NetCDF variable; a GeoTIFF holds one band \
                 (remove the key)"
            ),
        ));
    }
    let bytes = std::fs::read(path).map_err(|e| err(path, e.to_string()))?;
    let bad = |e: tiff::TiffError| {
        let hint = if matches!(e, tiff::TiffError::IoError(_)) {
            " (the file ends before its data do: cut short?)"
        } else {
            ""
        };
        err(path, format!("the GeoTIFF could not be read: {e}{hint}"))
    };
    let mut dec = Decoder::new(Cursor::new(bytes)).map_err(bad)?;
    let (w, h) = dec.dimensions().map_err(bad)?;
    let (w, h) = (w as usize, h as usize);
    match dec.colortype().map_err(bad)? {
        tiff::ColorType::Gray(_) => {}
        other => {
            return Err(err(
                path,
                format!(
                    "the GeoTIFF's pixels are {other:?}; a bathymetry is one band of numbers \
                     (select the band first, `gdal_translate -b 1 IN.tif OUT.tif`)"
                ),
            ));
        }
    }
    if w < 2 || h < 2 {
        return Err(err(
            path,
            format!("the GeoTIFF is {w} x {h} pixels; a bathymetry needs at least 2 x 2"),
        ));
    }
    if dec
        .find_tag(Tag::ModelTransformationTag)
        .map_err(bad)?
        .is_some()
    {
        return Err(err(
            path,
            format!(
                "the GeoTIFF is placed by a ModelTransformation (a rotated or sheared raster), \
                 which is not read; {CONVERT}"
            ),
        ));
    }
    let keys = match dec.find_tag(Tag::GeoKeyDirectoryTag).map_err(bad)? {
        Some(_) => geokeys(&dec.get_tag_u16_vec(Tag::GeoKeyDirectoryTag).map_err(bad)?),
        None => Vec::new(),
    };
    let projection = frame(&keys, path)?;
    let key = |id: u16| keys.iter().find(|(k, _)| *k == id).map(|(_, v)| *v);
    let tag = |dec: &mut Decoder<Cursor<Vec<u8>>>, t: Tag, name: &str, n: usize| match dec
        .find_tag(t)
        .map_err(bad)?
    {
        None => Err(err(
            path,
            format!("the GeoTIFF has no {name} tag, which places it; {CONVERT}"),
        )),
        Some(_) => {
            let v = dec.get_tag_f64_vec(t).map_err(bad)?;
            if v.len() < n || v.iter().take(n).any(|x| !x.is_finite()) {
                Err(err(
                    path,
                    format!("the GeoTIFF's {name} tag needs {n} finite numbers, not {v:?}"),
                ))
            } else {
                Ok(v)
            }
        }
    };
    let scale = tag(&mut dec, Tag::ModelPixelScaleTag, "ModelPixelScale", 2)?;
    let tie = tag(&mut dec, Tag::ModelTiepointTag, "ModelTiepoint", 6)?;
    if !(scale[0] > 0.0 && scale[1] > 0.0) {
        return Err(err(
            path,
            format!("the GeoTIFF's ModelPixelScale ({scale:?}) must be above 0 in x and y"),
        ));
    }
    let nodata: Option<f64> = match dec.find_tag(Tag::Unknown(GDAL_NODATA)).map_err(bad)? {
        Some(_) => dec
            .get_tag_ascii_string(Tag::Unknown(GDAL_NODATA))
            .ok()
            .and_then(|s| s.trim_matches(char::from(0)).trim().parse().ok()),
        None => None,
    };
    let values = numbers(dec.read_image().map_err(bad)?);
    if values.len() != w * h {
        return Err(err(
            path,
            format!(
                "the GeoTIFF holds {} values for {w} x {h} pixels (one band expected)",
                values.len()
            ),
        ));
    }
    // Pixel centres, unless the pixels are points (GTRasterTypeGeoKey 2).
    let half = if key(RASTER_TYPE) == Some(2) {
        0.0
    } else {
        0.5
    };
    let xs: Vec<f64> = (0..w)
        .map(|i| tie[3] + (i as f64 - tie[0] + half) * scale[0])
        .collect();
    let ys: Vec<f64> = (0..h)
        .map(|j| tie[4] - (j as f64 - tie[1] + half) * scale[1])
        .collect();
    let missing = |v: f64| !v.is_finite() || nodata == Some(v) || v.abs() > 1e30;
    let elevation = values.iter().any(|&v| !missing(v) && v < 0.0);
    let depths: Vec<f64> = values
        .iter()
        .map(|&v| match (missing(v), elevation) {
            (true, _) => f64::NAN,
            (false, true) => -v,
            (false, false) => v,
        })
        .collect();
    let axes = Axes {
        x: Some((1, xs)),
        y: Some((0, ys)),
        geographic: projection.is_none(),
        projection,
        ..Axes::default()
    };
    let at = |i: usize, j: usize| depths[j * w + i];
    sample("the GeoTIFF", &axes, &at, o, path)
}

/// The raster's frame from its GeoKeys: `None` for longitude and latitude on WGS 84, the
/// zone's projection for WGS 84 / UTM; an error naming any other frame.
fn frame(keys: &[(u16, u16)], path: &Path) -> Result<Option<TransverseMercator>, EnvError> {
    let key = |id: u16| keys.iter().find(|(k, _)| *k == id).map(|(_, v)| *v);
    let projected = key(MODEL_TYPE) == Some(MODEL_PROJECTED)
        || (key(MODEL_TYPE).is_none() && key(PROJECTED_CS_TYPE).is_some());
    let projection = if projected {
        Some(utm_zone(
            key(PROJECTED_CS_TYPE),
            key(PROJ_LINEAR_UNITS),
            path,
        )?)
    } else {
        None
    };
    if projection.is_none()
        && key(MODEL_TYPE) != Some(MODEL_GEOGRAPHIC)
        && key(GEOGRAPHIC_TYPE).is_none()
    {
        return Err(err(
            path,
            format!(
                "the GeoTIFF has no GeoKeys saying its frame (GTModelTypeGeoKey); a bathymetry \
                 GeoTIFF is on longitude and latitude, WGS 84 (EPSG:4326): {CONVERT}"
            ),
        ));
    }
    if let Some(code) = key(GEOGRAPHIC_TYPE)
        .filter(|c| projection.is_none() && *c != EPSG_WGS84 && *c != USER_DEFINED)
    {
        return Err(err(
            path,
            format!(
                "the GeoTIFF is on the geographic frame EPSG:{code}; only WGS 84 (EPSG:4326) is \
                 read: {CONVERT}"
            ),
        ));
    }
    Ok(projection)
}

/// The UTM zone of a projected GeoTIFF, from its `ProjectedCSTypeGeoKey` (`code`) and
/// `ProjLinearUnitsGeoKey` (`units`); any other projection is refused, its code named.
fn utm_zone(
    code: Option<u16>,
    units: Option<u16>,
    path: &Path,
) -> Result<TransverseMercator, EnvError> {
    let named = code
        .filter(|c| *c != USER_DEFINED)
        .map(|c| format!("ProjectedCSTypeGeoKey = {c}, EPSG:{c}"))
        .unwrap_or_else(|| "a user-defined projection".into());
    if let Some(c @ (32661 | 32761)) = code {
        let pole = if c == 32661 { "North" } else { "South" };
        return Err(err(
            path,
            format!(
                "the GeoTIFF is in a projected frame ({named}): WGS 84 / UPS {pole}, the polar \
                 stereographic beyond UTM's latitudes, which is not read; {CONVERT}"
            ),
        ));
    }
    let tm = match code.and_then(|c| TransverseMercator::utm_from_epsg(u32::from(c))) {
        Some(Ok(tm)) => tm,
        Some(Err(e)) => {
            return Err(err(
                path,
                format!("the GeoTIFF is in a projected frame ({named}): {e}; {CONVERT}"),
            ));
        }
        None => {
            return Err(err(
                path,
                format!(
                    "the GeoTIFF is in a projected frame ({named}); only longitude and latitude \
                     on WGS 84 (EPSG:4326) and WGS 84 / UTM (EPSG:32601 to 32660, 32701 to \
                     32760) are read: {CONVERT}, or to the site's UTM zone (`gdalwarp -t_srs \
                     EPSG:326NN`)"
                ),
            ));
        }
    };
    match units {
        None | Some(LINEAR_METER) => Ok(tm),
        Some(u) => Err(err(
            path,
            format!(
                "the GeoTIFF is in {} with ProjLinearUnitsGeoKey = {u}; UTM is read in metres \
                 ({LINEAR_METER}): {CONVERT}",
                tm.name()
            ),
        )),
    }
}

/// The raster's values as numbers.
fn numbers(r: DecodingResult) -> Vec<f64> {
    match r {
        DecodingResult::U8(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U64(v) => v.into_iter().map(|x| x as f64).collect(),
        DecodingResult::F16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::F32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::F64(v) => v,
        DecodingResult::I8(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I64(v) => v.into_iter().map(|x| x as f64).collect(),
    }
}

#[cfg(test)]
mod tests;
