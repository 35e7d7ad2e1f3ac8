//! Missions end to end on shortened presets and small scenarios: no panics, reproducible, sane
//! summaries, several vehicles, replayable logs.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_core::{BehaviourKind, PlannerEvent, VehicleKind};
use plumetrace_log::snapshot::{Header, open, replay};
use plumetrace_mission::snapshot_log::SnapshotLogWriter;
use plumetrace_mission::{
    EndReason, EventKind, Mission, MissionOptions, MissionSetup, Outcome, VehicleStatus,
    run_mission,
};
use plumetrace_planner::PlannerKind;
use plumetrace_scenario::{Origin, PRESETS, ScenarioConfig, build, load_preset};

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

/// Every behaviour and declaration rule in the run's events is one its vehicle's planner declares
/// in the registry (`avoid` too, for planners flying with obstacle avoidance).
fn reports_only_what_its_planner_declares(
    run: &plumetrace_mission::MissionRun,
    label: &str,
) -> usize {
    let mut rules = 0;
    for e in &run.events {
        let EventKind::Planner(event) = &e.event else {
            continue;
        };
        let kind = run.vehicles[e.vehicle as usize]
            .planner
            .unwrap_or_else(|| panic!("{label}: an event of a vehicle without a planner"));
        let entry = plumetrace_planner::planners::entry(kind);
        match event {
            PlannerEvent::Behaviour { behaviour } => assert!(
                entry.behaviours.contains(behaviour) || *behaviour == BehaviourKind::Avoid,
                "{label}: {kind} reported {behaviour:?}, which it does not declare"
            ),
            PlannerEvent::Declared { rule, .. } => {
                rules += 1;
                assert!(
                    entry.rules.iter().any(|r| r.rule == *rule),
                    "{label}: {kind} declared with '{rule}', which it does not declare"
                );
            }
            _ => {}
        }
    }
    rules
}

#[test]
fn planners_report_the_behaviours_and_rules_they_declare() {
    for name in [
        "demo-survey",
        "demo-infotaxis",
        "li-zhang-open",
        "soares-freshwater",
    ] {
        let mut cfg = load_preset(name).unwrap();
        shorten(&mut cfg, 1500.0, 3000.0);
        let sc = build(&cfg, &Origin::Preset(name.into()), Some(2)).unwrap();
        let run = run_mission(sc, &mut |_, _| {}).unwrap();
        assert!(
            reports_only_what_its_planner_declares(&run, name) > 0,
            "{name}: no declaration to check ({:?})",
            run.outcome
        );
    }
}

#[test]
fn every_mission_preset_runs_without_panicking() {
    for p in PRESETS {
        let cfg = load_preset(p.name).unwrap();
        if cfg.mission.is_none() {
            continue;
        }
        let run = run_mission(shortened(p.name, 1500.0, 120.0, 3), &mut |_, _| {}).unwrap();
        reports_only_what_its_planner_declares(&run, p.name);
        let s = &run.summary;
        assert!(
            s.sim_time_s > 0.0 && s.sim_time_s <= 120.0 + 1e-9,
            "{}: {}",
            p.name,
            s.sim_time_s
        );
        // 40 m: in Li and Zhang's 1 m/s current a 1.2 m/s vehicle searching across and up the
        // flow makes about 0.5 m/s over the ground; a formation cruises at 0.25 m/s (25 m).
        let least = if s.team.is_some() { 25.0 } else { 40.0 };
        assert!(
            s.path_length_m > least,
            "{}: the vehicle barely moved ({} m)",
            p.name,
            s.path_length_m
        );
        assert!(
            !run.trajectory.is_empty()
                && run
                    .events
                    .iter()
                    .any(|e| matches!(e.event, EventKind::Planner(_) | EventKind::Telemetry(_)))
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
fn a_mission_that_does_not_time_its_stages_flies_the_same() {
    // Stage timing off (as campaigns fly): the same summary and trajectory, every stage at zero;
    // on, the stages that run every step took some time.
    let fly = |stage_times: bool| {
        let setup = MissionSetup::new(shortened("demo", 600.0, 300.0, 7)).unwrap();
        let options = MissionOptions {
            stage_times,
            ..MissionOptions::default()
        };
        let mut m = Mission::new(setup, options).unwrap();
        m.run(&mut |_, _| {}).unwrap();
        m.finish().unwrap()
    };
    let (on, off) = (fly(true), fly(false));
    let digest = |r: &plumetrace_mission::MissionRun| {
        (
            serde_json::to_string(&r.summary).unwrap(),
            serde_json::to_string(&r.trajectory).unwrap(),
        )
    };
    assert_eq!(digest(&on), digest(&off));
    // Every stage, by name.
    let all = |t: &plumetrace_sim::StageTimes| -> Vec<(String, f64)> {
        let v = serde_json::to_value(t).unwrap();
        let fields = v.as_object().unwrap().iter();
        fields
            .map(|(k, s)| (k.clone(), s.as_f64().unwrap()))
            .collect()
    };
    let (timed, untimed) = (all(&on.stage_times), all(&off.stage_times));
    assert_eq!(timed.len(), 8);
    assert!(untimed.iter().all(|(_, s)| *s == 0.0), "{untimed:?}");
    assert!(
        timed.iter().all(|(_, s)| s.is_finite() && *s >= 0.0),
        "{timed:?}"
    );
    assert!(on.stage_times.advance_environment_s > 0.0 && on.stage_times.sense_s > 0.0);
}

#[test]
fn the_demo_finds_the_plume_and_traces_it_towards_the_source() {
    let run = run_mission(shortened("demo", 3500.0, 900.0, 1), &mut |_, _| {}).unwrap();
    let s = &run.summary;
    assert!(
        s.first_detection_s.is_some_and(|t| t < 300.0),
        "first detection at {:?} s",
        s.first_detection_s
    );
    let src = run.sources[0];
    let closest = run
        .trajectory
        .iter()
        .map(|r| ((r.true_x_m - src.x).powi(2) + (r.true_y_m - src.y).powi(2)).sqrt())
        .fold(f64::MAX, f64::min);
    assert!(
        closest < 30.0,
        "never got within 30 m of the source: {closest}"
    );
    // Behaviours are typed from the planner to the trajectory.
    assert!(
        run.trajectory
            .iter()
            .any(|r| r.behaviour == Some(BehaviourKind::TrackIn))
    );
}

#[test]
fn bad_planner_settings_are_rejected_with_the_file_and_key_path() {
    let text =
        load_preset_text("demo").replace("kind = \"amp\"", "kind = \"amp\"\nbeta_deg = -5.0");
    let e = setup_error(&text);
    assert!(
        e.contains("scenario.toml") && e.contains("planner.beta_deg"),
        "{e}"
    );
    let text = load_preset_text("demo").replace("kind = \"amp\"", "kind = \"amp\"\nnre = 2");
    let e = setup_error(&text);
    assert!(
        e.contains("planner.nre") && e.contains("unknown field"),
        "{e}"
    );
    // Keys that are each within bounds but contradict each other.
    let text = load_preset_text("demo")
        .replace("kind = \"amp\"", "kind = \"amp\"\ntrack_flow_min_mps = 4.0");
    let e = setup_error(&text);
    assert!(
        e.contains("scenario.toml")
            && e.contains("planner.track_flow_min_mps")
            && e.contains("must be below track_flow_max_mps (3), not 4"),
        "{e}"
    );
    // The older name of `kind`: the error names the key as written.
    let text = load_preset_text("demo").replace("kind = \"amp\"", "strategy = \"butterfly\"");
    let e = setup_error(&text);
    assert!(
        e.contains("planner.strategy") && e.contains("unknown planner 'butterfly'"),
        "{e}"
    );
    // A sensor threshold on a vehicle without a planner has no effect: refused.
    let text = demo_text_with(
        &AMP_AND_SURVEY
            .replacen(
                "planner = \"survey\"",
                "[vehicles.chem_sensor]\nthreshold_v = 0.3",
                1,
            )
            .replace(
                "[planners.survey]\nkind = \"lawnmower\"\nlane_spacing_m = 60.0",
                "",
            ),
    );
    let e = setup_error(&text);
    assert!(
        e.contains("vehicles[1].chem_sensor.threshold_v") && e.contains("no planner"),
        "{e}"
    );
}

fn load_preset_text(name: &str) -> String {
    plumetrace_scenario::find_preset(name)
        .unwrap()
        .toml
        .to_string()
}

fn setup_error(text: &str) -> String {
    let origin = Origin::File("scenario.toml".into());
    let cfg = plumetrace_scenario::parse(text, &origin).unwrap();
    let sc = build(&cfg, &origin, None).unwrap();
    MissionSetup::new(sc).err().unwrap().to_string()
}

#[test]
fn a_sensor_threshold_in_an_older_file_reaches_the_planner() {
    // The demo with a threshold above any reading the plume gives: no detection at all.
    let text = load_preset_text("demo").replace(
        "heading_deg = 270.0",
        "heading_deg = 270.0\n[vehicles.chem_sensor]\nthreshold_v = 4.99",
    );
    let origin = Origin::File("scenario.toml".into());
    let mut cfg = plumetrace_scenario::parse(&text, &origin).unwrap();
    // The whole spin-up: the plume reaches the downflow edge, where the search starts.
    shorten(&mut cfg, 3500.0, 400.0);
    let setup = MissionSetup::new(build(&cfg, &origin, Some(1)).unwrap()).unwrap();
    let p = setup.planners[0].as_ref().unwrap();
    assert_eq!(p.config.detection_threshold_v(), Some(4.99));
    let mut m = Mission::new(setup, MissionOptions::default()).unwrap();
    m.run(&mut |_, _| {}).unwrap();
    let run = m.finish().unwrap();
    assert_eq!(run.summary.first_detection_s, None);
    assert!(run.trajectory.iter().all(|r| !r.detection));
    // The same run at the default threshold detects.
    let run = run_mission(shortened("demo", 3500.0, 400.0, 1), &mut |_, _| {}).unwrap();
    assert!(run.summary.first_detection_s.is_some());
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

#[test]
fn two_auvs_fly_the_amp_from_different_corners_and_are_recorded_apart() {
    let setup = demo_with(TWO_AUVS, 1500.0, 3);
    assert_eq!(setup.planners.iter().flatten().count(), 2);
    let mut m = Mission::new(setup, MissionOptions::default()).unwrap();
    let end = m.run(&mut |_, _| {}).unwrap();
    let run = m.finish().unwrap();
    let s = &run.summary;
    assert_eq!(s.vehicles.len(), 2);
    assert_eq!(s.vehicles[0].name, "north");
    assert_eq!(s.vehicles[1].planner, Some(PlannerKind::Amp));
    for v in &s.vehicles {
        assert!(v.path_length_m > 500.0, "{v:?}");
        assert!(v.first_detection_s.is_some(), "{v:?}");
    }
    // Both tracks, both event streams.
    for k in 0..2u32 {
        assert!(run.trajectory.iter().filter(|r| r.vehicle == k).count() > 1000);
        assert!(run.events.iter().any(|e| e.vehicle == k
            && matches!(e.event, EventKind::Planner(PlannerEvent::Behaviour { .. }))));
    }
    // They started on different sides and were apart at the start.
    let first = |k: u32| run.trajectory.iter().find(|r| r.vehicle == k).unwrap();
    assert!((first(0).true_y_m - first(1).true_y_m).abs() > 100.0);
    // The mission ends when both planners are done, or at the limit.
    match end.reason {
        EndReason::PlannersDone => assert!(
            s.vehicles.iter().all(|v| v.status != VehicleStatus::Active),
            "{:?}",
            s.vehicles
        ),
        EndReason::TimeLimit => assert!((end.t_s - 1500.0).abs() < 1e-6),
    }
    assert!(matches!(
        run.outcome,
        Outcome::Declared | Outcome::TimedOut | Outcome::NoDeclaration
    ));
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
fn a_surface_craft_surveys_beside_an_auv_tracing_the_plume() {
    let setup = demo_with(AMP_AND_SURVEY, 1200.0, 2);
    let kinds: Vec<PlannerKind> = setup
        .planners
        .iter()
        .flatten()
        .map(|p| p.config.kind())
        .collect();
    assert_eq!(kinds, [PlannerKind::Amp, PlannerKind::Lawnmower]);
    let mut m = Mission::new(setup, MissionOptions::default()).unwrap();
    m.run(&mut |_, _| {}).unwrap();
    let run = m.finish().unwrap();
    let behaviours = |k: u32| -> Vec<BehaviourKind> {
        let mut b: Vec<BehaviourKind> = run
            .events
            .iter()
            .filter(|e| e.vehicle == k)
            .filter_map(|e| match &e.event {
                EventKind::Planner(p) => p.behaviour(),
                _ => None,
            })
            .collect();
        b.dedup();
        b
    };
    assert!(
        behaviours(0).contains(&BehaviourKind::TrackIn),
        "{:?}",
        behaviours(0)
    );
    assert!(
        behaviours(1).starts_with(&[BehaviourKind::GoTo, BehaviourKind::Survey]),
        "{:?}",
        behaviours(1)
    );
    let boat: Vec<_> = run.trajectory.iter().filter(|r| r.vehicle == 1).collect();
    assert!(boat.len() > 1000);
    assert!(
        boat.iter().all(|r| (r.true_z_m - 8.0).abs() < 1e-9),
        "the boat stays at the surface of the 8 m deep site"
    );
    assert!(
        boat.iter()
            .any(|r| r.behaviour == Some(BehaviourKind::Survey))
    );
    let s = &run.summary;
    assert_eq!(s.vehicles[1].kind, VehicleKind::Surface);
    assert!(
        s.vehicles.iter().all(|v| v.path_length_m > 500.0),
        "{:?}",
        s.vehicles
    );
}

#[test]
fn a_vehicle_without_a_position_estimate_cannot_fly_the_amp() {
    let text = TWO_AUVS.replacen(
        "planner = \"tracer\"",
        "planner = \"tracer\"\n[vehicles.nav]\nposition_estimate = false",
        1,
    );
    let e = setup_error(&demo_text_with(&text));
    assert!(
        e.contains("vehicles[0].nav.position_estimate") && e.contains("'amp'"),
        "{e}"
    );
}

#[test]
fn replaying_a_snapshot_log_reproduces_every_decision() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("snapshots.jsonl.gz");
    let setup = MissionSetup::new(shortened("demo", 2000.0, 700.0, 5)).unwrap();
    let mut m = Mission::new(setup, MissionOptions::default()).unwrap();
    let header = Header::new(m.name(), m.seed(), &m.vehicle_names(), m.planned()).unwrap();
    m.observe(Box::new(SnapshotLogWriter::create(&path, &header).unwrap()))
        .unwrap();
    m.run(&mut |_, _| {}).unwrap();
    let run = m.finish().unwrap();
    let steps = run.trajectory.iter().filter(|r| r.vehicle == 0).count() as u64;
    let report = replay(open(&path).unwrap(), &|_| None).unwrap();
    assert_eq!(report.decisions, steps, "one decision per step");
    assert_eq!(report.differing, 0, "{:?}", report.first.first());
    // Another configuration decides differently somewhere: the replay reports it.
    let other: toml::Table = "kind = \"amp\"\nbeta_deg = 40.0".parse().unwrap();
    let report = replay(open(&path).unwrap(), &|_| Some(other.clone())).unwrap();
    assert!(report.differing > 0 && report.first[0].line >= 2);
    // A log that is not one is refused with its line.
    let bad = dir.path().join("bad.jsonl");
    std::fs::write(&bad, "{\"format\":\"x\"}\n").unwrap();
    let e = replay(open(&bad).unwrap(), &|_| None)
        .err()
        .unwrap()
        .to_string();
    assert!(e.starts_with("line 1:"), "{e}");
}

#[test]
fn the_summary_keeps_the_declaration_and_the_end_apart() {
    let run = run_mission(shortened("demo", 3500.0, 2400.0, 1), &mut |_, _| {}).unwrap();
    let s = &run.summary;
    let d = s.first_declaration.as_ref().expect("the demo declares");
    assert_eq!(s.outcome, Outcome::Declared);
    assert!(
        d.t_s < s.ended.t_s,
        "declared at {} s, ended at {} s",
        d.t_s,
        s.ended.t_s
    );
    assert_eq!(
        s.ended.reason,
        EndReason::PlannersDone,
        "the mapping ends the mission"
    );
    assert_eq!(s.vehicles[0].kind, VehicleKind::Auv);
    assert_eq!(s.vehicles[0].status, VehicleStatus::Finished);
}

#[test]
fn a_vehicle_without_a_planner_that_drifts_away_fails_nothing() {
    // A buoy-like surface craft 5 m from the domain's downflow edge, drifting out with the
    // current, beside the AMP AUV.
    let text = TWO_AUVS
        .replacen(
            "kind = \"auv\"\nname = \"north\"",
            "kind = \"surface\"\nname = \"buoy\"",
            1,
        )
        .replacen(
            "x_m = 470.0\ny_m = 60.0\nheading_deg = 270.0\nplanner = \"tracer\"",
            "x_m = 515.0\ny_m = 60.0\nheading_deg = 270.0",
            1,
        );
    assert!(text.contains("buoy") && text.contains("x_m = 515.0"));
    let setup = demo_with(&text, 300.0, 4);
    assert!(setup.planners[0].is_none() && setup.planners[1].is_some());
    let mut m = Mission::new(setup, MissionOptions::default()).unwrap();
    m.run(&mut |_, _| {}).unwrap();
    let run = m.finish().unwrap();
    let s = &run.summary;
    assert_eq!(
        s.vehicles[0].status,
        VehicleStatus::LeftDomain,
        "the buoy drifted out"
    );
    assert!(run.events.iter().any(|e| e.vehicle == 0
        && matches!(
            e.event,
            EventKind::World(plumetrace_sim::WorldEvent::Incident { .. })
        )));
    assert_eq!(
        s.outcome,
        Outcome::TimedOut,
        "the AUV flew on to the time limit: {:?}",
        s.vehicles
    );
    assert_eq!(s.ended.reason, EndReason::TimeLimit);
    assert_eq!(s.vehicles[1].status, VehicleStatus::Active);
}

#[test]
fn a_two_vehicle_log_with_a_decision_period_replays_exactly() {
    let text = TWO_AUVS.replace(
        "[planners.tracer]\nkind = \"amp\"\nmapping = false",
        "[planners.tracer]\nkind = \"amp\"\nmapping = false\n\n[planners.slow]\nkind = \"amp\"\ndecision_period_s = 0.5",
    )
    .replacen("planner = \"tracer\"", "planner = \"slow\"", 1);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("two.jsonl.gz");
    let setup = demo_with(&text, 600.0, 6);
    let mut m = Mission::new(setup, MissionOptions::default()).unwrap();
    let header = Header::new(m.name(), m.seed(), &m.vehicle_names(), m.planned()).unwrap();
    assert_eq!(header.vehicles.len(), 2);
    m.observe(Box::new(SnapshotLogWriter::create(&path, &header).unwrap()))
        .unwrap();
    m.run(&mut |_, _| {}).unwrap();
    // Too late for a second log: it would miss the first decisions.
    let late = SnapshotLogWriter::create(&dir.path().join("late.gz"), &header).unwrap();
    assert!(m.observe(Box::new(late)).is_err());
    assert!(
        !dir.path().join("late.gz").exists(),
        "nothing is left of it"
    );
    m.finish().unwrap();
    let report = replay(open(&path).unwrap(), &|_| None).unwrap();
    // 6,000 steps: the fast vehicle decides at every one, the slow one at every fifth.
    assert_eq!(report.decisions, 6000 + 1200);
    assert_eq!(report.differing, 0, "{:?}", report.first.first());
}

/// A planner from outside the registry: due east at 1 m/s, 3 m up, every second.
struct DueEast {
    asked: std::sync::Arc<std::sync::atomic::AtomicU64>,
}

impl plumetrace_core::Planner for DueEast {
    fn decide(&mut self, _: &plumetrace_core::SensorSnapshot) -> plumetrace_core::Decision {
        self.asked
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        plumetrace_core::Decision::new(
            plumetrace_core::Command {
                heading: plumetrace_core::Heading::from_deg(90.0),
                speed_mps: 1.0,
                vertical: plumetrace_core::VerticalCommand::Altitude(3.0),
            },
            plumetrace_core::PlanStatus::Running,
        )
    }
    fn decision_period_s(&self) -> f64 {
        1.0
    }
}

#[test]
fn a_replaced_planner_flies_the_vehicle_and_only_before_the_first_step() {
    let asked = std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0));
    let setup = MissionSetup::new(shortened("demo", 0.0, 60.0, 1)).unwrap();
    let mut m = Mission::new(setup, MissionOptions::default()).unwrap();
    m.replace_planner(
        0,
        Box::new(DueEast {
            asked: asked.clone(),
        }),
    )
    .unwrap();
    let missing = m.replace_planner(
        5,
        Box::new(DueEast {
            asked: asked.clone(),
        }),
    );
    assert!(missing.unwrap_err().to_string().contains("no vehicle 5"));
    m.step().unwrap();
    let late = m.replace_planner(
        0,
        Box::new(DueEast {
            asked: asked.clone(),
        }),
    );
    assert!(
        late.unwrap_err()
            .to_string()
            .contains("before the first step")
    );
    let run = {
        m.run(&mut |_, _| {}).unwrap();
        m.finish().unwrap()
    };
    // Asked about once a second for 60 s, and it flew where it said: it starts at x = 470 m heading
    // west and ends east of its start.
    let n = asked.load(std::sync::atomic::Ordering::Relaxed);
    assert!((50..=61).contains(&n), "asked {n} times");
    let last = run.trajectory.last().unwrap();
    assert!(last.true_x_m > 470.0, "x = {}", last.true_x_m);
    assert!(
        run.events
            .iter()
            .all(|e| !matches!(e.event, EventKind::Planner(_))),
        "the replacement reported nothing, so no planner events"
    );
}

#[test]
fn missions_flown_in_one_environment_give_what_they_give_alone() {
    // Two missions of seed 7 with different time limits share one environment; one of seed 8
    // cannot (another plume) and flies alone. Everything is recorded: trajectories, events, the
    // mean plume and the replay page's frames, which read the shared environment.
    let cases = [(7, 300.0), (7, 200.0), (8, 300.0)];
    let digest = |r: &plumetrace_mission::MissionRun| {
        (
            serde_json::to_string(&r.summary).unwrap(),
            serde_json::to_string(&r.trajectory).unwrap(),
            serde_json::to_string(&r.events).unwrap(),
            format!("{:?}", r.mean_plume),
            format!("{:?}", r.plume_frames.as_ref().map(|f| &f.frames)),
        )
    };
    let alone: Vec<_> = cases
        .iter()
        .map(|&(seed, limit)| {
            let r = run_mission(shortened("demo", 600.0, limit, seed), &mut |_, _| {}).unwrap();
            digest(&r)
        })
        .collect();
    let missions = cases
        .iter()
        .map(|&(seed, limit)| {
            (
                MissionSetup::new(shortened("demo", 600.0, limit, seed)).unwrap(),
                MissionOptions::default(),
            )
        })
        .collect();
    let mut order = Vec::new();
    let mut shared = vec![None; cases.len()];
    plumetrace_mission::fly_shared(missions, &mut |k, r| {
        order.push(k);
        shared[k] = Some(digest(&r.unwrap()));
    });
    // The other seed first (it cannot join), then the shorter mission, then the longer.
    assert_eq!(order, [2, 1, 0]);
    for (k, (a, b)) in alone.iter().zip(&shared).enumerate() {
        assert!(Some(a) == b.as_ref(), "mission {k} differs");
    }
    assert_ne!(alone[0].1, alone[1].1);
}

#[test]
fn dropping_unreachable_filaments_changes_no_reading() {
    // duck-2003-st's plume reaches the domain's edge, some 360 m beyond the op-area's downflow
    // edge; by default filaments more than 230 m beyond it (the cage's 30 m and the 200 m
    // margin) are dropped. A mission with a margin too large to drop anything reads the same
    // plume: every reading, track and event is the same bits.
    let setup = |margin: Option<f64>| {
        let mut cfg = load_preset("duck-2003-st").unwrap();
        let m = cfg.mission.as_mut().unwrap();
        m.time_limit_s = 900.0;
        m.drop_margin_m = margin;
        let mut s = MissionSetup::new(
            build(&cfg, &Origin::Preset("duck-2003-st".into()), Some(5)).unwrap(),
        )
        .unwrap();
        s.spin_up().unwrap();
        s
    };
    let dropped = |s: &MissionSetup| s.env.plume().filaments().unwrap().stats().dropped;
    let (with, without) = (setup(None), setup(Some(1e6)));
    assert!(dropped(&with) > 1000, "dropped {}", dropped(&with));
    assert_eq!(dropped(&without), 0);
    assert!(
        with.env.plume().filaments().unwrap().len() + 1000
            < without.env.plume().filaments().unwrap().len()
    );
    let fly = |s: MissionSetup| {
        let mut m = Mission::new(s, MissionOptions::default()).unwrap();
        m.run(&mut |_, _| {}).unwrap();
        let r = m.finish().unwrap();
        (
            serde_json::to_string(&r.summary).unwrap(),
            serde_json::to_string(&r.trajectory).unwrap(),
            serde_json::to_string(&r.events).unwrap(),
        )
    };
    let (a, b) = (fly(with), fly(without));
    assert!(a.2.contains("detection"), "the mission met the plume");
    assert!(a == b, "the missions differ");
}

/// The AMP on a vehicle whose current meter never reaches the planner (as over a front-seat link
/// without one): every snapshot's flow reading is taken out.
struct WithoutCurrentMeter(plumetrace_planner::Amp);

impl plumetrace_core::Planner for WithoutCurrentMeter {
    fn decide(&mut self, s: &plumetrace_core::SensorSnapshot) -> plumetrace_core::Decision {
        let mut s = s.clone();
        s.flow = None;
        self.0.decide(&s)
    }
}

/// The demo without a current meter, the planner given `prior_deg` as the prior flow direction:
/// the first declaration's error, m, with the flow estimated from the track over
/// `track_flow_window_s` windows (0: the prior alone).
fn demo_without_current_meter(seed: u64, track_flow_window_s: f64, prior_deg: f64) -> Option<f64> {
    let setup = MissionSetup::new(shortened("demo", 3500.0, 2400.0, seed)).unwrap();
    let area = plumetrace_guidance::OpArea::new(vec![
        plumetrace_core::Vec2::new(60.0, -80.0),
        plumetrace_core::Vec2::new(460.0, -80.0),
        plumetrace_core::Vec2::new(460.0, 80.0),
        plumetrace_core::Vec2::new(60.0, 80.0),
    ])
    .unwrap();
    let p = plumetrace_planner::AmpParams {
        mapping_lines: 3,
        mapping_length_m: 60.0,
        track_flow_window_s,
        ..plumetrace_planner::AmpParams::default()
    };
    let amp = plumetrace_planner::Amp::new(
        p,
        area,
        Vec::new(),
        plumetrace_core::Heading::from_deg(prior_deg),
    )
    .trusting_prior()
    // As the registry builds it: held points are declared before the mission's end.
    .ending_at(Some(2400.0));
    let mut m = Mission::new(setup, MissionOptions::default()).unwrap();
    m.replace_planner(0, Box::new(WithoutCurrentMeter(amp)))
        .unwrap();
    m.run(&mut |_, _| {}).unwrap();
    let run = m.finish().unwrap();
    run.summary.first_declaration.map(|d| d.error_m)
}

#[test]
fn without_a_current_meter_the_amp_reads_the_current_from_its_track() {
    // The prior 45 degrees off the demo's eastward current: from the track, every run declares
    // within 10 m (1.8-3.9 m); on the prior alone the runs declare 4.1-15.2 m away, a median
    // error over three times the track's.
    let (mut track, mut prior) = (Vec::new(), Vec::new());
    for seed in 1..=4 {
        let t = demo_without_current_meter(seed, 60.0, 135.0);
        assert!(t.is_some_and(|e| e < 10.0), "seed {seed}: {t:?}");
        track.push(t.unwrap_or(f64::INFINITY));
        prior.push(demo_without_current_meter(seed, 0.0, 135.0).unwrap_or(f64::INFINITY));
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        (v[1] + v[2]) / 2.0
    };
    let (t, p) = (median(&mut track), median(&mut prior));
    assert!(
        p > 2.0 * t,
        "median error from the track {t:.1} m, on the prior alone {p:.1} m"
    );
}

/// A planner holding a point it would declare later: due east at `speed_mps`, every second; its
/// run's end (not chosen by it) declares the point, once.
struct HoldsAPoint {
    speed_mps: f64,
    held: Option<plumetrace_core::Vec2>,
}

impl plumetrace_core::Planner for HoldsAPoint {
    fn decide(&mut self, _: &plumetrace_core::SensorSnapshot) -> plumetrace_core::Decision {
        plumetrace_core::Decision::new(
            plumetrace_core::Command {
                heading: plumetrace_core::Heading::from_deg(90.0),
                speed_mps: self.speed_mps,
                vertical: plumetrace_core::VerticalCommand::Altitude(3.0),
            },
            plumetrace_core::PlanStatus::Running,
        )
    }
    fn decision_period_s(&self) -> f64 {
        1.0
    }
    fn run_ended(&mut self, _t_s: f64) -> Vec<plumetrace_core::PlannerEvent> {
        self.held
            .take()
            .map(|pos_m| plumetrace_core::PlannerEvent::Declared {
                pos_m,
                rule: plumetrace_core::DeclarationKind::new("held"),
            })
            .into_iter()
            .collect()
    }
}

#[test]
fn a_point_held_when_the_run_ends_for_the_world_is_declared_as_on_a_vehicle() {
    let held = plumetrace_core::Vec2::new(101.0, 2.0);
    let dir = tempfile::tempdir().unwrap();
    let fly = |speed_mps: f64, limit_s: f64| {
        let setup = MissionSetup::new(shortened("demo", 0.0, limit_s, 1)).unwrap();
        let mut m = Mission::new(setup, MissionOptions::default()).unwrap();
        let planner = HoldsAPoint {
            speed_mps,
            held: Some(held),
        };
        m.replace_planner(0, Box::new(planner)).unwrap();
        let planned: Vec<bool> = m.planned().iter().map(Option::is_some).collect();
        let alog = plumetrace_mission::alog::AlogObserver::create(
            dir.path(),
            &m.vehicle_names(),
            &planned,
        )
        .unwrap();
        m.observe(Box::new(alog)).unwrap();
        m.run(&mut |_, _| {}).unwrap();
        m.finish().unwrap()
    };
    // The .alog posts the declaration too.
    let alog_declarations = || {
        let text = std::fs::read_to_string(dir.path().join("auv.alog")).unwrap();
        text.lines()
            .filter(|l| l.contains("CPT_DECLARATION"))
            .map(str::to_string)
            .collect::<Vec<_>>()
    };
    let declared = |run: &plumetrace_mission::MissionRun| -> Vec<f64> {
        run.events
            .iter()
            .filter(|e| matches!(e.event, EventKind::Planner(PlannerEvent::Declared { .. })))
            .map(|e| e.t_s)
            .collect()
    };
    // The time limit: the held point is declared at the last step, and the mission counts it.
    let run = fly(0.5, 60.0);
    let at = declared(&run);
    assert_eq!(at.len(), 1, "{at:?}");
    assert!(at[0] > 59.0, "declared at {} s", at[0]);
    assert_eq!(run.outcome, Outcome::Declared);
    assert_eq!(run.summary.declarations.len(), 1);
    let d = &run.summary.declarations[0];
    assert_eq!((d.x_m, d.y_m), (held.x, held.y));
    let posted = alog_declarations();
    assert_eq!(posted.len(), 1, "{posted:?}");
    assert!(
        posted[0].contains("x=101.00,y=2.00,rule=held"),
        "{posted:?}"
    );
    // Leaving the domain (east edge 50 m from the start at 2.5 m/s) ends the run: the point is
    // declared after the incident, once, and the outcome stays the failure.
    let run = fly(2.5, 600.0);
    assert_eq!(run.outcome, Outcome::LeftDomain);
    let at = declared(&run);
    assert_eq!(at.len(), 1, "{at:?}");
    let left = run
        .events
        .iter()
        .position(|e| {
            matches!(
                e.event,
                EventKind::World(plumetrace_sim::WorldEvent::Incident { .. })
            )
        })
        .unwrap();
    let decl = run
        .events
        .iter()
        .position(|e| matches!(e.event, EventKind::Planner(PlannerEvent::Declared { .. })))
        .unwrap();
    assert!(decl > left, "the declaration comes after the incident");
    assert!(at[0] < 100.0, "declared at {} s, when it left", at[0]);
    assert_eq!(run.summary.declarations.len(), 1);
}
