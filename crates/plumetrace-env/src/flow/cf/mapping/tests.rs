//! Tests of CF grids in a transverse Mercator grid mapping (UTM): currents and a seabed written
//! on a zone's eastings and northings read back in the local frame, and the mappings refused.

use crate::flow::FlowField;
use crate::flow::GriddedFlow;
use crate::flow::cf::CfOptions;
use crate::seabed::{Seabed, SeabedOptions};
use crate::test_files::rect;
use plumetrace_core::Vec2;
use plumetrace_core::geo::{LocalFrame, Origin, TransverseMercator};
use plumetrace_netcdf::Dataset;
use std::path::PathBuf;

fn tmp(name: &str, bytes: &[u8]) -> PathBuf {
    crate::test_files::tmp_in(
        &format!("plumetrace-cf-tm-{}", std::process::id()),
        name,
        bytes,
    )
}

/// Off Plymouth, 1 deg west of zone 30N's central meridian (grid north 0.77 deg off true).
fn frame() -> LocalFrame {
    LocalFrame::new(Origin {
        lat_deg: 50.0,
        lon_deg: -4.0,
    })
    .unwrap()
}

fn zone() -> TransverseMercator {
    TransverseMercator::utm(30, true).unwrap()
}

fn options() -> CfOptions {
    CfOptions {
        frame: Some(frame()),
        start_s: None,
        duration_s: 100.0,
        depth_m: None,
        area: rect(-1500.0, 1500.0, -1500.0, 1500.0),
        must_cover: rect(-1000.0, 1000.0, -1000.0, 1000.0),
        spacing_m: Some(25.0),
        u_variable: None,
        v_variable: None,
    }
}

/// The true current the tests write, east and north in the local frame, m/s.
fn current(p: Vec2) -> Vec2 {
    Vec2::new(0.2 + 1e-4 * p.x, -0.1 + 2e-4 * p.y)
}

/// Eastings and northings every 50 m over 3.4 km about the origin, and the local position of
/// each node (row by row from the south).
fn nodes() -> (Vec<f64>, Vec<f64>, Vec<Vec2>) {
    let (e0, n0) = zone().forward(50.0, -4.0).unwrap();
    let es: Vec<f64> = (0..69)
        .map(|i| (e0 - 1700.0).round() + 50.0 * i as f64)
        .collect();
    let ns: Vec<f64> = (0..69)
        .map(|j| (n0 - 1700.0).round() + 50.0 * j as f64)
        .collect();
    let f = frame();
    let mut local = Vec::new();
    for &n in &ns {
        for &e in &es {
            let (lat, lon) = zone().inverse(e, n).unwrap();
            local.push(f.to_local(lat, lon));
        }
    }
    (es, ns, local)
}

/// A dataset on the zone's grid with its grid mapping `crs` (attributes as GDAL writes them).
fn utm_dataset(es: &[f64], ns: &[f64]) -> (Dataset, usize, usize) {
    let (mut d, y, x) = grid_only(es, ns);
    d.var("crs", &[], vec![0.0])
        .attr("grid_mapping_name", "transverse_mercator")
        .attr("longitude_of_central_meridian", -3.0)
        .attr("latitude_of_projection_origin", 0.0)
        .attr("scale_factor_at_central_meridian", 0.9996)
        .attr("false_easting", 500_000.0)
        .attr("false_northing", 0.0)
        .attr("semi_major_axis", 6_378_137.0)
        .attr("inverse_flattening", 298.257_223_563);
    (d, y, x)
}

/// The grid's coordinates alone.
fn grid_only(es: &[f64], ns: &[f64]) -> (Dataset, usize, usize) {
    let mut d = Dataset::default();
    let y = d.dim("y", ns.len());
    let x = d.dim("x", es.len());
    d.var("y", &[y], ns.to_vec())
        .attr("standard_name", "projection_y_coordinate")
        .attr("units", "m");
    d.var("x", &[x], es.to_vec())
        .attr("standard_name", "projection_x_coordinate")
        .attr("units", "m");
    (d, y, x)
}

/// The error reading currents from `path`, as text.
fn error(path: &std::path::Path, o: &CfOptions) -> String {
    match GriddedFlow::from_netcdf(path, o) {
        Ok(_) => panic!("{} was read", path.display()),
        Err(e) => e.to_string(),
    }
}

fn worst(flow: &GriddedFlow) -> f64 {
    let mut w: f64 = 0.0;
    for k in 0..=40 {
        for l in 0..=40 {
            let p = Vec2::new(-1000.0 + 50.0 * k as f64, -1000.0 + 50.0 * l as f64);
            let (a, b) = (flow.velocity(p), current(p));
            w = w.max((a.x - b.x).abs().max((a.y - b.y).abs()));
        }
    }
    w
}

#[test]
fn currents_on_a_utm_grid_read_back_in_the_local_frame() {
    let (es, ns, local) = nodes();
    // East and north components.
    let (mut d, y, x) = utm_dataset(&es, &ns);
    d.var("u", &[y, x], local.iter().map(|p| current(*p).x).collect())
        .attr("standard_name", "eastward_sea_water_velocity")
        .attr("grid_mapping", "crs")
        .attr("units", "m s-1");
    d.var("v", &[y, x], local.iter().map(|p| current(*p).y).collect())
        .attr("standard_name", "northward_sea_water_velocity")
        .attr("grid_mapping", "crs")
        .attr("units", "m s-1");
    let p = tmp("east.nc", &d.to_bytes().unwrap());
    let flow = GriddedFlow::from_netcdf(&p, &options()).unwrap();
    let w = worst(&flow);
    eprintln!("eastward/northward: worst {w:.2e} m/s");
    assert!(w < 1e-6, "{w}");
    // Along the grid's axes (each node's own grid north, found by the test from the zone):
    // turned at the origin, so within the convergence's change over the area.
    let (mut d, y, x) = utm_dataset(&es, &ns);
    let f = frame();
    let (mut gu, mut gv) = (Vec::new(), Vec::new());
    let mut k = 0;
    for &n in &ns {
        for &e in &es {
            let (lat, lon) = zone().inverse(e + 1.0, n).unwrap();
            let ax = f.to_local(lat, lon) - local[k];
            let ax = ax * (1.0 / ax.x.hypot(ax.y));
            let c = current(local[k]);
            // Components along grid x (ax) and grid y (ax turned a quarter left).
            gu.push(c.x * ax.x + c.y * ax.y);
            gv.push(-c.x * ax.y + c.y * ax.x);
            k += 1;
        }
    }
    d.var("u", &[y, x], gu)
        .attr("standard_name", "sea_water_x_velocity")
        .attr("grid_mapping", "crs: x y")
        .attr("units", "m s-1");
    d.var("v", &[y, x], gv)
        .attr("standard_name", "sea_water_y_velocity")
        .attr("grid_mapping", "crs: x y")
        .attr("units", "m s-1");
    let p = tmp("grid.nc", &d.to_bytes().unwrap());
    let flow = GriddedFlow::from_netcdf(&p, &options()).unwrap();
    let w = worst(&flow);
    eprintln!("along the grid: worst {w:.2e} m/s");
    assert!(w < 1e-5, "{w}");
    let e = error(
        &p,
        &CfOptions {
            frame: None,
            ..options()
        },
    );
    assert!(
        e.contains(
            "the currents' grid is projected (UTM zone 30N, grid mapping crs): give the site's \
             origin"
        ),
        "{e}"
    );
}

#[test]
fn a_seabed_on_a_utm_grid_reads_back_in_the_local_frame() {
    let (es, ns, local) = nodes();
    let (mut d, y, x) = utm_dataset(&es, &ns);
    d.var(
        "h",
        &[y, x],
        local.iter().map(|p| 200.0 + 0.1 * p.x).collect(),
    )
    .attr("standard_name", "sea_floor_depth_below_sea_surface")
    .attr("grid_mapping", "crs")
    .attr("units", "m");
    let p = tmp("seabed.nc", &d.to_bytes().unwrap());
    let o = SeabedOptions {
        frame: Some(frame()),
        area: rect(-1500.0, 1500.0, -1500.0, 1500.0),
        must_cover: rect(-1000.0, 1000.0, -1000.0, 1000.0),
        spacing_m: Some(25.0),
        variable: None,
    };
    let s = Seabed::from_file(&p, &o).unwrap();
    let mut w: f64 = 0.0;
    for k in 0..=40 {
        for l in 0..=40 {
            let (px, py) = (-1000.0 + 50.0 * k as f64, -1000.0 + 50.0 * l as f64);
            w = w.max((s.depth_at(px, py) - (200.0 + 0.1 * px)).abs());
        }
    }
    eprintln!("seabed: worst {w:.2e} m");
    assert!(w < 1e-6, "{w}");
}

#[test]
fn other_mappings_and_ellipsoids_are_refused_by_name() {
    let (es, ns, _) = nodes();
    let with = |name: &str, edit: &dyn Fn(&mut Dataset)| {
        let (mut d, y, x) = grid_only(&es, &ns);
        edit(&mut d);
        for (v, sn) in [
            ("u", "eastward_sea_water_velocity"),
            ("v", "northward_sea_water_velocity"),
        ] {
            d.var(v, &[y, x], vec![0.1; es.len() * ns.len()])
                .attr("standard_name", sn)
                .attr("grid_mapping", "crs")
                .attr("units", "m s-1");
        }
        error(&tmp(name, &d.to_bytes().unwrap()), &options())
    };
    let e = with("lcc.nc", &|d| {
        d.var("crs", &[], vec![0.0])
            .attr("grid_mapping_name", "lambert_conformal_conic");
    });
    assert!(
        e.contains(
            "lcc.nc: variable u: its grid mapping crs is \"lambert_conformal_conic\", which is \
             not read"
        ),
        "{e}"
    );
    let e = with("grs80.nc", &|d| {
        d.var("crs", &[], vec![0.0])
            .attr("grid_mapping_name", "transverse_mercator")
            .attr("longitude_of_central_meridian", -3.0)
            .attr("latitude_of_projection_origin", 0.0)
            .attr("scale_factor_at_central_meridian", 0.9996)
            .attr("semi_major_axis", 6_378_388.0)
            .attr("inverse_flattening", 297.0);
    });
    assert!(
        e.contains(
            "variable crs: semi_major_axis = 6378388, inverse_flattening = 297 is not WGS 84"
        ),
        "{e}"
    );
    let e = with("noscale.nc", &|d| {
        d.var("crs", &[], vec![0.0])
            .attr("grid_mapping_name", "transverse_mercator")
            .attr("longitude_of_central_meridian", -3.0)
            .attr("latitude_of_projection_origin", 0.0);
    });
    assert!(
        e.contains(
            "variable crs: a transverse_mercator grid mapping needs attribute \
             scale_factor_at_central_meridian"
        ),
        "{e}"
    );
}
