//! Tests of the CF currents reader: files written by the crate's own NetCDF writer.

use super::*;
use crate::flow::FlowField;
use crate::test_files::rect;
use crate::{StreamId, stream_rng};
use plumetrace_core::geo::Origin;
use plumetrace_netcdf::{Dataset, NcType};
use std::path::PathBuf;

fn tmp(name: &str, bytes: &[u8]) -> PathBuf {
    crate::test_files::tmp_in(
        &format!("plumetrace-cf-{}-{name}", std::process::id()),
        name,
        bytes,
    )
}

fn options() -> CfOptions {
    CfOptions {
        frame: None,
        start_s: None,
        duration_s: 100.0,
        depth_m: None,
        area: rect(0.0, 200.0, 0.0, 100.0),
        must_cover: rect(10.0, 190.0, 10.0, 90.0),
        spacing_m: None,
        u_variable: None,
        v_variable: None,
    }
}

/// A projected grid x 0..200 step 50, y 0..100 step 50, two frames 0 and 100 s.
fn projected() -> Dataset {
    projected_in("m s-1")
}

fn projected_in(u_units: &str) -> Dataset {
    let mut d = Dataset::default();
    let t = d.record_dim("time", 2);
    let y = d.dim("y", 3);
    let x = d.dim("x", 5);
    d.var("time", &[t], vec![0.0, 100.0])
        .attr("units", "seconds since 2026-03-01 00:00:00");
    d.var("y", &[y], vec![0.0, 50.0, 100.0])
        .attr("standard_name", "projection_y_coordinate")
        .attr("units", "m");
    d.var("x", &[x], vec![0.0, 50.0, 100.0, 150.0, 200.0])
        .attr("standard_name", "projection_x_coordinate")
        .attr("units", "m");
    let field = |f: fn(f64, f64, f64) -> f64| {
        let mut out = Vec::new();
        for tt in [0.0, 100.0] {
            for yy in [0.0, 50.0, 100.0] {
                for xx in [0.0, 50.0, 100.0, 150.0, 200.0] {
                    out.push(f(tt, xx, yy));
                }
            }
        }
        out
    };
    d.var(
        "u",
        &[t, y, x],
        field(|t, x, _| 0.1 + 0.001 * x + 0.002 * t),
    )
    .attr("standard_name", "sea_water_x_velocity")
    .attr("units", u_units);
    d.var("v", &[t, y, x], field(|_, _, y| -0.05 + 0.0003 * y))
        .attr("standard_name", "sea_water_y_velocity")
        .attr("units", "m s-1");
    d
}

fn read(name: &str, d: &Dataset, o: &CfOptions) -> Result<GriddedFlow, String> {
    let p = tmp(name, &d.to_bytes().unwrap());
    GriddedFlow::from_netcdf(&p, o).map_err(|e| e.to_string())
}

#[test]
fn a_projected_grid_gives_the_same_flow_as_the_csv_grid_bit_for_bit() {
    let d = projected();
    let mut nc = read("same.nc", &d, &options()).unwrap();
    let mut csv = String::from("t_s,x_m,y_m,u_mps,v_mps\n");
    for t in [0.0f64, 100.0] {
        for y in [0.0f64, 50.0, 100.0] {
            for x in [0.0f64, 50.0, 100.0, 150.0, 200.0] {
                let u = 0.1 + 0.001 * x + 0.002 * t;
                let v = -0.05 + 0.0003 * y;
                csv += &format!("{t:?},{x:?},{y:?},{u:?},{v:?}\n");
            }
        }
    }
    let mut grid = GriddedFlow::from_csv(&tmp("same.csv", csv.as_bytes())).unwrap();
    let mut rng = stream_rng(1, StreamId::Flow);
    for t in [0.0, 12.5, 50.0, 99.0, 100.0, 150.0] {
        nc.advance(t, 1.0, &mut rng).unwrap();
        grid.advance(t, 1.0, &mut rng).unwrap();
        for (x, y) in [
            (0.0, 0.0),
            (13.7, 91.1),
            (199.0, 3.0),
            (-20.0, 40.0),
            (75.0, 250.0),
        ] {
            let (a, b) = (nc.velocity(Vec2::new(x, y)), grid.velocity(Vec2::new(x, y)));
            assert_eq!(a.x.to_bits(), b.x.to_bits(), "t {t} ({x}, {y})");
            assert_eq!(a.y.to_bits(), b.y.to_bits(), "t {t} ({x}, {y})");
        }
    }
}

/// Longitude/latitude around 50 N 4 W, depth levels 0, 10, 30 m (positive down), hourly frames
/// in hours since a date, values packed as shorts in cm s-1 with a fill value.
fn geographic(fill_at: Option<usize>) -> Dataset {
    geographic_grid(fill_at, None)
}

/// `geographic(fill_at)`, its longitude and latitude given instead as 2-D arrays `lon_rho` and
/// `lat_rho` on dimensions without coordinates (as ROMS writes them) when `two_d` is given, with
/// a fill value at latitude node `k` when it is `Some(Some(k))`: an even grid that is
/// curvilinear in form.
fn geographic_grid(fill_at: Option<usize>, two_d: Option<Option<usize>>) -> Dataset {
    let mut d = Dataset::default();
    let t = d.record_dim("time", 3);
    let z = d.dim("depth", 3);
    let (la, lo) = if two_d.is_some() {
        (d.dim("eta_rho", 4), d.dim("xi_rho", 5))
    } else {
        (d.dim("lat", 4), d.dim("lon", 5))
    };
    d.var("time", &[t], vec![10.0, 11.0, 12.0])
        .attr("standard_name", "time")
        .attr("units", "hours since 2026-03-01 00:00:00");
    d.var("depth", &[z], vec![0.0, 10.0, 30.0])
        .attr("standard_name", "depth")
        .attr("positive", "down")
        .attr("units", "m");
    // Latitudes north to south (descending), as some products store them.
    let (lats, lons) = (
        [50.03, 50.01, 49.99, 49.97],
        [-4.04, -4.02, -4.0, -3.98, -3.96],
    );
    if let Some(fill) = two_d {
        let mut lat2: Vec<f64> = lats.iter().flat_map(|&a| [a; 5]).collect();
        let lon2: Vec<f64> = (0..4).flat_map(|_| lons).collect();
        if let Some(k) = fill {
            lat2[k] = 1e37;
        }
        d.var("lat_rho", &[la, lo], lat2)
            .of_type(NcType::Float)
            .attr("standard_name", "latitude")
            .attr("units", "degree_north");
        d.var("lon_rho", &[la, lo], lon2)
            .attr("standard_name", "longitude")
            .attr("units", "degree_east");
    } else {
        d.var("lat", &[la], lats.to_vec())
            .of_type(NcType::Float)
            .attr("units", "degrees_north");
        d.var("lon", &[lo], lons.to_vec())
            .attr("units", "degrees_east");
    }
    // u (cm/s) = 10 * (hour - 9) + depth level's depth: uniform in space.
    let mut u = Vec::new();
    for h in [10.0, 11.0, 12.0] {
        for depth in [0.0, 10.0, 30.0] {
            for _ in 0..20 {
                u.push((10.0 * (h - 9.0) + depth) * 100.0);
            }
        }
    }
    if let Some(k) = fill_at {
        u[k] = -32767.0;
    }
    d.var("uo", &[t, z, la, lo], u)
        .of_type(NcType::Short)
        .attr("standard_name", "eastward_sea_water_velocity")
        .attr("units", "cm s-1")
        .attr("scale_factor", 0.01f32)
        .attr("add_offset", 0.0)
        .attr("_FillValue", -32767i16)
        .attr("coordinates", "time depth lat_rho lon_rho");
    // A field that varies in space, so that the cells' weights matter.
    let v: Vec<f64> = (0..180).map(|k| 5.0 + 0.01 * (k % 20) as f64).collect();
    d.var("vo", &[t, z, la, lo], v)
        .of_type(NcType::Float)
        .attr("standard_name", "northward_sea_water_velocity")
        .attr("units", "m s-1")
        .attr("missing_value", 1e20f32);
    d
}

fn site() -> CfOptions {
    CfOptions {
        frame: Some(
            LocalFrame::new(Origin {
                lat_deg: 50.0,
                lon_deg: -4.0,
            })
            .unwrap(),
        ),
        // 10:30 on the day: half-way between the first two frames.
        start_s: Some(plumetrace_netcdf::time::parse_date("2026-03-01T10:30:00Z").unwrap()),
        duration_s: 3600.0,
        depth_m: Some(5.0),
        area: rect(-1000.0, 1000.0, -1000.0, 1000.0),
        must_cover: rect(-500.0, 500.0, -500.0, 500.0),
        spacing_m: Some(250.0),
        u_variable: None,
        v_variable: None,
    }
}

#[test]
fn a_geographic_grid_is_unpacked_interpolated_in_depth_and_offset_in_time() {
    let mut f = read("geo.nc", &geographic(None), &site()).unwrap();
    // At 10:30, depth 5 m: u = (10 * 1.5 + 5) cm/s = 0.20 m/s.
    let u = f.velocity(Vec2::new(100.0, -200.0));
    assert!((u.x - 0.20).abs() < 1e-6, "{u:?}");
    assert!((5.0..5.2).contains(&u.y), "{u:?}");
    let mut rng = stream_rng(1, StreamId::Flow);
    // 30 min later it is 11:00: (10 * 2 + 5) cm/s.
    f.advance(1800.0, 1800.0, &mut rng).unwrap();
    let u = f.velocity(Vec2::new(0.0, 0.0));
    assert!((u.x - 0.25).abs() < 1e-6, "{u:?}");
}

#[test]
fn a_fill_value_inside_the_op_area_is_an_error_and_outside_it_is_still_water() {
    // Node (lat 49.99, lon -4.0) of the first frame, depth 0: inside the op-area's reach.
    let at = 2 * 5 + 2;
    let e = read("fill.nc", &geographic(Some(at)), &site()).unwrap_err();
    assert!(e.contains("missing value") && e.contains("fill.nc"), "{e}");
    // The corner node (lat 50.03, lon -4.04) is far from the op-area.
    let f = read("fill-far.nc", &geographic(Some(0)), &site()).unwrap();
    assert_eq!(f.frame_count(), 3);
}

#[test]
fn the_errors_name_the_variable_attribute_or_dimension_and_suggest() {
    let mut o = site();
    o.u_variable = Some("u0".into());
    let e = read("typo.nc", &geographic(None), &o).unwrap_err();
    assert!(
        e.contains("flow.netcdf.u_variable = \"u0\": no such variable; did you mean \"uo\"?"),
        "{e}"
    );
    let mut o = site();
    o.must_cover = rect(-500.0, 3000.0, -500.0, 500.0);
    let e = read("cover.nc", &geographic(None), &o).unwrap_err();
    assert!(e.contains("does not cover the op-area"), "{e}");
    let mut o = site();
    o.frame = None;
    let e = read("origin.nc", &geographic(None), &o).unwrap_err();
    assert!(e.contains("[origin] lat_deg and lon_deg"), "{e}");
    let mut o = site();
    o.depth_m = None;
    let e = read("depth.nc", &geographic(None), &o).unwrap_err();
    assert!(
        e.contains("3 depth levels") && e.contains("flow.netcdf.depth_m"),
        "{e}"
    );
    let mut o = site();
    o.depth_m = Some(31.0);
    let e = read("deep.nc", &geographic(None), &o).unwrap_err();
    assert!(e.contains("below the deepest level"), "{e}");
    let mut o = site();
    o.duration_s = 3.0 * 3600.0;
    let e = read("time.nc", &geographic(None), &o).unwrap_err();
    assert!(e.contains("frames span -1800 s to 5400 s"), "{e}");

    let mut d = projected();
    d.var("w", &[0, 1, 2], vec![0.0; 30]);
    let mut o = options();
    o.u_variable = Some("w".into());
    o.v_variable = Some("v".into());
    let e = read("units.nc", &d, &o).unwrap_err();
    assert!(e.contains("variable w: no attribute units"), "{e}");

    let d = projected_in("furlongs per fortnight");
    let e = read("furlongs.nc", &d, &options()).unwrap_err();
    assert!(
        e.contains(
            "variable u: attribute units = \"furlongs per fortnight\" is not a velocity unit"
        ),
        "{e}"
    );

    let mut d = Dataset::default();
    d.var("salt", &[], vec![35.0])
        .attr("standard_name", "sea_water_salinity");
    let e = read("nothing.nc", &d, &options()).unwrap_err();
    assert!(
        e.contains("no variables with standard_name eastward_sea_water_velocity")
            && e.contains("salt (sea_water_salinity)"),
        "{e}"
    );
}

#[test]
fn other_formats_are_refused_by_name() {
    let p = tmp("flow.csv", b"x_m,y_m,u_mps,v_mps\n");
    let e = GriddedFlow::from_netcdf(&p, &site())
        .unwrap_err()
        .to_string();
    assert!(e.contains("flow.csv: not a NetCDF file"), "{e}");
    let p = tmp("model.nc4", b"\x89HDF\r\n\x1a\n\0\0\0\0");
    let e = GriddedFlow::from_netcdf(&p, &site())
        .unwrap_err()
        .to_string();
    assert!(e.contains("nccopy -k classic"), "{e}");
}

#[test]
fn velocity_units_are_read_in_their_usual_spellings() {
    for (u, s) in [
        ("m s-1", Some(1.0)),
        ("m/s", Some(1.0)),
        ("m.s-1", Some(1.0)),
        ("m s^-1", Some(1.0)),
        ("meter second-1", Some(1.0)),
        ("cm s-1", Some(0.01)),
        ("cm/s", Some(0.01)),
        ("knots", Some(1852.0 / 3600.0)),
        ("m", None),
        ("degC", None),
    ] {
        assert_eq!(velocity_scale(u), s, "{u}");
    }
}

fn geographic_2d(lat_fill: Option<usize>) -> Dataset {
    geographic_grid(None, Some(lat_fill))
}

fn same_bits(a: &mut GriddedFlow, b: &mut GriddedFlow, points: &[(f64, f64)]) {
    let mut rng = stream_rng(1, StreamId::Flow);
    assert_eq!(a.grid_size(), b.grid_size());
    assert_eq!(a.frame_count(), b.frame_count());
    for t in [0.0, 900.0, 1800.0, 3600.0] {
        a.advance(t, 1.0, &mut rng).unwrap();
        b.advance(t, 1.0, &mut rng).unwrap();
        for &(x, y) in points {
            let (p, q) = (a.velocity(Vec2::new(x, y)), b.velocity(Vec2::new(x, y)));
            assert_eq!(p.x.to_bits(), q.x.to_bits(), "t {t} ({x}, {y})");
            assert_eq!(p.y.to_bits(), q.y.to_bits(), "t {t} ({x}, {y})");
        }
    }
}

#[test]
fn a_curvilinear_file_on_an_even_grid_reads_as_the_rectilinear_file_bit_for_bit() {
    let mut rect = read("rect.nc", &geographic(None), &site()).unwrap();
    let mut curv = read("curv.nc", &geographic_2d(None), &site()).unwrap();
    let mut points = Vec::new();
    for k in 0..41 {
        let x = -1000.0 + 50.0 * k as f64;
        points.push((x, 0.37 * x - 120.0));
        points.push((x, -x));
    }
    same_bits(&mut rect, &mut curv, &points);
    // Every node of the sampled grid, through its values: the whole field, not a few points.
    let mut o = site();
    o.spacing_m = Some(97.0);
    let mut rect = read("rect97.nc", &geographic(None), &o).unwrap();
    let mut curv = read("curv97.nc", &geographic_2d(None), &o).unwrap();
    let (nx, ny) = rect.grid_size();
    let nodes: Vec<(f64, f64)> = (0..nx * ny)
        .map(|k| {
            let dx = 2000.0 / (nx - 1) as f64;
            let dy = 2000.0 / (ny - 1) as f64;
            (
                -1000.0 + (k % nx) as f64 * dx,
                -1000.0 + (k / nx) as f64 * dy,
            )
        })
        .collect();
    same_bits(&mut rect, &mut curv, &nodes);
}

/// A smooth projected field, m/s.
fn smooth(x: f64, y: f64) -> (f64, f64) {
    (
        0.3 + 0.2 * (x / 400.0).sin() * (y / 300.0).cos(),
        -0.1 + 0.15 * (x / 350.0).cos() + 0.0001 * y,
    )
}

/// The smooth field on projected 2-D x and y: `n` x `n` nodes `step_m` apart, turned `turn_deg`
/// about (100, 50) m. One frame, no depth.
fn turned(n: usize, step_m: f64, turn_deg: f64) -> Dataset {
    turned_folded(n, step_m, turn_deg, None)
}

/// `turned`, with the x of two nodes swapped (a folded grid) when `swap` is given.
fn turned_folded(n: usize, step_m: f64, turn_deg: f64, swap: Option<(usize, usize)>) -> Dataset {
    let mut d = Dataset::default();
    let eta = d.dim("eta", n);
    let xi = d.dim("xi", n);
    let (s, c) = turn_deg.to_radians().sin_cos();
    let half = step_m * (n - 1) as f64 / 2.0;
    let (mut xs, mut ys, mut us, mut vs) = (vec![], vec![], vec![], vec![]);
    for j in 0..n {
        for i in 0..n {
            let (a, b) = (i as f64 * step_m - half, j as f64 * step_m - half);
            let (x, y) = (100.0 + c * a - s * b, 50.0 + s * a + c * b);
            let (u, v) = smooth(x, y);
            xs.push(x);
            ys.push(y);
            us.push(u);
            vs.push(v);
        }
    }
    if let Some((a, b)) = swap {
        xs.swap(a, b);
    }
    d.var("x_2d", &[eta, xi], xs)
        .attr("standard_name", "projection_x_coordinate")
        .attr("units", "m");
    d.var("y_2d", &[eta, xi], ys)
        .attr("standard_name", "projection_y_coordinate")
        .attr("units", "m");
    d.var("u", &[eta, xi], us)
        .attr("standard_name", "sea_water_x_velocity")
        .attr("units", "m s-1")
        .attr("coordinates", "x_2d y_2d");
    d.var("v", &[eta, xi], vs)
        .attr("standard_name", "sea_water_y_velocity")
        .attr("units", "m s-1")
        .attr("coordinates", "x_2d y_2d");
    d
}

/// The stated tolerance of a turned grid against the field and the rectilinear read, m/s: the
/// bilinear error of the smooth field on 40 m cells is below 1e-3 m/s.
const TURNED_TOL_MPS: f64 = 2e-3;

#[test]
fn a_turned_curvilinear_grid_reproduces_the_rectilinear_field_within_tolerance() {
    let mut o = options();
    o.area = rect(-500.0, 700.0, -400.0, 500.0);
    o.must_cover = rect(-300.0, 500.0, -200.0, 300.0);
    o.spacing_m = Some(25.0);
    o.duration_s = 0.0;
    let straight = read("straight.nc", &turned(41, 40.0, 0.0), &o).unwrap();
    let curv = read("turned.nc", &turned(41, 40.0, 30.0), &o).unwrap();
    let mut worst: f64 = 0.0;
    for k in 0..=40 {
        for l in 0..=25 {
            let (x, y) = (-300.0 + 20.0 * k as f64, -200.0 + 20.0 * l as f64);
            let (a, b) = (
                straight.velocity(Vec2::new(x, y)),
                curv.velocity(Vec2::new(x, y)),
            );
            let (u, v) = smooth(x, y);
            for d in [a.x - b.x, a.y - b.y, b.x - u, b.y - v] {
                worst = worst.max(d.abs());
            }
        }
    }
    assert!(worst < TURNED_TOL_MPS, "worst {worst} m/s");
    assert!(
        worst > 1e-6,
        "the field is not linear, so the grids differ a little"
    );
}

#[test]
fn a_curvilinear_grid_that_misses_the_op_area_or_folds_or_has_holes_is_located() {
    let mut o = options();
    o.area = rect(-500.0, 700.0, -400.0, 500.0);
    o.must_cover = rect(-300.0, 900.0, -200.0, 300.0);
    o.duration_s = 0.0;
    let e = read("small.nc", &turned(21, 40.0, 30.0), &o).unwrap_err();
    assert!(
        e.contains("small.nc")
            && e.contains("the currents' curvilinear grid (x_2d and y_2d: x ")
            && e.contains("does not cover the op-area: its point (")
            && e.contains("in none of the grid's cells"),
        "{e}"
    );
    let e = read("fold.nc", &turned_folded(5, 40.0, 10.0, Some((6, 7))), &o).unwrap_err();
    assert!(
        e.contains("variables x_2d and y_2d: the grid's cell at (eta 0, xi 1) is")
            && e.contains("folded or degenerate"),
        "{e}"
    );
    let e = read("hole.nc", &geographic_2d(Some(7)), &site()).unwrap_err();
    assert!(
        e.contains("variable lat_rho: a missing or non-finite value at (eta_rho 1, xi_rho 2)"),
        "{e}"
    );
}

/// A projected 5 x 3 grid 50 m apart over two frames on four terrain-following levels of
/// `standard_name` (`ocean_sigma_coordinate` or `ocean_s_coordinate_g1`/`g2`), the water `h =
/// 20 + 0.02 x` m deep (`h0` at node 0 when given) under a surface `eta = 0.5` then `-0.3` m,
/// with `formula_terms` as given (`None`: all of them). The eastward velocity is 0.01 s-1 times
/// its level's depth below the surface plus 0.001 s-1 times x, so at 5 m it is `0.05 + 0.001 x`.
fn terrain_following(standard_name: &str, formula_terms: Option<&str>, h0: Option<f64>) -> Dataset {
    let mut d = Dataset::default();
    let t = d.record_dim("time", 2);
    let k = d.dim("s_rho", 4);
    let y = d.dim("y", 3);
    let x = d.dim("x", 5);
    let one = d.dim("one", 1);
    let (xs, ys) = ([0.0, 50.0, 100.0, 150.0, 200.0], [0.0, 50.0, 100.0]);
    let s = [-0.875, -0.625, -0.375, -0.125];
    let c: Vec<f64> = s.iter().map(|v: &f64| -v * v).collect();
    let (hc, etas) = (4.0, [0.5, -0.3]);
    let h = |i: usize| match (i, h0) {
        (0, Some(h)) => h,
        _ => 20.0 + 0.02 * xs[i],
    };
    d.var("time", &[t], vec![0.0, 100.0])
        .attr("units", "seconds since 2026-03-01 00:00:00");
    d.var("x", &[x], xs.to_vec())
        .attr("standard_name", "projection_x_coordinate")
        .attr("units", "m");
    d.var("y", &[y], ys.to_vec())
        .attr("standard_name", "projection_y_coordinate")
        .attr("units", "m");
    let sigma = standard_name == "ocean_sigma_coordinate";
    let all = if sigma {
        "sigma: s_rho eta: zeta depth: h"
    } else {
        "s: s_rho C: Cs_r eta: zeta depth: h depth_c: hc"
    };
    d.var("s_rho", &[k], s.to_vec())
        .attr("standard_name", standard_name)
        .attr("positive", "up")
        .attr("formula_terms", formula_terms.unwrap_or(all));
    d.var("Cs_r", &[k], c.clone());
    d.var("hc", &[], vec![hc]).attr("units", "m");
    let mut hv = Vec::new();
    let mut zeta = Vec::new();
    for _ in 0..3 {
        for i in 0..5 {
            hv.push(h(i));
        }
    }
    for e in etas {
        zeta.extend([e; 15]);
    }
    // The ROMS layout: h on (y, x), zeta on (time, one, y, x).
    d.var("h", &[y, x], hv).attr("units", "m");
    d.var("zeta", &[t, one, y, x], zeta).attr("units", "m");
    let (mut u, mut v) = (Vec::new(), Vec::new());
    for eta in etas {
        for kk in 0..4 {
            for _ in 0..3 {
                for (i, xx) in xs.iter().enumerate() {
                    let h = h(i);
                    // Depth below the surface, eta - z, from the CF formulas.
                    let z = match standard_name {
                        "ocean_sigma_coordinate" => eta + s[kk] * (h + eta),
                        "ocean_s_coordinate_g1" => {
                            let big = hc * s[kk] + (h - hc) * c[kk];
                            big + eta * (1.0 + big / h)
                        }
                        _ => {
                            let big = (hc * s[kk] + h * c[kk]) / (hc + h);
                            eta + (eta + h) * big
                        }
                    };
                    u.push(0.01 * (eta - z) + 0.001 * xx);
                    v.push(0.1);
                }
            }
        }
    }
    d.var("u", &[t, k, y, x], u)
        .attr("standard_name", "sea_water_x_velocity")
        .attr("units", "m s-1");
    d.var("v", &[t, k, y, x], v)
        .attr("standard_name", "sea_water_y_velocity")
        .attr("units", "m s-1");
    d
}

#[test]
fn terrain_following_levels_give_each_column_its_depths() {
    let mut o = options();
    o.depth_m = Some(5.0);
    for sn in [
        "ocean_sigma_coordinate",
        "ocean_s_coordinate_g1",
        "ocean_s_coordinate_g2",
    ] {
        let mut f = read(&format!("{sn}.nc"), &terrain_following(sn, None, None), &o).unwrap();
        let mut rng = stream_rng(1, StreamId::Flow);
        for t in [0.0, 50.0, 100.0] {
            f.advance(t, 1.0, &mut rng).unwrap();
            for (x, y) in [(0.0, 0.0), (35.0, 80.0), (200.0, 100.0), (123.0, 45.0)] {
                let w = f.velocity(Vec2::new(x, y));
                let want = 0.05 + 0.001 * x;
                assert!((w.x - want).abs() < 1e-12, "{sn} t {t} ({x}, {y}): {w:?}");
                assert!((w.y - 0.1).abs() < 1e-12, "{sn}");
            }
        }
    }
    // Shallower than the layer inside the op-area's reach: a missing value, located.
    let e = read(
        "shallow.nc",
        &terrain_following("ocean_s_coordinate_g2", None, Some(4.0)),
        &o,
    )
    .unwrap_err();
    assert!(
        e.contains("missing value") && e.contains("at (0.0, 0.0) m"),
        "{e}"
    );
    o.depth_m = None;
    let e = read(
        "no-depth.nc",
        &terrain_following("ocean_sigma_coordinate", None, None),
        &o,
    )
    .unwrap_err();
    assert!(
        e.contains("4 terrain-following levels") && e.contains("flow.netcdf.depth_m"),
        "{e}"
    );
}

#[test]
fn a_missing_or_misnamed_formula_term_is_located() {
    let mut o = options();
    o.depth_m = Some(5.0);
    let sn = "ocean_s_coordinate_g2";
    let e = read(
        "terms.nc",
        &terrain_following(sn, Some("s: s_rho C: Cs_r eta: zeta depth: h"), None),
        &o,
    )
    .unwrap_err();
    assert!(
        e.contains(
            "terms.nc: variable s_rho (standard_name ocean_s_coordinate_g2): attribute \
             formula_terms = \"s: s_rho C: Cs_r eta: zeta depth: h\" lacks the term depth_c; \
             its levels' depths need s, C, eta, depth, depth_c"
        ),
        "{e}"
    );
    let e = read(
        "misnamed.nc",
        &terrain_following(
            sn,
            Some("s: s_rho C: Cs_w eta: zeta depth: h depth_c: hc"),
            None,
        ),
        &o,
    )
    .unwrap_err();
    assert!(
        e.contains(
            "formula term C names variable \"Cs_w\", which the file does not have; did \
             you mean \"Cs_r\"?"
        ),
        "{e}"
    );
    let e = read(
        "garbled.nc",
        &terrain_following(sn, Some("s s_rho"), None),
        &o,
    )
    .unwrap_err();
    assert!(e.contains("is not a list of `term: variable` pairs"), "{e}");
    // A term on dimensions of its own (a staggered grid): h at u points is one node short.
    let mut d = terrain_following(
        sn,
        Some("s: s_rho C: Cs_r eta: zeta depth: h_u depth_c: hc"),
        None,
    );
    let xi_u = d.dim("xi_u", 4);
    d.var("h_u", &[2, xi_u], vec![20.0; 12]).attr("units", "m");
    let e = read("stagger.nc", &d, &o).unwrap_err();
    assert!(
        e.contains(
            "variable h_u (formula term depth): its dimension xi_u is not one of variable u's \
             time and horizontal dimensions (a staggered grid?"
        ),
        "{e}"
    );
    let mut d = terrain_following("ocean_s_coordinate", None, None);
    d.var("unused", &[], vec![0.0]);
    let e = read("old-s.nc", &d, &o).unwrap_err();
    assert!(
        e.contains("standard_name ocean_s_coordinate, which is not read") && e.contains("g2"),
        "{e}"
    );
}
