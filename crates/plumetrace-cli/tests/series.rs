//! The time series of a plume run (`probes.csv`, `filament_series.csv`), through the built binary.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

mod common;
use common::{bin, run_ok};

/// Probes on points of the output grid (201 x 101 over 200 m x 100 m: whole metres), at its
/// height, some in the plume's first minute and some outside it.
const PROBES: &str = "probes = [[15.0, 0.0, 2.0], [20.0, 0.0, 2.0], [25.0, 1.0, 2.0], \
                      [30.0, 0.0, 2.0], [40.0, -1.0, 2.0], [60.0, 3.0, 2.0], [100.0, 40.0, 2.0]]";

/// `plume-demo` shortened to a minute with the time average from the start, and `keys` added to
/// `[output]`.
fn scenario(dir: &Path, name: &str, keys: &str) -> PathBuf {
    let text = plumetrace_scenario::find_preset("plume-demo").unwrap().toml;
    assert!(
        text.trim_end().ends_with("threshold = 0.05"),
        "[output] is last"
    );
    let text = text
        .replace("duration_s = 600.0", "duration_s = 60.0")
        .replace("average_start_s = 300.0", "average_start_s = 0.0");
    let path = dir.join(name);
    std::fs::write(&path, format!("{text}{keys}\n")).unwrap();
    path
}

fn run(scenario: &Path, out: &Path, seed: &str) {
    run_ok(&[
        "run",
        scenario.to_str().unwrap(),
        "--seed",
        seed,
        "--out",
        out.to_str().unwrap(),
    ]);
}

/// A CSV file's rows after the header, as numbers; checks the header.
fn rows(path: &Path, header: &str) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(header), "{}", path.display());
    lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

fn stats(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("stats.json")).unwrap()).unwrap()
}

#[test]
fn probe_series_mean_equals_the_time_average_at_the_same_points() {
    let dir = tempfile::tempdir().unwrap();
    // No probe_interval_s: the probes are sampled with the time average.
    let s = scenario(dir.path(), "probes.toml", PROBES);
    let checked = run_ok(&["check", s.to_str().unwrap()]);
    assert!(
        String::from_utf8_lossy(&checked.stdout).contains("7 probes sampled every 1.0 s"),
        "{checked:?}"
    );
    let out = dir.path().join("out");
    run(&s, &out, "3");
    let probes = rows(
        &out.join("probes.csv"),
        "t_s,probe,x_m,y_m,z_m,concentration",
    );
    let n = 7;
    let st = stats(&out);
    assert_eq!(st["probes"], n);
    assert_eq!(st["probe_samples"], 60);
    assert_eq!(st["mean_samples"], 60, "the same steps as the average");
    assert_eq!(probes.len(), 60 * n);
    for (i, r) in probes.iter().enumerate() {
        let (sample, k) = (i / n, i % n);
        assert_eq!(
            r[0],
            (sample + 1) as f64,
            "sampled every second from t = 1 s"
        );
        assert_eq!(r[1], k as f64);
        assert!(r[5].is_finite() && r[5] >= 0.0);
    }
    let snapshot = rows(
        &out.join("snapshot.csv"),
        "x_m,y_m,concentration,mean_concentration,intermittency",
    );
    let mut in_plume = 0;
    for k in 0..n {
        let series: Vec<&Vec<f64>> = probes.iter().skip(k).step_by(n).collect();
        let (x, y) = (series[0][2], series[0][3]);
        let probe_mean = series.iter().map(|r| r[5]).sum::<f64>() / series.len() as f64;
        let grid = snapshot
            .iter()
            .find(|r| (r[0] - x).abs() < 1e-9 && (r[1] - y).abs() < 1e-9)
            .unwrap_or_else(|| panic!("probe {k} ({x}, {y}) is not a grid point"));
        let map_mean = grid[3];
        assert!(
            (probe_mean - map_mean).abs() <= 1e-5 * probe_mean.abs().max(map_mean.abs()) + 1e-12,
            "probe {k} at ({x}, {y}): series mean {probe_mean:e}, time-averaged map {map_mean:e}"
        );
        // The last sample is the final snapshot.
        let last = series.last().unwrap()[5];
        assert!((last - grid[2]).abs() <= 1e-5 * last.abs().max(grid[2].abs()) + 1e-12);
        if map_mean > 1e-3 {
            in_plume += 1;
        }
    }
    assert!(in_plume >= 3, "only {in_plume} probes met the plume");
}

#[test]
fn probe_and_filament_series_are_reproducible_with_the_same_seed() {
    let dir = tempfile::tempdir().unwrap();
    let keys = format!("{PROBES}\nprobe_interval_s = 0.5\nfilaments_interval_s = 15.0");
    let s = scenario(dir.path(), "series.toml", &keys);
    let (a, b, c) = (
        dir.path().join("a"),
        dir.path().join("b"),
        dir.path().join("c"),
    );
    run(&s, &a, "5");
    run(&s, &b, "5");
    run(&s, &c, "6");
    let read = |d: &Path, f: &str| std::fs::read(d.join(f)).unwrap();
    for f in ["probes.csv", "filament_series.csv"] {
        assert_eq!(read(&a, f), read(&b, f), "{f}");
        assert_ne!(read(&a, f), read(&c, f), "{f}");
    }
    assert_eq!(stats(&a)["probe_samples"], 120, "every 0.5 s");
    // The series do not change the plume: the final state is the one without them.
    let plain = scenario(dir.path(), "plain.toml", "");
    let d = dir.path().join("d");
    run(&plain, &d, "5");
    assert_eq!(read(&a, "snapshot.csv"), read(&d, "snapshot.csv"));
    assert_eq!(read(&a, "filaments.csv"), read(&d, "filaments.csv"));
    assert!(!d.join("probes.csv").exists() && !d.join("filament_series.csv").exists());
}

#[test]
fn filament_series_holds_every_filament_at_each_interval() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), "filaments.toml", "filaments_interval_s = 20.0");
    let out = dir.path().join("out");
    run(&s, &out, "2");
    let series = rows(&out.join("filament_series.csv"), "t_s,x_m,y_m,z_m,radius_m");
    let st = stats(&out);
    assert_eq!(st["filament_snapshots"], 3);
    assert_eq!(st["filament_snapshots_skipped"], 0);
    assert_eq!(st["filament_series_rows"], series.len());
    assert!(!out.join("probes.csv").exists(), "no probes, no probes.csv");
    let mut times: Vec<f64> = series.iter().map(|r| r[0]).collect();
    times.dedup();
    assert_eq!(times, [20.0, 40.0, 60.0]);
    // Filaments are released all along: each snapshot has more than the one before.
    let count = |t: f64| series.iter().filter(|r| r[0] == t).count();
    assert!(0 < count(20.0) && count(20.0) < count(40.0) && count(40.0) < count(60.0));
    // The last snapshot is the run's final state, as filaments.csv writes it.
    let last: Vec<Vec<f64>> = series
        .iter()
        .filter(|r| r[0] == 60.0)
        .map(|r| r[1..].to_vec())
        .collect();
    assert_eq!(
        last,
        rows(&out.join("filaments.csv"), "x_m,y_m,z_m,radius_m")
    );
    assert_eq!(st["filaments"]["live"], last.len());
}

#[test]
fn bad_series_keys_are_refused_by_check_with_the_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    for (name, keys, key) in [
        (
            "outside.toml",
            "probes = [[20.0, 0.0, 2.0], [-5.0, 0.0, 2.0]]",
            "output.probes[1]: [-5.0, 0.0, 2.0] is outside the domain",
        ),
        (
            "fast.toml",
            "filaments_interval_s = 0.01",
            "output.filaments_interval_s: must be 0 (no snapshots) or in [sim.dt_s, sim.duration_s]",
        ),
        (
            "typo.toml",
            "probe_interval = 1.0",
            "output.probe_interval: ",
        ),
    ] {
        let s = scenario(dir.path(), name, keys);
        let out = bin().args(["check", s.to_str().unwrap()]).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{name}");
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(e.contains(name) && e.contains(key), "{name}: {e}");
        assert!(!e.contains("panicked"), "{e}");
    }
}
