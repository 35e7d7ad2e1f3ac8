//! `plumetrace benchmark` as a user runs it, and the split it enforces: `campaign` and `family`
//! cannot reach a task's test seeds unless asked with `--test-seeds`.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

mod common;
use common::{bin, run_ok};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Runs the binary; (success, stdout, stderr).
fn plumetrace(args: &[&str]) -> (bool, String, String) {
    let out = bin().args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn fails_with(args: &[&str], want: &str) {
    let (ok, _, err) = plumetrace(args);
    assert!(!ok, "plumetrace {args:?} succeeded");
    assert!(
        err.contains(want),
        "plumetrace {args:?}:\n{err}\nwant: {want}"
    );
}

/// A campaign on the coastal family with seed `seed` and `seeds` seeds.
fn coastal_campaign(dir: &Path, seed: u64, seeds: u64) -> PathBuf {
    let family = root().join("examples/families/coastal.family.toml");
    let p = dir.join("c.toml");
    std::fs::write(
        &p,
        format!(
            "name = \"tune\"\nseed = {seed}\nseeds = {seeds}\nscenarios = [{:?}]\n\
             [[configs]]\nname = \"amp\"\n[configs.set]\n\"mission.time_limit_s\" = 60.0\n\
             \"sim.duration_s\" = 60.0\n",
            family.to_str().unwrap()
        ),
    )
    .unwrap();
    p
}

#[test]
fn a_campaign_or_family_draw_reaches_test_seeds_only_when_asked() {
    let tmp = tempfile::tempdir().unwrap();
    // The coastal task's test seed is 3202, its tuning seed 3201.
    let test = coastal_campaign(tmp.path(), 3202, 2);
    let out = tmp.path().join("out");
    let (f, o) = (test.to_str().unwrap(), out.to_str().unwrap());
    fails_with(
        &["campaign", f, "--out", o],
        "seed: seed 3202 with 2 seeds flies test seeds of benchmark task 'coastal' (task set v1) \
         on scenarios[0]",
    );
    fails_with(
        &["campaign", f, "--out", o],
        "tune on its tuning seed 3201, or pass --test-seeds",
    );
    assert!(!out.exists(), "a refused campaign wrote {}", out.display());
    run_ok(&["campaign", f, "--out", o, "--test-seeds", "--jobs", "1"]);
    assert!(out.join("runs.csv").exists());

    // The tuning seed flies without asking.
    let tuning = coastal_campaign(tmp.path(), 3201, 2);
    let o2 = tmp.path().join("tuning");
    run_ok(&[
        "campaign",
        tuning.to_str().unwrap(),
        "--out",
        o2.to_str().unwrap(),
        "--jobs",
        "1",
    ]);

    let family = root().join("examples/families/coastal.family.toml");
    let fam = family.to_str().unwrap();
    let sites = tmp.path().join("sites");
    let s = sites.to_str().unwrap();
    fails_with(
        &["family", fam, "--sample", "3", "--seed", "3202", "--out", s],
        "--seed 3202 with --sample 3 draws test seeds of benchmark task 'coastal' (task set v1; \
         site 0 is one); draw its tuning seed 3201, or pass --test-seeds",
    );
    assert!(!sites.exists());
    run_ok(&[
        "family",
        fam,
        "--sample",
        "3",
        "--seed",
        "3202",
        "--out",
        s,
        "--test-seeds",
    ]);
    let sites2 = tmp.path().join("sites2");
    run_ok(&[
        "family",
        fam,
        "--sample",
        "3",
        "--seed",
        "3201",
        "--out",
        sites2.to_str().unwrap(),
    ]);
}

#[test]
fn no_shipped_campaign_reaches_a_test_seed() {
    for e in std::fs::read_dir(root().join("examples/campaigns")).unwrap() {
        let p = e.unwrap().path();
        let c = plumetrace_campaign::Campaign::load(&p, Some(1));
        assert!(c.is_ok(), "{}: {:?}", p.display(), c.err());
    }
}

#[test]
fn the_benchmark_flies_resumes_and_writes_the_leaderboard() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("bench");
    let o = out.to_str().unwrap();
    let args = [
        "benchmark",
        "--tasks",
        "freshwater-team",
        "--seeds-per-task",
        "2",
        "--jobs",
        "2",
        "--out",
        o,
    ];
    let first = run_ok(&args);
    let text = String::from_utf8_lossy(&first.stdout);
    assert!(
        text.contains(
            "freshwater-team: 1 planners x 2 test seeds: 2 runs, 0 already recorded, 2 run now"
        ),
        "{text}"
    );
    let md = std::fs::read_to_string(out.join("leaderboard.md")).unwrap();
    assert!(
        md.starts_with("# Benchmark leaderboard, task set v1\n"),
        "{md}"
    );
    assert!(md.contains("| 1 | formation | 2 |"), "{md}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("leaderboard.json")).unwrap())
            .unwrap();
    assert_eq!(json["task_set"], "v1");
    assert_eq!(json["tasks"][0]["task"]["name"], "freshwater-team");
    assert_eq!(json["tasks"][0]["entries"][0]["runs"], 2);
    assert!(out.join("freshwater-team/success.svg").exists());
    // The task's campaign flies the task's test seeds.
    let runs = std::fs::read_to_string(out.join("freshwater-team/runs.csv")).unwrap();
    let seed0 = plumetrace_env::derive_seed(3252, 0).to_string();
    assert!(runs.contains(&seed0), "{runs}");

    let again = run_ok(&args);
    let text = String::from_utf8_lossy(&again.stdout);
    assert!(
        text.contains("2 runs, 2 already recorded, 0 run now"),
        "{text}"
    );
    assert_eq!(
        md,
        std::fs::read_to_string(out.join("leaderboard.md")).unwrap()
    );
}

#[test]
fn every_planner_meets_the_same_seeds() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("bench");
    run_ok(&[
        "benchmark",
        "--tasks",
        "kelp",
        "--planner",
        "moth,surge_cast",
        "--seeds-per-task",
        "1",
        "--jobs",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    let runs = std::fs::read_to_string(out.join("kelp/runs.csv")).unwrap();
    let seeds: Vec<&str> = runs
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(4).unwrap())
        .collect();
    assert_eq!(seeds.len(), 2);
    assert_eq!(seeds[0], seeds[1]);
    assert_eq!(seeds[0], plumetrace_env::derive_seed(3222, 0).to_string());
}

#[test]
fn benchmark_errors_name_what_is_wrong() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let o = out.to_str().unwrap();
    fails_with(
        &["benchmark", "--tasks", "coastl", "--out", o],
        "error: no task 'coastl' in task set v1 (did you mean 'coastal'?); tasks: coastal, \
         faults, kelp, duck-like, multi-source, freshwater-team",
    );
    fails_with(
        &["benchmark", "--planner", "amq", "--out", o],
        "error: no planner 'amq' (did you mean 'amp'?); planners: amp, infotaxis, lawnmower, \
         moth, surge_cast, formation",
    );
    fails_with(
        &[
            "benchmark",
            "--tasks",
            "freshwater-team",
            "--planner",
            "amp",
            "--out",
            o,
        ],
        "error: task 'freshwater-team' is not flown by 'amp': its planners are formation",
    );
    fails_with(
        &[
            "benchmark",
            "--tasks",
            "kelp",
            "--seeds-per-task",
            "201",
            "--out",
            o,
        ],
        "benchmark task 'kelp': --seeds-per-task 201: task 'kelp' has 200 test seeds (1 to 200)",
    );
    fails_with(
        &["benchmark", "--seeds-per-task", "0", "--out", o],
        "invalid value '0' for '--seeds-per-task <SEEDS_PER_TASK>': must be a whole number from 1",
    );
    let missing = tmp.path().join("nope.toml");
    fails_with(
        &[
            "benchmark",
            "--planner-file",
            missing.to_str().unwrap(),
            "--out",
            o,
        ],
        "nope.toml: ",
    );
    let bad = tmp.path().join("mine.toml");
    std::fs::write(&bad, "kind = \"mot\"\n").unwrap();
    fails_with(
        &[
            "benchmark",
            "--planner-file",
            bad.to_str().unwrap(),
            "--out",
            o,
        ],
        "mine.toml:1: kind: 'mot' is not a planner (did you mean 'moth'?)",
    );
    std::fs::write(&bad, "kind = \"moth\"\nspeed_mp = 3.0\n").unwrap();
    fails_with(
        &[
            "benchmark",
            "--tasks",
            "kelp",
            "--planner-file",
            bad.to_str().unwrap(),
            "--out",
            o,
        ],
        "mine.toml:2: speed_mp: unknown field `speed_mp`; did you mean `speed_mps`?",
    );
    let foreign = tmp.path().join("foreign");
    std::fs::create_dir_all(&foreign).unwrap();
    std::fs::write(foreign.join("notes.txt"), "mine").unwrap();
    fails_with(
        &[
            "benchmark",
            "--tasks",
            "kelp",
            "--out",
            foreign.to_str().unwrap(),
        ],
        "holds files (notes.txt among them) but no benchmark (no tasks/)",
    );
}
