//! Bad input as a new user would give it: one regression test per class of problem once found
//! (aborts on huge sizes, hangs, non-finite outputs, lost results, errors that did not say
//! where, missions `check` called fine). Each runs the built binary.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

mod common;
use common::{bin, demo, run_ok};

/// `demo` with `from` replaced by `to` (which must match).
fn demo_with(from: &str, to: &str) -> String {
    let d = demo();
    assert!(d.contains(from), "{from}");
    d.replacen(from, to, 1)
}

/// Runs `plumetrace ARGS`, expects failure (status 1; 2 for a bad flag, as the argument parser
/// reports it), and returns standard error.
fn fails(args: &[&str]) -> String {
    let out = bin().args(args).output().unwrap();
    assert!(
        matches!(out.status.code(), Some(1 | 2)),
        "plumetrace {args:?} did not fail: {:?} {}",
        out.status,
        String::from_utf8_lossy(&out.stdout)
    );
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// `check` on `text` written as `dir/name`: the error, which must name the file and `key`.
fn check_error(dir: &Path, name: &str, text: &str, key: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    let e = fails(&["check", p.to_str().unwrap()]);
    assert!(
        e.contains(name) && e.contains(key),
        "the error does not name {name} and {key}: {e}"
    );
    e
}

#[test]
fn unbounded_sizes_are_refused_before_anything_is_allocated() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    check_error(
        d,
        "far.toml",
        &demo_with(
            "time_limit_s = 2400.0",
            "time_limit_s = 2400.0\nsubregions = [[[60.0, -80.0], [1e18, -80.0], [60.0, 80.0]]]",
        ),
        "mission.subregions[0][1][0]",
    );
    check_error(
        d,
        "filaments.toml",
        &demo_with(
            "init_radius_m = 0.1",
            "init_radius_m = 0.1\nmax_filaments = 4611686018427387904\ninitial_filaments = 1000000",
        ),
        "plume.max_filaments",
    );
    // Campaigns: seeds and sweeps are bounded before the run list is made.
    let c = d.join("c.toml");
    std::fs::write(
        &c,
        "name = \"c\"\nseed = 1\nseeds = 2\nscenarios = [\"demo\"]\n",
    )
    .unwrap();
    let e = fails(&[
        "campaign",
        c.to_str().unwrap(),
        "--out",
        d.join("o").to_str().unwrap(),
        "--seeds",
        "100000000",
    ]);
    assert!(e.contains("--seeds") && e.contains("1 to 1000000"), "{e}");
    let keys = [
        "beta_deg",
        "lambda_s",
        "l_u_m",
        "l_c_m",
        "k_deg_per_m",
        "r_m",
        "n_re",
    ];
    let mut sweep = String::from("[sweep]\n");
    for k in keys {
        let values: Vec<String> = (1..=12).map(|v| format!("{v}.0")).collect();
        let values = if k == "n_re" {
            (1..=12).map(|v| v.to_string()).collect()
        } else {
            values
        };
        sweep.push_str(&format!("{k} = [{}]\n", values.join(", ")));
    }
    std::fs::write(
        &c,
        format!("name = \"c\"\nseed = 1\nseeds = 2\nscenarios = [\"demo\"]\n{sweep}"),
    )
    .unwrap();
    let e = fails(&[
        "campaign",
        c.to_str().unwrap(),
        "--out",
        d.join("o").to_str().unwrap(),
    ]);
    assert!(
        e.contains("c.toml") && e.contains("sweep") && e.contains("35831808 sweep points"),
        "{e}"
    );
}

#[test]
fn what_would_never_end_is_refused_by_check() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    check_error(
        d,
        "fix.toml",
        &demo_with(
            "heading_deg = 270.0",
            "heading_deg = 270.0\n[vehicles.nav]\nfix_interval_s = 1e-12",
        ),
        "vehicles[0].nav.fix_interval_s",
    );
    for (from, to, key) in [
        (
            "time_limit_s = 2400.0",
            "time_limit_s = 1e300",
            "mission.time_limit_s",
        ),
        ("spinup_s = 3500.0", "spinup_s = 1e300", "mission.spinup_s"),
        (
            "spinup_dt_s = 30.0",
            "spinup_dt_s = 1e-300",
            "mission.spinup_s",
        ),
        (
            "time_limit_s = 2400.0",
            "time_limit_s = 2e7",
            "mission.time_limit_s",
        ),
        // A flow grid so fine and diffusive that its own stable step is microseconds: the
        // flow's sub-steps would never end.
        (
            "nx = 21\nny = 13\nnoise_gain = 0.23",
            "nx = 1000\nny = 1000\nnoise_gain = 0.23\ndiffusivity_x_m2ps = 1e4\ndiffusivity_y_m2ps = 1e4",
            "flow.farrell",
        ),
    ] {
        check_error(d, "long.toml", &demo_with(from, to), key);
    }
    let plume = plumetrace_scenario::find_preset("plume-demo").unwrap().toml;
    let e = check_error(
        d,
        "tiny.toml",
        &plume.replacen("dt_s = 0.1", "dt_s = 1e-9", 1),
        "sim.duration_s",
    );
    assert!(e.contains("steps"), "{e}");
    let c = d.join("c.toml");
    std::fs::write(
        &c,
        "name = \"c\"\nseed = 1\nseeds = 1\nscenarios = [\"demo\"]\n",
    )
    .unwrap();
    let e = fails(&[
        "campaign",
        c.to_str().unwrap(),
        "--out",
        d.join("o").to_str().unwrap(),
        "--jobs",
        "5000",
    ]);
    assert!(e.contains("--jobs") && e.contains("1 to 256"), "{e}");
    // A FIFO would block a reader for ever: refused without opening it.
    let fifo = d.join("pipe.toml");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if made.is_ok_and(|s| s.success()) {
        let e = fails(&["check", fifo.to_str().unwrap()]);
        assert!(
            e.contains("pipe.toml") && e.contains("not a regular file"),
            "{e}"
        );
    }
}

#[test]
fn values_that_would_overflow_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    check_error(
        d,
        "mass.toml",
        &demo_with("mass_rate_per_s = 16.0", "mass_rate_per_s = 1e306"),
        "sources[0].mass_rate_per_s",
    );
    // A gridded flow of 1e300 m/s: refused with the file's line.
    std::fs::write(
        d.join("flow.csv"),
        "x_m,y_m,u_mps,v_mps\n0,0,0.1,0\n520,0,0.1,0\n0,150,1e300,0\n520,150,0.1,0\n0,-150,0.1,0\n520,-150,0.1,0\n",
    )
    .unwrap();
    let text = demo()
        .replacen(
            "model = \"farrell\"",
            "model = \"gridded\"\nfile = \"flow.csv\"",
            1,
        )
        .replacen("[flow.mean]\nspeed_mps = 0.15\ntoward_deg = 90.0\n", "", 1);
    let start = text.find("[flow.farrell]").unwrap();
    let end = text.find("[plume]").unwrap();
    let text = format!("{}{}", &text[..start], &text[end..]);
    let e = check_error(d, "grid.toml", &text, "flow.file");
    assert!(e.contains("line 4") && e.contains("1e300"), "{e}");
}

/// A campaign of one short demo mission per seed.
fn short_campaign(dir: &Path, name: &str, extra: &str) -> PathBuf {
    let p = dir.join(format!("{name}.toml"));
    std::fs::write(
        &p,
        format!(
            "name = \"{name}\"\nseed = 5\nseeds = 2\nscenarios = [\"demo\"]\n{extra}\
             [[configs]]\nname = \"amp\"\n[configs.set]\nmapping = false\n\
             \"mission.time_limit_s\" = 60.0\n\"mission.spinup_s\" = 60.0\n"
        ),
    )
    .unwrap();
    p
}

#[test]
fn results_are_never_written_over() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let c = short_campaign(d, "one", "");
    let other = short_campaign(d, "two", "success_radius_m = 20.0\n");
    let out = |n: &str| d.join(n).to_str().unwrap().to_string();
    run_ok(&[
        "campaign",
        c.to_str().unwrap(),
        "--out",
        &out("s1"),
        "--shard",
        "1/2",
    ]);
    run_ok(&[
        "campaign",
        c.to_str().unwrap(),
        "--out",
        &out("s2"),
        "--shard",
        "2/2",
    ]);
    run_ok(&["campaign", other.to_str().unwrap(), "--out", &out("theirs")]);
    let theirs = std::fs::read(d.join("theirs/runs.csv")).unwrap();
    // Merging into another campaign's directory is refused and leaves it as it was.
    let e = fails(&["merge", &out("s1"), &out("s2"), "--out", &out("theirs")]);
    assert!(e.contains("would be lost"), "{e}");
    assert_eq!(std::fs::read(d.join("theirs/runs.csv")).unwrap(), theirs);
    // Merging one shard into a directory that already holds every run keeps them all.
    let said = run_ok(&["merge", &out("s1"), &out("s2"), "--out", &out("full")]).stdout;
    assert!(
        String::from_utf8_lossy(&said).starts_with("merged 2 directories: "),
        "{}",
        String::from_utf8_lossy(&said)
    );
    let all = std::fs::read(d.join("full/runs.csv")).unwrap();
    let said = run_ok(&["merge", &out("s1"), "--out", &out("full")]).stdout;
    assert!(
        String::from_utf8_lossy(&said).starts_with("merged 1 directory: "),
        "{}",
        String::from_utf8_lossy(&said)
    );
    assert_eq!(
        std::fs::read(d.join("full/runs.csv")).unwrap(),
        all,
        "no run lost"
    );
    // A campaign into a directory holding the user's own files is refused.
    std::fs::create_dir_all(d.join("mine")).unwrap();
    std::fs::write(d.join("mine/summary.md"), "my notes").unwrap();
    let e = fails(&["campaign", c.to_str().unwrap(), "--out", &out("mine")]);
    assert!(e.contains("not a campaign directory"), "{e}");
    assert_eq!(
        std::fs::read_to_string(d.join("mine/summary.md")).unwrap(),
        "my notes"
    );
    let e = fails(&["merge", &out("s1"), "--out", &out("mine")]);
    assert!(e.contains("not a campaign directory"), "{e}");
    // A run never writes over its own scenario file.
    std::fs::create_dir_all(d.join("run")).unwrap();
    let own = d.join("run/summary.json");
    std::fs::write(&own, demo()).unwrap();
    let e = fails(&["run", own.to_str().unwrap(), "--out", &out("run")]);
    assert!(e.contains("over this input file"), "{e}");
    assert_eq!(std::fs::read_to_string(&own).unwrap(), demo());
    // Duplicate sweep values would plan runs thrown away: refused.
    let dup = short_campaign(d, "dup", "[sweep]\nbeta_deg = [10.0, 20.0, 10.0]\n");
    let e = fails(&["campaign", dup.to_str().unwrap(), "--out", &out("dup")]);
    assert!(
        e.contains("sweep.beta_deg[2]") && e.contains("listed twice"),
        "{e}"
    );
}

#[test]
fn long_and_clashing_names_make_distinct_short_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // The longest name a config may have (200 characters): still a short file name.
    let long = "n".repeat(200);
    let p = d.join("names.toml");
    std::fs::write(
        &p,
        format!(
            "name = \"names\"\nseed = 5\nseeds = 1\nscenarios = [\"demo\"]\n\
             [[configs]]\nname = \"a/b\"\n[configs.set]\n\"mission.time_limit_s\" = 30.0\n\"mission.spinup_s\" = 30.0\n\
             [[configs]]\nname = \"a_b\"\n[configs.set]\n\"mission.time_limit_s\" = 30.0\n\"mission.spinup_s\" = 30.0\n\
             [[configs]]\nname = \"{long}\"\n[configs.set]\n\"mission.time_limit_s\" = 30.0\n\"mission.spinup_s\" = 30.0\n"
        ),
    )
    .unwrap();
    let out = d.join("o");
    run_ok(&[
        "campaign",
        p.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--jobs",
        "2",
    ]);
    let runs = std::fs::read_to_string(out.join("runs.csv")).unwrap();
    assert!(!runs.contains(",error,"), "{runs}");
    let examples: Vec<String> = std::fs::read_dir(out.join("examples"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    // An example and its replay page for each of the 3 groups.
    assert_eq!(examples.len(), 6, "{examples:?}");
    assert!(examples.iter().all(|e| e.len() < 150), "{examples:?}");
}

#[test]
fn errors_say_where() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Invalid UTF-8: byte offset, line and column.
    let p = d.join("bytes.toml");
    let mut bytes = demo().into_bytes();
    bytes.splice(10..10, [0xff, 0xfe]);
    std::fs::write(&p, bytes).unwrap();
    let e = fails(&["check", p.to_str().unwrap()]);
    assert!(
        e.contains("bytes.toml") && e.contains("byte 10 (line 1, column 11)"),
        "{e}"
    );
    // A bad y_m is reported on y_m; tiny numbers are short.
    let e = check_error(
        d,
        "y.toml",
        &demo_with("y_m = -60.0", "y_m = -600.0"),
        "vehicles[0].y_m",
    );
    assert!(e.contains("outside the domain"), "{e}");
    let e = check_error(
        d,
        "tiny.toml",
        &demo_with("speed_mps = 0.15", "speed_mps = -1e-300"),
        "flow.mean.speed_mps",
    );
    assert!(e.contains("-1e-300") && e.len() < 400, "{e}");
    // A vertex with three numbers is an error, not silently cut.
    check_error(
        d,
        "vertex.toml",
        &demo_with("[[60.0, -80.0], [460.0", "[[60.0, -80.0, 5.0], [460.0"),
        "mission.op_area[0]",
    );
    // A date where a table or a number belongs: said as such.
    let e = check_error(
        d,
        "date.toml",
        &demo_with("time_limit_s = 2400.0", "time_limit_s = 1979-05-27"),
        "mission.time_limit_s",
    );
    assert!(e.contains("date/time") && !e.contains("$__toml"), "{e}");
    // A self-intersecting, asymmetric op-area.
    let e = check_error(
        d,
        "bowtie.toml",
        &demo_with(
            "op_area = [[60.0, -80.0], [460.0, -80.0], [460.0, 80.0], [60.0, 80.0]]",
            "op_area = [[60.0, -80.0], [300.0, 70.0], [460.0, -80.0], [60.0, 20.0]]",
        ),
        "mission.op_area",
    );
    assert!(e.contains("crosses itself"), "{e}");
    // A negative seed: a message about the flag, not a hint to turn it into a file name.
    let e = fails(&["run", "--preset", "demo", "--seed", "-1"]);
    assert!(
        e.contains("--seed") && e.contains("whole number from 0") && !e.contains("'-- -1'"),
        "{e}"
    );
}

#[test]
fn check_warns_about_missions_that_cannot_succeed() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let text = demo_with("x_m = 100.0\ny_m = 0.0", "x_m = 30.0\ny_m = 0.0")
        .replacen("x_m = 470.0\ny_m = -60.0", "x_m = 510.0\ny_m = -60.0", 1)
        .replacen(
            "heading_deg = 270.0",
            "heading_deg = 270.0\nplanner = \"hot\"",
            1,
        )
        .replacen("prior_flow_toward_deg = 90.0\n", "", 1);
    let (a, b) = (
        text.find("[planner]").unwrap(),
        text.find("[output]").unwrap_or(text.len()),
    );
    let text = format!(
        "{}[planners.hot]\nkind = \"amp\"\nthreshold_v = 6.0\n\n{}",
        &text[..a],
        &text[b..]
    );
    let p = d.join("warn.toml");
    std::fs::write(&p, text).unwrap();
    let out = run_ok(&["check", p.to_str().unwrap()]);
    let w = String::from_utf8_lossy(&out.stderr);
    for want in [
        "sources[0] at (30, 0) is outside the op-area",
        "at or above the sensor's full scale",
        "starts 50 m outside the op-area",
        "mission.prior_flow_toward_deg is not given",
    ] {
        assert!(w.contains(want), "no warning '{want}' in:\n{w}");
    }
    assert!(
        w.lines()
            .all(|l| l.starts_with("warning: ") && l.contains("warn.toml")),
        "{w}"
    );
}

#[test]
fn problems_the_fuzzer_found_stay_fixed() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A date under an empty key: the key is written quoted, so the path still says where.
    let e = check_error(
        d,
        "empty.toml",
        &demo_with("[mission]", "[output]\n\"\" = 1979-05-27\n[mission]"),
        "output.\"\"",
    );
    assert!(e.contains("date/time"), "{e}");
    // A steady plume with a vanishing diffusivity once gave NaN concentrations after one step.
    let fresh = plumetrace_scenario::find_preset("freshwater").unwrap().toml;
    let (from, _) = fresh
        .lines()
        .find_map(|l| {
            l.strip_prefix("horizontal_diffusivity_m2ps = ")
                .map(|v| (l, v))
        })
        .unwrap();
    check_error(
        d,
        "fresh.toml",
        &fresh.replacen(from, "horizontal_diffusivity_m2ps = 5e-324", 1),
        "plume.horizontal_diffusivity_m2ps",
    );
    // A campaign naming a plume-only scenario: the error names the scenario's entry.
    let c = d.join("plume.toml");
    std::fs::write(
        &c,
        "name = \"c\"\nseed = 1\nseeds = 1\nscenarios = [\"demo\", \"pompy\"]\n",
    )
    .unwrap();
    let e = fails(&[
        "campaign",
        c.to_str().unwrap(),
        "--out",
        d.join("o").to_str().unwrap(),
    ]);
    assert!(
        e.contains("plume.toml") && e.contains("scenarios[1]") && e.contains("no [mission]"),
        "{e}"
    );
    // A configuration name over two lines: refused at its index.
    std::fs::write(
        &c,
        "name = \"c\"\nseed = 1\nseeds = 1\nscenarios = [\"demo\"]\n[[configs]]\nname = \"a\\nb\"\n",
    )
    .unwrap();
    let e = fails(&[
        "campaign",
        c.to_str().unwrap(),
        "--out",
        d.join("o").to_str().unwrap(),
    ]);
    assert!(
        e.contains("configs[0].name") && e.contains("one line"),
        "{e}"
    );
    // An empty key in a sweep: its path is written quoted.
    std::fs::write(
        &c,
        "name = \"c\"\nseed = 1\nseeds = 1\nscenarios = [\"demo\"]\n[sweep]\n\"\" = \"nope\"\n",
    )
    .unwrap();
    let e = fails(&[
        "campaign",
        c.to_str().unwrap(),
        "--out",
        d.join("o").to_str().unwrap(),
    ]);
    assert!(e.contains("sweep.\"\"") && e.contains("array"), "{e}");
}
