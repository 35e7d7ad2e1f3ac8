//! `plumetrace campaign`, `merge` and `bench missions` as a user runs them, including a campaign
//! killed with SIGKILL and resumed.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::{Duration, Instant};

mod common;
use common::{bin, run_ok};

/// One configuration, `seeds` seeds of a 1,000 s demo mission.
fn campaign(dir: &Path, seeds: u64) -> PathBuf {
    let p = dir.join("c.toml");
    std::fs::write(
        &p,
        format!(
            "name = \"kill\"\nseed = 5\nseeds = {seeds}\nscenarios = [\"demo\"]\n\
             [[configs]]\nname = \"amp\"\n[configs.set]\nmapping = false\n\
             \"mission.time_limit_s\" = 1000.0\n\"mission.spinup_s\" = 1000.0\n"
        ),
    )
    .unwrap();
    p
}

fn data_rows(p: &Path) -> usize {
    std::fs::read_to_string(p)
        .map(|t| t.lines().count().saturating_sub(1))
        .unwrap_or(0)
}

#[test]
fn a_killed_campaign_resumes_with_every_run_exactly_once() {
    let tmp = tempfile::tempdir().unwrap();
    let file = campaign(tmp.path(), 8);
    let (f, killed, clean) = (
        file.to_str().unwrap(),
        tmp.path().join("killed"),
        tmp.path().join("clean"),
    );
    let mut child = bin()
        .args([
            "campaign",
            f,
            "--out",
            killed.to_str().unwrap(),
            "--jobs",
            "2",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let runs = killed.join("runs.csv");
    let started = Instant::now();
    while data_rows(&runs) < 2 {
        assert!(
            started.elapsed() < Duration::from_secs(300),
            "no rows after 300 s"
        );
        assert!(
            child.try_wait().unwrap().is_none(),
            "campaign finished before it could be killed"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap(); // SIGKILL: no chance to clean up.
    child.wait().unwrap();
    let recorded = data_rows(&runs);
    assert!((2..8).contains(&recorded), "{recorded} rows at the kill");

    let out = run_ok(&["campaign", f, "--out", killed.to_str().unwrap()]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains(&format!("{recorded} already recorded")),
        "{text}"
    );
    run_ok(&[
        "campaign",
        f,
        "--out",
        clean.to_str().unwrap(),
        "--jobs",
        "1",
    ]);
    let resumed = std::fs::read_to_string(&runs).unwrap();
    assert_eq!(
        resumed,
        std::fs::read_to_string(clean.join("runs.csv")).unwrap()
    );
    let mut keys: Vec<&str> = resumed
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(3).unwrap())
        .collect();
    keys.dedup();
    assert_eq!(keys, ["0", "1", "2", "3", "4", "5", "6", "7"]);
}

#[test]
fn shards_merge_and_bad_input_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    let file = campaign(tmp.path(), 2);
    let f = file.to_str().unwrap();
    let d = |n: &str| tmp.path().join(n).to_str().unwrap().to_string();
    run_ok(&["campaign", f, "--out", &d("s1"), "--shard", "1/2"]);
    run_ok(&[
        "campaign",
        f,
        "--out",
        &d("s2"),
        "--shard",
        "2/2",
        "--seeds",
        "2",
    ]);
    let out = run_ok(&["merge", &d("s1"), &d("s2"), "--out", &d("m")]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("2 of 2 runs"));
    run_ok(&["campaign", f, "--out", &d("one")]);
    let read = |p: &str| std::fs::read_to_string(Path::new(p).join("runs.csv")).unwrap();
    assert_eq!(read(&d("m")), read(&d("one")));
    for f in [
        "summary.csv",
        "summary.md",
        "success.svg",
        "errors.svg",
        "trajectories.svg",
    ] {
        assert!(Path::new(&d("m")).join(f).exists(), "{f}");
    }

    for (args, want) in [
        (
            vec!["campaign", f, "--out", &d("x"), "--shard", "3/2"],
            "1 <= K <= N",
        ),
        (
            vec!["campaign", f, "--out", &d("x"), "--jobs", "0"],
            "--jobs",
        ),
        (
            vec!["campaign", "missing.toml", "--out", &d("x")],
            "missing.toml",
        ),
        (
            vec!["merge", &d("nothing-here"), "--out", &d("x")],
            "campaign.json",
        ),
    ] {
        let out = bin().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(err.contains(want), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let bad = tmp.path().join("bad.toml");
    std::fs::write(
        &bad,
        "name = \"x\"\nseed = 1\nseeds = 2\nscenarios = [\"demo\"]\n[[configs]]\nname = \"a\"\n[configs.set]\nn_re = 0\n",
    )
    .unwrap();
    let out = bin()
        .args(["campaign", bad.to_str().unwrap(), "--out", &d("x")])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.toml") && err.contains("planner.n_re"),
        "{err}"
    );
}

#[test]
fn bench_missions_reports_rates_per_thread_count() {
    let out = run_ok(&[
        "bench",
        "missions",
        "--preset",
        "demo",
        "--runs",
        "2",
        "--threads",
        "1,2",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = v["results"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    for (r, t) in rows.iter().zip([1, 2]) {
        assert_eq!(r["threads"], t);
        assert!(r["missions_per_s"].as_f64().unwrap() > 0.0);
    }
    assert!(v["scaling"].as_f64().unwrap().is_finite());
    let out = bin()
        .args(["bench", "missions", "--preset", "plume-demo"])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a mission"));
}

#[test]
fn bench_raster_times_the_grids_a_run_draws_in_both_precisions() {
    let out = run_ok(&["bench", "raster", "--preset", "demo", "--queries", "2"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["filaments"].as_u64().unwrap() > 100, "{v}");
    // The figure's grid is 160 points across; the page's at most 96 on its longer side.
    assert_eq!(v["figure"]["points"][0], 160);
    assert_eq!(v["page"]["points"][0], 96);
    for grid in ["figure", "page"] {
        let g = &v[grid];
        assert!(g["ms_per_query_display"].as_f64().unwrap() > 0.0, "{g}");
        assert!(g["ms_per_query_standard"].as_f64().unwrap() > 0.0, "{g}");
        let d = g["max_relative_difference"].as_f64().unwrap();
        assert!((0.0..1e-15).contains(&d), "{g}");
    }
    // A sample of a run: the index build and a display query of each grid.
    let build = v["ms_per_index_build"].as_f64().unwrap();
    assert!(build > 0.0, "{v}");
    let parts = build
        + v["figure"]["ms_per_query_display"].as_f64().unwrap()
        + v["page"]["ms_per_query_display"].as_f64().unwrap();
    let sample = v["ms_per_sample"].as_f64().unwrap();
    assert!((sample - parts).abs() <= 1e-9 * parts, "{v}");
    let out = bin()
        .args(["bench", "raster", "--preset", "pompy"])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a mission"));
}
