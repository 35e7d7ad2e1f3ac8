//! Transverse Mercator and UTM against published values, the meridian arc and round trips.

use super::*;
use geographiclib_rs::{Geodesic, InverseGeodesic};

fn utm(zone: i64, north: bool) -> TransverseMercator {
    TransverseMercator::utm(zone, north).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn round_trips_across_zones_and_hemispheres_within_a_nanodegree() {
    let mut worst: f64 = 0.0;
    let mut worst_m: f64 = 0.0;
    for zone in [1, 2, 18, 30, 31, 33, 59, 60] {
        for north in [true, false] {
            let tm = utm(zone, north);
            let cm = tm.params().central_meridian_deg;
            let lats: Vec<f64> = if north {
                vec![0.0, 0.5, 12.0, 36.18, 45.0, 60.0, 72.5, 80.0, 84.0, 84.5]
            } else {
                vec![-0.5, -12.0, -33.9, -45.0, -60.0, -72.5, -80.0, -80.5]
            };
            for &lat in &lats {
                // Across the zone (3 deg each side) and well beyond it.
                for dlon in [
                    -15.0, -9.0, -3.0, -2.9, -1.0, 0.0, 0.7, 3.0, 6.0, 12.0, 15.0,
                ] {
                    let lon = crate::wrap_deg_180(cm + dlon);
                    let (e, n) = tm.forward(lat, lon).unwrap_or_else(|e| panic!("{e}"));
                    let (lat2, lon2) = tm.inverse(e, n).unwrap_or_else(|e| panic!("{e}"));
                    let d = (lat2 - lat)
                        .abs()
                        .max(crate::wrap_deg_180(lon2 - lon).abs());
                    assert!(
                        d < 1e-9,
                        "zone {zone} {north} ({lat}, {lon}): {lat2}, {lon2}"
                    );
                    worst = worst.max(d);
                    let (e2, n2) = tm.forward(lat2, lon2).unwrap_or_else(|e| panic!("{e}"));
                    worst_m = worst_m.max((e2 - e).abs().max((n2 - n).abs()));
                }
            }
        }
    }
    assert!(worst_m < 1e-6, "worst forward-inverse-forward {worst_m} m");
    eprintln!("worst round trip {worst:e} deg, {worst_m:e} m");
}

#[test]
fn the_central_meridian_is_the_meridian_arc_times_the_scale() {
    // On the central meridian the northing is k0 times the meridian arc from the equator,
    // which GeographicLib's geodesic gives exactly: this checks every forward coefficient.
    let g = Geodesic::wgs84();
    let tm = utm(31, true);
    for lat in [1.0, 10.0, 25.0, 36.18, 45.0, 60.0, 75.0, 84.0] {
        let s: f64 = g.inverse(0.0, 3.0, lat, 3.0);
        let (e, n) = tm.forward(lat, 3.0).unwrap_or_else(|e| panic!("{e}"));
        assert!((e - 500_000.0).abs() < 1e-9, "{lat}: {e}");
        assert!(
            (n - 0.9996 * s).abs() < 1e-6,
            "{lat}: {n} vs {}",
            0.9996 * s
        );
    }
    // The south's false northing puts the equator at 10 000 km.
    let (_, n) = utm(31, false)
        .forward(-45.0, 3.0)
        .unwrap_or_else(|e| panic!("{e}"));
    let s: f64 = g.inverse(0.0, 3.0, -45.0, 3.0);
    assert!((n - (10_000_000.0 - 0.9996 * s)).abs() < 1e-6, "{n}");
}

#[test]
fn the_map_is_conformal_off_the_meridian() {
    // Steps of 10 m in four directions (central differences along geodesics) scale alike.
    use geographiclib_rs::DirectGeodesic;
    let g = Geodesic::wgs84();
    let tm = utm(18, true);
    for (lat, lon) in [(36.18, -75.75), (10.0, -66.0), (60.0, -87.0)] {
        let scale = |azi: f64| {
            let (la, lo): (f64, f64) = g.direct(lat, lon, azi, 5.0);
            let (lb, lb_lon): (f64, f64) = g.direct(lat, lon, azi + 180.0, 5.0);
            let a = tm.forward(la, lo).unwrap_or_else(|e| panic!("{e}"));
            let b = tm.forward(lb, lb_lon).unwrap_or_else(|e| panic!("{e}"));
            (a.0 - b.0).hypot(a.1 - b.1) / 10.0
        };
        let k: Vec<f64> = [0.0, 45.0, 90.0, 137.0].iter().map(|&a| scale(a)).collect();
        for w in k.windows(2) {
            assert!((w[0] - w[1]).abs() < 1e-9, "({lat}, {lon}): {k:?}");
        }
    }
}

#[test]
fn published_points_are_reproduced() {
    // GeographicLib's GeoConvert manual page: 33.3 44.4 is "38n 444140.54 3684706.36".
    let (e, n) = utm(38, true)
        .forward(33.3, 44.4)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!((e - 444_140.54).abs() < 0.005, "{e}");
    assert!((n - 3_684_706.36).abs() < 0.005, "{n}");
    // The British National Grid (OSGB 1936 on the Airy 1830 ellipsoid; latitude of origin
    // 49 N, so these also check the origin's northing).
    let bng = TransverseMercator::on_ellipsoid(
        6_377_563.396,
        1.0 / 299.324_964_6,
        TmParams {
            central_meridian_deg: -2.0,
            origin_lat_deg: 49.0,
            scale: 0.999_601_271_7,
            false_easting_m: 400_000.0,
            false_northing_m: -100_000.0,
        },
        "British National Grid",
        (-90.0, 90.0),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    // Ordnance Survey, "A guide to coordinate systems in Great Britain", the worked example of
    // its annex C: 52 deg 39' 27.2531" N, 1 deg 43' 4.5177" E is E 651409.903 m, N 313177.270 m
    // (given to the millimetre).
    let (lat, lon) = (
        52.0 + 39.0 / 60.0 + 27.2531 / 3600.0,
        1.0 + 43.0 / 60.0 + 4.5177 / 3600.0,
    );
    let (e, n) = bng.forward(lat, lon).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("OS guide: {e:.4} {n:.4}");
    assert!((e - 651_409.903).abs() < 0.001, "{e}");
    assert!((n - 313_177.270).abs() < 0.001, "{n}");
    // EPSG Guidance Note 7-2, its transverse Mercator example: 50 deg 30' N, 0 deg 30' E is
    // E 577274.99 m, N 69740.50 m, given to the centimetre (met within 6 and 8 mm: the note's
    // numbers come from a shorter series; the Ordnance Survey's above agree to 0.1 mm).
    let (e, n) = bng.forward(50.5, 0.5).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("EPSG 7-2: {e:.4} {n:.4}");
    assert!((e - 577_274.99).abs() < 0.01, "{e}");
    assert!((n - 69_740.50).abs() < 0.01, "{n}");
    let (lat, lon) = bng
        .inverse(577_274.99, 69_740.50)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        (lat - 50.5).abs() < 1e-7 && (lon - 0.5).abs() < 1e-7,
        "{lat} {lon}"
    );
}

#[test]
fn zones_and_limits_are_refused_with_what_is_wrong() {
    for zone in [0, 61, -3] {
        assert_eq!(
            TransverseMercator::utm(zone, true).err(),
            Some(ProjectionError::Zone(zone))
        );
    }
    assert_eq!(
        ProjectionError::Zone(61).to_string(),
        "UTM zone 61 does not exist (zones are 1 to 60)"
    );
    let tm = utm(18, true);
    let e = tm.forward(85.0, -75.0).err().map(|e| e.to_string());
    assert_eq!(
        e.as_deref(),
        Some("latitude 85 deg is outside UTM zone 18N's limits (-80.5 to 84.5 deg)")
    );
    let e = tm.forward(36.0, -44.0).err().map(|e| e.to_string());
    assert_eq!(
        e.as_deref(),
        Some(
            "longitude -44 deg is 31.0 deg from UTM zone 18N's central meridian (-75 deg); \
             more than 30 deg away the projection is not used"
        )
    );
    // An easting far beyond the zone (inverse) and a NaN.
    assert!(matches!(
        tm.inverse(4_500_000.0, 4_000_000.0),
        Err(ProjectionError::Longitude { .. })
    ));
    assert!(matches!(
        tm.forward(f64::NAN, -75.0),
        Err(ProjectionError::NotFinite { .. })
    ));
    // The EPSG codes of WGS 84 / UTM, and the neighbours that are not UTM zones.
    let z = |c| TransverseMercator::utm_from_epsg(c).map(|r| r.map(|t| t.name().to_string()));
    assert_eq!(z(32618), Some(Ok("UTM zone 18N".into())));
    assert_eq!(z(32760), Some(Ok("UTM zone 60S".into())));
    assert_eq!(z(32600), Some(Err(ProjectionError::Zone(0))));
    assert_eq!(z(32761), Some(Err(ProjectionError::Zone(61))));
    assert_eq!(z(4326), None);
    assert_eq!(z(27700), None);
}
