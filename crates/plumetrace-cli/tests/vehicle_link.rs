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
use std::time::{Duration, Instant};

/// Starts a front seat (in lock-step or in real time); returns it once it is ready (its
/// onboard file written).
fn frontseat(dir: &Path, lock_step: bool, extra: &[&str]) -> Child {
    let onboard = dir.join("onboard.toml");
    let out = dir.join("fs");
    let mut args = vec![
        "frontseat",
        "--preset",
        "demo",
        "--write-onboard",
        onboard.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--wait-s",
        "20",
    ];
    if lock_step {
        args.push("--lock-step");
    }
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

/// Waits for a process to exit, at most `limit`; kills it and fails the test after that.
fn wait_for(child: &mut Child, limit: Duration, what: &str) -> std::process::ExitStatus {
    let deadline = Instant::now() + limit;
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what} did not exit within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Flies the onboard process against a front seat started with `extra` (its onboard file
/// changed by `edit` first); returns the onboard report and the front seat's. Every wait is
/// bounded.
fn fly_with(
    dir: &Path,
    lock_step: bool,
    extra: &[&str],
    edit: impl Fn(String) -> String,
) -> (Value, Value) {
    let mut fs = frontseat(dir, lock_step, extra);
    let onboard = dir.join("onboard.toml");
    let text = std::fs::read_to_string(&onboard).unwrap();
    std::fs::write(&onboard, edit(text)).unwrap();
    let out = dir.join("ob");
    let mut ob = common::bin()
        .args([
            "onboard",
            onboard.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let limit = Duration::from_secs(240);
    assert!(wait_for(&mut ob, limit, "onboard").success());
    assert!(wait_for(&mut fs, limit, "frontseat").success());
    let read =
        |p: &Path| -> Value { serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap() };
    (
        read(&out.join("onboard.json")),
        read(&dir.join("fs").join("frontseat.json")),
    )
}

/// [`fly_with`] in lock-step, the onboard file as written.
fn fly(dir: &Path, extra: &[&str]) -> (Value, Value) {
    fly_with(dir, true, extra, |t| t)
}

/// Sets `key = value` in the onboard file's `[table]`.
fn set_key(text: String, table: &str, key: &str, value: &str) -> String {
    let head = format!("[{table}]\n");
    assert!(text.contains(&head), "no [{table}] in {text}");
    let kept: Vec<&str> = text
        .lines()
        .filter(|l| !l.starts_with(&format!("{key} = ")))
        .collect();
    kept.join("\n").replacen(
        &format!("[{table}]"),
        &format!("[{table}]\n{key} = {value}"),
        1,
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
    // The front seat sends its current meter's readings, as a vehicle's ADCP would.
    let (ob, fs) = fly(dir.path(), &["--listen", "127.0.0.1:0"]);
    assert_eq!(ob["end"], "finished", "{ob}");
    let error = declared_near_the_source(&ob);
    println!("Bluefin: declared {error:.1} m from the source: {ob}");
    assert!(error < 30.0, "declared {error:.1} m from the source");
    assert!(ob["pauses"].as_array().unwrap().is_empty(), "{ob}");
    assert_eq!(ob["commands_rejected"], 0);
    no_unsafe_commands(&fs);
    assert_eq!(fs["finished"], true);
    // Every record was read, bar one the front seat may send after the back seat's final stop
    // and before it sees the line close.
    let (sent, read) = (
        fs["nav_records"].as_u64().unwrap(),
        ob["nav_records"].as_u64().unwrap(),
    );
    assert!(sent == read || sent == read + 1, "sent {sent}, read {read}");
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
    // The altitude hold as the Bluefin link sent it: DESIRED_ALTITUDE, no DESIRED_DEPTH.
    assert!(alog.iter().any(|(v, _)| v == "DESIRED_ALTITUDE"));
    assert!(!alog.iter().any(|(v, _)| v == "DESIRED_DEPTH"));
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
        let f: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(f.len(), 4, "{line}");
        let t: f64 = f[0].parse().unwrap();
        assert!(t >= last, "time order: {line}");
        last = t;
        assert!(plumetrace_log::alog::VARIABLES.contains(&f[1]), "{line}");
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
    plumetrace_log::snapshot::open(p)
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
            "--no-flow",
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
/// Flies the Iver remote helm over a pseudo-terminal in lock-step (depths in feet: remote
/// helm 4), with the current meter's readings on the line; `extra` adds faults.
fn fly_iver(dir: &Path, extra: &[&str], edit: impl Fn(String) -> String) -> (Value, Value) {
    let mut args = vec!["--protocol", "iver", "--remote-helm-major", "4"];
    args.extend_from_slice(extra);
    fly_with(dir, true, &args, edit)
}

/// What a flight over the Iver remote helm must show: every poll answered with a checked
/// command, Iver sentences on the wire, depths in feet that hold the AMP's altitude, a
/// declaration near the source, and a log that replays to the same decisions.
fn iver_flight_declares_and_replays(dir: &Path, ob: &Value, fs: &Value) -> f64 {
    no_unsafe_commands(fs);
    // Every poll was answered, bar one the front seat may make after the back seat's final stop
    // and before it sees the line close (a busy machine's timing).
    let unanswered = fs["unanswered"].as_u64().unwrap();
    assert!(
        unanswered == 0 || (unanswered == 1 && fs["back_seat_gone"] == true),
        "{fs}"
    );
    // Likewise every record was read, bar that last one.
    let (sent, read) = (
        fs["nav_records"].as_u64().unwrap(),
        ob["nav_records"].as_u64().unwrap(),
    );
    assert!(sent == read || sent == read + 1, "{fs} {ob}");
    assert_eq!(ob["commands_rejected"], 0);
    let error = declared_near_the_source(ob);
    assert!(error < 30.0, "declared {error:.1} m from the source");
    let log = std::fs::read_to_string(dir.join("ob").join("link.log")).unwrap();
    assert!(
        log.contains("> $OMS,") && log.contains("< $OSI,") && log.contains("< $VDCUR,"),
        "Iver and current sentences on the wire"
    );
    // Depths go out in feet (remote helm 4): the AMP's 2 m altitude (1 m while it traces the
    // plume, most of the flight) over about 8 m of water: 19.7 ft and 23.0 ft.
    let oms: Vec<f64> = log
        .lines()
        .filter_map(|l| l.split_once("> $OMS,"))
        .map(|(_, r)| r.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    let mean = oms.iter().sum::<f64>() / oms.len() as f64;
    assert!((17.0..24.0).contains(&mean), "mean $OMS depth {mean} ft");
    let alog = read_alog(&dir.join("ob").join("run.alog"));
    assert!(alog.iter().any(|(v, _)| v == "CPT_DECLARATION"));
    let snapshots = dir.join("ob").join("snapshots.jsonl.gz");
    let out = common::run_ok(&["replay", snapshots.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains(" 0 differ"), "{text}");
    error
}

#[test]
fn iver_over_a_pseudo_terminal_in_lock_step_declares_near_the_source_and_replays_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let (ob, fs) = fly_iver(dir.path(), &[], |t| t);
    let error = iver_flight_declares_and_replays(dir.path(), &ob, &fs);
    let pauses = ob["pauses"].as_array().unwrap();
    if ob["end"] == "finished" {
        // The planner finished its mission before the front seat's time limit: no pause.
        assert!(pauses.is_empty(), "{ob}");
    } else {
        // The front seat ended at its time limit and its pseudo-terminal went away for good:
        // the back seat paused on the lost line (the only pause) and gave up without reopening
        // it.
        assert_eq!(ob["end"], "linkgaveup", "{ob}");
        assert_eq!(pauses.len(), 1, "{ob}");
        assert!(
            pauses[0][2].as_str().unwrap().starts_with("link lost"),
            "{ob}"
        );
        assert!(pauses[0][1].is_null(), "{ob}");
    }
    assert_eq!(ob["connections"], 1, "{ob}");
    println!("Iver: declared {error:.1} m from the source: {ob}");
}

#[test]
fn an_iver_restart_silences_the_line_pauses_the_planner_which_goes_on_to_its_declaration() {
    let dir = tempfile::tempdir().unwrap();
    let (ob, fs) = fly_iver(
        dir.path(),
        &[
            "--restart-at",
            "200",
            "--restart-for",
            "4",
            "--garbage",
            "0.02",
        ],
        // Two seconds: long enough that a busy machine's scheduling stalls (the silence is
        // wall time) do not count as a silent line, well within the 4 s restart.
        |t| set_key(t, "link", "silence_timeout_s", "2.0"),
    );
    assert_eq!(fs["restarts"], 1, "{fs}");
    let pauses = ob["pauses"].as_array().unwrap();
    let silent: Vec<&Value> = pauses
        .iter()
        .filter(|p| p[2].as_str().unwrap().starts_with("line silent"))
        .collect();
    assert_eq!(silent.len(), 1, "{ob}");
    // In lock-step the vehicle does not move while its computer restarts: the planner pauses
    // at the last record before and resumes with the first after.
    let (start, end) = (silent[0][0].as_f64().unwrap(), silent[0][1].as_f64());
    assert!((start - 199.9).abs() < 1e-6, "paused at {start}");
    assert!(end.is_some_and(|e| (e - 200.0).abs() < 1e-6), "{ob}");
    // The serial device stayed open: one connection, no reopening.
    assert_eq!(ob["connections"], 1, "{ob}");
    // The boot text and the garbage were counted and dropped, never acted on.
    assert!(
        ob["lines_rejected"]["no_dollar"].as_u64().unwrap() >= 1,
        "{ob}"
    );
    iver_flight_declares_and_replays(dir.path(), &ob, &fs);
}

/// `(time, position, flow)` of vehicle 0 in a snapshot log, in order.
type Track = Vec<(f64, [f64; 2], Option<[f64; 3]>)>;

fn track(p: &Path) -> Track {
    plumetrace_onboard_log(p)
        .iter()
        .skip(1)
        .map(|l| serde_json::from_str::<Value>(l).unwrap())
        .filter(|r| r["vehicle"] == 0)
        .map(|r| {
            let s = &r["snapshot"];
            let f = |v: &Value| v.as_f64().unwrap();
            let pos = [f(&s["nav"]["pos_m"][0]), f(&s["nav"]["pos_m"][1])];
            let flow = s["flow"].as_object().map(|fl| {
                let v = &fl["velocity_mps"];
                [f(&fl["time_s"]), f(&v[0]), f(&v[1])]
            });
            (f(&s["time_s"]), pos, flow)
        })
        .collect()
}

/// The first time two tracks are more than `metres` apart (`None`: never, where both have
/// records).
fn apart_at(a: &Track, b: &Track, metres: f64) -> Option<f64> {
    let b: std::collections::BTreeMap<i64, [f64; 2]> = b
        .iter()
        .map(|(t, p, _)| ((t * 10.0).round() as i64, *p))
        .collect();
    a.iter().find_map(|(t, p, _)| {
        let q = b.get(&((t * 10.0).round() as i64))?;
        ((p[0] - q[0]).hypot(p[1] - q[1]) > metres).then_some(*t)
    })
}

#[test]
fn measured_current_crosses_the_link_and_keeps_the_onboard_run_on_the_simulated_track() {
    let dir = tempfile::tempdir().unwrap();
    // The simulated mission: the same planner, fed by the simulator directly.
    let sim = dir.path().join("sim");
    common::run_ok(&["run", "--preset", "demo", "--out", sim.to_str().unwrap()]);
    let sim = track(&sim.join("snapshots.jsonl.gz"));
    let flights = ["with", "without"].map(|how| {
        let d = dir.path().join(how);
        std::fs::create_dir_all(&d).unwrap();
        let mut extra = vec!["--listen", "127.0.0.1:0", "--time-limit-s", "300"];
        if how == "without" {
            extra.push("--no-flow");
        }
        let (ob, fs) = fly(&d, &extra);
        no_unsafe_commands(&fs);
        assert_eq!(ob["lines_rejected"], serde_json::json!({}), "{ob}");
        (d.join("ob").join("snapshots.jsonl.gz"), ob)
    });
    let with = track(&flights[0].0);
    let without = track(&flights[1].0);
    // The flow field varies in space: the readings agree while the two tracks do.
    let apart_with = apart_at(&with, &sim, 5.0).unwrap_or(f64::INFINITY);
    // Every snapshot built onboard carries the latest current reading, which is the simulated
    // flow sensor's (to the sentence's precision: 0.001 kn, 0.1 deg).
    assert!(with.len() >= 2900, "{}", with.len());
    let sim_flow: std::collections::BTreeMap<i64, [f64; 2]> = sim
        .iter()
        .filter_map(|(_, _, f)| f.map(|f| ((f[0] * 10.0).round() as i64, [f[1], f[2]])))
        .collect();
    let mut readings = std::collections::BTreeSet::new();
    for (t, _, f) in &with {
        let f = f.unwrap_or_else(|| panic!("no flow in the snapshot at {t} s"));
        readings.insert((f[0] * 10.0).round() as i64);
        if *t >= apart_with {
            continue;
        }
        // The reading arrives with the record it was taken at (stamped with the record before).
        let taken = sim_flow
            .range(..=((f[0] + 0.1) * 10.0).round() as i64)
            .next_back()
            .map(|(_, v)| *v)
            .unwrap();
        let err = (f[1] - taken[0]).hypot(f[2] - taken[1]);
        assert!(err < 0.003, "at {t} s: onboard {f:?}, simulated {taken:?}");
    }
    assert!(readings.len() >= 200, "{} readings", readings.len());
    assert!(without.iter().all(|(_, _, f)| f.is_none()));
    // With the measured current the onboard planner flies the simulated mission's track several
    // times longer than on the prior flow alone, which leaves it within the first minute.
    let apart_without = apart_at(&without, &sim, 5.0).unwrap_or(f64::INFINITY);
    println!(
        "5 m from the simulated track at {apart_with} s with the current, {apart_without} s without"
    );
    assert!(apart_without < 60.0, "{apart_without}");
    assert!(
        apart_with >= 4.0 * apart_without,
        "{apart_with} vs {apart_without}"
    );
}

#[test]
fn in_real_time_over_loopback_tcp_navigation_flows_and_every_command_is_acknowledged() {
    let dir = tempfile::tempdir().unwrap();
    // The front seat flies 8 s of mission in real time; the back seat stops after 6 s and
    // says so, and the front seat then ends too.
    let (ob, fs) = fly_with(
        dir.path(),
        false,
        &["--listen", "127.0.0.1:0", "--time-limit-s", "8"],
        |t| {
            assert!(t.contains("mode = \"real_time\""), "{t}");
            set_key(t, "run", "time_limit_s", "6.0")
        },
    );
    assert_eq!(ob["end"], "timelimit", "{ob}");
    assert!(ob["pauses"].as_array().unwrap().is_empty(), "{ob}");
    let records = ob["nav_records"].as_u64().unwrap();
    assert!((40..=70).contains(&records), "{ob}");
    let sent = ob["commands_sent"].as_u64().unwrap();
    assert!(sent >= 40, "{ob}");
    assert_eq!(ob["acks_given_up"], 0, "{ob}");
    assert_eq!(ob["lines_rejected"], serde_json::json!({}), "{ob}");
    no_unsafe_commands(&fs);
    assert_eq!(fs["commands"].as_u64().unwrap(), sent, "{fs} {ob}");
    assert_eq!(fs["finished"], true, "{fs}");
    assert!(
        fs["stops"].as_u64().unwrap() >= 1,
        "the final stop arrived: {fs}"
    );
    // Every command was acknowledged on the wire, and current readings came with the
    // navigation.
    let log = std::fs::read_to_string(dir.path().join("ob").join("link.log")).unwrap();
    let count = |p: &str| log.lines().filter(|l| l.contains(p)).count();
    assert!(count("< $VDCUR,") >= 3, "{log}");
    // `> $BPRMB,<command time>,...` and `< $BFACK,<time>,RMB,<command time>,...`, each line
    // after the seconds since the link started.
    let field = |l: &str, k: usize| l.split([',', '*']).nth(k).map(str::to_string);
    let secs = |l: &str| l.split(' ').next().unwrap().parse::<f64>().unwrap();
    let rmb: Vec<(f64, String)> = log
        .lines()
        .filter(|l| l.contains("> $BPRMB,"))
        .map(|l| (secs(l), field(l, 1).unwrap()))
        .collect();
    let acked: std::collections::BTreeSet<String> = log
        .lines()
        .filter(|l| l.contains("< $BFACK,"))
        .filter_map(|l| field(l, 3))
        .collect();
    assert!(
        rmb.len() as u64 >= sent,
        "{} $BPRMB for {sent} commands",
        rmb.len()
    );
    let end = rmb.last().unwrap().0;
    // An acknowledgement may still be on its way for what went out in the last second.
    let missing: Vec<&(f64, String)> = rmb
        .iter()
        .filter(|(t, c)| *t < end - 1.0 && !acked.contains(c))
        .collect();
    assert!(missing.is_empty(), "not acknowledged: {missing:?}");
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
    // Iver sentences carry no time: a silence in mission time is refused in lock-step.
    let o = common::bin()
        .args([
            "frontseat",
            "--preset",
            "demo",
            "--protocol",
            "iver",
            "--lock-step",
            "--silent-at",
            "300",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("--silent-at") && e.contains("--restart-at"),
        "{e}"
    );
}
