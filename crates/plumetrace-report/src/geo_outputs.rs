//! A flown mission in latitude and longitude, for a scenario with an `[origin]`: `trajectory.csv`
//! with the positions in both frames, and `track.geojson` (RFC 7946: the vehicles' tracks, the
//! declarations, the true sources and the op-area) for GIS tools.
//!
//! Without an origin nothing here is written, so a run's files stay as they were.

use crate::run_dir::{RunDirError, trajectory_csv};
use plumetrace_core::Vec2;
use plumetrace_core::geo::{LocalFrame, Origin};
use plumetrace_mission::MissionRun;
use plumetrace_mission::output::write_atomic;
use serde_json::{Value, json};
use std::path::Path;

/// The GeoJSON file's name in a run's output directory.
pub const GEOJSON: &str = "track.geojson";

/// Decimals of a degree: 1e-7 deg is about a centimetre.
const DEG_DECIMALS: usize = 7;

/// `trajectory.csv` with four more columns: `true_lat_deg,true_lon_deg,est_lat_deg,est_lon_deg`
/// (the estimate's empty where the vehicle has none).
pub fn trajectory_csv_geo(run: &MissionRun, frame: &LocalFrame) -> Result<String, RunDirError> {
    let local = trajectory_csv(run)?;
    let mut out = String::with_capacity(local.len() * 3 / 2);
    let mut lines = local.lines();
    if let Some(header) = lines.next() {
        out.push_str(header);
        out.push_str(",true_lat_deg,true_lon_deg,est_lat_deg,est_lon_deg\n");
    }
    let deg = |x: f64| format!("{x:.DEG_DECIMALS$}");
    for (line, r) in lines.zip(&run.trajectory) {
        let (lat, lon) = frame.to_geographic(Vec2::new(r.true_x_m, r.true_y_m));
        let est = match (r.est_x_m, r.est_y_m) {
            (Some(x), Some(y)) => {
                let (a, b) = frame.to_geographic(Vec2::new(x, y));
                format!("{},{}", deg(a), deg(b))
            }
            _ => ",".to_string(),
        };
        out.push_str(&format!("{line},{},{},{est}\n", deg(lat), deg(lon)));
    }
    Ok(out)
}

/// `[lon, lat]` of a local position, rounded to [`DEG_DECIMALS`].
fn position(frame: &LocalFrame, p: Vec2) -> Value {
    let (lat, lon) = frame.to_geographic(p);
    let round = |x: f64| {
        let s = 10f64.powi(DEG_DECIMALS as i32);
        (x * s).round() / s
    };
    json!([round(lon), round(lat)])
}

/// `track.geojson`: a `LineString` per vehicle (its true track, a point a second at most), a
/// `Point` per declaration and per true source, and the op-area's `Polygon`.
pub fn geojson(run: &MissionRun, frame: &LocalFrame, name: &str) -> Value {
    let mut features = Vec::new();
    for (k, v) in run.vehicles.iter().enumerate() {
        let mut coords = Vec::new();
        let mut last_t = f64::NEG_INFINITY;
        let rows: Vec<_> = run
            .trajectory
            .iter()
            .filter(|r| r.vehicle as usize == k)
            .collect();
        for (i, r) in rows.iter().enumerate() {
            if r.t_s - last_t >= 1.0 || i + 1 == rows.len() {
                coords.push(position(frame, Vec2::new(r.true_x_m, r.true_y_m)));
                last_t = r.t_s;
            }
        }
        features.push(json!({
            "type": "Feature",
            "geometry": {"type": "LineString", "coordinates": coords},
            "properties": {"kind": "track", "vehicle": v.name},
        }));
    }
    for d in &run.summary.declarations {
        let vehicle = run
            .vehicles
            .get(d.vehicle as usize)
            .map(|v| v.name.as_str());
        features.push(json!({
            "type": "Feature",
            "geometry": {"type": "Point", "coordinates": position(frame, Vec2::new(d.x_m, d.y_m))},
            "properties": {
                "kind": "declaration",
                "vehicle": vehicle,
                "t_s": d.t_s,
                "error_m": d.error_m,
                "rule": plumetrace_core::variant_name(&d.rule),
            },
        }));
    }
    for s in &run.sources {
        features.push(json!({
            "type": "Feature",
            "geometry": {"type": "Point", "coordinates": position(frame, Vec2::new(s.x, s.y))},
            "properties": {"kind": "source", "z_m": s.z},
        }));
    }
    if !run.op_area.is_empty() {
        let mut ring: Vec<Value> = run.op_area.iter().map(|p| position(frame, *p)).collect();
        ring.push(ring[0].clone());
        features.push(json!({
            "type": "Feature",
            "geometry": {"type": "Polygon", "coordinates": [ring]},
            "properties": {"kind": "op_area"},
        }));
    }
    let o = frame.origin();
    json!({
        "type": "FeatureCollection",
        "name": name,
        "origin": {"lat_deg": o.lat_deg, "lon_deg": o.lon_deg},
        "features": features,
    })
}

/// Writes `trajectory.csv` (in both frames, over the local one) and `track.geojson` into `out`.
pub fn write_geographic_outputs(
    run: &MissionRun,
    out: &Path,
    origin: Origin,
    name: &str,
) -> Result<(), RunDirError> {
    let frame = LocalFrame::new(origin).map_err(|e| RunDirError::Write {
        path: out.join(GEOJSON),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, e.to_string()),
    })?;
    let write = |file: &str, bytes: &[u8]| {
        let path = out.join(file);
        write_atomic(&path, bytes).map_err(|source| RunDirError::Write { path, source })
    };
    write(
        "trajectory.csv",
        trajectory_csv_geo(run, &frame)?.as_bytes(),
    )?;
    let text = serde_json::to_string_pretty(&geojson(run, &frame, name)).map_err(|source| {
        RunDirError::Encode {
            what: "track.geojson",
            source,
        }
    })?;
    write(GEOJSON, format!("{text}\n").as_bytes())
}
