//! Recording a mission: observers of the step.
//!
//! An [`Observer`] sees every step after it ran ([`StepView`]: the world, the step's decisions,
//! snapshots and world events, and what the mission made of them). The mission's own records are
//! observers too: [`EventRecorder`] (every vehicle's planner events, telemetry, world and mission
//! events), [`TrajectoryRecorder`] (every vehicle, every step), [`TrackStats`] (path lengths and
//! first detections for the summary) and [`MeanPlumeRecorder`] (the figure's time-averaged
//! plume). Plots are drawn afterwards from what they recorded, never inside the loop.

use crate::outcome::{MissionEvent, VehicleStatus};
use plumetrace_core::{BehaviourKind, PlannerEvent, Telemetry, Vec2, Vec3, VehicleId};
use plumetrace_env::{ConcentrationField, FlowField, GridSpec, MeanConcentrationGrid};
use plumetrace_sim::{Incident, StepReport, WorldEvent, WorldView};
use serde::Serialize;

/// What observers see after a step.
pub struct StepView<'a> {
    /// The world after the step.
    pub world: WorldView<'a>,
    /// The step's decisions, snapshots (when recorded) and world events; `report.t_s` is the
    /// time the snapshots were taken.
    pub report: &'a StepReport,
    /// What the mission recorded about vehicles in this step.
    pub mission_events: &'a [(VehicleId, MissionEvent)],
    /// Every vehicle's status after the step.
    pub statuses: &'a [VehicleStatus],
    /// What planners still had to report as their runs ended in this step for a reason they
    /// did not choose (an incident, the time limit: [`plumetrace_core::Planner::run_ended`]),
    /// by vehicle index: a declaration a planner was holding.
    pub ended: &'a [(usize, Vec<PlannerEvent>)],
}

impl StepView<'_> {
    /// Every planner event of the step with its vehicle's index: each decision's events, then
    /// what planners reported as their runs ended ([`StepView::ended`]).
    pub fn planner_events(&self) -> impl Iterator<Item = (usize, &PlannerEvent)> {
        let decided = self.report.decisions.iter().enumerate().flat_map(|(k, d)| {
            d.iter()
                .flat_map(move |d| d.events.iter().map(move |e| (k, e)))
        });
        let ended = self
            .ended
            .iter()
            .flat_map(|(k, events)| events.iter().map(move |e| (*k, e)));
        decided.chain(ended)
    }

    /// Each vehicle that decided this step, with the snapshot it decided on (recorded only when
    /// an observer wants snapshots) and its decision, by vehicle index.
    pub fn decided(
        &self,
    ) -> impl Iterator<
        Item = (
            usize,
            &plumetrace_core::SensorSnapshot,
            &plumetrace_core::Decision,
        ),
    > {
        self.report
            .snapshots
            .iter()
            .zip(&self.report.decisions)
            .enumerate()
            .filter_map(|(k, (s, d))| Some((k, s.as_ref()?, d.as_ref()?)))
    }
}

/// Something that records a mission as it runs.
pub trait Observer: Send {
    /// Looks at one step.
    fn observe(&mut self, step: &StepView<'_>);

    /// Whether it needs the snapshots given to planners (the world then keeps them).
    fn wants_snapshots(&self) -> bool {
        false
    }

    /// The mission is over: flush what is buffered; errors name what could not be written.
    fn finish(&mut self) -> Result<(), RecordError> {
        Ok(())
    }
}

/// Why an observer could not write its output.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// A file could not be written.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: String,
        /// What failed.
        message: String,
    },
    /// A log writer failed; its message names the file.
    #[error(transparent)]
    Log(#[from] plumetrace_log::LogError),
}

impl RecordError {
    /// A file that could not be written.
    pub fn file(path: &std::path::Path, e: impl std::fmt::Display) -> Self {
        RecordError::File {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    }
}

/// Any event of a vehicle, as written to `events.jsonl` (every kind tagged by its `event`
/// field, names from serde).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum EventKind {
    /// From the vehicle's planner.
    Planner(PlannerEvent),
    /// The planner's beliefs.
    Telemetry(Telemetry),
    /// From the world (fixes, incidents, messages, bad commands).
    World(WorldEvent),
    /// From the mission (planner finished or aborted).
    Mission(MissionEvent),
}

/// One timestamped event of one vehicle.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EventRecord {
    /// Time, s (the decision time of the step it happened in).
    pub t_s: f64,
    /// Vehicle index.
    pub vehicle: u32,
    /// The event.
    #[serde(flatten)]
    pub event: EventKind,
}

/// A lost point of a run: saved by a [`PlannerEvent::LostPoint`], then moved by each
/// [`PlannerEvent::LostPointMoved`] of the same vehicle from where it was.
#[derive(Debug, Clone, PartialEq)]
pub struct LostPointTrack {
    /// The index of the event that saved it.
    pub saved: usize,
    /// Its vehicle.
    pub vehicle: u32,
    /// Where it was saved, m.
    pub pos_m: Vec2,
    /// Each move, in order: when (s) and where to (m).
    pub moves: Vec<(f64, Vec2)>,
}

impl LostPointTrack {
    /// Where its planner last put it, m.
    pub fn now_m(&self) -> Vec2 {
        self.moves.last().map_or(self.pos_m, |m| m.1)
    }
}

/// Every lost point of `events`, in the order saved. A move is the latest point of its vehicle
/// last at the move's `from_m` (the latest, should two have been saved at the same spot); a move
/// from where no point is, is passed over.
pub fn lost_points(events: &[EventRecord]) -> Vec<LostPointTrack> {
    let mut points: Vec<LostPointTrack> = Vec::new();
    for (k, e) in events.iter().enumerate() {
        match &e.event {
            EventKind::Planner(PlannerEvent::LostPoint { pos_m }) => {
                points.push(LostPointTrack {
                    saved: k,
                    vehicle: e.vehicle,
                    pos_m: *pos_m,
                    moves: Vec::new(),
                });
            }
            EventKind::Planner(PlannerEvent::LostPointMoved { from_m, to_m }) => {
                if let Some(p) = points
                    .iter_mut()
                    .rev()
                    .find(|p| p.vehicle == e.vehicle && p.now_m() == *from_m)
                {
                    p.moves.push((e.t_s, *to_m));
                }
            }
            _ => {}
        }
    }
    points
}

/// Records every event of every vehicle, in order.
#[derive(Debug, Default)]
pub struct EventRecorder {
    /// The events so far.
    pub events: Vec<EventRecord>,
}

impl Observer for EventRecorder {
    fn observe(&mut self, step: &StepView<'_>) {
        let t = step.report.t_s;
        for (i, d) in step.report.decisions.iter().enumerate() {
            let Some(d) = d else { continue };
            let vehicle = i as u32;
            self.events.extend(d.events.iter().map(|e| EventRecord {
                t_s: t,
                vehicle,
                event: EventKind::Planner(e.clone()),
            }));
            self.events.extend(d.telemetry.iter().map(|e| EventRecord {
                t_s: t,
                vehicle,
                event: EventKind::Telemetry(e.clone()),
            }));
        }
        self.events
            .extend(step.report.events.iter().map(|(id, e)| EventRecord {
                t_s: t,
                vehicle: id.0,
                event: EventKind::World(e.clone()),
            }));
        // After the incident that ended a run, what its planner still had to report.
        self.events
            .extend(step.ended.iter().flat_map(|(k, events)| {
                events.iter().map(move |e| EventRecord {
                    t_s: t,
                    vehicle: *k as u32,
                    event: EventKind::Planner(e.clone()),
                })
            }));
        self.events
            .extend(step.mission_events.iter().map(|(id, e)| EventRecord {
                t_s: t,
                vehicle: id.0,
                event: EventKind::Mission(*e),
            }));
    }
}

/// One row of the trajectory (one vehicle, one step).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrajectoryRow {
    /// Time, s.
    pub t_s: f64,
    /// Vehicle index.
    pub vehicle: u32,
    /// True position, m.
    pub true_x_m: f64,
    /// True position, m.
    pub true_y_m: f64,
    /// True height above the seabed, m.
    pub true_z_m: f64,
    /// Estimated position, m (`None`: the vehicle has no position estimate).
    pub est_x_m: Option<f64>,
    /// Estimated position, m.
    pub est_y_m: Option<f64>,
    /// True heading, deg.
    pub heading_deg: f64,
    /// Water-relative speed, m/s.
    pub speed_mps: f64,
    /// Active behaviour (`None`: no planner, or before its first decision).
    pub behaviour: Option<BehaviourKind>,
    /// Latest chemical reading, V.
    pub reading_v: f64,
    /// The latest reading exceeds the vehicle's planner's detection threshold.
    pub detection: bool,
}

/// Records every vehicle's state at every step, and each vehicle's behaviour from its planner's
/// events.
#[derive(Debug)]
pub struct TrajectoryRecorder {
    /// The rows so far.
    pub rows: Vec<TrajectoryRow>,
    behaviour: Vec<Option<BehaviourKind>>,
    thresholds: Vec<Option<f64>>,
    positions: Vec<bool>,
}

impl TrajectoryRecorder {
    /// A recorder for vehicles whose planners threshold at `thresholds` (`None`: no detections
    /// marked) and which have a position estimate or not.
    pub fn new(thresholds: Vec<Option<f64>>, positions: Vec<bool>) -> Self {
        TrajectoryRecorder {
            rows: Vec::new(),
            behaviour: vec![None; thresholds.len()],
            thresholds,
            positions,
        }
    }
}

/// The behaviour each decision switched to (the last one of the step).
fn behaviour_switches(report: &StepReport) -> impl Iterator<Item = (usize, BehaviourKind)> + '_ {
    report.decisions.iter().enumerate().filter_map(|(i, d)| {
        d.as_ref()?
            .events
            .iter()
            .rev()
            .find_map(PlannerEvent::behaviour)
            .map(|b| (i, b))
    })
}

impl Observer for TrajectoryRecorder {
    fn observe(&mut self, step: &StepView<'_>) {
        for (i, b) in behaviour_switches(step.report) {
            if let Some(slot) = self.behaviour.get_mut(i) {
                *slot = Some(b);
            }
        }
        let t = step.world.time_s();
        for v in step.world.vehicles() {
            let i = v.vehicle.id.0 as usize;
            let s = v.vehicle.state;
            let est = self
                .positions
                .get(i)
                .copied()
                .unwrap_or(true)
                .then(|| v.nav.estimate_m());
            let reading = v.last_chem.map_or(0.0, |c| c.reading);
            let threshold = self.thresholds.get(i).copied().flatten();
            self.rows.push(TrajectoryRow {
                t_s: t,
                vehicle: v.vehicle.id.0,
                true_x_m: s.pos_m.x,
                true_y_m: s.pos_m.y,
                true_z_m: s.z_m,
                est_x_m: est.map(|e| e.x),
                est_y_m: est.map(|e| e.y),
                heading_deg: s.heading.deg(),
                speed_mps: s.speed_mps,
                behaviour: self.behaviour.get(i).copied().flatten(),
                reading_v: reading,
                detection: v.last_chem.is_some() && threshold.is_some_and(|th| reading > th),
            });
        }
    }
}

/// Per-vehicle numbers for the summary: path over ground, first detection, the path traced from
/// the first detection to the first declaration, declarations.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VehicleTrack {
    /// Distance over ground, m.
    pub path_length_m: f64,
    /// Time and estimated position of the planner's first detection.
    pub first_detection: Option<(f64, Vec2)>,
    /// Distance from the first detection to the first declaration, m.
    pub trace_length_m: f64,
    /// Declarations: time, position and rule.
    pub declarations: Vec<(f64, Vec2, plumetrace_core::DeclarationKind)>,
    /// The longest stretch spent in one behaviour without a reading above the detection
    /// threshold: its length, s, and the behaviour.
    pub longest_quiet: Option<(f64, BehaviourKind)>,
    /// The farthest the true position went outside the op-area, m (0: never outside).
    pub max_outside_m: f64,
    /// When the vehicle reached the seabed (the incident `hit_bottom`), s.
    pub hit_bottom_s: Option<f64>,
    last_pos: Option<Vec2>,
    /// The behaviour in control and since when it has had no detection.
    quiet_since: Option<(BehaviourKind, f64)>,
}

/// Records [`VehicleTrack`]s and the mean flow at the first source.
#[derive(Debug)]
pub struct TrackStats {
    /// One per vehicle.
    pub tracks: Vec<VehicleTrack>,
    thresholds: Vec<Option<f64>>,
    op_area: Option<plumetrace_guidance::OpArea>,
    flow_sum: Vec2,
    flow_n: f64,
    flow_at: Option<Vec2>,
    sample_every: u64,
}

impl TrackStats {
    /// Stats for vehicles whose planners threshold readings at `thresholds` (one per vehicle,
    /// `None`: no planner or none that thresholds) in `op_area`; the mean flow is sampled at
    /// `flow_at` every `sample_every` steps.
    pub fn new(
        thresholds: Vec<Option<f64>>,
        op_area: &[Vec2],
        flow_at: Option<Vec2>,
        sample_every: u64,
    ) -> Self {
        TrackStats {
            tracks: vec![VehicleTrack::default(); thresholds.len()],
            thresholds,
            op_area: plumetrace_guidance::OpArea::new(op_area.to_vec()).ok(),
            flow_sum: Vec2::zeros(),
            flow_n: 0.0,
            flow_at,
            sample_every: sample_every.max(1),
        }
    }

    /// The mean flow at the first source over the mission, m/s.
    pub fn mean_flow_mps(&self) -> Vec2 {
        if self.flow_n > 0.0 {
            self.flow_sum / self.flow_n
        } else {
            Vec2::zeros()
        }
    }
}

impl Observer for TrackStats {
    fn observe(&mut self, step: &StepView<'_>) {
        let t = step.report.t_s;
        for (i, e) in step.planner_events() {
            let Some(track) = self.tracks.get_mut(i) else {
                continue;
            };
            match e {
                PlannerEvent::Detection { pos_m } if track.first_detection.is_none() => {
                    track.first_detection = Some((t, *pos_m));
                }
                PlannerEvent::Declared { pos_m, rule } => {
                    track.declarations.push((t, *pos_m, rule.clone()));
                }
                _ => {}
            }
        }
        for (i, b) in behaviour_switches(step.report) {
            if let Some(track) = self.tracks.get_mut(i) {
                track.quiet_since = Some((b, t));
            }
        }
        for (id, e) in &step.report.events {
            if let WorldEvent::Incident {
                what: Incident::HitBottom,
            } = e
                && let Some(track) = self.tracks.get_mut(id.0 as usize)
            {
                // Found by the step's check, at its end.
                track.hit_bottom_s.get_or_insert(step.world.time_s());
            }
        }
        for v in step.world.vehicles() {
            let i = v.vehicle.id.0 as usize;
            let threshold = self.thresholds.get(i).copied().flatten();
            let Some(track) = self.tracks.get_mut(i) else {
                continue;
            };
            let p = v.vehicle.state.pos_m;
            if let Some(outside_m) = self.op_area.as_ref().and_then(|a| a.outside_by(p)) {
                track.max_outside_m = track.max_outside_m.max(outside_m);
            }
            if let Some((b, since)) = track.quiet_since {
                let detected = threshold
                    .zip(v.last_chem)
                    .is_some_and(|(th, c)| c.reading > th);
                if detected || !v.active {
                    track.quiet_since = v.active.then_some((b, t));
                } else if b != BehaviourKind::Done
                    && track.longest_quiet.is_none_or(|(d, _)| t - since > d)
                {
                    track.longest_quiet = Some((t - since, b));
                }
            }
            if let Some(q) = track.last_pos {
                let d = (p - q).norm();
                track.path_length_m += d;
                if track.first_detection.is_some() && track.declarations.is_empty() {
                    track.trace_length_m += d;
                }
            }
            track.last_pos = Some(p);
        }
        if (step.world.steps() - 1).is_multiple_of(self.sample_every)
            && let Some(at) = self.flow_at
        {
            self.flow_sum += step.world.env().flow().velocity(at);
            self.flow_n += 1.0;
        }
    }
}

/// The bounding box of `points`: west, east, south, north, m.
pub fn bounds_of(points: &[Vec2]) -> (f64, f64, f64, f64) {
    points.iter().fold(
        (f64::MAX, f64::MIN, f64::MAX, f64::MIN),
        |(x0, x1, y0, y1), p| (x0.min(p.x), x1.max(p.x), y0.min(p.y), y1.max(p.y)),
    )
}

/// Accumulates the time-averaged concentration over a grid every `sample_every` steps (the
/// figure's plume; display precision, [`ConcentrationField::display_grid_concentrations`]).
#[derive(Debug)]
pub struct MeanPlumeRecorder {
    /// The average so far.
    pub grid: MeanConcentrationGrid,
    sample_every: u64,
}

impl MeanPlumeRecorder {
    /// How often a mission of `time_limit_s` samples its figure's plume, s: the time limit over
    /// 120 (about 120 samples in a mission that runs to its limit), within 20-60 s (60 s: as
    /// often as the replay page's frames, [`crate::PLUME_FRAME_EVERY_S`]). A current of 0.1-0.3
    /// m/s carries the filaments 6-18 m between samples 60 s apart, one to three cells of the
    /// figure's grid over a kilometre of op-area. Every 60 s instead of 20 s, a `duck-2003-st`
    /// run (a 2 h limit) takes 0.42 s of CPU instead of 0.55 s (docs/results/performance.md),
    /// and its figure's cells' colours differ from the 20 s average's by 1.5 of 255 levels on
    /// average. A mission of 40 minutes or less (`demo`, `demo-survey`, `demo-surge-cast`)
    /// still samples every 20 s.
    pub fn every_s(time_limit_s: f64) -> f64 {
        let every = time_limit_s / 120.0;
        if every.is_finite() {
            every.clamp(20.0, 60.0)
        } else {
            20.0
        }
    }

    /// An average over `grid`, sampled every `sample_every` steps.
    pub fn new(grid: GridSpec, sample_every: u64) -> Self {
        MeanPlumeRecorder {
            grid: MeanConcentrationGrid::new(grid, 0.0).for_display(),
            sample_every: sample_every.max(1),
        }
    }

    /// The grid covering `vertices` with a 5 % margin, inside the domain, at height `z_m`.
    pub fn grid_over(vertices: &[Vec2], domain: plumetrace_env::Rect, z_m: f64) -> GridSpec {
        let (x0, x1, y0, y1) = bounds_of(vertices);
        let pad = 0.05 * (x1 - x0).max(y1 - y0);
        GridSpec {
            x_min_m: (x0 - pad).max(domain.x_min_m),
            x_max_m: (x1 + pad).min(domain.x_max_m),
            y_min_m: (y0 - pad).max(domain.y_min_m),
            y_max_m: (y1 + pad).min(domain.y_max_m),
            nx: 160,
            ny: (160.0 * (y1 - y0) / (x1 - x0).max(1e-9)).clamp(40.0, 400.0) as usize,
            z_m,
        }
    }
}

impl Observer for MeanPlumeRecorder {
    fn observe(&mut self, step: &StepView<'_>) {
        if (step.world.steps() - 1).is_multiple_of(self.sample_every) {
            self.grid.accumulate(step.world.env().plume());
        }
    }
}

/// One frame of the plume as the replay page shows it: the concentration over a grid and the
/// flow over a coarser one, at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct PlumeFrame {
    /// Time, s.
    pub t_s: f64,
    /// Concentration at every point of [`PlumeFrames::grid`], row by row from the south-west.
    pub concentration: Vec<f32>,
    /// Water velocity (east, north), m/s, at every point of [`PlumeFrames::flow_grid`].
    pub flow_mps: Vec<[f32; 2]>,
}

/// Samples the plume and the flow every `every_s` seconds (the replay page's background):
/// concentration on a grid of at most 96 x 96 points at the first vehicle's altitude (display
/// precision, [`ConcentrationField::display_grid_concentrations`]), flow on one of at most 12 x
/// 12. A mission of 2 h sampled every 60 s keeps 121 frames of about 37 kB.
#[derive(Debug)]
pub struct PlumeFrames {
    /// Where the concentration is sampled.
    pub grid: GridSpec,
    /// Where the flow is sampled.
    pub flow_grid: GridSpec,
    /// The frames so far.
    pub frames: Vec<PlumeFrame>,
    every_steps: u64,
    points: Vec<Vec3>,
    flow_points: Vec<Vec2>,
}

/// Largest side of the concentration grid, points.
pub const PLUME_FRAME_MAX_SIDE: usize = 96;
/// Largest side of the flow grid, points.
pub const FLOW_FRAME_MAX_SIDE: usize = 12;

impl PlumeFrames {
    /// The replay page's frames of a mission: over the op-area `vertices` with a 15 % margin
    /// (clipped to `domain`), at height `z_m`, one every `every_steps` steps.
    pub fn over(
        vertices: &[Vec2],
        domain: plumetrace_env::Rect,
        z_m: f64,
        every_steps: u64,
    ) -> Self {
        let (x0, x1, y0, y1) = bounds_of(vertices);
        let pad = 0.15 * (x1 - x0).max(y1 - y0);
        PlumeFrames::new(
            (x0 - pad, x1 + pad, y0 - pad, y1 + pad),
            domain,
            z_m,
            every_steps,
        )
    }

    /// Frames over `bounds` (x0, x1, y0, y1, m, clipped to `domain`) at height `z_m`, one every
    /// `every_steps` steps.
    pub fn new(
        bounds: (f64, f64, f64, f64),
        domain: plumetrace_env::Rect,
        z_m: f64,
        every_steps: u64,
    ) -> Self {
        let (x0, x1, y0, y1) = (
            bounds.0.max(domain.x_min_m),
            bounds.1.min(domain.x_max_m),
            bounds.2.max(domain.y_min_m),
            bounds.3.min(domain.y_max_m),
        );
        let sides = |max: usize| {
            let (w, h) = ((x1 - x0).max(1e-6), (y1 - y0).max(1e-6));
            if w >= h {
                (
                    max,
                    ((max as f64) * h / w).round().clamp(2.0, max as f64) as usize,
                )
            } else {
                (
                    ((max as f64) * w / h).round().clamp(2.0, max as f64) as usize,
                    max,
                )
            }
        };
        let grid_of = |(nx, ny): (usize, usize)| GridSpec {
            x_min_m: x0,
            x_max_m: x1,
            y_min_m: y0,
            y_max_m: y1,
            nx,
            ny,
            z_m,
        };
        let grid = grid_of(sides(PLUME_FRAME_MAX_SIDE));
        let flow_grid = grid_of(sides(FLOW_FRAME_MAX_SIDE));
        PlumeFrames {
            points: grid.points(),
            flow_points: flow_grid.points().iter().map(|p| p.xy()).collect(),
            grid,
            flow_grid,
            frames: Vec::new(),
            every_steps: every_steps.max(1),
        }
    }

    fn sample(&mut self, world: WorldView<'_>) {
        let mut c = vec![0.0; self.points.len()];
        world
            .env()
            .plume()
            .display_grid_concentrations(&self.grid, &self.points, &mut c);
        let flow = world.env().flow();
        self.frames.push(PlumeFrame {
            t_s: world.time_s(),
            concentration: c
                .iter()
                .map(|&v| if v.is_finite() { v as f32 } else { 0.0 })
                .collect(),
            flow_mps: self
                .flow_points
                .iter()
                .map(|&p| {
                    let v = flow.velocity(p);
                    [v.x as f32, v.y as f32]
                })
                .collect(),
        });
    }
}

impl Observer for PlumeFrames {
    fn observe(&mut self, step: &StepView<'_>) {
        if (step.world.steps() - 1).is_multiple_of(self.every_steps) {
            self.sample(step.world);
        }
    }
}

/// The true sources of the mission's plume.
pub fn true_sources(world: WorldView<'_>) -> Vec<Vec3> {
    world
        .env()
        .plume()
        .filaments()
        .map(|f| f.sources().iter().map(|s| s.pos_m).collect())
        .unwrap_or_else(|| match world.env().plume() {
            plumetrace_env::Plume::Steady(field) => field.source_positions(),
            plumetrace_env::Plume::Filaments(_) => Vec::new(),
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::outcome::MissionEvent;
    use plumetrace_core::{DeclarationKind, Link, RegionEvent};
    use plumetrace_sim::{Incident, LossReason};

    /// One event of every kind, so the tags can be checked. The matches make this list fail to
    /// compile when a variant is added without being listed here.
    fn one_of_each() -> Vec<EventKind> {
        let p = Vec2::zeros();
        let planner = [
            PlannerEvent::Behaviour {
                behaviour: BehaviourKind::Find,
            },
            PlannerEvent::Detection { pos_m: p },
            PlannerEvent::LostPoint { pos_m: p },
            PlannerEvent::LostPointMoved {
                from_m: p,
                to_m: Vec2::new(1.0, 2.0),
            },
            PlannerEvent::Declared {
                pos_m: p,
                rule: DeclarationKind::new("along_flow"),
            },
            PlannerEvent::Region {
                index: 0,
                what: RegionEvent::Started,
            },
            PlannerEvent::CageAbort {
                distance_outside_m: 31.0,
            },
            PlannerEvent::AvoidStart {
                pos_m: p,
                course_deg: 45.0,
            },
            PlannerEvent::ReferenceTarget { pos_m: p },
            PlannerEvent::AvoidEnd { pos_m: p },
        ];
        for e in &planner {
            match e {
                PlannerEvent::Behaviour { .. }
                | PlannerEvent::Detection { .. }
                | PlannerEvent::LostPoint { .. }
                | PlannerEvent::LostPointMoved { .. }
                | PlannerEvent::Declared { .. }
                | PlannerEvent::Region { .. }
                | PlannerEvent::CageAbort { .. }
                | PlannerEvent::AvoidStart { .. }
                | PlannerEvent::ReferenceTarget { .. }
                | PlannerEvent::AvoidEnd { .. } => {}
            }
        }
        let telemetry = [
            Telemetry::SourceEstimate { pos_m: p },
            Telemetry::Formation {
                scale_cw: Some(1.0),
                ranges_m: Some([1.0, 2.0]),
                ranges_to: Some([VehicleId(1), VehicleId(2)]),
                setpoint_m: Some(1.5),
                reading: 0.5,
                declaration_confidence: None,
            },
            Telemetry::SourceMap {
                entropy_bits: 3.0,
                peak_m: p,
                mass: 0.5,
            },
            Telemetry::SourceMapRaster {
                origin_m: p,
                cell_m: 5.0,
                nx: 1,
                ny: 1,
                log10_p: vec![0.0],
            },
        ];
        for e in &telemetry {
            match e {
                Telemetry::SourceEstimate { .. }
                | Telemetry::Formation { .. }
                | Telemetry::SourceMap { .. }
                | Telemetry::SourceMapRaster { .. } => {}
            }
        }
        let world = [
            WorldEvent::NavFix {
                jump_m: 1.0,
                to_m: p,
            },
            WorldEvent::Incident {
                what: Incident::Collided,
            },
            WorldEvent::NonFiniteCommand {
                command: "NaN".into(),
            },
            WorldEvent::MessageDelivered {
                from: VehicleId(1),
                link: Link::Acoustic,
                sent_s: 0.0,
            },
            WorldEvent::MessageLost {
                from: VehicleId(1),
                link: Link::Radio,
                sent_s: 0.0,
                reason: LossReason::Dropped,
            },
        ];
        for e in &world {
            match e {
                WorldEvent::NavFix { .. }
                | WorldEvent::Incident { .. }
                | WorldEvent::NonFiniteCommand { .. }
                | WorldEvent::MessageDelivered { .. }
                | WorldEvent::MessageLost { .. } => {}
            }
        }
        let mission = [MissionEvent::PlannerFinished, MissionEvent::PlannerAborted];
        for e in &mission {
            match e {
                MissionEvent::PlannerFinished | MissionEvent::PlannerAborted => {}
            }
        }
        planner
            .into_iter()
            .map(EventKind::Planner)
            .chain(telemetry.into_iter().map(EventKind::Telemetry))
            .chain(world.into_iter().map(EventKind::World))
            .chain(mission.into_iter().map(EventKind::Mission))
            .collect()
    }

    #[test]
    fn the_figures_plume_is_sampled_about_120_times_over_the_time_limit() {
        let every = MeanPlumeRecorder::every_s;
        // The demos (40 minutes) every 20 s, a two-hour mission every 60 s, one hour between.
        assert_eq!(every(2400.0), 20.0);
        assert_eq!(every(900.0), 20.0);
        assert_eq!(every(3600.0), 30.0);
        assert_eq!(every(7200.0), 60.0);
        assert_eq!(every(18000.0), 60.0);
        assert_eq!(every(f64::INFINITY), 20.0);
        assert_eq!(every(f64::NAN), 20.0);
    }

    #[test]
    fn lost_points_follow_their_moves_by_vehicle_and_position() {
        let at = |t_s: f64, vehicle: u32, e: PlannerEvent| EventRecord {
            t_s,
            vehicle,
            event: EventKind::Planner(e),
        };
        let lost = |x: f64, y: f64| PlannerEvent::LostPoint {
            pos_m: Vec2::new(x, y),
        };
        let moved = |from: (f64, f64), to: (f64, f64)| PlannerEvent::LostPointMoved {
            from_m: Vec2::new(from.0, from.1),
            to_m: Vec2::new(to.0, to.1),
        };
        let events = [
            at(1.0, 0, lost(10.0, 0.0)),
            at(2.0, 1, lost(10.0, 0.0)),
            at(3.0, 0, lost(10.0, 0.0)),
            at(4.0, 0, lost(50.0, 5.0)),
            // Vehicle 0's latest point at (10, 0), then its other one there, then the first
            // move's point again from where it went.
            at(5.0, 0, moved((10.0, 0.0), (12.0, 1.0))),
            at(5.0, 0, moved((10.0, 0.0), (11.0, -1.0))),
            at(6.0, 0, moved((12.0, 1.0), (13.0, 1.5))),
            // From where no point of that vehicle is: passed over.
            at(7.0, 0, moved((50.0, 5.5), (0.0, 0.0))),
            at(7.0, 2, moved((50.0, 5.0), (0.0, 0.0))),
        ];
        let points = lost_points(&events);
        let got: Vec<(usize, u32, Vec2, usize)> = points
            .iter()
            .map(|l| (l.saved, l.vehicle, l.now_m(), l.moves.len()))
            .collect();
        assert_eq!(
            got,
            vec![
                (0, 0, Vec2::new(11.0, -1.0), 1),
                (1, 1, Vec2::new(10.0, 0.0), 0),
                (2, 0, Vec2::new(13.0, 1.5), 2),
                (3, 0, Vec2::new(50.0, 5.0), 0),
            ]
        );
        assert_eq!(
            points[2].moves,
            vec![(5.0, Vec2::new(12.0, 1.0)), (6.0, Vec2::new(13.0, 1.5))]
        );
        assert_eq!(points[2].pos_m, Vec2::new(10.0, 0.0), "as saved");
    }

    #[test]
    fn every_event_has_its_own_tag_in_the_event_field() {
        let mut tags = Vec::new();
        for e in one_of_each() {
            let record = EventRecord {
                t_s: 1.0,
                vehicle: 0,
                event: e,
            };
            let v: serde_json::Value =
                serde_json::to_value(&record).unwrap_or(serde_json::Value::Null);
            let tag = v["event"].as_str().unwrap_or_else(|| panic!("no tag: {v}"));
            assert_eq!(v["t_s"], 1.0);
            tags.push(tag.to_string());
        }
        let n = tags.len();
        tags.sort();
        tags.dedup();
        assert_eq!(tags.len(), n, "two kinds of event share a tag: {tags:?}");
    }
}
