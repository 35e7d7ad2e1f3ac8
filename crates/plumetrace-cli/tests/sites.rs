//! Rehearsing at a site: currents from a CF NetCDF file fly the same mission, bit for bit, as
//! the same numbers in a CSV grid; bad files are refused with located messages.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::{bin, demo, run_ok};
use plumetrace_netcdf::{Dataset, NcType};
use std::path::Path;

const XS: [f64; 14] = [
    0.0, 40.0, 80.0, 120.0, 160.0, 200.0, 240.0, 280.0, 320.0, 360.0, 400.0, 440.0, 480.0, 520.0,
];
const TIMES: [f64; 5] = [0.0, 300.0, 600.0, 900.0, 1200.0];

fn ys() -> Vec<f64> {
    (0..11).map(|k| -150.0 + 30.0 * f64::from(k)).collect()
}

/// A tidal current turning over the run, sheared across the site.
fn uv(t: f64, x: f64, y: f64) -> (f64, f64) {
    let phase = std::f64::consts::TAU * t / 44_712.0;
    (
        0.15 + 0.03 * phase.cos() + 0.0001 * y,
        0.02 * phase.sin() + 0.01 * (x / 97.0).sin(),
    )
}

/// The demo mission, shortened, over a gridded flow read from `file`.
fn scenario(file: &str, extra: &str) -> String {
    let text = demo()
        .replacen(
            "model = \"farrell\"",
            &format!("model = \"gridded\"\nfile = \"{file}\"\n{extra}"),
            1,
        )
        .replacen("[flow.mean]\nspeed_mps = 0.15\ntoward_deg = 90.0\n", "", 1)
        .replacen("time_limit_s = 2400.0", "time_limit_s = 600.0", 1)
        .replacen("spinup_s = 3500.0", "spinup_s = 600.0", 1);
    let start = text.find("[flow.farrell]").unwrap();
    let end = text.find("[plume]").unwrap();
    format!("{}{}", &text[..start], &text[end..])
}

fn csv() -> String {
    let mut s = String::from("t_s,x_m,y_m,u_mps,v_mps\n");
    for t in TIMES {
        for y in ys() {
            for x in XS {
                let (u, v) = uv(t, x, y);
                s += &format!("{t:?},{x:?},{y:?},{u:?},{v:?}\n");
            }
        }
    }
    s
}

/// The same field as CF currents: projected x/y, time in hours since a date, as a record
/// dimension.
fn netcdf(u_units: &str, scale: f64) -> Vec<u8> {
    let ys = ys();
    let mut d = Dataset::default();
    let t = d.record_dim("time", TIMES.len());
    let y = d.dim("y", ys.len());
    let x = d.dim("x", XS.len());
    d.attr("Conventions", "CF-1.8");
    d.var("time", &[t], TIMES.iter().map(|s| s / 3600.0).collect())
        .attr("standard_name", "time")
        .attr("units", "hours since 2026-06-01 04:00:00");
    d.var("y", &[y], ys.clone())
        .attr("standard_name", "projection_y_coordinate")
        .attr("units", "m");
    d.var("x", &[x], XS.to_vec())
        .attr("standard_name", "projection_x_coordinate")
        .attr("units", "m");
    let (mut us, mut vs) = (Vec::new(), Vec::new());
    for tt in TIMES {
        for yy in &ys {
            for xx in XS {
                let (u, v) = uv(tt, xx, *yy);
                us.push(u * scale);
                vs.push(v * scale);
            }
        }
    }
    d.var("u", &[t, y, x], us)
        .attr("standard_name", "sea_water_x_velocity")
        .attr("units", u_units);
    d.var("v", &[t, y, x], vs)
        .attr("standard_name", "sea_water_y_velocity")
        .attr("units", u_units)
        .of_type(NcType::Double);
    d.to_bytes().unwrap()
}

fn fly(dir: &Path, name: &str, text: &str) -> (String, String) {
    let s = dir.join(format!("{name}.toml"));
    std::fs::write(&s, text).unwrap();
    let out = dir.join(name);
    run_ok(&[
        "run",
        s.to_str().unwrap(),
        "--seed",
        "5",
        "--out",
        out.to_str().unwrap(),
    ]);
    let read = |f: &str| std::fs::read_to_string(out.join(f)).unwrap();
    // The summary without the wall-clock times.
    let mut summary: serde_json::Value = serde_json::from_str(&read("summary.json")).unwrap();
    if let Some(m) = summary.as_object_mut() {
        for k in ["wall_s", "real_time_factor", "spinup_wall_s", "stage_times"] {
            m.remove(k);
        }
    }
    (
        read("trajectory.csv"),
        format!("{summary}\n{}", read("events.jsonl")),
    )
}

#[test]
fn currents_from_netcdf_fly_the_csv_grid_mission_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("flow.csv"), csv()).unwrap();
    std::fs::write(d.join("currents.nc"), netcdf("m s-1", 1.0)).unwrap();
    let a = fly(d, "csv", &scenario("flow.csv", ""));
    let b = fly(d, "nc", &scenario("currents.nc", ""));
    assert!(a.0.lines().count() > 100);
    assert_eq!(a.0, b.0, "trajectory.csv differs");
    assert_eq!(a.1, b.1, "summary.json differs");
    // The start named as a date: the same frames when it is the file's first time plus the
    // spin-up (the date the vehicles start).
    let c = fly(
        d,
        "dated",
        &scenario(
            "currents.nc",
            "[flow.netcdf]\nstart = \"2026-06-01T04:10:00Z\"\n",
        ),
    );
    assert_eq!(
        a.0, c.0,
        "a start date at the file's first time plus the spin-up"
    );
}

fn check_err(dir: &Path, name: &str, text: &str) -> String {
    let s = dir.join(format!("{name}.toml"));
    std::fs::write(&s, text).unwrap();
    let out = bin().args(["check", s.to_str().unwrap()]).output().unwrap();
    assert!(!out.status.success(), "{name} was accepted");
    String::from_utf8_lossy(&out.stderr).to_string()
}

#[test]
fn bad_currents_files_and_keys_are_located() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("furlongs.nc"), netcdf("furlongs s-1", 1.0)).unwrap();
    let e = check_err(d, "units", &scenario("furlongs.nc", ""));
    assert!(
        e.contains("flow.file")
            && e.contains("furlongs.nc: variable u: attribute units = \"furlongs s-1\""),
        "{e}"
    );
    std::fs::write(d.join("cm.nc"), netcdf("cm s-1", 100.0)).unwrap();
    std::fs::write(d.join("flow.csv"), csv()).unwrap();
    let a = fly(d, "m", &scenario("flow.csv", ""));
    let b = fly(d, "cm", &scenario("cm.nc", ""));
    // cm/s scaled back: the same to rounding, so close trajectories (not bit for bit).
    assert_eq!(a.0.lines().count(), b.0.lines().count());

    std::fs::write(d.join("currents.nc"), netcdf("m s-1", 1.0)).unwrap();
    let e = check_err(
        d,
        "typo",
        &scenario("currents.nc", "[flow.netcdf]\nu_varaible = \"u\"\n"),
    );
    assert!(e.contains("u_varaible") && e.contains("u_variable"), "{e}");
    let e = check_err(
        d,
        "name",
        &scenario("currents.nc", "[flow.netcdf]\nu_variable = \"uu\"\n"),
    );
    assert!(e.contains("no such variable; did you mean \"u\"?"), "{e}");
    let e = check_err(
        d,
        "late",
        &scenario(
            "currents.nc",
            "[flow.netcdf]\nstart = \"2026-06-01T05:00:00Z\"\n",
        ),
    );
    assert!(e.contains("frames span"), "{e}");
    let e = check_err(
        d,
        "date",
        &scenario("currents.nc", "[flow.netcdf]\nstart = \"1 June\"\n"),
    );
    assert!(
        e.contains("flow.netcdf.start") && e.contains("is not a date"),
        "{e}"
    );
    let text = scenario("currents.nc", "").replacen(
        "op_area = [[60.0, -80.0], [460.0, -80.0]",
        "op_area = [[60.0, -80.0], [560.0, -80.0]",
        1,
    );
    let e = check_err(d, "cover", &text);
    assert!(e.contains("does not cover the op-area"), "{e}");
    std::fs::write(d.join("notes.nc"), "a text file\n").unwrap();
    let e = check_err(
        d,
        "notnc",
        &scenario("notes.nc", "[flow.netcdf]\ndepth_m = 2.0\n"),
    );
    assert!(
        e.contains("notes.nc: not a NetCDF file: it starts with \"a text f\""),
        "{e}"
    );
    std::fs::write(d.join("notes.txt"), "a text file\n").unwrap();
    let e = check_err(
        d,
        "nottxt",
        &scenario("notes.txt", "[flow.netcdf]\ndepth_m = 2.0\n"),
    );
    assert!(e.contains("flow.netcdf") && e.contains("not one"), "{e}");
}

#[test]
fn the_example_site_flies_in_both_frames() {
    let dir = tempfile::tempdir().unwrap();
    let site = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/sites/site.toml");
    // A shorter mission from a copy beside the example's currents file.
    let text = std::fs::read_to_string(&site).unwrap().replacen(
        "time_limit_s = 2400.0",
        "time_limit_s = 120.0",
        1,
    );
    let copy = site.with_file_name("site-short.test.toml");
    std::fs::write(&copy, text).unwrap();
    let out = dir.path().join("run");
    let done = bin()
        .args([
            "run",
            copy.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let _ = std::fs::remove_file(&copy);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let traj = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let header = traj.lines().next().unwrap();
    assert!(
        header.ends_with(",detection,true_lat_deg,true_lon_deg,est_lat_deg,est_lon_deg"),
        "{header}"
    );
    let first: Vec<&str> = traj.lines().nth(1).unwrap().split(',').collect();
    let lat: f64 = first[12].parse().unwrap();
    let lon: f64 = first[13].parse().unwrap();
    // The vehicle starts at 50.34946 N, 4.143387 W and has moved a few centimetres.
    assert!(
        (lat - 50.34946).abs() < 2e-6 && (lon + 4.143387).abs() < 2e-6,
        "{lat} {lon}"
    );
    let geo: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("track.geojson")).unwrap()).unwrap();
    assert_eq!(geo["type"], "FeatureCollection");
    let kinds: Vec<&str> = geo["features"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["properties"]["kind"].as_str().unwrap())
        .collect();
    assert!(kinds.contains(&"track") && kinds.contains(&"source") && kinds.contains(&"op_area"));
    let src = geo["features"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["properties"]["kind"] == "source")
        .unwrap();
    let c = &src["geometry"]["coordinates"];
    assert!((c[0].as_f64().unwrap() + 4.148593).abs() < 1e-7, "{c}");
    assert!((c[1].as_f64().unwrap() - 50.35).abs() < 1e-7, "{c}");
}

#[test]
fn positions_in_degrees_without_an_origin_are_located() {
    let dir = tempfile::tempdir().unwrap();
    let text = demo().replacen(
        "x_m = 100.0\ny_m = 0.0",
        "lat_deg = 50.35\nlon_deg = -4.15",
        1,
    );
    let e = check_err(dir.path(), "noorigin", &text);
    assert!(
        e.contains("noorigin.toml:41: sources[0].lat_deg") && e.contains("add [origin]"),
        "{e}"
    );
}

/// A ridge across the demo's op-area: 20 m of water east of x = 420 m, 3 m west of x = 400 m.
fn ridge() -> Vec<u8> {
    let xs: Vec<f64> = (0..28).map(|k| -10.0 + 20.0 * f64::from(k)).collect();
    let ys: Vec<f64> = (0..17).map(|k| -160.0 + 20.0 * f64::from(k)).collect();
    let mut d = Dataset::default();
    let y = d.dim("y", ys.len());
    let x = d.dim("x", xs.len());
    d.var("y", &[y], ys.clone())
        .attr("axis", "Y")
        .attr("units", "m");
    d.var("x", &[x], xs.clone())
        .attr("axis", "X")
        .attr("units", "m");
    let mut depth = Vec::new();
    for _ in &ys {
        for &xx in &xs {
            depth.push(3.0 + 17.0 * ((xx - 400.0) / 20.0).clamp(0.0, 1.0));
        }
    }
    d.var("depth", &[y, x], depth)
        .attr("standard_name", "sea_floor_depth_below_sea_surface")
        .attr("units", "m");
    d.to_bytes().unwrap()
}

/// The demo, shortened, over [`ridge`], its AUV's `[vehicles.dynamics]` given: its events and
/// summary.
fn over_the_ridge(dynamics: &str) -> (String, serde_json::Value) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("ridge.nc"), ridge()).unwrap();
    let text = demo()
        .replacen(
            "depth_m = 8.0\n",
            "\n[bathymetry]\nfile = \"ridge.nc\"\n",
            1,
        )
        .replacen(
            "[mission]",
            &format!("[vehicles.dynamics]\n{dynamics}\n\n[mission]"),
            1,
        )
        .replacen("time_limit_s = 2400.0", "time_limit_s = 300.0", 1)
        .replacen("duration_s = 2400.0", "duration_s = 300.0", 1)
        .replacen("spinup_s = 3500.0", "spinup_s = 300.0", 1);
    let s = d.join("ridge.toml");
    std::fs::write(&s, text).unwrap();
    let out = d.join("run");
    run_ok(&["run", s.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let events = std::fs::read_to_string(out.join("events.jsonl")).unwrap();
    let summary =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    (events, summary)
}

#[test]
fn a_vehicle_that_meets_a_ridge_hits_the_bottom_and_the_summary_says_so() {
    // Blind to the seabed ahead (no DVL slope, no forward altimeter), the altitude hold lags the
    // wall.
    let (events, summary) = over_the_ridge("dvl_beam_angle_deg = 0.0\nlook_ahead_m = 0.0");
    assert!(
        events.contains("\"event\":\"incident\",\"what\":\"hit_bottom\""),
        "{events}"
    );
    assert_eq!(summary["outcome"], "collided");
    let v = &summary["vehicles"][0];
    assert_eq!(v["status"], "collided");
    // It starts 50 m east of the ridge and meets it on one of its mapping lines.
    let t = v["hit_bottom_s"].as_f64().unwrap();
    assert!(t > 20.0 && t < 300.0, "{t}");
    let ended = summary["ended"]["t_s"].as_f64().unwrap();
    assert!(
        (ended - t).abs() < 1e-9,
        "the mission ends there: {ended} {t}"
    );
}

#[test]
fn the_field_auv_sees_the_ridge_ahead_and_climbs_it() {
    let (events, summary) = over_the_ridge("");
    assert!(!events.contains("hit_bottom"), "{events}");
    assert_ne!(summary["outcome"], "collided");
    assert!(summary["vehicles"][0].get("hit_bottom_s").is_none());
}
