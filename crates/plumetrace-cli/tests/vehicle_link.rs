//! End to end over the real links: `plumetrace frontseat` flies the demo's vehicle and plume and
//! `plumetrace onboard` flies the AMP against it, in lock-step (deterministic), over loopback
//! TCP with the Bluefin protocol and over a pseudo-terminal with the Iver protocol; faults: a
//! front-seat restart with garbage lines, and 30 s without navigation.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use serde_json::Value;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Stdio};

/// Starts a front seat; returns it once it is ready (its onboard file written).
fn frontseat(dir: &Path, extra: &[&str]) -> Child {
    let onboard = dir.join("onboard.toml");
    let out = dir.join("fs");
    let mut args = vec![
        "frontseat",
        "--preset",
        "demo",
        "--lock-step",
        "--write-onboard",
        onboard.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--wait-s",
        "20",
    ];
    args.extend_from_slice(extra);
    let mut child = common::bin()
        .args(&args)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.as_mut().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert!(first.contains("front seat"), "{first}");
    child
}

/// Flies the onboard process against a front seat started with `extra`; returns the onboard
/// report and the front seat's.
fn fly(dir: &Path, extra: &[&str]) -> (Value, Value) {
    let mut fs = frontseat(dir, extra);
    let onboard = dir.join("onboard.toml");
    let out = dir.join("ob");
    let o = common::bin()
        .args([
            "onboard",
            onboard.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(fs.wait().unwrap().success());
    let read =
        |p: &Path| -> Value { serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap() };
    (
        read(&out.join("onboard.json")),
        read(&dir.join("fs").join("frontseat.json")),
    )
}

fn declared_near_the_source(report: &Value) -> f64 {
    let d = report["declarations"].as_array().unwrap();
    assert!(!d.is_empty(), "no declaration: {report}");
    let (x, y) = (d[0][0].as_f64().unwrap(), d[0][1].as_f64().unwrap());
    // The demo's source is at (100, 0).
    (x - 100.0).hypot(y)
}

fn no_unsafe_commands(fs: &Value) {
    assert_eq!(fs["unsafe_commands"], 0, "{fs}");
    assert_eq!(fs["bad_lines"], 0, "{fs}");
}

#[test]
fn bluefin_over_tcp_in_lock_step_declares_and_replays_exactly_and_again_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let (ob, fs) = fly(dir.path(), &["--listen", "127.0.0.1:0"]);
    assert_eq!(ob["end"], "finished", "{ob}");
    let error = declared_near_the_source(&ob);
    assert!(error < 30.0, "declared {error:.1} m from the source");
    assert!(ob["pauses"].as_array().unwrap().is_empty(), "{ob}");
    assert_eq!(ob["commands_rejected"], 0);
    no_unsafe_commands(&fs);
    assert_eq!(fs["finished"], true);
    assert_eq!(fs["nav_records"], ob["nav_records"]);
    // The logged decisions come out again from the same planner.
    let log = dir.path().join("ob").join("snapshots.jsonl.gz");
    let out = common::run_ok(&["replay", log.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains(" 0 differ"), "{text}");
    // Another configuration departs from the logged decisions, and the replay says where.
    let other = dir.path().join("other.toml");
    std::fs::write(&other, "kind = \"amp\"\nbeta_deg = 35.0\n").unwrap();
    let o = common::bin()
        .args([
            "replay",
            log.to_str().unwrap(),
            "--planner-file",
            other.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("  line "),
        "the first differences are listed: {text}"
    );
    let alog = read_alog(&dir.path().join("ob").join("run.alog"));
    assert!(
        alog.iter().any(|(v, _)| v == "CPT_DECLARATION"),
        "the declaration is in run.alog"
    );
    // Lock-step is deterministic: a second flight logs the same decisions.
    let again = tempfile::tempdir().unwrap();
    let (ob2, _) = fly(again.path(), &["--listen", "127.0.0.1:0"]);
    assert_eq!(ob2["declarations"], ob["declarations"]);
    let lines = |p: &Path| -> Vec<String> {
        let r = plumetrace_onboard_log(p);
        r.into_iter().skip(1).collect()
    };
    assert_eq!(
        lines(&again.path().join("ob").join("snapshots.jsonl.gz")),
        lines(&log)
    );
}

/// Reads an `.alog` line by line with its documented layout: `%%` header lines, then
/// `TIME VARIABLE SOURCE VALUE` in time order; returns the postings.
fn read_alog(path: &Path) -> Vec<(String, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut postings = Vec::new();
    let mut last = f64::NEG_INFINITY;
    let mut header = true;
    for line in text.lines() {
        if line.starts_with("%%") {
            assert!(header, "header lines come first: {line}");
            continue;
        }
        header = false;
        let f: Vec<&str> = line.split(' ').collect();
        assert_eq!(f.len(), 4, "{line}");
        let t: f64 = f[0].parse().unwrap();
        assert!(t >= last, "time order: {line}");
        last = t;
        assert!(
            plumetrace_onboard::alog::VARIABLES.contains(&f[1]),
            "{line}"
        );
        postings.push((f[1].to_string(), f[3].to_string()));
    }
    assert!(text.contains("%% LOGSTART"));
    for v in [
        "NAV_X",
        "NAV_Y",
        "NAV_HEADING",
        "NAV_SPEED",
        "NAV_DEPTH",
        "DESIRED_HEADING",
        "DESIRED_SPEED",
        "CPT_BEHAVIOUR",
        "CPT_READING",
        "CPT_DETECTION",
    ] {
        assert!(
            postings.iter().any(|(n, _)| n == v),
            "{v} missing from {}",
            path.display()
        );
    }
    postings
}

#[test]
fn a_mission_writes_an_alog_per_planned_vehicle_that_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    common::run_ok(&[
        "run",
        "--preset",
        "demo",
        "--alog",
        "--no-snapshot-log",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    let postings = read_alog(&dir.path().join("auv.alog"));
    assert!(postings.iter().any(|(v, _)| v == "DESIRED_ALTITUDE"));
    assert!(
        postings.iter().any(|(v, _)| v == "CPT_DECLARATION"),
        "the demo declares"
    );
}

/// The lines of a snapshot log.
fn plumetrace_onboard_log(p: &Path) -> Vec<String> {
    plumetrace_onboard::snapshot_log::open(p)
        .unwrap()
        .lines()
        .map(Result::unwrap)
        .collect()
}

#[test]
fn a_front_seat_restart_pauses_the_planner_which_reconnects_and_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let (ob, fs) = fly(
        dir.path(),
        &[
            "--listen",
            "127.0.0.1:0",
            "--restart-at",
            "200",
            "--restart-for",
            "1",
            "--garbage",
            "0.02",
        ],
    );
    assert_eq!(ob["end"], "finished", "{ob}");
    declared_near_the_source(&ob);
    let pauses = ob["pauses"].as_array().unwrap();
    let lost: Vec<&Value> = pauses
        .iter()
        .filter(|p| p[2].as_str().unwrap().starts_with("link lost"))
        .collect();
    assert_eq!(lost.len(), 1, "{ob}");
    assert!(lost[0][1].is_f64(), "the planner resumed: {ob}");
    assert_eq!(ob["connections"], 2, "{ob}");
    assert_eq!(fs["connections"], 2, "{fs}");
    no_unsafe_commands(&fs);
    // Garbage was counted and dropped, never acted on.
    let rejected: u64 = ob["lines_rejected"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert!(rejected > 0, "{ob}");
    assert_eq!(ob["commands_rejected"], 0);
}

#[test]
fn thirty_seconds_without_navigation_pause_the_planner_and_send_the_stop() {
    let dir = tempfile::tempdir().unwrap();
    let (ob, fs) = fly(
        dir.path(),
        &[
            "--listen",
            "127.0.0.1:0",
            "--silent-at",
            "300",
            "--silent-for",
            "30",
        ],
    );
    let pauses = ob["pauses"].as_array().unwrap();
    assert_ne!(ob["end"], "linkgaveup", "{ob}");
    let (start, end) = (
        pauses[0][0].as_f64().unwrap(),
        pauses[0][1].as_f64().unwrap(),
    );
    assert!(
        pauses[0][2]
            .as_str()
            .unwrap()
            .starts_with("navigation older than 5 s"),
        "{ob}"
    );
    // The last record before the silence is at 299.9 s; the first tick more than 5 s later at
    // 305.0 s; navigation comes back at 330.0 s.
    assert!((start - 305.0).abs() < 1e-6, "paused at {start}");
    assert!((end - 330.0).abs() < 1e-6, "resumed at {end}");
    // The stop went out when the planner paused (and once more at the end).
    assert!(ob["safe_commands"].as_u64().unwrap() >= 1, "{ob}");
    assert!(fs["stops"].as_u64().unwrap() >= 1, "{fs}");
    no_unsafe_commands(&fs);
}
#[test]
fn iver_over_a_pseudo_terminal_in_lock_step_answers_every_poll_with_checked_commands() {
    let dir = tempfile::tempdir().unwrap();
    let (ob, fs) = fly(
        dir.path(),
        &[
            "--protocol",
            "iver",
            "--remote-helm-major",
            "4",
            "--time-limit-s",
            "600",
        ],
    );
    no_unsafe_commands(&fs);
    assert_eq!(fs["unanswered"], 0, "{fs}");
    assert_eq!(fs["nav_records"], ob["nav_records"], "{fs} {ob}");
    assert_eq!(ob["nav_records"], 6000, "{ob}");
    assert_eq!(ob["commands_rejected"], 0);
    let log = std::fs::read_to_string(dir.path().join("ob").join("link.log")).unwrap();
    assert!(
        log.contains("> $OMS,") && log.contains("< $OSI,"),
        "Iver sentences on the wire"
    );
    // The planner found and tracked the plume over the serial link.
    let alog = read_alog(&dir.path().join("ob").join("run.alog"));
    assert!(
        alog.iter()
            .any(|(v, x)| v == "CPT_BEHAVIOUR" && x == "track_in"),
        "no track-in"
    );
    // Depths go out in feet (remote helm 4): the AMP's 2 m altitude over about 8 m of water.
    let oms: Vec<f64> = log
        .lines()
        .filter_map(|l| l.split_once("> $OMS,"))
        .map(|(_, r)| r.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    let mean = oms.iter().sum::<f64>() / oms.len() as f64;
    assert!((17.0..22.0).contains(&mean), "mean $OMS depth {mean} ft");
}

#[test]
fn bad_onboard_files_and_front_seat_flags_name_what_and_where() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        "[mission]\nop_area = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]\n[planner]\nkind = \"amp\"\n[link]\nprotocol = \"bluefin\"\naddress = \"127.0.0.1:1\"\norigin = { lat_deg = 36.0, lon_deg = -75.0 }\nstale_nav_s = -2.0\n",
    )
    .unwrap();
    let o = common::bin()
        .args(["onboard", bad.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("bad.toml") && e.contains("link.stale_nav_s"),
        "{e}"
    );
    for (flag, value) in [
        ("--drop", "1.5"),
        ("--nav-period-s", "0"),
        ("--origin", "95,0"),
    ] {
        let o = common::bin()
            .args(["frontseat", "--preset", "demo", flag, value])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{flag} {value}");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains(flag), "{flag}: {e}");
    }
}
