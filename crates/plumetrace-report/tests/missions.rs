//! Figures and pages of flown missions: the mission figure names every vehicle's track, the
//! replay page carries the run (its tracks, plume frames, fault windows and events), and a
//! replayed snapshot log makes a page of the logged track and the replayed behaviours.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_log::snapshot::{Header, open, replay_with};
use plumetrace_mission::snapshot_log::SnapshotLogWriter;
use plumetrace_mission::{Mission, MissionOptions, MissionRun, MissionSetup, run_mission};
use plumetrace_report::{LogPageBuilder, PageData, mission_figure};
use plumetrace_scenario::{Origin, ScenarioConfig, build, load_preset};

/// A preset with its spin-up and time limit cut down for a quick test.
fn shortened(
    name: &str,
    spinup_s: f64,
    limit_s: f64,
    seed: u64,
) -> plumetrace_scenario::BuiltScenario {
    let mut cfg = load_preset(name).unwrap();
    shorten(&mut cfg, spinup_s, limit_s);
    build(&cfg, &Origin::Preset(name.into()), Some(seed)).unwrap()
}

fn shorten(cfg: &mut ScenarioConfig, spinup_s: f64, limit_s: f64) {
    if let Some(m) = cfg.mission.as_mut() {
        m.spinup_s = m.spinup_s.min(spinup_s);
        m.time_limit_s = limit_s;
    }
}

fn load_preset_text(name: &str) -> String {
    plumetrace_scenario::find_preset(name)
        .unwrap()
        .toml
        .to_string()
}

/// The demo with a second AUV starting from the other downflow corner, both flying the AMP.
const TWO_AUVS: &str = r#"
[[vehicles]]
kind = "auv"
name = "north"
x_m = 470.0
y_m = 60.0
heading_deg = 270.0
planner = "tracer"

[[vehicles]]
kind = "auv"
name = "south"
x_m = 470.0
y_m = -60.0
heading_deg = 270.0
planner = "tracer"

[planners.tracer]
kind = "amp"
mapping = false
"#;

/// The demo's text with its vehicle and planner tables replaced.
fn demo_text_with(vehicles_and_planners: &str) -> String {
    let base = load_preset_text("demo");
    let start = base.find("[[vehicles]]").unwrap();
    let mission = base.find("[mission]").unwrap();
    let planner = base.find("[planner]").unwrap();
    let output = base.find("[output]").unwrap_or(base.len());
    format!(
        "{}{}\n{}{}",
        &base[..start],
        vehicles_and_planners,
        &base[mission..planner],
        &base[output..]
    )
}

fn demo_with(vehicles_and_planners: &str, limit_s: f64, seed: u64) -> MissionSetup {
    let origin = Origin::File("two.toml".into());
    let mut cfg =
        plumetrace_scenario::parse(&demo_text_with(vehicles_and_planners), &origin).unwrap();
    shorten(&mut cfg, 2000.0, limit_s);
    MissionSetup::new(build(&cfg, &origin, Some(seed)).unwrap()).unwrap()
}

/// The mission of `demo_with(vehicles_and_planners, limit_s, seed)`, flown.
fn fly(vehicles_and_planners: &str, limit_s: f64, seed: u64) -> MissionRun {
    let setup = demo_with(vehicles_and_planners, limit_s, seed);
    let mut m = Mission::new(setup, MissionOptions::default()).unwrap();
    m.run(&mut |_, _| {}).unwrap();
    m.finish().unwrap()
}

#[test]
fn the_figure_of_two_auvs_names_both_tracks() {
    let run = fly(TWO_AUVS, 1500.0, 3);
    let svg = mission_figure(&run, "two AUVs").unwrap();
    assert!(
        svg.contains("north (amp) estimated track") && svg.contains("south (amp) estimated track"),
        "the legend names both vehicles"
    );
}

/// An AUV flying the AMP beside a surface craft flying the lawnmower.
const AMP_AND_SURVEY: &str = r#"
[[vehicles]]
kind = "auv"
name = "tracer"
x_m = 470.0
y_m = -60.0
heading_deg = 270.0
planner = "amp"

[[vehicles]]
kind = "surface"
name = "boat"
x_m = 470.0
y_m = 60.0
heading_deg = 270.0
planner = "survey"

[planners.amp]
kind = "amp"

[planners.survey]
kind = "lawnmower"
lane_spacing_m = 60.0
"#;

#[test]
fn the_figure_of_a_surface_craft_beside_an_auv_names_both_tracks() {
    let run = fly(AMP_AND_SURVEY, 1200.0, 2);
    let svg = mission_figure(&run, "pair").unwrap();
    assert!(
        svg.contains("tracer (amp) estimated track")
            && svg.contains("boat (lawnmower) estimated track")
    );
}

#[test]
fn the_replay_page_carries_the_run_its_plume_frames_and_its_fault_window() {
    let text = load_preset_text("demo").replacen(
        "[mission]",
        "[vehicles.flow_sensor]\nfault_start_s = 100.0\nfault_end_s = 300.0\n\n[mission]",
        1,
    );
    let origin = Origin::File("fault.toml".into());
    let mut cfg = plumetrace_scenario::parse(&text, &origin).unwrap();
    shorten(&mut cfg, 2000.0, 400.0);
    let run = run_mission(build(&cfg, &origin, Some(3)).unwrap(), &mut |_, _| {}).unwrap();
    let page = PageData::from_run(&run, "fault");
    assert_eq!(page.vehicles.len(), 1);
    let v = &page.vehicles[0];
    assert_eq!(v.faults.len(), 1);
    assert_eq!((v.faults[0].0, v.faults[0].1), (100.0, 300.0));
    // One kept point a second over 400 s, true and estimated positions for each.
    let n = v.track.t.len();
    assert!((395..=460).contains(&n), "{n} track points");
    assert_eq!(v.track.tx.len(), n);
    assert_eq!(v.track.ex.len(), n);
    assert_eq!(v.track.b.len(), n);
    // Every detection of the trajectory is still on the page after thinning.
    let detected = run.trajectory.iter().any(|r| r.detection);
    assert_eq!(v.track.d.contains(&1), detected);
    // Plume frames every 60 s from the first step: 0.1, 60.1, ..., 360.1 s.
    let plume = page.plume.as_ref().unwrap();
    assert_eq!(plume.t.len(), 7, "{:?}", plume.t);
    assert_eq!(plume.levels.len(), 7);
    assert!(
        plume
            .levels
            .iter()
            .all(|l| l.len() == (plume.nx * plume.ny).div_ceil(3) * 4)
    );
    assert!(
        plume
            .flow
            .iter()
            .all(|f| f.len() == 2 * plume.flow_nx * plume.flow_ny)
    );
    assert!(plume.max_concentration > 0.0);
    // The events of the run, all of them.
    assert_eq!(page.events.len(), run.events.len());
    let html = page.html().unwrap();
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(html.contains("<title>fault</title>"));
}

#[test]
fn a_replayed_log_makes_a_page_of_the_logged_track_and_the_replayed_behaviours() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("log.jsonl.gz");
    let sc = shortened("demo", 2000.0, 300.0, 5);
    let mut mission =
        Mission::new(MissionSetup::new(sc).unwrap(), MissionOptions::default()).unwrap();
    let header = Header::new(
        "demo",
        mission.seed(),
        &mission.vehicle_names(),
        mission.planned(),
    )
    .unwrap();
    mission
        .observe(Box::new(SnapshotLogWriter::create(&path, &header).unwrap()))
        .unwrap();
    mission.run(&mut |_, _| {}).unwrap();
    let run = mission.finish().unwrap();
    let mut builder = LogPageBuilder::default();
    let report = replay_with(open(&path).unwrap(), &|_| None, &mut |r| builder.add(r)).unwrap();
    assert_eq!(report.differing, 0);
    let page = builder.page("replay", "same planner");
    assert_eq!(page.vehicles.len(), 1);
    let v = &page.vehicles[0];
    assert_eq!(v.planner.as_deref(), Some("amp"));
    assert!(v.track.tx.is_empty(), "a log has no truth");
    assert!(page.plume.is_none() && page.sources.is_empty());
    assert_eq!(v.track.ex.len(), v.track.t.len());
    // The same behaviours in the same order as the run recorded.
    let switches = |events: &[serde_json::Value]| -> Vec<String> {
        events
            .iter()
            .filter(|e| e["event"] == "behaviour")
            .map(|e| e["behaviour"].as_str().unwrap_or("").to_string())
            .collect()
    };
    let from_run = PageData::from_run(&run, "run");
    assert!(!switches(&page.events).is_empty());
    assert_eq!(switches(&page.events), switches(&from_run.events));
    assert_eq!(page.op_area, from_run.op_area);
    assert!(page.html().is_ok());
    // The same planner decides the same: no divergence to mark.
    assert!(page.replayed && page.divergence.is_none());
    // Another planner decides otherwise at some point, which the page marks.
    let mut other = LogPageBuilder::default();
    let lawnmower: toml::Table = "kind = \"lawnmower\"".parse().unwrap();
    let report = replay_with(
        open(&path).unwrap(),
        &|_| Some(lawnmower.clone()),
        &mut |r| other.add(r),
    )
    .unwrap();
    assert!(report.differing > 0);
    let page = other.page("replay", "lawnmower");
    let d = page.divergence.as_ref().expect("the first divergence");
    assert_eq!(d.t_s, (report.first[0].t_s * 10.0).round() / 10.0);
    let html = page.html().unwrap();
    assert!(html.contains("\"divergence\":{\"t_s\""));
    assert!(html.contains("'data-divergence'"));
    // A log says nothing of the sensor's unit: the page assumes none.
    assert!(page.vehicles.iter().all(|v| v.unit.is_empty()));
}

#[test]
fn the_page_names_the_sensors_unit_and_says_the_outcome_once() {
    let run = run_mission(shortened("demo", 2000.0, 1500.0, 1), &mut |_, _| {}).unwrap();
    let page = PageData::from_run(&run, "demo");
    assert_eq!(page.vehicles[0].unit, "V");
    assert!(
        !page.subtitle.contains("declared: declared"),
        "{}",
        page.subtitle
    );
    if run.summary.first_declaration.is_some() {
        assert!(
            page.subtitle.starts_with("declared at "),
            "{}",
            page.subtitle
        );
    }
    let html = page.html().unwrap();
    // The timeline's rows are labelled, the legend's keys are the marks they name, event
    // lines are not cut.
    for s in [
        "data-timeline-rows",
        "keyCanvas(it[0], it[2])",
        "overflow-wrap: anywhere",
    ] {
        assert!(html.contains(s), "{s}");
    }
    assert!(!html.contains("text-overflow: ellipsis"));
}
