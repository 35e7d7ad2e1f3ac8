//! Formation tracing end to end on `soares-freshwater`: the team declares near the outlet, the
//! follower keeps its ranges, the team's numbers reach the summary, and lossy links show up in
//! them.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_mission::{EventKind, Outcome, run_mission};
use plumetrace_scenario::{Origin, build, load_preset};
use plumetrace_sim::WorldEvent;

fn run(seed: u64, loss: f64) -> plumetrace_mission::MissionRun {
    let mut cfg = load_preset("soares-freshwater").unwrap();
    if let Some(a) = cfg.comms.acoustic.as_mut() {
        a.loss_probability = Some(loss);
    }
    let built = build(
        &cfg,
        &Origin::Preset("soares-freshwater".into()),
        Some(seed),
    )
    .unwrap();
    run_mission(built, &mut |_, _| {}).unwrap()
}

#[test]
fn the_team_traces_the_freshwater_plume_to_its_outlet_keeping_its_ranges() {
    let r = run(11, 0.0);
    let s = &r.summary;
    assert_eq!(s.outcome, Outcome::Declared, "{s:?}");
    let d = s.first_declaration.as_ref().unwrap();
    assert!(
        d.error_m < 10.0,
        "declared {:.1} m from the outlet",
        d.error_m
    );
    let team = s.team.as_ref().expect("three planners make a team");
    // d = 10 m: the follower's true ranges within 10 % of it.
    let median = team.range_error_median_m.unwrap();
    assert!(median < 1.0, "median range error {median}");
    assert_eq!(team.non_finite_commands, 0);
    let confidence = team
        .declaration_confidence
        .expect("the confirmed rule reports one");
    assert!((0.0..=1.0).contains(&confidence), "{confidence}");
    assert_eq!(team.acoustic_lost, 0, "ideal links lose nothing");
    assert!(team.acoustic_delivered > 100);
    let smax = team.scale_max.unwrap();
    assert!(
        smax > 1.0 && smax <= 2.0 * (1.0f64 - 0.0025).sqrt(),
        "{smax}"
    );
    assert!(team.centroid_cross_median_m.unwrap() < 2.0);
    let overhead = team.distance_overhead.unwrap();
    assert!(overhead > 1.0 && overhead < 1.5, "{overhead}");
    assert!(!r.events.iter().any(|e| matches!(
        e.event,
        EventKind::World(WorldEvent::NonFiniteCommand { .. })
    )));
}

#[test]
fn with_a_fifth_of_the_acoustic_packets_lost_the_losses_are_counted_and_the_team_still_declares() {
    let r = run(11, 0.2);
    let team = r.summary.team.as_ref().unwrap();
    let lost = team.acoustic_lost as f64;
    let all = lost + team.acoustic_delivered as f64;
    // Each packet is lost with probability 0.2 per recipient (busy modems add a few).
    assert!(lost / all > 0.15 && lost / all < 0.3, "{lost} of {all}");
    assert_eq!(r.summary.outcome, Outcome::Declared);
    assert!(team.range_error_median_m.unwrap() < 1.0);
}

#[test]
fn a_follower_naming_a_leader_that_does_not_exist_is_refused_with_the_vehicles_there_are() {
    let preset = plumetrace_scenario::find_preset("soares-freshwater").unwrap();
    let text = preset
        .toml
        .replace("left_leader = 2", "left_leader = 10000");
    let origin = Origin::File("team.toml".into());
    let cfg = plumetrace_scenario::parse(&text, &origin).unwrap();
    let built = build(&cfg, &origin, None).unwrap();
    let Err(e) = plumetrace_mission::MissionSetup::new(built) else {
        panic!("accepted");
    };
    let e = e.to_string();
    for part in [
        "team.toml",
        "planners.follower.left_leader",
        "vehicle 10000 does not exist",
        "3 vehicles, 0 (follower), 1 (leader-right), 2 (leader-left)",
    ] {
        assert!(e.contains(part), "{part}: {e}");
    }
}
