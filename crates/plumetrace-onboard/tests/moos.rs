//! The MOOS link against an in-process fake MOOSDB (a TCP listener thread speaking the wire
//! format of `plumetrace_onboard::moos::wire`): the handshake, registrations, navigation in,
//! set-points out, a registered planner flying a simple simulated vehicle in the loop, pauses on
//! stale navigation, lock-step time from the postings, reconnection after the server drops the
//! connection or sends an unreadable stream, a refused name, the manual override, and bad packets
//! counted and never acted on.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_onboard::config::Onboard;
use plumetrace_onboard::moos::wire::{
    Framer, Message, PROTOCOL_LEN, data, decode_packet, encode_packet, kind, protocol_bytes,
    unix_now,
};
use plumetrace_onboard::runner::{self, RunEnd, RunReport};
use std::collections::BTreeSet;
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::time::{Duration, Instant};

/// The fake server's clock runs this far ahead of the test's (its welcome says so, and its
/// timing replies agree).
const SERVER_AHEAD_S: f64 = 0.25;

/// What the fake server does, in seconds since it started.
#[derive(Clone, Default)]
struct Script {
    /// No `NAV_*` in `[from, to)` (the chemical variable and timing replies go on).
    silent: Option<(f64, f64)>,
    /// Close the connection at these times (then accept the next one).
    close_at: Vec<f64>,
    /// Send a packet whose length field is negative at this time (an unreadable stream).
    bad_length_at: Option<f64>,
    /// Send bad traffic at this time: a packet with an unknown message type, then a packet with
    /// `NAV_X` as a non-number, `NAV_HEADING` as NaN and an unregistered variable.
    garbage_at: Option<f64>,
    /// Refuse the first connection with a poison message (a name already taken).
    poison_first: bool,
    /// `MOOS_MANUAL_OVERRIDE` is `true` in `[from, to)` (posted at both ends).
    manual_override: Option<(f64, f64)>,
    /// At each registration, send the variable's stored value posted this many seconds ago
    /// (as a MOOSDB does), for the navigation variables.
    stored_age_s: Option<f64>,
    /// At the registration of the chemical variable, send a stored string of more than 1 MiB.
    huge_stored_value: bool,
    /// The consolidation period in the timing replies, s.
    consolidation_s: f64,
    /// The welcome names this computer's host (a MOOSDB on the same host).
    same_host: bool,
    /// The first timing reply's clock is this far off.
    first_reply_off_s: f64,
    /// Stop serving.
    end_at: f64,
}

/// A message the server received, with when (server seconds) and on which connection.
#[derive(Debug, Clone)]
struct Seen {
    t: f64,
    unix: f64,
    conn: usize,
    m: Message,
}

#[derive(Debug, Default)]
struct Record {
    protocols: Vec<Vec<u8>>,
    handshakes: Vec<Message>,
    seen: Vec<Seen>,
}

impl Record {
    fn values(&self, key: &str) -> Vec<&Seen> {
        self.seen
            .iter()
            .filter(|s| s.m.kind == kind::NOTIFY && s.m.key == key)
            .collect()
    }
}

/// A simple vehicle the server flies from the client's set-points.
struct Vehicle {
    x: f64,
    y: f64,
    heading: f64,
    speed: f64,
}

fn read_exact_timeout(s: &mut TcpStream, n: usize, until: Instant) -> Option<Vec<u8>> {
    let mut out = vec![0u8; n];
    let mut got = 0;
    while got < n {
        if Instant::now() > until {
            return None;
        }
        match s.read(&mut out[got..]) {
            Ok(0) => return None,
            Ok(k) => got += k,
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) => {}
            Err(_) => return None,
        }
    }
    Some(out)
}

fn notify(key: &str, v: f64, t: f64) -> Message {
    let mut m = Message::with_double(kind::NOTIFY, key, v, t);
    m.source = "uSimMarine".into();
    m.community = "#1".into();
    m
}

/// Starts the fake MOOSDB; returns its port and the thread that returns what it saw.
fn fake_moosdb(script: Script) -> (u16, std::thread::JoinHandle<Record>) {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    listener.set_nonblocking(true).unwrap();
    let handle = std::thread::spawn(move || {
        let start = Instant::now();
        let now = || start.elapsed().as_secs_f64();
        let moos_now = || unix_now() + SERVER_AHEAD_S;
        let mut rec = Record::default();
        let mut v = Vehicle {
            x: 100.0,
            y: 0.0,
            heading: 90.0,
            speed: 1.0,
        };
        let mut closes = script.close_at.clone();
        let mut bad_length = script.bad_length_at;
        let mut garbage = script.garbage_at;
        let mut overrides: Vec<(f64, &str)> = script
            .manual_override
            .map(|(a, b)| vec![(a, "true"), (b, "false")])
            .unwrap_or_default();
        let mut conn = 0;
        while now() < script.end_at {
            let Ok((mut s, _)) = listener.accept() else {
                std::thread::sleep(Duration::from_millis(5));
                continue;
            };
            conn += 1;
            s.set_nonblocking(false).unwrap();
            s.set_read_timeout(Some(Duration::from_millis(5))).unwrap();
            let until = Instant::now() + Duration::from_secs(2);
            let Some(p) = read_exact_timeout(&mut s, PROTOCOL_LEN, until) else {
                continue;
            };
            rec.protocols.push(p);
            // The handshake packet: its length first.
            let Some(len) = read_exact_timeout(&mut s, 4, until) else {
                continue;
            };
            let n = i32::from_le_bytes([len[0], len[1], len[2], len[3]]) as usize;
            let Some(rest) = read_exact_timeout(&mut s, n.saturating_sub(4), until) else {
                continue;
            };
            let mut bytes = len;
            bytes.extend_from_slice(&rest);
            let hello = decode_packet(&bytes).unwrap();
            rec.handshakes.push(hello[0].clone());
            if script.poison_first && conn == 1 {
                let k = Message::with_string(
                    kind::POISON,
                    "",
                    "A client of this name (\"pPlumetrace\") already exists",
                    moos_now(),
                );
                let _ = s.write_all(&encode_packet(&[k]).unwrap());
                continue;
            }
            let mut w = Message::with_double(kind::WELCOME, "", SERVER_AHEAD_S, moos_now());
            w.string = b"asynchronous".to_vec();
            w.source_aux = if script.same_host {
                let h = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap();
                format!("hostname={}", h.trim())
            } else {
                "hostname=fake".into()
            };
            w.community = "#1".into();
            s.write_all(&encode_packet(&[w]).unwrap()).unwrap();
            let mut registered: BTreeSet<String> = BTreeSet::new();
            let mut replies = 0;
            let mut framer = Framer::default();
            let mut last_nav = f64::NEG_INFINITY;
            let mut last_step = now();
            let mut buf = [0u8; 8192];
            'conn: while now() < script.end_at {
                if closes.first().is_some_and(|c| now() >= *c) {
                    closes.remove(0);
                    break 'conn;
                }
                if bad_length.is_some_and(|b| now() >= b) {
                    bad_length = None;
                    let _ = s.write_all(&(-5i32).to_le_bytes());
                    let _ = s.write_all(&[0u8; 40]);
                    // The client is expected to hang up; wait for it.
                    let until = Instant::now() + Duration::from_secs(2);
                    while Instant::now() < until {
                        match s.read(&mut buf) {
                            Ok(0) => break,
                            Ok(_) => {}
                            Err(e)
                                if matches!(
                                    e.kind(),
                                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                                ) => {}
                            Err(_) => break,
                        }
                    }
                    break 'conn;
                }
                if garbage.is_some_and(|g| now() >= g) {
                    garbage = None;
                    let mut bad = encode_packet(&[notify("NAV_X", 1.0, moos_now())]).unwrap();
                    // The first message's type: after the header (9) and its length and id (8).
                    bad[17] = b'Z';
                    let _ = s.write_all(&bad);
                    let mut x = Message::with_string(kind::NOTIFY, "NAV_X", "abc", moos_now());
                    x.source = "uSimMarine".into();
                    let ms = [
                        x,
                        notify("NAV_HEADING", f64::NAN, moos_now()),
                        notify("NOT_REGISTERED", 1.0, moos_now()),
                    ];
                    let _ = s.write_all(&encode_packet(&ms).unwrap());
                }
                if overrides.first().is_some_and(|o| now() >= o.0) {
                    let (_, v) = overrides.remove(0);
                    let mut m =
                        Message::with_string(kind::NOTIFY, "MOOS_MANUAL_OVERRIDE", v, moos_now());
                    m.source = "uMAC".into();
                    let _ = s.write_all(&encode_packet(&[m]).unwrap());
                }
                match s.read(&mut buf) {
                    Ok(0) => break 'conn,
                    Ok(k) => framer.push(&buf[..k]),
                    Err(e)
                        if matches!(
                            e.kind(),
                            std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                        ) => {}
                    Err(_) => break 'conn,
                }
                while let Some(Ok(p)) = framer.next_packet() {
                    let Ok(ms) = decode_packet(&p) else { continue };
                    let mut reply = Vec::new();
                    for m in ms {
                        match m.kind {
                            kind::REGISTER => {
                                registered.insert(m.key.clone());
                                stored(&script, &m.key, moos_now(), &mut s);
                            }
                            kind::TIMING => {
                                let mut r = m.clone();
                                replies += 1;
                                let off = if replies == 1 {
                                    script.first_reply_off_s
                                } else {
                                    0.0
                                };
                                r.double = moos_now() + off;
                                r.double2 = script.consolidation_s;
                                reply.push(r);
                            }
                            kind::NOTIFY if m.data_type == data::DOUBLE => match m.key.as_str() {
                                "DESIRED_HEADING" => v.heading = m.double,
                                "DESIRED_SPEED" => v.speed = m.double,
                                _ => {}
                            },
                            _ => {}
                        }
                        rec.seen.push(Seen {
                            t: now(),
                            unix: unix_now(),
                            conn,
                            m,
                        });
                    }
                    if !reply.is_empty() {
                        let _ = s.write_all(&encode_packet(&reply).unwrap());
                    }
                }
                let t = now();
                let dt = t - last_step;
                last_step = t;
                let h = v.heading.to_radians();
                v.x += v.speed * h.sin() * dt;
                v.y += v.speed * h.cos() * dt;
                if t - last_nav >= 0.1 {
                    last_nav = t;
                    let silent = script.silent.is_some_and(|(a, b)| t >= a && t < b);
                    let tm = moos_now();
                    let mut ms = Vec::new();
                    if !silent {
                        for (key, val) in [
                            ("NAV_X", v.x),
                            ("NAV_Y", v.y),
                            ("NAV_HEADING", v.heading),
                            ("NAV_SPEED", v.speed),
                            ("NAV_DEPTH", 4.0),
                            ("NAV_ALTITUDE", 6.0),
                        ] {
                            ms.push(notify(key, val, tm));
                        }
                    }
                    ms.push(notify("CHEM_READING", 0.0, tm));
                    ms.retain(|m| registered.contains(&m.key));
                    if !ms.is_empty() && s.write_all(&encode_packet(&ms).unwrap()).is_err() {
                        break 'conn;
                    }
                }
            }
        }
        rec
    });
    (port, handle)
}

/// What a MOOSDB sends at a registration under `script`: the stored value.
fn stored(script: &Script, key: &str, now: f64, s: &mut TcpStream) {
    if let Some(age) = script.stored_age_s.filter(|_| key.starts_with("NAV_")) {
        let v = if key == "NAV_X" { 100.0 } else { 1.0 };
        let _ = s.write_all(&encode_packet(&[notify(key, v, now - age)]).unwrap());
    }
    if script.huge_stored_value && key == "CHEM_READING" {
        let mut m = Message::with_string(kind::NOTIFY, key, &"9".repeat(1_100_000), now - 30.0);
        m.source = "uSensor".into();
        // Framed by hand: more than the encoder writes.
        let len = 9 + m.wire_len();
        let mut p = Vec::with_capacity(len);
        p.extend_from_slice(&(len as i32).to_le_bytes());
        p.extend_from_slice(&1i32.to_le_bytes());
        p.push(0);
        p.extend_from_slice(&message_bytes(&m));
        let _ = s.write_all(&p);
    }
}

/// A message's bytes as a packet carries them (the packet's 9-byte header removed).
fn message_bytes(m: &Message) -> Vec<u8> {
    let mut small = m.clone();
    let string = std::mem::take(&mut small.string);
    // Encode with an empty string, then patch the lengths and append the string.
    let p = encode_packet(&[small]).unwrap();
    let mut b = p[9..].to_vec();
    let total = (b.len() + string.len()) as i32;
    b[..4].copy_from_slice(&total.to_le_bytes());
    let at = b.len() - 4;
    b[at..].copy_from_slice(&(string.len() as i32).to_le_bytes());
    b.extend_from_slice(&string);
    b
}

fn onboard(port: u16, time_limit_s: f64, mode: &str) -> Onboard {
    let text = format!(
        r#"
[mission]
op_area = [[60.0, -80.0], [460.0, -80.0], [460.0, 80.0], [60.0, 80.0]]
prior_flow_toward_deg = 90.0
[planner]
kind = "amp"
[link]
protocol = "moos"
origin = {{ lat_deg = 36.18, lon_deg = -75.75 }}
stale_nav_s = 0.3
reconnect_min_s = 0.1
reconnect_max_s = 0.4
[link.moos]
host = "127.0.0.1"
port = {port}
app_name = "pPlumetrace"
chem_variable = "CHEM_READING"
[run]
time_limit_s = {time_limit_s}
mode = "{mode}"
"#
    );
    Onboard::from_toml(&text).unwrap_or_else(|e| panic!("{e}"))
}

/// Flies the AMP against the fake server; returns the run's report, what the server saw and
/// the traffic log.
fn fly(script: Script, time_limit_s: f64) -> (RunReport, Record, String) {
    fly_in(script, time_limit_s, "real_time")
}

/// [`fly`] with the run's `mode`.
fn fly_in(script: Script, time_limit_s: f64, mode: &str) -> (RunReport, Record, String) {
    let (port, server) = fake_moosdb(Script {
        end_at: time_limit_s + 1.0,
        ..script
    });
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("link.log");
    let o = onboard(port, time_limit_s, mode);
    let traffic = std::fs::File::create(&log).unwrap();
    let mut link = runner::link_for(&o, Some(Box::new(traffic))).unwrap();
    let report = runner::run(&o, &mut *link, None, &mut |_, _| {}).unwrap();
    drop(link);
    let rec = server.join().unwrap();
    let text = std::fs::read_to_string(&log).unwrap();
    (report, rec, text)
}

#[test]
fn a_registered_planner_flies_against_a_fake_moosdb() {
    let (report, rec, log) = fly(
        Script {
            garbage_at: Some(1.0),
            ..Script::default()
        },
        3.0,
    );
    assert_eq!(report.end, RunEnd::TimeLimit);
    assert_eq!(report.connections, 1);
    // The handshake: the protocol name, then the name as an asynchronous client.
    assert_eq!(rec.protocols, vec![protocol_bytes().to_vec()]);
    let h = &rec.handshakes[0];
    assert_eq!((h.kind, h.data_type), (kind::DATA, data::STRING));
    assert_eq!(h.key, "asynchronous");
    assert_eq!(h.text(), Some("pPlumetrace"));
    // Registrations: every navigation variable and the chemical one, interval 0, our name.
    let regs: BTreeSet<&str> = rec
        .seen
        .iter()
        .filter(|s| s.m.kind == kind::REGISTER)
        .inspect(|s| {
            assert_eq!(s.m.source, "pPlumetrace");
            assert_eq!(s.m.double, 0.0);
        })
        .map(|s| s.m.key.as_str())
        .collect();
    for v in [
        "NAV_X",
        "NAV_Y",
        "NAV_HEADING",
        "NAV_SPEED",
        "NAV_DEPTH",
        "NAV_ALTITUDE",
        "CHEM_READING",
        "MOOS_MANUAL_OVERRIDE",
    ] {
        assert!(regs.contains(v), "{v} not registered: {regs:?}");
    }
    // Navigation arrived at 10 Hz and the planner answered with finite set-points.
    assert!(report.nav_records >= 15, "{report:?}");
    assert!(report.decisions >= 5, "{report:?}");
    let heading = rec.values("DESIRED_HEADING");
    let speed = rec.values("DESIRED_SPEED");
    let depth = rec.values("DESIRED_DEPTH");
    assert!(heading.len() >= 5, "{} headings", heading.len());
    // One speed per heading, and the stop at the end of the run.
    assert_eq!(heading.len() + 1, speed.len());
    assert_eq!(speed.last().map(|s| s.m.double), Some(0.0));
    assert_eq!(
        rec.values("CPT_STATUS").last().and_then(|s| s.m.text()),
        Some("ended")
    );
    for s in &heading {
        assert!((0.0..360.0).contains(&s.m.double), "{:?}", s.m);
    }
    for s in &speed {
        assert!(s.m.double.is_finite() && (0.0..=2.5).contains(&s.m.double));
    }
    // The AMP holds an altitude: it goes out as a depth over the water depth (4 + 6 m).
    assert!(!depth.is_empty());
    for s in &depth {
        assert!((0.0..=10.0).contains(&s.m.double), "{:?}", s.m);
    }
    // Postings carry the client's name, increasing ids and the server's time (the skew).
    let ids: Vec<i32> = heading.iter().map(|s| s.m.id).collect();
    assert!(ids.windows(2).all(|w| w[0] < w[1]), "{ids:?}");
    for s in heading.iter().chain(&speed) {
        assert_eq!(s.m.source, "pPlumetrace");
    }
    // Heartbeats: a timing message about once a second.
    let timings = rec.seen.iter().filter(|s| s.m.kind == kind::TIMING).count();
    assert!((2..=5).contains(&timings), "{timings} timing messages");
    // pMarineViewer draws the op-area: posted once, at the connection.
    let polygons = rec.values("VIEW_POLYGON");
    assert_eq!(polygons.len(), 1, "{polygons:?}");
    assert_eq!(
        polygons[0].m.text(),
        Some(
            "pts={60.00,-80.00:460.00,-80.00:460.00,80.00:60.00,80.00},label=cpt_op_area,edge_color=yellow,vertex_color=yellow,vertex_size=2,edge_size=1"
        )
    );
    // The AMP's estimate, once it has one, as a marker.
    for m in rec.values("VIEW_MARKER") {
        assert!(
            m.m.text().is_some_and(
                |t| t.starts_with("type=diamond,x=") && t.contains(",label=cpt_estimate,")
            ),
            "{m:?}"
        );
    }
    // The behaviour went out as the .alog writer names it.
    let behaviour = rec.values("CPT_BEHAVIOUR");
    assert!(!behaviour.is_empty());
    assert!(
        behaviour[0]
            .m
            .text()
            .is_some_and(|t| !t.is_empty() && t != "?")
    );
    // The bad traffic was counted and logged, never acted on.
    let r = &report.lines.rejected;
    assert_eq!(r.get("bad_type"), Some(&1), "{r:?}");
    assert_eq!(r.get("bad_field"), Some(&2), "{r:?}");
    assert_eq!(r.get("unknown"), Some(&1), "{r:?}");
    assert!(report.lines.accepted > 100);
    // One bad message costs only itself (libMOOS reads the rest of its packet).
    assert!(
        log.contains(" ! a message: unknown message type 0x5a"),
        "{log}"
    );
    assert!(log.contains(" > N DESIRED_HEADING D"), "{log}");
    assert!(log.contains(" < N NAV_X D"), "{log}");
    // Set-points were stamped with the server's clock: the welcome's skew, kept by the timing
    // replies (the server runs 0.25 s ahead of this process's clock).
    for s in heading.iter().chain(&speed) {
        let ahead = s.m.time - s.unix;
        assert!(
            (ahead - SERVER_AHEAD_S).abs() < 0.1,
            "posted {ahead:.3} s ahead of the receipt"
        );
    }
}

#[test]
fn a_refused_name_is_retried_and_the_manual_override_pauses_the_planner() {
    let (report, rec, log) = fly(
        Script {
            poison_first: true,
            manual_override: Some((1.2, 1.8)),
            ..Script::default()
        },
        3.0,
    );
    // Refused once (not a connection for the runner), welcomed the second time.
    assert_eq!(rec.handshakes.len(), 2);
    assert_eq!(report.connections, 1, "{report:?}");
    assert!(log.contains("the MOOSDB refused the client"), "{log}");
    let held: Vec<_> = report
        .pauses
        .iter()
        .filter(|p| p.reason.contains("does not accept commands"))
        .collect();
    assert_eq!(held.len(), 1, "{:?}", report.pauses);
    let paused = rec.values("CPT_PAUSED");
    assert_eq!(paused.len(), 2, "{paused:?}");
    let (t_on, t_off) = (paused[0].t, paused[1].t);
    assert!((1.2..1.8).contains(&t_on), "paused at {t_on}");
    assert!(t_off >= 1.8, "resumed at {t_off}");
    assert!(
        rec.values("DESIRED_HEADING")
            .iter()
            .all(|s| s.t < t_on || s.t >= t_off)
    );
}

#[test]
fn stale_navigation_pauses_the_planner_and_publishes_the_stop() {
    let (report, rec, _) = fly(
        Script {
            silent: Some((1.0, 2.0)),
            ..Script::default()
        },
        3.5,
    );
    let stale: Vec<_> = report
        .pauses
        .iter()
        .filter(|p| p.reason.starts_with("navigation older than 0.3 s"))
        .collect();
    assert_eq!(stale.len(), 1, "{:?}", report.pauses);
    let start = stale[0].start_s;
    let end = stale[0].end_s.unwrap();
    assert!(end - start > 0.4, "paused {start} to {end}");
    // During the pause: DESIRED_SPEED = 0 and CPT_PAUSED = true went out once, and no
    // set-point but that stop; after it CPT_PAUSED = false and the set-points again.
    let paused = rec.values("CPT_PAUSED");
    let texts: Vec<&str> = paused.iter().filter_map(|s| s.m.text()).collect();
    assert_eq!(texts, vec!["true", "false"], "{paused:?}");
    let (t_on, t_off) = (paused[0].t, paused[1].t);
    assert!((1.0..2.0).contains(&t_on), "paused at {t_on} (server time)");
    assert!(t_off >= 2.0, "resumed at {t_off} (server time)");
    let speeds_during: Vec<f64> = rec
        .values("DESIRED_SPEED")
        .iter()
        .filter(|s| s.t >= t_on - 1e-3 && s.t < t_off)
        .map(|s| s.m.double)
        .collect();
    assert_eq!(speeds_during, vec![0.0]);
    assert!(
        rec.values("DESIRED_HEADING")
            .iter()
            .all(|s| s.t < t_on - 1e-3 || s.t >= t_off)
    );
    assert!(
        rec.values("DESIRED_HEADING").iter().any(|s| s.t >= t_off),
        "no set-points after the pause"
    );
}

#[test]
fn a_dropped_connection_and_an_unreadable_stream_lead_to_reconnection() {
    let (report, rec, log) = fly(
        Script {
            close_at: vec![1.0],
            bad_length_at: Some(2.2),
            ..Script::default()
        },
        4.0,
    );
    assert_eq!(report.connections, 3, "{report:?}");
    assert_eq!(rec.handshakes.len(), 3);
    let lost: Vec<_> = report
        .pauses
        .iter()
        .filter(|p| p.reason.starts_with("link lost"))
        .collect();
    assert_eq!(lost.len(), 2, "{:?}", report.pauses);
    assert_eq!(report.lines.rejected.get("bad_length"), Some(&1));
    assert!(log.contains("unreadable stream"), "{log}");
    // Each connection registered again and got set-points.
    for conn in 1..=3 {
        let regs = rec
            .seen
            .iter()
            .filter(|s| s.conn == conn && s.m.kind == kind::REGISTER)
            .count();
        assert_eq!(regs, 8, "connection {conn}");
        assert!(
            rec.values("DESIRED_HEADING").iter().any(|s| s.conn == conn),
            "no set-points on connection {conn}"
        );
    }
}

/// In lock-step mission time is the MOOS time of the postings and every navigation record
/// gets its set-points back.
#[test]
fn in_lock_step_mission_time_comes_from_the_postings() {
    let (report, rec, _) = fly_in(Script::default(), 2.0, "lock_step");
    assert_eq!(report.end, RunEnd::TimeLimit, "{report:?}");
    // The time limit is reached on the postings' clock (they come every 0.1 s).
    assert!((2.0..2.3).contains(&report.time_s), "{}", report.time_s);
    assert!(report.nav_records >= 15, "{report:?}");
    // One command per record once the first decision is made.
    assert!(
        report.commands_sent + 1 >= report.nav_records,
        "{} commands for {} records",
        report.commands_sent,
        report.nav_records
    );
    assert_eq!(
        rec.values("DESIRED_HEADING").len() as u64,
        report.commands_sent
    );
}

/// A stored value larger than 1 MiB (MOOS sets no limit) is skipped, not a reason to reconnect:
/// the MOOSDB would send it again at every registration.
#[test]
fn a_stored_value_over_a_mebibyte_is_skipped_and_the_connection_stays() {
    let (report, rec, log) = fly(
        Script {
            huge_stored_value: true,
            ..Script::default()
        },
        3.0,
    );
    assert_eq!(rec.handshakes.len(), 1, "{log}");
    assert_eq!(report.connections, 1, "{report:?}");
    assert_eq!(
        report.lines.rejected.get("too_large"),
        Some(&1),
        "{report:?}"
    );
    assert_eq!(report.end, RunEnd::TimeLimit);
    assert!(report.decisions >= 5, "{report:?}");
    assert_eq!(
        rec.values("CPT_STATUS").last().and_then(|s| s.m.text()),
        Some("ended")
    );
}

/// The values a MOOSDB stores and sends at registration are as old as their MOOS time says:
/// 49.8 s old, they make no navigation record.
#[test]
fn stored_navigation_older_than_the_limit_is_not_steered_on() {
    let (report, rec, _) = fly(
        Script {
            stored_age_s: Some(49.8),
            silent: Some((0.0, 1.5)),
            ..Script::default()
        },
        3.0,
    );
    let early: Vec<f64> = rec
        .values("DESIRED_HEADING")
        .iter()
        .map(|s| s.t)
        .filter(|t| *t < 1.5)
        .collect();
    assert!(early.is_empty(), "steered on stale values at {early:?}");
    assert!(
        report.lines.rejected.get("stale").is_some_and(|n| *n >= 6),
        "{report:?}"
    );
    assert!(rec.values("DESIRED_HEADING").iter().any(|s| s.t >= 1.5));
}

/// A pause published before the connection was lost is ended in the community when the
/// planner steers again on the next connection.
#[test]
fn cpt_paused_goes_back_to_false_after_a_reconnection() {
    let (_, rec, _) = fly(
        Script {
            silent: Some((1.0, 2.0)),
            close_at: vec![1.6],
            ..Script::default()
        },
        3.5,
    );
    let paused = rec.values("CPT_PAUSED");
    let texts: Vec<(usize, &str)> = paused
        .iter()
        .filter_map(|s| Some((s.conn, s.m.text()?)))
        .collect();
    assert_eq!(texts, vec![(1, "true"), (2, "false")], "{paused:?}");
}

/// The consolidation period in the timing replies paces outgoing mail, as libMOOS's writing
/// thread does.
#[test]
fn the_consolidation_period_paces_the_set_points() {
    let (report, rec, log) = fly(
        Script {
            consolidation_s: 0.5,
            ..Script::default()
        },
        4.0,
    );
    let times: Vec<f64> = rec.values("DESIRED_HEADING").iter().map(|s| s.t).collect();
    assert!(times.len() >= 4, "{times:?}");
    // After the first reply set the period, packets are 0.5 s apart on average (the server's
    // receipt times jitter on a loaded machine).
    let gaps: Vec<f64> = times
        .windows(2)
        .filter(|w| w[0] > 1.5)
        .map(|w| w[1] - w[0])
        .collect();
    let mean = gaps.iter().sum::<f64>() / gaps.len().max(1) as f64;
    assert!(gaps.len() >= 3 && mean >= 0.45, "{gaps:?}");
    assert!(gaps.iter().all(|g| *g >= 0.25), "{gaps:?}");
    assert!(report.decisions as usize > times.len(), "{report:?}");
    // The period is written to the traffic log once, when it changes.
    assert_eq!(
        log.matches("# consolidation period 0.500 s (the MOOSDB's timing reply)")
            .count(),
        1,
        "{log}"
    );
}

/// A MOOSDB on this host: no skew correction (libMOOS turns it off), so postings carry this
/// computer's clock even though the welcome says 0.25 s.
#[test]
fn no_skew_correction_for_a_moosdb_on_this_host() {
    let (_, rec, log) = fly(
        Script {
            same_host: true,
            ..Script::default()
        },
        2.0,
    );
    assert!(
        log.contains("not estimated: the MOOSDB is on this host"),
        "{log}"
    );
    for s in rec.values("DESIRED_HEADING") {
        let ahead = s.m.time - s.unix;
        assert!(ahead.abs() < 0.1, "posted {ahead:.3} s ahead");
    }
}

/// The first timing reply does not count towards the skew (libMOOS skips it): one that is 5 s
/// off leaves the set-points stamped with the welcome's skew.
#[test]
fn the_first_timing_reply_does_not_move_the_skew() {
    let (_, rec, _) = fly(
        Script {
            first_reply_off_s: 5.0,
            ..Script::default()
        },
        3.0,
    );
    let heading = rec.values("DESIRED_HEADING");
    assert!(heading.len() >= 5);
    for s in heading {
        let ahead = s.m.time - s.unix;
        assert!(
            (ahead - SERVER_AHEAD_S).abs() < 0.1,
            "posted {ahead:.3} s ahead"
        );
    }
}

#[test]
fn the_link_names_the_process_posting_the_navigation() {
    let (port, server) = fake_moosdb(Script {
        end_at: 2.0,
        ..Script::default()
    });
    let o = onboard(port, 1.0, "real_time");
    let mut link = runner::link_for(&o, None).unwrap();
    let name = link.sensor_source().unwrap();
    assert_eq!(*name.lock().unwrap(), "", "not known before any posting");
    let mut seen = Vec::new();
    let report = runner::run(&o, &mut *link, None, &mut |_, _| {
        seen.push(name.lock().unwrap().clone());
    })
    .unwrap();
    drop(link);
    server.join().unwrap();
    assert!(report.decisions > 0);
    // Known by the first decision: the source of the NAV_X postings (run.alog's source column).
    assert!(seen.iter().all(|n| n == "uSimMarine"), "{seen:?}");
}
