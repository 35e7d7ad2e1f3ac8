//! Bad input that names files: names that become file names are checked where the scenario is
//! read, writers stay inside their output directory whatever the name, and a run that cannot go
//! ahead leaves an earlier run's files as they were.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

mod common;
use common::{bin, demo};

/// Every file under `dir`, relative to it, sorted.
fn tree(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p.clone());
            }
            out.push(p.strip_prefix(dir).unwrap().display().to_string());
        }
    }
    out.sort();
    out
}

/// Runs `plumetrace ARGS`, expects status 1, and returns standard error.
fn fails(args: &[&str]) -> String {
    let out = bin().args(args).output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(1),
        "plumetrace {args:?}: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn hostile_vehicle_names_are_refused_and_nothing_is_written_outside_out() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let long = "x".repeat(300);
    let names = [
        "../alog-escaped",
        "../../alog-escaped",
        "/tmp/alog-escaped-absolute",
        "a/b",
        "..",
        ".hidden",
        "a\\u0000b",
        "bell\\u0007",
        long.as_str(),
        "",
    ];
    for (i, name) in names.iter().enumerate() {
        let text = demo().replacen("name = \"auv\"", &format!("name = \"{name}\""), 1);
        let file = d.join(format!("s{i}.toml"));
        std::fs::write(&file, &text).unwrap();
        let out = d.join("o").join("a").join("b");
        let before = tree(d);
        if name.is_empty() {
            // an empty name is the default (`vehicles[0]`); `check` accepts it
            continue;
        }
        let e = fails(&["check", file.to_str().unwrap()]);
        let line = text
            .lines()
            .position(|l| l.starts_with("name = \""))
            .unwrap();
        let line = text
            .lines()
            .skip(line + 1)
            .position(|l| l.starts_with("name = "))
            .unwrap()
            + line
            + 2;
        assert!(
            e.contains(&format!("s{i}.toml:{line}: vehicles[0].name:")),
            "{name}: {e}"
        );
        let e = fails(&[
            "run",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--alog",
        ]);
        assert!(e.contains("vehicles[0].name"), "{name}: {e}");
        let after: Vec<String> = tree(d)
            .into_iter()
            .filter(|p| !p.starts_with("o"))
            .collect();
        assert_eq!(after, before, "{name}: files appeared outside --out");
        assert!(!Path::new("/tmp/alog-escaped-absolute.alog").exists());
        let _ = std::fs::remove_dir_all(d.join("o"));
    }
}

#[test]
fn two_vehicles_with_one_name_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("twins.toml");
    let twin = "[[vehicles]]\nkind = \"auv\"\nname = \"auv\"\nx_m = 470.0\ny_m = 60.0\nheading_deg = 270.0\n\n[mission]";
    std::fs::write(&file, demo().replacen("[mission]", twin, 1)).unwrap();
    let e = fails(&["check", file.to_str().unwrap()]);
    assert!(
        e.contains("twins.toml:")
            && e.contains("vehicles[1].name: \"auv\" is also vehicles[0]'s name"),
        "{e}"
    );
}

/// Flies an onboard file into `out`, whatever its exit status.
fn fly_onboard(file: &std::path::Path, out: &std::path::Path) -> std::process::Output {
    common::bin()
        .args([
            "onboard",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap()
}

/// An onboard file for a Bluefin front seat on a port nobody listens on.
const ONBOARD: &str = r#"name = "t"
[mission]
op_area = [[60.0, -80.0], [460.0, -80.0], [460.0, 80.0], [60.0, 80.0]]
prior_flow_toward_deg = 90.0
[planner]
kind = "amp"
[link]
protocol = "bluefin"
address = "127.0.0.1:9"
origin = { lat_deg = 36.18, lon_deg = -75.75 }
give_up_s = 0.5
[run]
mode = "lock_step"
"#;

#[test]
fn an_onboard_file_that_cannot_fly_leaves_the_previous_flight_whole() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = d.join("flight");
    std::fs::create_dir_all(&out).unwrap();
    let earlier = [
        ("link.log", "earlier traffic\n".repeat(1000)),
        ("run.alog", "earlier alog\n".to_string()),
        ("onboard.json", "{}".to_string()),
    ];
    for (name, text) in &earlier {
        std::fs::write(out.join(name), text).unwrap();
    }
    let cases = [
        (
            "kind = \"amp\"",
            "kind = \"lawnmower\"\nedge_margin_m = 1000.0",
            "bad.toml:7: planner.edge_margin_m: no survey lane fits",
        ),
        (
            "kind = \"amp\"",
            "kind = \"amp\"\nspeed_mps = 10.0",
            "bad.toml:7: planner.speed_mps: 10 m/s is above the vehicle's limit link.limits.max_speed_mps (2.5 m/s)",
        ),
        (
            "[460.0, 80.0], [60.0, 80.0]]",
            "[460.0, 80.0, 3.0], [60.0, 80.0]]",
            "vertex 2 has 3 coordinates",
        ),
    ];
    for (from, to, want) in cases {
        let file = d.join("bad.toml");
        std::fs::write(&file, ONBOARD.replacen(from, to, 1)).unwrap();
        for check in [true, false] {
            let mut args = vec![
                "onboard",
                file.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ];
            if check {
                args.push("--check");
            }
            let e = fails(&args);
            assert!(e.contains(want), "{to}: {e}");
        }
        for (name, text) in &earlier {
            assert_eq!(
                &std::fs::read_to_string(out.join(name)).unwrap(),
                text,
                "{name}"
            );
        }
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), 3, "no new files");
    }
}

#[test]
fn onboard_check_connects_to_nothing_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("ok.toml");
    std::fs::write(&file, ONBOARD).unwrap();
    let out = dir.path().join("never");
    let started = std::time::Instant::now();
    let o = common::run_ok(&[
        "onboard",
        file.to_str().unwrap(),
        "--check",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(started.elapsed().as_secs_f64() < 5.0);
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(said.contains("ok.toml: ok: planner amp"), "{said}");
    assert!(!out.exists());
}

#[test]
fn onboard_warns_of_planner_keys_without_effect_before_it_flies() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("inert.toml");
    let inert = "kind = \"amp\"\nfix_smoothing = false\nfix_wait_s = 300.0";
    std::fs::write(&file, ONBOARD.replacen("kind = \"amp\"", inert, 1)).unwrap();
    let check = |file: &std::path::Path| {
        let o = common::run_ok(&["onboard", file.to_str().unwrap(), "--check"]);
        (
            String::from_utf8_lossy(&o.stdout).to_string(),
            String::from_utf8_lossy(&o.stderr).to_string(),
        )
    };
    let (said, warned) = check(&file);
    assert!(said.contains("inert.toml: ok: planner amp"), "{said}");
    assert!(
        warned.contains("warning: ")
            && warned.contains(
                "inert.toml:8: planner.fix_wait_s: has no effect with fix_smoothing = false"
            ),
        "{warned}"
    );
    // Nothing said of a file whose keys all act.
    let plain = dir.path().join("plain.toml");
    std::fs::write(&plain, ONBOARD).unwrap();
    let (_, warned) = check(&plain);
    assert!(!warned.contains("warning"), "{warned}");
    // Flying warns too, before it connects (here to a port nobody listens on: the link gives
    // up after half a second). A flight that never connected writes its files and fails.
    let out = dir.path().join("flight");
    let o = fly_onboard(&file, &out);
    let warned = String::from_utf8_lossy(&o.stderr);
    assert!(
        warned.contains("planner.fix_wait_s: has no effect"),
        "{warned}"
    );
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(
        said.contains("inert.toml: the link gave up (never connected to the front seat"),
        "{said}"
    );
    assert_eq!(o.status.code(), Some(1), "{warned}");
    assert!(
        warned.contains("inert.toml: never connected to the front seat in link.give_up_s (0.5 s)"),
        "{warned}"
    );
    for f in ["link.log", "onboard.json", "run.alog", "snapshots.jsonl.gz"] {
        assert!(out.join(f).is_file(), "{f} not written");
    }
}

#[test]
fn an_onboard_flight_whose_front_seat_never_sends_navigation_fails_after_writing_its_files() {
    // A peer that accepts the connection and says nothing (a front seat that is up but not
    // sending): the link counts the connection, drops it after link.silence_timeout_s, and the
    // flight, having heard no navigation, gives up after link.give_up_s.
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    let held = std::thread::spawn(move || {
        let mut conns = Vec::new();
        listener.set_nonblocking(true).unwrap();
        let until = std::time::Instant::now() + std::time::Duration::from_secs(20);
        while std::time::Instant::now() < until && conns.len() < 50 {
            match listener.accept() {
                Ok((c, _)) => conns.push(c),
                Err(_) => std::thread::sleep(std::time::Duration::from_millis(10)),
            }
        }
        conns.len()
    });
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("silent.toml");
    std::fs::write(
        &file,
        ONBOARD
            .replacen("127.0.0.1:9", &format!("127.0.0.1:{port}"), 1)
            .replacen(
                "give_up_s = 0.5",
                "give_up_s = 1.0\nsilence_timeout_s = 0.5",
                1,
            ),
    )
    .unwrap();
    let out = dir.path().join("flight");
    let o = fly_onboard(&file, &out);
    let (said, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert_eq!(o.status.code(), Some(1), "{said}{err}");
    assert!(
        said.contains("the link gave up (connected, but no navigation record came"),
        "{said}"
    );
    assert!(
        err.contains("silent.toml: connected, but no navigation record came from the front seat"),
        "{err}"
    );
    assert!(out.join("onboard.json").is_file());
    drop(held);
}

#[test]
fn family_out_at_a_file_says_so_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("plain");
    std::fs::write(&file, "x").unwrap();
    let fam = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/families/coastal.family.toml"
    );
    let e = fails(&[
        "family",
        fam,
        "--sample",
        "2",
        "--out",
        file.to_str().unwrap(),
    ]);
    assert!(e.contains("plain: is a file, not a directory"), "{e}");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
}

#[test]
fn run_and_campaign_out_at_a_file_say_so_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("plain");
    std::fs::write(&file, "x").unwrap();
    let out = file.to_str().unwrap();
    let campaign = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/campaigns/amp-vs-lawnmower.toml"
    );
    for args in [
        vec!["run", "--preset", "demo", "--out", out],
        vec!["campaign", campaign, "--seeds", "1", "--out", out],
    ] {
        let e = fails(&args);
        assert_eq!(
            e,
            format!(
                "error: --out {out}: is a file, not a directory; give a directory (created if \
                 needed)\n"
            ),
            "{args:?}"
        );
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
    }
}

#[test]
fn a_start_inside_an_obstacle_is_refused_by_check() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("walled.toml");
    let wall = "[[obstacles]]\nname = \"pier\"\nvertices = [[460.0, -70.0], [480.0, -70.0], [480.0, -50.0], [460.0, -50.0]]\n\n[[vehicles]]";
    let text = demo().replacen("[[vehicles]]", wall, 1);
    std::fs::write(&file, &text).unwrap();
    let e = fails(&["check", file.to_str().unwrap()]);
    let line = text.lines().position(|l| l == "x_m = 470.0").unwrap() + 1;
    assert!(
        e.contains(&format!(
            "walled.toml:{line}: vehicles[0].x_m: start (470, -60) is inside obstacles[0] ('pier')"
        )),
        "{e}"
    );
}

#[test]
fn a_plume_run_whose_flow_diverges_names_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("wild.toml");
    let text = plumetrace_scenario::find_preset("plume-demo")
        .unwrap()
        .toml
        .replacen("noise_gain = 0.3", "noise_gain = 100.0", 1);
    std::fs::write(&file, &text).unwrap();
    let out = dir.path().join("o");
    let e = fails(&[
        "run",
        file.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let line = text.lines().position(|l| l == "[flow.farrell]").unwrap() + 1;
    assert!(
        e.contains(&format!("wild.toml:{line}: step "))
            && e.contains("flow.farrell: the field diverged"),
        "{e}"
    );
}
