//! The world's stages with hand-made planners: incidents, non-finite commands, message delivery
//! with delay and loss, decision periods, several vehicles with different planners.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use plumetrace_core::{
    Command, Decision, Heading, Link, MessageBody, Outgoing, PlanStatus, Planner, Recipient,
    SensorSnapshot, Vec2, Vec3, VehicleId, VerticalCommand,
};
use plumetrace_env::flow::{MeanFlow, UniformFlow};
use plumetrace_env::steady::GaussianPlume;
use plumetrace_env::{Environment, FlowModel, ObstacleSet, Plume, Rect, SoftObstacle};
use plumetrace_sim::{
    ChannelParams, ChemSensorParams, CommsParams, FlowSensorParams, Incident, LossReason,
    NavParams, RangingParams, SimVehicle, Vehicle, VehicleParams, World, WorldEvent,
};

const DT: f64 = 0.1;

fn env(obstacles: Vec<SoftObstacle>) -> Environment {
    let domain = Rect::new(0.0, 200.0, 0.0, 200.0).unwrap();
    let mean = MeanFlow::Steady {
        speed_mps: 0.1,
        toward_deg: 90.0,
    };
    let plume = GaussianPlume::new(
        Vec3::new(20.0, 100.0, 0.0),
        1.0,
        0.1,
        90.0,
        0.05,
        0.01,
        Some(10.0),
    )
    .unwrap();
    Environment::new(
        domain,
        FlowModel::Uniform(UniformFlow::new(mean).unwrap()),
        Plume::Steady(Box::new(plume)),
        ObstacleSet::new(obstacles),
        DT,
        1,
    )
    .unwrap()
}

fn vehicle(
    id: u32,
    kind: plumetrace_core::VehicleKind,
    pos: (f64, f64),
    heading: f64,
) -> SimVehicle {
    let params = match kind {
        plumetrace_core::VehicleKind::Auv => VehicleParams::auv(),
        plumetrace_core::VehicleKind::Surface => VehicleParams::surface(),
    };
    SimVehicle::new(
        format!("v{id}"),
        Vehicle::new(
            VehicleId(id),
            params,
            Vec2::new(pos.0, pos.1),
            2.0,
            Heading::from_deg(heading),
        ),
        NavParams::lbl(),
        ChemSensorParams::default(),
        FlowSensorParams::default(),
        None,
        7,
    )
}

fn auv(id: u32, pos: (f64, f64), heading: f64) -> SimVehicle {
    vehicle(id, plumetrace_core::VehicleKind::Auv, pos, heading)
}

fn command(heading_deg: f64, speed_mps: f64) -> Command {
    Command {
        heading: Heading::from_deg(heading_deg),
        speed_mps,
        vertical: VerticalCommand::Altitude(2.0),
    }
}

/// Holds a heading and speed; counts its decisions and the samples it received.
struct Hold {
    command: Command,
    period_s: f64,
    decisions: std::sync::Arc<std::sync::Mutex<Vec<(f64, usize)>>>,
}

impl Planner for Hold {
    fn decide(&mut self, s: &SensorSnapshot) -> Decision {
        if let Ok(mut d) = self.decisions.lock() {
            d.push((s.time_s, s.chem.len()));
        }
        Decision::new(self.command, PlanStatus::Running)
    }

    fn decision_period_s(&self) -> f64 {
        self.period_s
    }
}

fn hold(heading_deg: f64, speed: f64) -> Box<dyn Planner> {
    Box::new(Hold {
        command: command(heading_deg, speed),
        period_s: 0.0,
        decisions: Default::default(),
    })
}

#[test]
fn a_vehicle_that_enters_kelp_or_leaves_the_domain_is_stopped_with_an_incident() {
    let kelp = SoftObstacle::new(
        "kelp",
        &[[60.0, 40.0], [80.0, 40.0], [80.0, 60.0], [60.0, 60.0]],
    )
    .unwrap();
    let mut w = World::new(
        env(vec![kelp]),
        vec![auv(0, (40.0, 50.0), 90.0), auv(1, (180.0, 150.0), 90.0)],
        DT,
        Some(10.0),
    )
    .unwrap();
    let mut planners = vec![Some(hold(90.0, 2.0)), Some(hold(90.0, 2.0))];
    let mut incidents = Vec::new();
    for _ in 0..400 {
        let r = w.step(&mut planners).unwrap();
        for (id, e) in r.events {
            if let WorldEvent::Incident { what } = e {
                incidents.push((id, what, w.time_s()));
            }
        }
    }
    assert_eq!(incidents.len(), 2, "{incidents:?}");
    let kelp_hit = incidents.iter().find(|i| i.0 == VehicleId(0)).unwrap();
    assert_eq!(kelp_hit.1, Incident::Collided);
    // 20 m at about 2 m/s (plus the current), after the speed builds up.
    assert!(kelp_hit.2 > 8.0 && kelp_hit.2 < 14.0, "{kelp_hit:?}");
    let out = incidents.iter().find(|i| i.0 == VehicleId(1)).unwrap();
    assert_eq!(out.1, Incident::LeftDomain);
    // Stopped vehicles stay where they stopped and decide no more.
    let p = w.vehicles()[0].vehicle.state.pos_m;
    let r = w.step(&mut planners).unwrap();
    assert!(r.decisions.iter().all(Option::is_none));
    assert_eq!(w.vehicles()[0].vehicle.state.pos_m, p);
    assert!(!w.vehicles()[0].active && !w.vehicles()[1].active);
}

/// Returns a good command, then a NaN speed, a NaN heading and an infinite altitude in turn.
struct Broken {
    n: u32,
}

impl Planner for Broken {
    fn decide(&mut self, _: &SensorSnapshot) -> Decision {
        self.n += 1;
        let mut c = command(0.0, 1.5);
        match self.n % 4 {
            2 => c.speed_mps = f64::NAN,
            3 => c.heading = Heading::from_rad(f64::NAN),
            0 => c.vertical = VerticalCommand::Altitude(f64::INFINITY),
            _ => {}
        }
        Decision::new(c, PlanStatus::Running)
    }
}

#[test]
fn a_non_finite_command_is_recorded_and_replaced_by_the_previous_one() {
    let mut w = World::new(
        env(vec![]),
        vec![auv(0, (100.0, 20.0), 0.0)],
        DT,
        Some(10.0),
    )
    .unwrap();
    let mut planners: Vec<Option<Box<dyn Planner>>> = vec![Some(Box::new(Broken { n: 0 }))];
    let r = w.step(&mut planners).unwrap();
    assert!(r.events.is_empty());
    assert_eq!(w.vehicles()[0].command.speed_mps, 1.5);
    let r = w.step(&mut planners).unwrap();
    assert!(
        matches!(&r.events[..], [(VehicleId(0), WorldEvent::NonFiniteCommand { command })] if command.contains("NaN")),
        "{:?}",
        r.events
    );
    assert_eq!(
        w.vehicles()[0].command.speed_mps,
        1.5,
        "the previous command stays"
    );
    let mut bad = 0;
    for _ in 0..100 {
        let r = w.step(&mut planners).unwrap();
        bad += r
            .events
            .iter()
            .filter(|(_, e)| matches!(e, WorldEvent::NonFiniteCommand { .. }))
            .count();
        let c = w.vehicles()[0].command;
        assert!(c.is_finite() && c.heading.deg() == 0.0, "{c:?}");
    }
    assert_eq!(bad, 75, "three of every four commands are bad");
    let s = w.vehicles()[0].vehicle.state;
    assert!(s.pos_m.x.is_finite() && s.pos_m.y > 20.0 && s.speed_mps > 1.0);
}

/// What a talker heard: receive time, send time, text.
type Heard = std::sync::Arc<std::sync::Mutex<Vec<(f64, f64, String)>>>;

/// Broadcasts its decision count as text over `link` at every decision; records what it hears.
struct Talker {
    link: Link,
    heard: Heard,
    n: u32,
}

impl Planner for Talker {
    fn decide(&mut self, s: &SensorSnapshot) -> Decision {
        if let Ok(mut h) = self.heard.lock() {
            for m in &s.inbox {
                if let MessageBody::Text { text } = &m.body {
                    h.push((s.time_s, m.sent_s, text.clone()));
                }
            }
        }
        self.n += 1;
        let mut d = Decision::new(command(0.0, 0.0), PlanStatus::Running);
        d.outbox.push(Outgoing {
            to: Recipient::Broadcast,
            link: self.link,
            body: MessageBody::Text {
                text: self.n.to_string(),
            },
        });
        d
    }
}

fn talkers(
    comms: CommsParams,
    link: Link,
    separation_m: f64,
) -> (World, Vec<Option<Box<dyn Planner>>>, Heard) {
    let heard = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let w = World::with_comms(
        env(vec![]),
        vec![
            auv(0, (10.0, 100.0), 0.0),
            auv(1, (10.0 + separation_m, 100.0), 0.0),
        ],
        DT,
        Some(10.0),
        comms,
        11,
    )
    .unwrap();
    let planners: Vec<Option<Box<dyn Planner>>> = vec![
        Some(Box::new(Talker {
            link,
            heard: Default::default(),
            n: 0,
        })),
        Some(Box::new(Talker {
            link,
            heard: heard.clone(),
            n: 0,
        })),
    ];
    (w, planners, heard)
}

#[test]
fn messages_arrive_after_the_channels_delay_or_are_lost() {
    // Ideal radio: a message sent at a decision arrives at the next one.
    let (mut w, mut p, heard) = talkers(CommsParams::default(), Link::Radio, 150.0);
    for _ in 0..10 {
        w.step(&mut p).unwrap();
    }
    let h = heard.lock().unwrap().clone();
    assert_eq!(h.len(), 9);
    assert!(
        h.iter().all(|(t, sent, _)| (t - sent - DT).abs() < 1e-9),
        "{h:?}"
    );
    // Acoustic: 150 m at 1500 m/s plus 0.3 s latency = 0.4 s; 20 % lost.
    let acoustic = ChannelParams {
        latency_s: 0.3,
        sound_speed_mps: Some(1500.0),
        loss_probability: 0.2,
        max_range_m: None,
        one_in_flight: false,
    };
    let comms = CommsParams {
        acoustic,
        radio: ChannelParams::IDEAL,
        ranging: RangingParams::default(),
    };
    let (mut w, mut p, heard) = talkers(comms, Link::Acoustic, 150.0);
    let mut lost = 0;
    let mut delivered = 0;
    // 300 s: the drifting vehicles stay inside the 200 m domain.
    for _ in 0..3000 {
        let r = w.step(&mut p).unwrap();

        for (id, e) in &r.events {
            match e {
                WorldEvent::MessageLost { reason, .. } if *id == VehicleId(1) => {
                    assert_eq!(*reason, LossReason::Dropped);
                    lost += 1;
                }
                WorldEvent::MessageDelivered { .. } if *id == VehicleId(1) => delivered += 1,
                _ => {}
            }
        }
    }
    let h = heard.lock().unwrap().clone();
    assert_eq!(h.len(), delivered);
    // Delivered at the first step at or after sent + 0.4 s (0.4 s is four steps; rounding
    // may put the arrival just after the fourth).
    assert!(
        h.iter()
            .all(|(t, sent, _)| t - sent > 0.4 - 1e-9 && t - sent < 0.4 + DT + 1e-9),
        "{:?}",
        &h[..3]
    );
    let sent = lost + delivered + w.messages_in_flight();
    let rate = lost as f64 / sent as f64;
    // About 3,000 messages at p = 0.2: sd 0.0073.
    assert!((rate - 0.2).abs() < 0.025, "loss rate {rate}");
    // Out of range: nothing arrives.
    let short = CommsParams {
        acoustic: ChannelParams {
            max_range_m: Some(100.0),
            ..ChannelParams::IDEAL
        },
        radio: ChannelParams::IDEAL,
        ranging: RangingParams::default(),
    };
    let (mut w, mut p, heard) = talkers(short, Link::Acoustic, 150.0);
    let r = w.step(&mut p).unwrap();
    assert!(r.events.iter().any(|(_, e)| matches!(
        e,
        WorldEvent::MessageLost {
            reason: LossReason::OutOfRange,
            ..
        }
    )));
    assert!(heard.lock().unwrap().is_empty());
}

#[test]
fn message_losses_are_the_same_for_the_same_seed() {
    let lossy = CommsParams {
        acoustic: ChannelParams {
            loss_probability: 0.5,
            ..ChannelParams::IDEAL
        },
        radio: ChannelParams::IDEAL,
        ranging: RangingParams::default(),
    };
    let losses = |seed: u64| {
        let (w, mut p, _) = talkers(lossy, Link::Acoustic, 150.0);
        // The same world, its channels seeded with `seed`.
        let mut w = World::with_comms(
            env(vec![]),
            w.vehicles().to_vec(),
            DT,
            Some(10.0),
            lossy,
            seed,
        )
        .unwrap();
        let mut lost = Vec::new();
        for k in 0..200 {
            let r = w.step(&mut p).unwrap();
            for (id, e) in r.events {
                if matches!(e, WorldEvent::MessageLost { .. }) {
                    lost.push((k, id));
                }
            }
        }
        lost
    };
    let a = losses(5);
    assert!(a.len() > 100 && a.len() < 300, "{}", a.len());
    assert_eq!(a, losses(5));
    assert_ne!(a, losses(6));
}

/// Two AUVs 10 m apart with ideal channels.
fn pair() -> World {
    World::new(
        env(vec![]),
        vec![auv(0, (50.0, 50.0), 0.0), auv(1, (60.0, 50.0), 0.0)],
        DT,
        Some(10.0),
    )
    .unwrap()
}

#[test]
fn a_message_to_a_stopped_or_missing_vehicle_is_reported_lost() {
    let mut w = pair();
    w.stop(VehicleId(1));
    let to = |id| plumetrace_core::Message {
        from: VehicleId(0),
        to: Recipient::Vehicle(VehicleId(id)),
        link: Link::Radio,
        sent_s: 0.0,
        body: MessageBody::Text { text: "x".into() },
    };
    let e = w.send(to(1));
    assert!(
        matches!(
            &e[..],
            [(
                VehicleId(1),
                WorldEvent::MessageLost {
                    reason: LossReason::RecipientStopped,
                    ..
                }
            )]
        ),
        "{e:?}"
    );
    let e = w.send(to(7));
    assert!(
        matches!(
            &e[..],
            [(
                VehicleId(0),
                WorldEvent::MessageLost {
                    reason: LossReason::NoSuchRecipient,
                    ..
                }
            )]
        ),
        "{e:?}"
    );
    assert_eq!(w.messages_in_flight(), 0);
}

#[test]
fn vehicles_with_different_planners_decide_at_their_own_periods() {
    let fast = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let slow = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let mut w = World::new(
        env(vec![]),
        vec![
            auv(0, (50.0, 50.0), 0.0),
            vehicle(
                1,
                plumetrace_core::VehicleKind::Surface,
                (50.0, 150.0),
                90.0,
            ),
            auv(2, (150.0, 50.0), 0.0),
        ],
        DT,
        Some(10.0),
    )
    .unwrap();
    let mut planners: Vec<Option<Box<dyn Planner>>> = vec![
        Some(Box::new(Hold {
            command: command(0.0, 2.0),
            period_s: 0.0,
            decisions: fast.clone(),
        })),
        Some(Box::new(Hold {
            command: command(90.0, 1.0),
            period_s: 1.0,
            decisions: slow.clone(),
        })),
        None,
    ];
    let mut snapshots = 0;
    w.record_snapshots(true);
    for _ in 0..100 {
        let r = w.step(&mut planners).unwrap();
        snapshots += r.snapshots.iter().flatten().count();
        if let Some(s) = &r.snapshots[1] {
            assert_eq!(s.nav.altitude_m, None, "surface craft have no altimeter");
            assert_eq!(s.nav.depth_m, Some(0.0));
        }
        if let Some(s) = &r.snapshots[0] {
            assert!(s.nav.altitude_m.is_some_and(|a| (a - 2.0).abs() < 1.0));
            assert!(s.nav.pos_m.is_some());
        }
    }
    let fast = fast.lock().unwrap().clone();
    let slow = slow.lock().unwrap().clone();
    assert_eq!(fast.len(), 100, "every step");
    assert_eq!(slow.len(), 10, "every second");
    assert_eq!(snapshots, 110);
    // The 10 Hz chemical samples accumulate between the slow planner's decisions.
    assert!(slow[1..].iter().all(|(_, n)| *n == 10), "{slow:?}");
    assert!(
        slow.iter()
            .zip(0..)
            .all(|((t, _), k)| (t - f64::from(k)).abs() < 1e-9)
    );
    // Each vehicle flew its own command; the one without a planner stayed put (drifting).
    let v = w.vehicles();
    assert!(v[0].vehicle.state.pos_m.y > 60.0);
    assert!(v[1].vehicle.state.pos_m.x > 55.0 && (v[1].vehicle.state.pos_m.y - 150.0).abs() < 1.0);
    assert!(
        (v[2].vehicle.state.pos_m - Vec2::new(151.0, 50.0)).norm() < 0.1,
        "{:?}",
        v[2].vehicle.state.pos_m
    );
}

/// Sends a ranging request to vehicle 1 at every decision; records the ranges it gets back.
struct Ranger {
    ranges: std::sync::Arc<std::sync::Mutex<Vec<f64>>>,
}

impl Planner for Ranger {
    fn decide(&mut self, s: &SensorSnapshot) -> Decision {
        if let Ok(mut r) = self.ranges.lock() {
            for m in &s.inbox {
                if let MessageBody::RangeReply { range_m, .. } = m.body {
                    r.push(range_m);
                }
            }
        }
        let mut d = Decision::new(command(0.0, 0.0), PlanStatus::Running);
        d.outbox.push(Outgoing {
            to: Recipient::Broadcast,
            link: Link::Acoustic,
            body: MessageBody::RangeRequest {
                target: VehicleId(1),
                reading: 0.0,
            },
        });
        d
    }
}

/// Answers every ranging request addressed to it at once; counts the requests it hears.
struct Echoer {
    me: VehicleId,
    heard: std::sync::Arc<std::sync::Mutex<u32>>,
}

impl Planner for Echoer {
    fn decide(&mut self, s: &SensorSnapshot) -> Decision {
        let mut d = Decision::new(command(0.0, 0.0), PlanStatus::Running);
        for m in &s.inbox {
            if let MessageBody::RangeRequest { target, .. } = m.body {
                if let Ok(mut h) = self.heard.lock() {
                    *h += 1;
                }
                if target == self.me {
                    d.outbox.push(Outgoing {
                        to: Recipient::Vehicle(m.from),
                        link: Link::Acoustic,
                        body: MessageBody::RangeEcho {
                            heading: Heading::from_deg(45.0),
                            scale_cw: Some(1.5),
                        },
                    });
                }
            }
        }
        d
    }
}

#[test]
fn ranging_measures_the_slant_range_with_the_timing_noise_and_one_packet_in_flight() {
    let comms = CommsParams {
        acoustic: ChannelParams {
            latency_s: 0.25,
            sound_speed_mps: Some(1500.0),
            loss_probability: 0.0,
            max_range_m: None,
            one_in_flight: true,
        },
        radio: ChannelParams::IDEAL,
        ranging: RangingParams {
            timing_noise_sd_s: 0.002,
            sound_speed_mps: 1500.0,
        },
    };
    let ranges = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let heard = std::sync::Arc::new(std::sync::Mutex::new(0));
    let heard2 = std::sync::Arc::new(std::sync::Mutex::new(0));
    let follower = auv(0, (50.0, 100.0), 0.0);
    let mut w = World::with_comms(
        env(vec![]),
        vec![
            follower,
            auv(1, (50.0, 130.0), 0.0),
            auv(2, (80.0, 100.0), 0.0),
        ],
        DT,
        Some(10.0),
        comms,
        3,
    )
    .unwrap();
    // Every vehicle 2 m above the seabed: the slant range is the horizontal one.
    let truth = 30.0;
    let mut p: Vec<Option<Box<dyn Planner>>> = vec![
        Some(Box::new(Ranger {
            ranges: ranges.clone(),
        })),
        Some(Box::new(Echoer {
            me: VehicleId(1),
            heard: heard.clone(),
        })),
        Some(Box::new(Echoer {
            me: VehicleId(2),
            heard: heard2.clone(),
        })),
    ];
    let mut busy = 0;
    // 1000 s: the current (0.1 m/s East) carries the three together, all inside the domain.
    for _ in 0..10_000 {
        let r = w.step(&mut p).unwrap();
        busy += r
            .events
            .iter()
            .filter(|(_, e)| {
                matches!(
                    e,
                    WorldEvent::MessageLost {
                        reason: LossReason::ModemBusy,
                        ..
                    }
                )
            })
            .count();
    }
    let r = ranges.lock().unwrap().clone();
    let n = r.len() as f64;
    let mean = r.iter().sum::<f64>() / n;
    let sd = (r.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    // A request every step would be 10,000; the modem carries one at a time (0.25 s turnaround
    // plus 20 ms of travel: at most one request in three steps of 0.1 s goes out).
    assert!(n > 2000.0 && n <= 10_000.0 / 3.0, "{n}");
    assert!(
        busy > 0,
        "requests sent while the previous one travels are lost"
    );
    // Timing noise 2 ms: range sd 1.5 m.
    assert!(
        (mean - truth).abs() < 4.0 * 1.5 / n.sqrt(),
        "{mean} vs {truth}"
    );
    assert!((sd - 1.5).abs() < 0.1, "{sd}");
    // Both hear every request that was sent; only the target answered.
    let (h1, h2) = (*heard.lock().unwrap(), *heard2.lock().unwrap());
    assert_eq!(h1, h2, "busy {busy}");
    assert!(h1 as f64 >= n);
}

#[test]
fn an_unsolicited_echo_is_lost_and_a_deaf_modem_hears_nothing() {
    let mut w = pair();
    let e = w.send(plumetrace_core::Message {
        from: VehicleId(1),
        to: Recipient::Vehicle(VehicleId(0)),
        link: Link::Acoustic,
        sent_s: 0.0,
        body: MessageBody::RangeEcho {
            heading: Heading::from_deg(0.0),
            scale_cw: None,
        },
    });
    assert!(
        matches!(
            &e[..],
            [(
                VehicleId(0),
                WorldEvent::MessageLost {
                    reason: LossReason::Unsolicited,
                    ..
                }
            )]
        ),
        "{e:?}"
    );
    w.vehicles_mut()[1].deaf_window_s = Some((0.0, 1.0));
    let text = plumetrace_core::Message {
        from: VehicleId(0),
        to: Recipient::Vehicle(VehicleId(1)),
        link: Link::Acoustic,
        sent_s: 0.0,
        body: MessageBody::Text { text: "x".into() },
    };
    assert!(w.send(text.clone()).is_empty(), "on its way");
    let mut p: Vec<Option<Box<dyn Planner>>> = vec![None, None];
    let r = w.step(&mut p).unwrap();
    assert!(r.events.iter().any(|(id, e)| *id == VehicleId(1)
        && matches!(
            e,
            WorldEvent::MessageLost {
                reason: LossReason::Deaf,
                ..
            }
        )));
    for _ in 0..10 {
        w.step(&mut p).unwrap();
    }
    w.send(plumetrace_core::Message {
        sent_s: w.time_s(),
        ..text
    });
    let r = w.step(&mut p).unwrap();
    assert!(
        r.events
            .iter()
            .any(|(id, e)| *id == VehicleId(1) && matches!(e, WorldEvent::MessageDelivered { .. })),
        "heard after the window: {:?}",
        r.events
    );
}

#[test]
fn fleets_sharing_an_environment_step_as_in_worlds_of_their_own() {
    let moving = |k: u32, y: f64| {
        let mut v = auv(k, (50.0 + 5.0 * f64::from(k), y), 90.0);
        v.command.speed_mps = 1.0;
        v
    };
    let fleet_vehicles = |y: f64| vec![moving(0, y), moving(1, y)];
    let params = CommsParams::default();
    let mut shared = env(vec![]);
    let mut fleets: Vec<plumetrace_sim::Fleet> = [40.0, 120.0]
        .iter()
        .map(|&y| {
            plumetrace_sim::Fleet::new(&shared, fleet_vehicles(y), DT, Some(10.0), params, 3)
                .unwrap()
        })
        .collect();
    let mut alone: Vec<World> = [40.0, 120.0]
        .iter()
        .map(|&y| World::with_comms(env(vec![]), fleet_vehicles(y), DT, Some(10.0), params, 3))
        .collect::<Result<_, _>>()
        .unwrap();
    let mut none: Vec<Option<Box<dyn Planner>>> = vec![None, None];
    for _ in 0..50 {
        if fleets[0].env_due() {
            shared.step().unwrap();
        }
        for (f, w) in fleets.iter_mut().zip(&mut alone) {
            f.step(&shared, &mut none).unwrap();
            w.step(&mut none).unwrap();
        }
    }
    for (f, w) in fleets.iter().zip(&alone) {
        let states = |v: &[SimVehicle]| {
            v.iter()
                .map(|v| format!("{:?} {:?}", v.vehicle.state, v.last_chem))
                .collect::<Vec<_>>()
        };
        assert_eq!(states(f.vehicles()), states(w.vehicles()));
        assert!(
            (f.vehicles()[0].vehicle.state.pos_m - Vec2::new(50.0, 40.0)).norm() > 1.0
                || f.vehicles()[0].vehicle.state.pos_m.y > 100.0
        );
    }
    // An environment that was not advanced for the fleet's step (or advanced twice) is refused.
    let mut late =
        plumetrace_sim::Fleet::new(&shared, fleet_vehicles(40.0), DT, None, params, 3).unwrap();
    let e = late.step(&shared, &mut none).unwrap_err().to_string();
    assert!(e.contains("world.env") && e.contains("needs step"), "{e}");
    shared.step().unwrap();
    late.step(&shared, &mut none).unwrap();
    shared.step().unwrap();
    shared.step().unwrap();
    assert!(late.step(&shared, &mut none).is_err());
}

/// The seabed of [`env`]'s domain rising eastward at `slope` from 40 m of water at x = 0 (a
/// ridge with a plateau 1 m deep beyond where it would reach the surface).
fn sloping(slope: f64) -> std::sync::Arc<plumetrace_env::Seabed> {
    let area = Rect::new(0.0, 200.0, 0.0, 200.0).unwrap();
    let n = 201;
    let depths: Vec<f64> = (0..n * 3)
        .map(|k| (40.0 - slope * (k % n) as f64).max(1.0))
        .collect();
    std::sync::Arc::new(plumetrace_env::Seabed::from_depths(area, n, 3, &depths).unwrap())
}

#[test]
fn altitude_hold_follows_a_sloping_seabed_and_a_steep_one_is_hit() {
    // A 10 % slope: the AUV, flying upslope at 2 m/s with altitude 2 m, climbs with it.
    let mut e = env(vec![]);
    e.set_seabed(Some(sloping(0.1)));
    let mut w = World::new(e, vec![auv(0, (10.0, 100.0), 90.0)], DT, Some(40.0)).unwrap();
    let mut planners = vec![Some(hold(90.0, 2.0))];
    let mut lowest = f64::INFINITY;
    for _ in 0..800 {
        let r = w.step(&mut planners).unwrap();
        assert!(
            !r.events
                .iter()
                .any(|(_, e)| matches!(e, WorldEvent::Incident { .. })),
            "{:?}",
            r.events
        );
        let s = &w.vehicles()[0].vehicle.state;
        let floor = w.env().seabed_height_at(s.pos_m);
        lowest = lowest.min(s.z_m - floor);
    }
    // Above the seabed all the way (the lag on a 10 % slope at 2 m/s is about 1 m; the
    // altitude error's sd 0.35 m).
    assert!(lowest > 0.0 && lowest < 1.9, "{lowest}");
    // A 100 % slope rises 2 m a second under it: the vertical response cannot keep up.
    let mut e = env(vec![]);
    e.set_seabed(Some(sloping(1.0)));
    let mut w = World::new(e, vec![auv(0, (10.0, 100.0), 90.0)], DT, Some(40.0)).unwrap();
    let mut hit = None;
    for _ in 0..400 {
        let r = w.step(&mut planners).unwrap();
        if let Some((_, WorldEvent::Incident { what })) = r.events.first() {
            hit = Some((*what, w.vehicles()[0].vehicle.state.pos_m.x));
            break;
        }
    }
    let (what, x) = hit.expect("the vehicle hits the seabed");
    assert_eq!(what, Incident::HitBottom);
    assert!(x > 10.0 && x < 40.0, "{x}");
    assert!(!w.vehicles()[0].active);
}
