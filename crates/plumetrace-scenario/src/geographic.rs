//! Positions in latitude and longitude: with an `[origin]`, a scenario may give its sources'
//! and vehicles' positions as `lat_deg` and `lon_deg`, and its op-area and subregions as
//! `mission.op_area_lat_lon` and `mission.subregions_lat_lon` (`[lat_deg, lon_deg]` pairs).
//! They are turned into the local frame's `x_m` and `y_m` (the core's WGS-84 geodesy around
//! the origin) before the file is read, so everything after sees metres only. A scenario with
//! none of these keys is read exactly as before.

use crate::limits::{Bound, limit};
use plumetrace_core::Vec2;
use plumetrace_core::geo::{LocalFrame, Origin};
use toml::{Table, Value};

/// A key path and what is wrong there.
pub(crate) type GeoError = (String, String);

/// The tables of positions: (array key, entries' keys in x/y, in lat/lon).
const POINTS: &[&str] = &["sources", "vehicles"];

/// Whether the table gives any position in latitude and longitude.
pub(crate) fn any(table: &Table) -> bool {
    let in_points = POINTS.iter().any(|k| {
        table.get(*k).and_then(Value::as_array).is_some_and(|a| {
            a.iter().any(|e| {
                e.as_table()
                    .is_some_and(|t| t.contains_key("lat_deg") || t.contains_key("lon_deg"))
            })
        })
    });
    let in_mission = table
        .get("mission")
        .and_then(Value::as_table)
        .is_some_and(|m| m.contains_key("op_area_lat_lon") || m.contains_key("subregions_lat_lon"));
    in_points || in_mission
}

/// A number within its documented bound (the row of `pattern` in [`crate::limits::LIMITS`]).
fn number(v: &Value, path: &str, pattern: &str) -> Result<f64, GeoError> {
    let x = match v {
        Value::Float(f) => *f,
        Value::Integer(i) => *i as f64,
        _ => return Err((path.to_string(), "expected a number of degrees".into())),
    };
    if let Some(l) = limit(pattern)
        && let Bound::Number { min, max, .. } = l.bound
        && !(x.is_finite() && x >= min && x <= max)
    {
        return Err((
            path.to_string(),
            format!("must be {} ({}), got {x:?}", l.bound.describe(), l.why),
        ));
    }
    Ok(x)
}

/// The frame of `[origin]`, or an error at `needed_by`.
fn frame(table: &Table, needed_by: &str) -> Result<LocalFrame, GeoError> {
    let Some(o) = table.get("origin").and_then(Value::as_table) else {
        return Err((
            needed_by.to_string(),
            "a position in latitude and longitude needs the site's origin: add [origin] with \
             lat_deg and lon_deg"
                .into(),
        ));
    };
    let get = |k: &str| {
        o.get(k)
            .ok_or_else(|| (format!("origin.{k}"), "missing".to_string()))
            .and_then(|v| number(v, &format!("origin.{k}"), &format!("origin.{k}")))
    };
    LocalFrame::new(Origin {
        lat_deg: get("lat_deg")?,
        lon_deg: get("lon_deg")?,
    })
    .map_err(|e| ("origin".to_string(), e.to_string()))
}

/// Converts every position given in latitude and longitude into `x_m` and `y_m`.
pub(crate) fn to_local(table: &mut Table) -> Result<(), GeoError> {
    let mut frame_for: Option<LocalFrame> = None;
    let mut get_frame = |table: &Table, at: &str| -> Result<LocalFrame, GeoError> {
        if let Some(f) = &frame_for {
            return Ok(f.clone());
        }
        let f = frame(table, at)?;
        frame_for = Some(f.clone());
        Ok(f)
    };
    for key in POINTS {
        let n = table
            .get(*key)
            .and_then(Value::as_array)
            .map_or(0, Vec::len);
        for i in 0..n {
            let Some(e) = table[*key].as_array().and_then(|a| a[i].as_table()) else {
                continue;
            };
            if !(e.contains_key("lat_deg") || e.contains_key("lon_deg")) {
                continue;
            }
            let at = format!("{key}[{i}]");
            let f = get_frame(table, &format!("{at}.lat_deg"))?;
            let Some(Value::Array(a)) = table.get_mut(*key) else {
                continue;
            };
            let Some(Value::Table(e)) = a.get_mut(i) else {
                continue;
            };
            point(e, &at, key, &f)?;
        }
    }
    let has = |t: &Table, k: &str| {
        t.get("mission")
            .and_then(Value::as_table)
            .is_some_and(|m| m.contains_key(k))
    };
    for (geo, local, nested) in [
        ("op_area_lat_lon", "op_area", false),
        ("subregions_lat_lon", "subregions", true),
    ] {
        if !has(table, geo) {
            continue;
        }
        let f = get_frame(table, &format!("mission.{geo}"))?;
        let Some(Value::Table(m)) = table.get_mut("mission") else {
            continue;
        };
        if m.contains_key(local) {
            return Err((
                format!("mission.{geo}"),
                format!("give mission.{local} (metres) or mission.{geo}, not both"),
            ));
        }
        let v = m.remove(geo).unwrap_or(Value::Array(Vec::new()));
        let path = format!("mission.{geo}");
        let converted = if nested {
            let Value::Array(polys) = v else {
                return Err((path, "expected a list of polygons".into()));
            };
            let mut out = Vec::with_capacity(polys.len());
            for (k, p) in polys.iter().enumerate() {
                out.push(polygon(
                    p,
                    &format!("{path}[{k}]"),
                    &format!("{path}[]"),
                    &f,
                )?);
            }
            Value::Array(out)
        } else {
            polygon(&v, &path, &path, &f)?
        };
        m.insert(local.to_string(), converted);
    }
    Ok(())
}

/// One source's or vehicle's `lat_deg` and `lon_deg` into `x_m` and `y_m`.
fn point(e: &mut Table, at: &str, key: &str, f: &LocalFrame) -> Result<(), GeoError> {
    if e.contains_key("x_m") || e.contains_key("y_m") {
        return Err((
            format!("{at}.lat_deg"),
            "give x_m and y_m (metres) or lat_deg and lon_deg, not both".into(),
        ));
    }
    let mut deg = |k: &str| -> Result<f64, GeoError> {
        let v = e.remove(k).ok_or_else(|| {
            (
                format!("{at}.{k}"),
                "missing (lat_deg and lon_deg go together)".to_string(),
            )
        })?;
        number(&v, &format!("{at}.{k}"), &format!("{key}[].{k}"))
    };
    let (lat, lon) = (deg("lat_deg")?, deg("lon_deg")?);
    let p = f.to_local(lat, lon);
    e.insert("x_m".into(), Value::Float(p.x));
    e.insert("y_m".into(), Value::Float(p.y));
    Ok(())
}

/// A polygon of `[lat_deg, lon_deg]` pairs into `[x_m, y_m]` pairs.
fn polygon(v: &Value, path: &str, pattern: &str, f: &LocalFrame) -> Result<Value, GeoError> {
    let Value::Array(pts) = v else {
        return Err((
            path.to_string(),
            "expected a list of [lat_deg, lon_deg] pairs".into(),
        ));
    };
    let mut out = Vec::with_capacity(pts.len());
    for (k, p) in pts.iter().enumerate() {
        let at = format!("{path}[{k}]");
        let pair = p
            .as_array()
            .filter(|a| a.len() == 2)
            .ok_or_else(|| (at.clone(), "expected a [lat_deg, lon_deg] pair".to_string()))?;
        let lat = number(&pair[0], &format!("{at}[0]"), &format!("{pattern}[][0]"))?;
        let lon = number(&pair[1], &format!("{at}[1]"), &format!("{pattern}[][1]"))?;
        let q: Vec2 = f.to_local(lat, lon);
        out.push(Value::Array(vec![Value::Float(q.x), Value::Float(q.y)]));
    }
    Ok(Value::Array(out))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_in_degrees_become_metres_and_back_within_a_millimetre() {
        let text = r#"
            [origin]
            lat_deg = 50.35
            lon_deg = -4.15
            [[sources]]
            lat_deg = 50.351
            lon_deg = -4.149
            [mission]
            op_area_lat_lon = [[50.349, -4.151], [50.349, -4.14], [50.353, -4.14]]
        "#;
        let mut t: Table = toml::from_str(text).unwrap_or_default();
        assert!(any(&t));
        to_local(&mut t).unwrap_or_else(|e| panic!("{e:?}"));
        let f = LocalFrame::new(Origin {
            lat_deg: 50.35,
            lon_deg: -4.15,
        })
        .unwrap_or_else(|e| panic!("{e}"));
        let s = t["sources"][0].as_table().cloned().unwrap_or_default();
        let (x, y) = (
            s["x_m"].as_float().unwrap_or(f64::NAN),
            s["y_m"].as_float().unwrap_or(f64::NAN),
        );
        assert!(x > 70.0 && x < 72.0 && y > 110.0 && y < 112.0, "{x} {y}");
        let (lat, lon) = f.to_geographic(Vec2::new(x, y));
        let back = f.to_local(lat, lon);
        assert!((back.x - x).abs() < 1e-3 && (back.y - y).abs() < 1e-3);
        // Degrees to metres and back: the same point within a millimetre.
        let there = f.to_geographic(Vec2::new(x, y));
        let d = f.to_local(there.0, there.1) - f.to_local(50.351, -4.149);
        assert!(d.norm() < 1e-3, "{d:?}");
        assert_eq!(t["mission"]["op_area"].as_array().map(Vec::len), Some(3));
        assert!(t["mission"].get("op_area_lat_lon").is_none());
    }

    #[test]
    fn missing_origin_mixed_frames_and_bad_degrees_are_located() {
        let err = |text: &str| {
            let mut t: Table = toml::from_str(text).unwrap_or_default();
            to_local(&mut t).err().unwrap_or_default()
        };
        let e = err("[[sources]]\nlat_deg = 50.0\nlon_deg = -4.0\n");
        assert_eq!(e.0, "sources[0].lat_deg");
        assert!(e.1.contains("add [origin]"), "{e:?}");
        let e = err(
            "[origin]\nlat_deg = 50.0\nlon_deg = -4.0\n[[vehicles]]\nx_m = 1.0\nlat_deg = 50.0\nlon_deg = -4.0\n",
        );
        assert_eq!(e.0, "vehicles[0].lat_deg");
        assert!(e.1.contains("not both"), "{e:?}");
        let e = err(
            "[origin]\nlat_deg = 50.0\nlon_deg = -4.0\n[[sources]]\nlat_deg = 95.0\nlon_deg = -4.0\n",
        );
        assert_eq!(e.0, "sources[0].lat_deg");
        assert!(e.1.contains("<= 90"), "{e:?}");
        let e = err(
            "[origin]\nlat_deg = 50.0\nlon_deg = -4.0\n[mission]\nop_area_lat_lon = [[50.0]]\n",
        );
        assert_eq!(e.0, "mission.op_area_lat_lon[0]");
    }
}
