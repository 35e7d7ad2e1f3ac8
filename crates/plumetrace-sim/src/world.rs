//! The world: an environment and several vehicles stepped together in named stages.
//!
//! One step of `dt` runs, in order:
//! 1. **advance environment**: the flow and plume advance every `env_every` steps (the plume's
//!    step is a multiple of the vehicles'; its physics does not depend on the step);
//! 2. **sense**: each vehicle's due chemical, flow and range samples, taken at its true position;
//! 3. **communicate**: messages sent at the previous step are delivered (the seam for acoustic
//!    delays and losses);
//! 4. **decide**: each vehicle with a planner gets its [`SensorSnapshot`] (navigation estimate,
//!    samples since the last decision, messages) and returns a [`Decision`];
//! 5. **control**: a command that is not finite is replaced by the previous one;
//! 6. **integrate**: vehicle dynamics in the local current, then navigation (fixes jump here);
//! 7. **check**: vehicles that left the domain or entered an obstacle are stopped with an incident;
//! 8. **record**: the caller's observer sees the world after the step.
//!
//! Each stage is a function, and its wall time is summed in [`StageTimes`].

use crate::{
    ChemSensor, ChemSensorParams, FixEvent, FlowSensor, FlowSensorParams, NavParams, Navigator,
    RangeSensor, RangeSensorParams, Vehicle,
};
use plumetrace_core::{
    ChemSample, Command, Decision, FlowSample, Message, Planner, RangeReturn, SensorSnapshot, Vec3,
    VehicleId, VerticalCommand,
};
use plumetrace_env::{EnvError, Environment, FlowField, SimRng, StreamId, stream_rng};
use serde::Serialize;
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
    /// The observer.
    pub record_s: f64,
}

/// Something that stopped a vehicle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "incident")]
pub enum Incident {
    /// The vehicle's true position left the simulated domain.
    LeftDomain,
    /// The vehicle entered an obstacle (kelp is no-go for vehicles).
    Collided,
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
    pending_chem: Vec<ChemSample>,
    last_flow: Option<FlowSample>,
    last_ranges: Option<RangeReturn>,
    inbox: Vec<Message>,
    rng_motion: SimRng,
    rng_nav: SimRng,
    rng_chem: SimRng,
    rng_flow: SimRng,
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
            range: range.map(|params| RangeSensor { params }),
            command,
            active: true,
            last_chem: None,
            pending_chem: Vec::new(),
            last_flow: None,
            last_ranges: None,
            inbox: Vec::new(),
            rng_motion: stream_rng(seed, StreamId::Vehicle(i)),
            rng_nav: stream_rng(seed, StreamId::Sensor(i, 0)),
            rng_chem: stream_rng(seed, StreamId::Sensor(i, 1)),
            rng_flow: stream_rng(seed, StreamId::Sensor(i, 2)),
        }
    }
}

/// What one step produced.
#[derive(Debug, Default)]
pub struct StepReport {
    /// Each vehicle's decision, if it has a planner and is active (indexed by vehicle).
    pub decisions: Vec<Option<Decision>>,
    /// Navigation fixes.
    pub fixes: Vec<(VehicleId, FixEvent)>,
    /// Incidents.
    pub incidents: Vec<(VehicleId, Incident)>,
}

/// The simulated world.
#[derive(Debug)]
pub struct World {
    env: Environment,
    vehicles: Vec<SimVehicle>,
    dt_s: f64,
    env_every: u64,
    step: u64,
    water_depth_m: Option<f64>,
    outbox: Vec<Message>,
    times: StageTimes,
}

fn timed<T>(acc: &mut f64, f: impl FnOnce() -> T) -> T {
    let t0 = Instant::now();
    let out = f();
    *acc += t0.elapsed().as_secs_f64();
    out
}

impl World {
    /// A world stepping vehicles at `dt_s`; the environment's own step must be a whole number of
    /// vehicle steps.
    pub fn new(
        env: Environment,
        vehicles: Vec<SimVehicle>,
        dt_s: f64,
        water_depth_m: Option<f64>,
    ) -> Result<Self, EnvError> {
        plumetrace_env::error::require_positive("sim.dt_s", dt_s)?;
        let ratio = env.dt_s() / dt_s;
        if (ratio - ratio.round()).abs() > 1e-9 || ratio < 0.5 {
            return Err(EnvError::invalid(
                "mission.env_dt_s",
                format!(
                    "must be a whole multiple of sim.dt_s ({dt_s}), got {}",
                    env.dt_s()
                ),
            ));
        }
        Ok(World {
            env,
            vehicles,
            dt_s,
            env_every: ratio.round() as u64,
            step: 0,
            water_depth_m,
            outbox: Vec::new(),
            times: StageTimes::default(),
        })
    }

    /// Mission time, s (0 at the start, after any spin-up).
    pub fn time_s(&self) -> f64 {
        self.step as f64 * self.dt_s
    }

    /// The vehicles' step, s.
    pub fn dt_s(&self) -> f64 {
        self.dt_s
    }

    /// The environment.
    pub fn env(&self) -> &Environment {
        &self.env
    }

    /// The vehicles.
    pub fn vehicles(&self) -> &[SimVehicle] {
        &self.vehicles
    }

    /// Stops a vehicle (it keeps its position and takes no more decisions).
    pub fn stop(&mut self, id: VehicleId) {
        if let Some(v) = self.vehicles.get_mut(id.0 as usize) {
            v.active = false;
            v.command.speed_mps = 0.0;
        }
    }

    /// Queues a message for delivery at the next step.
    pub fn send(&mut self, m: Message) {
        self.outbox.push(m);
    }

    /// Time spent per stage so far.
    pub fn stage_times(&self) -> StageTimes {
        self.times
    }

    /// One step with one planner slot per vehicle (`None`: no planner, the vehicle keeps its
    /// command).
    pub fn step(
        &mut self,
        planners: &mut [Option<Box<dyn Planner>>],
        observer: &mut dyn FnMut(&World, &StepReport),
    ) -> Result<StepReport, EnvError> {
        let mut times = self.times;
        let t = self.time_s();
        timed(&mut times.advance_environment_s, || {
            self.advance_environment()
        })?;
        timed(&mut times.sense_s, || self.sense(t));
        timed(&mut times.communicate_s, || self.communicate());
        let decisions = timed(&mut times.decide_s, || self.decide(t, planners));
        timed(&mut times.control_s, || self.control(&decisions));
        let fixes = timed(&mut times.integrate_s, || self.integrate(t));
        let incidents = timed(&mut times.check_s, || self.check());
        let report = StepReport {
            decisions,
            fixes,
            incidents,
        };
        self.step += 1;
        let t0 = Instant::now();
        observer(self, &report);
        times.record_s += t0.elapsed().as_secs_f64();
        self.times = times;
        Ok(report)
    }

    fn advance_environment(&mut self) -> Result<(), EnvError> {
        if self.step.is_multiple_of(self.env_every) {
            self.env.step()?;
        }
        Ok(())
    }

    fn sense(&mut self, t: f64) {
        let env = &self.env;
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
            if let Some(r) = &v.range {
                v.last_ranges = Some(r.sample(env.obstacles(), s.pos_m, s.heading));
            }
        }
    }

    fn communicate(&mut self) {
        for m in self.outbox.drain(..) {
            for v in self
                .vehicles
                .iter_mut()
                .filter(|v| v.active && v.vehicle.id != m.from)
            {
                let for_it = match m.to {
                    plumetrace_core::Recipient::Broadcast => true,
                    plumetrace_core::Recipient::Vehicle(id) => id == v.vehicle.id,
                };
                if for_it {
                    v.inbox.push(m.clone());
                }
            }
        }
    }

    fn decide(
        &mut self,
        t: f64,
        planners: &mut [Option<Box<dyn Planner>>],
    ) -> Vec<Option<Decision>> {
        let mut out = Vec::with_capacity(self.vehicles.len());
        for (k, v) in self.vehicles.iter_mut().enumerate() {
            let planner = planners.get_mut(k).and_then(|p| p.as_mut());
            match planner {
                Some(p) if v.active => {
                    let snapshot = SensorSnapshot {
                        time_s: t,
                        vehicle: v.vehicle.id,
                        nav: v.nav.estimate(&v.vehicle.state),
                        chem: std::mem::take(&mut v.pending_chem),
                        flow: v.last_flow,
                        ranges: v.last_ranges,
                        inbox: std::mem::take(&mut v.inbox),
                    };
                    out.push(Some(p.decide(&snapshot)));
                }
                _ => out.push(None),
            }
        }
        out
    }

    fn control(&mut self, decisions: &[Option<Decision>]) {
        for (v, d) in self.vehicles.iter_mut().zip(decisions) {
            if let Some(d) = d
                && d.command.is_finite()
            {
                v.command = d.command;
            }
        }
    }

    fn integrate(&mut self, t: f64) -> Vec<(VehicleId, FixEvent)> {
        let mut fixes = Vec::new();
        let dt = self.dt_s;
        for v in self.vehicles.iter_mut().filter(|v| v.active) {
            let flow = self.env.flow().velocity(v.vehicle.state.pos_m);
            v.vehicle
                .step(&v.command, flow, self.water_depth_m, dt, &mut v.rng_motion);
            let measured = v.last_flow.map(|f| f.velocity_mps);
            if let Some(fix) = v
                .nav
                .update(&v.vehicle.state, measured, t + dt, dt, &mut v.rng_nav)
            {
                fixes.push((v.vehicle.id, fix));
            }
        }
        fixes
    }

    fn check(&mut self) -> Vec<(VehicleId, Incident)> {
        let mut incidents = Vec::new();
        let domain = self.env.domain();
        for v in self.vehicles.iter_mut().filter(|v| v.active) {
            let p = v.vehicle.state.pos_m;
            let incident = if !(domain.contains(p) && p.x.is_finite() && p.y.is_finite()) {
                Some(Incident::LeftDomain)
            } else if self.env.obstacles().contains(p) {
                Some(Incident::Collided)
            } else {
                None
            };
            if let Some(i) = incident {
                v.active = false;
                v.command.speed_mps = 0.0;
                incidents.push((v.vehicle.id, i));
            }
        }
        incidents
    }
}
