//! Missions end to end on shortened presets: no panics, reproducible, sane summaries.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_mission::{Outcome, run_mission};
use plumetrace_scenario::{Origin, PRESETS, build, load_preset};

/// A preset with its spin-up and time limit cut down for a quick test.
fn shortened(
    name: &str,
    spinup_s: f64,
    limit_s: f64,
    seed: u64,
) -> plumetrace_scenario::BuiltScenario {
    let mut cfg = load_preset(name).unwrap();
    if let Some(m) = cfg.mission.as_mut() {
        m.spinup_s = m.spinup_s.min(spinup_s);
        m.time_limit_s = limit_s;
    }
    build(&cfg, &Origin::Preset(name.into()), Some(seed)).unwrap()
}

#[test]
fn every_mission_preset_runs_without_panicking() {
    for p in PRESETS {
        let cfg = load_preset(p.name).unwrap();
        if cfg.mission.is_none() {
            continue;
        }
        let run = run_mission(shortened(p.name, 1500.0, 120.0, 3), &mut |_, _| {}).unwrap();
        let s = &run.summary;
        assert!(
            s.sim_time_s > 0.0 && s.sim_time_s <= 120.0 + 1e-9,
            "{}: {}",
            p.name,
            s.sim_time_s
        );
        assert!(
            s.path_length_m > 100.0,
            "{}: the vehicle barely moved ({} m)",
            p.name,
            s.path_length_m
        );
        assert!(
            !run.trajectory.is_empty()
                && run
                    .events
                    .iter()
                    .any(|e| matches!(e.event, plumetrace_mission::run::EventKind::Planner(_)))
        );
        assert!(
            matches!(
                run.outcome,
                Outcome::TimedOut | Outcome::Declared | Outcome::NoDeclaration
            ),
            "{}: {:?}",
            p.name,
            run.outcome
        );
    }
}

#[test]
fn same_seed_same_summary_and_trajectory() {
    let a = run_mission(shortened("demo", 600.0, 300.0, 7), &mut |_, _| {}).unwrap();
    let b = run_mission(shortened("demo", 600.0, 300.0, 7), &mut |_, _| {}).unwrap();
    let c = run_mission(shortened("demo", 600.0, 300.0, 8), &mut |_, _| {}).unwrap();
    let digest = |r: &plumetrace_mission::MissionRun| {
        (
            serde_json::to_string(&r.summary).unwrap(),
            serde_json::to_string(&r.trajectory).unwrap(),
        )
    };
    assert_eq!(digest(&a), digest(&b));
    assert_ne!(digest(&a).1, digest(&c).1);
}

#[test]
fn the_demo_finds_the_plume_and_traces_it_towards_the_source() {
    let run = run_mission(shortened("demo", 3500.0, 900.0, 1), &mut |_, _| {}).unwrap();
    let s = &run.summary;
    assert!(
        s.first_detection_s.is_finite() && s.first_detection_s < 300.0,
        "first detection at {} s",
        s.first_detection_s
    );
    // The closest approach of the estimated track to the source, once tracing.
    let closest = run
        .trajectory
        .iter()
        .map(|r| ((r.true_x_m - s.source_x).powi(2) + (r.true_y_m - s.source_y).powi(2)).sqrt())
        .fold(f64::MAX, f64::min);
    assert!(
        closest < 30.0,
        "never got within 30 m of the source: {closest}"
    );
}

#[test]
fn bad_planner_settings_are_rejected_with_their_key_path() {
    let mut cfg = load_preset("demo").unwrap();
    cfg.planner.as_mut().unwrap().beta_deg = Some(-5.0);
    let sc = build(&cfg, &Origin::Preset("demo".into()), None).unwrap();
    let e = run_mission(sc, &mut |_, _| {}).unwrap_err().to_string();
    assert!(e.contains("planner.beta_deg"), "{e}");
    let mut cfg = load_preset("demo").unwrap();
    cfg.planner.as_mut().unwrap().n_re = Some(0);
    let sc = build(&cfg, &Origin::Preset("demo".into()), None).unwrap();
    assert!(
        run_mission(sc, &mut |_, _| {})
            .unwrap_err()
            .to_string()
            .contains("planner.n_re")
    );
}
