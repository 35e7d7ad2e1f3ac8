//! Tests of the GeoTIFF reader in UTM: seabeds written by the test in a zone read back in the
//! local frame, and the projections that are refused.

use super::super::{Seabed, SeabedOptions};
use crate::test_files::rect;
use plumetrace_core::Vec2;
use plumetrace_core::geo::{LocalFrame, Origin, TransverseMercator};
use std::io::Cursor;
use std::path::PathBuf;

fn tmp(name: &str, bytes: &[u8]) -> PathBuf {
    crate::test_files::tmp_in(
        &format!("plumetrace-utm-tiff-{}", std::process::id()),
        name,
        bytes,
    )
}

fn frame(lat_deg: f64, lon_deg: f64) -> LocalFrame {
    LocalFrame::new(Origin { lat_deg, lon_deg }).unwrap()
}

/// A GeoTIFF of `n` x `n` float pixels `step` m a side whose first pixel's corner (or centre,
/// with `point`) is at `corner` (easting, northing), tagged with the GeoKeys `keys`, holding
/// `value(easting, northing)` at each node.
fn utm_tiff(
    n: usize,
    step: f64,
    corner: (f64, f64),
    point: bool,
    keys: &[(u16, u16)],
    value: impl Fn(f64, f64) -> f64,
) -> Vec<u8> {
    use tiff::encoder::{TiffEncoder, colortype::Gray32Float};
    use tiff::tags::Tag;
    let half = if point { 0.0 } else { 0.5 };
    let mut data = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let e = corner.0 + (i as f64 + half) * step;
            let nn = corner.1 - (j as f64 + half) * step;
            data.push(value(e, nn) as f32);
        }
    }
    let mut dir: Vec<u16> = vec![1, 1, 0, keys.len() as u16];
    for (k, v) in keys {
        dir.extend([*k, 0, 1, *v]);
    }
    let mut out = Cursor::new(Vec::new());
    let mut enc = TiffEncoder::new(&mut out).unwrap();
    let mut image = enc.new_image::<Gray32Float>(n as u32, n as u32).unwrap();
    let e = image.encoder();
    e.write_tag(Tag::ModelPixelScaleTag, &[step, step, 0.0][..])
        .unwrap();
    e.write_tag(
        Tag::ModelTiepointTag,
        &[0.0f64, 0.0, 0.0, corner.0, corner.1, 0.0][..],
    )
    .unwrap();
    e.write_tag(Tag::GeoKeyDirectoryTag, &dir[..]).unwrap();
    image.write_data(&data).unwrap();
    out.into_inner()
}

fn options(f: LocalFrame) -> SeabedOptions {
    SeabedOptions {
        frame: Some(f),
        area: rect(-1500.0, 1500.0, -1500.0, 1500.0),
        must_cover: rect(-1000.0, 1000.0, -1000.0, 1000.0),
        spacing_m: Some(25.0),
        variable: None,
    }
}

/// The seabed the tests write: 200 m deep at the origin, 10 % deeper each metre east in the
/// local frame (so a turned or scaled grid shows at once: the zone's grid north is 0.8 deg off
/// true north at the first site, its scale 0.9996).
fn slope(x: f64) -> f64 {
    200.0 + 0.1 * x
}

/// Writes the slope around `(lat, lon)` in EPSG `code` (pixels as areas or points), reads it
/// back, and returns the largest depth error at local points over the op-area, m.
fn slope_error(lat: f64, lon: f64, code: u16, point: bool) -> f64 {
    let f = frame(lat, lon);
    let tm = TransverseMercator::utm_from_epsg(u32::from(code))
        .unwrap()
        .unwrap();
    let (e0, n0) = tm.forward(lat, lon).unwrap();
    // 25 m pixels over 3.2 km, their edges on whole metres.
    let corner = ((e0 - 1600.0).round(), (n0 + 1600.0).round());
    let depth = |e: f64, n: f64| {
        let (la, lo) = tm.inverse(e, n).unwrap();
        slope(f.to_local(la, lo).x)
    };
    let mut keys = vec![(1024, 1), (3072, code), (3076, 9001)];
    if point {
        keys.push((1025, 2));
    }
    let name = format!("slope-{code}-{point}.tif");
    let path = tmp(&name, &utm_tiff(129, 25.0, corner, point, &keys, depth));
    let s = Seabed::from_file(&path, &options(f.clone())).unwrap();
    let mut worst: f64 = 0.0;
    for k in 0..=40 {
        for l in 0..=40 {
            let (x, y) = (-1000.0 + 50.0 * k as f64, -1000.0 + 50.0 * l as f64);
            worst = worst.max((s.depth_at(x, y) - slope(x)).abs());
        }
    }
    // The local points agree with the geodesy: one of them is where the zone says.
    let (la, lo) = f.to_geographic(Vec2::new(700.0, -300.0));
    let (e, n) = tm.forward(la, lo).unwrap();
    assert!((depth(e, n) - slope(700.0)).abs() < 1e-9);
    worst
}

#[test]
fn a_utm_geotiff_reads_back_as_the_seabed_it_was_written_from() {
    // Off Plymouth in zone 30N, 1 deg west of its central meridian; off Sydney in zone 56S.
    // And off Plymouth in the next zone west, 29N, 5 deg from its central meridian.
    for (lat, lon, code) in [
        (50.0, -4.0, 32630),
        (-33.9, 151.3, 32756),
        (50.0, -4.0, 32629),
    ] {
        for point in [false, true] {
            let worst = slope_error(lat, lon, code, point);
            eprintln!("EPSG:{code} pixel-is-point {point}: worst {worst:.2e} m");
            assert!(worst < 1e-3, "EPSG:{code} {point}: {worst} m");
        }
    }
}

#[test]
fn projections_other_than_utm_and_places_outside_the_zone_are_refused() {
    let f = frame(50.0, -4.0);
    let tm = TransverseMercator::utm(30, true).unwrap();
    let (e0, n0) = tm.forward(50.0, -4.0).unwrap();
    let corner = ((e0 - 1600.0).round(), (n0 + 1600.0).round());
    let write = |name: &str, keys: &[(u16, u16)]| {
        tmp(name, &utm_tiff(129, 25.0, corner, false, keys, |_, _| 30.0))
    };
    let read =
        |path: &PathBuf, o: &SeabedOptions| Seabed::from_file(path, o).unwrap_err().to_string();
    // British National Grid: named by its key and code, the conversions kept.
    let bng = write("bng.tif", &[(1024, 1), (3072, 27700)]);
    let e = read(&bng, &options(f.clone()));
    assert!(
        e.contains(
            "bng.tif: the GeoTIFF is in a projected frame (ProjectedCSTypeGeoKey = 27700, \
             EPSG:27700); only longitude and latitude on WGS 84 (EPSG:4326) and WGS 84 / UTM \
             (EPSG:32601 to 32660, 32701 to 32760) are read"
        ) && e.contains("gdalwarp -t_srs EPSG:4326 IN.tif OUT.tif")
            && e.contains("gdal_translate -of netCDF IN.tif OUT.nc")
            && e.contains("EPSG:326NN"),
        "{e}"
    );
    let user = write("user.tif", &[(1024, 1), (3072, 32767)]);
    assert!(read(&user, &options(f.clone())).contains("(a user-defined projection)"));
    // The codes either side of the series are not zones.
    for (code, zone) in [(32600, 0), (32700, 0), (32799, 99)] {
        let p = write(&format!("zone{code}.tif"), &[(1024, 1), (3072, code)]);
        let e = read(&p, &options(f.clone()));
        assert!(
            e.contains(&format!(
                "the GeoTIFF is in a projected frame (ProjectedCSTypeGeoKey = {code}, \
                 EPSG:{code}): UTM zone {zone} does not exist (zones are 1 to 60)"
            )),
            "{e}"
        );
    }
    // The poles' codes next to the series are UPS.
    let ups = write("ups.tif", &[(1024, 1), (3072, 32661)]);
    assert!(read(&ups, &options(f.clone())).contains(
        "(ProjectedCSTypeGeoKey = 32661, EPSG:32661): WGS 84 / UPS North, the polar stereographic \
         beyond UTM's latitudes, which is not read; reproject it"
    ));
    // Feet are refused.
    let feet = write("feet.tif", &[(1024, 1), (3072, 32630), (3076, 9002)]);
    assert!(
        read(&feet, &options(f.clone()))
            .contains("in UTM zone 30N with ProjLinearUnitsGeoKey = 9002"),
    );
    // A site beyond the zone's latitudes, or far from its meridian, and no origin at all.
    let utm = write("utm.tif", &[(1024, 1), (3072, 32630)]);
    let e = read(&utm, &options(frame(85.0, -4.0)));
    assert!(
        e.contains(
            "the bathymetry's grid is projected (UTM zone 30N), which cannot place the site's \
             origin (85, -4): latitude 85 deg is outside UTM zone 30N's limits (-80.5 to 84.5 \
             deg); reproject it to longitude and latitude (`gdalwarp -t_srs EPSG:4326`)"
        ) && !e.contains("own UTM zone"),
        "{e}"
    );
    let e = read(&utm, &options(frame(50.0, 40.0)));
    assert!(
        e.contains("longitude 40 deg is 43.0 deg from UTM zone 30N's central meridian"),
        "{e}"
    );
    let mut bare = options(f.clone());
    bare.frame = None;
    let e = read(&utm, &bare);
    assert!(
        e.contains(
            "the bathymetry's grid is projected (UTM zone 30N): give the site's origin \
             ([origin] lat_deg and lon_deg)"
        ),
        "{e}"
    );
    // A site in the zone the grid does not reach: the easting and northing are named.
    let e = read(&utm, &options(frame(50.2, -4.0)));
    assert!(
        e.contains("the bathymetry's grid (easting ") && e.contains("does not cover"),
        "{e}"
    );
}
