//! A mission as a stepper: [`Mission::new`] spins the plume up and builds the world and the
//! planners, [`Mission::step`] runs one step and lets the observers record it,
//! [`Mission::finish`] returns what was recorded.
//!
//! The step itself is the world's (stages 1-7); the mission then applies the planners' statuses
//! (a planner that finishes or aborts stops its vehicle), records (stage 8, the observers) and
//! checks for the end. What the mission comes to is decided in [`crate::outcome`].

use crate::outcome::{EndReason, MissionEnd, MissionEvent, Outcome, VehicleStatus};
use crate::record::{
    EventRecord, EventRecorder, MeanPlumeRecorder, Observer, PlumeFrames, StepView, TrackStats,
    TrajectoryRecorder, TrajectoryRow, true_sources,
};
use crate::setup::{MissionError, MissionSetup, PlannedVehicle};
use crate::summary::{Summary, SummaryInput};
use plumetrace_core::{PlanStatus, Planner, Vec2, Vec3, VehicleId, VehicleKind};
use plumetrace_env::Environment;
use plumetrace_env::MeanConcentrationGrid;
use plumetrace_planner::{MissionGeometry, PlannerKind};
use plumetrace_sim::{Fleet, SimVehicle, StageTimes, WorldEvent, WorldView};
use std::time::Instant;

/// What a mission records besides its summary and events.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MissionOptions {
    /// Accumulate the time-averaged plume over the op-area for the figure (a grid of
    /// concentration queries every [`MeanPlumeRecorder::every_s`] of the time limit).
    pub mean_plume: bool,
    /// Keep every step of every vehicle's trajectory.
    pub trajectory: bool,
    /// Sample the plume and the flow every this many seconds for the replay page
    /// ([`PlumeFrames`]; `None`: not at all).
    pub plume_frames_every_s: Option<f64>,
    /// Time each stage of the step ([`MissionRun::stage_times`]; all zero when off): seven
    /// clock readings a step, about 4 % of a `duck-2003-st` mission's CPU. Campaigns leave it
    /// off.
    pub stage_times: bool,
}

/// The whole number of steps of `dt_s` nearest to `every_s`, at least one (how often a recorder
/// samples).
fn steps_of(every_s: f64, dt_s: f64) -> u64 {
    (every_s / dt_s).round().max(1.0) as u64
}

/// The replay page's plume frame interval when nothing else is asked for, s.
pub const PLUME_FRAME_EVERY_S: f64 = 60.0;

impl Default for MissionOptions {
    fn default() -> Self {
        MissionOptions {
            mean_plume: true,
            trajectory: true,
            plume_frames_every_s: Some(PLUME_FRAME_EVERY_S),
            stage_times: true,
        }
    }
}

/// A vehicle as the figure and summaries name it.
#[derive(Debug, Clone, PartialEq)]
pub struct VehicleInfo {
    /// Name.
    pub name: String,
    /// AUV or surface craft.
    pub kind: VehicleKind,
    /// Its planner's kind, if any.
    pub planner: Option<PlannerKind>,
    /// When its sensors were faulty (from the scenario), for the figures.
    pub faults: Vec<FaultWindow>,
    /// The unit of its chemical readings: "V" (the analog sensor) or "ppt" (a salinity probe).
    pub reading_unit: &'static str,
}

/// A time window in which one of a vehicle's sensors was faulty.
#[derive(Debug, Clone, PartialEq)]
pub struct FaultWindow {
    /// Start, s.
    pub start_s: f64,
    /// End, s.
    pub end_s: f64,
    /// What was wrong, in words.
    pub what: &'static str,
}

/// Everything a mission produced.
#[derive(Debug)]
pub struct MissionRun {
    /// What it came to.
    pub outcome: Outcome,
    /// Key numbers.
    pub summary: Summary,
    /// Every step of every vehicle (empty unless recorded).
    pub trajectory: Vec<TrajectoryRow>,
    /// The event stream.
    pub events: Vec<EventRecord>,
    /// Wall time per stage.
    pub stage_times: StageTimes,
    /// Wall time of the spin-up, s.
    pub spinup_wall_s: f64,
    /// Time-averaged concentration at the first vehicle's altitude over the op-area (if
    /// recorded).
    pub mean_plume: Option<MeanConcentrationGrid>,
    /// The plume and flow sampled during the run (if recorded).
    pub plume_frames: Option<PlumeFrames>,
    /// True sources.
    pub sources: Vec<Vec3>,
    /// Op-area polygon.
    pub op_area: Vec<Vec2>,
    /// Subregions.
    pub subregions: Vec<Vec<Vec2>>,
    /// Obstacle outlines.
    pub obstacles: Vec<Vec<Vec2>>,
    /// Mean flow at the first source over the mission, m/s.
    pub mean_flow_mps: Vec2,
    /// The vehicles, by index.
    pub vehicles: Vec<VehicleInfo>,
}

/// A mission being flown.
pub struct Mission {
    env: Environment,
    flight: Flight,
}

/// A mission without its environment: the fleet, its planners, observers and end conditions.
/// It flies in an environment it is given at every step, its own ([`Mission`]) or one shared
/// with other missions ([`crate::shared::SharedMissions`]), and only reads it.
pub(crate) struct Flight {
    name: String,
    seed: u64,
    fleet: Fleet,
    planners: Vec<Option<Box<dyn Planner>>>,
    planned: Vec<Option<PlannedVehicle>>,
    statuses: Vec<VehicleStatus>,
    step_limit: u64,
    first_failure: Option<Outcome>,
    end: Option<MissionEnd>,
    events: EventRecorder,
    trajectory: Option<TrajectoryRecorder>,
    stats: TrackStats,
    team: crate::team::TeamStats,
    mean_plume: Option<MeanPlumeRecorder>,
    plume_frames: Option<PlumeFrames>,
    faults: Vec<Vec<FaultWindow>>,
    observers: Vec<Box<dyn Observer>>,
    sources: Vec<Vec3>,
    geometry: MissionGeometry,
    op_area: Vec<Vec2>,
    subregions: Vec<Vec<Vec2>>,
    success_radius_m: f64,
    spinup_wall_s: f64,
}

impl Mission {
    /// Develops the plume (spin-up), then builds the world and every vehicle's planner.
    pub fn new(mut setup: MissionSetup, options: MissionOptions) -> Result<Self, MissionError> {
        let started = Instant::now();
        setup.spin_up()?;
        let spinup_wall_s = started.elapsed().as_secs_f64();
        let (env, flight) = Flight::new(setup, options, None, spinup_wall_s);
        Ok(Mission {
            env,
            flight: flight?,
        })
    }
}

impl Flight {
    /// Builds the fleet and every vehicle's planner from a spun-up setup, to fly in `shared`
    /// if given, else in the setup's own environment; the setup's own environment is returned
    /// either way (unused and unchanged when `shared` is given or building fails).
    pub(crate) fn new(
        setup: MissionSetup,
        options: MissionOptions,
        shared: Option<&Environment>,
        spinup_wall_s: f64,
    ) -> (Environment, Result<Self, MissionError>) {
        let origin = setup.origin.to_string();
        let env_error = |error| MissionError::Env {
            origin: origin.clone(),
            error,
        };
        let MissionSetup {
            name,
            seed,
            env: own_env,
            vehicles: setups,
            planners: planned,
            geometry,
            spec,
            dt_s,
            depth_m,
            comms,
            ..
        } = setup;
        let env = shared.unwrap_or(&own_env);
        let built = (|| {
            let mut vehicles = Vec::with_capacity(setups.len());
            let mut planners: Vec<Option<Box<dyn Planner>>> = Vec::with_capacity(setups.len());
            for (v, p) in setups.iter().zip(&planned) {
                let mut sim = SimVehicle::new(
                    v.name.clone(),
                    v.vehicle.clone(),
                    v.nav,
                    v.chem_sensor,
                    v.flow_sensor,
                    v.range_sensor,
                    seed,
                );
                sim.deaf_window_s = v.deaf_window_s;
                vehicles.push(sim);
                planners.push(match p {
                    Some(p) => Some(p.config.build(&p.context, &p.key).map_err(|error| {
                        MissionError::Invalid {
                            origin: origin.clone(),
                            error,
                        }
                    })?),
                    None => None,
                });
            }
            let mut fleet =
                Fleet::new(env, vehicles, dt_s, depth_m, comms, seed).map_err(env_error)?;
            fleet.time_stages(options.stage_times);
            let sources = true_sources(WorldView::new(env, &fleet));
            let statuses: Vec<VehicleStatus> = planned
                .iter()
                .map(|p| {
                    if p.is_some() {
                        VehicleStatus::Active
                    } else {
                        VehicleStatus::NoPlanner
                    }
                })
                .collect();
            let sample_every = steps_of(20.0, dt_s);
            let thresholds: Vec<Option<f64>> = planned
                .iter()
                .map(|p| p.as_ref().and_then(|p| p.config.detection_threshold_v()))
                .collect();
            let positions: Vec<bool> = setups.iter().map(|v| v.nav.position_estimate).collect();
            // The figure's plume at the height of the first vehicle with a planner.
            let z = planned
                .iter()
                .position(Option::is_some)
                .and_then(|k| setups.get(k))
                .map_or(0.0, |v| v.vehicle.state.z_m);
            let mean_plume = options.mean_plume.then(|| {
                MeanPlumeRecorder::new(
                    MeanPlumeRecorder::grid_over(&spec.op_area, env.domain(), z),
                    steps_of(MeanPlumeRecorder::every_s(spec.time_limit_s), dt_s),
                )
            });
            let plume_frames = options
                .plume_frames_every_s
                .filter(|s| s.is_finite() && *s > 0.0)
                .map(|every| {
                    PlumeFrames::over(&spec.op_area, env.domain(), z, steps_of(every, dt_s))
                });
            let faults = setups
                .iter()
                .map(|v| {
                    v.flow_sensor
                        .fault
                        .map(|f| FaultWindow {
                            start_s: f.start_s,
                            end_s: f.end_s,
                            what: "flow sensor reads the wrong layer",
                        })
                        .into_iter()
                        .collect()
                })
                .collect();
            let flight = Flight {
                name,
                plume_frames,
                faults,
                seed,
                step_limit: (spec.time_limit_s / dt_s).round() as u64,
                stats: TrackStats::new(
                    thresholds.clone(),
                    &spec.op_area,
                    sources.first().map(|s| s.xy()),
                    sample_every,
                ),
                team: crate::team::TeamStats::new(
                    planned.iter().map(Option::is_some).collect(),
                    sources.first().copied(),
                ),
                trajectory: options
                    .trajectory
                    .then(|| TrajectoryRecorder::new(thresholds, positions)),
                fleet,
                planners,
                planned,
                statuses,
                first_failure: None,
                end: None,
                events: EventRecorder::default(),
                mean_plume,
                observers: Vec::new(),
                sources,
                geometry,
                op_area: spec.op_area,
                subregions: spec.subregions,
                success_radius_m: spec.success_radius_m,
                spinup_wall_s,
            };
            Ok(flight)
        })();
        (own_env, built)
    }

    /// The fleet.
    pub(crate) fn fleet(&self) -> &Fleet {
        &self.fleet
    }

    /// Adds time spent advancing the environment for this mission.
    pub(crate) fn add_environment_time(&mut self, s: f64) {
        self.fleet.add_environment_time(s);
    }

    /// Adds an observer (e.g. a snapshot log); the world keeps snapshots if it wants them. An
    /// observer that wants snapshots must come before the first step (a log that misses the first
    /// decisions could not be replayed).
    pub(crate) fn observe(&mut self, o: Box<dyn Observer>) -> Result<(), MissionError> {
        if o.wants_snapshots() {
            if self.fleet.steps() > 0 {
                return Err(MissionError::Output {
                    what: "a snapshot log".into(),
                    message: format!(
                        "it must observe the mission from its start, not from step {}",
                        self.fleet.steps()
                    ),
                });
            }
            self.fleet.record_snapshots(true);
        }
        self.observers.push(o);
        Ok(())
    }

    /// Scenario name.
    pub(crate) fn name(&self) -> &str {
        &self.name
    }

    /// Run seed.
    pub(crate) fn seed(&self) -> u64 {
        self.seed
    }

    /// Flies `planner` for vehicle `vehicle` instead of the one its planner table builds: a
    /// planner outside the registry (written in Python, or an agent being trained) behind the
    /// same [`Planner`] seam. Only before the first step, and only for a vehicle with a planner
    /// table: the table still gives the detection threshold the trajectory and statistics mark
    /// detections with, and the snapshot log's header still names it.
    pub(crate) fn replace_planner(
        &mut self,
        vehicle: usize,
        planner: Box<dyn Planner>,
    ) -> Result<(), MissionError> {
        let invalid = |message: String| MissionError::Output {
            what: "a replacement planner".into(),
            message,
        };
        if self.fleet.steps() > 0 {
            return Err(invalid(format!(
                "planners can only be replaced before the first step, not at step {}",
                self.fleet.steps()
            )));
        }
        match self.planners.get_mut(vehicle) {
            Some(slot @ Some(_)) => {
                *slot = Some(planner);
                Ok(())
            }
            Some(None) => Err(invalid(format!(
                "vehicle {vehicle} ({}) has no planner table to replace",
                self.fleet.vehicles()[vehicle].name
            ))),
            None => Err(invalid(format!(
                "there is no vehicle {vehicle} (the mission has {})",
                self.planners.len()
            ))),
        }
    }

    /// Each vehicle's planner as configured.
    pub(crate) fn planned(&self) -> &[Option<PlannedVehicle>] {
        &self.planned
    }

    /// The mission geometry the planners fly.
    pub(crate) fn geometry(&self) -> &MissionGeometry {
        &self.geometry
    }

    /// Each vehicle's status.
    pub(crate) fn statuses(&self) -> &[VehicleStatus] {
        &self.statuses
    }

    /// The vehicles' names, by index.
    pub(crate) fn vehicle_names(&self) -> Vec<String> {
        self.fleet
            .vehicles()
            .iter()
            .map(|v| v.name.clone())
            .collect()
    }

    /// Mission time, s.
    pub(crate) fn time_s(&self) -> f64 {
        self.fleet.time_s()
    }

    /// The mission's time limit, s.
    pub(crate) fn time_limit_s(&self) -> f64 {
        self.step_limit as f64 * self.fleet.dt_s()
    }

    /// The end, once reached.
    pub(crate) fn end(&self) -> Option<MissionEnd> {
        self.end
    }

    /// One step; returns the end when this step (or an earlier one) ended the mission.
    /// An environment error of this mission, named by its scenario.
    pub(crate) fn env_error(&self, error: plumetrace_env::EnvError) -> MissionError {
        MissionError::Env {
            origin: format!("scenario '{}'", self.name),
            error,
        }
    }

    pub(crate) fn step(&mut self, env: &Environment) -> Result<Option<MissionEnd>, MissionError> {
        if self.end.is_some() {
            return Ok(self.end);
        }
        let report = self
            .fleet
            .step(env, &mut self.planners)
            .map_err(|error| self.env_error(error))?;
        let mut mission_events = Vec::new();
        for (i, d) in report.decisions.iter().enumerate() {
            let Some(d) = d else { continue };
            let id = VehicleId(i as u32);
            match d.status {
                PlanStatus::Running => {}
                PlanStatus::Finished => {
                    if self.statuses[i] == VehicleStatus::Active {
                        self.statuses[i] = VehicleStatus::Finished;
                        self.fleet.stop(id);
                        mission_events.push((id, MissionEvent::PlannerFinished));
                    }
                }
                PlanStatus::Abort => {
                    self.statuses[i] = VehicleStatus::Aborted;
                    self.first_failure
                        .get_or_insert(Outcome::of_abort(&d.events));
                    self.fleet.stop(id);
                    mission_events.push((id, MissionEvent::PlannerAborted));
                }
            }
        }
        // Vehicles an incident stops while still flying (not finished or aborted by their
        // planners this step): their runs end for a reason the planners did not choose.
        let mut stopped: Vec<usize> = Vec::new();
        for (id, e) in &report.events {
            if let WorldEvent::Incident { what } = e {
                let k = id.0 as usize;
                // A vehicle without a planner is recorded, but fails nothing.
                if self.statuses[k] != VehicleStatus::NoPlanner {
                    self.first_failure
                        .get_or_insert(Outcome::of_incident(*what));
                }
                if self.statuses[k] == VehicleStatus::Active {
                    stopped.push(k);
                }
                self.statuses[k] = VehicleStatus::of_incident(*what);
            }
        }
        let t = self.fleet.time_s();
        if !self.statuses.contains(&VehicleStatus::Active) {
            self.end = Some(MissionEnd {
                reason: EndReason::PlannersDone,
                t_s: t,
            });
        } else if self.fleet.steps() >= self.step_limit {
            self.end = Some(MissionEnd {
                reason: EndReason::TimeLimit,
                t_s: t,
            });
        }
        // What a planner still has to report when its run ends for a reason it did not choose
        // (an incident, the time limit), as on a vehicle: a declaration it was holding.
        let time_limit = matches!(self.end, Some(e) if e.reason == EndReason::TimeLimit);
        let mut ended = Vec::new();
        if time_limit || !stopped.is_empty() {
            for (k, planner) in self.planners.iter_mut().enumerate() {
                let Some(planner) = planner else { continue };
                let active = self.statuses[k] == VehicleStatus::Active;
                if stopped.contains(&k) || (time_limit && active) {
                    let events = planner.run_ended(t);
                    if !events.is_empty() {
                        ended.push((k, events));
                    }
                }
            }
        }
        let mut lap = self.fleet.lap();
        let mut record_s = 0.0;
        {
            let view = StepView {
                world: WorldView::new(env, &self.fleet),
                report: &report,
                mission_events: &mission_events,
                statuses: &self.statuses,
                ended: &ended,
            };
            self.events.observe(&view);
            self.stats.observe(&view);
            self.team.observe(&view);
            if let Some(t) = self.trajectory.as_mut() {
                t.observe(&view);
            }
            if let Some(m) = self.mean_plume.as_mut() {
                m.observe(&view);
            }
            if let Some(f) = self.plume_frames.as_mut() {
                f.observe(&view);
            }
            for o in &mut self.observers {
                o.observe(&view);
            }
        }
        lap.to(&mut record_s);
        self.fleet.add_record_time(record_s);
        Ok(self.end)
    }

    /// What was recorded; the observers are finished (their buffered output flushed).
    pub(crate) fn finish(mut self, env: &Environment) -> Result<MissionRun, MissionError> {
        for o in &mut self.observers {
            o.finish().map_err(|e| MissionError::Output {
                what: "an observer's output".into(),
                message: e.to_string(),
            })?;
        }
        let end = self.end.unwrap_or(MissionEnd {
            reason: EndReason::TimeLimit,
            t_s: self.fleet.time_s(),
        });
        let vehicles: Vec<VehicleInfo> = self
            .fleet
            .vehicles()
            .iter()
            .zip(&self.planned)
            .zip(&self.faults)
            .map(|((v, p), faults)| VehicleInfo {
                name: v.name.clone(),
                kind: v.vehicle.params.kind,
                planner: p.as_ref().map(|p| p.config.kind()),
                faults: faults.clone(),
                reading_unit: if v.chem.params().salinity.is_some() {
                    "ppt"
                } else {
                    "V"
                },
            })
            .collect();
        let mean_flow = self.stats.mean_flow_mps();
        let summary = Summary::new(SummaryInput {
            scenario: self.name.clone(),
            seed: self.seed,
            end,
            first_failure: self.first_failure,
            statuses: &self.statuses,
            tracks: &self.stats.tracks,
            vehicles: vehicles
                .iter()
                .map(|v| (v.name.clone(), v.kind, v.planner))
                .collect(),
            sources: &self.sources,
            success_radius_m: self.success_radius_m,
            subregions: self.subregions.len(),
            mean_flow_mps: mean_flow,
            team: self.team.summary(),
        });
        Ok(MissionRun {
            outcome: summary.outcome,
            summary,
            trajectory: self.trajectory.map(|t| t.rows).unwrap_or_default(),
            events: self.events.events,
            stage_times: self.fleet.stage_times(),
            spinup_wall_s: self.spinup_wall_s,
            mean_plume: self.mean_plume.map(|m| m.grid),
            plume_frames: self.plume_frames,
            sources: self.sources,
            op_area: self.op_area,
            subregions: self.subregions,
            obstacles: env
                .obstacles()
                .iter()
                .map(|o| {
                    o.polygon
                        .exterior()
                        .coords()
                        .map(|c| Vec2::new(c.x, c.y))
                        .collect()
                })
                .collect(),
            mean_flow_mps: mean_flow,
            vehicles,
        })
    }
}

impl Mission {
    /// Adds an observer (e.g. a snapshot log); the world keeps snapshots if it wants them. An
    /// observer that wants snapshots must come before the first step (a log that misses the first
    /// decisions could not be replayed).
    pub fn observe(&mut self, o: Box<dyn Observer>) -> Result<(), MissionError> {
        self.flight.observe(o)
    }

    /// Scenario name.
    pub fn name(&self) -> &str {
        self.flight.name()
    }

    /// Run seed.
    pub fn seed(&self) -> u64 {
        self.flight.seed()
    }

    /// The world: the mission's environment and its fleet.
    pub fn world(&self) -> WorldView<'_> {
        WorldView::new(&self.env, &self.flight.fleet)
    }

    /// Flies `planner` for vehicle `vehicle` instead of the one its planner table builds: a
    /// planner outside the registry (written in Python, or an agent being trained) behind the
    /// same [`Planner`] seam. Only before the first step, and only for a vehicle with a planner
    /// table: the table still gives the detection threshold the trajectory and statistics mark
    /// detections with, and the snapshot log's header still names it.
    pub fn replace_planner(
        &mut self,
        vehicle: usize,
        planner: Box<dyn Planner>,
    ) -> Result<(), MissionError> {
        self.flight.replace_planner(vehicle, planner)
    }

    /// Each vehicle's planner as configured.
    pub fn planned(&self) -> &[Option<PlannedVehicle>] {
        self.flight.planned()
    }

    /// The mission geometry the planners fly.
    pub fn geometry(&self) -> &MissionGeometry {
        self.flight.geometry()
    }

    /// Each vehicle's status.
    pub fn statuses(&self) -> &[VehicleStatus] {
        self.flight.statuses()
    }

    /// The vehicles' names, by index.
    pub fn vehicle_names(&self) -> Vec<String> {
        self.flight.vehicle_names()
    }

    /// Mission time, s.
    pub fn time_s(&self) -> f64 {
        self.flight.time_s()
    }

    /// The mission's time limit, s.
    pub fn time_limit_s(&self) -> f64 {
        self.flight.time_limit_s()
    }

    /// The end, once reached.
    pub fn end(&self) -> Option<MissionEnd> {
        self.flight.end()
    }

    /// One step (the environment first when it is due, then the fleet); returns the end when
    /// this step (or an earlier one) ended the mission.
    pub fn step(&mut self) -> Result<Option<MissionEnd>, MissionError> {
        if self.flight.end.is_some() {
            return Ok(self.flight.end);
        }
        if self.flight.fleet.env_due() {
            let mut lap = self.flight.fleet.lap();
            let mut env_s = 0.0;
            self.env
                .step()
                .map_err(|error| self.flight.env_error(error))?;
            lap.to(&mut env_s);
            self.flight.fleet.add_environment_time(env_s);
        }
        self.flight.step(&self.env)
    }

    /// Steps to the end; `progress(t, limit)` is called every 600 steps.
    pub fn run(&mut self, progress: &mut dyn FnMut(f64, f64)) -> Result<MissionEnd, MissionError> {
        let limit = self.time_limit_s();
        loop {
            if let Some(end) = self.step()? {
                return Ok(end);
            }
            if self.flight.fleet.steps().is_multiple_of(600) {
                progress(self.flight.fleet.time_s(), limit);
            }
        }
    }

    /// What was recorded; the observers are finished (their buffered output flushed).
    pub fn finish(self) -> Result<MissionRun, MissionError> {
        self.flight.finish(&self.env)
    }
}

/// Sets up, flies and finishes a scenario's mission recording what `options` asks for;
/// `progress(t, limit)` is called now and then.
pub fn run_mission_with(
    sc: plumetrace_scenario::BuiltScenario,
    options: MissionOptions,
    progress: &mut dyn FnMut(f64, f64),
) -> Result<MissionRun, MissionError> {
    let mut m = Mission::new(MissionSetup::new(sc)?, options)?;
    m.run(progress)?;
    m.finish()
}

/// [`run_mission_with`] recording everything.
pub fn run_mission(
    sc: plumetrace_scenario::BuiltScenario,
    progress: &mut dyn FnMut(f64, f64),
) -> Result<MissionRun, MissionError> {
    run_mission_with(sc, MissionOptions::default(), progress)
}
