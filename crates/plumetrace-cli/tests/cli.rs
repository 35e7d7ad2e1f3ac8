//! Runs the built `plumetrace` binary in temporary directories.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

mod common;
use common::{bin, run_ok};

/// The demo preset shortened to one simulated minute, written as a scenario file.
fn short_demo(dir: &Path) -> PathBuf {
    let text = plumetrace_scenario::find_preset("plume-demo").unwrap().toml;
    let text = text
        .replace("duration_s = 600.0", "duration_s = 60.0")
        .replace("average_start_s = 300.0", "average_start_s = 30.0");
    let path = dir.join("short.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn presets_lists_every_registered_preset() {
    let out = run_ok(&["presets"]);
    let text = String::from_utf8(out.stdout).unwrap();
    for p in plumetrace_scenario::PRESETS {
        assert!(
            text.lines()
                .any(|l| l.starts_with(p.name) && l.contains(p.summary)),
            "{} missing from:\n{text}",
            p.name
        );
    }
}

#[test]
fn run_writes_outputs_and_is_reproducible() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = short_demo(dir.path());
    let s = scenario.to_str().unwrap();
    let (a, b, c) = (
        dir.path().join("a"),
        dir.path().join("b"),
        dir.path().join("c"),
    );
    run_ok(&["run", s, "--seed", "5", "--out", a.to_str().unwrap()]);
    run_ok(&["run", s, "--seed", "5", "--out", b.to_str().unwrap()]);
    run_ok(&["run", s, "--seed", "6", "--out", c.to_str().unwrap()]);
    for f in ["stats.json", "snapshot.csv", "filaments.csv", "plume.svg"] {
        assert!(a.join(f).is_file(), "{f} missing");
    }
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(a.join("stats.json")).unwrap()).unwrap();
    assert_eq!(stats["steps"], 600);
    assert_eq!(stats["seed"], 5);
    let released = stats["filaments"]["released"].as_u64().unwrap();
    assert!(
        (200..400).contains(&released),
        "released {released} filaments in 60 s at 5 /s"
    );
    let read = |d: &Path, f: &str| std::fs::read(d.join(f)).unwrap();
    assert_eq!(read(&a, "snapshot.csv"), read(&b, "snapshot.csv"));
    assert_eq!(read(&a, "filaments.csv"), read(&b, "filaments.csv"));
    assert_ne!(read(&a, "filaments.csv"), read(&c, "filaments.csv"));
    let snap = String::from_utf8(read(&a, "snapshot.csv")).unwrap();
    assert!(snap.starts_with("x_m,y_m,concentration,mean_concentration,intermittency\n"));
    assert_eq!(snap.lines().count(), 1 + 201 * 101);
    let svg = String::from_utf8(read(&a, "plume.svg")).unwrap();
    assert!(svg.contains("East (m)") && svg.contains("North (m)") && svg.contains("source"));
}

#[test]
fn steady_preset_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("fw");
    run_ok(&[
        "run",
        "--preset",
        "freshwater",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("stats.json")).unwrap()).unwrap();
    assert_eq!(stats["plume_model"], "steady");
    assert!(stats["max_concentration"].as_f64().unwrap() > 0.0);
}

#[test]
fn check_accepts_good_files_and_names_the_key_of_bad_ones() {
    let dir = tempfile::tempdir().unwrap();
    let good = short_demo(dir.path());
    let out = run_ok(&["check", good.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("ok"));
    let bad = dir.path().join("bad.toml");
    let text = std::fs::read_to_string(&good)
        .unwrap()
        .replace("mass_rate_per_s = 5.0", "mass_rate_per_s = -5.0");
    std::fs::write(&bad, text).unwrap();
    let out = bin()
        .args(["check", bad.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.toml") && err.contains("sources[0].mass_rate_per_s"),
        "{err}"
    );
    let typo = dir.path().join("typo.toml");
    let text = std::fs::read_to_string(&good)
        .unwrap()
        .replace("noise_gain = 0.3", "noise_gane = 0.3");
    std::fs::write(&typo, text).unwrap();
    let out = bin()
        .args(["check", typo.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("flow.farrell") && err.contains("noise_gane"),
        "{err}"
    );
    let missing = bin()
        .args(["check", "/nonexistent/x.toml"])
        .output()
        .unwrap();
    assert_eq!(missing.status.code(), Some(1));
}

#[test]
fn bad_flags_are_errors_not_panics() {
    for args in [
        vec!["run", "--preset", "nope"],
        vec!["run"],
        vec!["bench", "plume", "--dt=-1"],
        vec![
            "bench",
            "plume",
            "--release-rate=-3",
            "--warmup",
            "0",
            "--duration",
            "0.1",
        ],
    ] {
        let out = bin().args(&args).output().unwrap();
        assert_eq!(
            out.status.code(),
            Some(1),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(String::from_utf8_lossy(&out.stderr).starts_with("error:"));
    }
    let out = bin().args(["run", "--seed", "abc"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "clap usage errors exit 2");
}

#[test]
fn bench_plume_prints_the_documented_json() {
    let out = run_ok(&[
        "bench",
        "plume",
        "--warmup",
        "5",
        "--duration",
        "1",
        "--queries",
        "1000",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in [
        "ns_per_filament_step",
        "mean_live_filaments",
        "point_query_ns",
        "sim_s_per_cpu_s",
    ] {
        assert!(
            v[key].as_f64().is_some_and(|x| x > 0.0),
            "{key} missing or not positive in {v}"
        );
    }
    assert_eq!(v["pompy_compatible"], true);
    assert_eq!(v["steps_timed"], 100);
}

#[test]
fn mission_run_writes_summary_trajectory_events_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    let text = plumetrace_scenario::find_preset("demo").unwrap().toml;
    let text = text
        .replace("time_limit_s = 2400.0", "time_limit_s = 200.0")
        .replace("spinup_s = 3500.0", "spinup_s = 600.0");
    let path = dir.path().join("mission.toml");
    std::fs::write(&path, text).unwrap();
    let out = dir.path().join("m");
    run_ok(&[
        "run",
        path.to_str().unwrap(),
        "--seed",
        "2",
        "--out",
        out.to_str().unwrap(),
        "--stats",
    ]);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    for key in [
        "outcome",
        "ended",
        "declared",
        "first_declaration",
        "declarations",
        "first_detection_s",
        "path_length_m",
        "trace_length_m",
        "sim_time_s",
        "sources",
        "vehicles",
        "stage_times",
    ] {
        assert!(summary.get(key).is_some(), "summary.json lacks {key}");
    }
    assert_eq!(summary["sim_time_s"], 200.0);
    assert_eq!(summary["outcome"], "timed_out");
    assert_eq!(summary["ended"]["reason"], "time_limit");
    assert_eq!(summary["ended"]["t_s"], 200.0);
    assert!(summary["first_declaration"].is_null());
    assert_eq!(summary["vehicles"][0]["planner"], "amp");
    let sources = summary["sources"].as_array().unwrap();
    assert_eq!(sources.len(), 1);
    assert_eq!(sources[0]["x_m"], 100.0);
    assert_eq!(
        summary["sources_located"].as_u64().unwrap(),
        u64::from(sources[0]["located"].as_bool().unwrap())
    );
    let traj = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    assert!(traj.starts_with("t_s,vehicle,true_x_m,true_y_m,true_z_m,est_x_m,est_y_m,heading_deg,speed_mps,behaviour,reading_v,detection\n"));
    assert_eq!(traj.lines().count(), 1 + 2000);
    let events = std::fs::read_to_string(out.join("events.jsonl")).unwrap();
    for line in events.lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        assert!(v["t_s"].is_number() && v["event"].is_string(), "{line}");
    }
    assert!(events.contains("\"behaviour\""));
    let svg = std::fs::read_to_string(out.join("plot.svg")).unwrap();
    for label in ["East (m)", "North (m)", "op-area", "true source"] {
        assert!(svg.contains(label), "plot lacks {label}");
    }
    // The legend lists only what is drawn.
    let detected = traj.lines().skip(1).any(|l| l.ends_with(",1"));
    assert_eq!(
        svg.contains("\ndetection\n"),
        detected,
        "detections in the track: {detected}"
    );
    assert!(!svg.contains("declared source"));
    // The snapshot log replays to the same decisions.
    let log = out.join("snapshots.jsonl.gz");
    assert!(log.exists());
    let replayed = stdout(run_ok(&["replay", log.to_str().unwrap()]));
    assert!(
        replayed.contains("2000 decisions replayed, 0 differ"),
        "{replayed}"
    );
    let other = dir.path().join("other.toml");
    std::fs::write(&other, "kind = \"amp\"\nspeed_mps = 1.5\n").unwrap();
    let out = bin()
        .args(["replay", log.to_str().unwrap(), "--planner-file"])
        .arg(&other)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(3),
        "decisions differ: exit status 3"
    );
    let replayed = stdout(out);
    assert!(
        !replayed.contains(", 0 differ") && replayed.contains("line 2, vehicle 0"),
        "{replayed}"
    );
    // The replayed page shows the run's true sources (read from the summary.json beside the log);
    // the same log anywhere else carries no truth, and its page shows none.
    let page_of = |log: &std::path::Path, page: &std::path::Path| {
        let out = bin()
            .args(["replay", log.to_str().unwrap(), "--planner-file"])
            .arg(&other)
            .arg("--page")
            .arg(page)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(3));
        std::fs::read_to_string(page).unwrap()
    };
    let page = page_of(&log, &dir.path().join("replayed.html"));
    assert!(
        page.contains("\"sources\":[["),
        "no true source on the replayed page"
    );
    let alone = dir.path().join("alone.jsonl.gz");
    std::fs::copy(&log, &alone).unwrap();
    let page = page_of(&alone, &dir.path().join("alone.html"));
    assert!(
        page.contains("\"sources\":[]"),
        "a log without its run has no truth"
    );
    // A bad planner file is named in the error.
    std::fs::write(&other, "kind = \"amp\"\nspeed = 1.5\n").unwrap();
    let out = bin()
        .args(["replay", log.to_str().unwrap(), "--planner-file"])
        .arg(&other)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("other.toml") && err.contains("speed: unknown field"),
        "{err}"
    );
}

#[test]
fn planners_lists_every_planner_with_its_keys_and_the_guide_has_the_table() {
    let text = stdout(run_ok(&["planners"]));
    assert!(
        text.contains("amp: REMUS Adaptive Mission Planner"),
        "{text}"
    );
    for key in [
        "decision_period_s",
        "beta_deg",
        "threshold_v",
        "lost_point_eviction",
    ] {
        assert!(text.contains(key), "{key} missing from:\n{text}");
    }
    let md = stdout(run_ok(&["planners", "--markdown"]));
    let readme = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../docs/planners.md"
    ))
    .unwrap();
    let start = readme
        .find("<!-- planners:start -->\n")
        .expect("docs/planners.md marks its planner table");
    let end = readme.find("<!-- planners:end -->").unwrap();
    assert_eq!(
        &readme[start + "<!-- planners:start -->\n".len()..end],
        md,
        "docs/planners.md's planner table is not the registry's: run scripts/readme_tables.sh"
    );
}

#[test]
fn check_names_bad_planner_and_mission_keys() {
    let dir = tempfile::tempdir().unwrap();
    let demo = plumetrace_scenario::find_preset("demo").unwrap().toml;
    let cases = [
        (
            demo.replace("mapping_lines = 3", "mapping_lines = 3\nspeed_mps = -2.0"),
            "planner.speed_mps",
        ),
        (
            demo.replace("mapping_lines = 3", "mapping_lines = 3\nbeta = 20"),
            "planner.beta: unknown field",
        ),
        (
            format!(
                "{}\n[planners.tracer]\nkind = \"amp\"\nlamda_s = 5.0\n",
                without_legacy_planner(demo)
                    .replace("x_m = 470.0", "x_m = 470.0\nplanner = \"tracer\"")
            ),
            "planners.tracer.lamda_s: unknown field",
        ),
        (
            demo.replace("time_limit_s = 2400.0", "time_limit_s = -1.0"),
            "mission.time_limit_s",
        ),
        (
            demo.replace("env_dt_s = 5.0", "env_dt_s = 0.25"),
            "mission.env_dt_s",
        ),
    ];
    for (k, (text, key)) in cases.iter().enumerate() {
        assert_ne!(text.as_str(), demo, "case {k} did not apply");
        let path = dir.path().join(format!("bad{k}.toml"));
        std::fs::write(&path, text).unwrap();
        let out = bin()
            .args(["check", path.to_str().unwrap()])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "case {k}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(key) && err.contains(&format!("bad{k}.toml")),
            "case {k}: {err}"
        );
        // `run` rejects it with the same message, before any step.
        let run = bin()
            .args(["run", path.to_str().unwrap(), "--out"])
            .arg(dir.path().join(format!("out{k}")))
            .output()
            .unwrap();
        assert_eq!(run.status.code(), Some(1), "case {k}");
        assert_eq!(String::from_utf8_lossy(&run.stderr), err, "case {k}");
    }
    // A good file: check says how long the mission can be and who flies what.
    let path = dir.path().join("good.toml");
    std::fs::write(&path, demo).unwrap();
    let ok = stdout(run_ok(&["check", path.to_str().unwrap()]));
    assert!(
        ok.contains("mission of up to 2400 s") && ok.contains("auv flies amp (planner)"),
        "{ok}"
    );
}

/// A scenario's text without its `[planner]` table (up to the next table or the end).
fn without_legacy_planner(text: &str) -> String {
    let (a, b) = (
        text.find("[planner]").unwrap(),
        text.find("[output]").unwrap_or(text.len()),
    );
    format!("{}{}", &text[..a], &text[b..])
}

fn stdout(out: std::process::Output) -> String {
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn the_guide_has_the_limits_table() {
    let md = stdout(run_ok(&["limits", "--markdown"]));
    let readme = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../docs/scenarios.md"
    ))
    .unwrap();
    let start = readme
        .find("<!-- limits:start -->\n")
        .expect("docs/scenarios.md marks its limits table")
        + "<!-- limits:start -->\n".len();
    let end = readme.find("<!-- limits:end -->").unwrap();
    assert_eq!(
        &readme[start..end],
        md,
        "docs/scenarios.md's limits table is not the code's: run scripts/readme_tables.sh"
    );
}

#[test]
fn check_says_how_the_flow_grid_steps() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../plumetrace-scenario/presets/pompy.toml"
    ))
    .unwrap();
    let check = |text: &str| {
        let p = dir.path().join("pompy.toml");
        std::fs::write(&p, text).unwrap();
        String::from_utf8_lossy(&run_ok(&["check", p.to_str().unwrap()]).stdout).into_owned()
    };
    // The preset's grid steps every 0.05 s under 0.01 s puff steps.
    let out = check(&text);
    assert!(
        out.contains("the flow steps once per 5 plume steps"),
        "{out}"
    );
    // With the plume's step (no block), nothing is said.
    let along = text.replace("step_s = 0.05", "step_s = 0.0");
    assert_ne!(along, text);
    let out = check(&along);
    assert!(
        out.contains("ok (plume run") && !out.contains("flow"),
        "{out}"
    );
    // A plume step beyond half the grid's stable limit takes sub-steps.
    let coarse = along.replace("dt_s = 0.01", "dt_s = 0.5");
    let out = check(&coarse);
    assert!(out.contains(" times per plume step"), "{out}");
}

#[test]
fn the_moos_script_names_an_unknown_argument_before_it_skips() {
    // No MOOSDB on this PATH: the run would be skipped, but a mistyped argument is named first.
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scripts/moos_interop.sh");
    let run = |args: &[&str]| {
        std::process::Command::new("bash")
            .arg(script)
            .args(args)
            .env("PATH", "/usr/bin:/bin")
            .output()
            .unwrap()
    };
    let typo = run(&["--bni", "x"]);
    assert_eq!(typo.status.code(), Some(2));
    let err = String::from_utf8(typo.stderr).unwrap();
    assert!(
        err.contains("moos_interop: unknown argument '--bni' (expected --bin PATH or --keep)"),
        "{err}"
    );
    let fine = run(&["--keep"]);
    assert_eq!(fine.status.code(), Some(0));
    let out = String::from_utf8(fine.stdout).unwrap();
    assert!(out.contains("skipped: no MOOSDB on the PATH"), "{out}");
}
