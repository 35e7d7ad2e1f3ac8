//! Acceptance checks over several seeds: the Duck 2003 missions (the AMP) and Li and Zhang's
//! kelp mission (the moth planner with obstacle avoidance). Slow in a
//! debug build: run with `cargo test --release -p plumetrace-mission --test duck_campaign --
//! --ignored` (CI does).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_core::DeclarationKind;
use plumetrace_mission::{Summary, run_mission};
use plumetrace_scenario::{Origin, build, load_preset};

/// The preset's mission at seeds 1..=n on two threads, in seed order.
fn run_seeds(preset: &str, n: u64) -> Vec<(u64, Summary)> {
    run_seeds_with(preset, n, &[])
}

/// [`run_seeds`] with the preset's planner keys `planner` set.
fn run_seeds_with(preset: &str, n: u64, planner: &[(&str, toml::Value)]) -> Vec<(u64, Summary)> {
    let mut cfg = load_preset(preset).unwrap();
    if !planner.is_empty() {
        let table = cfg.planner.get_or_insert_with(toml::Table::new);
        for (key, value) in planner {
            table.insert((*key).into(), value.clone());
        }
    }
    run_config(preset, &cfg, n)
}

/// `cfg` (the preset's, changed) at seeds 1..=n on two threads, in seed order.
fn run_config(
    preset: &str,
    cfg: &plumetrace_scenario::ScenarioConfig,
    n: u64,
) -> Vec<(u64, Summary)> {
    let seeds: Vec<u64> = (1..=n).collect();
    let results = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for chunk in seeds.chunks(seeds.len().div_ceil(2)) {
            let results = &results;
            s.spawn(move || {
                for &seed in chunk {
                    let sc = build(cfg, &Origin::Preset(preset.into()), Some(seed)).unwrap();
                    let run = run_mission(sc, &mut |_, _| {}).unwrap();
                    results.lock().unwrap().push((seed, run.summary));
                }
            });
        }
    });
    let mut results = results.into_inner().unwrap();
    results.sort_by_key(|r| r.0);
    results
}

#[test]
#[ignore = "about a minute in release mode; run with --ignored"]
fn duck_st_map_declaration_declares_every_seed_within_a_few_metres() {
    // Over 100 seeds (README, "The Duck check") the map at its defaults declares every run with
    // a median error of 6.0 m and a p90 of 9.8 m; 20 seeds must all but one declare, with a
    // median below 8 m.
    let results = run_seeds_with(
        "duck-2003-st",
        20,
        &[
            ("map_declaration", toml::Value::String("instead".into())),
            ("mapping", toml::Value::Boolean(false)),
        ],
    );
    let mut errors: Vec<f64> = results
        .iter()
        .filter_map(|r| r.1.first_declaration.as_ref())
        .filter(|d| d.rule == DeclarationKind::new("source_map"))
        .map(|d| d.error_m)
        .collect();
    errors.sort_by(f64::total_cmp);
    let median = errors.get(errors.len() / 2).copied().unwrap_or(f64::NAN);
    eprintln!("map declarations {}/20, errors {errors:?}", errors.len());
    assert!(
        errors.len() >= 19,
        "declared by the map in {} of 20",
        errors.len()
    );
    assert!(median < 8.0, "median error {median} m");
}

#[test]
#[ignore = "about a minute in release mode; run with --ignored"]
fn duck_st_declares_in_most_seeds_without_an_along_flow_bias() {
    // The default declaration (traced at 1 m, placed upflow of the lost points at their mean
    // across the flow) has no systematic along-flow error: over these 20 seeds every run
    // declares, the median error is under 5 m and the median signed along-flow error near 0
    // (the paper's rule, at the most upflow lost point, lay a median 6-10 m downflow).
    let results = run_seeds("duck-2003-st", 20);
    let declared: Vec<_> = results
        .iter()
        .filter_map(|r| r.1.first_declaration.as_ref())
        .collect();
    let median_of = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    let median = median_of(declared.iter().map(|d| d.error_m).collect());
    let along = median_of(declared.iter().map(|d| d.error_along_m).collect());
    eprintln!(
        "declared {}/20, median error {median:.1} m, median signed along-flow error {along:.1} m",
        declared.len()
    );
    assert!(
        declared.len() >= 18,
        "declared in {} of 20 seeds",
        declared.len()
    );
    assert!(median < 8.0, "median error {median} m");
    assert!(
        along.abs() < 3.0,
        "median signed along-flow error {along} m"
    );
}

#[test]
#[ignore = "about half a minute in release mode; run with --ignored"]
fn infotaxis_traces_the_duck_plume_to_its_head() {
    // Infotaxis at its defaults on the Duck mission: with a dilution model in its map it
    // declared a median 59 m downflow, where it met the plume; its plume model now puts the
    // information at the plume's head. Over these 10 seeds every run must declare, the median
    // within 8 m and at least 9 within 20 m.
    let mut cfg = load_preset("duck-2003-st").unwrap();
    cfg.planner = Some(toml::Table::from_iter([(
        "kind".to_string(),
        toml::Value::String("infotaxis".into()),
    )]));
    let results = run_config("duck-2003-st", &cfg, 10);
    let mut errors: Vec<f64> = results
        .iter()
        .filter_map(|r| r.1.first_declaration.as_ref())
        .map(|d| d.error_m)
        .collect();
    errors.sort_by(f64::total_cmp);
    eprintln!("infotaxis declared {}/10, errors {errors:?}", errors.len());
    assert_eq!(errors.len(), 10, "declared in {} of 10 seeds", errors.len());
    let median = (errors[4] + errors[5]) / 2.0;
    assert!(median < 8.0, "median error {median} m");
    let within = errors.iter().filter(|e| **e <= 20.0).count();
    assert!(within >= 9, "{within} of 10 within 20 m");
}

#[test]
#[ignore = "about a minute in release mode; run with --ignored"]
fn duck_mt_locates_the_sources_and_declares_the_southern_edges() {
    let results = run_seeds("duck-2003-mt", 8);
    let sources: usize = results.iter().map(|r| r.1.sources.len()).sum();
    let located: usize = results.iter().map(|r| r.1.sources_located).sum();
    let mut errors: Vec<f64> = results
        .iter()
        .flat_map(|r| r.1.sources.iter())
        .filter(|s| s.located)
        .filter_map(|s| s.nearest_error_m)
        .collect();
    errors.sort_by(f64::total_cmp);
    let median = errors.get(errors.len() / 2).copied().unwrap_or(f64::NAN);
    // The plumes of the northern sources cross into the southern subregions, whose searches
    // should end at their upflow edge (y = 550 m) with a declaration there.
    let edges: Vec<usize> = results
        .iter()
        .map(|r| {
            r.1.declarations
                .iter()
                .filter(|d| {
                    d.rule == DeclarationKind::new("upflow_edge") && (d.y_m - 550.0).abs() < 1.0
                })
                .count()
        })
        .collect();
    eprintln!(
        "located {located}/{sources}, errors {errors:?}, median {median:.1} m, edge declarations per mission {edges:?}"
    );
    assert_eq!(sources, 16, "two sources per mission");
    assert!(located >= 14, "located {located} of {sources} sources");
    assert!(median < 20.0, "median error of located sources {median} m");
    assert!(
        edges.iter().filter(|&&n| n == 2).count() >= 6,
        "both southern subregions end at their edge in too few missions: {edges:?}"
    );
}

#[test]
#[ignore = "about half a minute in release mode; run with --ignored"]
fn li_zhang_kelp_declares_without_collisions() {
    // Seeds 1-50, not the seeds the avoidance was tuned on (campaign seeds 77-82).
    let results = run_seeds("li-zhang-kelp", 50);
    let collided = results
        .iter()
        .filter(|r| r.1.outcome == plumetrace_mission::Outcome::Collided)
        .count();
    let mut errors: Vec<f64> = results
        .iter()
        .filter_map(|r| r.1.first_declaration.as_ref().map(|d| d.error_m))
        .collect();
    errors.sort_by(f64::total_cmp);
    let median = errors.get(errors.len() / 2).copied().unwrap_or(f64::NAN);
    eprintln!(
        "li-zhang-kelp: declared {}/50, collided {collided}, error median {median:.2} m, \
         p90 {:.2} m, max {:.2} m",
        errors.len(),
        errors
            .get(errors.len() * 9 / 10)
            .copied()
            .unwrap_or(f64::NAN),
        errors.last().copied().unwrap_or(f64::NAN)
    );
    assert_eq!(collided, 0, "collisions in kelp");
    assert!(errors.len() >= 45, "declared in {} of 50", errors.len());
    assert!(median < 3.0, "error median {median} m");
}
