//! `plume.nc` (feature `netcdf`) read back by a reader of the classic format written from the
//! specification, and compared with `probes.csv` and `snapshot.csv`.

#![cfg(feature = "netcdf")]
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeMap;
use std::path::Path;

mod common;
use common::run_ok;

#[derive(Debug, Clone, PartialEq)]
enum Value {
    Text(String),
    Int(Vec<i32>),
    Double(Vec<f64>),
}

#[derive(Debug)]
struct Var {
    dims: Vec<usize>,
    attrs: BTreeMap<String, Value>,
    nc_type: u32,
    vsize: u64,
    begin: u64,
}

#[derive(Debug)]
struct File {
    version: u8,
    numrecs: u32,
    dims: Vec<(String, u32)>,
    attrs: BTreeMap<String, Value>,
    vars: Vec<(String, Var)>,
    header_len: usize,
}

/// A big-endian cursor that fails the test on a short file.
struct Cursor<'a> {
    b: &'a [u8],
    at: usize,
}

impl Cursor<'_> {
    fn take(&mut self, n: usize) -> &[u8] {
        assert!(self.at + n <= self.b.len(), "the file ends at {}", self.at);
        let s = &self.b[self.at..self.at + n];
        self.at += n;
        s
    }
    fn u32(&mut self) -> u32 {
        u32::from_be_bytes(self.take(4).try_into().unwrap())
    }
    fn u64(&mut self) -> u64 {
        u64::from_be_bytes(self.take(8).try_into().unwrap())
    }
    fn pad(&mut self) {
        while !self.at.is_multiple_of(4) {
            assert_eq!(self.take(1), [0], "padding is zero");
        }
    }
    fn name(&mut self) -> String {
        let n = self.u32() as usize;
        let s = String::from_utf8(self.take(n).to_vec()).unwrap();
        self.pad();
        s
    }
    /// `ABSENT | TAG nelems`: the number of elements.
    fn list(&mut self, tag: u32) -> usize {
        let t = self.u32();
        let n = self.u32() as usize;
        assert!(
            t == tag || (t == 0 && n == 0),
            "tag {t:#x}, expected {tag:#x}"
        );
        n
    }
    fn attrs(&mut self) -> BTreeMap<String, Value> {
        let n = self.list(0x0C);
        (0..n)
            .map(|_| {
                let name = self.name();
                let ty = self.u32();
                let n = self.u32() as usize;
                let v = match ty {
                    2 => Value::Text(String::from_utf8(self.take(n).to_vec()).unwrap()),
                    4 => Value::Int(
                        (0..n)
                            .map(|_| i32::from_be_bytes(self.take(4).try_into().unwrap()))
                            .collect(),
                    ),
                    6 => Value::Double(
                        (0..n)
                            .map(|_| f64::from_be_bytes(self.take(8).try_into().unwrap()))
                            .collect(),
                    ),
                    other => panic!("attribute {name} has type {other}"),
                };
                self.pad();
                (name, v)
            })
            .collect()
    }
}

/// Reads the header of a classic (CDF-1) or 64-bit offset (CDF-2) file.
fn parse(bytes: &[u8]) -> File {
    let mut c = Cursor { b: bytes, at: 0 };
    assert_eq!(c.take(3), b"CDF");
    let version = c.take(1)[0];
    assert!(version == 1 || version == 2, "version {version}");
    let numrecs = c.u32();
    let n = c.list(0x0A);
    let dims = (0..n).map(|_| (c.name(), c.u32())).collect();
    let attrs = c.attrs();
    let n = c.list(0x0B);
    let vars = (0..n)
        .map(|_| {
            let name = c.name();
            let rank = c.u32() as usize;
            let dims = (0..rank).map(|_| c.u32() as usize).collect();
            let attrs = c.attrs();
            let nc_type = c.u32();
            let vsize = u64::from(c.u32());
            let begin = if version == 1 {
                u64::from(c.u32())
            } else {
                c.u64()
            };
            (
                name,
                Var {
                    dims,
                    attrs,
                    nc_type,
                    vsize,
                    begin,
                },
            )
        })
        .collect();
    File {
        version,
        numrecs,
        dims,
        attrs,
        vars,
        header_len: c.at,
    }
}

impl File {
    fn var(&self, name: &str) -> &Var {
        &self
            .vars
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("no variable {name}"))
            .1
    }
    fn dim(&self, name: &str) -> (usize, u32) {
        let k = self.dims.iter().position(|(n, _)| n == name).unwrap();
        (k, self.dims[k].1)
    }
    fn doubles(&self, bytes: &[u8], name: &str) -> Vec<f64> {
        let v = self.var(name);
        assert_eq!(v.nc_type, 6, "{name} is double");
        let n: u64 = v.dims.iter().map(|&d| u64::from(self.dims[d].1)).product();
        assert_eq!(v.vsize, n * 8, "{name}'s vsize");
        let at = v.begin as usize;
        bytes[at..at + 8 * n as usize]
            .chunks(8)
            .map(|b| f64::from_be_bytes(b.try_into().unwrap()))
            .collect()
    }
}

fn text(attrs: &BTreeMap<String, Value>, key: &str) -> String {
    match attrs.get(key) {
        Some(Value::Text(s)) => s.clone(),
        other => panic!("{key}: {other:?}"),
    }
}

fn csv(path: &Path) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-6 * a.abs().max(b.abs()) + 1e-12
}

#[test]
fn plume_nc_reads_back_as_probes_csv_and_the_mean_map() {
    let dir = tempfile::tempdir().unwrap();
    let demo = plumetrace_scenario::find_preset("plume-demo")
        .unwrap()
        .toml
        .replace("duration_s = 600.0", "duration_s = 30.0")
        .replace("average_start_s = 300.0", "average_start_s = 10.0");
    let scenario = dir.path().join("nc.toml");
    std::fs::write(
        &scenario,
        format!(
            "{demo}probes = [[15.0, 0.0, 2.0], [20.5, 0.25, 1.0], [25.0, -1.0, 0.0]]\n\
             probe_interval_s = 2.0\n"
        ),
    )
    .unwrap();
    let out = dir.path().join("out");
    run_ok(&[
        "run",
        scenario.to_str().unwrap(),
        "--seed",
        "18446744073709551615",
        "--out",
        out.to_str().unwrap(),
    ]);
    let bytes = std::fs::read(out.join("plume.nc")).unwrap();
    let f = parse(&bytes);
    assert_eq!(
        (f.version, f.numrecs),
        (2, 0),
        "64-bit offset, no record dimension"
    );
    let names: Vec<&str> = f.dims.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["time", "probe", "grid_x", "grid_y"]);
    assert_eq!(f.dim("time").1, 15);
    assert_eq!(f.dim("probe").1, 3);
    assert_eq!((f.dim("grid_x").1, f.dim("grid_y").1), (201, 101));
    assert_eq!(text(&f.attrs, "Conventions"), "CF-1.8");
    assert_eq!(text(&f.attrs, "scenario"), "plume-demo");
    assert_eq!(text(&f.attrs, "seed"), "18446744073709551615");
    assert!(text(&f.attrs, "title").contains("plume-demo"));

    // The data follow the header, one variable after another, and end the file.
    let mut end = f.header_len as u64;
    for (name, v) in &f.vars {
        assert_eq!(v.begin, end, "{name} starts where the one before ends");
        end += v.vsize;
    }
    assert_eq!(end, bytes.len() as u64);

    let time = f.var("time");
    assert_eq!(time.dims, [f.dim("time").0]);
    assert_eq!(text(&time.attrs, "standard_name"), "time");
    assert!(text(&time.attrs, "units").starts_with("seconds since "));
    let conc = f.var("concentration");
    assert_eq!(conc.dims, [f.dim("time").0, f.dim("probe").0]);
    assert_eq!(text(&conc.attrs, "coordinates"), "x y z");
    assert!(!text(&conc.attrs, "units").is_empty() && !text(&conc.attrs, "long_name").is_empty());
    for c in ["x", "y", "z"] {
        assert_eq!(text(&f.var(c).attrs, "units"), "m");
    }
    let mean = f.var("mean_concentration");
    assert_eq!(mean.dims, [f.dim("grid_y").0, f.dim("grid_x").0]);
    assert_eq!(mean.attrs.get("samples"), Some(&Value::Int(vec![21])));

    let (t, x, y, z) = (
        f.doubles(&bytes, "time"),
        f.doubles(&bytes, "x"),
        f.doubles(&bytes, "y"),
        f.doubles(&bytes, "z"),
    );
    let c = f.doubles(&bytes, "concentration");
    assert_eq!(x, [15.0, 20.5, 25.0]);
    assert_eq!(y, [0.0, 0.25, -1.0]);
    assert_eq!(z, [2.0, 1.0, 0.0]);
    let rows = csv(&out.join("probes.csv"));
    assert_eq!(rows.len(), c.len());
    for (i, r) in rows.iter().enumerate() {
        let (sample, k) = (i / 3, i % 3);
        assert_eq!(r[0], t[sample]);
        assert_eq!(r[0], 2.0 * (sample + 1) as f64);
        assert_eq!(r[1], k as f64);
        assert_eq!((r[2], r[3], r[4]), (x[k], y[k], z[k]));
        assert!(close(r[5], c[i]), "row {i}: csv {} netcdf {}", r[5], c[i]);
    }
    assert!(c.iter().any(|&v| v > 1e-3), "the probes meet the plume");

    let gx = f.doubles(&bytes, "grid_x");
    let gy = f.doubles(&bytes, "grid_y");
    assert_eq!((gx[0], gx[200], gy[0], gy[100]), (0.0, 200.0, -50.0, 50.0));
    assert_eq!(f.doubles(&bytes, "grid_z"), [2.0]);
    let m = f.doubles(&bytes, "mean_concentration");
    let snapshot = csv(&out.join("snapshot.csv"));
    assert_eq!(snapshot.len(), m.len());
    for (k, r) in snapshot.iter().enumerate() {
        assert_eq!((r[0], r[1]), (gx[k % 201], gy[k / 201]));
        assert!(
            close(r[3], m[k]),
            "grid point {k}: csv {} netcdf {}",
            r[3],
            m[k]
        );
    }
}
