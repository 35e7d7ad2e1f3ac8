//! Campaigns end to end on a shortened demo mission: determinism across calls, thread counts and
//! shards; resuming; damaged and foreign results; malformed campaign files.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_campaign::{Campaign, CampaignError, RunOptions, Shard, Share, merge, run_campaign};
use std::path::{Path, PathBuf};

/// Two configurations x two sweep values x 2 seeds of a 1,500 s demo mission.
const CAMPAIGN: &str = r#"
name = "test"
seed = 11
seeds = 2
scenarios = ["demo"]

[[configs]]
name = "paper"
[configs.set]
declaration = "along_flow"
mapping = false
"mission.time_limit_s" = 1500.0
"mission.spinup_s" = 1500.0

[[configs]]
name = "cross"
[configs.set]
declaration = "along_and_cross_flow"
mapping = false
"mission.time_limit_s" = 1500.0
"mission.spinup_s" = 1500.0

[sweep]
beta_deg = [20.0, 30.0]
"#;

fn campaign_file(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("campaign.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn run(file: &Path, out: &Path, opts: RunOptions, seeds: Option<u64>) {
    let c = Campaign::load(file, seeds).unwrap();
    run_campaign(&c, out, opts, &|_, _| {}).unwrap();
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

#[test]
fn same_campaign_same_results_whatever_the_threads_and_shards() {
    let tmp = tempfile::tempdir().unwrap();
    let file = campaign_file(tmp.path(), CAMPAIGN);
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    run(
        &file,
        &a,
        RunOptions {
            jobs: Some(1),
            shard: None,
            ..RunOptions::default()
        },
        None,
    );
    run(
        &file,
        &b,
        RunOptions {
            jobs: Some(2),
            shard: None,
            ..RunOptions::default()
        },
        None,
    );
    let runs = read(&a.join("runs.csv"));
    assert_eq!(runs.lines().count(), 1 + 2 * 2 * 2, "{runs}");
    assert_eq!(
        runs,
        read(&b.join("runs.csv")),
        "--jobs 1 and --jobs 2 differ"
    );
    assert_eq!(read(&a.join("summary.csv")), read(&b.join("summary.csv")));

    // Common random numbers: every group at seed index k has the same seed.
    let rows: Vec<Vec<String>> = runs
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    for r in &rows {
        let twin = rows.iter().find(|s| s[3] == r[3]).unwrap();
        assert_eq!(r[4], twin[4], "seed of seed index {}", r[3]);
    }
    let outcomes: Vec<&str> = rows.iter().map(|r| r[5].as_str()).collect();
    assert!(outcomes.contains(&"declared"), "{outcomes:?}");

    // Three shards, merged, equal the single run byte for byte.
    let shards: Vec<PathBuf> = (1..=3).map(|k| tmp.path().join(format!("s{k}"))).collect();
    for (k, dir) in shards.iter().enumerate() {
        let shard = Some(Shard {
            index: k as u64 + 1,
            count: 3,
        });
        run(
            &file,
            dir,
            RunOptions {
                jobs: Some(2),
                shard,
                ..RunOptions::default()
            },
            None,
        );
    }
    let shard_rows: usize = shards
        .iter()
        .map(|d| read(&d.join("runs.csv")).lines().count() - 1)
        .sum();
    assert_eq!(shard_rows, 8, "every run in exactly one shard");
    let merged = tmp.path().join("merged");
    let report = merge(&shards, &merged).unwrap();
    assert_eq!((report.runs, report.expected), (8, 8));
    assert_eq!(read(&merged.join("runs.csv")), runs);
    assert_eq!(
        read(&merged.join("summary.csv")),
        read(&a.join("summary.csv"))
    );
    assert_eq!(
        read(&merged.join("summary.md")),
        read(&a.join("summary.md"))
    );
    for f in ["success.svg", "errors.svg", "trajectories.svg"] {
        assert!(read(&merged.join(f)).contains("<svg"), "{f}");
    }
    // An example and its replay page per group (4 groups), whichever shard flew it.
    let names: Vec<String> = std::fs::read_dir(merged.join("examples"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.iter().filter(|n| n.ends_with(".json")).count(), 4);
    assert_eq!(names.iter().filter(|n| n.ends_with(".html")).count(), 4);
    for n in names.iter().filter(|n| n.ends_with(".html")) {
        let page = read(&merged.join("examples").join(n));
        assert!(page.contains("id=\"plumetrace-data\""), "{n}");
        let json = n.replace(".html", ".json");
        assert!(names.contains(&json), "{n} has no example {json}");
    }
}

#[test]
fn resuming_skips_recorded_runs_cuts_a_partial_row_and_extends_seeds() {
    let tmp = tempfile::tempdir().unwrap();
    let text = CAMPAIGN.replace("[sweep]\nbeta_deg = [20.0, 30.0]\n", "");
    let file = campaign_file(tmp.path(), &text);
    let full = tmp.path().join("full");
    run(&file, &full, RunOptions::default(), Some(3));
    let want = read(&full.join("runs.csv"));
    assert_eq!(want.lines().count(), 1 + 2 * 3);

    // A directory where a killed campaign left two rows and half of a third.
    let dir = tmp.path().join("resumed");
    run(&file, &dir, RunOptions::default(), Some(1));
    let partial = read(&dir.join("runs.csv"));
    assert_eq!(partial.lines().count(), 3);
    let next_row = want.lines().nth(2).unwrap();
    std::fs::write(
        dir.join("runs.csv"),
        format!("{partial}{}", &next_row[..next_row.len() / 2]),
    )
    .unwrap();
    let c = Campaign::load(&file, Some(3)).unwrap();
    let report = run_campaign(&c, &dir, RunOptions::default(), &|_, _| {}).unwrap();
    assert!(report.cut_partial_line);
    assert_eq!((report.planned, report.skipped, report.ran), (6, 2, 4));
    assert_eq!(read(&dir.join("runs.csv")), want);

    // Nothing left to do: a third call runs nothing and changes nothing.
    let report = run_campaign(&c, &dir, RunOptions::default(), &|_, _| {}).unwrap();
    assert_eq!((report.skipped, report.ran), (6, 0));
    assert_eq!(read(&dir.join("runs.csv")), want);
    let summary_of_3 = read(&dir.join("summary.csv"));

    // Fewer seeds than recorded: the call summarises its own seeds, as a directory of that
    // many would, and says what it left out; runs.csv keeps every run.
    let c = Campaign::load(&file, Some(2)).unwrap();
    let report = run_campaign(&c, &dir, RunOptions::default(), &|_, _| {}).unwrap();
    assert_eq!((report.planned, report.skipped, report.ran), (4, 4, 0));
    assert_eq!(read(&dir.join("runs.csv")), want);
    let two = tmp.path().join("two");
    run(&file, &two, RunOptions::default(), Some(2));
    assert_eq!(
        read(&dir.join("summary.csv")),
        read(&two.join("summary.csv"))
    );
    assert_ne!(read(&dir.join("summary.csv")), summary_of_3);
    let md = read(&dir.join("summary.md"));
    assert!(md.contains("4 of 4 runs recorded"), "{md}");
    assert!(
        md.contains(
            "2 more runs in `runs.csv`, of seeds beyond the 2 per group this call asked for"
        ),
        "{md}"
    );
    assert!(!read(&two.join("summary.md")).contains("more runs in"));
}

#[test]
fn a_directory_of_another_campaign_or_a_damaged_file_is_refused_without_touching_it() {
    let tmp = tempfile::tempdir().unwrap();
    let text = CAMPAIGN.replace("[sweep]\nbeta_deg = [20.0, 30.0]\n", "");
    let file = campaign_file(tmp.path(), &text);
    let dir = tmp.path().join("out");
    run(&file, &dir, RunOptions::default(), Some(1));
    let before = read(&dir.join("runs.csv"));

    let other = tmp.path().join("other");
    std::fs::create_dir_all(&other).unwrap();
    let other_file = campaign_file(&other, &text.replace("seed = 11", "seed = 12"));
    let c = Campaign::load(&other_file, Some(1)).unwrap();
    let e = run_campaign(&c, &dir, RunOptions::default(), &|_, _| {}).unwrap_err();
    assert!(e.to_string().contains("different campaign"), "{e}");
    assert_eq!(read(&dir.join("runs.csv")), before);

    // A row damaged in the middle: an error naming the file and line, and the file is kept.
    let mut lines: Vec<String> = before.lines().map(str::to_string).collect();
    let mut fields: Vec<&str> = lines[1].split(',').collect();
    fields[4] = "not-a-seed";
    lines[1] = fields.join(",");
    let damaged = lines.join("\n") + "\n";
    std::fs::write(dir.join("runs.csv"), &damaged).unwrap();
    let c = Campaign::load(&file, Some(1)).unwrap();
    let e = run_campaign(&c, &dir, RunOptions::default(), &|_, _| {}).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("runs.csv:2"), "{msg}");
    assert_eq!(read(&dir.join("runs.csv")), damaged);

    // Another version's columns (here without the source counts): refused, file kept.
    let old_header = before
        .lines()
        .next()
        .unwrap()
        .replace(",sources,sources_located", "");
    let older = format!("{old_header}\n");
    std::fs::write(dir.join("runs.csv"), &older).unwrap();
    let e = run_campaign(&c, &dir, RunOptions::default(), &|_, _| {}).unwrap_err();
    assert!(e.to_string().contains("another plumetrace version"), "{e}");
    assert_eq!(read(&dir.join("runs.csv")), older);
}

fn load_err(text: &str) -> CampaignError {
    let tmp = tempfile::tempdir().unwrap();
    let file = campaign_file(tmp.path(), text);
    Campaign::load(&file, None).unwrap_err()
}

#[test]
fn malformed_campaigns_are_rejected_with_their_key_path() {
    let cases: [(&str, &str); 8] = [
        (
            "name = \"x\"\nseed = 1\nseeds = 2\nscenarios = [\"demo\"]\ntypo = 3\n",
            "unknown field `typo`",
        ),
        (
            "name = \"x\"\nseed = 1\nseeds = 2\nscenarios = [\"demo\", \"duck-2003\"]\n",
            "scenarios[1]: 'duck-2003' is neither a preset (demo, ",
        ),
        (
            "name = \"x\"\nseed = 1\nseeds = \"many\"\nscenarios = [\"demo\"]\n",
            "seeds",
        ),
        (
            "name = \"x\"\nseed = 1\nseeds = 2\nscenarios = [\"no-such-preset\"]\n",
            "scenarios[0]",
        ),
        (
            "name = \"x\"\nseed = 1\nseeds = 2\nscenarios = [\"demo\"]\n[[configs]]\nname = \"a\"\n[configs.set]\nbeta_deg = 95.0\n",
            "planner.beta_deg",
        ),
        (
            "name = \"x\"\nseed = 1\nseeds = 2\nscenarios = [\"demo\"]\n[[configs]]\nname = \"a\"\n[configs.set]\nbeta_dge = 25.0\n",
            "planner.beta_dge",
        ),
        (
            "name = \"x\"\nseed = 1\nseeds = 2\nscenarios = [\"demo\"]\n[sweep]\nlambda_s = 5.0\n",
            "sweep.lambda_s",
        ),
        (
            "name = \"x\"\nseed = 1\nseeds = 2\nscenarios = [\"demo\"]\n[[configs]]\nname = \"a\"\n[[configs]]\nname = \"a\"\n",
            "configs[1].name",
        ),
    ];
    for (text, key) in cases {
        let msg = load_err(text).to_string();
        assert!(msg.contains(key), "expected '{key}' in: {msg}");
        assert!(msg.contains("campaign.toml"), "no file in: {msg}");
    }
    // A near miss of a preset's name is told the name.
    let msg = load_err(cases[1].0).to_string();
    assert!(
        msg.ends_with("nor a path ending in .toml; did you mean 'duck-2003-st'?"),
        "{msg}"
    );
}

#[test]
fn every_shipped_example_campaign_loads_and_builds_every_group() {
    let dir = std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/campaigns"
    ));
    let mut n = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let c = plumetrace_campaign::Campaign::load(&path, Some(1))
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert!(!c.runs().is_empty());
            n += 1;
        }
    }
    assert!(n >= 3, "found {n} example campaigns");
}

#[test]
fn runs_sharing_a_spin_up_give_the_bits_of_separate_spin_ups() {
    // Three configurations: two differ in planner keys and the mission's time limit only (they
    // share the plume's spin-up at each seed), one in its source (it spins up its own).
    let text = CAMPAIGN.replace(
        "[sweep]\nbeta_deg = [20.0, 30.0]\n",
        "[[configs]]\nname = \"stronger\"\n[configs.set]\nmapping = false\n\
         \"mission.time_limit_s\" = 1200.0\n\"mission.spinup_s\" = 1500.0\n\
         \"sources.0.mass_rate_per_s\" = 30.0\n",
    );
    let tmp = tempfile::tempdir().unwrap();
    let file = campaign_file(tmp.path(), &text);
    let c = Campaign::load(&file, None).unwrap();
    let groups = plumetrace_campaign::execute::share_groups(&c, &c.runs());
    // Per seed: {paper, cross} together, {stronger} alone.
    assert_eq!(groups.len(), 2 * 2, "{groups:?}");
    assert_eq!(groups.iter().filter(|g| g.len() == 2).count(), 2);
    for g in &groups {
        assert!(g.iter().all(|k| k.seed_index == g[0].seed_index));
        if g.len() == 2 {
            assert!(g.iter().all(|k| k.config < 2), "{g:?}");
        }
    }
    let (shared, separate) = (tmp.path().join("shared"), tmp.path().join("separate"));
    run(
        &file,
        &shared,
        RunOptions {
            share: Share::SpinUp,
            ..RunOptions::default()
        },
        None,
    );
    run(
        &file,
        &separate,
        RunOptions {
            share: Share::Nothing,
            ..RunOptions::default()
        },
        None,
    );
    let runs = read(&shared.join("runs.csv"));
    assert_eq!(runs.lines().count(), 1 + 3 * 2, "{runs}");
    assert_eq!(runs, read(&separate.join("runs.csv")));
    assert!(runs.contains("declared"), "{runs}");
}

/// Every file of a campaign directory but `campaign.json` and `campaign.toml`, by name.
fn results(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    for sub in ["", "examples"] {
        for entry in std::fs::read_dir(dir.join(sub)).unwrap() {
            let path = entry.unwrap().path();
            if path.is_file() {
                out.push((
                    format!("{sub}/{}", path.file_name().unwrap().to_string_lossy()),
                    std::fs::read(&path).unwrap(),
                ));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn runs_in_one_world_give_the_bits_of_separate_runs_on_any_thread_count() {
    // Four configurations at each seed: three planners (two AMP rules with different time
    // limits, a lawnmower) fly in one world; the fourth changes the source and flies alone.
    let text = CAMPAIGN
        .replace("\n[sweep]\nbeta_deg = [20.0, 30.0]\n", "\n")
        .replace(
            "name = \"cross\"\n[configs.set]\ndeclaration = \"along_and_cross_flow\"\nmapping = false\n\
             \"mission.time_limit_s\" = 1500.0",
            "name = \"cross\"\n[configs.set]\ndeclaration = \"along_and_cross_flow\"\nmapping = false\n\
             \"mission.time_limit_s\" = 900.0",
        )
        + "\n[[configs]]\nname = \"lawnmower\"\n[configs.planner]\nkind = \"lawnmower\"\n\
           lane_spacing_m = 40.0\n[configs.set]\n\"mission.time_limit_s\" = 1200.0\n\
           \"mission.spinup_s\" = 1500.0\n\
           \n[[configs]]\nname = \"stronger\"\n[configs.set]\nmapping = false\n\
           \"mission.time_limit_s\" = 1200.0\n\"mission.spinup_s\" = 1500.0\n\
           \"sources.0.mass_rate_per_s\" = 30.0\n";
    let tmp = tempfile::tempdir().unwrap();
    let file = campaign_file(tmp.path(), &text);
    let c = Campaign::load(&file, None).unwrap();
    assert_eq!(c.configs.len(), 4, "{text}");
    let groups = plumetrace_campaign::execute::share_groups(&c, &c.runs());
    // Per seed: {paper, cross, lawnmower} in one world, {stronger} alone.
    assert_eq!(groups.len(), 2 * 2, "{groups:?}");
    for g in &groups {
        assert!(g.iter().all(|k| k.seed_index == g[0].seed_index));
        match g.len() {
            3 => assert!(g.iter().all(|k| k.config < 3), "{g:?}"),
            1 => assert_eq!(g[0].config, 3, "{g:?}"),
            _ => panic!("{g:?}"),
        }
    }
    let separate = tmp.path().join("separate");
    run(
        &file,
        &separate,
        RunOptions {
            jobs: Some(1),
            share: Share::Nothing,
            ..RunOptions::default()
        },
        None,
    );
    let expected = results(&separate);
    let runs = read(&separate.join("runs.csv"));
    assert_eq!(runs.lines().count(), 1 + 4 * 2, "{runs}");
    assert!(
        runs.contains("lawnmower") && runs.contains("declared"),
        "{runs}"
    );
    // The examples' replay pages and tracks are compared too.
    assert!(
        expected
            .iter()
            .filter(|(n, _)| n.starts_with("examples/"))
            .count()
            >= 8
    );
    for jobs in [1, 2] {
        let shared = tmp.path().join(format!("shared-{jobs}"));
        run(
            &file,
            &shared,
            RunOptions {
                jobs: Some(jobs),
                ..RunOptions::default()
            },
            None,
        );
        let got = results(&shared);
        assert_eq!(
            got.iter().map(|(n, _)| n).collect::<Vec<_>>(),
            expected.iter().map(|(n, _)| n).collect::<Vec<_>>()
        );
        for ((name, a), (_, b)) in got.iter().zip(&expected) {
            assert!(a == b, "{jobs} threads: {name} differs");
        }
    }
    // A group interrupted after some of its runs: the rest fly in a fresh shared world and
    // the results are the same.
    let resumed = tmp.path().join("resumed");
    std::fs::create_dir_all(&resumed).unwrap();
    run(
        &file,
        &resumed,
        RunOptions {
            shard: Some("1/3".parse().unwrap()),
            ..RunOptions::default()
        },
        None,
    );
    let partial = read(&resumed.join("runs.csv"));
    assert_eq!(partial.lines().count(), 1 + 3, "{partial}");
    run(&file, &resumed, RunOptions::default(), None);
    assert_eq!(read(&resumed.join("runs.csv")), runs);
}
