//! Commands and errors as a new user meets them: `--set` and `--planner` on `run` and `check`,
//! `check --preset`, `presets --show` and `--markdown`, "did you mean" for keys, presets,
//! planners and commands, errors at the line of the key as written, and warnings for keys with
//! no effect. Each runs the built binary and reads what it prints.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

mod common;
use common::{bin, demo, run_ok};

/// The 1-based line of the first line of `text` that starts with `start`.
fn line(text: &str, start: &str) -> usize {
    text.lines().position(|l| l.starts_with(start)).unwrap() + 1
}

/// Runs `plumetrace ARGS` in `dir`: (status, stdout, stderr).
fn plumetrace(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = bin().current_dir(dir).args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

/// `check --preset demo --set SET` in `dir`.
fn check_demo_set(dir: &Path, set: &str) -> (i32, String, String) {
    plumetrace(dir, &["check", "--preset", "demo", "--set", set])
}

/// `check FILE` of `text` written as `name` in `dir`: its standard error (and whether it passed).
fn check(dir: &Path, name: &str, text: &str) -> (bool, String) {
    std::fs::write(dir.join(name), text).unwrap();
    let (status, _, err) = plumetrace(dir, &["check", name]);
    (status == 0, err)
}

#[test]
fn a_planner_key_typo_names_the_file_line_key_and_the_key_meant() {
    let dir = tempfile::tempdir().unwrap();
    let text = demo().replace("mapping_lines = 3", "maping_lines = 3");
    let (ok, err) = check(dir.path(), "typo.toml", &text);
    assert!(!ok);
    assert_eq!(
        err,
        format!(
            "error: typo.toml:{}: planner.maping_lines: unknown field `maping_lines`; did you \
             mean `mapping_lines`? (`plumetrace planners` lists every key)\n",
            line(&text, "maping_lines")
        )
    );
    // The same in a named planner table.
    let named = demo()
        .replace("[planner]", "[planners.tracer]")
        .replace(
            "heading_deg = 270.0",
            "heading_deg = 270.0\nplanner = \"tracer\"",
        )
        .replace("mapping_lines = 3", "maping_lines = 3");
    let (_, err) = check(dir.path(), "named.toml", &named);
    assert!(
        err.starts_with(&format!(
            "error: named.toml:{}: planners.tracer.maping_lines: unknown field `maping_lines`; \
             did you mean `mapping_lines`?",
            line(&named, "maping_lines")
        )),
        "{err}"
    );
}

#[test]
fn the_kind_is_named_as_written_with_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let text = demo().replace("kind = \"amp\"", "strategy = \"ampp\"");
    let (_, err) = check(dir.path(), "kind.toml", &text);
    assert!(
        err.starts_with(&format!(
            "error: kind.toml:{}: planner.strategy: unknown planner 'ampp'; did you mean 'amp'? \
             (known: ",
            line(&text, "strategy")
        )),
        "{err}"
    );
    // `strategy` is read in a named table too (it once said "kind: missing").
    let named = demo()
        .replace("[planner]", "[planners.tracer]")
        .replace(
            "heading_deg = 270.0",
            "heading_deg = 270.0\nplanner = \"tracer\"",
        )
        .replace("kind = \"amp\"", "strategy = \"amp\"");
    assert_eq!(
        check(dir.path(), "named.toml", &named),
        (true, String::new())
    );
}

#[test]
fn an_unknown_scenario_key_gets_its_line_and_the_nearest_key() {
    let dir = tempfile::tempdir().unwrap();
    let text = demo().replace("dt_s = 0.1", "dtt_s = 0.1");
    let (_, err) = check(dir.path(), "sim.toml", &text);
    assert_eq!(
        err,
        format!(
            "error: sim.toml:{}: sim.dtt_s: unknown field `dtt_s`; did you mean `dt_s`?\n",
            line(&text, "dtt_s")
        )
    );
}

#[test]
fn a_missing_file_named_like_a_preset_suggests_the_preset() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["run", "demo"][..],
        &["check", "demo"],
        &["check", "demo.toml"],
    ] {
        let (status, _, err) = plumetrace(dir.path(), args);
        assert_eq!(status, 1);
        assert!(
            err.ends_with(
                ": no such file; did you mean the built-in scenario `--preset demo`? \
                 (`plumetrace presets` lists them)\n"
            ),
            "{args:?}: {err}"
        );
    }
    let (_, _, err) = plumetrace(dir.path(), &["run", "--preset", "dmeo"]);
    assert!(
        err.starts_with("error: no preset named 'dmeo'; did you mean 'demo'? (known: demo, "),
        "{err}"
    );
    let (_, _, err) = plumetrace(dir.path(), &["presets", "--show", "dmeo"]);
    assert!(err.contains("did you mean 'demo'?"), "{err}");
}

#[test]
fn commands_and_flags_get_the_parsers_suggestion() {
    let dir = tempfile::tempdir().unwrap();
    let (status, _, err) = plumetrace(dir.path(), &["chek", "x.toml"]);
    assert_eq!(status, 2);
    assert!(
        err.contains("a similar subcommand exists: 'check'"),
        "{err}"
    );
    let (_, _, err) = plumetrace(dir.path(), &["run", "--prest", "demo"]);
    assert!(
        err.contains("a similar argument exists: '--preset'"),
        "{err}"
    );
}

#[test]
fn check_takes_a_preset_and_every_preset_is_quiet() {
    let dir = tempfile::tempdir().unwrap();
    for p in plumetrace_scenario::PRESETS {
        let (status, out, err) = plumetrace(dir.path(), &["check", "--preset", p.name]);
        assert_eq!(status, 0, "{}: {err}", p.name);
        assert!(
            out.starts_with(&format!("preset '{}': ok (", p.name)),
            "{out}"
        );
        assert!(!err.contains("warning: preset"), "{}: {err}", p.name);
        // presets --show prints the file the preset is.
        let (_, shown, _) = plumetrace(dir.path(), &["presets", "--show", p.name]);
        assert_eq!(shown, p.toml);
    }
}

#[test]
fn examples_are_quiet() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/plumes");
    for entry in std::fs::read_dir(root).unwrap() {
        let path = entry.unwrap().path();
        let (status, _, err) = plumetrace(Path::new("."), &["check", path.to_str().unwrap()]);
        assert_eq!(status, 0, "{}: {err}", path.display());
        assert!(!err.contains("warning"), "{}: {err}", path.display());
    }
}

#[test]
fn set_and_planner_change_the_scenario_as_a_campaign_does() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (status, out, err) = plumetrace(
        d,
        &[
            "check",
            "--preset",
            "demo",
            "--planner",
            "moth",
            "--set",
            "mission.time_limit_s=600",
        ],
    );
    assert_eq!(status, 0, "{err}");
    assert!(
        out.contains("mission of up to 600 s") && out.contains("auv flies moth (planner)"),
        "{out}"
    );
    // The file's duration, left behind by a time limit set here, is no news.
    assert_eq!(err, "");
    let cases: &[(&[&str], &str)] = &[
        (
            &["--planner", "mothh"],
            "error: --planner mothh: no such planner; did you mean 'moth'? (known: amp, ",
        ),
        (
            &["--set", "beta_deg=-5"],
            "error: preset 'demo': planner.beta_deg: must be >= 0 and <= 90 deg, got -5 deg",
        ),
        (
            &["--set", "beta_deg"],
            "error: --set \"beta_deg\": expected KEY=VALUE",
        ),
        (
            &["--set", "kind=moth"],
            "error: --set \"kind=moth\": the value is not TOML (a string is quoted: \
             kind='\"moth\"')\n",
        ),
        (
            &["--set", "sources.3.x_m=1"],
            "error: --set \"sources.3.x_m=1\": 'sources.3': index 3 is past the end: the array has 1 entry, index 0",
        ),
    ];
    for (extra, want) in cases {
        let mut args = vec!["check", "--preset", "demo"];
        args.extend_from_slice(extra);
        let (status, _, err) = plumetrace(d, &args);
        assert_eq!(status, 1, "{extra:?}");
        assert!(err.starts_with(want), "{extra:?}: {err}");
    }
    // A team of several planner tables: --planner cannot say which; refused.
    let (_, _, err) = plumetrace(
        d,
        &[
            "check",
            "--preset",
            "soares-freshwater",
            "--planner",
            "moth",
        ],
    );
    assert!(
        err.starts_with(
            "error: --planner moth: the scenario has several planner tables (planners.follower, \
             planners.leader_left, planners.leader_right) and --planner replaces a scenario's \
             one planner table; change one of them with --set planners.NAME.kind='\"moth\"'"
        ),
        "{err}"
    );
    // run flies what check checked.
    let (status, _, err) = plumetrace(
        d,
        &[
            "run",
            "--preset",
            "demo",
            "--planner",
            "lawnmower",
            "--set",
            "mission.time_limit_s=60",
            "--set",
            "mission.spinup_s=60",
            "--out",
            "o",
            "--no-snapshot-log",
        ],
    );
    assert_eq!(status, 0, "{err}");
    let summary = std::fs::read_to_string(d.join("o/summary.json")).unwrap();
    assert!(summary.contains("\"lawnmower\""), "{summary}");
}

#[test]
fn keys_with_no_effect_are_warned_of_by_check_and_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let text =
        demo().replace("duration_s = 2400.0", "duration_s = 100.0") + "\n[output]\nnx = 50\n";
    std::fs::write(d.join("w.toml"), &text).unwrap();
    let want = format!(
        "warning: w.toml:{}: sim.duration_s: 100 s has no effect on a mission, which runs until \
         its vehicles are done or mission.time_limit_s (2400 s); set that instead (or make the \
         two equal)\nwarning: w.toml:{}: output.nx: has no effect on a mission: the [output] grid \
         and time average are written by plume runs only (a scenario without [mission]); remove \
         it\n",
        line(&text, "duration_s"),
        line(&text, "nx = 50"),
    );
    let (status, _, err) = plumetrace(d, &["check", "w.toml"]);
    assert_eq!((status, err.as_str()), (0, want.as_str()));
    let (status, _, err) = plumetrace(
        d,
        &[
            "run",
            "w.toml",
            "--set",
            "mission.spinup_s=10",
            "--out",
            "o",
            "--no-snapshot-log",
        ],
    );
    assert_eq!(status, 0, "{err}");
    assert!(err.starts_with(&want), "{err}");
}

#[test]
fn planner_keys_with_no_effect_at_the_tables_values_are_warned_of() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let with = |keys: &str| {
        let text = demo().replacen("kind = \"amp\"", &format!("kind = \"amp\"\n{keys}"), 1);
        assert_ne!(text, demo(), "the demo has a [planner] kind = \"amp\" line");
        std::fs::write(d.join("k.toml"), &text).unwrap();
        plumetrace(d, &["check", "k.toml"])
    };
    let (status, _, err) = with("fix_smoothing = false\nfix_wait_s = 300.0");
    assert_eq!(status, 0, "{err}");
    assert!(
        err.contains(
            "planner.fix_wait_s: has no effect with fix_smoothing = false: the wait for the next \
             fix is part of moving lost points with it"
        ),
        "{err}"
    );
    let (_, _, err) = with("declaration_fix_frames = 1\ndeclaration_frame_wait_s = 600.0");
    assert!(
        err.contains(
            "planner.declaration_frame_wait_s: has no effect with declaration_fix_frames = 1"
        ),
        "{err}"
    );
    let (_, _, err) = with("declaration_frame_wait_s = 600.0");
    assert!(!err.contains("declaration_frame_wait_s"), "{err}");
    let (_, _, err) =
        with("map_declaration = \"instead\"\nmap_dilution_m = 20.0\nmap_dilution_s = 30.0");
    assert!(
        err.contains("planner.map_dilution_s: has no effect while map_dilution_m (20 m)"),
        "{err}"
    );
    // A ratio that follows the current replaces the fixed one; neither acts without a spread.
    let (_, _, err) =
        with("map_declaration = \"instead\"\nmap_along_speed_mps = 0.3\nmap_along_ratio = 0.5");
    assert!(
        err.contains("planner.map_along_ratio: has no effect while map_along_speed_mps (0.3 m/s)"),
        "{err}"
    );
    let (_, _, err) = with(
        "map_declaration = \"instead\"\nmap_diffusivity_m2ps = 0.0\nmap_along_speed_mps = 0.3",
    );
    assert!(
        err.contains("planner.map_along_speed_mps: has no effect while map_diffusivity_m2ps is 0"),
        "{err}"
    );
    // Without a map declaration (the default) the AMP keeps no map: every map key given idles.
    let (status, _, err) = with("map_mass = 0.5\nmap_along_ratio = 0.5");
    assert_eq!(status, 0, "{err}");
    for key in ["map_mass", "map_along_ratio"] {
        assert!(
            err.contains(&format!(
                "planner.{key}: has no effect with map_declaration = \"off\" (the default)"
            )),
            "{key}: {err}"
        );
    }
    // Given where they act (the AMP's map dilutes after 30 m unless map_dilution_m = 0), or
    // not given: no warning.
    let (status, _, err) = with(
        "fix_smoothing = true\nfix_wait_s = 300.0\nmap_declaration = \"also\"\nmap_dilution_m = 0.0\nmap_dilution_s = 30.0",
    );
    assert_eq!((status, err.contains("has no effect")), (0, false), "{err}");
    let (_, _, err) = with("fix_smoothing = false");
    assert!(!err.contains("has no effect"), "{err}");
}

/// The snapshot log of a 30 s demo run written under `dir`.
fn short_demo_log(dir: &Path) -> std::path::PathBuf {
    run_ok(&[
        "run",
        "--preset",
        "demo",
        "--set",
        "mission.time_limit_s=30",
        "--set",
        "mission.spinup_s=10",
        "--out",
        dir.join("o").to_str().unwrap(),
    ]);
    dir.join("o/snapshots.jsonl.gz")
}

#[test]
fn replay_takes_the_planner_table_of_a_scenario_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let log = short_demo_log(d);
    std::fs::write(
        d.join("p.toml"),
        "[planner]\nkind = \"amp\"\nbeta_dg = 25.0\n",
    )
    .unwrap();
    let (status, _, err) = plumetrace(
        d,
        &["replay", log.to_str().unwrap(), "--planner-file", "p.toml"],
    );
    assert_eq!(status, 1);
    assert_eq!(
        err,
        "error: p.toml:3: planner.beta_dg: unknown field `beta_dg`; did you mean `beta_deg`? \
         (`plumetrace planners` lists every key)\n"
    );
    std::fs::write(d.join("p.toml"), demo()).unwrap();
    let (status, out, err) = plumetrace(
        d,
        &["replay", log.to_str().unwrap(), "--planner-file", "p.toml"],
    );
    assert_eq!(status, 0, "{err}");
    assert!(out.contains(", 0 differ"), "{out}");
}

#[test]
fn replay_refuses_a_vehicle_the_log_does_not_have() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let log = short_demo_log(d);
    // Another planner table: replayed for vehicle 3 of a one-vehicle log, it would replace no
    // planner and every decision would replay as logged.
    std::fs::write(d.join("p.toml"), "kind = \"lawnmower\"\n").unwrap();
    let log_arg = log.to_str().unwrap();
    let replay = |vehicle: &str| {
        plumetrace(
            d,
            &[
                "replay",
                log_arg,
                "--planner-file",
                "p.toml",
                "--vehicle",
                vehicle,
            ],
        )
    };
    let (status, out, err) = replay("3");
    assert_eq!(status, 1, "{out}");
    assert_eq!(
        err,
        format!(
            "error: --vehicle 3: {} has no vehicle 3 with a planner; its vehicles with \
             planners: 0 (auv)\n",
            log.display()
        )
    );
    let (status, out, err) = replay("0");
    assert_eq!(status, 3, "another planner differs: {out}{err}");
}

#[test]
fn a_log_from_before_a_key_existed_replays_with_a_note_naming_it() {
    use std::io::BufRead;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let log = short_demo_log(d);
    let (status, out, err) = plumetrace(d, &["replay", log.to_str().unwrap()]);
    assert_eq!(status, 0, "{err}");
    assert!(!out.contains("note:"), "a log writes every key: {out}");
    // The same log as one written before the two keys existed: its planner table lacks them.
    let lines: Vec<String> = plumetrace_log::snapshot::open(&log)
        .unwrap()
        .lines()
        .map(Result::unwrap)
        .collect();
    let mut header: serde_json::Value = serde_json::from_str(&lines[0]).unwrap();
    let table = header["vehicles"][0]["planner"]
        .as_str()
        .unwrap()
        .to_string();
    let older: String = table
        .lines()
        .filter(|l| {
            !l.starts_with("declaration_fix_frames") && !l.starts_with("declaration_frame_wait_s")
        })
        .map(|l| format!("{l}\n"))
        .collect();
    assert_ne!(older, table, "the table has the keys to take out: {table}");
    header["vehicles"][0]["planner"] = serde_json::Value::String(older);
    let mut text = format!("{header}\n");
    for l in &lines[1..] {
        text.push_str(l);
        text.push('\n');
    }
    std::fs::write(d.join("old.jsonl"), text).unwrap();
    let (status, out, err) = plumetrace(d, &["replay", "old.jsonl"]);
    assert_eq!(status, 0, "{err}");
    assert!(
        out.contains(
            "note: vehicle 0 (auv)'s logged planner table has no `declaration_fix_frames`, \
             `declaration_frame_wait_s` (the log predates these keys): they replay with today's \
             defaults, which may not be how it flew; to replay it as flown, give \
             `--planner-file F --vehicle 0`"
        ),
        "{out}"
    );
}

#[test]
fn a_value_of_the_wrong_type_is_told_the_keys_bounds() {
    let dir = tempfile::tempdir().unwrap();
    let (status, _, err) = check_demo_set(dir.path(), "declaration_fix_frames=2.5");
    assert_eq!(status, 1);
    assert!(
        err.contains(
            "planner.declaration_fix_frames: invalid type: floating point `2.5`, expected a \
             whole number in 1..=10"
        ),
        "{err}"
    );
}

/// `text` with its wall time (`0.2 s of wall time`) left out, which depends on the machine.
fn without_wall_time(text: &str) -> String {
    let Some(at) = text.find(" s of wall time") else {
        return text.to_string();
    };
    let start = text[..at].rfind(' ').map_or(0, |i| i + 1);
    format!("{}W{}", &text[..start], &text[at..])
}

#[test]
fn the_guide_quotes_the_demo_s_line_as_it_flies() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let read = |p: &str| std::fs::read_to_string(root.join(p)).unwrap();
    let (status, demo, err) = plumetrace(d, &["run", "--preset", "demo", "--out", "out/demo"]);
    assert_eq!(status, 0, "{err}");
    let demo = without_wall_time(demo.trim_end());
    // The README wraps the line in its command block.
    let readme = read("README.md");
    let start = readme
        .find("\n    demo: located")
        .expect("README.md quotes the demo's line")
        + 1;
    let end = start + readme[start..].find("\n\n").unwrap();
    let quoted = readme[start..end].trim_start().replace("\n    ", " ");
    assert_eq!(without_wall_time(&quoted), demo, "README.md");
    // The commands page quotes it (with `--out out`) and the figures page its title.
    let demo_out = demo.replace("wrote out/demo", "wrote out");
    let commands = read("docs/commands.md");
    assert!(
        commands
            .lines()
            .any(|l| without_wall_time(l.trim_start()) == demo_out),
        "docs/commands.md has no line {demo_out}"
    );
    let verdict = demo
        .strip_prefix("demo: ")
        .and_then(|v| v.split(';').next())
        .unwrap();
    assert!(
        read("docs/figures.md").contains(&format!("`demo (seed 1): {verdict}`")),
        "docs/figures.md: demo (seed 1): {verdict}"
    );
}

#[test]
fn the_readme_has_the_preset_table() {
    let md = String::from_utf8(run_ok(&["presets", "--markdown"]).stdout).unwrap();
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../README.md")).unwrap();
    let start = readme
        .find("<!-- presets:start -->\n")
        .expect("README.md marks its preset table")
        + "<!-- presets:start -->\n".len();
    let end = readme.find("<!-- presets:end -->").unwrap();
    assert_eq!(
        &readme[start..end],
        md,
        "README.md's preset table is not the code's: run scripts/readme_tables.sh"
    );
    for p in plumetrace_scenario::PRESETS {
        assert!(md.contains(&format!("| `{}` | {} |", p.name, p.summary)));
    }
}

#[test]
fn a_planner_kind_changed_by_set_is_told_of_the_planner_flag() {
    let dir = tempfile::tempdir().unwrap();
    let (status, _, err) = check_demo_set(dir.path(), "planner.kind=\"moth\"");
    assert_eq!(status, 1);
    assert_eq!(
        err,
        "error: preset 'demo': planner.mapping_length_m: unknown field `mapping_length_m` \
         (`plumetrace planners` lists every key); --set planner.kind changes the planner's kind \
         but keeps the keys of the one before, which this kind does not read: `--planner KIND` \
         replaces the whole planner table\n"
    );
    let (status, _, err) = plumetrace(
        dir.path(),
        &["check", "--preset", "demo", "--planner", "moth"],
    );
    assert_eq!(status, 0, "{err}");
}

#[test]
fn a_file_of_another_kind_is_named_with_the_command_that_takes_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let copy = |from: &str, to: &str| {
        std::fs::copy(root.join(from), d.join(to)).unwrap();
    };
    copy("examples/campaigns/amp-vs-lawnmower.toml", "c.toml");
    copy("examples/families/coastal.family.toml", "f.toml");
    let (status, scenario, _) = plumetrace(d, &["presets", "--show", "demo"]);
    assert_eq!(status, 0);
    std::fs::write(d.join("s.toml"), scenario).unwrap();
    let refused = |args: &[&str], says: &str| {
        let (status, out, err) = plumetrace(d, args);
        assert_eq!((status, out.as_str()), (1, ""), "{args:?}: {err}");
        assert_eq!(err, format!("error: {says}\n"), "{args:?}");
    };
    let campaign = "c.toml: is a campaign file (it has `scenarios`), not a";
    let family = "f.toml: is a family file (it has `base`), not a";
    let scenario = "s.toml: is a scenario file (it has `sim`), not a";
    refused(
        &["run", "c.toml", "--out", "o"],
        &format!("{campaign} scenario file: run it with `plumetrace campaign c.toml --out DIR`"),
    );
    refused(
        &["run", "f.toml", "--out", "o"],
        &format!(
            "{family} scenario file: run it with `plumetrace family f.toml --sample N --out DIR`"
        ),
    );
    refused(
        &["campaign", "s.toml", "--out", "o"],
        &format!("{scenario} campaign file: run it with `plumetrace run s.toml --out DIR`"),
    );
    refused(
        &["family", "c.toml", "--sample", "1", "--out", "o"],
        &format!("{campaign} family file: run it with `plumetrace campaign c.toml --out DIR`"),
    );
    assert!(!d.join("o").exists(), "nothing was written");
    // Each file is taken by its own command.
    let (status, _, err) = plumetrace(d, &["run", "s.toml", "--out", "o"]);
    assert_eq!(status, 0, "{err}");
}

#[test]
fn check_takes_campaign_and_family_files_too() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let family = root.join("examples/families/faults.family.toml");
    let family_text = std::fs::read_to_string(&family).unwrap();
    // Every example campaign and family checks, and says how to run it.
    let mut checked = 0;
    for sub in ["examples/campaigns", "examples/families"] {
        for entry in std::fs::read_dir(root.join(sub)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "toml") {
                continue;
            }
            let (status, out, err) = plumetrace(dir.path(), &["check", path.to_str().unwrap()]);
            assert_eq!(status, 0, "{}: {err}", path.display());
            let says = if sub.ends_with("families") {
                ": ok (family '"
            } else {
                ": ok (campaign '"
            };
            assert!(out.contains(says), "{}: {out}", path.display());
            checked += 1;
        }
    }
    assert!(checked > 30, "{checked}");
    let (_, out, _) = plumetrace(
        dir.path(),
        &[
            "check",
            root.join("examples/campaigns/amp-fix-smoothing.toml")
                .to_str()
                .unwrap(),
        ],
    );
    assert!(
        out.contains(
            "ok (campaign 'amp-fix-smoothing': 33 groups of 200 seeds, 6600 runs); run it with \
             `plumetrace campaign "
        ),
        "{out}"
    );
    let (_, out, _) = plumetrace(dir.path(), &["check", family.to_str().unwrap()]);
    assert!(
        out.contains("ok (family 'faults'; the first 8 sites at seed 1 build)"),
        "{out}"
    );
    // A benchmark's test-seed campaign is told how it runs.
    let bench = root.join("benchmarks/campaigns/amp-unbiased-faults.toml");
    let (status, out, _) = plumetrace(dir.path(), &["check", bench.to_str().unwrap()]);
    assert_eq!(status, 0);
    assert!(
        out.contains("--out DIR --test-seeds` (it flies a benchmark task's test seeds)"),
        "{out}"
    );

    // Errors name the file's line and key, as `campaign` and `family` do.
    let campaign = format!(
        "name = \"c\"\nseed = 1\nseedz = 2\nscenarios = [\"{}\"]\n",
        family.display()
    );
    let (ok, err) = check(dir.path(), "c.toml", &campaign);
    assert!(!ok);
    assert!(
        err.contains("c.toml:3: seedz: unknown field `seedz`"),
        "{err}"
    );
    let campaign = format!(
        "name = \"c\"\nseed = 1\nseeds = 2\nscenarios = [\"{}\"]\n\n[[configs]]\nname = \"x\"\n\
         [configs.set]\nfix_wiat_s = 1.0\n",
        family.display()
    );
    let (ok, err) = check(dir.path(), "c.toml", &campaign);
    assert!(!ok);
    assert!(
        err.contains("c.toml:9:") && err.contains("did you mean `fix_wait_s`?"),
        "{err}"
    );
    let swapped = family_text.replace("speed_mps = [0.1, 0.3]", "speed_mps = [0.3, 0.1]");
    assert_ne!(swapped, family_text);
    let (ok, err) = check(dir.path(), "f.family.toml", &swapped);
    assert!(!ok);
    assert!(
        err.contains("f.family.toml:")
            && err.contains("flow.speed_mps: [low, high] needs low <= high"),
        "{err}"
    );
    // A campaign without `scenarios` is still read as one (by its `seeds`), and says what it
    // misses; so does a family without `base`.
    let (ok, err) = check(dir.path(), "c2.toml", "name = \"c\"\nseed = 1\nseeds = 2\n");
    assert!(!ok);
    assert!(
        err.contains("c2.toml: missing key `scenarios`: every campaign file has"),
        "{err}"
    );
    let no_base = family_text.replace("base = \"duck-2003-st\"\n", "");
    assert_ne!(no_base, family_text);
    let (ok, err) = check(dir.path(), "f2.toml", &no_base);
    assert!(!ok);
    assert!(
        err.contains("missing field `base`") && !err.contains("line 1, column 1"),
        "{err}"
    );
    // --set and --planner are for scenarios.
    let (status, _, err) = plumetrace(
        dir.path(),
        &["check", family.to_str().unwrap(), "--set", "beta_deg=3"],
    );
    assert_eq!(status, 1);
    assert!(
        err.contains("is a family file: --planner and --set apply to scenario files"),
        "{err}"
    );
}
