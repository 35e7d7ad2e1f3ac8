//! Tests of the seabed: the bathymetry reader (files written by the crate's own NetCDF writer)
//! and filaments over a sloping seabed.

use super::*;
use crate::field::ConcentrationField;
use crate::flow::MeanFlow;
use crate::flow::{FlowModel, UniformFlow};
use crate::plume::{FilamentParams, FilamentPlume, Source, VerticalBoundary};
use crate::test_files::rect;
use crate::{StreamId, stream_rng};
use plumetrace_core::Vec3;
use plumetrace_core::geo::Origin;
use plumetrace_netcdf::{Dataset, NcType};
use std::path::PathBuf;
use std::sync::Arc;

fn tmp(name: &str, bytes: &[u8]) -> PathBuf {
    crate::test_files::tmp_in(
        &format!("plumetrace-seabed-{}", std::process::id()),
        name,
        bytes,
    )
}

/// A projected grid, x 0..400 step 100, y 0..200 step 100: depth 30 m at x = 0 rising 5 m
/// per 100 m eastward (a 5 % slope).
fn projected() -> Dataset {
    projected_with(Some("m"), None)
}

/// [`projected`] with the depth's units (or none) and a fill value.
fn projected_with(units: Option<&str>, fill: Option<f64>) -> Dataset {
    let mut d = Dataset::default();
    let y = d.dim("y", 3);
    let x = d.dim("x", 5);
    d.var("y", &[y], vec![0.0, 100.0, 200.0])
        .attr("standard_name", "projection_y_coordinate")
        .attr("units", "m");
    d.var("x", &[x], vec![0.0, 100.0, 200.0, 300.0, 400.0])
        .attr("standard_name", "projection_x_coordinate")
        .attr("units", "m");
    let mut depth = Vec::new();
    for _ in 0..3 {
        for k in 0..5 {
            depth.push(30.0 - 5.0 * k as f64);
        }
    }
    let v = d
        .var("depth", &[y, x], depth)
        .attr("standard_name", "sea_floor_depth_below_sea_surface");
    if let Some(u) = units {
        v.attr("units", u);
    }
    if let Some(f) = fill {
        v.attr("_FillValue", f);
    }
    d
}

fn options() -> SeabedOptions {
    SeabedOptions {
        frame: None,
        area: rect(0.0, 400.0, 0.0, 200.0),
        must_cover: rect(50.0, 350.0, 50.0, 150.0),
        spacing_m: Some(50.0),
        variable: None,
    }
}

fn read(name: &str, d: &Dataset, o: &SeabedOptions) -> Result<Seabed, String> {
    let p = tmp(name, &d.to_bytes().unwrap());
    Seabed::from_netcdf(&p, o).map_err(|e| e.to_string())
}

#[test]
fn a_projected_depth_grid_gives_heights_above_the_deepest_point() {
    let s = read("slope.nc", &projected(), &options()).unwrap();
    assert_eq!(s.surface_m(), 30.0);
    assert_eq!(s.shallowest_m(), 10.0);
    assert!((s.height_at(0.0, 100.0) - 0.0).abs() < 1e-12);
    assert!((s.height_at(250.0, 37.0) - 12.5).abs() < 1e-12);
    assert!((s.depth_at(400.0, 200.0) - 10.0).abs() < 1e-12);
    // Beyond the grid: the edge's value; a NaN position does not panic.
    assert!((s.height_at(-50.0, 500.0) - 0.0).abs() < 1e-12);
    assert!(s.height_at(f64::NAN, 0.0).is_finite());
}

/// GEBCO's layout: `elevation` on lat/lon, negative below sea level, integers.
fn gebco(land_at: Option<usize>) -> Dataset {
    let mut d = Dataset::default();
    let la = d.dim("lat", 4);
    let lo = d.dim("lon", 5);
    d.var("lat", &[la], vec![49.97, 49.99, 50.01, 50.03])
        .attr("standard_name", "latitude")
        .attr("units", "degrees_north");
    d.var("lon", &[lo], vec![-4.04, -4.02, -4.0, -3.98, -3.96])
        .attr("standard_name", "longitude")
        .attr("units", "degrees_east");
    let mut e: Vec<f64> = (0..20).map(|k| -40.0 + (k % 5) as f64).collect();
    if let Some(k) = land_at {
        e[k] = 300.0;
    }
    d.var("elevation", &[la, lo], e)
        .of_type(NcType::Short)
        .attr("standard_name", "height_above_reference_ellipsoid")
        .attr("units", "m");
    d
}

#[test]
fn a_gebco_elevation_on_longitude_and_latitude_is_read_as_depth() {
    let s = read("gebco.nc", &gebco(None), &geo_options()).unwrap();
    // -40 m at lon -4.04, one metre shallower each 0.02 deg east: -38 m at the origin.
    assert!(
        (s.depth_at(0.0, 0.0) - 38.0).abs() < 0.01,
        "{}",
        s.depth_at(0.0, 0.0)
    );
    // Land (elevation > 0) outside the op-area takes the shallowest water.
    let s = read("land-out.nc", &gebco(Some(0)), &geo_options()).unwrap();
    assert!(s.depth_at(-1000.0, -1000.0) > 0.0);
    let e = read("land-in.nc", &gebco(Some(7)), &geo_options()).unwrap_err();
    assert!(
        e.contains("variable elevation: the seabed is at or above the surface")
            && e.contains("inside the op-area")
            && e.contains("positive = \"up\""),
        "{e}"
    );
}

#[test]
fn the_errors_name_the_variable_attribute_or_dimension_and_suggest() {
    // A typo'd variable.
    let mut o = options();
    o.variable = Some("dept".into());
    let e = read("typo.nc", &projected(), &o).unwrap_err();
    assert!(
        e.contains(
            "typo.nc: bathymetry.variable = \"dept\": no such variable; did you mean \"depth\"?"
        ),
        "{e}"
    );
    // No depth at all.
    let mut d = Dataset::default();
    let x = d.dim("x", 2);
    let y = d.dim("y", 2);
    d.var("x", &[x], vec![0.0, 1.0]).attr("axis", "X");
    d.var("y", &[y], vec![0.0, 1.0]).attr("axis", "Y");
    d.var("temp", &[y, x], vec![1.0; 4]).attr("units", "K");
    let e = read("none.nc", &d, &options()).unwrap_err();
    assert!(
        e.contains("no seabed depth") && e.contains("name it with bathymetry.variable"),
        "{e}"
    );
    // Units that are not a length, and none.
    let e = read("nounits.nc", &projected_with(None, None), &options()).unwrap_err();
    assert!(
        e.contains("variable depth: no attribute units (m or km expected)"),
        "{e}"
    );
    let e = read(
        "units.nc",
        &projected_with(Some("fathoms"), None),
        &options(),
    )
    .unwrap_err();
    assert!(
        e.contains("variable depth: attribute units = \"fathoms\" is not a length (m or km)"),
        "{e}"
    );
    // A fill value inside the op-area.
    let e = read(
        "fill.nc",
        &projected_with(Some("m"), Some(20.0)),
        &options(),
    )
    .unwrap_err();
    assert!(
        e.contains("variable depth: a missing value (_FillValue or missing_value) at")
            && e.contains("where the op-area needs the seabed"),
        "{e}"
    );
    // A grid that does not cover the op-area.
    let mut o = options();
    o.must_cover = rect(50.0, 450.0, 50.0, 150.0);
    let e = read("cover.nc", &projected(), &o).unwrap_err();
    assert!(
        e.contains("the bathymetry's grid (x 0 to 400, y 0 to 200) does not cover the op-area"),
        "{e}"
    );
    // Longitude and latitude without an origin.
    let mut o = geo_options();
    o.frame = None;
    let e = read("origin.nc", &gebco(None), &o).unwrap_err();
    assert!(
        e.contains("give the site's origin ([origin] lat_deg and lon_deg)"),
        "{e}"
    );
    // A time axis.
    let mut d = Dataset::default();
    let t = d.dim("time", 2);
    let y = d.dim("y", 2);
    let x = d.dim("x", 2);
    d.var("time", &[t], vec![0.0, 1.0])
        .attr("units", "hours since 2026-01-01");
    d.var("x", &[x], vec![0.0, 400.0]).attr("axis", "X");
    d.var("y", &[y], vec![0.0, 200.0]).attr("axis", "Y");
    d.var("h", &[t, y, x], vec![10.0; 8]).attr("units", "m");
    let e = read("time.nc", &d, &options()).unwrap_err();
    assert!(
        e.contains(
            "variable h: dimension time is a time axis of 2 values; a seabed is one 2-D grid"
        ),
        "{e}"
    );
    // Not a file, not NetCDF.
    let e = Seabed::from_netcdf(Path::new("/no/such/seabed.nc"), &options())
        .unwrap_err()
        .to_string();
    assert!(e.contains("/no/such/seabed.nc"), "{e}");
    let e = Seabed::from_netcdf(&tmp("text.nc", b"x,y,depth\n"), &options())
        .unwrap_err()
        .to_string();
    assert!(e.contains("text.nc"), "{e}");
}

/// A 10 % slope rising eastward across 200 m (20 m), in 40 m of water at the west.
fn slope() -> Arc<Seabed> {
    let area = rect(0.0, 200.0, -50.0, 50.0);
    let depths: Vec<f64> = (0..3 * 21)
        .map(|k| 40.0 - 0.1 * (10.0 * (k % 21) as f64))
        .collect();
    Arc::new(Seabed::from_depths(area, 21, 3, &depths).unwrap())
}

#[test]
fn filaments_never_go_below_a_sloping_seabed() {
    let sb = slope();
    let area = rect(0.0, 200.0, -50.0, 50.0);
    let params = FilamentParams {
        vertical: VerticalBoundary::Reflecting {
            depth_m: Some(sb.surface_m()),
        },
        // A strong vertical walk, so that many filaments meet the seabed.
        dispersion: crate::plume::Dispersion::Physical {
            horizontal_m2ps: 0.05,
            vertical_m2ps: 0.05,
        },
        ..FilamentParams::default()
    };
    // A source on the seabed, 0.1 m up, in a current running upslope.
    let src = Vec3::new(20.0, 0.0, sb.height_at(20.0, 0.0) + 0.1);
    let mut p = FilamentPlume::new(
        area,
        vec![Source {
            pos_m: src,
            mass_rate_per_s: 1.0,
            filament_rate_hz: 20.0,
        }],
        params,
    )
    .unwrap();
    p.set_seabed(Some(sb.clone()));
    let flow = FlowModel::Uniform(
        UniformFlow::new(MeanFlow::Steady {
            speed_mps: 0.3,
            toward_deg: 90.0,
        })
        .unwrap(),
    );
    let mut rng = stream_rng(7, StreamId::Plume);
    let mut checked = 0usize;
    let mut near = 0usize;
    for k in 1..=600 {
        p.step(&flow, k as f64, 1.0, &mut rng);
        for (pos, _) in p.filaments() {
            let f = sb.height_at(pos.x, pos.y);
            assert!(pos.z >= f, "filament at {pos:?} below the seabed at {f}");
            assert!(pos.z <= sb.surface_m());
            checked += 1;
            near += usize::from(pos.z - f < 0.5);
        }
    }
    assert!(checked > 100_000 && near > 1000, "{checked} {near}");
    // The concentration at the seabed adds the image there: the index and the scan agree.
    p.prepare_queries();
    let q = Vec3::new(60.0, 0.0, sb.height_at(60.0, 0.0) + 0.2);
    let (a, b) = (p.concentration(q), p.concentration_full_scan(q));
    assert!(a > 0.0 && (a - b).abs() <= 1e-9 * a, "{a} {b}");
}

#[test]
fn a_file_deeper_than_the_deepest_ocean_is_refused_with_where() {
    // The projected grid's 10-30 m read as kilometres: 30,000 m is a unit gone wrong.
    let e = read("km.nc", &projected_with(Some("km"), None), &options()).unwrap_err();
    assert!(
        e.contains(
            "km.nc: variable depth: a depth of 30000.0 m at (0.0, 0.0) m, deeper than \
             the deepest ocean (11000 m)"
        ),
        "{e}"
    );
}

#[test]
fn from_depths_refuses_what_is_not_water() {
    let area = rect(0.0, 1.0, 0.0, 1.0);
    let e = Seabed::from_depths(area, 2, 2, &[1.0, 2.0, 0.0, 3.0]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "depths[2]: must be a finite depth > 0 m and at most 11000 m (the deepest ocean), got 0.0"
    );
    let e = Seabed::from_depths(area, 2, 2, &[1.0, 2.0, 11_000.5, 3.0]).unwrap_err();
    assert!(e.to_string().starts_with("depths[2]: "), "{e}");
    assert!(Seabed::from_depths(area, 2, 2, &[1.0, 2.0, 11_000.0, 3.0]).is_ok());
    assert!(Seabed::from_depths(area, 1, 2, &[1.0, 2.0]).is_err());
    assert!(Seabed::from_depths(area, 2, 2, &[1.0]).is_err());
}

/// The 5 % slope of [`projected`] on a curvilinear grid: projected 2-D x and y turned 20° about
/// (200, 100) m, 9 x 9 nodes 60 m apart (ROMS's `h` on `x_rho` and `y_rho`).
fn turned_slope() -> Dataset {
    let mut d = Dataset::default();
    let eta = d.dim("eta_rho", 9);
    let xi = d.dim("xi_rho", 9);
    let (s, c) = 20f64.to_radians().sin_cos();
    let (mut xs, mut ys, mut h) = (vec![], vec![], vec![]);
    for j in 0..9 {
        for i in 0..9 {
            let (a, b) = (60.0 * i as f64 - 240.0, 60.0 * j as f64 - 240.0);
            let (x, y) = (200.0 + c * a - s * b, 100.0 + s * a + c * b);
            xs.push(x);
            ys.push(y);
            h.push(30.0 - 0.05 * x);
        }
    }
    d.var("x_rho", &[eta, xi], xs)
        .attr("standard_name", "projection_x_coordinate")
        .attr("units", "m");
    d.var("y_rho", &[eta, xi], ys)
        .attr("standard_name", "projection_y_coordinate")
        .attr("units", "m");
    d.var("h", &[eta, xi], h)
        .attr("units", "m")
        .attr("coordinates", "x_rho y_rho");
    d
}

#[test]
fn a_curvilinear_bathymetry_samples_the_slope_it_holds() {
    let s = read("turned-slope.nc", &turned_slope(), &options()).unwrap();
    let flat = read("slope-again.nc", &projected(), &options()).unwrap();
    // A plane is reproduced exactly by bilinear cells (to rounding), turned or not.
    for (x, y) in [(50.0, 50.0), (200.0, 100.0), (333.0, 140.0), (120.0, 75.0)] {
        let (a, b) = (s.depth_at(x, y), flat.depth_at(x, y));
        assert!((a - b).abs() < 1e-9, "({x}, {y}): {a} against {b}");
    }
    let mut o = options();
    o.must_cover = rect(0.0, 400.0, -200.0, 150.0);
    let e = read("turned-short.nc", &turned_slope(), &o).unwrap_err();
    assert!(
        e.contains("the bathymetry's curvilinear grid (x_rho and y_rho: x ")
            && e.contains("does not cover the op-area"),
        "{e}"
    );
}

#[test]
fn the_shared_cell_lookup_gives_the_heights_of_the_seabed_s_own_bit_for_bit() {
    // The lookup the seabed had before it shared the flow grid's.
    fn own(s: &Seabed, x: f64, y: f64) -> f64 {
        let fx = ((x - s.x0) / s.dx).clamp(0.0, (s.nx - 1) as f64);
        let fy = ((y - s.y0) / s.dy).clamp(0.0, (s.ny - 1) as f64);
        let i = (fx as usize).min(s.nx - 2);
        let j = (fy as usize).min(s.ny - 2);
        let (tx, ty) = (fx - i as f64, fy - j as f64);
        let tx = if tx.is_finite() { tx } else { 0.0 };
        let ty = if ty.is_finite() { ty } else { 0.0 };
        let h = |a: usize, b: usize| s.height[b * s.nx + a];
        let south = h(i, j) + tx * (h(i + 1, j) - h(i, j));
        let north = h(i, j + 1) + tx * (h(i + 1, j + 1) - h(i, j + 1));
        south + ty * (north - south)
    }
    let mut o = options();
    o.spacing_m = Some(37.0);
    let s = read("lookup.nc", &projected(), &o).unwrap();
    let mut rng = stream_rng(3, StreamId::Flow);
    use rand::Rng;
    let mut points: Vec<(f64, f64)> = (0..20_000)
        .map(|_| {
            (
                rng.random_range(-50.0..450.0),
                rng.random_range(-50.0..250.0),
            )
        })
        .collect();
    points.extend([
        (f64::NAN, 10.0),
        (10.0, f64::NAN),
        (f64::INFINITY, f64::NEG_INFINITY),
        (-0.0, 0.0),
        (400.0, 200.0),
        (0.0, 0.0),
    ]);
    for (x, y) in points {
        assert_eq!(
            s.height_at(x, y).to_bits(),
            own(&s, x, y).to_bits(),
            "({x}, {y})"
        );
    }
}

/// A GeoTIFF of `w` x `h` float pixels 0.005° a side from (4.03 W, 50.02 N), tagged with the
/// GeoKeys `keys` (id, value), holding `value(lon, lat)` at each pixel's centre, with GDAL's
/// no-data tag `-9999`: written with the TIFF crate's encoder, GeoTIFF tags by number.
fn geotiff(w: usize, h: usize, keys: &[(u16, u16)], value: impl Fn(f64, f64) -> f64) -> Vec<u8> {
    use tiff::encoder::{TiffEncoder, colortype::Gray32Float};
    use tiff::tags::Tag;
    let mut data = Vec::new();
    for j in 0..h {
        for i in 0..w {
            let (lon, lat) = geotiff_node(i, j);
            data.push(value(lon, lat) as f32);
        }
    }
    let mut dir: Vec<u16> = vec![1, 1, 0, keys.len() as u16];
    for (k, v) in keys {
        dir.extend([*k, 0, 1, *v]);
    }
    let mut out = Cursor::new(Vec::new());
    let mut enc = TiffEncoder::new(&mut out).unwrap();
    let mut image = enc.new_image::<Gray32Float>(w as u32, h as u32).unwrap();
    let e = image.encoder();
    e.write_tag(Tag::ModelPixelScaleTag, &[0.005f64, 0.005, 0.0][..])
        .unwrap();
    e.write_tag(
        Tag::ModelTiepointTag,
        &[0.0f64, 0.0, 0.0, -4.03, 50.02, 0.0][..],
    )
    .unwrap();
    e.write_tag(Tag::GeoKeyDirectoryTag, &dir[..]).unwrap();
    e.write_tag(Tag::Unknown(42113), "-9999").unwrap();
    image.write_data(&data).unwrap();
    out.into_inner()
}

use std::io::Cursor;

/// The centre of pixel `(i, j)`, as a GeoTIFF reader computes it.
fn geotiff_node(i: usize, j: usize) -> (f64, f64) {
    (
        -4.03 + (i as f64 + 0.5) * 0.005,
        50.02 - (j as f64 + 0.5) * 0.005,
    )
}

const WGS84: &[(u16, u16)] = &[(1024, 2), (1025, 1), (2048, 4326)];

/// A site at (50 N, 4 W): a 2 km domain around the origin, its inner kilometre the op-area,
/// 100 m nodes (the GEBCO-style NetCDF grids and the GeoTIFFs alike).
fn geo_options() -> SeabedOptions {
    SeabedOptions {
        frame: Some(
            LocalFrame::new(Origin {
                lat_deg: 50.0,
                lon_deg: -4.0,
            })
            .unwrap(),
        ),
        area: rect(-1000.0, 1000.0, -1000.0, 1000.0),
        must_cover: rect(-500.0, 500.0, -500.0, 500.0),
        spacing_m: Some(100.0),
        variable: None,
    }
}

/// GEBCO-style elevation: -20 m at 4.03 W falling 1 m per 0.001° eastward.
fn east_slope(lon: f64, _lat: f64) -> f64 {
    -20.0 - 1000.0 * (lon + 4.03)
}

#[test]
fn a_geotiff_reads_as_the_same_grid_in_netcdf_bit_for_bit() {
    let (w, h) = (13, 9);
    let tif = tmp("slope.tif", &geotiff(w, h, WGS84, east_slope));
    let from_tiff = Seabed::from_file(&tif, &geo_options()).unwrap();
    let mut d = Dataset::default();
    let la = d.dim("lat", h);
    let lo = d.dim("lon", w);
    d.var("lat", &[la], (0..h).map(|j| geotiff_node(0, j).1).collect())
        .attr("units", "degrees_north");
    d.var("lon", &[lo], (0..w).map(|i| geotiff_node(i, 0).0).collect())
        .attr("units", "degrees_east");
    let mut z = Vec::new();
    for j in 0..h {
        for i in 0..w {
            let (lon, lat) = geotiff_node(i, j);
            z.push(f64::from(east_slope(lon, lat) as f32));
        }
    }
    d.var("elevation", &[la, lo], z)
        .attr("standard_name", "height_above_mean_sea_level")
        .attr("units", "m");
    let from_nc = read("slope.nc", &d, &geo_options()).unwrap();
    assert_eq!(from_tiff, from_nc);
    // 20 m deep at 4.03 W, 80 m at 3.97 W: about 40 m deep at the origin.
    assert!((from_tiff.depth_at(0.0, 0.0) - 50.0).abs() < 0.5);
    // Positive values are depths; no-data far from the op-area takes the shallowest water.
    let depths = geotiff(w, h, WGS84, |lon, lat| {
        if lat > 50.015 {
            -9999.0
        } else {
            -east_slope(lon, lat)
        }
    });
    let s = Seabed::from_file(&tmp("depths.tif", &depths), &geo_options()).unwrap();
    assert_eq!(s.depth_at(0.0, 0.0), from_tiff.depth_at(0.0, 0.0));
}

#[test]
fn a_geotiff_in_another_frame_or_cut_short_is_located() {
    let o = geo_options();
    let utm = tmp(
        "utm.tif",
        &geotiff(13, 9, &[(1024, 1), (3072, 27700)], east_slope),
    );
    let e = Seabed::from_file(&utm, &o).unwrap_err().to_string();
    assert!(
        e.contains(
            "utm.tif: the GeoTIFF is in a projected frame (ProjectedCSTypeGeoKey = 27700, \
             EPSG:27700); only longitude and latitude on WGS 84 (EPSG:4326) and WGS 84 / UTM"
        ) && e.contains("gdal_translate -of netCDF IN.tif OUT.nc"),
        "{e}"
    );
    let nad = tmp(
        "nad27.tif",
        &geotiff(13, 9, &[(1024, 2), (2048, 4267)], east_slope),
    );
    let e = Seabed::from_file(&nad, &o).unwrap_err().to_string();
    assert!(e.contains("geographic frame EPSG:4267"), "{e}");
    let bare = tmp("bare.tif", &geotiff(13, 9, &[], east_slope));
    let e = Seabed::from_file(&bare, &o).unwrap_err().to_string();
    assert!(e.contains("no GeoKeys saying its frame"), "{e}");
    let whole = geotiff(13, 9, WGS84, east_slope);
    let cut = tmp("cut.tif", &whole[..whole.len() / 2]);
    let e = Seabed::from_file(&cut, &o).unwrap_err().to_string();
    assert!(
        e.contains("cut.tif: the GeoTIFF could not be read: "),
        "{e}"
    );
    let mut small = o.clone();
    small.must_cover = rect(-500.0, 2500.0, -500.0, 500.0);
    small.area = rect(-1000.0, 3000.0, -1000.0, 1000.0);
    let e = Seabed::from_file(&tmp("small.tif", &whole), &small)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("the bathymetry's grid (lon ") && e.contains("does not cover"),
        "{e}"
    );
    let mut named = o;
    named.variable = Some("elevation".into());
    let e = Seabed::from_file(&tmp("named.tif", &whole), &named)
        .unwrap_err()
        .to_string();
    assert!(e.contains("a GeoTIFF holds one band"), "{e}");
}
