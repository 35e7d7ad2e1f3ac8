//! The world: an environment and a fleet of vehicles stepped together in named stages.
//!
//! A [`World`] owns its environment; a [`Fleet`] (the vehicles with their streams, channels,
//! clock and stage times) only reads one, so several fleets can fly against one environment that
//! their caller steps once for all of them, each giving the bits of a world of its own.
//!
//! One step of `dt` runs, in order:
//! 1. **advance environment**: the flow and plume advance every `env_every` steps (the plume's
//!    step is a multiple of the vehicles'; its physics does not depend on the step); the world
//!    does this, or the caller of [`Fleet::step`] when [`Fleet::env_due`];
//! 2. **sense**: each vehicle's due chemical, flow and range samples, taken at its true position;
//! 3. **communicate**: messages that have arrived by now are delivered to their recipients'
//!    inboxes;
//! 4. **decide**: each active vehicle with a planner whose decision is due (every step, or every
//!    `decision_period_s`) gets its [`SensorSnapshot`] (navigation estimate, samples since its
//!    last decision, messages) and returns a [`Decision`]; its outgoing messages go through their
//!    link's channel model ([`crate::comms`]: delay from the distance between sender and
//!    recipient at sending, loss, range, one packet in flight per modem) and are on their way;
//!    a range echo is turned into the requester's measured range here (acoustic ranging);
//! 5. **control**: a command that is not finite is recorded as an event and replaced by the
//!    vehicle's previous command (the safe one: finite, and what the vehicle is already doing);
//! 6. **integrate**: vehicle dynamics in the local current, then navigation (fixes jump here);
//! 7. **check**: vehicles that left the domain, entered an obstacle or went below the seabed are
//!    stopped with an incident;
//! 8. **record**: observers of the run (in the mission) look at the world after the step; their
//!    time is added with [`World::add_record_time`].
//!
//! Each stage is a function, and its wall time is summed in [`StageTimes`].

use crate::comms::{Comms, CommsParams, LossReason, Transmission, is_range_echo};
use crate::{
    ChemSensor, ChemSensorParams, FlowSensor, FlowSensorParams, NavParams, Navigator, RangeSensor,
    RangeSensorParams, Vehicle,
};
use plumetrace_core::{
    ChemSample, Command, Decision, FlowSample, Link, Message, MessageBody, Planner, RangeReturn,
    Recipient, SensorSnapshot, Vec2, Vec3, VehicleId, VerticalCommand,
};
use plumetrace_env::{EnvError, Environment, FlowField, SimRng, StreamId, stream_rng};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Wall time spent in each stage of the step.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct StageTimes {
    /// Flow and plume.
    pub advance_environment_s: f64,
    /// Sensor samples.
    pub sense_s: f64,
    /// Message delivery.
    pub communicate_s: f64,
    /// Planners.
    pub decide_s: f64,
    /// Command checks.
    pub control_s: f64,
    /// Dynamics and navigation.
    pub integrate_s: f64,
    /// Domain and obstacle checks.
    pub check_s: f64,
    /// The observers.
    pub record_s: f64,
}

/// Something that stopped a vehicle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Incident {
    /// The vehicle's true position left the simulated domain.
    LeftDomain,
    /// The vehicle entered an obstacle (kelp is no-go for vehicles).
    Collided,
    /// The vehicle reached the seabed (over a seabed that is not flat: the seabed rose faster
    /// than the vehicle could climb).
    HitBottom,
}

/// What the world reports about a vehicle in a step (planners report their own events).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "event")]
pub enum WorldEvent {
    /// A position fix moved the navigation estimate.
    NavFix {
        /// How far the estimate jumped, m.
        jump_m: f64,
        /// The estimate after the fix.
        to_m: Vec2,
    },
    /// The vehicle was stopped.
    Incident {
        /// Why.
        what: Incident,
    },
    /// The planner returned a command with a non-finite number; the previous command was kept.
    NonFiniteCommand {
        /// The planner's command as text (NaN and infinities do not fit in JSON numbers).
        command: String,
    },
    /// A message reached this vehicle.
    MessageDelivered {
        /// Sender.
        from: VehicleId,
        /// Link.
        link: Link,
        /// When it was sent, s.
        sent_s: f64,
    },
    /// A message to this vehicle was lost.
    MessageLost {
        /// Sender.
        from: VehicleId,
        /// Link.
        link: Link,
        /// When it was sent, s.
        sent_s: f64,
        /// Why.
        reason: LossReason,
    },
}

/// A vehicle with its navigation, sensors and random streams.
#[derive(Debug, Clone)]
pub struct SimVehicle {
    /// Name for logs.
    pub name: String,
    /// Truth and dynamics.
    pub vehicle: Vehicle,
    /// Navigation estimate.
    pub nav: Navigator,
    /// Chemical sensor.
    pub chem: ChemSensor,
    /// Flow sensor.
    pub flow_sensor: FlowSensor,
    /// Obstacle range sensors.
    pub range: Option<RangeSensor>,
    /// The command being executed.
    pub command: Command,
    /// False once stopped (incident, finished or aborted).
    pub active: bool,
    /// The latest chemical sample (for logs).
    pub last_chem: Option<ChemSample>,
    /// A window `[start, end)` of mission time, s, during which the vehicle's modem hears
    /// nothing (messages arriving then are lost as `deaf`).
    pub deaf_window_s: Option<(f64, f64)>,
    next_decision_s: f64,
    pending_chem: Vec<ChemSample>,
    last_flow: Option<FlowSample>,
    last_ranges: Option<RangeReturn>,
    inbox: Vec<Message>,
    rng_motion: SimRng,
    rng_nav: SimRng,
    rng_chem: SimRng,
    rng_flow: SimRng,
    rng_measure: SimRng,
    rng_range: SimRng,
}

impl SimVehicle {
    /// A vehicle with its streams derived from `seed` and its index.
    pub fn new(
        name: String,
        vehicle: Vehicle,
        nav: NavParams,
        chem: ChemSensorParams,
        flow: FlowSensorParams,
        range: Option<RangeSensorParams>,
        seed: u64,
    ) -> Self {
        let i = vehicle.id.0;
        let command = Command {
            heading: vehicle.state.heading,
            speed_mps: 0.0,
            vertical: VerticalCommand::Altitude(vehicle.state.z_m),
        };
        SimVehicle {
            name,
            nav: Navigator::new(nav, &vehicle.state),
            vehicle,
            chem: ChemSensor::new(chem),
            flow_sensor: FlowSensor::new(flow),
            range: range.map(RangeSensor::new),
            command,
            active: true,
            last_chem: None,
            deaf_window_s: None,
            next_decision_s: 0.0,
            pending_chem: Vec::new(),
            last_flow: None,
            last_ranges: None,
            inbox: Vec::new(),
            rng_motion: stream_rng(seed, StreamId::Vehicle(i)),
            rng_nav: stream_rng(seed, StreamId::Sensor(i, 0)),
            rng_chem: stream_rng(seed, StreamId::Sensor(i, 1)),
            rng_flow: stream_rng(seed, StreamId::Sensor(i, 2)),
            rng_measure: stream_rng(seed, StreamId::Sensor(i, 3)),
            rng_range: stream_rng(seed, StreamId::Sensor(i, 4)),
        }
    }
}

/// What one step produced.
#[derive(Debug, Default)]
pub struct StepReport {
    /// Time at the start of the step (when the snapshots were taken), s.
    pub t_s: f64,
    /// Each vehicle's decision, if it decided in this step (indexed by vehicle).
    pub decisions: Vec<Option<Decision>>,
    /// The snapshots behind those decisions, when the world records them
    /// ([`World::record_snapshots`]).
    pub snapshots: Vec<Option<SensorSnapshot>>,
    /// What happened to vehicles, in order.
    pub events: Vec<(VehicleId, WorldEvent)>,
}

/// The vehicles of one world with everything that is theirs: navigation, sensors, random
/// streams, message channels, clock and stage times. A fleet only reads the environment
/// (`&Environment` in every stage), so several fleets can fly against one environment that is
/// stepped once for all of them ([`Fleet::step`]); each then gives the bits it would give in a
/// world of its own, since nothing a fleet does reaches the environment or another fleet.
#[derive(Debug)]
pub struct Fleet {
    vehicles: Vec<SimVehicle>,
    dt_s: f64,
    env_dt_s: f64,
    env_every: u64,
    env_start: u64,
    step: u64,
    water_depth_m: Option<f64>,
    comms: Comms,
    record_snapshots: bool,
    times: StageTimes,
    timed: bool,
}

/// The simulated world: an environment and the fleet flying in it.
#[derive(Debug)]
pub struct World {
    env: Environment,
    fleet: Fleet,
}

/// A look at a world after a step: the environment and one fleet. The environment may be a
/// world's own or one shared by several fleets.
#[derive(Debug, Clone, Copy)]
pub struct WorldView<'a> {
    env: &'a Environment,
    fleet: &'a Fleet,
}

impl<'a> WorldView<'a> {
    /// A view of `fleet` flying in `env`.
    pub fn new(env: &'a Environment, fleet: &'a Fleet) -> Self {
        WorldView { env, fleet }
    }

    /// The environment.
    pub fn env(&self) -> &'a Environment {
        self.env
    }

    /// The fleet.
    pub fn fleet(&self) -> &'a Fleet {
        self.fleet
    }

    /// The vehicles.
    pub fn vehicles(&self) -> &'a [SimVehicle] {
        &self.fleet.vehicles
    }

    /// Mission time, s.
    pub fn time_s(&self) -> f64 {
        self.fleet.time_s()
    }

    /// Steps taken by the fleet.
    pub fn steps(&self) -> u64 {
        self.fleet.step
    }

    /// The vehicles' step, s.
    pub fn dt_s(&self) -> f64 {
        self.fleet.dt_s
    }

    /// Water depth, m, if the scenario gives one.
    pub fn water_depth_m(&self) -> Option<f64> {
        self.fleet.water_depth_m
    }

    /// Messages on their way.
    pub fn messages_in_flight(&self) -> usize {
        self.fleet.comms.in_flight()
    }
}

/// A stopwatch read once between stages, or never (a fleet that does not time its stages,
/// [`Fleet::time_stages`]); a fleet hands one out ([`Fleet::lap`]).
pub struct Lap(Option<Instant>);

impl Lap {
    /// A stopwatch started now if `on`, else one that reads no clock.
    fn start(on: bool) -> Self {
        Lap(on.then(Instant::now))
    }

    /// Adds the time since the last reading to `acc` (nothing if off).
    pub fn to(&mut self, acc: &mut f64) {
        if let Some(last) = self.0.as_mut() {
            let now = Instant::now();
            *acc += (now - *last).as_secs_f64();
            *last = now;
        }
    }
}

impl World {
    /// A world stepping vehicles at `dt_s` with ideal message channels; the environment's own
    /// step must be a whole number of vehicle steps. `seed` seeds the channels' random stream.
    pub fn new(
        env: Environment,
        vehicles: Vec<SimVehicle>,
        dt_s: f64,
        water_depth_m: Option<f64>,
    ) -> Result<Self, EnvError> {
        World::with_comms(
            env,
            vehicles,
            dt_s,
            water_depth_m,
            CommsParams::default(),
            0,
        )
    }

    /// A world with the given channel models, their losses drawn from the run `seed`.
    pub fn with_comms(
        env: Environment,
        vehicles: Vec<SimVehicle>,
        dt_s: f64,
        water_depth_m: Option<f64>,
        comms: CommsParams,
        seed: u64,
    ) -> Result<Self, EnvError> {
        let fleet = Fleet::new(&env, vehicles, dt_s, water_depth_m, comms, seed)?;
        Ok(World { env, fleet })
    }

    /// The environment and the fleet.
    pub fn view(&self) -> WorldView<'_> {
        WorldView::new(&self.env, &self.fleet)
    }

    /// The fleet.
    pub fn fleet(&self) -> &Fleet {
        &self.fleet
    }

    /// Keep every snapshot given to a planner in the step reports (for snapshot logs).
    pub fn record_snapshots(&mut self, on: bool) {
        self.fleet.record_snapshots(on);
    }

    /// Mission time, s (0 at the start, after any spin-up).
    pub fn time_s(&self) -> f64 {
        self.fleet.time_s()
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.fleet.steps()
    }

    /// The vehicles' step, s.
    pub fn dt_s(&self) -> f64 {
        self.fleet.dt_s()
    }

    /// Water depth, m, if the scenario gives one.
    pub fn water_depth_m(&self) -> Option<f64> {
        self.fleet.water_depth_m()
    }

    /// The environment.
    pub fn env(&self) -> &Environment {
        &self.env
    }

    /// The vehicles.
    pub fn vehicles(&self) -> &[SimVehicle] {
        self.fleet.vehicles()
    }

    /// The vehicles, mutably (tests and scripted scenarios: a forced fix, a moved vehicle).
    pub fn vehicles_mut(&mut self) -> &mut [SimVehicle] {
        self.fleet.vehicles_mut()
    }

    /// Messages on their way.
    pub fn messages_in_flight(&self) -> usize {
        self.fleet.messages_in_flight()
    }

    /// Stops a vehicle (it keeps its position and takes no more decisions).
    pub fn stop(&mut self, id: VehicleId) {
        self.fleet.stop(id);
    }

    /// Sends a message now from its sender's true position (scripted scenarios, tests); what
    /// became of it for each recipient that lost it is returned as events.
    pub fn send(&mut self, message: Message) -> Vec<(VehicleId, WorldEvent)> {
        self.fleet.send(message)
    }

    /// Time spent per stage so far.
    pub fn stage_times(&self) -> StageTimes {
        self.fleet.stage_times()
    }

    /// Adds the observers' time of a step to the record stage.
    pub fn add_record_time(&mut self, s: f64) {
        self.fleet.add_record_time(s);
    }

    /// One step with one planner slot per vehicle (`None`: no planner, the vehicle keeps its
    /// command), stages 1 to 7.
    pub fn step(
        &mut self,
        planners: &mut [Option<Box<dyn Planner>>],
    ) -> Result<StepReport, EnvError> {
        if self.fleet.env_due() {
            let mut lap = self.fleet.lap();
            self.env.step()?;
            lap.to(&mut self.fleet.times.advance_environment_s);
        }
        self.fleet.step(&self.env, planners)
    }
}

/// How many vehicle steps of `dt_s` make one environment step of `env_dt_s`: `None` unless
/// `env_dt_s` is a whole multiple (1 or more, within 1e-9) of `dt_s`.
pub fn steps_per_env_step(env_dt_s: f64, dt_s: f64) -> Option<u64> {
    let ratio = env_dt_s / dt_s;
    (env_dt_s.is_finite() && ratio >= 1.0 - 1e-9 && (ratio - ratio.round()).abs() < 1e-9)
        .then(|| ratio.round() as u64)
}

impl Fleet {
    /// A fleet stepping `vehicles` at `dt_s` in `env` (whose step must be a whole number of
    /// vehicle steps), with the given channel models, their losses drawn from the run `seed`.
    pub fn new(
        env: &Environment,
        vehicles: Vec<SimVehicle>,
        dt_s: f64,
        water_depth_m: Option<f64>,
        comms: CommsParams,
        seed: u64,
    ) -> Result<Self, EnvError> {
        plumetrace_env::error::require_positive("dt_s", dt_s)?;
        let Some(env_every) = steps_per_env_step(env.dt_s(), dt_s) else {
            return Err(EnvError::invalid(
                "env",
                format!(
                    "its step must be a whole multiple of dt_s ({dt_s}), got {}",
                    env.dt_s()
                ),
            ));
        };
        if let Some(k) = vehicles
            .iter()
            .enumerate()
            .position(|(k, v)| v.vehicle.id.0 as usize != k)
        {
            return Err(EnvError::invalid(
                format!("vehicles[{k}]"),
                "vehicle ids must be their index in the list",
            ));
        }
        comms.validate().map_err(|e| e.under("comms"))?;
        Ok(Fleet {
            vehicles,
            dt_s,
            env_dt_s: env.dt_s(),
            env_every,
            env_start: env.steps(),
            step: 0,
            water_depth_m,
            comms: Comms::new(comms, seed),
            record_snapshots: false,
            times: StageTimes::default(),
            timed: true,
        })
    }

    /// Whether the environment advances before this fleet's next step (stage 1: every
    /// `env_every` vehicle steps, starting with the first).
    pub fn env_due(&self) -> bool {
        self.step.is_multiple_of(self.env_every)
    }

    /// The environment's step count that the fleet's next step must see: its count when the
    /// fleet was made, plus one for each stage 1 so far and the one before this step.
    pub fn env_steps_expected(&self) -> u64 {
        self.env_start + self.step / self.env_every + 1
    }

    /// Adds time spent advancing the environment for this fleet (its own, or its share of a
    /// shared environment's) to stage 1.
    pub fn add_environment_time(&mut self, s: f64) {
        if self.timed {
            self.times.advance_environment_s += s;
        }
    }

    /// Time each stage of the step (on at first): [`Fleet::stage_times`] stays at zero when
    /// off, and a step reads no clock (seven readings a step when on).
    pub fn time_stages(&mut self, on: bool) {
        self.timed = on;
    }

    /// A stopwatch for a stage's time, started now: one that reads no clock when the stages are
    /// not timed ([`Fleet::time_stages`]).
    pub fn lap(&self) -> Lap {
        Lap::start(self.timed)
    }

    /// Keep every snapshot given to a planner in the step reports (for snapshot logs).
    pub fn record_snapshots(&mut self, on: bool) {
        self.record_snapshots = on;
    }

    /// Mission time, s (0 at the start, after any spin-up).
    pub fn time_s(&self) -> f64 {
        self.step as f64 * self.dt_s
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.step
    }

    /// The vehicles' step, s.
    pub fn dt_s(&self) -> f64 {
        self.dt_s
    }

    /// Water depth, m, if the scenario gives one.
    pub fn water_depth_m(&self) -> Option<f64> {
        self.water_depth_m
    }

    /// The vehicles.
    pub fn vehicles(&self) -> &[SimVehicle] {
        &self.vehicles
    }

    /// The vehicles, mutably (tests and scripted scenarios: a forced fix, a moved vehicle).
    pub fn vehicles_mut(&mut self) -> &mut [SimVehicle] {
        &mut self.vehicles
    }

    /// Messages on their way.
    pub fn messages_in_flight(&self) -> usize {
        self.comms.in_flight()
    }

    /// Stops a vehicle (it keeps its position and takes no more decisions).
    pub fn stop(&mut self, id: VehicleId) {
        if let Some(v) = self.vehicles.get_mut(id.0 as usize) {
            v.active = false;
            v.command.speed_mps = 0.0;
        }
    }

    /// Sends a message now from its sender's true position (scripted scenarios, tests); what
    /// became of it for each recipient that lost it is returned as events.
    pub fn send(&mut self, message: Message) -> Vec<(VehicleId, WorldEvent)> {
        let mut events = Vec::new();
        self.transmit(&message, &mut events);
        events
    }

    /// Puts a message through its channel to every recipient (one vehicle, or every other
    /// active vehicle); losses become events.
    fn transmit(&mut self, m: &Message, events: &mut Vec<(VehicleId, WorldEvent)>) {
        let from_m = self
            .vehicles
            .get(m.from.0 as usize)
            .map_or(Vec2::zeros(), |v| v.vehicle.state.pos_m);
        // A range echo reaches its requester as a measured range, or not at all.
        let measured;
        let unsolicited = |to: VehicleId| {
            (
                to,
                WorldEvent::MessageLost {
                    from: m.from,
                    link: m.link,
                    sent_s: m.sent_s,
                    reason: LossReason::Unsolicited,
                },
            )
        };
        let m = if is_range_echo(&m.body) {
            let (Recipient::Vehicle(to), MessageBody::RangeEcho { heading, scale_cw }) =
                (m.to, &m.body)
            else {
                events.push(unsolicited(m.from));
                return;
            };
            let range = match (
                self.vehicles.get(m.from.0 as usize),
                self.vehicles.get(to.0 as usize),
            ) {
                (Some(a), Some(b)) => self.comms.measure_range(to, m.from, slant_m(a, b)),
                _ => None,
            };
            let Some(range_m) = range else {
                events.push(unsolicited(to));
                return;
            };
            measured = Message {
                body: MessageBody::RangeReply {
                    range_m,
                    sender_heading: *heading,
                    scale_cw: *scale_cw,
                },
                ..m.clone()
            };
            &measured
        } else {
            m
        };
        let lost = |to: VehicleId, reason| {
            (
                to,
                WorldEvent::MessageLost {
                    from: m.from,
                    link: m.link,
                    sent_s: m.sent_s,
                    reason,
                },
            )
        };
        if let Recipient::Vehicle(to) = m.to
            && to.0 as usize >= self.vehicles.len()
        {
            events.push(lost(m.from, LossReason::NoSuchRecipient));
            return;
        }
        let busy = self.comms.busy(m.from, m.link, m.sent_s);
        let sender = m.from.0 as usize;
        for (k, v) in self.vehicles.iter().enumerate() {
            let id = v.vehicle.id;
            let addressed = match m.to {
                Recipient::Broadcast => id != m.from,
                Recipient::Vehicle(to) => to == id,
            };
            if !addressed {
                continue;
            }
            if !v.active {
                // A broadcast reaches whoever is listening; a message to a stopped vehicle is lost.
                if m.to != Recipient::Broadcast {
                    events.push(lost(id, LossReason::RecipientStopped));
                }
                continue;
            }
            if busy {
                events.push(lost(id, LossReason::ModemBusy));
                continue;
            }
            match self.comms.transmit(m, from_m, id, v.vehicle.state.pos_m) {
                Transmission::Lost(reason) => events.push(lost(id, reason)),
                Transmission::InFlight { .. } => {
                    if let MessageBody::RangeRequest { target, .. } = m.body
                        && target == id
                        && let Some(s) = self.vehicles.get(sender)
                    {
                        let d = slant_m(s, &self.vehicles[k]);
                        self.comms.record_request(m.from, id, d);
                    }
                }
            }
        }
    }

    /// Time spent per stage so far.
    pub fn stage_times(&self) -> StageTimes {
        self.times
    }

    /// Adds the observers' time of a step to the record stage.
    pub fn add_record_time(&mut self, s: f64) {
        if self.timed {
            self.times.record_s += s;
        }
    }

    /// One step of the fleet in `env`, which the caller has advanced for it (stage 1, when
    /// [`Fleet::env_due`]): stages 2 to 7 with one planner slot per vehicle (`None`: no
    /// planner, the vehicle keeps its command). An environment at another step than the fleet's
    /// clock expects, or with another step length, is refused.
    pub fn step(
        &mut self,
        env: &Environment,
        planners: &mut [Option<Box<dyn Planner>>],
    ) -> Result<StepReport, EnvError> {
        if env.steps() != self.env_steps_expected() || env.dt_s() != self.env_dt_s {
            return Err(EnvError::invalid(
                "world.env",
                format!(
                    "the environment is at step {} of {} s; the fleet's step {} needs step {} of \
                     {} s",
                    env.steps(),
                    env.dt_s(),
                    self.step,
                    self.env_steps_expected(),
                    self.env_dt_s
                ),
            ));
        }
        let mut times = self.times;
        let t = self.time_s();
        let mut report = StepReport {
            t_s: t,
            ..StepReport::default()
        };
        // One clock reading between stages: each stage's time runs to the next one's start.
        let mut lap = self.lap();
        self.sense(env, t);
        lap.to(&mut times.sense_s);
        self.communicate(t, &mut report.events);
        lap.to(&mut times.communicate_s);
        self.decide(t, env.seabed(), planners, &mut report);
        lap.to(&mut times.decide_s);
        self.control(&report.decisions, &mut report.events);
        lap.to(&mut times.control_s);
        self.integrate(env, t, &mut report.events);
        lap.to(&mut times.integrate_s);
        self.check(env, &mut report.events);
        lap.to(&mut times.check_s);
        self.step += 1;
        self.times = times;
        Ok(report)
    }

    fn sense(&mut self, env: &Environment, t: f64) {
        for v in self.vehicles.iter_mut().filter(|v| v.active) {
            let s = v.vehicle.state;
            if v.chem.due(t) {
                let c = env.sample_concentration(Vec3::new(s.pos_m.x, s.pos_m.y, s.z_m));
                let sample = v.chem.sample(c, t, &mut v.rng_chem);
                v.last_chem = Some(sample);
                v.pending_chem.push(sample);
            }
            if v.flow_sensor.due(t) {
                let truth = env.flow().velocity(s.pos_m);
                v.last_flow = Some(v.flow_sensor.sample(truth, t, &mut v.rng_flow));
            }
            if let Some(r) = &mut v.range
                && r.due(t)
            {
                v.last_ranges =
                    Some(r.sample(env.obstacles(), s.pos_m, s.heading, &mut v.rng_range));
            }
        }
    }

    fn communicate(&mut self, t: f64, events: &mut Vec<(VehicleId, WorldEvent)>) {
        for arrived in self.comms.arrived(t) {
            let m = arrived.message;
            let Some(v) = self.vehicles.get_mut(arrived.to.0 as usize) else {
                continue;
            };
            let deaf = v
                .deaf_window_s
                .is_some_and(|(a, b)| t + 1e-9 >= a && t + 1e-9 < b);
            if !v.active || deaf {
                events.push((
                    arrived.to,
                    WorldEvent::MessageLost {
                        from: m.from,
                        link: m.link,
                        sent_s: m.sent_s,
                        reason: if deaf {
                            LossReason::Deaf
                        } else {
                            LossReason::RecipientStopped
                        },
                    },
                ));
                continue;
            }
            events.push((
                arrived.to,
                WorldEvent::MessageDelivered {
                    from: m.from,
                    link: m.link,
                    sent_s: m.sent_s,
                },
            ));
            v.inbox.push(m);
        }
    }

    fn decide(
        &mut self,
        t: f64,
        seabed: Option<&plumetrace_env::Seabed>,
        planners: &mut [Option<Box<dyn Planner>>],
        report: &mut StepReport,
    ) {
        let n = self.vehicles.len();
        report.decisions = vec![None; n];
        if self.record_snapshots {
            report.snapshots = vec![None; n];
        }
        let depth = self.water_depth_m;
        let mut sent = Vec::new();
        for (k, v) in self.vehicles.iter_mut().enumerate() {
            let Some(p) = planners.get_mut(k).and_then(|p| p.as_mut()) else {
                // No planner reads them: nothing piles up.
                v.pending_chem.clear();
                v.inbox.clear();
                continue;
            };
            if !v.active || t + 1e-9 < v.next_decision_s {
                continue;
            }
            let period = p.decision_period_s();
            v.next_decision_s = if period > 0.0 && period.is_finite() {
                // Decisions on the grid k * period, whatever the step.
                ((t + 1e-9) / period).floor() * period + period
            } else {
                t
            };
            let snapshot = SensorSnapshot {
                time_s: t,
                vehicle: v.vehicle.id,
                nav: v.nav.estimate_over(
                    &v.vehicle.state,
                    v.vehicle.params.kind,
                    depth,
                    seabed.map(|s| s.height_at(v.vehicle.state.pos_m.x, v.vehicle.state.pos_m.y)),
                    &mut v.rng_measure,
                ),
                chem: std::mem::take(&mut v.pending_chem),
                flow: v.last_flow,
                ranges: v.last_ranges,
                inbox: std::mem::take(&mut v.inbox),
            };
            let decision = p.decide(&snapshot);
            sent.extend(decision.outbox.iter().map(|o| Message {
                from: v.vehicle.id,
                to: o.to,
                link: o.link,
                sent_s: t,
                body: o.body.clone(),
            }));
            if self.record_snapshots {
                report.snapshots[k] = Some(snapshot);
            }
            report.decisions[k] = Some(decision);
        }
        for m in &sent {
            self.transmit(m, &mut report.events);
        }
    }

    fn control(
        &mut self,
        decisions: &[Option<Decision>],
        events: &mut Vec<(VehicleId, WorldEvent)>,
    ) {
        for (v, d) in self.vehicles.iter_mut().zip(decisions) {
            let Some(d) = d else { continue };
            if d.command.is_finite() {
                v.command = d.command;
            } else {
                events.push((
                    v.vehicle.id,
                    WorldEvent::NonFiniteCommand {
                        command: format!("{:?}", d.command),
                    },
                ));
            }
        }
    }

    fn integrate(&mut self, env: &Environment, t: f64, events: &mut Vec<(VehicleId, WorldEvent)>) {
        let dt = self.dt_s;
        for v in self.vehicles.iter_mut().filter(|v| v.active) {
            let flow = env.flow().velocity(v.vehicle.state.pos_m);
            match env.seabed() {
                None => v
                    .vehicle
                    .step(&v.command, flow, self.water_depth_m, dt, &mut v.rng_motion),
                Some(sb) => v.vehicle.step_over(
                    &v.command,
                    flow,
                    self.water_depth_m,
                    Some(&|p: Vec2| sb.height_at(p.x, p.y)),
                    dt,
                    &mut v.rng_motion,
                ),
            }
            let measured = v.last_flow.map(|f| f.velocity_mps);
            if let Some(fix) = v
                .nav
                .update(&v.vehicle.state, measured, t + dt, dt, &mut v.rng_nav)
            {
                events.push((
                    v.vehicle.id,
                    WorldEvent::NavFix {
                        jump_m: fix.jump_m(),
                        to_m: fix.after_m,
                    },
                ));
            }
        }
    }

    fn check(&mut self, env: &Environment, events: &mut Vec<(VehicleId, WorldEvent)>) {
        let domain = env.domain();
        for v in self.vehicles.iter_mut().filter(|v| v.active) {
            let p = v.vehicle.state.pos_m;
            let incident = if !(domain.contains(p) && p.x.is_finite() && p.y.is_finite()) {
                Some(Incident::LeftDomain)
            } else if env.obstacles().contains(p) {
                Some(Incident::Collided)
            } else if env
                .seabed()
                .is_some_and(|s| v.vehicle.state.z_m < s.height_at(p.x, p.y))
            {
                Some(Incident::HitBottom)
            } else {
                None
            };
            if let Some(what) = incident {
                v.active = false;
                v.command.speed_mps = 0.0;
                events.push((v.vehicle.id, WorldEvent::Incident { what }));
            }
        }
    }
}

/// True slant distance between two vehicles (horizontal and vertical), m.
fn slant_m(a: &SimVehicle, b: &SimVehicle) -> f64 {
    let (p, q) = (&a.vehicle.state, &b.vehicle.state);
    ((p.pos_m - q.pos_m).norm_squared() + (p.z_m - q.z_m).powi(2)).sqrt()
}
