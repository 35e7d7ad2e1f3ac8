//! Formation tracing (seed 004): two surface leaders with GPS and an underwater follower that
//! keeps station on acoustic ranges.
//!
//! **Graph and frame.** The team is the graph `V = {1, 2, 3}` with the one edge `(2, 3)`: the
//! follower is node 1 (it only classifies readings as the centre's), the right leader node 2 and
//! the left leader node 3 (left and right looking up-flow). The flow frame has its first axis
//! up-flow (`theta`, the direction the leaders head for) and its second axis to the left. The
//! biases are `b_uw = [-1, 0, 0]` and `b_cw = [0, -d/2, d/2]` (4)-(5), so a leader's dynamic bias
//! (7) is `beta = s_cw b_cw` along the left axis.
//!
//! **Leader** ([`FormationLeader`]): the sum (11) `k_w u_w + k_c u_c + k_f u_f` of
//! - the up-flow urge (9) `u_w = (u_0 + |w| / k_w)` along the up-flow axis, with `|w|` the
//!   current's speed when it is known (`current_speed_mps`, 0: unknown) and the up-flow direction
//!   the mission's prior flow direction reversed (the base current the team is given). The paper
//!   writes `u_0 = 1`; with the formation terms in metres per second that urge would keep a
//!   vehicle of MEDUSA's speed at its cap, where (12) can no longer speed one leader up to close
//!   an along-flow gap, so `u_0` is a speed (`urge_mps`, 0.25 m/s: the team's cruise) below the
//!   cap (`max_speed_mps`, 0.6 m/s);
//! - plume centring (10) `u_c = -u_max + 2 u_max / (1 + exp(-(c_l - c_r) / k_l))` along the left
//!   axis;
//! - Laplacian feedback (6) on the GPS positions exchanged by radio,
//!   `u_f = -((p_i - beta_i) - (p_j - beta_j))`;
//!
//! turned into a speed and a course (12)-(13), the speed capped at `max_speed_mps` and scaled
//! by the cosine of the angle between the course and the measured heading (zero beyond 90 deg:
//! a vehicle with a turn-rate limit would otherwise circle a bias point it overshoots). The
//! cross-flow scale evolves by (8), `ds/dt = k_cw ((c_l + c_r) - c_c)`, with `c_c` the follower's
//! reading (piggybacked on its ranging requests), and is kept in `[scale_min, scale_max]` and,
//! when the follower does not hear the scale, below the bound (16)
//! `2 sqrt(1 - (D/d)^2)` (times 0.95, a margin for the follower's range noise). The two leaders
//! integrate (8) from the same readings; each averages its scale with its partner's at every radio
//! message so that they agree. Readings older than `stale_s` are not used: without the partner
//! the leader drops the formation and centring terms; without the follower it holds its scale.
//!
//! A leader answers every ranging request addressed to it at once with its compass heading (and
//! its scale with `share_scale`), and broadcasts its position, filtered reading and scale by radio
//! every `radio_period_s`.
//!
//! **Declaration** (the paper stops at the source without a rule): each leader keeps, per team
//! member, the peak of its filtered readings and, over all members, the most up-flow point where
//! a member read at least `significant_fraction` of its own peak (and at least `min_peak`): that
//! member's along-flow position on the formation's centre line (the leaders' midpoint) at that
//! time. The follower's position is not known; the leader takes the station the follower keeps
//! (behind the midpoint by `sqrt(d^2 - D^2 - (s_cw d / 2)^2)`, or `upflow_offset_m` with a shared
//! scale). When every member's latest reading has stayed below `quiet_fraction` of its peak for
//! `quiet_s` and the midpoint is at least `past_m` up-flow of that point, the leader declares
//! there and finishes. On the steady plume of a surface outlet the concentration ends at the
//! outlet, so the most up-flow strong reading is the outlet's along-flow position (less the max
//! filter's lag); the centre line gives the cross-flow position. That is the `passed_peak` rule;
//! the default `confirmed` rule ([`declare`]) declares from the along-flow profile the team
//! sensed, confirmed over a distance.
//!
//! **Closing up** (`close_on_fade`): once both leaders' readings have faded below
//! `quiet_fraction` of the larger leader peak, the scale falls to `scale_min` at
//! `close_rate_per_s` and stays there, whatever (8) says. The plume narrows towards its outlet:
//! leaders `d/2` to the sides of it stop reading it some metres (tens at the faster currents)
//! down-flow of the outlet, and a follower whose depth wanders loses the thin surface plume as
//! far out, so the open formation's profile ends short of the outlet; closed, the leaders read
//! on to it.
//!
//! **Follower** ([`FormationFollower`]): no position estimate at all. It sends a ranging request
//! every `ranging_period_s`, alternately to each leader, with its filtered reading piggybacked,
//! and keeps the latest range to each. Speed (14) is PI on the common-mode error
//! `eps = (z_l + z_r) / 2 - d_f`, clamped to `[0, max_speed_mps]`, with anti-windup (the
//! integral stops growing while the output is clamped in the error's direction); heading (15) is
//! `psi_f + gamma(K_h delta)` with `delta = z_l - z_r`: too far from the left leader turns left.
//! `gamma(a) = gamma_max (2 / pi) atan(a)`, odd and increasing, so `sin(gamma(a)) a > 0` for
//! `gamma_max <= 180 deg`; `psi_f` is a Kalman estimate of the formation heading: a random walk of
//! `heading_process_sd_deg` per square-root second, updated by every piggybacked leader heading
//! with measurement noise `heading_measurement_sd_deg`. The set-point is `d_f = d`, or with
//! `use_scale` and a scale heard, (17) with `D^2` inside the root (as (18)):
//! `d_f = sqrt(d_x^2 + (s_cw d / 2)^2 + D^2)`. Until both ranges are known it holds its heading
//! at zero speed; when the latest range is older than `stale_s` it holds the formation heading at
//! the speed the integral has learnt (the leaders' cruise), after `coast_s` it stops (the
//! leaders may have stopped), and after `lost_s` without a reply it finishes (the leaders have
//! stopped, or the link is gone). With `range_filter` the feedback runs on ranges filtered and
//! predicted to the present ([`ranging`]), and while one leader's range is stale only the fresh
//! one's common mode (the heading held). Depth is held at `depth_m`.
//!
//! Both read chemical samples through eq. (1), `c = s_max - S` for a salinity sensor
//! (`reading = "freshness"`) or the reading itself (`"concentration"`), and a `filter_window_s`
//! sliding-window max filter.

use crate::planners::{BuildContext, PlannerParams};
use plumetrace_core::params::{Bounds, Choice, ParamError, Params};
use plumetrace_core::{
    BehaviourKind, Decision, DeclarationKind, Heading, Link, MessageBody, Outgoing, PlanStatus,
    Planner, PlannerEvent, Recipient, RuleDoc, SensorSnapshot, Telemetry, Vec2, VehicleId,
    VerticalCommand,
};
use plumetrace_guidance::{Autopilot, AutopilotParams, OpArea, Steer};
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

mod declare;
mod ranging;

/// Ranges further than this many standard deviations from their prediction are set aside.
const RANGE_GATE_SIGMAS: f64 = 4.0;

/// Time between the telemetry records of a formation member, s.
const TELEMETRY_PERIOD_S: f64 = 1.0;

/// Which side of the formation a leader flies, looking up-flow.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FormationSide {
    /// Node 3, bias `+d/2` across the flow.
    Left,
    /// Node 2, bias `-d/2`.
    Right,
}

impl Choice for FormationSide {
    const ALL: &'static [Self] = &[FormationSide::Left, FormationSide::Right];
}

/// How a chemical reading becomes a concentration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReadingModel {
    /// Eq. (1): a salinity reading `S` gives `c = s_max_ppt - S`.
    Freshness,
    /// The reading is the concentration.
    Concentration,
}

impl Choice for ReadingModel {
    const ALL: &'static [Self] = &[ReadingModel::Freshness, ReadingModel::Concentration];
}

/// The leaders' declaration rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DeclarationRule {
    /// Every reading faded for `quiet_s` and the midpoint `past_m` up-flow of the strong point.
    PassedPeak,
    /// The along-flow profile the team sensed: the plume's end confirmed over `confirm_m`.
    Confirmed,
}

impl Choice for DeclarationRule {
    const ALL: &'static [Self] = &[DeclarationRule::PassedPeak, DeclarationRule::Confirmed];
}

/// The formation's rule in events: the team moved up-flow past its strongest readings and every
/// member's reading faded; declared at the most up-flow strong reading, on the formation's centre
/// line.
pub const PASSED_PEAK: DeclarationKind = DeclarationKind::new("formation_passed_peak");

/// The confirmed rule in events: the team's along-flow profile ended, confirmed over a distance;
/// declared at the most up-flow strong reading, on the formation's centre line.
pub const CONFIRMED: DeclarationKind = DeclarationKind::new("formation_confirmed");

plumetrace_core::params! {
    /// Parameters of a formation leader (surface craft with GPS).
    pub struct FormationLeaderParams {
        /// Which side of the formation this leader flies (looking up-flow).
        side: FormationSide = FormationSide::Right, "", Bounds::Any;
        /// Base inter-vehicle distance d of the biases (4)-(5).
        d_m: f64 = 10.0, "m", Bounds::closed(1.0, 1000.0);
        /// Step size k_cw of the cross-flow scale (8).
        k_cw: f64 = 0.05, "1/(s unit)", Bounds::non_negative(100.0);
        /// Logistic response k_l of the centring (10).
        k_l: f64 = 0.02, "unit", Bounds::positive(1e6);
        /// Largest cross-flow centring velocity u_c^max (10).
        uc_max: f64 = 0.1, "m/s", Bounds::non_negative(10.0);
        /// Base up-flow urge u_0 of (9) (the paper's 1, here a speed).
        urge_mps: f64 = 0.25, "m/s", Bounds::non_negative(10.0);
        /// Weight k_f of the formation feedback in (11).
        k_f: f64 = 0.5, "1/s", Bounds::non_negative(100.0);
        /// Weight k_w of the up-flow urge in (11), and its divisor of the current's speed in (9).
        k_w: f64 = 1.0, "", Bounds::positive(100.0);
        /// Weight k_c of the centring in (11).
        k_c: f64 = 1.0, "", Bounds::non_negative(100.0);
        /// Speed of the current |w| added to the up-flow urge (9); 0 when it is not known.
        current_speed_mps: f64 = 0.0, "m/s", Bounds::non_negative(10.0);
        /// Speed cap of (12).
        max_speed_mps: f64 = 0.6, "m/s", Bounds::positive(10.0);
        /// Heading-rate limit of the commands.
        max_turn_rate_deg_s: f64 = 10.0, "deg/s", Bounds::positive(360.0);
        /// Initial cross-flow scale s_cw.
        scale_init: f64 = 1.0, "", Bounds::closed(0.01, 100.0);
        /// Smallest cross-flow scale.
        scale_min: f64 = 0.3, "", Bounds::closed(0.01, 100.0);
        /// Largest cross-flow scale (also capped by (16) unless the scale is shared).
        scale_max: f64 = 2.0, "", Bounds::closed(0.01, 100.0);
        /// Depth D of the follower, for the bound (16) and its station.
        follower_depth_m: f64 = 0.5, "m", Bounds::non_negative(1000.0);
        /// Send s_cw in the ranging replies (the follower's scale adjustment (17)/(18)); lifts the bound (16).
        share_scale: bool = false, "", Bounds::Any;
        /// Desired up-flow offset d_x of the follower behind the leaders' midpoint with a shared scale.
        upflow_offset_m: f64 = 8.66, "m", Bounds::non_negative(1000.0);
        /// How readings become concentrations: eq. (1) for salinity, or as read.
        reading: ReadingModel = ReadingModel::Freshness, "", Bounds::Any;
        /// Salinity upper bound S_max of eq. (1).
        s_max_ppt: f64 = 35.0, "ppt", Bounds::closed(0.0, 1000.0);
        /// Window of the sliding max filter.
        filter_window_s: f64 = 4.0, "s", Bounds::non_negative(600.0);
        /// Time between radio broadcasts of position, reading and scale.
        radio_period_s: f64 = 0.1, "s", Bounds::closed(0.01, 600.0);
        /// Information older than this is not used.
        stale_s: f64 = 10.0, "s", Bounds::positive(3600.0);
        /// Declare a source and finish (the rule in the module docs).
        declare: bool = true, "", Bounds::Any;
        /// Which rule declares: `confirmed` (the along-flow profile) or `passed_peak` (a lull in time).
        declaration_rule: DeclarationRule = DeclarationRule::Confirmed, "", Bounds::Any;
        /// Bin width of the along-flow profile (`confirmed`).
        bin_m: f64 = 1.0, "m", Bounds::closed(0.1, 100.0);
        /// Least along-flow span of the strong readings (`confirmed`).
        min_strong_m: f64 = 3.0, "m", Bounds::non_negative(1000.0);
        /// How far up-flow of the last trace of plume the midpoint must go (`confirmed`).
        confirm_m: f64 = 10.0, "m", Bounds::non_negative(1000.0);
        /// Declare this fraction of the strongest member's peak-to-edge distance up-flow of its edge (`confirmed`; 0: at the edge, chosen on the formation family's tuning seed with `close_on_fade`; 0.59 puts an open formation's declaration on the outlet).
        extrapolate: f64 = 0.0, "", Bounds::closed(0.0, 5.0);
        /// A reading of at least this fraction of its member's peak marks a strong point.
        significant_fraction: f64 = 0.5, "", Bounds::closed(0.0, 1.0);
        /// Readings below this fraction of their member's peak count as faded.
        quiet_fraction: f64 = 0.2, "", Bounds::closed(0.0, 1.0);
        /// How long every reading must stay faded before declaring.
        quiet_s: f64 = 10.0, "s", Bounds::non_negative(3600.0);
        /// How far up-flow of the strong point the midpoint must be before declaring.
        past_m: f64 = 2.0, "m", Bounds::non_negative(1000.0);
        /// Least peak that counts as plume (readings below it are noise).
        min_peak: f64 = 0.01, "unit", Bounds::non_negative(1e6);
        /// When every reading has faded after the plume was seen, centre at full speed towards the side that read it last.
        reacquire: bool = false, "", Bounds::Any;
        /// Compensate courses for the measured flow (crab angle).
        flow_compensation: bool = false, "", Bounds::Any;
        /// When both leaders' readings have faded below `quiet_fraction` of the larger leader peak, close the formation (the scale down to `scale_min` at `close_rate_per_s`) and keep it closed: the plume narrows towards its outlet.
        close_on_fade: bool = true, "", Bounds::Any;
        /// How fast the scale falls while the formation closes.
        close_rate_per_s: f64 = 0.05, "1/s", Bounds::positive(100.0);
        /// With close_on_fade, open a closed formation again when a leader's reading comes back to `quiet_fraction` of the larger leader peak it closed on (the fade was a gap in an intermittent plume, not the plume narrowing past the leaders); it closes again on the next fade.
        reopen_on_return: bool = false, "", Bounds::Any;
        /// How far each position fix moves the leader's own position estimate, which otherwise follows its dead reckoning (1: every fix taken whole, as the navigation estimate does; 0.05 chosen on the formation family's tuning seed, for RTK to 5 m GPS).
        fix_gain: f64 = 0.05, "", Bounds::positive(1.0);
    }
}

plumetrace_core::params! {
    /// Parameters of a formation follower (underwater, no position estimate).
    pub struct FormationFollowerParams {
        /// Vehicle index of the left leader.
        left_leader: u32 = 2, "", Bounds::whole(0, 10_000);
        /// Vehicle index of the right leader.
        right_leader: u32 = 1, "", Bounds::whole(0, 10_000);
        /// Range set-point d to each leader.
        d_m: f64 = 10.0, "m", Bounds::closed(1.0, 1000.0);
        /// Proportional speed gain K_p^s of (14).
        kp_s: f64 = 0.2, "1/s", Bounds::non_negative(100.0);
        /// Integral speed gain K_i^s of (14).
        ki_s: f64 = 0.005, "1/s^2", Bounds::non_negative(100.0);
        /// Heading gain K_p^h of (15).
        kp_h: f64 = 0.1, "1/m", Bounds::non_negative(100.0);
        /// Largest heading correction gamma_max of (15).
        gamma_max_deg: f64 = 90.0, "deg", Bounds::closed(0.0, 180.0);
        /// Speed cap.
        max_speed_mps: f64 = 1.0, "m/s", Bounds::positive(10.0);
        /// Heading-rate limit of the commands.
        max_turn_rate_deg_s: f64 = 10.0, "deg/s", Bounds::positive(360.0);
        /// Depth D held.
        depth_m: f64 = 0.5, "m", Bounds::non_negative(11_000.0);
        /// Time between ranging requests (alternately to each leader).
        ranging_period_s: f64 = 2.0, "s", Bounds::closed(0.1, 600.0);
        /// Use the leaders' s_cw in the set-point (17)/(18) when they send it.
        use_scale: bool = false, "", Bounds::Any;
        /// Desired up-flow offset d_x behind the leaders' midpoint, for (17)/(18).
        upflow_offset_m: f64 = 8.66, "m", Bounds::non_negative(1000.0);
        /// Process noise of the formation-heading Kalman filter, per square-root second.
        heading_process_sd_deg: f64 = 3.0, "deg", Bounds::positive(180.0);
        /// Measurement noise of a piggybacked leader heading.
        heading_measurement_sd_deg: f64 = 10.0, "deg", Bounds::positive(180.0);
        /// A range older than this is stale: hold the formation heading at the learnt speed.
        stale_s: f64 = 10.0, "s", Bounds::positive(3600.0);
        /// Finish after this long without a reply (longer than the deaf windows a modem may have).
        lost_s: f64 = 120.0, "s", Bounds::positive(36_000.0);
        /// Without a reply for this long, stop (drift with the current) instead of holding the formation heading at the learnt speed: the leaders may have stopped.
        coast_s: f64 = 30.0, "s", Bounds::positive(36_000.0);
        /// Keep station on filtered ranges (range and range rate, predicted to the present) rather than the latest raw ones; after an outage, the fresh range's common mode alone until both are fresh.
        range_filter: bool = false, "", Bounds::Any;
        /// Standard deviation of a range, for the filter.
        range_noise_sd_m: f64 = 1.0, "m", Bounds::positive(1000.0);
        /// Standard deviation of the range's white acceleration, for the filter.
        range_accel_sd_mps2: f64 = 0.02, "m/s^2", Bounds::positive(100.0);
        /// How readings become concentrations: eq. (1) for salinity, or as read.
        reading: ReadingModel = ReadingModel::Freshness, "", Bounds::Any;
        /// Salinity upper bound S_max of eq. (1).
        s_max_ppt: f64 = 35.0, "ppt", Bounds::closed(0.0, 1000.0);
        /// Window of the sliding max filter.
        filter_window_s: f64 = 4.0, "s", Bounds::non_negative(600.0);
    }
}

impl PlannerParams for FormationLeaderParams {
    const KIND: &'static str = "formation_leader";
    const SUMMARY: &'static str = "Formation leader (seed 004): Laplacian formation feedback on GPS positions by radio, up-flow urge, plume centring and cross-flow scaling; answers the follower's ranging requests; declares when the team has passed its strongest readings";
    const BEHAVIOURS: &'static [BehaviourKind] = &[];
    const RULES: &'static [RuleDoc] = &[
        RuleDoc {
            rule: CONFIRMED,
            doc: "the strong readings span min_strong_m along the flow, the team went confirm_m up-flow of the last reading above quiet_fraction of its member's peak, and every reading faded: the most up-flow strong reading, on the formation's centre line (with a confidence in the leader's telemetry)",
        },
        RuleDoc {
            rule: PASSED_PEAK,
            doc: "the team moved past_m up-flow of its strongest readings and every member's reading stayed below quiet_fraction of its peak for quiet_s: the most up-flow strong reading, on the formation's centre line",
        },
    ];

    fn validate(&self, prefix: &str) -> Result<(), ParamError> {
        self.check_bounds(prefix)?;
        if self.scale_min > self.scale_init || self.scale_init > self.scale_max {
            return Err(ParamError::at(
                prefix,
                "scale_init",
                format!(
                    "must lie in [scale_min, scale_max] = [{}, {}], got {}",
                    self.scale_min, self.scale_max, self.scale_init
                ),
            ));
        }
        if !self.share_scale && self.follower_depth_m >= self.d_m {
            return Err(ParamError::at(
                prefix,
                "follower_depth_m",
                format!(
                    "must be less than d_m ({}): the follower cannot reach its ranges (16)",
                    self.d_m
                ),
            ));
        }
        Ok(())
    }

    fn detection_threshold_v(&self) -> Option<f64> {
        None
    }

    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Planner>, ParamError> {
        Ok(Box::new(FormationLeader::new(
            self.clone(),
            ctx.vehicle,
            ctx.geometry.prior_flow_toward().reversed(),
            ctx.geometry.op_area.clone(),
        )))
    }
}

impl PlannerParams for FormationFollowerParams {
    const KIND: &'static str = "formation_follower";
    const SUMMARY: &'static str = "Formation follower (seed 004): no position; PI speed on the common-mode range error and heading from a Kalman estimate of the formation heading plus the differential-mode term, on ranges measured alternately to the two leaders";
    const BEHAVIOURS: &'static [BehaviourKind] = &[];
    const RULES: &'static [RuleDoc] = &[];
    const NEEDS_POSITION: bool = false;

    fn validate(&self, prefix: &str) -> Result<(), ParamError> {
        self.check_bounds(prefix)?;
        if self.left_leader == self.right_leader {
            return Err(ParamError::at(
                prefix,
                "right_leader",
                "the two leaders must be different vehicles",
            ));
        }
        Ok(())
    }

    fn detection_threshold_v(&self) -> Option<f64> {
        None
    }

    fn build(&self, ctx: &BuildContext) -> Result<Box<dyn Planner>, ParamError> {
        for (key, id) in [
            ("left_leader", self.left_leader),
            ("right_leader", self.right_leader),
        ] {
            if id == ctx.vehicle.0 {
                return Err(ParamError {
                    key: key.into(),
                    message: format!("{id} is the follower itself"),
                });
            }
            if !ctx.team.is_empty() && id as usize >= ctx.team.len() {
                let named: Vec<String> = ctx
                    .team
                    .iter()
                    .enumerate()
                    .map(|(k, n)| format!("{k} ({n})"))
                    .collect();
                return Err(ParamError {
                    key: key.into(),
                    message: format!(
                        "vehicle {id} does not exist: the scenario has {} vehicles, {}",
                        ctx.team.len(),
                        named.join(", ")
                    ),
                });
            }
        }
        Ok(Box::new(FormationFollower::new(self.clone())))
    }
}

/// A sliding-window max filter of concentrations.
#[derive(Debug, Clone, PartialEq)]
pub struct MaxFilter {
    window_s: f64,
    samples: VecDeque<(f64, f64)>,
}

impl MaxFilter {
    /// A filter over the last `window_s` seconds.
    pub fn new(window_s: f64) -> Self {
        MaxFilter {
            window_s,
            samples: VecDeque::new(),
        }
    }

    /// Adds a sample (non-finite ones are left out).
    pub fn add(&mut self, t_s: f64, c: f64) {
        if !(t_s.is_finite() && c.is_finite()) {
            return;
        }
        // Monotone queue: a sample no larger than a newer one never becomes the max again.
        while self.samples.back().is_some_and(|&(_, v)| v <= c) {
            self.samples.pop_back();
        }
        self.samples.push_back((t_s, c));
        while self
            .samples
            .front()
            .is_some_and(|&(t, _)| t < t_s - self.window_s - 1e-9)
        {
            self.samples.pop_front();
        }
    }

    /// The largest sample of the window, if any.
    pub fn value(&self) -> Option<f64> {
        self.samples.front().map(|&(_, v)| v)
    }
}

/// A reading as a concentration: eq. (1) or as read.
fn concentration(model: ReadingModel, s_max: f64, reading: f64) -> f64 {
    match model {
        ReadingModel::Freshness => s_max - reading,
        ReadingModel::Concentration => reading,
    }
}

/// Something heard about another member: a value with its time.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Heard<T> {
    value: T,
    t_s: f64,
}

impl<T: Copy> Heard<T> {
    fn fresh(h: &Option<Heard<T>>, t_s: f64, stale_s: f64) -> Option<T> {
        h.filter(|h| t_s - h.t_s <= stale_s).map(|h| h.value)
    }
}

/// What the partner leader last said.
#[derive(Debug, Clone, Copy, PartialEq)]
struct PartnerState {
    pos_m: Vec2,
    reading: f64,
    scale: f64,
}

/// The formation feedback (6) of leader `i` on the edge `(i, j)`: `-((p_i - beta_i) - (p_j - beta_j))`.
pub fn laplacian_feedback(p_i: Vec2, beta_i: Vec2, p_j: Vec2, beta_j: Vec2) -> Vec2 {
    -((p_i - beta_i) - (p_j - beta_j))
}

/// The centring velocity (10) across the flow (positive: to the left).
pub fn centring(c_left: f64, c_right: f64, uc_max: f64, k_l: f64) -> f64 {
    let x = ((c_left - c_right) / k_l).clamp(-700.0, 700.0);
    -uc_max + 2.0 * uc_max / (1.0 + (-x).exp())
}

/// The rate of the cross-flow scale (8).
pub fn scale_rate(c_left: f64, c_right: f64, c_centre: f64, k_cw: f64) -> f64 {
    k_cw * ((c_left + c_right) - c_centre)
}

/// The declaration bookkeeping of a leader.
#[derive(Debug, Clone, PartialEq)]
struct Declarer {
    /// Peak filtered reading per member: self, partner, follower.
    peaks: [f64; 3],
    /// The most up-flow strong point: (along-flow coordinate, point on the centre line).
    strong: Option<(f64, Vec2)>,
    quiet_since_s: Option<f64>,
}

/// A formation leader.
#[derive(Debug, Clone)]
pub struct FormationLeader {
    p: FormationLeaderParams,
    me: VehicleId,
    upflow: Heading,
    autopilot: Autopilot,
    filter: MaxFilter,
    scale: f64,
    partner: Option<Heard<PartnerState>>,
    follower_reading: Option<Heard<f64>>,
    last_t_s: Option<f64>,
    next_radio_s: f64,
    next_telemetry_s: f64,
    declarer: Declarer,
    profile: declare::Profile,
    /// The side that last read more, +1 left, -1 right (0: none yet).
    last_side: f64,
    declared: bool,
    position: FixSmoother,
    /// Peak readings of this leader and its partner, for the closing.
    lead_peaks: [f64; 2],
    /// The formation has closed (`close_on_fade`).
    closed: bool,
}

impl FormationLeader {
    /// A leader flying `p` on vehicle `me`, heading up-flow along `upflow`, caged in `op_area`.
    pub fn new(p: FormationLeaderParams, me: VehicleId, upflow: Heading, op_area: OpArea) -> Self {
        FormationLeader {
            autopilot: Autopilot::new(AutopilotParams {
                op_area,
                flow_compensation: p.flow_compensation,
                max_turn_rate_deg_s: p.max_turn_rate_deg_s,
                vertical: VerticalCommand::Surface,
                nav_drift_mps: 0.0,
                max_inset_m: 0.0,
            }),
            filter: MaxFilter::new(p.filter_window_s),
            scale: p.scale_init,
            me,
            upflow,
            partner: None,
            follower_reading: None,
            last_t_s: None,
            next_radio_s: 0.0,
            next_telemetry_s: 0.0,
            declarer: Declarer {
                peaks: [0.0; 3],
                strong: None,
                quiet_since_s: None,
            },
            profile: declare::Profile::default(),
            last_side: 0.0,
            declared: false,
            position: FixSmoother::new(p.fix_gain),
            lead_peaks: [0.0; 2],
            closed: false,
            p,
        }
    }

    /// The current cross-flow scale.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The largest scale allowed: `scale_max`, and (16) when the follower does not hear it.
    fn scale_cap(&self) -> f64 {
        if self.p.share_scale {
            self.p.scale_max
        } else {
            let r = self.p.follower_depth_m / self.p.d_m;
            self.p
                .scale_max
                .min(0.95 * 2.0 * (1.0 - r * r).max(0.0).sqrt())
        }
    }

    /// Closes the formation once both leaders' readings (`own`, `partner`) have faded below
    /// `quiet_fraction` of the larger of their peaks (at least `min_peak`): one leader may never
    /// have been over the plume. It stays closed, unless `reopen_on_return` and a reading comes
    /// back to that fraction of the peaks it closed on.
    fn update_closing(&mut self, own: f64, partner: Option<f64>) {
        let Some(q) = partner.filter(|q| q.is_finite()) else {
            return;
        };
        if !self.p.close_on_fade || !own.is_finite() {
            return;
        }
        if self.closed {
            // The peaks it closed on, unchanged while it is closed.
            let peak = self.lead_peaks[0].max(self.lead_peaks[1]);
            self.closed = !(self.p.reopen_on_return && own.max(q) >= self.p.quiet_fraction * peak);
            return;
        }
        self.lead_peaks[0] = self.lead_peaks[0].max(own);
        self.lead_peaks[1] = self.lead_peaks[1].max(q);
        let peak = self.lead_peaks[0].max(self.lead_peaks[1]);
        self.closed = peak >= self.p.min_peak && own.max(q) < self.p.quiet_fraction * peak;
    }

    /// Unit vector to the left of the up-flow direction.
    fn left(&self) -> Vec2 {
        self.upflow.turned_deg(-90.0).unit()
    }

    /// This leader's sign across the flow: left +1, right -1.
    fn sign(&self) -> f64 {
        match self.p.side {
            FormationSide::Left => 1.0,
            FormationSide::Right => -1.0,
        }
    }

    /// The dynamic bias (7) of a leader of `sign` at scale `s`.
    fn bias(&self, sign: f64, s: f64) -> Vec2 {
        self.left() * (sign * s * 0.5 * self.p.d_m)
    }

    /// Where the follower keeps station behind the midpoint `mid`.
    fn follower_station(&self, mid: Vec2) -> Vec2 {
        let half = 0.5 * self.scale * self.p.d_m;
        let behind = if self.p.share_scale {
            self.p.upflow_offset_m
        } else {
            (self.p.d_m.powi(2) - self.p.follower_depth_m.powi(2) - half * half)
                .max(0.0)
                .sqrt()
        };
        mid - self.upflow.unit() * behind
    }

    fn read_inbox(&mut self, s: &SensorSnapshot, outbox: &mut Vec<Outgoing>) {
        for m in &s.inbox {
            match m.body {
                MessageBody::FormationState {
                    pos_m,
                    reading,
                    scale_cw,
                } if m.from != self.me
                    && pos_m.x.is_finite()
                    && pos_m.y.is_finite()
                    && reading.is_finite()
                    && scale_cw.is_finite() =>
                {
                    self.partner = Some(Heard {
                        value: PartnerState {
                            pos_m,
                            reading,
                            scale: scale_cw,
                        },
                        t_s: m.sent_s,
                    });
                    // The two leaders agree on the scale.
                    self.scale = (0.5 * (self.scale + scale_cw))
                        .clamp(self.p.scale_min, self.scale_cap().max(self.p.scale_min));
                }
                MessageBody::RangeRequest { target, reading } => {
                    if reading.is_finite() {
                        self.follower_reading = Some(Heard {
                            value: reading,
                            t_s: m.sent_s,
                        });
                    }
                    if target == self.me {
                        outbox.push(Outgoing {
                            to: Recipient::Vehicle(m.from),
                            link: Link::Acoustic,
                            body: MessageBody::RangeEcho {
                                heading: s.nav.heading,
                                scale_cw: self.p.share_scale.then_some(self.scale),
                            },
                        });
                    }
                }
                _ => {}
            }
        }
    }

    /// Updates the declaration bookkeeping; the declared point, its rule and its confidence (the
    /// confirmed rule's) when the rule fires.
    fn check_declaration(
        &mut self,
        t: f64,
        me_pos: Vec2,
        own: Option<f64>,
        partner: Option<PartnerState>,
        follower: Option<f64>,
    ) -> Option<(Vec2, DeclarationKind, Option<f64>)> {
        let up = self.upflow.unit();
        let mid = partner.map_or(me_pos - self.bias(self.sign(), self.scale), |q| {
            0.5 * (me_pos + q.pos_m)
        });
        let members = [
            own.map(|c| (c, me_pos)),
            partner.map(|q| (q.reading, q.pos_m)),
            follower.map(|c| (c, self.follower_station(mid))),
        ];
        if self.p.declaration_rule == DeclarationRule::Confirmed {
            let rule = declare::Rule {
                bin_m: self.p.bin_m,
                significant_fraction: self.p.significant_fraction,
                quiet_fraction: self.p.quiet_fraction,
                min_peak: self.p.min_peak,
                min_strong_m: self.p.min_strong_m,
                confirm_m: self.p.confirm_m,
                extrapolate: self.p.extrapolate,
            };
            let along = members.map(|m| m.map(|(c, p)| (c, p.dot(&up))));
            let d = self.profile.update(&rule, along, mid.dot(&up))?;
            let at = declare::on_centre_line(mid, up, d.along_m);
            return Some((at, CONFIRMED, Some(d.confidence)));
        }
        let d = &mut self.declarer;
        let mut faded = true;
        for (k, m) in members.iter().enumerate() {
            let Some((c, pos)) = *m else { continue };
            d.peaks[k] = d.peaks[k].max(c);
            if c >= self.p.min_peak && c >= self.p.significant_fraction * d.peaks[k] {
                let along = pos.dot(&up);
                if d.strong.is_none_or(|(a, _)| along > a) {
                    d.strong = Some((along, mid + up * (along - mid.dot(&up))));
                }
            }
            if declare::reads_on(c, d.peaks[k], self.p.min_peak, self.p.quiet_fraction) {
                faded = false;
            }
        }
        if !faded || d.strong.is_none() {
            d.quiet_since_s = None;
            return None;
        }
        let since = *d.quiet_since_s.get_or_insert(t);
        let (along, point) = d.strong?;
        (t - since >= self.p.quiet_s && mid.dot(&up) - along >= self.p.past_m).then_some((
            point,
            PASSED_PEAK,
            None,
        ))
    }
}

impl Planner for FormationLeader {
    fn decide(&mut self, s: &SensorSnapshot) -> Decision {
        let t = s.time_s;
        let dt = self.last_t_s.map_or(0.0, |l| (t - l).clamp(0.0, 60.0));
        self.last_t_s = Some(t);
        for c in &s.chem {
            let c_now = concentration(self.p.reading, self.p.s_max_ppt, c.reading);
            self.filter.add(c.time_s, c_now);
        }
        let mut outbox = Vec::new();
        self.read_inbox(s, &mut outbox);
        let own = self.filter.value();
        let Some(nav_pos) = s.nav.pos_m.filter(|p| p.x.is_finite() && p.y.is_finite()) else {
            let mut d = Decision::new(self.autopilot.hold(s.nav.heading), PlanStatus::Running);
            d.outbox = outbox;
            return d;
        };
        let me_pos = self.position.update(t, nav_pos, s.nav.last_fix_s);
        let partner = Heard::fresh(&self.partner, t, self.p.stale_s);
        let follower = Heard::fresh(&self.follower_reading, t, self.p.stale_s);
        let c_own = own.unwrap_or(0.0);
        let (c_left, c_right) = match (self.p.side, partner) {
            (FormationSide::Left, Some(q)) => (c_own, q.reading),
            (FormationSide::Right, Some(q)) => (q.reading, c_own),
            (_, None) => (c_own, c_own),
        };
        self.update_closing(c_own, partner.map(|q| q.reading));
        // (8), kept in its bounds; held without the partner or the follower; closed on a fade.
        if self.closed {
            self.scale = (self.scale - self.p.close_rate_per_s * dt).max(self.p.scale_min);
        } else if let (Some(_), Some(c_c)) = (partner, follower) {
            let rate = scale_rate(c_left, c_right, c_c, self.p.k_cw);
            if rate.is_finite() {
                self.scale = (self.scale + rate * dt)
                    .clamp(self.p.scale_min, self.scale_cap().max(self.p.scale_min));
            }
        }
        let up = self.upflow.unit();
        let left = self.left();
        let u_w = up * (self.p.urge_mps + self.p.current_speed_mps / self.p.k_w);
        if (c_left - c_right).abs() >= self.p.min_peak {
            self.last_side = (c_left - c_right).signum();
        }
        let faded = c_left.max(c_right).max(follower.unwrap_or(0.0)) < self.p.min_peak;
        let centre = if self.p.reacquire && faded && self.last_side != 0.0 {
            self.p.uc_max * self.last_side
        } else {
            centring(c_left, c_right, self.p.uc_max, self.p.k_l)
        };
        let (u_c, u_f) = match partner {
            Some(q) => (
                left * centre,
                laplacian_feedback(
                    me_pos,
                    self.bias(self.sign(), self.scale),
                    q.pos_m,
                    self.bias(-self.sign(), self.scale),
                ),
            ),
            None => (Vec2::zeros(), Vec2::zeros()),
        };
        let u = u_w * self.p.k_w + u_c * self.p.k_c + u_f * self.p.k_f;
        let course = Heading::of_vector(u).unwrap_or(self.upflow);
        // (12), slowed while the vehicle turns towards the course (a vehicle that cannot turn on
        // the spot would otherwise circle around a nearby bias point).
        let facing = course.diff_deg(s.nav.heading).to_radians().cos().max(0.0);
        let speed = u.norm().min(self.p.max_speed_mps) * facing;
        if t + 1e-9 >= self.next_radio_s {
            self.next_radio_s = t + self.p.radio_period_s;
            outbox.push(Outgoing {
                to: Recipient::Broadcast,
                link: Link::Radio,
                body: MessageBody::FormationState {
                    pos_m: me_pos,
                    reading: c_own,
                    scale_cw: self.scale,
                },
            });
        }
        let mut events = Vec::new();
        let mut status = PlanStatus::Running;
        let mut telemetry = if t + 1e-9 >= self.next_telemetry_s {
            self.next_telemetry_s = t + TELEMETRY_PERIOD_S;
            vec![Telemetry::Formation {
                scale_cw: Some(self.scale),
                ranges_m: None,
                ranges_to: None,
                setpoint_m: None,
                reading: c_own,
                declaration_confidence: None,
            }]
        } else {
            Vec::new()
        };
        if self.p.declare
            && !self.declared
            && let Some((pos_m, rule, confidence)) =
                self.check_declaration(t, me_pos, own, partner, follower)
        {
            self.declared = true;
            events.push(PlannerEvent::Declared { pos_m, rule });
            if confidence.is_some() {
                telemetry.push(Telemetry::Formation {
                    scale_cw: Some(self.scale),
                    ranges_m: None,
                    ranges_to: None,
                    setpoint_m: None,
                    reading: c_own,
                    declaration_confidence: confidence,
                });
            }
            status = PlanStatus::Finished;
        }
        let flow = s.flow.map_or(Vec2::zeros(), |f| f.velocity_mps);
        let steer = Steer {
            heading: course,
            speed_mps: if speed.is_finite() { speed } else { 0.0 },
        };
        let command = match self
            .autopilot
            .command(t, Some(me_pos), s.nav.heading, steer, flow)
        {
            Ok(c) => c,
            Err(abort) => abort.command,
        };
        Decision {
            command,
            outbox,
            events,
            telemetry,
            status,
        }
    }
}

/// A vehicle's own position with its fixes smoothed: between fixes the estimate moves as the
/// navigation estimate does (dead reckoning); at a fix, when the navigation estimate jumps to the
/// fix, it moves `gain` of the way from its prediction to the fix. With `gain` 1 it is the
/// navigation estimate itself. A fix of error sigma then leaves an error of about
/// sigma sqrt(gain / (2 - gain)) (for fixes far more frequent than the dead reckoning drifts).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixSmoother {
    gain: f64,
    est: Option<Vec2>,
    last_nav: Vec2,
    last_fix_s: Option<f64>,
    last_t_s: f64,
    // The dead reckoning's velocity over the last step without a fix.
    velocity: Vec2,
}

impl FixSmoother {
    /// A smoother taking `gain` (0, 1] of each fix.
    pub fn new(gain: f64) -> Self {
        FixSmoother {
            gain,
            est: None,
            last_nav: Vec2::zeros(),
            last_fix_s: None,
            last_t_s: 0.0,
            velocity: Vec2::zeros(),
        }
    }

    /// The estimate at `t_s`, given the navigation estimate `nav` and the time of its last fix.
    pub fn update(&mut self, t_s: f64, nav: Vec2, last_fix_s: Option<f64>) -> Vec2 {
        let dt = (t_s - self.last_t_s).max(0.0);
        let est = match self.est {
            None => nav,
            Some(_) if self.gain >= 1.0 => nav,
            Some(e) if last_fix_s != self.last_fix_s => {
                let predicted = e + self.velocity * dt;
                predicted + (nav - predicted) * self.gain
            }
            Some(e) => {
                if dt > 0.0 {
                    self.velocity = (nav - self.last_nav) / dt;
                }
                e + (nav - self.last_nav)
            }
        };
        self.est = Some(est);
        self.last_nav = nav;
        self.last_fix_s = last_fix_s;
        self.last_t_s = t_s;
        est
    }
}

/// A scalar Kalman filter of a heading (random walk), on the circle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadingKalman {
    estimate: Option<Heading>,
    var_deg2: f64,
    q_deg2_per_s: f64,
    r_deg2: f64,
    last_t_s: f64,
}

impl HeadingKalman {
    /// A filter with process noise `process_sd_deg` per square-root second and measurement noise
    /// `measurement_sd_deg`.
    pub fn new(process_sd_deg: f64, measurement_sd_deg: f64) -> Self {
        HeadingKalman {
            estimate: None,
            var_deg2: 0.0,
            q_deg2_per_s: process_sd_deg * process_sd_deg,
            r_deg2: measurement_sd_deg * measurement_sd_deg,
            last_t_s: 0.0,
        }
    }

    /// Updates with a heading measured at `t_s` (the first one initialises the filter).
    pub fn update(&mut self, t_s: f64, z: Heading) {
        match self.estimate {
            None => {
                self.estimate = Some(z);
                self.var_deg2 = self.r_deg2;
            }
            Some(x) => {
                let p = self.var_deg2 + self.q_deg2_per_s * (t_s - self.last_t_s).max(0.0);
                let k = p / (p + self.r_deg2);
                self.estimate = Some(x.turned_deg(k * z.diff_deg(x)));
                self.var_deg2 = (1.0 - k) * p;
            }
        }
        self.last_t_s = t_s;
    }

    /// The estimate, if any measurement came.
    pub fn estimate(&self) -> Option<Heading> {
        self.estimate
    }
}

/// A formation follower.
#[derive(Debug, Clone)]
pub struct FormationFollower {
    p: FormationFollowerParams,
    filter: MaxFilter,
    heading: HeadingKalman,
    /// Latest range to the left and right leader.
    ranges: [Option<Heard<f64>>; 2],
    /// The filtered range to the left and right leader.
    tracks: [ranging::RangeTrack; 2],
    scale: Option<f64>,
    integral: f64,
    last_t_s: Option<f64>,
    next_request_s: f64,
    ask_left: bool,
    last_reply_s: f64,
    next_telemetry_s: f64,
    rate: plumetrace_guidance::RateFilter,
}

impl FormationFollower {
    /// A follower flying `p`.
    pub fn new(p: FormationFollowerParams) -> Self {
        FormationFollower {
            filter: MaxFilter::new(p.filter_window_s),
            heading: HeadingKalman::new(p.heading_process_sd_deg, p.heading_measurement_sd_deg),
            ranges: [None, None],
            tracks: [ranging::RangeTrack::default(); 2],
            scale: None,
            integral: 0.0,
            last_t_s: None,
            next_request_s: 0.0,
            ask_left: true,
            last_reply_s: 0.0,
            next_telemetry_s: 0.0,
            rate: plumetrace_guidance::RateFilter::new(p.max_turn_rate_deg_s),
            p,
        }
    }

    /// The range set-point: `d`, or (17)/(18) with the leaders' scale.
    pub fn setpoint_m(&self) -> f64 {
        match (self.p.use_scale, self.scale) {
            (true, Some(s)) => (self.p.upflow_offset_m.powi(2)
                + (0.5 * s * self.p.d_m).powi(2)
                + self.p.depth_m.powi(2))
            .sqrt(),
            _ => self.p.d_m,
        }
    }

    fn read_inbox(&mut self, s: &SensorSnapshot) {
        for m in &s.inbox {
            if let MessageBody::RangeReply {
                range_m,
                sender_heading,
                scale_cw,
            } = m.body
            {
                let side = if m.from.0 == self.p.left_leader {
                    0
                } else if m.from.0 == self.p.right_leader {
                    1
                } else {
                    continue;
                };
                if !(range_m.is_finite() && range_m >= 0.0 && sender_heading.rad().is_finite()) {
                    continue;
                }
                self.ranges[side] = Some(Heard {
                    value: range_m,
                    t_s: s.time_s,
                });
                let n = self.range_noise();
                self.tracks[side].update(&n, s.time_s, range_m);
                self.last_reply_s = s.time_s;
                self.heading.update(s.time_s, sender_heading);
                if let Some(sc) = scale_cw.filter(|v| v.is_finite() && *v > 0.0) {
                    self.scale = Some(sc);
                }
            }
        }
    }
}

impl FormationFollower {
    /// The range filter's settings.
    fn range_noise(&self) -> ranging::RangeNoise {
        ranging::RangeNoise {
            measurement_sd_m: self.p.range_noise_sd_m,
            accel_sd_mps2: self.p.range_accel_sd_mps2,
            gate_sigmas: RANGE_GATE_SIGMAS,
        }
    }

    /// (14)-(15) on the ranges `l` and `r` to the left and right leader: heading and speed.
    fn feedback(&mut self, l: f64, r: f64, d_f: f64, psi_f: Heading, dt: f64) -> (Heading, f64) {
        let eps = 0.5 * (l + r) - d_f;
        let delta = l - r;
        let raw = self.p.kp_s * eps + self.p.ki_s * self.integral;
        // Anti-windup: no integration while clamped in the error's direction.
        let clamped_high = raw >= self.p.max_speed_mps && eps > 0.0;
        let clamped_low = raw <= 0.0 && eps < 0.0;
        if !(clamped_high || clamped_low) {
            self.integral += eps * dt;
        }
        let v = (self.p.kp_s * eps + self.p.ki_s * self.integral).clamp(0.0, self.p.max_speed_mps);
        let gamma =
            self.p.gamma_max_deg * std::f64::consts::FRAC_2_PI * (self.p.kp_h * delta).atan();
        // Too far from the left leader (delta > 0): turn left (anticlockwise).
        (psi_f.turned_deg(-gamma), v)
    }

    /// Heading and speed from the ranges at `t`: the feedback while ranges are fresh (with the
    /// filter, both predicted to `t`, and only the fresh one's common mode while the other is
    /// stale), the formation heading at the learnt speed while all are stale, and the present
    /// heading at rest before both leaders have answered.
    fn station_keeping(
        &mut self,
        t: f64,
        dt: f64,
        d_f: f64,
        psi_f: Heading,
        now: Heading,
    ) -> (Heading, f64) {
        let cruise = if t - self.last_reply_s > self.p.coast_s {
            0.0
        } else {
            (self.p.ki_s * self.integral).clamp(0.0, self.p.max_speed_mps)
        };
        if self.p.range_filter {
            let n = self.range_noise();
            let est = |k: usize| {
                let tr = &self.tracks[k];
                tr.range_at(&n, t)
                    .map(|z| (z, t - tr.last_s() <= self.p.stale_s))
            };
            return match (est(0), est(1)) {
                (Some((l, true)), Some((r, true))) => self.feedback(l, r, d_f, psi_f, dt),
                (Some((z, true)), Some(_)) | (Some(_), Some((z, true))) => {
                    self.feedback(z, z, d_f, psi_f, dt)
                }
                (Some(_), Some(_)) => (psi_f, cruise),
                _ => (now, 0.0),
            };
        }
        let fresh = |h: &Option<Heard<f64>>| h.filter(|h| t - h.t_s <= self.p.stale_s);
        match (self.ranges[0], self.ranges[1]) {
            (Some(l), Some(r)) if fresh(&Some(l)).is_some() || fresh(&Some(r)).is_some() => {
                self.feedback(l.value, r.value, d_f, psi_f, dt)
            }
            (Some(_), Some(_)) => (psi_f, cruise),
            _ => (now, 0.0),
        }
    }
}

impl Planner for FormationFollower {
    fn decide(&mut self, s: &SensorSnapshot) -> Decision {
        let t = s.time_s;
        let first = self.last_t_s.is_none();
        let dt = self.last_t_s.map_or(0.0, |l| (t - l).clamp(0.0, 60.0));
        self.last_t_s = Some(t);
        if first {
            self.rate.reset(s.nav.heading);
            self.last_reply_s = t;
        }
        for c in &s.chem {
            let c_now = concentration(self.p.reading, self.p.s_max_ppt, c.reading);
            self.filter.add(c.time_s, c_now);
        }
        self.read_inbox(s);
        let reading = self.filter.value().unwrap_or(0.0);
        let mut outbox = Vec::new();
        if t + 1e-9 >= self.next_request_s {
            self.next_request_s = t + self.p.ranging_period_s;
            let target = if self.ask_left {
                self.p.left_leader
            } else {
                self.p.right_leader
            };
            self.ask_left = !self.ask_left;
            outbox.push(Outgoing {
                to: Recipient::Broadcast,
                link: Link::Acoustic,
                body: MessageBody::RangeRequest {
                    target: VehicleId(target),
                    reading,
                },
            });
        }
        let d_f = self.setpoint_m();
        let psi_f = self.heading.estimate().unwrap_or(s.nav.heading);
        let (heading, speed) = self.station_keeping(t, dt, d_f, psi_f, s.nav.heading);
        let heading = self.rate.filter(heading, dt);
        let speed = if speed.is_finite() { speed } else { 0.0 };
        let status = if t - self.last_reply_s > self.p.lost_s {
            PlanStatus::Finished
        } else {
            PlanStatus::Running
        };
        let report = t + 1e-9 >= self.next_telemetry_s;
        if report {
            self.next_telemetry_s = t + TELEMETRY_PERIOD_S;
        }
        let ranges_m = match self.ranges {
            [Some(l), Some(r)] => Some([l.value, r.value]),
            _ => None,
        };
        Decision {
            command: plumetrace_core::Command {
                heading,
                speed_mps: if status == PlanStatus::Finished {
                    0.0
                } else {
                    speed
                },
                vertical: VerticalCommand::Depth(self.p.depth_m),
            },
            outbox,
            events: Vec::new(),
            telemetry: if report {
                vec![Telemetry::Formation {
                    scale_cw: self.scale,
                    ranges_m,
                    ranges_to: Some([
                        VehicleId(self.p.left_leader),
                        VehicleId(self.p.right_leader),
                    ]),
                    setpoint_m: Some(d_f),
                    reading,
                    declaration_confidence: None,
                }]
            } else {
                Vec::new()
            },
            status,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plumetrace_core::{ChemSample, Message, NavEstimate};

    /// A square op-area far larger than any test run.
    fn area() -> OpArea {
        OpArea::new(vec![
            Vec2::new(-1e4, -1e4),
            Vec2::new(1e4, -1e4),
            Vec2::new(1e4, 1e4),
            Vec2::new(-1e4, 1e4),
        ])
        .unwrap_or_else(|e| panic!("{e}"))
    }

    fn snapshot(
        t: f64,
        id: u32,
        pos: Option<Vec2>,
        heading: Heading,
        chem: Vec<ChemSample>,
        inbox: Vec<Message>,
    ) -> SensorSnapshot {
        SensorSnapshot {
            time_s: t,
            vehicle: VehicleId(id),
            nav: NavEstimate {
                pos_m: pos,
                heading,
                speed_mps: 0.0,
                altitude_m: None,
                depth_m: None,
                last_fix_s: None,
            },
            chem,
            flow: None,
            ranges: None,
            inbox,
        }
    }

    /// A deterministic uniform stream for test noise (onboard crates use no random crate).
    struct Lcg(u64);

    impl Lcg {
        fn uniform(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((self.0 >> 11) as f64) / ((1u64 << 53) as f64)
        }

        /// A standard normal draw (Box-Muller).
        fn normal(&mut self) -> f64 {
            let u = self.uniform().max(1e-12);
            let v = self.uniform();
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        }
    }

    /// A kinematic body: turns at most `rate` deg/s towards its commanded heading.
    #[derive(Clone, Copy)]
    struct Body {
        pos: Vec2,
        heading: Heading,
        speed: f64,
        cmd_heading: Heading,
        cmd_speed: f64,
    }

    impl Body {
        fn new(pos: Vec2, heading_deg: f64) -> Self {
            let h = Heading::from_deg(heading_deg);
            Body {
                pos,
                heading: h,
                speed: 0.0,
                cmd_heading: h,
                cmd_speed: 0.0,
            }
        }

        fn step(&mut self, dt: f64, rate: f64) {
            let e = self.cmd_heading.diff_deg(self.heading);
            self.heading = self.heading.turned_deg(e.clamp(-rate * dt, rate * dt));
            self.speed = self.cmd_speed;
            self.pos += self.heading.unit() * (self.speed * dt);
        }
    }

    /// The partner leader's radio state at `t`, 10 m to the north: its filtered `reading` and
    /// scale.
    fn partner_state(t: f64, reading: f64, scale_cw: f64) -> Message {
        Message {
            from: VehicleId(1),
            to: Recipient::Broadcast,
            link: Link::Radio,
            sent_s: t,
            body: MessageBody::FormationState {
                pos_m: Vec2::new(0.0, 10.0),
                reading,
                scale_cw,
            },
        }
    }

    fn leader(side: FormationSide, id: u32) -> FormationLeader {
        FormationLeader::new(
            FormationLeaderParams {
                side,
                declare: false,
                ..FormationLeaderParams::default()
            },
            VehicleId(id),
            Heading::from_deg(270.0),
            area(),
        )
    }

    #[test]
    fn inconsistent_keys_are_refused_with_their_names() {
        let f = FormationFollowerParams {
            left_leader: 1,
            right_leader: 1,
            ..FormationFollowerParams::default()
        };
        let e = f.validate("planners.f").err().map(|e| e.key);
        assert_eq!(e.as_deref(), Some("planners.f.right_leader"));
        let l = FormationLeaderParams {
            scale_init: 3.0,
            ..FormationLeaderParams::default()
        };
        let e = l.validate("planners.l").err().map(|e| e.key);
        assert_eq!(e.as_deref(), Some("planners.l.scale_init"));
        let deep = FormationLeaderParams {
            follower_depth_m: 12.0,
            ..FormationLeaderParams::default()
        };
        assert!(deep.validate("p").is_err(), "(16) has no solution");
    }

    #[test]
    fn the_fix_smoother_follows_the_dead_reckoning_and_averages_the_fixes() {
        let mut rng = Lcg(11);
        let sigma = 2.0;
        let (mut raw, mut smooth) = (Vec::new(), Vec::new());
        let mut whole = FixSmoother::new(1.0);
        let mut small = FixSmoother::new(0.05);
        let mut fix = Vec2::zeros();
        let mut last_fix_s = None;
        // 0.5 m/s east, a step of 0.1 s, a fix of 2 m error every second; the dead reckoning is
        // exact between fixes.
        for k in 0..6000 {
            let t = k as f64 * 0.1;
            let truth = Vec2::new(0.5 * t, 0.0);
            if k % 10 == 0 {
                fix = Vec2::new(rng.normal(), rng.normal()) * sigma;
                last_fix_s = Some(t);
            }
            let nav = truth + fix;
            assert_eq!(
                whole.update(t, nav, last_fix_s),
                nav,
                "gain 1 is the estimate"
            );
            let e = small.update(t, nav, last_fix_s);
            if t > 100.0 {
                raw.push((nav - truth).norm_squared());
                smooth.push((e - truth).norm_squared());
            }
        }
        let rms = |v: &[f64]| (v.iter().sum::<f64>() / v.len() as f64).sqrt();
        let (r, s) = (rms(&raw), rms(&smooth));
        // Per axis sigma sqrt(g / (2 - g)) = 0.32 m for g = 0.05: about 0.45 m over both axes.
        assert!((2.4..3.3).contains(&r), "raw {r}");
        assert!(s < 0.7 && s > 0.2, "smoothed {s} (raw {r})");
    }

    #[test]
    fn the_max_filter_keeps_the_largest_reading_of_its_window() {
        let mut f = MaxFilter::new(4.0);
        for (t, c) in [(0.0, 1.0), (1.0, 3.0), (2.0, 2.0), (5.0, 0.5)] {
            f.add(t, c);
        }
        assert_eq!(f.value(), Some(3.0), "3.0 at t = 1 is inside [1, 5]");
        f.add(5.5, 0.1);
        assert_eq!(f.value(), Some(2.0), "3.0 left the window");
        f.add(6.0, f64::NAN);
        assert_eq!(f.value(), Some(2.0));
        f.add(10.0, 0.2);
        assert_eq!(f.value(), Some(0.2));
        assert_eq!(
            concentration(ReadingModel::Freshness, 35.0, 34.9),
            35.0 - 34.9
        );
    }

    #[test]
    fn laplacian_feedback_drives_a_perturbed_pair_back_to_its_biases() {
        // Up-flow is West (270): the left of the formation is South. The right leader (node 2)
        // starts 14 m too far North and 6 m ahead; the pair must end d = 10 m apart North-South.
        let mut l = [
            leader(FormationSide::Right, 0),
            leader(FormationSide::Left, 1),
        ];
        let mut b = [
            Body::new(Vec2::new(100.0, 19.0), 270.0),
            Body::new(Vec2::new(106.0, 0.0), 270.0),
        ];
        let dt = 0.1;
        let mut radio: Vec<Message> = Vec::new();
        for k in 0..3000 {
            let t = f64::from(k) * dt;
            let mut next = Vec::new();
            for i in 0..2 {
                let inbox: Vec<Message> = radio
                    .iter()
                    .filter(|m| m.from.0 != i as u32)
                    .cloned()
                    .collect();
                let d = l[i].decide(&snapshot(
                    t,
                    i as u32,
                    Some(b[i].pos),
                    b[i].heading,
                    vec![],
                    inbox,
                ));
                assert!(d.command.is_finite());
                b[i].cmd_heading = d.command.heading;
                b[i].cmd_speed = d.command.speed_mps;
                next.extend(d.outbox.into_iter().map(|o| Message {
                    from: VehicleId(i as u32),
                    to: o.to,
                    link: o.link,
                    sent_s: t,
                    body: o.body,
                }));
            }
            radio = next;
            for body in &mut b {
                body.step(dt, 10.0);
            }
        }
        let sep = b[0].pos - b[1].pos;
        // Right minus left: +d along North (the right of West is North), nothing along the flow.
        assert!((sep.y - 10.0).abs() < 0.5, "{sep:?}");
        assert!(sep.x.abs() < 0.5, "{sep:?}");
        assert!(
            b[0].pos.x < 100.0 - 50.0,
            "the pair went up-flow: {:?}",
            b[0].pos
        );
        // And the feedback itself is zero exactly at the biases.
        let beta = Vec2::new(0.0, 5.0);
        assert_eq!(
            laplacian_feedback(Vec2::new(3.0, 5.0), beta, Vec2::new(3.0, -5.0), -beta),
            Vec2::zeros()
        );
    }

    #[test]
    fn the_scale_grows_when_the_sides_read_more_than_the_centre() {
        assert!(scale_rate(0.3, 0.3, 0.2, 0.05) > 0.0);
        assert!(scale_rate(0.05, 0.05, 0.3, 0.05) < 0.0);
        assert!(
            centring(0.3, 0.1, 0.5, 0.02) > 0.49,
            "left reads more: go left"
        );
        assert!(centring(0.1, 0.3, 0.5, 0.02) < -0.49);
        assert_eq!(centring(0.2, 0.2, 0.5, 0.02), 0.0);
        // A leader whose own side and partner read 0.3 and whose follower reads 0.2 widens.
        let mut l = leader(FormationSide::Left, 0);
        let s0 = l.scale();
        for k in 0..100 {
            let t = f64::from(k) * 0.1;
            let inbox = vec![
                partner_state(t, 0.3, l.scale()),
                Message {
                    from: VehicleId(2),
                    to: Recipient::Broadcast,
                    link: Link::Acoustic,
                    sent_s: t,
                    body: MessageBody::RangeRequest {
                        target: VehicleId(1),
                        reading: 0.2,
                    },
                },
            ];
            let chem = vec![ChemSample {
                time_s: t,
                reading: 35.0 - 0.3,
            }];
            let d = l.decide(&snapshot(
                t,
                0,
                Some(Vec2::zeros()),
                Heading::from_deg(270.0),
                chem,
                inbox,
            ));
            assert!(
                d.outbox
                    .iter()
                    .all(|o| !matches!(o.body, MessageBody::RangeEcho { .. })),
                "not addressed"
            );
        }
        // 9.9 s at 0.05 (0.6 - 0.2) = 0.198 per second.
        let grown = l.scale() - s0;
        assert!((grown - 0.198).abs() < 0.03, "{grown}");
        assert!(l.scale() <= l.scale_cap() + 1e-12);
    }

    /// Leaders flying straight West at 0.3 m/s, 10 m apart across the flow, and the follower
    /// starting `offset` from its station; ranges every `period` (the follower's requests) with
    /// `delay` s of travel and `noise_m` of noise. Returns the range errors after `settle_s`.
    fn follow(start_offset: Vec2, delay_s: f64, noise_m: f64, settle_s: f64) -> Vec<f64> {
        let p = FormationFollowerParams {
            left_leader: 2,
            right_leader: 1,
            ..FormationFollowerParams::default()
        };
        follow_with(p, start_offset, delay_s, noise_m, settle_s, None)
    }

    /// `follow` with the follower's parameters and a deaf window `[from, to)` in which no reply
    /// reaches it.
    fn follow_with(
        p: FormationFollowerParams,
        start_offset: Vec2,
        delay_s: f64,
        noise_m: f64,
        settle_s: f64,
        deaf: Option<(f64, f64)>,
    ) -> Vec<f64> {
        let d = p.d_m;
        let depth = p.depth_m;
        let mut f = FormationFollower::new(p);
        let v = 0.3;
        // Up-flow West: left is South. Right leader (1) North, left leader (2) South.
        let leader_pos = |t: f64, which: u32| {
            let y = if which == 1 { 5.0 } else { -5.0 };
            Vec2::new(200.0 - v * t, y)
        };
        let behind = (d * d - depth * depth - 25.0).sqrt();
        let station = Vec2::new(200.0 + behind, 0.0);
        let mut body = Body::new(station + start_offset, 270.0);
        let mut rng = Lcg(7);
        let dt = 0.1;
        let mut pending: Vec<(f64, Message)> = Vec::new();
        let mut errors = Vec::new();
        let mut done = false;
        for k in 0..6000 {
            let t = f64::from(k) * dt;
            let deafened = deaf.is_some_and(|(a, b)| (a..b).contains(&t));
            let inbox: Vec<Message> = pending
                .iter()
                .filter(|(at, _)| *at <= t + 1e-9 && !deafened)
                .map(|(_, m)| m.clone())
                .collect();
            pending.retain(|(at, _)| *at > t + 1e-9);
            let dec = if done {
                Decision::new(
                    plumetrace_core::Command {
                        heading: body.heading,
                        speed_mps: 0.0,
                        vertical: VerticalCommand::Depth(depth),
                    },
                    PlanStatus::Finished,
                )
            } else {
                f.decide(&snapshot(t, 0, None, body.heading, vec![], inbox))
            };
            // A finished planner is not asked again (as in the simulator).
            done |= dec.status == PlanStatus::Finished;
            assert!(dec.command.is_finite(), "{:?}", dec.command);
            for o in dec.outbox {
                if let MessageBody::RangeRequest { target, .. } = o.body {
                    let lp = leader_pos(t, target.0);
                    let r = ((lp - body.pos).norm_squared() + depth * depth).sqrt();
                    pending.push((
                        t + 2.0 * delay_s,
                        Message {
                            from: target,
                            to: Recipient::Vehicle(VehicleId(0)),
                            link: Link::Acoustic,
                            sent_s: t + delay_s,
                            body: MessageBody::RangeReply {
                                range_m: r + noise_m * rng.normal(),
                                sender_heading: Heading::from_deg(270.0),
                                scale_cw: None,
                            },
                        },
                    ));
                }
            }
            body.cmd_heading = dec.command.heading;
            body.cmd_speed = dec.command.speed_mps;
            body.step(dt, 10.0);
            if t >= settle_s {
                for w in [1, 2] {
                    let r =
                        ((leader_pos(t + dt, w) - body.pos).norm_squared() + depth * depth).sqrt();
                    errors.push((r - d).abs());
                }
            }
        }
        errors
    }

    fn median(mut v: Vec<f64>) -> f64 {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    }

    #[test]
    fn the_follower_converges_from_10_m_off_with_ideal_ranges() {
        // 10 m behind and to the side of its station, ranges every 2 s, no delay, no noise.
        let e = follow(Vec2::new(8.0, 6.0), 0.0, 0.0, 300.0);
        let m = median(e.clone());
        assert!(m < 0.5, "median range error {m}");
        let worst = e.iter().copied().fold(0.0, f64::max);
        assert!(worst < 1.5, "worst range error {worst}");
    }

    #[test]
    fn the_follower_holds_its_station_with_delayed_noisy_alternating_ranges() {
        // Ranges every 2 s alternately, 10 ms of travel each way, 0.3 m of noise.
        let e = follow(Vec2::new(8.0, 6.0), 0.01, 0.3, 300.0);
        let m = median(e);
        assert!(m < 1.0, "median range error {m} (10 % of d)");
    }

    /// The follower with the range filter on or off.
    fn follower_params(filter: bool) -> FormationFollowerParams {
        FormationFollowerParams {
            left_leader: 2,
            right_leader: 1,
            range_filter: filter,
            ..FormationFollowerParams::default()
        }
    }

    /// The left leader's formation scale at each 0.1 s step of `steps`, with `params` (its side
    /// and `declare = false` set here), where it and its partner read the plume while `on(t)`
    /// (its own reading 0.1, the partner's 0.3) and nothing otherwise.
    fn left_leader_scales(
        params: FormationLeaderParams,
        steps: u32,
        on: impl Fn(f64) -> bool,
    ) -> Vec<f64> {
        let mut l = FormationLeader::new(
            FormationLeaderParams {
                side: FormationSide::Left,
                declare: false,
                ..params
            },
            VehicleId(0),
            Heading::from_deg(270.0),
            area(),
        );
        let mut scales = Vec::new();
        for k in 0..steps {
            let t = f64::from(k) * 0.1;
            let on = on(t);
            let inbox = vec![partner_state(t, if on { 0.3 } else { 0.0 }, l.scale())];
            let chem = vec![ChemSample {
                time_s: t,
                reading: 35.0 - if on { 0.1 } else { 0.0 },
            }];
            let pos = Some(Vec2::zeros());
            l.decide(&snapshot(t, 0, pos, Heading::from_deg(270.0), chem, inbox));
            scales.push(l.scale());
        }
        scales
    }

    #[test]
    fn the_formation_closes_once_both_leaders_readings_fade() {
        // Own and partner's readings 0.3 (the partner's) and 0.1 (own) for 30 s, then nothing.
        let run = |close: bool| {
            let p = FormationLeaderParams {
                close_on_fade: close,
                ..FormationLeaderParams::default()
            };
            left_leader_scales(p, 600, |t| t < 30.0)
        };
        let closed = run(true);
        // Faded at 34 s (the 4 s max filter), then 0.05 per second down to 0.3.
        assert_eq!(closed[300], 1.0, "open while the plume is read");
        assert!((closed[440] - 0.5).abs() < 0.05, "{}", closed[440]);
        assert_eq!(closed[599], 0.3);
        assert_eq!(run(false)[599], 1.0);
    }

    #[test]
    fn a_closed_formation_reopens_when_the_plume_comes_back_with_reopen_on_return() {
        // Read for 30 s, a gap of 15 s, read again for 7 s, then nothing.
        let run = |reopen: bool| {
            let p = FormationLeaderParams {
                reopen_on_return: reopen,
                ..FormationLeaderParams::default()
            };
            left_leader_scales(p, 800, |t| t < 30.0 || (45.0..52.0).contains(&t))
        };
        // Closing from 34 s; at 45 s the plume is back: the scale is held (no follower) where
        // it was, 1 - 0.05 x 11 = 0.45, and falls again from the next fade (56 s).
        let reopened = run(true);
        assert!((reopened[500] - 0.45).abs() < 0.02, "{}", reopened[500]);
        assert!((reopened[550] - 0.45).abs() < 0.02, "{}", reopened[550]);
        assert_eq!(reopened[799], 0.3);
        let kept = run(false);
        assert_eq!(kept[500], 0.3, "closed for good without the key");
    }

    #[test]
    fn the_follower_rejoins_after_a_ranging_outage_of_a_minute() {
        // Deaf from 100 s to 165 s (the family's longest window and the next reply's wait).
        let run = |now: bool| {
            let p = if now {
                follower_params(false)
            } else {
                // Before: finished after 60 s without a reply, coasting until then.
                FormationFollowerParams {
                    lost_s: 60.0,
                    coast_s: 60.0,
                    ..follower_params(false)
                }
            };
            median(follow_with(
                p,
                Vec2::new(8.0, 6.0),
                0.01,
                0.3,
                300.0,
                Some((100.0, 165.0)),
            ))
        };
        let (now, before) = (run(true), run(false));
        assert!(now < 1.0, "median range error {now} after the outage");
        assert!(before > 5.0, "the follower gave up before: {before}");
    }

    #[test]
    fn the_filtered_follower_rejoins_after_a_ranging_outage_too() {
        let e = follow_with(
            follower_params(true),
            Vec2::new(8.0, 6.0),
            0.01,
            0.3,
            300.0,
            Some((100.0, 165.0)),
        );
        let m = median(e);
        assert!(m < 1.0, "median range error {m} after the outage");
    }

    #[test]
    fn a_stray_range_moves_the_filtered_follower_little() {
        // Both leaders answer at 10 m for a minute, then one answer is 40 m (a late echo).
        let run = |filter: bool| {
            let mut f = FormationFollower::new(follower_params(filter));
            let mut speeds = Vec::new();
            for k in 0..700 {
                let t = f64::from(k) * 0.1;
                let inbox = if k % 20 == 5 {
                    let stray = k == 605;
                    vec![Message {
                        from: VehicleId(if k % 40 == 5 { 2 } else { 1 }),
                        to: Recipient::Vehicle(VehicleId(0)),
                        link: Link::Acoustic,
                        sent_s: t,
                        body: MessageBody::RangeReply {
                            range_m: if stray { 40.0 } else { 10.0 },
                            sender_heading: Heading::from_deg(270.0),
                            scale_cw: None,
                        },
                    }]
                } else {
                    vec![]
                };
                let d = f.decide(&snapshot(
                    t,
                    0,
                    None,
                    Heading::from_deg(270.0),
                    vec![],
                    inbox,
                ));
                if t > 60.0 {
                    speeds.push(d.command.speed_mps);
                }
            }
            speeds.into_iter().fold(0.0, f64::max)
        };
        let (now, before) = (run(true), run(false));
        assert!(now < 0.1, "filtered: {now} m/s");
        assert!(before > 0.9, "raw: {before} m/s");
    }
}
