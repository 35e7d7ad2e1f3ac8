//! The REMUS Adaptive Mission Planner (AMP).
//!
//! Behaviours and the switching logic of the field system:
//! - **Go-To** drives to the most downflow corner of the area (or of the next subregion; during
//!   that transit of a multi-source mission detections are ignored);
//! - **Find** sweeps across the flow at `psi_f +- 90 +- 20` degrees with billiard reflections at the
//!   boundary;
//! - **Track-In** (any detection before declaration) heads `upflow + LHS beta`, updating LHS from
//!   the wrapped difference between vehicle heading and flow direction, and saves the last detection
//!   point; after `lambda` seconds without detection it saves that point as a lost point;
//! - **Track-Out** goes `L_u` upflow and `L_c` across the flow from the most upflow lost point, to the
//!   side opposite the exit; it ends on detection or arrival, and the declaration check runs;
//! - **Reacquire** flies `N_re` Bowties from 10 m upflow of the most upflow lost point down to it,
//!   then drops the point; with no point left it returns to Find.
//!
//! Declaration ([`DeclarationRule`]) leads to post-declaration mapping ([`MappingParams`]) and the
//! end of the mission. In a multi-source mission the area is split into subregions searched in
//! turn; a subregion ends on timeout (source-free), on a declaration, or when the plume is traced
//! to its upflow edge (declared there); no mapping is flown between subregions.
//!
//! The planner steers through the onboard guidance: every course passes the op-area cage (an
//! abort ends the mission), flow compensation and the heading-rate filter before it is commanded.

mod bowtie;
mod declaration;
mod find;
mod mapping;

pub use bowtie::{Bowtie, centres as bowtie_centres};
pub use declaration::DeclarationRule;
pub use find::{candidates as find_candidates, reflect as find_reflect};
pub use mapping::MappingParams;

use crate::flow::FlowEstimate;
use plumetrace_core::{
    Command, Decision, Heading, PlanStatus, Planner, PlannerEvent, RegionEvent, SensorSnapshot,
    Vec2, VerticalCommand, wrap_deg_360,
};
use plumetrace_guidance::{
    Cage, CageAction, FollowLine, GoToPoint, ModeStatus, OpArea, Pose, RateFilter, Steer,
    compensate_flow,
};
use serde::{Deserialize, Serialize};

/// Parameters of the AMP. Defaults: Table 4 of the field tests and the field vehicle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AmpParams {
    /// Speed command, m/s.
    pub speed_mps: f64,
    /// Altitude command, m.
    pub altitude_m: f64,
    /// `lambda`: time without detection that ends Track-In, s.
    pub lambda_s: f64,
    /// `beta`: Track-In offset from upflow, deg.
    pub beta_deg: f64,
    /// `L_u`: Track-Out goal distance upflow of the most upflow lost point, m.
    pub l_u_m: f64,
    /// `L_c`: Track-Out goal distance across the flow, m.
    pub l_c_m: f64,
    /// `N_re`: Bowties per lost point.
    pub n_re: usize,
    /// `K`: Follow Line gain, deg/m.
    pub k_deg_per_m: f64,
    /// `R`: arrival radius, m.
    pub r_m: f64,
    /// Minimum turning radius for Dubins approaches, m.
    pub min_turn_radius_m: f64,
    /// Heading-rate limit of the commands, deg/s.
    pub max_turn_rate_deg_s: f64,
    /// Most lost points kept.
    pub max_lost_points: usize,
    /// Which lost point makes room when the list is full.
    pub lost_point_eviction: LostPointEviction,
    /// Find offset from across-flow, deg.
    pub find_offset_deg: f64,
    /// Distance from the boundary at which Find reflects, m.
    pub find_margin_m: f64,
    /// Bowtie line angle from upflow, deg.
    pub bowtie_angle_deg: f64,
    /// Bowtie reach across the flow on each side, m.
    pub bowtie_half_width_m: f64,
    /// Distance upflow of the lost point of the first Bowtie centre, m.
    pub bowtie_offset_m: f64,
    /// The declaration rule.
    pub declaration: DeclarationRule,
    /// Post-declaration mapping (none: the mission ends at the declaration).
    pub mapping: Option<MappingParams>,
    /// Time constant of the flow estimate, s.
    pub flow_average_s: f64,
    /// Compensate courses for the measured flow.
    pub flow_compensation: bool,
    /// Search time per subregion of a multi-source mission before it is declared source-free, s.
    pub region_timeout_s: f64,
}

impl Default for AmpParams {
    fn default() -> Self {
        AmpParams {
            speed_mps: 2.0,
            altitude_m: 2.0,
            lambda_s: 5.0,
            beta_deg: 20.0,
            l_u_m: 18.0,
            l_c_m: 18.0,
            n_re: 2,
            k_deg_per_m: 5.0,
            r_m: 10.0,
            min_turn_radius_m: 12.0,
            max_turn_rate_deg_s: 10.0,
            max_lost_points: 6,
            lost_point_eviction: LostPointEviction::Oldest,
            find_offset_deg: 20.0,
            find_margin_m: 10.0,
            bowtie_angle_deg: 15.0,
            bowtie_half_width_m: 13.0,
            bowtie_offset_m: 10.0,
            declaration: DeclarationRule::AlongFlow { along_m: 4.0 },
            mapping: Some(MappingParams::default()),
            flow_average_s: 60.0,
            flow_compensation: true,
            region_timeout_s: 1800.0,
        }
    }
}

impl AmpParams {
    /// A Follow Line leg from `a` to `b` with the planner's speed, radius, gain and turning radius
    /// (approaching the start with the line's heading).
    fn line(&self, a: Vec2, b: Vec2) -> FollowLine {
        FollowLine::new(
            a,
            b,
            self.speed_mps,
            self.r_m,
            self.k_deg_per_m,
            self.min_turn_radius_m,
        )
    }
}

/// Which lost point is dropped when a new one arrives at a full list (the field planner kept at
/// most six; which one made room is not recorded).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LostPointEviction {
    /// The oldest point (the default): the list follows the latest losses.
    Oldest,
    /// The most downflow of the older points (the new one always enters): the list keeps the
    /// points nearest the source, which Track-Out, Reacquire and the declaration use. Near a
    /// source whose plume reaches the vehicle's altitude only intermittently, points near the
    /// plume's tip survive the losses further downflow until three agree. The price: upflow
    /// points whose Bowties keep finding chemical downflow of them are never dropped, and a
    /// declaration can then wait for ever (4 of 40 `duck-2003-st` runs).
    MostDownflow,
}

/// The AMP behaviours, by their registry names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BehaviourKind {
    /// Drive to the search start.
    GoTo,
    /// Drive to the next subregion, ignoring detections.
    Transit,
    /// Sweep across the flow.
    Find,
    /// Counter-turn up the plume.
    TrackIn,
    /// Cross the plume upflow of the last contact.
    TrackOut,
    /// Bowties around the lost points.
    Reacquire,
    /// Post-declaration pattern.
    Mapping,
    /// Mission over.
    Done,
}

impl BehaviourKind {
    /// The registry name.
    pub fn name(self) -> &'static str {
        match self {
            BehaviourKind::GoTo => "go_to",
            BehaviourKind::Transit => "transit",
            BehaviourKind::Find => "find",
            BehaviourKind::TrackIn => "track_in",
            BehaviourKind::TrackOut => "track_out",
            BehaviourKind::Reacquire => "reacquire",
            BehaviourKind::Mapping => "mapping",
            BehaviourKind::Done => "done",
        }
    }
}

#[derive(Debug, Clone)]
struct Reacquire {
    point: Vec2,
    n: usize,
    leg: usize,
    bowtie: Bowtie,
    line: FollowLine,
}

#[derive(Debug, Clone)]
enum Mode {
    GoTo(GoToPoint),
    Transit(GoToPoint),
    Find(Heading),
    TrackIn(Heading),
    TrackOut(GoToPoint),
    Reacquire(Box<Reacquire>),
    Mapping {
        legs: Vec<(Vec2, Vec2)>,
        k: usize,
        line: Box<FollowLine>,
    },
    Done,
}

impl Mode {
    fn kind(&self) -> BehaviourKind {
        match self {
            Mode::GoTo(_) => BehaviourKind::GoTo,
            Mode::Transit(_) => BehaviourKind::Transit,
            Mode::Find(_) => BehaviourKind::Find,
            Mode::TrackIn(_) => BehaviourKind::TrackIn,
            Mode::TrackOut(_) => BehaviourKind::TrackOut,
            Mode::Reacquire(_) => BehaviourKind::Reacquire,
            Mode::Mapping { .. } => BehaviourKind::Mapping,
            Mode::Done => BehaviourKind::Done,
        }
    }
}

/// What a behaviour step sees.
#[derive(Debug, Clone, Copy)]
struct Ctx {
    t: f64,
    pos: Vec2,
    heading: Heading,
    detected: bool,
}

/// The Adaptive Mission Planner for one AUV.
#[derive(Debug, Clone)]
pub struct Amp {
    p: AmpParams,
    cage: Cage,
    regions: Vec<OpArea>,
    region: usize,
    region_started_s: f64,
    mode: Mode,
    lhs: f64,
    last_detection: Option<(f64, Vec2)>,
    in_contact: bool,
    lost: Vec<Vec2>,
    declared: Vec<Vec2>,
    flow: FlowEstimate,
    filter: RateFilter,
    last_t: Option<f64>,
    last_steer: Steer,
    started: bool,
    events: Vec<PlannerEvent>,
}

impl Amp {
    /// A planner for `area`, searched whole (single-source mission) or, with several `regions`,
    /// one subregion after the other. `prior_flow` is the flow direction assumed until the first
    /// flow measurement.
    pub fn new(p: AmpParams, area: OpArea, regions: Vec<OpArea>, prior_flow: Heading) -> Self {
        let regions = if regions.is_empty() {
            vec![area.clone()]
        } else {
            regions
        };
        Amp {
            p,
            cage: Cage::new(area),
            regions,
            region: 0,
            region_started_s: 0.0,
            mode: Mode::Done,
            lhs: 1.0,
            last_detection: None,
            in_contact: false,
            lost: Vec::new(),
            declared: Vec::new(),
            flow: FlowEstimate::new(p.flow_average_s, prior_flow),
            filter: RateFilter::new(p.max_turn_rate_deg_s),
            last_t: None,
            last_steer: Steer {
                heading: Heading::NORTH,
                speed_mps: p.speed_mps,
            },
            started: false,
            events: Vec::new(),
        }
    }

    /// The active behaviour.
    pub fn behaviour(&self) -> BehaviourKind {
        self.mode.kind()
    }

    /// The saved lost points.
    pub fn lost_points(&self) -> &[Vec2] {
        &self.lost
    }

    /// The course the active behaviour asked for at the last decision (before the cage, flow
    /// compensation and rate filtering).
    pub fn last_course(&self) -> Heading {
        self.last_steer.heading
    }

    /// The LHS variable (+1: expected to leave the plume on its left looking upflow).
    pub fn lhs(&self) -> f64 {
        self.lhs
    }

    /// The parameters.
    pub fn params(&self) -> &AmpParams {
        &self.p
    }

    fn multi_region(&self) -> bool {
        self.regions.len() > 1
    }

    fn set_mode(&mut self, mode: Mode) {
        let changed = mode.kind() != self.mode.kind();
        self.mode = mode;
        if changed {
            self.events.push(PlannerEvent::Behaviour {
                name: self.mode.kind().name(),
            });
        }
    }

    /// Where the search of subregion `k` starts: its most downflow corner (for the current flow
    /// estimate), moved 1.5 `R` towards the subregion's centre.
    pub fn search_start(&self, k: usize) -> Vec2 {
        let region = &self.regions[k];
        let corner = region.furthest_vertex_along(self.flow.toward().unit());
        let centre = region.vertices().iter().fold(Vec2::zeros(), |a, v| a + v)
            / region.vertices().len() as f64;
        let d = centre - corner;
        let n = d.norm();
        if n > 2.0 * self.p.r_m {
            corner + d / n * (1.5 * self.p.r_m)
        } else {
            centre
        }
    }

    fn start_region(&mut self, k: usize, t: f64) {
        self.region = k;
        self.region_started_s = t;
        self.lost.clear();
        self.last_detection = None;
        self.events.push(PlannerEvent::Region {
            index: k,
            what: RegionEvent::Started,
        });
        let goal = GoToPoint {
            target_m: self.search_start(k),
            speed_mps: self.p.speed_mps,
            radius_m: self.p.r_m,
        };
        if self.multi_region() {
            self.set_mode(Mode::Transit(goal))
        } else {
            self.set_mode(Mode::GoTo(goal))
        }
    }

    fn next_region(&mut self, t: f64) {
        if self.region + 1 < self.regions.len() {
            self.start_region(self.region + 1, t);
        } else {
            self.set_mode(Mode::Done);
        }
    }

    fn enter_find(&mut self, pos: Vec2) {
        let h = find::initial_heading(
            &self.regions[self.region],
            pos,
            self.flow.toward(),
            self.p.find_offset_deg,
        );
        self.set_mode(Mode::Find(h));
    }

    fn lhs_from_heading(&self, heading: Heading) -> f64 {
        // Table 1: psi_v - psi_f wrapped to [0, 360) and compared with 180.
        if wrap_deg_360(heading.deg() - self.flow.toward().deg()) < 180.0 {
            1.0
        } else {
            -1.0
        }
    }

    fn enter_track_in(&mut self, ctx: Ctx) {
        if !matches!(self.mode, Mode::TrackIn(_)) {
            if self.last_detection.is_none() {
                self.lhs = self.lhs_from_heading(ctx.heading);
            }
            let h = self.flow.upflow().turned_deg(self.lhs * self.p.beta_deg);
            self.set_mode(Mode::TrackIn(h));
        }
    }

    /// Saves a lost point, keeping at most `max_lost_points`: beyond it the point chosen by
    /// `lost_point_eviction` is dropped.
    fn save_lost_point(&mut self, p: Vec2) {
        self.lost.push(p);
        self.events.push(PlannerEvent::LostPoint { pos_m: p });
        if self.lost.len() > self.p.max_lost_points {
            let drop = match self.p.lost_point_eviction {
                LostPointEviction::Oldest => 0,
                LostPointEviction::MostDownflow => {
                    let u = self.flow.upflow().unit();
                    // Among the older points (the new one always enters, or a list of six
                    // upflow points would never change); `min_by` keeps the first of equals.
                    let older = &self.lost[..self.lost.len() - 1];
                    older
                        .iter()
                        .enumerate()
                        .min_by(|a, b| a.1.dot(&u).total_cmp(&b.1.dot(&u)))
                        .map_or(0, |(i, _)| i)
                }
            };
            self.lost.remove(drop);
        }
    }

    fn most_upflow_lost(&self) -> Option<Vec2> {
        let u = self.flow.upflow().unit();
        self.lost
            .iter()
            .copied()
            .max_by(|a, b| a.dot(&u).total_cmp(&b.dot(&u)))
    }

    /// The Track-Out goal: `L_u` upflow and `L_c` across the flow from the most upflow lost
    /// point, on the side opposite to where the vehicle left the plume.
    pub fn track_out_goal(&self) -> Option<Vec2> {
        let p = self.most_upflow_lost()?;
        let up = self.flow.upflow();
        // LHS = +1: left the plume on its left (looking upflow): go to the right, clockwise.
        Some(p + up.unit() * self.p.l_u_m + up.turned_deg(90.0 * self.lhs).unit() * self.p.l_c_m)
    }

    fn declare(&mut self, at: Vec2, rule: &'static str, region_event: RegionEvent) {
        self.declared.push(at);
        self.events.push(PlannerEvent::Declared { pos_m: at, rule });
        if self.multi_region() {
            self.events.push(PlannerEvent::Region {
                index: self.region,
                what: region_event,
            });
            let t = self.last_t.unwrap_or(0.0);
            self.next_region(t);
        } else if let Some(m) = self.p.mapping {
            let legs = m.legs(at, self.flow.toward());
            let line = self.p.line(legs[0].0, legs[0].1);
            self.set_mode(Mode::Mapping {
                legs,
                k: 0,
                line: Box::new(line),
            });
        } else {
            self.set_mode(Mode::Done);
        }
    }

    /// Runs the declaration check; true when a source was declared.
    fn try_declare(&mut self) -> bool {
        match self.p.declaration.check(&self.lost, self.flow.upflow()) {
            Some(at) => {
                self.declare(at, self.p.declaration.name(), RegionEvent::Declared);
                true
            }
            None => false,
        }
    }

    /// In a multi-source mission: tracing reached the subregion's upflow edge; declare there.
    fn check_upflow_edge(&mut self, pos: Vec2) -> bool {
        if !self.multi_region() {
            return false;
        }
        let e = self.regions[self.region].edge_info(pos);
        let up = self.flow.upflow().unit();
        if e.distance_m < self.p.r_m && e.outward_normal.dot(&up) > 0.7 {
            let on_edge = if e.inside {
                pos + e.outward_normal * e.distance_m
            } else {
                pos - e.outward_normal * e.distance_m
            };
            self.declare(on_edge, "upflow_edge", RegionEvent::DeclaredAtEdge);
            return true;
        }
        false
    }

    fn new_bowtie(&self, point: Vec2, n: usize) -> (Bowtie, FollowLine) {
        let up = self.flow.upflow();
        let centres = bowtie::centres(point, up, self.p.bowtie_offset_m, self.p.n_re.max(1));
        let c = centres[n.min(centres.len() - 1)];
        let b = Bowtie::new(
            c,
            up,
            self.lhs,
            self.p.bowtie_angle_deg,
            self.p.bowtie_half_width_m,
        );
        let line = self.p.line(b.first.0, b.first.1);
        (b, line)
    }

    fn enter_reacquire(&mut self, pos: Vec2) {
        match self.most_upflow_lost() {
            Some(point) => {
                let (bowtie, line) = self.new_bowtie(point, 0);
                self.set_mode(Mode::Reacquire(Box::new(Reacquire {
                    point,
                    n: 0,
                    leg: 0,
                    bowtie,
                    line,
                })));
            }
            None => self.enter_find(pos),
        }
    }

    /// One pass of the switching logic; `None` means "decide again" after a switch.
    fn step_once(&mut self, ctx: Ctx) -> Option<Option<Steer>> {
        let p = self.p;
        let pose = Pose {
            pos_m: ctx.pos,
            heading: ctx.heading,
        };
        let tracking_allowed = !matches!(
            self.mode,
            Mode::Transit(_) | Mode::Mapping { .. } | Mode::Done
        );
        if ctx.detected && tracking_allowed && !matches!(self.mode, Mode::TrackIn(_)) {
            if matches!(self.mode, Mode::TrackOut(_)) && self.try_declare() {
                return None;
            }
            self.enter_track_in(ctx);
        }
        match &mut self.mode {
            Mode::GoTo(g) | Mode::Transit(g) => match g.update(ctx.pos) {
                ModeStatus::Running(s) => Some(Some(s)),
                ModeStatus::Done(_) => {
                    self.region_started_s = ctx.t;
                    self.enter_find(ctx.pos);
                    None
                }
            },
            Mode::Find(h) => {
                let e = self.regions[self.region].edge_info(ctx.pos);
                if (!e.inside || e.distance_m < p.find_margin_m)
                    && h.unit().dot(&e.outward_normal) > 0.0
                {
                    *h = find::reflect(*h, e.outward_normal, self.flow.toward(), p.find_offset_deg);
                }
                Some(Some(Steer {
                    heading: *h,
                    speed_mps: p.speed_mps,
                }))
            }
            Mode::TrackIn(h) => {
                if ctx.detected {
                    // Table 1: command with the current LHS, then update LHS from the heading.
                    *h = self.flow.upflow().turned_deg(self.lhs * p.beta_deg);
                    let heading = *h;
                    self.lhs = self.lhs_from_heading(ctx.heading);
                    self.last_detection = Some((ctx.t, ctx.pos));
                    if self.check_upflow_edge(ctx.pos) {
                        return None;
                    }
                    return Some(Some(Steer {
                        heading,
                        speed_mps: p.speed_mps,
                    }));
                }
                let heading = *h;
                match self.last_detection {
                    Some((t_last, at)) if ctx.t - t_last > p.lambda_s => {
                        self.save_lost_point(at);
                        match self.track_out_goal() {
                            Some(goal) => self.set_mode(Mode::TrackOut(GoToPoint {
                                target_m: goal,
                                speed_mps: p.speed_mps,
                                radius_m: p.r_m,
                            })),
                            None => self.enter_find(ctx.pos),
                        }
                        None
                    }
                    _ => Some(Some(Steer {
                        heading,
                        speed_mps: p.speed_mps,
                    })),
                }
            }
            Mode::TrackOut(g) => match g.update(ctx.pos) {
                ModeStatus::Running(s) => {
                    if self.check_upflow_edge(ctx.pos) {
                        return None;
                    }
                    Some(Some(s))
                }
                ModeStatus::Done(_) => {
                    if !self.try_declare() {
                        self.enter_reacquire(ctx.pos);
                    }
                    None
                }
            },
            Mode::Reacquire(r) => match r.line.update(pose) {
                ModeStatus::Running(s) => Some(Some(s)),
                ModeStatus::Done(_) => {
                    r.leg += 1;
                    let (speed, radius, k) = (p.speed_mps, p.r_m, p.k_deg_per_m);
                    match r.leg {
                        // The side of the Bowtie: from the end of the first line, downflow, to the start of the second.
                        1 => {
                            r.line = FollowLine::tracking(
                                r.bowtie.first.1,
                                r.bowtie.second.0,
                                speed,
                                radius,
                                k,
                            )
                        }
                        2 => r.line = p.line(r.bowtie.second.0, r.bowtie.second.1),
                        _ => {
                            let (point, n) = (r.point, r.n + 1);
                            if n < p.n_re.max(1) {
                                let (bowtie, line) = self.new_bowtie(point, n);
                                self.mode = Mode::Reacquire(Box::new(Reacquire {
                                    point,
                                    n,
                                    leg: 0,
                                    bowtie,
                                    line,
                                }));
                            } else {
                                self.lost.retain(|q| *q != point);
                                self.enter_reacquire(ctx.pos);
                            }
                        }
                    }
                    None
                }
            },
            Mode::Mapping { legs, k, line } => match line.update(pose) {
                ModeStatus::Running(s) => Some(Some(s)),
                ModeStatus::Done(_) => {
                    *k += 1;
                    if *k < legs.len() {
                        let (a, b) = legs[*k];
                        **line = p.line(a, b);
                    } else {
                        self.set_mode(Mode::Done);
                    }
                    None
                }
            },
            Mode::Done => Some(None),
        }
    }
}

impl Planner for Amp {
    fn name(&self) -> &'static str {
        "amp"
    }

    fn decide(&mut self, s: &SensorSnapshot) -> Decision {
        let t = s.time_s;
        let dt = self.last_t.map_or(0.0, |l| (t - l).max(0.0));
        self.last_t = Some(t);
        if let Some(f) = s.flow {
            self.flow.add(f.time_s, f.velocity_mps);
        }
        let pos = s.nav.pos_m;
        if !self.started {
            self.started = true;
            self.filter.reset(s.nav.heading);
            self.start_region(0, t);
        }
        let transit = matches!(self.mode, Mode::Transit(_));
        let detected = !transit && s.chem.iter().any(|c| c.detection);
        if detected && !self.in_contact {
            self.events.push(PlannerEvent::Detection { pos_m: pos });
        }
        self.in_contact = detected
            || self
                .last_detection
                .is_some_and(|(tl, _)| t - tl <= self.p.lambda_s)
                && self.in_contact;
        // Subregion timeout (multi-source missions).
        if self.multi_region()
            && !matches!(self.mode, Mode::Transit(_) | Mode::Done)
            && t - self.region_started_s > self.p.region_timeout_s
        {
            self.events.push(PlannerEvent::Region {
                index: self.region,
                what: RegionEvent::TimedOut,
            });
            self.next_region(t);
        }
        let ctx = Ctx {
            t,
            pos,
            heading: s.nav.heading,
            detected,
        };
        let mut steer = None;
        // A decision may switch behaviours a few times (e.g. Track-Out arrives, the check
        // declares, mapping starts); the bound only guards against a switching loop.
        for _ in 0..8 {
            match self.step_once(ctx) {
                Some(Some(st)) => {
                    steer = Some(st);
                    break;
                }
                Some(None) => break,
                None => continue,
            }
        }
        let status = if matches!(self.mode, Mode::Done) {
            PlanStatus::Finished
        } else {
            PlanStatus::Running
        };
        let steer = steer.unwrap_or(self.last_steer);
        self.last_steer = steer;
        let caged = match self.cage.apply(pos, steer.heading) {
            CageAction::Abort { .. } => {
                let events = std::mem::take(&mut self.events);
                return Decision {
                    command: self.command(s.nav.heading, 0.0),
                    events,
                    status: PlanStatus::Abort,
                };
            }
            action => action.heading().unwrap_or(steer.heading),
        };
        let water = if self.p.flow_compensation {
            compensate_flow(caged, steer.speed_mps, self.flow.velocity_mps()).heading
        } else {
            caged
        };
        let heading = self.filter.filter(water, dt);
        let events = std::mem::take(&mut self.events);
        Decision {
            command: self.command(heading, steer.speed_mps),
            events,
            status,
        }
    }

    fn declarations(&self) -> Vec<Vec2> {
        self.declared.clone()
    }
}

impl Amp {
    fn command(&self, heading: Heading, speed_mps: f64) -> Command {
        Command {
            heading,
            speed_mps,
            vertical: VerticalCommand::Altitude(self.p.altitude_m),
        }
    }
}
