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
//!   side opposite the exit; it ends on detection or arrival, and the declaration check runs
//!   (not on a contact upflow of every lost point, unless `declaration_on_upflow_contact`: the
//!   plume goes on there, and Track-In follows it); when the check holds, a confirming Track-Out
//!   first zigzags `declaration_confirm_m` upflow of the point, and a contact there resumes
//!   Track-In instead of declaring;
//! - **Reacquire** flies `N_re` Bowties from 10 m upflow of the most upflow lost point down to it,
//!   then drops the point; with no point left it returns to Find.
//!
//! Declaration ([`DeclarationRule`], placed by [`Placement`]: by default `declaration_upflow_m`
//! upflow of the most upflow lost point and at the three points' mean across the flow, where the
//! field rule declared the most upflow point itself; with `map_declaration`, also or instead the
//! source-likelihood map's rule of [`crate::estimate::tracker`]) leads to post-declaration mapping ([`MappingParams`]) and the
//! end of the mission. In a multi-source mission the area is split into subregions searched in
//! turn; a subregion ends on timeout (source-free), on a declaration, or when the plume is traced
//! to its upflow edge (declared there); no mapping is flown between subregions.
//!
//! Each behaviour is a [`Behaviour`](crate::behaviour::Behaviour); the switching logic above is
//! the AMP's [`Arbiter`](crate::behaviour::Arbiter). Every course passes the shared
//! [`Autopilot`] (op-area cage, flow compensation, heading-rate filter); a cage abort ends the
//! mission. A chemical sample counts as a detection when its reading exceeds `threshold_v`.
//!
//! Keys shared with other planners come from [`AutopilotKeys`] and [`MapKeys`], at their
//! defaults but for the map's, chosen on Duck-like and coastal sites: `map_mass` 0.7 (among
//! 0.5-0.9: higher waits longer and, on coastal sites, drifts upflow), `map_hold_s` 300 s (0 and
//! 600 s did worse on Duck-like sites), `map_estimate_radius_m` 10 m (it lowered the p90 error),
//! `map_mixing_length_m` 0.12 m and `map_dilution_m` 30 m.

mod behaviours;
mod bowtie;
mod declaration;
mod find;
mod fixes;
mod mapping;

pub use bowtie::{Bowtie, centres as bowtie_centres};
pub use declaration::{
    ALONG_AND_CROSS_FLOW, ALONG_FLOW, DeclarationAcross, DeclarationChoice, DeclarationRule,
    Placement, UPFLOW_EDGE,
};
pub use find::{candidates as find_candidates, reflect as find_reflect};
pub use mapping::MappingParams;

use crate::behaviour::{Arbiter, Behaviour, EventLog, GoTo, Idle, Legs, LineParams, Percept};
use crate::behaviour::{Proposal, Reached};
use crate::estimate::MapTracker;
use crate::flow::{FlowEstimate, TrackFlow, TrackFlowParams};
use crate::planners::{BuildContext, PlannerParams};
use crate::shared_keys::{AutopilotKeys, MapKeys};
use behaviours::{ConfirmLeg, Find, Reacquire, TrackIn, TrackOut};
use plumetrace_core::params::{Bounds, Choice, ParamError, Params};
use plumetrace_core::{
    BehaviourKind, Decision, DeclarationKind, Heading, PlanStatus, Planner, PlannerEvent,
    RegionEvent, RuleDoc, SensorSnapshot, Telemetry, Vec2, VerticalCommand, wrap_deg_360,
};
use plumetrace_guidance::{Autopilot, AutopilotParams, FollowLine, GoToPoint, OpArea, Steer};
use serde::{Deserialize, Serialize};

plumetrace_core::params! {
    /// Parameters of the AMP. Defaults: Table 4 of the field tests and the field vehicle.
    pub struct AmpParams {
        include autopilot: AutopilotKeys = AutopilotKeys::default();
        include map: MapKeys = MapKeys { map_mass: 0.7, map_hold_s: 300.0, map_estimate_radius_m: 10.0, map_mixing_length_m: 0.12, map_dilution_m: 30.0, ..MapKeys::default() };
        /// Altitude flown while tracing the plume (Track-In, Track-Out, Reacquire; 0: altitude_m, as in the field). A bottom source's chemical reaches a vehicle at altitude z only some way downflow, a distance that grows as z^2 with how weakly the water mixes vertically: lower, the contacts begin nearer the source whatever the mixing.
        track_altitude_m: f64 = 1.0, "m", Bounds::non_negative(1000.0);
        /// lambda: time without detection that ends Track-In.
        lambda_s: f64 = 5.0, "s", Bounds::positive(3600.0);
        /// beta: Track-In offset from upflow.
        beta_deg: f64 = 20.0, "deg", Bounds::closed(0.0, 90.0);
        /// L_u: Track-Out goal distance upflow of the most upflow lost point.
        l_u_m: f64 = 18.0, "m", Bounds::non_negative(1000.0);
        /// L_c: Track-Out goal distance across the flow.
        l_c_m: f64 = 18.0, "m", Bounds::non_negative(1000.0);
        /// N_re: Bowties per lost point.
        n_re: u32 = 2, "", Bounds::whole(1, 50);
        /// K: Follow Line cross-track gain.
        k_deg_per_m: f64 = 5.0, "deg/m", Bounds::positive(180.0);
        /// R: arrival radius of Go-To, Track-Out and Follow Line.
        r_m: f64 = 10.0, "m", Bounds::positive(1000.0);
        /// Turning radius of the Dubins approach to each line.
        min_turn_radius_m: f64 = 12.0, "m", Bounds::positive(1000.0);
        /// Re-plans of the Dubins approach to a line's start before it gives up and the line is joined from where the vehicle is at up to 45 deg (0: never, as in the field: near an edge the cage or the current can keep the vehicle off the turn onto the line for good).
        approach_replans: u32 = 4, "", Bounds::whole(0, 1000);
        /// Most lost points kept (the field planner kept six).
        max_lost_points: u32 = 6, "", Bounds::whole(3, 1000);
        /// Which lost point a full list drops.
        lost_point_eviction: LostPointEviction = LostPointEviction::MostDownflow, "", Bounds::Any;
        /// Find offset from across-flow.
        find_offset_deg: f64 = 20.0, "deg", Bounds::closed(0.0, 80.0);
        /// Distance from the boundary at which Find reflects.
        find_margin_m: f64 = 10.0, "m", Bounds::non_negative(1000.0);
        /// Bowtie line angle from upflow.
        bowtie_angle_deg: f64 = 15.0, "deg", Bounds::closed(1.0, 80.0);
        /// Bowtie reach across the flow on each side.
        bowtie_half_width_m: f64 = 13.0, "m", Bounds::positive(1000.0);
        /// Distance upflow of the lost point of the first Bowtie centre.
        bowtie_offset_m: f64 = 10.0, "m", Bounds::non_negative(1000.0);
        /// Declaration rule.
        declaration: DeclarationChoice = DeclarationChoice::AlongFlow, "", Bounds::Any;
        /// Along-flow spread of the three most upflow lost points that declares (the field rule's 4 m declared in 28 of 40 demo missions against 37 with 6 m, and 39 against 40 of 40 coastal sites, at the same median error: the declared point is the most upflow one either way).
        declaration_along_m: f64 = 6.0, "m", Bounds::positive(1000.0);
        /// Crossflow spread bound of the along_and_cross_flow rule.
        declaration_cross_m: f64 = 8.0, "m", Bounds::positive(1000.0);
        /// How far upflow of the most upflow lost point the lost-point rules declare (0: at it, the field rule). The contacts of a bottom source begin only where its chemical has mixed up to the tracing altitude, some metres downflow of it: tracing at 1 m, the most upflow lost point lay a median 1.6-3.4 m downflow of the source on the families' tuning sites.
        declaration_upflow_m: f64 = 2.5, "m", Bounds::non_negative(100.0);
        /// Whether a contact during Track-Out upflow of the most upflow lost point runs the declaration check (true: the field rule, every Track-Out contact does). Such a contact says the plume goes on upflow: in a strong current a plume's patches far downflow of the source can gather three lost points within declaration_along_m, and the check then declared 150 m from the source.
        declaration_on_upflow_contact: bool = false, "", Bounds::Any;
        /// Before a lost-point rule declares, a confirming Track-Out flies from where the vehicle is to this far upflow of the point to declare (each leg clipped to the op-area pattern_margin_m inside it); a contact on the way more than declaration_along_m upflow of the point says the plume goes on there, and Track-In follows it instead of declaring (0: declare at once, the field rule). Far downflow of a source the plume breaks into patches, and the upflow ends of one patch can gather three lost points within declaration_along_m: on the families' tuning sites the check then declared 125-534 m downflow of the source (4 of 900 sites), with the plume going on beyond Track-Out's reach; the confirming leg costs a median 100 s before each declaration.
        declaration_confirm_m: f64 = 60.0, "m", Bounds::non_negative(1000.0);
        /// How far to each side of the flow axis through the point to declare the confirming Track-Out zigzags: three legs, each a third of declaration_confirm_m further upflow, first to the side away from the vehicle, then across to the other and back (0: one leg straight upflow). Far downflow the instantaneous plume is narrow and meanders across the flow: straight up its axis a leg found the plume beyond the patch on 2 of the 4 tuning sites, zigzagging on 3.
        declaration_confirm_width_m: f64 = 30.0, "m", Bounds::non_negative(1000.0);
        /// Where across the flow the lost-point rules declare: most_upflow (the most upflow lost point, the field rule) or mean (the mean of the three most upflow lost points across the flow).
        declaration_across: DeclarationAcross = DeclarationAcross::Mean, "", Bounds::Any;
        /// Fly the post-declaration mapping pattern (single-source missions).
        mapping: bool = true, "", Bounds::Any;
        /// Mapping lines.
        mapping_lines: u32 = 4, "", Bounds::whole(1, 100);
        /// Mapping line length.
        mapping_length_m: f64 = 80.0, "m", Bounds::positive(10_000.0);
        /// Mapping line spacing.
        mapping_spacing_m: f64 = 20.0, "m", Bounds::positive(1000.0);
        /// Search time per subregion of a multi-source mission before it is declared source-free.
        region_timeout_s: f64 = 1800.0, "s", Bounds::positive(1e6);
        /// When Track-In updates LHS from the heading: heading_upflow (only while the heading is within 90 deg of upflow, so a turn from downflow completes) or every_detection (Table 1 as printed: a Track-In that starts heading downflow can lock onto it).
        track_in_lhs: LhsUpdate = LhsUpdate::HeadingUpflow, "", Bounds::Any;
        /// Lanes Find: spacing of the lanes across the flow (each pass after the first flies lanes between those of the passes before: half, then a quarter of this).
        find_spacing_m: f64 = 120.0, "m", Bounds::closed(10.0, 100_000.0);
        /// Find's pattern: lanes (first along the downflow edge, which every plume crosses on its way out, then planned lines across the flow, up it and back down, on any shape of area) or billiard (the field description: headings psi_f +- 90 +- find_offset_deg, at a boundary keep the sign along it and flip it across; in rotated areas it can miss parts of the area or cycle in a corner).
        find_pattern: FindPattern = FindPattern::Lanes, "", Bounds::Any;
        /// Lost points older than this are dropped (0: never; a point near the source whose Bowties keep finding chemical downflow of it would otherwise stay for good).
        lost_point_max_age_s: f64 = 1800.0, "s", Bounds::non_negative(1e6);
        /// Lost points saved under a flow direction more than this from the current one are dropped (180: never; after a tide turns they no longer mark the plume).
        lost_point_max_turn_deg: f64 = 45.0, "deg", Bounds::closed(1.0, 180.0);
        /// Longest Reacquire without a detection (around one lost point and the next) before Find takes over from where the vehicle is (0: no bound).
        reacquire_timeout_s: f64 = 900.0, "s", Bounds::non_negative(1e6);
        /// Clip Bowtie and mapping lines to the op-area, pattern_margin_m inside it (a line the cage keeps the vehicle from ending is never flown to its end).
        clip_patterns: bool = true, "", Bounds::Any;
        /// How far inside the op-area clipped pattern lines stay.
        pattern_margin_m: f64 = 10.0, "m", Bounds::non_negative(1000.0);
        /// Longest post-declaration mapping (0: no bound; above 0 each line is also given up when not done in twice its time plus five minutes).
        mapping_timeout_s: f64 = 1800.0, "s", Bounds::non_negative(1e6);
        /// A flow reading more than this from the recent mean (before the first reading: from the prior flow direction, when the scenario gives one) is held back until such readings persist for flow_gate_persist_s (180: every reading used; a wrong-layer current meter reads the current reversed).
        flow_gate_deg: f64 = 90.0, "deg", Bounds::closed(1.0, 180.0);
        /// How long implausible flow readings must persist to be believed.
        flow_gate_persist_s: f64 = 1800.0, "s", Bounds::non_negative(1e6);
        /// At each position fix, move the lost points saved since the fix before, and the points held for later fix frames, by the share of the fix's jump that was their own navigation error when they were saved, under what fix_error_m, fix_drift_mps and held_back_drift_mps say of the navigation (false: lost points stay where the navigation put them, as flown in the field). Each fix puts a dead-reckoned estimate back on the truth within the fix's own error; the jump it makes is that error less the stretch's own (the fix before's, and the drift since), so it tells how far a point saved part-way through was off. A vehicle that dead-reckons with its current meter also drifts while the readings are held back (with the last plausible one, by however much the current has changed since): on the faults family's tuning sites by up to 54 m before the next fix. The jump is measured between navigation records at most 5 s apart (over longer gaps nothing is moved). On 24 of the faults family's tuning sites (seed 3211) the navigation error at the 923 lost points saved between fixes had a median of 6.2 m (p90 13.3 m) as saved and 3.9 m (7.7 m) as moved without the held-back term (scripts/lost_point_nav_error.py).
        fix_smoothing: bool = true, "", Bounds::Any;
        /// With fix_smoothing, how long the declaration waits for the fix that places its points. When flow readings were held back since the last fix, the declaration check does not declare until the next fix, for at most this long counted from the first check it held back (tracing goes on meanwhile, and the check runs again at the next Track-Out's end). When the model moves the points of every stretch (fix_error_m or fix_drift_mps above 0) and declaration_fix_frames is above 1, the held points are declared at the fix that ends the frame of the last one's lost points, or this long after it was held (0: as soon as the last is held, as the fixes so far have placed them). Only a navigation that has reported a fix is waited for. On the faults family's tuning sites 900 s declared 198 of 200 within 10 m, 600 s 197 and 1200 s the same as 900 s.
        fix_wait_s: f64 = 900.0, "s", Bounds::non_negative(1e5);
        /// How many points, each from its own position-fix frame, the declared point is the mean of. Each fix puts the navigation back on the truth within the fix's own error, a new error each time, and the lost points saved until the next fix carry it (with the drift since): a point declared from one frame's lost points is off by that frame's error (3-5 m a side on the faults family). Above 1, the point a lost-point rule would declare (after its confirming Track-Out) is held and tracing goes on; the check then counts only the lost points saved after the next fix, and the point it makes then is averaged with the held one (and so on); their mean is declared (1: the first point, as in the field). A navigation that has reported no fix is not waited for, nor are multi-source searches or the source map's points. Chosen on the three families' tuning sites (2 raised declarations within 10 m from 184, 192 and 193 of 200 to 194, 197 and 199; 3 gained nothing more on the faults family). On their test sites the default's share within 10 m went from 98.0, 87.5 and 98.0 % (coastal, faults, duck-like) to 97.5, 94.5 and 99.0 %, and its median declaration time from 1347, 1663 and 1250 s to 2818, 3689 and 2514 s.
        declaration_fix_frames: u32 = 2, "", Bounds::whole(1, 10);
        /// With fix_smoothing, the error of a position fix that the smoothing assumes, a standard deviation per axis. A point saved at time t into a stretch of length T between fixes is moved by (f^2 + d^2 t T + h^2 b B) / (2 f^2 + d^2 T^2 + h^2 B^2) of the jump that ends the stretch (f: this key, d: fix_drift_mps, h: held_back_drift_mps, b and B: held-back time by then and in the whole stretch; the first stretch, which starts on the truth, has no f^2 of its own): the share of the jump that was its own error, given the jump. Without held-back readings only the ratio of this key to fix_drift_mps counts (the time over which the drift grows as large as a fix's error: 400 s at the defaults). With this key and fix_drift_mps both 0 only held-back stretches move, by held-back time. Chosen on the tuning sites (seed 3211) of the faults, coastal and duck-like families, 200 each (examples/campaigns/amp-fix-smoothing.toml): with 4 m and 0.01 m/s, declarations within 10 m went from 194, 196 and 199 (held-back stretches alone) to 198, 199 and 199, the median error from 4.5, 3.3 and 3.5 m to 3.5, 2.3 and 2.7 m, and the median declaration time from 3376, 2714 and 2237 s to 3420, 3013 and 2413 s; ratios of 200, 300 and 800 s declared fewer within 10 m on at least one family (192-198).
        fix_error_m: f64 = 4.0, "m", Bounds::non_negative(1000.0);
        /// With fix_smoothing, the dead-reckoning drift between fixes that the smoothing assumes: a velocity error per axis that holds over a stretch (see fix_error_m).
        fix_drift_mps: f64 = 0.01, "m/s", Bounds::non_negative(10.0);
        /// With fix_smoothing, the drift while flow readings are held back that the smoothing assumes, per axis (see fix_error_m). On the tuning sites 0.015 and 0.06 m/s declared 197 and 198 of 200 fault sites within 10 m against 198, at medians of 3.4 and 3.5 m.
        held_back_drift_mps: f64 = 0.03, "m/s", Bounds::non_negative(10.0);
        /// With declaration_fix_frames above 1, the longest wait from the first held point: then the mean of the points so far is declared (a fix that never comes, or a plume the vehicle does not trace again). Held points are also declared in the mission's last minute, when the mission's end is known (the scenario's time limit; onboard, run.time_limit_s). On the tuning sites 1800 s declared 192 of 200 fault sites within 10 m against 194 with 3600 s, and 7200 s gained nothing over 3600.
        declaration_frame_wait_s: f64 = 3600.0, "s", Bounds::non_negative(1e5);
        /// Without a current meter (no flow reading yet), the current is estimated from the vehicle's own track, one sample per this window: the drift of the navigation positions against the water track (heading and water speed) plus the jumps at position fixes spread over the time since the fix before; the samples go through the flow estimate (flow_average_s, flow_gate_deg from the prior) as a meter's readings would (0: the prior direction alone).
        track_flow_window_s: f64 = 60.0, "s", Bounds::non_negative(3600.0);
        /// A track sample of the current slower than this is not used (it carries no direction: before the first fix of a vehicle that dead-reckons through the water alone, the track shows no current).
        track_flow_min_mps: f64 = 0.05, "m/s", Bounds::non_negative(10.0);
        /// A track sample of the current faster than this is not used (a bad fix).
        track_flow_max_mps: f64 = 3.0, "m/s", Bounds::positive(10.0);
        /// Navigation error growth assumed between fixes: the cage acts this much earlier per second since the last fix (0: at the op-area's edge, as in the field).
        nav_drift_mps: f64 = 0.02, "m/s", Bounds::non_negative(10.0);
        /// The most the cage's area is shrunk by for the navigation error.
        max_cage_inset_m: f64 = 20.0, "m", Bounds::non_negative(1000.0);
        /// Declaring from the source-likelihood map: off (the lost-point rule alone), instead (the map's rule alone: its most likely cell once the mass within map_radius_m reaches map_mass), also (whichever rule declares first) or refine (the lost-point rule says when, the map where: its most likely cell if the map's rule holds then, else the lost point).
        map_declaration: MapDeclaration = MapDeclaration::Off, "", Bounds::Any;
    }
}

/// The `map_declaration` key: whether the AMP declares from its source-likelihood map.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MapDeclaration {
    /// No map: the lost-point rule alone.
    Off,
    /// The map's rule alone (Track-Out ends go to Reacquire).
    Instead,
    /// Either rule, whichever declares first.
    Also,
    /// The lost-point rule decides when; the map's most likely cell is declared if the map's
    /// rule holds then (else the lost point).
    Refine,
}

impl Choice for MapDeclaration {
    const ALL: &'static [Self] = &[
        MapDeclaration::Off,
        MapDeclaration::Instead,
        MapDeclaration::Also,
        MapDeclaration::Refine,
    ];
}

/// When Track-In updates LHS from the vehicle's heading.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LhsUpdate {
    /// Only while the heading is within 90 deg of upflow.
    HeadingUpflow,
    /// At every detection (Table 1 as printed).
    EveryDetection,
}

impl Choice for LhsUpdate {
    const ALL: &'static [Self] = &[LhsUpdate::HeadingUpflow, LhsUpdate::EveryDetection];
}

/// Find's search pattern.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FindPattern {
    /// Lanes across the flow laid out over the subregion, flown up the flow and back down.
    Lanes,
    /// The field description: at a boundary keep the sign along it and flip it across.
    Billiard,
}

impl Choice for FindPattern {
    const ALL: &'static [Self] = &[FindPattern::Lanes, FindPattern::Billiard];
}

impl AmpParams {
    /// The source-likelihood map with its declaration rule, when `map_declaration` is on.
    fn map_tracker(&self, area: &OpArea) -> Result<Option<MapTracker>, ParamError> {
        if self.map_declaration == MapDeclaration::Off {
            return Ok(None);
        }
        self.map.tracker(area, self.autopilot.threshold_v).map(Some)
    }

    /// The declaration rule the keys describe.
    pub fn declaration_rule(&self) -> DeclarationRule {
        match self.declaration {
            DeclarationChoice::AlongFlow => DeclarationRule::AlongFlow {
                along_m: self.declaration_along_m,
            },
            DeclarationChoice::AlongAndCrossFlow => DeclarationRule::AlongAndCrossFlow {
                along_m: self.declaration_along_m,
                cross_m: self.declaration_cross_m,
            },
        }
    }

    /// Where the lost-point rules put the declared source.
    pub fn placement(&self) -> Placement {
        Placement {
            upflow_m: self.declaration_upflow_m,
            across: self.declaration_across,
        }
    }

    /// The mapping pattern, if one is flown.
    pub fn mapping_params(&self) -> Option<MappingParams> {
        self.mapping.then_some(MappingParams {
            lines: self.mapping_lines as usize,
            length_m: self.mapping_length_m,
            spacing_m: self.mapping_spacing_m,
        })
    }

    /// What the fix smoothing assumes of the navigation's errors.
    fn drift_model(&self) -> fixes::DriftModel {
        fixes::DriftModel {
            fix_m: self.fix_error_m,
            drift_mps: self.fix_drift_mps,
            held_back_mps: self.held_back_drift_mps,
        }
    }

    fn line_params(&self) -> LineParams {
        LineParams {
            speed_mps: self.autopilot.speed_mps,
            radius_m: self.r_m,
            gain_deg_per_m: self.k_deg_per_m,
            min_turn_radius_m: self.min_turn_radius_m,
            approach_replans: match self.approach_replans {
                0 => u32::MAX,
                n => n,
            },
        }
    }

    /// A Follow Line leg from `a` to `b` with the planner's speed, radius, gain and turning radius
    /// (approaching the start with the line's heading).
    fn line(&self, a: Vec2, b: Vec2) -> FollowLine {
        self.line_params().line(a, b)
    }

    fn go_to(&self, target_m: Vec2) -> GoToPoint {
        GoToPoint {
            target_m,
            speed_mps: self.autopilot.speed_mps,
            radius_m: self.r_m,
        }
    }
}

impl PlannerParams for AmpParams {
    const KIND: &'static str = "amp";
    const SUMMARY: &'static str = "REMUS Adaptive Mission Planner: Find, Track-In, Track-Out, Reacquire (Bowtie), lost-point declaration, mapping, subregions";

    const THRESHOLD_KEY: Option<&'static str> = Some("threshold_v");
    const BEHAVIOURS: &'static [BehaviourKind] = &[
        BehaviourKind::GoTo,
        BehaviourKind::Transit,
        BehaviourKind::Find,
        BehaviourKind::TrackIn,
        BehaviourKind::TrackOut,
        BehaviourKind::Reacquire,
        BehaviourKind::Mapping,
        BehaviourKind::Done,
    ];
    const RULES: &'static [RuleDoc] = &[
        RuleDoc {
            rule: declaration::ALONG_FLOW,
            doc: "the three most upflow lost points lie within declaration_along_m of each other along the flow: declaration_upflow_m upflow of the most upflow one, across the flow as declaration_across says (with 0 and most_upflow: the most upflow one, the field rule), once a confirming Track-Out declaration_confirm_m upflow of it met no plume (0: at once, the field rule); with declaration_fix_frames above 1, the mean of such points from that many position-fix frames (fewer when declaration_frame_wait_s or the mission's end comes first)",
        },
        RuleDoc {
            rule: declaration::ALONG_AND_CROSS_FLOW,
            doc: "the same, and within declaration_cross_m across the flow too",
        },
        RuleDoc {
            rule: declaration::UPFLOW_EDGE,
            doc: "a multi-source search traced the plume to its subregion's up-flow edge: the point there",
        },
        RuleDoc {
            rule: crate::estimate::tracker::SOURCE_MAP,
            doc: "with map_declaration: the source map's most likely cell (the posterior mean within map_estimate_radius_m of it) once map_mass lies within map_radius_m of it for map_hold_s",
        },
    ];

    fn validate(&self, prefix: &str) -> Result<(), ParamError> {
        self.check_bounds(prefix)?;
        if self.track_flow_min_mps >= self.track_flow_max_mps {
            return Err(ParamError::at(
                prefix,
                "track_flow_min_mps",
                format!(
                    "must be below track_flow_max_mps ({}), not {}: no sample of the current from the track would be used",
                    self.track_flow_max_mps, self.track_flow_min_mps
                ),
            ));
        }
        Ok(())
    }

    fn detection_threshold_v(&self) -> Option<f64> {
        Some(self.autopilot.threshold_v)
    }

    fn without_effect(&self) -> Vec<(&'static str, String)> {
        // Without a map declaration the AMP keeps no map: every map key is idle.
        let mut out = if self.map_declaration == MapDeclaration::Off {
            MapKeys::keys()
                .into_iter()
                .map(|k| {
                    (
                        k.name,
                        "has no effect with map_declaration = \"off\" (the default): the AMP \
                         keeps no source map (set map_declaration = \"also\" or \"instead\", or \
                         leave the key out)"
                            .to_string(),
                    )
                })
                .collect()
        } else {
            self.map.without_effect()
        };
        if self.declaration_fix_frames <= 1 {
            out.push((
                "declaration_frame_wait_s",
                "has no effect with declaration_fix_frames = 1: nothing is held for a later fix \
                 frame (set declaration_fix_frames = 2 or more, or leave \
                 declaration_frame_wait_s out)"
                    .to_string(),
            ));
        }
        if !self.fix_smoothing {
            out.push((
                "fix_wait_s",
                "has no effect with fix_smoothing = false: the wait for the next fix is part of \
                 moving lost points with it (set fix_smoothing = true, or leave fix_wait_s out)"
                    .to_string(),
            ));
            for key in ["fix_error_m", "fix_drift_mps", "held_back_drift_mps"] {
                out.push((
                    key,
                    format!(
                        "has no effect with fix_smoothing = false: it says how far the next fix \
                         moves lost points (set fix_smoothing = true, or leave {key} out)"
                    ),
                ));
            }
        }
        out
    }

    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Planner>, ParamError> {
        // Refuse a map that does not fit (Amp::new would leave it out).
        self.map_tracker(&ctx.geometry.op_area)?;
        let amp = Amp::new(
            self.clone(),
            ctx.geometry.op_area.clone(),
            ctx.geometry.subregions.clone(),
            ctx.geometry.prior_flow_toward(),
        );
        let amp = amp.ending_at(ctx.mission_end_s);
        Ok(Box::new(if ctx.geometry.prior_flow_given {
            amp.trusting_prior()
        } else {
            amp
        }))
    }
}

/// Which lost point is dropped when a new one arrives at a full list (the field planner kept at
/// most six; which one made room is not recorded).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LostPointEviction {
    /// The oldest point: the list follows the latest losses. In strong currents the losses
    /// scatter tens of metres downflow of the source and the three most upflow points rarely
    /// agree: 48 of 60 coastal sites within 50 m, against 60 of 60 with the default.
    Oldest,
    /// The most downflow of the older points (the new one always enters; the default): the list
    /// keeps the points nearest the source, which Track-Out, Reacquire and the declaration use.
    /// Near a source whose plume reaches the vehicle's altitude only intermittently, points near
    /// the plume's tip survive the losses further downflow until three agree. Alone it has a
    /// price: upflow points whose Bowties keep finding chemical downflow of them are never
    /// dropped (4 of 40 `duck-2003-st` runs never declared); `lost_point_max_age_s` ages them
    /// out.
    MostDownflow,
}

impl Choice for LostPointEviction {
    const ALL: &'static [Self] = &[LostPointEviction::Oldest, LostPointEviction::MostDownflow];
}

/// Why an AMP behaviour finished.
#[derive(Debug, Clone, Copy, PartialEq)]
enum AmpDone {
    /// A goal reached or a pattern flown (Go-To, Transit, Track-Out, Mapping).
    Reached,
    /// Track-In lost contact `lambda` after the last detection, which was here.
    Lost { at: Vec2 },
    /// Tracing reached the subregion's upflow edge here (multi-source missions).
    AtEdge { at: Vec2 },
    /// Reacquire flew every Bowtie of this lost point without a detection.
    Searched { id: u64 },
}

impl From<Reached> for AmpDone {
    fn from(_: Reached) -> Self {
        AmpDone::Reached
    }
}

/// A lost point: where contact was lost, when, and the flow direction then.
#[derive(Debug, Clone, Copy, PartialEq)]
struct LostPoint {
    pos: Vec2,
    t_s: f64,
    flow: Heading,
    /// Time the flow reading had been held back since the last fix (`fix_smoothing`), s.
    held_back_s: f64,
    /// Which point this is (its position moves with `fix_smoothing`).
    id: u64,
    /// The fix frame it was saved in (how many fixes the navigation had reported).
    frame: u64,
}

/// How long before the mission's end points held for later fix frames are declared, s.
const LAST_CALL_S: f64 = 60.0;

/// A point a declaration would have made, held until later fix frames give theirs
/// (`declaration_fix_frames`).
#[derive(Debug, Clone, PartialEq)]
struct Candidate {
    at: Vec2,
    rule: DeclarationKind,
    /// The fix frame it was made in.
    frame: u64,
    t_s: f64,
    /// The lost points it was made from (the rule's three most upflow), as they were saved:
    /// each fix moves it by the mean of their shares of its jump (`fix_smoothing`).
    points: Vec<LostPoint>,
}

/// A declaration held back while the confirming Track-Out flies upflow of it
/// (`declaration_confirm_m`), or taken at once.
#[derive(Debug, Clone, PartialEq)]
struct Confirm {
    /// The point to declare.
    at: Vec2,
    /// The rule that placed it.
    rule: DeclarationKind,
    /// The confirming legs' ends, in order.
    goals: Vec<Vec2>,
    /// The lost points it was placed from (each fix during the leg moves it with them).
    points: Vec<LostPoint>,
}

/// What the AMP's behaviours share: parameters, areas, the flow estimate, LHS, the lost points
/// and the events of the current decision.
#[derive(Debug, Clone)]
struct Memory {
    p: AmpParams,
    regions: Vec<OpArea>,
    region: usize,
    region_started_s: f64,
    /// The whole op-area (pattern lines are clipped to it).
    area: OpArea,
    lhs: f64,
    last_detection: Option<(f64, Vec2)>,
    lost: Vec<LostPoint>,
    /// The id of the next lost point.
    next_lost_id: u64,
    /// Position fixes in the navigation records (`fix_smoothing`).
    fixes: fixes::FixWatch,
    declared: Vec<Vec2>,
    /// A declaration awaiting its confirming Track-Out.
    confirm: Option<Confirm>,
    /// Points held for later fix frames (`declaration_fix_frames`), oldest first.
    candidates: Vec<Candidate>,
    /// When the mission ends, s (held points are declared before then).
    end_s: Option<f64>,
    flow: FlowEstimate,
    events: Vec<PlannerEvent>,
    /// When Reacquire began after the last detection.
    reacquire_since: Option<f64>,
    /// The source-likelihood map, when `map_declaration` is on.
    map: Option<MapTracker>,
    /// Map telemetry of the current decision made inside the switching logic.
    map_telemetry: Vec<Telemetry>,
}

impl EventLog for Memory {
    fn log(&mut self, e: PlannerEvent) {
        self.events.push(e);
    }
}

impl Memory {
    fn multi_region(&self) -> bool {
        self.regions.len() > 1
    }

    fn lhs_from_heading(&self, heading: Heading) -> f64 {
        // Table 1: psi_v - psi_f wrapped to [0, 360) and compared with 180.
        if wrap_deg_360(heading.deg() - self.flow.toward().deg()) < 180.0 {
            1.0
        } else {
            -1.0
        }
    }

    fn most_upflow_lost(&self) -> Option<Vec2> {
        self.most_upflow_lost_point().map(|l| l.pos)
    }

    fn most_upflow_lost_point(&self) -> Option<&LostPoint> {
        let u = self.flow.upflow().unit();
        self.lost
            .iter()
            .max_by(|a, b| a.pos.dot(&u).total_cmp(&b.pos.dot(&u)))
    }

    /// Moves the lost points saved since the fix before `fix` by their share of its jump, an
    /// event for each point moved, the latest saved first (as the events' readers match a move to
    /// the latest point at its `from_m`, two points saved at one spot keep their own tracks).
    fn smooth_lost(&mut self, fix: &fixes::Fix) {
        let model = self.p.drift_model();
        for l in self.lost.iter_mut().rev() {
            let share = fix.share(l.t_s, l.held_back_s, &model);
            if share > 0.0 {
                let from_m = l.pos;
                l.pos += fix.jump_m * share;
                if l.pos != from_m {
                    self.events.push(PlannerEvent::LostPointMoved {
                        from_m,
                        to_m: l.pos,
                    });
                }
            }
        }
    }

    /// `pos` lies upflow of every lost point.
    fn upflow_of_lost(&self, pos: Vec2) -> bool {
        let u = self.flow.upflow().unit();
        self.most_upflow_lost()
            .is_some_and(|top| pos.dot(&u) > top.dot(&u))
    }

    /// The ends of the confirming Track-Out's legs before declaring `at` with the vehicle at
    /// `pos` (none: `declaration_confirm_m` is 0, or no leg lies inside the op-area).
    fn confirm_goals(&self, at: Vec2, pos: Vec2) -> Vec<Vec2> {
        let (length, width) = (
            self.p.declaration_confirm_m,
            self.p.declaration_confirm_width_m,
        );
        if length <= 0.0 {
            return Vec::new();
        }
        let up = self.flow.upflow();
        let (u, c) = (up.unit(), up.turned_deg(90.0).unit());
        // First to the side away from the vehicle.
        let mut side = if (pos - at).dot(&c) > 0.0 { -1.0 } else { 1.0 };
        let mut goals = Vec::new();
        for k in 1..=3 {
            let goal = at + u * (length * f64::from(k) / 3.0) + c * (width * side);
            side = -side;
            if width <= 0.0 && k < 3 {
                continue;
            }
            if let Some((_, end)) = self.pattern_line(at, goal) {
                goals.push(end);
            }
        }
        goals
    }

    /// `pos` lies more than `declaration_along_m` upflow of `point`.
    fn upflow_of_point(&self, pos: Vec2, point: Vec2) -> bool {
        let u = self.flow.upflow().unit();
        (pos - point).dot(&u) > self.p.declaration_along_m
    }

    /// Reacquire has searched for `reacquire_timeout_s` since the last detection.
    fn reacquire_timed_out(&self, t: f64) -> bool {
        self.p.reacquire_timeout_s > 0.0
            && self
                .reacquire_since
                .is_some_and(|t0| t - t0 > self.p.reacquire_timeout_s)
    }

    /// The lost points' positions, oldest first.
    fn lost_positions(&self) -> Vec<Vec2> {
        self.lost.iter().map(|l| l.pos).collect()
    }

    /// Where the lost points the declaration check counts lie ([`Memory::checked`]).
    fn checked_positions(&self) -> Vec<Vec2> {
        self.checked().map(|l| l.pos).collect()
    }

    /// The lost points the declaration check counts, oldest first: while a point is held
    /// (`declaration_fix_frames`), only those saved in a later fix frame than its own.
    fn checked(&self) -> impl Iterator<Item = &LostPoint> {
        let after = self.candidates.last().map(|c| c.frame);
        self.lost
            .iter()
            .filter(move |l| after.is_none_or(|f| l.frame > f))
    }

    /// The mean of the held points (`None`: none is held).
    fn candidate_mean(&self) -> Option<Vec2> {
        let n = self.candidates.len();
        (n > 0).then(|| self.candidates.iter().fold(Vec2::zeros(), |a, c| a + c.at) / n as f64)
    }

    /// A point is held from the navigation's present fix frame: another now would repeat its
    /// frame's error.
    fn held_in_this_frame(&self) -> bool {
        self.candidates
            .last()
            .is_some_and(|c| c.frame == self.fixes.count())
    }

    /// Takes the point a declaration would make at `t`: `Some` point to declare now (the mean of
    /// the held points with it, once `declaration_fix_frames` frames have given one), or `None`
    /// when it is held for a later fix frame.
    fn hold_for_frames(
        &mut self,
        at: Vec2,
        rule: DeclarationKind,
        t: f64,
        points: Vec<LostPoint>,
    ) -> Option<Vec2> {
        let wanted = self.p.declaration_fix_frames as usize;
        // The map's points pool every frame's detections: only the lost-point rules' are held.
        let lost_point_rule =
            rule == declaration::ALONG_FLOW || rule == declaration::ALONG_AND_CROSS_FLOW;
        if wanted <= 1 || self.multi_region() || self.fixes.count() == 0 || !lost_point_rule {
            return Some(at);
        }
        if self.holding_all_frames() || self.held_in_this_frame() {
            return None;
        }
        let frame = points
            .iter()
            .map(|l| l.frame)
            .max()
            .unwrap_or_else(|| self.fixes.count());
        self.candidates.push(Candidate {
            at,
            rule,
            frame,
            t_s: t,
            points,
        });
        if self.candidates.len() < wanted || (self.waits_for_fixes() && !self.candidates_placed()) {
            return None;
        }
        self.candidate_mean()
    }

    /// Whether fixes move held points (and a point awaiting its confirming Track-Out):
    /// `fix_smoothing` with a drift model that moves points of every stretch.
    fn moves_held_points(&self) -> bool {
        self.p.fix_smoothing && self.p.drift_model().moves_every_stretch()
    }

    /// Whether the held points wait for the fixes that end their frames (`fix_wait_s` above 0).
    fn waits_for_fixes(&self) -> bool {
        self.moves_held_points() && self.p.fix_wait_s > 0.0
    }

    /// Every frame has given its point, and they wait for the fixes that place them.
    fn holding_all_frames(&self) -> bool {
        let wanted = self.p.declaration_fix_frames as usize;
        wanted > 1 && self.candidates.len() >= wanted
    }

    /// Every held point has been placed by the fixes that end its lost points' frames.
    fn candidates_placed(&self) -> bool {
        let count = self.fixes.count();
        self.candidates
            .iter()
            .all(|c| c.points.iter().all(|l| l.frame < count))
    }

    /// The three most upflow lost points the declaration check counts, most upflow first.
    fn top_checked(&self) -> Vec<LostPoint> {
        let u = self.flow.upflow().unit();
        let mut points: Vec<LostPoint> = self.checked().copied().collect();
        points.sort_by(|a, b| b.pos.dot(&u).total_cmp(&a.pos.dot(&u)));
        points.truncate(3);
        points
    }

    /// Moves each held point, and a point awaiting its confirming Track-Out, by the mean of
    /// its lost points' shares of `fix`'s jump (those from before the stretch it ends have none).
    fn place_held(&mut self, fix: &fixes::Fix) {
        let model = self.p.drift_model();
        let mean_share = |points: &[LostPoint]| {
            if points.is_empty() {
                return 0.0;
            }
            points
                .iter()
                .map(|l| fix.share(l.t_s, l.held_back_s, &model))
                .sum::<f64>()
                / points.len() as f64
        };
        for c in &mut self.candidates {
            c.at += fix.jump_m * mean_share(&c.points);
        }
        if let Some(c) = self.confirm.as_mut() {
            c.at += fix.jump_m * mean_share(&c.points);
        }
    }

    /// The held points' mean and the last one's rule, once all `declaration_fix_frames` are held
    /// and placed by their fixes, or `fix_wait_s` after the last was held.
    fn candidates_ready(&self, t: f64) -> Option<(Vec2, DeclarationKind)> {
        let last = self.candidates.last()?;
        if !self.holding_all_frames() || !self.waits_for_fixes() {
            return None;
        }
        if !self.candidates_placed() && t - last.t_s <= self.p.fix_wait_s {
            return None;
        }
        self.held()
    }

    /// The held points' mean and the last one's rule (`None`: none is held).
    fn held(&self) -> Option<(Vec2, DeclarationKind)> {
        let rule = self.candidates.last()?.rule.clone();
        Some((self.candidate_mean()?, rule))
    }

    /// Declares the held points' mean at once (the run is ending): the event, if one was held.
    fn declare_held(&mut self) -> Option<PlannerEvent> {
        let (at, rule) = self.held()?;
        self.candidates.clear();
        self.declared.push(at);
        Some(PlannerEvent::Declared { pos_m: at, rule })
    }

    /// The held points' mean and the last one's rule, once `declaration_frame_wait_s` has passed
    /// since the first was held, or in the mission's last minute.
    fn frames_timed_out(&self, t: f64) -> Option<(Vec2, DeclarationKind)> {
        let first = self.candidates.first()?;
        let ending = self.end_s.is_some_and(|end| t >= end - LAST_CALL_S);
        if t - first.t_s <= self.p.declaration_frame_wait_s && !ending {
            return None;
        }
        self.held()
    }

    /// Drops lost points older than `lost_point_max_age_s`, and those saved under a flow
    /// direction more than `lost_point_max_turn_deg` from the current estimate.
    fn prune_lost(&mut self, t: f64) {
        let (age, turn) = (self.p.lost_point_max_age_s, self.p.lost_point_max_turn_deg);
        let now = self.flow.toward();
        self.lost.retain(|l| {
            (age <= 0.0 || t - l.t_s <= age)
                && (turn >= 180.0 || l.flow.diff_deg(now).abs() <= turn)
        });
    }

    /// A pattern line, clipped to the op-area `pattern_margin_m` inside it when `clip_patterns`
    /// is on (`None`: no part of it at least `r_m` long lies inside).
    fn pattern_line(&self, a: Vec2, b: Vec2) -> Option<(Vec2, Vec2)> {
        if !self.p.clip_patterns {
            return Some((a, b));
        }
        self.area
            .clip_segment(a, b, self.p.pattern_margin_m, self.p.r_m)
    }

    /// Saves a lost point, keeping at most `max_lost_points`: beyond it the point chosen by
    /// `lost_point_eviction` is dropped.
    fn save_lost_point(&mut self, p: Vec2, t: f64) {
        self.lost.push(LostPoint {
            pos: p,
            t_s: t,
            flow: self.flow.toward(),
            held_back_s: self.fixes.held_back_s(),
            id: self.next_lost_id,
            frame: self.fixes.count(),
        });
        self.next_lost_id += 1;
        self.events.push(PlannerEvent::LostPoint { pos_m: p });
        if self.lost.len() > self.p.max_lost_points as usize {
            let drop = match self.p.lost_point_eviction {
                LostPointEviction::Oldest => 0,
                LostPointEviction::MostDownflow => {
                    let u = self.flow.upflow().unit();
                    // Among the older points (the new one always enters, or a list of six
                    // upflow points would never change); `min_by` keeps the first of equals.
                    // While a point is held for a later fix frame, its frame's points stay: a
                    // later frame's point enters the check's count only when it is among the
                    // most upflow, as the held one's were.
                    let older = &self.lost[..self.lost.len() - 1];
                    older
                        .iter()
                        .enumerate()
                        .min_by(|a, b| a.1.pos.dot(&u).total_cmp(&b.1.pos.dot(&u)))
                        .map_or(0, |(i, _)| i)
                }
            };
            self.lost.remove(drop);
        }
    }

    /// The Track-Out goal: `L_u` upflow and `L_c` across the flow from the most upflow lost
    /// point, on the side opposite to where the vehicle left the plume.
    fn track_out_goal(&self) -> Option<Vec2> {
        let p = self.most_upflow_lost()?;
        let up = self.flow.upflow();
        // LHS = +1: left the plume on its left (looking upflow): go to the right, clockwise.
        Some(p + up.unit() * self.p.l_u_m + up.turned_deg(90.0 * self.lhs).unit() * self.p.l_c_m)
    }

    /// In a multi-source mission: the point on the subregion's upflow edge when the vehicle at
    /// `pos` has traced the plume there.
    fn upflow_edge(&self, pos: Vec2) -> Option<Vec2> {
        if !self.multi_region() {
            return None;
        }
        let e = self.regions[self.region].edge_info(pos);
        let up = self.flow.upflow().unit();
        (e.distance_m < self.p.r_m && e.outward_normal.dot(&up) > 0.7).then(|| {
            if e.inside {
                pos + e.outward_normal * e.distance_m
            } else {
                pos - e.outward_normal * e.distance_m
            }
        })
    }

    /// Where the search of subregion `k` starts: its most downflow corner (for the current flow
    /// estimate), moved 1.5 `R` towards the subregion's centre.
    fn search_start(&self, k: usize) -> Vec2 {
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
}

type AmpBehaviour = Box<dyn Behaviour<Memory, AmpDone>>;

/// The AMP's switching logic: which behaviour runs, and what follows each one's end.
struct Switching {
    active: AmpBehaviour,
}

impl Switching {
    fn set(&mut self, m: &mut Memory, next: AmpBehaviour) {
        let changed = next.kind() != self.active.kind();
        self.active = next;
        if changed {
            m.log(PlannerEvent::Behaviour {
                behaviour: self.active.kind(),
            });
        }
    }

    fn start_region(&mut self, m: &mut Memory, k: usize, t: f64) {
        m.region = k;
        m.region_started_s = t;
        m.lost.clear();
        m.last_detection = None;
        m.confirm = None;
        m.candidates.clear();
        m.log(PlannerEvent::Region {
            index: k,
            what: RegionEvent::Started,
        });
        let kind = if m.multi_region() {
            BehaviourKind::Transit
        } else {
            BehaviourKind::GoTo
        };
        let goal = m.p.go_to(m.search_start(k));
        self.set(m, Box::new(GoTo { goal, kind }));
    }

    fn next_region(&mut self, m: &mut Memory, t: f64) {
        if m.region + 1 < m.regions.len() {
            self.start_region(m, m.region + 1, t);
        } else {
            self.set(m, Box::new(Idle));
        }
    }

    /// Find from `pos`; `first`: the subregion's search starts (else the plume was lost for good).
    fn enter_find(&mut self, m: &mut Memory, pos: Vec2, first: bool) {
        let h = find::initial_heading(
            &m.regions[m.region],
            pos,
            m.flow.toward(),
            m.p.find_offset_deg,
        );
        self.set(m, Box::new(Find::new(h, first)));
    }

    fn enter_track_in(&mut self, m: &mut Memory, p: &Percept) {
        m.reacquire_since = None;
        if m.last_detection.is_none() {
            m.lhs = m.lhs_from_heading(p.heading);
        }
        let h = m.flow.upflow().turned_deg(m.lhs * m.p.beta_deg);
        self.set(m, Box::new(TrackIn { heading: h }));
    }

    fn enter_reacquire(&mut self, m: &mut Memory, pos: Vec2) {
        match m.most_upflow_lost_point().map(|l| (l.pos, l.id)) {
            Some((point, id)) => {
                let r = Reacquire::new(m, point, id);
                self.set(m, Box::new(r));
            }
            None => self.enter_find(m, pos, false),
        }
    }

    /// Declares `at`, or holds it for a later fix frame (`declaration_fix_frames`) while
    /// Reacquire goes on tracing from `pos`.
    fn declare(&mut self, m: &mut Memory, c: Confirm, what: RegionEvent, pos: Vec2, t: f64) {
        let Confirm {
            at, rule, points, ..
        } = c;
        match m.hold_for_frames(at, rule.clone(), t, points) {
            Some(at) => self.declare_now(m, at, rule, what, t),
            None => {
                m.confirm = None;
                self.enter_reacquire(m, pos);
            }
        }
    }

    fn declare_now(
        &mut self,
        m: &mut Memory,
        at: Vec2,
        rule: DeclarationKind,
        what: RegionEvent,
        t: f64,
    ) {
        m.confirm = None;
        m.candidates.clear();
        m.declared.push(at);
        m.log(PlannerEvent::Declared { pos_m: at, rule });
        if m.multi_region() {
            m.log(PlannerEvent::Region {
                index: m.region,
                what,
            });
            self.next_region(m, t);
        } else if let Some(map) = m.p.mapping_params() {
            // Lines near an edge are flown where they lie inside the op-area.
            let legs: Vec<(Vec2, Vec2)> = map
                .legs(at, m.flow.toward())
                .into_iter()
                .filter_map(|(a, b)| m.pattern_line(a, b))
                .collect();
            let mut pattern = Legs::new(legs, m.p.line_params(), BehaviourKind::Mapping);
            if m.p.mapping_timeout_s > 0.0 {
                pattern = pattern
                    .with_timeout(m.p.mapping_timeout_s)
                    .with_leg_budgets();
            }
            self.set(m, Box::new(pattern));
        } else {
            self.set(m, Box::new(Idle));
        }
    }

    /// Declares `at` at once, or first flies the confirming Track-Out to `declaration_confirm_m`
    /// upflow of it (where that leg has at least `r_m` inside the op-area).
    fn confirm_or_declare(&mut self, m: &mut Memory, at: Vec2, rule: DeclarationKind, p: &Percept) {
        let t = p.t_s;
        let goals = m.confirm_goals(at, p.pos_m);
        let points = m.top_checked();
        if goals.is_empty() {
            let c = Confirm {
                at,
                rule,
                goals,
                points,
            };
            self.declare(m, c, RegionEvent::Declared, p.pos_m, t);
            return;
        }
        let leg = ConfirmLeg::new(goals.iter().map(|g| m.p.go_to(*g)).collect());
        m.confirm = Some(Confirm {
            at,
            rule,
            goals,
            points,
        });
        self.set(m, Box::new(leg));
    }

    /// A contact while a declaration awaits its confirming Track-Out: more than
    /// `declaration_along_m` upflow of the point, the plume goes on there and Track-In follows
    /// it (true); elsewhere the leg flies on (false).
    fn confirm_contact(&mut self, m: &mut Memory, p: &Percept) -> bool {
        let beyond = m
            .confirm
            .as_ref()
            .is_some_and(|c| m.upflow_of_point(p.pos_m, c.at));
        if beyond {
            m.confirm = None;
        }
        beyond
    }

    /// Runs the declaration check; true when a source was declared (or a confirming Track-Out
    /// began).
    fn try_declare(&mut self, m: &mut Memory, p: &Percept) -> bool {
        let t = p.t_s;
        if m.p.map_declaration == MapDeclaration::Instead {
            return false;
        }
        if m.holding_all_frames() {
            // Every frame's point is held and waits for its fix: no new point is wanted.
            return false;
        }
        if m.p.fix_smoothing && m.p.fix_wait_s > 0.0 && m.fixes.awaiting_fix(t, m.p.fix_wait_s) {
            // The lost points are where a drifting navigation put them: the next fix places
            // them (fix_smoothing), and the check runs again at the next Track-Out's end.
            return false;
        }
        let rule = m.p.declaration_rule();
        match rule.check_placed(&m.checked_positions(), m.flow.upflow(), m.p.placement()) {
            Some(at) => {
                let refined = match (m.p.map_declaration, m.map.as_mut()) {
                    (MapDeclaration::Refine, Some(tracker)) => {
                        let read = tracker.read(t);
                        let mut telemetry = Vec::new();
                        tracker.report(t, &read, &mut telemetry, true);
                        m.map_telemetry.extend(telemetry);
                        if m.regions.len() > 1 {
                            tracker.reset();
                        }
                        read.declares(tracker.rule()).then_some(read.estimate_m)
                    }
                    _ => None,
                };
                match refined {
                    Some(peak) => {
                        self.confirm_or_declare(m, peak, crate::estimate::tracker::SOURCE_MAP, p)
                    }
                    None => self.confirm_or_declare(m, at, rule.kind(), p),
                }
                true
            }
            None => false,
        }
    }

    /// What follows the end of the active behaviour.
    fn after(&mut self, m: &mut Memory, p: &Percept, done: AmpDone) {
        match (self.active.kind(), done) {
            (_, AmpDone::AtEdge { at }) => {
                self.declare_now(
                    m,
                    at,
                    declaration::UPFLOW_EDGE,
                    RegionEvent::DeclaredAtEdge,
                    p.t_s,
                );
            }
            (_, AmpDone::Lost { at }) => {
                m.save_lost_point(at, p.t_s);
                match m.track_out_goal() {
                    Some(goal) => {
                        let g = m.p.go_to(goal);
                        self.set(m, Box::new(TrackOut { goal: g }));
                    }
                    None => self.enter_find(m, p.pos_m, false),
                }
            }
            (_, AmpDone::Searched { id }) => {
                m.lost.retain(|q| q.id != id);
                if m.reacquire_timed_out(p.t_s) {
                    // The plume is not where the lost points are: search on (they are kept
                    // for the next losses, until they age out).
                    m.reacquire_since = None;
                    self.enter_find(m, p.pos_m, false);
                } else {
                    self.enter_reacquire(m, p.pos_m);
                }
            }
            (BehaviourKind::TrackOut, AmpDone::Reached) => {
                if let Some(c) = m.confirm.take() {
                    // The confirming leg met no plume upflow of the point.
                    self.declare(m, c, RegionEvent::Declared, p.pos_m, p.t_s);
                } else if !self.try_declare(m, p) {
                    self.enter_reacquire(m, p.pos_m);
                }
            }
            (BehaviourKind::Mapping, AmpDone::Reached) => self.set(m, Box::new(Idle)),
            (_, AmpDone::Reached) => {
                // Go-To or Transit arrived: the subregion's search starts now.
                m.region_started_s = p.t_s;
                self.enter_find(m, p.pos_m, true);
            }
        }
    }
}

impl Arbiter<Memory> for Switching {
    fn arbitrate(&mut self, p: &Percept, m: &mut Memory) -> Option<Steer> {
        m.prune_lost(p.t_s);
        if let Some((at, rule)) = m
            .frames_timed_out(p.t_s)
            .or_else(|| m.candidates_ready(p.t_s))
        {
            self.declare_now(m, at, rule, RegionEvent::Declared, p.t_s);
        }
        // On the way to the search start: its corner follows the flow estimate as it settles
        // (the first sample of a noisy current meter can point anywhere).
        let kind = self.active.kind();
        if matches!(kind, BehaviourKind::GoTo | BehaviourKind::Transit) {
            let goal = m.p.go_to(m.search_start(m.region));
            self.active = Box::new(GoTo { goal, kind });
        }
        // Subregion timeout (multi-source missions).
        let kind = self.active.kind();
        if m.multi_region()
            && !matches!(kind, BehaviourKind::Transit | BehaviourKind::Done)
            && p.t_s - m.region_started_s > m.p.region_timeout_s
        {
            m.log(PlannerEvent::Region {
                index: m.region,
                what: RegionEvent::TimedOut,
            });
            self.next_region(m, p.t_s);
        }
        // A decision may switch behaviours a few times (e.g. Track-Out arrives, the check
        // declares, mapping starts); the bound only guards against a switching loop.
        for _ in 0..8 {
            let kind = self.active.kind();
            let tracking_allowed = !matches!(
                kind,
                BehaviourKind::Transit | BehaviourKind::Mapping | BehaviourKind::Done
            );
            let confirming = m.confirm.is_some() && kind == BehaviourKind::TrackOut;
            if p.detected && confirming && !self.confirm_contact(m, p) {
                // Chemical around the point to declare: the confirming leg flies on.
            } else if p.detected && tracking_allowed && kind != BehaviourKind::TrackIn {
                if kind == BehaviourKind::TrackOut
                    && !confirming
                    && (m.p.declaration_on_upflow_contact || !m.upflow_of_lost(p.pos_m))
                    && self.try_declare(m, p)
                {
                    continue;
                }
                self.enter_track_in(m, p);
            }
            match self.active.propose(p, m) {
                Proposal::Steer(s) => return Some(s),
                Proposal::Idle => return None,
                Proposal::Done(done) => self.after(m, p, done),
            }
        }
        None
    }

    fn active(&self) -> BehaviourKind {
        self.active.kind()
    }
}

/// The Adaptive Mission Planner for one AUV.
pub struct Amp {
    m: Memory,
    switching: Switching,
    autopilot: Autopilot,
    in_contact: bool,
    started: bool,
    last_steer: Steer,
    reported_estimate: Option<Vec2>,
    /// The current from the track, until a current meter reports (`None`: not estimated).
    track_flow: Option<TrackFlow>,
}

impl Amp {
    /// The planner for a mission that ends at `end_s` (s of mission time): points held for later
    /// fix frames (`declaration_fix_frames`) are declared in its last minute at the latest.
    pub fn ending_at(mut self, end_s: Option<f64>) -> Self {
        self.m.end_s = end_s.filter(|e| e.is_finite());
        self
    }

    /// The planner with its flow gate judging the first readings against the prior flow
    /// direction (one the mission plan gives): a current meter that reads reversed from the
    /// start is then held back too.
    pub fn trusting_prior(mut self) -> Self {
        self.m.flow = self.m.flow.trusting_fallback();
        self
    }

    /// A planner for `area`, searched whole (single-source mission) or, with several `regions`,
    /// one subregion after the other. `prior_flow` is the flow direction assumed until the first
    /// flow measurement. With `map_declaration` on, the source-likelihood map covers `area`
    /// (when it does not fit, the planner has none: the registry's build refuses such keys).
    pub fn new(p: AmpParams, area: OpArea, regions: Vec<OpArea>, prior_flow: Heading) -> Self {
        let map = p.map_tracker(&area).unwrap_or(None);
        let track_flow = (p.track_flow_window_s > 0.0).then(|| {
            TrackFlow::new(TrackFlowParams {
                window_s: p.track_flow_window_s,
                min_mps: p.track_flow_min_mps,
                max_mps: p.track_flow_max_mps,
            })
        });
        let regions = if regions.is_empty() {
            vec![area.clone()]
        } else {
            regions
        };
        let autopilot = Autopilot::new(AutopilotParams {
            nav_drift_mps: p.nav_drift_mps,
            max_inset_m: p.max_cage_inset_m,
            ..p.autopilot.autopilot(area.clone())
        });
        Amp {
            last_steer: Steer {
                heading: Heading::NORTH,
                speed_mps: p.autopilot.speed_mps,
            },
            m: Memory {
                flow: {
                    let f = p.autopilot.flow_estimate(prior_flow);
                    if p.flow_gate_deg < 180.0 {
                        f.with_gate(plumetrace_core::FlowGateParams {
                            max_turn_deg: p.flow_gate_deg,
                            persist_s: p.flow_gate_persist_s,
                            ..plumetrace_core::FlowGateParams::default()
                        })
                    } else {
                        f
                    }
                },
                p,
                regions,
                region: 0,
                region_started_s: 0.0,
                area,
                lhs: 1.0,
                last_detection: None,
                lost: Vec::new(),
                next_lost_id: 0,
                fixes: fixes::FixWatch::default(),
                declared: Vec::new(),
                confirm: None,
                candidates: Vec::new(),
                end_s: None,
                events: Vec::new(),
                reacquire_since: None,
                map,
                map_telemetry: Vec::new(),
            },
            switching: Switching {
                active: Box::new(Idle),
            },
            autopilot,
            in_contact: false,
            started: false,
            reported_estimate: None,
            track_flow,
        }
    }

    /// The active behaviour.
    pub fn behaviour(&self) -> BehaviourKind {
        self.switching.active()
    }

    /// The source-likelihood map, when `map_declaration` is on.
    pub fn source_map(&mut self) -> Option<&mut MapTracker> {
        self.m.map.as_mut()
    }

    /// The saved lost points, oldest first.
    pub fn lost_points(&self) -> Vec<Vec2> {
        self.m.lost_positions()
    }

    /// The point awaiting its confirming Track-Out and the ends of its legs, while it flies.
    pub fn confirming(&self) -> Option<(Vec2, &[Vec2])> {
        self.m.confirm.as_ref().map(|c| (c.at, c.goals.as_slice()))
    }

    /// Declared source positions so far, in order.
    pub fn declarations(&self) -> &[Vec2] {
        &self.m.declared
    }

    /// The course the active behaviour asked for at the last decision (before the cage, flow
    /// compensation and rate filtering).
    pub fn last_course(&self) -> Heading {
        self.last_steer.heading
    }

    /// The LHS variable (+1: expected to leave the plume on its left looking upflow).
    pub fn lhs(&self) -> f64 {
        self.m.lhs
    }

    /// The parameters.
    pub fn params(&self) -> &AmpParams {
        &self.m.p
    }

    /// Where the search of subregion `k` starts: its most downflow corner (for the current flow
    /// estimate), moved 1.5 `R` towards the subregion's centre.
    pub fn search_start(&self, k: usize) -> Vec2 {
        self.m.search_start(k)
    }

    /// The Track-Out goal: `L_u` upflow and `L_c` across the flow from the most upflow lost
    /// point, on the side opposite to where the vehicle left the plume.
    pub fn track_out_goal(&self) -> Option<Vec2> {
        self.m.track_out_goal()
    }

    /// Feeds the map (if any) and, with `map_declaration` `instead` or `also`, declares its most
    /// likely cell when the map's rule holds, in a searching behaviour (not on the way to a
    /// subregion, mapping or done).
    fn map_declaration(&mut self, s: &SensorSnapshot, pos: Vec2, telemetry: &mut Vec<Telemetry>) {
        let t = s.time_s;
        let flow = self.m.flow.velocity_mps();
        let ground = s.nav.heading.unit() * s.nav.speed_mps + flow;
        let mode = self.m.p.map_declaration;
        let multi = self.m.multi_region();
        let Some(tracker) = self.m.map.as_mut() else {
            return;
        };
        tracker.feed(s, pos, ground, flow);
        let searching = matches!(
            self.switching.active(),
            BehaviourKind::Find
                | BehaviourKind::TrackIn
                | BehaviourKind::TrackOut
                | BehaviourKind::Reacquire
        );
        let Some(read) = tracker.read_due(t, telemetry) else {
            return;
        };
        let by_map = matches!(mode, MapDeclaration::Instead | MapDeclaration::Also);
        let holds = tracker.declares(t, &read);
        if !by_map || !searching || !holds {
            return;
        }
        tracker.report(t, &read, telemetry, true);
        if multi {
            // The next subregion's search starts from the prior.
            tracker.reset();
        }
        let map_point = Confirm {
            at: read.estimate_m,
            rule: crate::estimate::tracker::SOURCE_MAP,
            goals: Vec::new(),
            points: Vec::new(),
        };
        self.switching
            .declare(&mut self.m, map_point, RegionEvent::Declared, pos, t);
    }

    /// The source estimate: the last declaration, else the mean of the held points, else the
    /// most upflow lost point.
    fn source_estimate(&self) -> Option<Vec2> {
        self.m
            .declared
            .last()
            .copied()
            .or_else(|| self.m.candidate_mean())
            .or_else(|| self.m.most_upflow_lost())
    }
}

impl Planner for Amp {
    /// A point held for a later fix frame is declared as it is.
    fn run_ended(&mut self, _t_s: f64) -> Vec<PlannerEvent> {
        self.m.declare_held().into_iter().collect()
    }

    fn decide(&mut self, s: &SensorSnapshot) -> Decision {
        let t = s.time_s;
        if let Some(f) = s.flow {
            // A current meter reports: its readings alone from now on.
            self.track_flow = None;
            self.m.flow.add(f.time_s, f.velocity_mps);
        } else if let Some(v) = self.track_flow.as_mut().and_then(|e| e.add(t, &s.nav)) {
            self.m.flow.add(t, v);
        }
        if let Some(fix) = self.m.fixes.observe(t, &s.nav, self.m.flow.doubting())
            && self.m.p.fix_smoothing
        {
            self.m.smooth_lost(&fix);
            if self.m.moves_held_points() {
                self.m.place_held(&fix);
            }
        }
        let Some(pos) = s.nav.pos_m else {
            // Without a position estimate the AMP can only hold its course (the registry refuses
            // vehicles that never have one).
            let command = self
                .autopilot
                .command(
                    t,
                    None,
                    s.nav.heading,
                    self.last_steer,
                    self.m.flow.velocity_mps(),
                )
                .unwrap_or_else(|a| a.command);
            return Decision::new(command, PlanStatus::Running);
        };
        if !self.started {
            self.started = true;
            self.switching.start_region(&mut self.m, 0, t);
        }
        let transit = self.switching.active() == BehaviourKind::Transit;
        let threshold = self.m.p.autopilot.threshold_v;
        let detected = !transit && s.chem.iter().any(|c| c.reading > threshold);
        if detected && !self.in_contact {
            self.m.log(PlannerEvent::Detection { pos_m: pos });
        }
        self.in_contact = detected
            || self
                .m
                .last_detection
                .is_some_and(|(tl, _)| t - tl <= self.m.p.lambda_s)
                && self.in_contact;
        let mut telemetry = Vec::new();
        self.map_declaration(s, pos, &mut telemetry);
        let percept = Percept {
            t_s: t,
            pos_m: pos,
            heading: s.nav.heading,
            detected,
        };
        let steer = self.switching.arbitrate(&percept, &mut self.m);
        let status = if self.switching.active() == BehaviourKind::Done {
            PlanStatus::Finished
        } else {
            PlanStatus::Running
        };
        let steer = steer.unwrap_or(self.last_steer);
        self.last_steer = steer;
        let estimate = self.source_estimate();
        if estimate.is_some() && estimate != self.reported_estimate {
            self.reported_estimate = estimate;
            telemetry.extend(estimate.map(|pos_m| Telemetry::SourceEstimate { pos_m }));
        }
        let flow = self.m.flow.velocity_mps();
        let tracing = matches!(
            self.switching.active(),
            BehaviourKind::TrackIn | BehaviourKind::TrackOut | BehaviourKind::Reacquire
        );
        let altitude_m = match self.m.p.track_altitude_m {
            a if tracing && a > 0.0 => a,
            _ => self.m.p.autopilot.altitude_m,
        };
        self.autopilot
            .set_vertical(VerticalCommand::Altitude(altitude_m));
        let (command, status) = match self.autopilot.command_nav(t, &s.nav, steer, flow) {
            Ok(c) => (c, status),
            Err(abort) => {
                // A point held for a later fix frame is declared before the planner gives up.
                if let Some(e) = self.m.declare_held() {
                    self.m.log(e);
                }
                self.m.log(PlannerEvent::CageAbort {
                    distance_outside_m: abort.distance_outside_m,
                });
                (abort.command, PlanStatus::Abort)
            }
        };
        telemetry.append(&mut self.m.map_telemetry);
        Decision {
            command,
            outbox: Vec::new(),
            events: std::mem::take(&mut self.m.events),
            telemetry,
            status,
        }
    }
}
