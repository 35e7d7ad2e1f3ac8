//! A rehearsal in one process: the front seat flies the demo's vehicle and plume, and the onboard
//! runner (a thread, with the onboard file the rehearsal wrote) flies the AMP against it over
//! loopback TCP with the Bluefin protocol in lock-step. The command-line tests fly the two
//! processes end to end; these check the library's own pieces.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_frontseat::{FrontSeatError, FrontSeatOptions, Rehearsal};
use plumetrace_onboard::config::{Onboard, ProtocolKind, RunMode};
use plumetrace_onboard::runner::{self, RunEnd};
use plumetrace_scenario::{BuiltScenario, Origin, build, load_preset};

fn demo() -> BuiltScenario {
    let cfg = load_preset("demo").unwrap();
    build(&cfg, &Origin::Preset("demo".into()), Some(7)).unwrap()
}

fn lock_step(time_limit_s: f64) -> FrontSeatOptions {
    FrontSeatOptions {
        listen: "127.0.0.1:0".into(),
        lock_step: true,
        wait_s: 20.0,
        time_limit_s: Some(time_limit_s),
        ..FrontSeatOptions::default()
    }
}

#[test]
fn the_onboard_file_names_this_front_seat_and_reads_back() {
    let r = Rehearsal::prepare(demo(), &lock_step(60.0)).unwrap();
    let address = r.link_table()["address"].as_str().unwrap().to_string();
    assert_eq!(r.location(), format!("listening on {address}"));
    assert!(
        !address.ends_with(":0"),
        "a free port was picked: {address}"
    );
    let text = r.onboard_file().unwrap();
    assert!(text.starts_with("# Written by `plumetrace frontseat` for scenario 'demo'"));
    let o = Onboard::from_toml(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(o.file.link.protocol, ProtocolKind::Bluefin);
    assert_eq!(o.file.link.address.as_deref(), Some(address.as_str()));
    assert_eq!(o.file.link.give_up_s, 5.0);
    assert_eq!(o.file.run.mode, RunMode::LockStep);
    assert_eq!(o.file.run.time_limit_s, 60.0);
    assert_eq!(o.file.run.lock_step_period_s, 0.1);
    assert!(
        o.file.flow.is_some(),
        "the current readings travel on the link"
    );
    assert_eq!(format!("{:?}", o.planner.kind()), "Amp");

    let no_flow = FrontSeatOptions {
        flow: false,
        ..lock_step(60.0)
    };
    let text = Rehearsal::prepare(demo(), &no_flow)
        .unwrap()
        .onboard_file()
        .unwrap();
    assert!(Onboard::from_toml(&text).unwrap().file.flow.is_none());
}

#[test]
fn a_time_limit_beyond_the_scenarios_is_refused_with_its_flag() {
    let e = Rehearsal::prepare(demo(), &lock_step(1e9)).err();
    assert!(
        matches!(
            &e,
            Some(FrontSeatError::Option {
                option: "--time-limit-s",
                ..
            })
        ),
        "{e:?}"
    );
    let bad = FrontSeatOptions {
        nav_period_s: 0.0,
        ..lock_step(60.0)
    };
    assert!(matches!(
        Rehearsal::prepare(demo(), &bad),
        Err(FrontSeatError::Option {
            option: "--nav-period-s",
            ..
        })
    ));
}

#[test]
fn the_onboard_runner_flies_against_the_front_seat_in_lock_step_every_record_answered() {
    let rehearsal = Rehearsal::prepare(demo(), &lock_step(30.0)).unwrap();
    let onboard = Onboard::from_toml(&rehearsal.onboard_file().unwrap()).unwrap();
    let back_seat = std::thread::spawn(move || {
        let mut link = runner::link_for(&onboard, None).unwrap();
        let mut decisions = 0u64;
        let report = runner::run(&onboard, &mut *link, None, &mut |_, _| decisions += 1).unwrap();
        (report, decisions)
    });
    let report = rehearsal.start().unwrap().fly().unwrap();
    let (ob, decisions) = back_seat.join().unwrap();
    let fs = &report.stats;
    assert_eq!(report.name, "demo");
    assert!((report.time_s - 30.0).abs() < 0.2, "{}", report.time_s);
    assert_eq!(fs.connections, 1, "{fs:?}");
    assert!(fs.nav_records >= 290, "{fs:?}");
    assert!(fs.commands > 0, "{fs:?}");
    assert_eq!(
        (fs.unanswered, fs.bad_lines, fs.unsafe_commands),
        (0, 0, 0),
        "{fs:?}"
    );
    assert_eq!(ob.end, RunEnd::TimeLimit, "{ob:?}");
    // The front seat waits for the back seat's end: one final stop, received, and the
    // back seat's "Finished".
    assert!(fs.finished, "{fs:?}");
    assert_eq!(fs.stops, 1, "{fs:?}");
    assert!(
        ob.pauses.iter().all(|p| !p.reason.starts_with("link lost")),
        "{ob:?}"
    );
    assert_eq!(ob.lines.rejected_total(), 0, "{ob:?}");
    assert_eq!(ob.decisions, decisions);
    assert!(ob.decisions > 0 && ob.commands_sent > 0, "{ob:?}");
    // Every record the front seat sent was read, bar one after the back seat's end.
    assert!(
        fs.nav_records == ob.nav_records || fs.nav_records == ob.nav_records + 1,
        "sent {}, read {}",
        fs.nav_records,
        ob.nav_records
    );
    // What `frontseat.json` holds.
    let json = serde_json::to_value(fs).unwrap();
    for key in [
        "nav_records",
        "commands",
        "stops",
        "unsafe_commands",
        "bad_lines",
        "connections",
        "restarts",
        "unanswered",
        "finished",
        "back_seat_gone",
        "end_s",
    ] {
        assert!(json.get(key).is_some(), "{key} in {json}");
    }
}

#[test]
fn a_ten_second_front_seat_restart_is_rehearsed_to_the_time_limit() {
    let mut options = lock_step(20.0);
    options.faults.restart_at = Some(5.0);
    options.faults.restart_for = 10.0;
    let rehearsal = Rehearsal::prepare(demo(), &options).unwrap();
    let onboard = Onboard::from_toml(&rehearsal.onboard_file().unwrap()).unwrap();
    assert_eq!(onboard.file.link.give_up_s, 15.0);
    assert_eq!(onboard.file.link.reconnect_max_s, 1.0);
    let back_seat = std::thread::spawn(move || {
        let mut link = runner::link_for(&onboard, None).unwrap();
        runner::run(&onboard, &mut *link, None, &mut |_, _| {}).unwrap()
    });
    let report = rehearsal.start().unwrap().fly().unwrap();
    let ob = back_seat.join().unwrap();
    let fs = &report.stats;
    assert_eq!(ob.end, RunEnd::TimeLimit, "{ob:?}");
    assert_eq!((fs.restarts, fs.connections), (1, 2), "{fs:?}");
    assert_eq!(fs.unsafe_commands, 0, "{fs:?}");
    assert!(fs.finished, "{fs:?}");
}
