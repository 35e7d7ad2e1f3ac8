//! Outputs say whether the mission located the source (within the scenario's success radius),
//! and a family's site file flown as written is the campaign's run of that site.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

mod common;
use common::run_ok;

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Runs a scenario file or preset into `out` and returns the printed line and `summary.json`.
fn fly(args: &[&str], out: &Path) -> (String, serde_json::Value) {
    let mut all = vec!["run"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--out", out.to_str().unwrap(), "--no-snapshot-log"]);
    let printed = String::from_utf8(run_ok(&all).stdout).unwrap();
    (printed, json(&out.join("summary.json")))
}

/// Infotaxis's earlier map model (dilution after 15 m, a round spread), under which it declared
/// far downflow on the demo site.
const EARLIER_MAP: [(&str, &str); 5] = [
    ("map_dilution_m", "15.0"),
    ("map_p_detect", "0.1"),
    ("map_diffusivity_m2ps", "0.1"),
    ("map_along_speed_mps", "0.0"),
    ("map_mass", "0.7"),
];

#[test]
fn the_run_line_summary_and_figure_say_whether_the_source_was_located() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Infotaxis on the demo site with a map that dilutes the plume after 15 m (an earlier
    // default) declares far downflow: not located.
    let sets: Vec<String> = EARLIER_MAP
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect();
    let mut args = vec!["--preset", "demo-infotaxis", "--seed", "1"];
    for set in &sets {
        args.extend(["--set", set.as_str()]);
    }
    let (line, s) = fly(&args, &d.join("far"));
    assert!(
        line.starts_with(
            "demo-infotaxis: NOT located: declared 156.1 m from the source (success radius 50 m); \
             declared at 1571 s"
        ),
        "{line}"
    );
    assert_eq!(s["success"], false);
    assert_eq!(s["success_radius_m"], 50.0);
    assert_eq!(s["sources"][0]["located"], false);
    assert_eq!(s["sources_located"], 0);
    let svg = std::fs::read_to_string(d.join("far/plot.svg")).unwrap();
    assert!(
        svg.contains(
            "demo-infotaxis (seed 1): NOT located: declared 156.1 m from the source (success \
             radius 50 m)"
        ),
        "the figure's title says it"
    );
    // The same run with a wider radius set in the scenario: located.
    let text = plumetrace_scenario::find_preset("demo-infotaxis")
        .unwrap()
        .toml;
    let keys: String = EARLIER_MAP
        .iter()
        .map(|(k, v)| format!("\n{k} = {v}"))
        .collect();
    let wide = text
        .replacen("[mission]\n", "[mission]\nsuccess_radius_m = 300.0\n", 1)
        .replacen(
            "kind = \"infotaxis\"",
            &format!("kind = \"infotaxis\"{keys}"),
            1,
        );
    std::fs::write(d.join("wide.toml"), &wide).unwrap();
    let (line, s) = fly(&[d.join("wide.toml").to_str().unwrap()], &d.join("wide"));
    assert!(
        line.starts_with(
            "demo-infotaxis: located: declared 156.1 m from the source (success radius 300 m)"
        ),
        "{line}"
    );
    assert_eq!(
        (s["success"].as_bool(), s["sources"][0]["located"].as_bool()),
        (Some(true), Some(true))
    );
    // Out of time before any declaration.
    let short = text
        .replacen("time_limit_s = 3600.0", "time_limit_s = 60.0", 1)
        .replacen("duration_s = 3600.0", "duration_s = 60.0", 1);
    std::fs::write(d.join("short.toml"), &short).unwrap();
    let (line, s) = fly(&[d.join("short.toml").to_str().unwrap()], &d.join("short"));
    assert!(
        line.starts_with(
            "demo-infotaxis: NOT located: no declaration (time limit); outcome timed_out"
        ),
        "{line}"
    );
    assert_eq!(
        (s["success"].as_bool(), s["declared"].as_bool()),
        (Some(false), Some(false))
    );
}

#[test]
fn several_sources_and_formations_say_it_too() {
    let dir = tempfile::tempdir().unwrap();
    let (line, s) = fly(&["--preset", "soares-freshwater"], &dir.path().join("team"));
    assert!(
        line.starts_with("soares-freshwater: located: declared ")
            && line.contains(" m from the source (success radius 10 m); 2 declarations"),
        "{line}"
    );
    assert_eq!(s["success_radius_m"], 10.0);
    assert_eq!(s["success"], true);
    let title = format!("soares-freshwater (seed {}): located: declared", s["seed"]);
    let svg = std::fs::read_to_string(dir.path().join("team/plot.svg")).unwrap();
    assert!(svg.contains(&title), "{title}");
    let (line, s) = fly(&["--preset", "duck-2003-mt"], &dir.path().join("two"));
    assert!(
        line.starts_with(
            "duck-2003-mt: located: 2 of 2 sources declared within the success radius (50 m); \
             4 declarations, nearest declaration per source: 0.9 m, 2.5 m"
        ),
        "{line}"
    );
    assert_eq!(
        (s["success"].as_bool(), s["sources_located"].as_u64()),
        (Some(true), Some(2))
    );
    let title = "duck-2003-mt (seed 1): located: 2 of 2 sources declared within the success \
                 radius (50 m)";
    let svg = std::fs::read_to_string(dir.path().join("two/plot.svg")).unwrap();
    assert!(svg.contains(title), "{title}");
}

/// The value of `column` in a `runs.csv` row.
fn cell<'a>(head: &[&str], row: &'a [&'a str], column: &str) -> &'a str {
    row[head.iter().position(|h| *h == column).unwrap()]
}

#[test]
fn a_family_site_file_flown_as_written_is_the_campaigns_run_of_that_site() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let coastal = include_str!("../../../examples/families/coastal.family.toml");
    let family = coastal
        .replacen("name = \"coastal\"", "name = \"shore\"", 1)
        .replacen("time_limit_s = 7200.0", "time_limit_s = 1500.0", 1);
    assert_ne!(family, coastal);
    std::fs::write(d.join("shore.family.toml"), family).unwrap();
    std::fs::write(
        d.join("campaign.toml"),
        "name = \"sites\"\nseed = 5\nseeds = 3\nscenarios = [\"shore.family.toml\"]\n",
    )
    .unwrap();
    let p = |x: &str| d.join(x).to_str().unwrap().to_string();
    run_ok(&[
        "campaign",
        &p("campaign.toml"),
        "--out",
        &p("campaign"),
        "--jobs",
        "2",
    ]);
    run_ok(&[
        "family",
        &p("shore.family.toml"),
        "--sample",
        "3",
        "--seed",
        "5",
        "--out",
        &p("sites"),
    ]);
    let runs = std::fs::read_to_string(d.join("campaign/runs.csv")).unwrap();
    let mut lines = runs.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let mut seen = std::collections::BTreeSet::new();
    let mut big = false;
    for line in lines {
        let row: Vec<&str> = line.split(',').collect();
        let k: u64 = cell(&head, &row, "seed_index").parse().unwrap();
        let seed: u64 = cell(&head, &row, "seed").parse().unwrap();
        big |= seed > i64::MAX as u64;
        let site = d.join(format!("sites/site-{k:03}.toml"));
        let text = std::fs::read_to_string(&site).unwrap();
        let name = format!("shore-site-{k:03}");
        assert!(text.contains(&format!("name = \"{name}\"")), "{text}");
        assert!(seen.insert(name.clone()), "site names are unique");
        let written = if seed > i64::MAX as u64 {
            format!("seed = \"{seed}\"")
        } else {
            format!("seed = {seed}")
        };
        assert!(text.contains(&written), "{written} in\n{text}");
        // Flown as written: no --seed.
        let (line, s) = fly(&[site.to_str().unwrap()], &d.join(format!("run-{k}")));
        assert!(line.starts_with(&format!("{name}: ")), "{line}");
        assert_eq!(s["seed"].as_u64(), Some(seed));
        assert_eq!(s["outcome"].as_str(), Some(cell(&head, &row, "outcome")));
        assert_eq!(s["success"].to_string(), cell(&head, &row, "success"));
        let number = |column: &str| cell(&head, &row, column).parse::<f64>().ok();
        assert_eq!(s["sim_time_s"].as_f64(), number("sim_time_s"), "site {k}");
        assert_eq!(
            s["path_length_m"].as_f64(),
            number("path_length_m"),
            "site {k}"
        );
        let first = &s["first_declaration"];
        assert_eq!(first["error_m"].as_f64(), number("error_m"), "site {k}");
        assert_eq!(first["x_m"].as_f64(), number("declared_x"), "site {k}");
        assert_eq!(
            s["first_detection_s"].as_f64(),
            number("first_detection_s"),
            "site {k}"
        );
    }
    assert_eq!(seen.len(), 3);
    assert!(
        big,
        "a seed beyond 2^63 - 1 is among the three (written as a string)"
    );
}
