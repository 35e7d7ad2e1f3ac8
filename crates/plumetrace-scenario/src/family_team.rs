//! Scenario families of teams: the `[team]` table of a family file, and what a family does with a
//! base scenario of several vehicles.
//!
//! Without `[team]`, a base of several vehicles keeps all of them: the first vehicle goes to the
//! drawn start and heading, and the others keep their place relative to it (the whole team is
//! moved and turned as one), so a formation's shape and its `[planners]` survive the draw.
//!
//! With `[team]` (formation tracing: a follower flying `formation_follower` and the two leaders it
//! names), the family's `[area]` is the basin (`length_m` along its axis, `width_m` across, a
//! rectangle) and the rest of a site is drawn here, from its own random stream (so the family
//! draws of `family.rs` are unchanged):
//! - the outlet: `outlet_from_end_m` inside the basin's up-flow end, `outlet_cross_m` off its
//!   centre line (near a side wall this is an outlet on a shore; the plume model has no walls, so
//!   the shore only bounds the vehicles); with `outlets` drawn as 2, a second outlet
//!   `second_along_m` down-flow and `second_cross_m` across, releasing `second_fraction` of the
//!   first's rate;
//! - the salinity of the medium (`medium_ppt`, the contrast with the fresh water; the team's
//!   `s_max_ppt` is set to it: the team measures the ambient salinity before it starts);
//! - the formation's scale `d_m` (the leaders' and follower's `d_m`); the leaders are given the
//!   drawn current's speed (`current_speed_mps`);
//! - the team's start: its centre `along` metres down-flow of the outlet, drawn in
//!   `start_along_fraction` of the plume's reach (where the surface centre line of the plume
//!   falls to `reach_freshness_ppt`, by the steady Gaussian solution with the surface reflecting,
//!   less the room the basin leaves), and across the flow within `start_cross_sigmas` plume
//!   widths (sigma_y at that distance) of the centre line; leaders `d/2` to each side, the
//!   follower `0.9 d` behind, all heading up-flow;
//! - the leaders' GPS (`gps`: `rtk`, 2 cm at 5 fixes a second, or `consumer`, `consumer_sigma_m`
//!   at one fix a second);
//! - the acoustics: packet loss (`acoustic_loss`), ranging timing noise (`ranging_noise_sd_s`),
//!   and with probability `deaf_probability` a deaf window of the follower's modem (`deaf_s`
//!   long, starting in `deaf_start_s`).

use crate::family::{
    FAMILY_LIMITS, FamilyFile, Range, Site, family_bound, float, invalid, round, table_at, uniform,
    unit,
};
use crate::{Origin, ScenarioError};
use plumetrace_core::Vec2;
use plumetrace_env::{StreamId, stream_rng};
use rand::Rng;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The random stream of a team draw.
const TEAM_STREAM: u64 = 0x7465_616d;

/// Density of fresh water, kg/m^3 (the salinity probe's).
const FRESH_KG_M3: f64 = 998.2;

/// Leader GPS grades.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GpsGrade {
    /// RTK: 2 cm, five fixes a second.
    Rtk,
    /// Consumer GPS: `consumer_sigma_m`, one fix a second.
    Consumer,
}

/// `[team]`: the formation's draws.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TeamDraw {
    /// Outlet distance from the basin's up-flow end, m.
    pub outlet_from_end_m: Range,
    /// Outlet offset from the basin's centre line, m.
    #[serde(default)]
    pub outlet_cross_m: Option<Range>,
    /// Numbers of outlets drawn from, equally likely (1 or 2).
    #[serde(default = "one_outlet")]
    pub outlets: Vec<u32>,
    /// The second outlet's distance down-flow of the first, m.
    #[serde(default = "second_along")]
    pub second_along_m: Range,
    /// The second outlet's offset across the flow from the first, m.
    #[serde(default = "second_cross")]
    pub second_cross_m: Range,
    /// The second outlet's rate as a fraction of the first's.
    #[serde(default = "second_fraction")]
    pub second_fraction: Range,
    /// Salinity of the medium, ppt.
    #[serde(default)]
    pub medium_ppt: Option<Range>,
    /// Formation scale d, m.
    #[serde(default)]
    pub d_m: Option<Range>,
    /// The plume's reach: where its surface centre line falls to this freshness, ppt.
    #[serde(default = "reach_freshness")]
    pub reach_freshness_ppt: f64,
    /// The team's start, as a fraction of the reach (the room in the basin caps it).
    pub start_along_fraction: Range,
    /// Least start distance down-flow of the outlet, m.
    #[serde(default = "start_along_min")]
    pub start_along_min_m: f64,
    /// The team's start across the flow, in plume widths sigma_y at its distance.
    #[serde(default = "cross_sigmas")]
    pub start_cross_sigmas: f64,
    /// Leader GPS grades drawn from, equally likely.
    #[serde(default = "rtk_only")]
    pub gps: Vec<GpsGrade>,
    /// Consumer GPS error (standard deviation), m.
    #[serde(default = "consumer_sigma")]
    pub consumer_sigma_m: Range,
    /// Acoustic packet loss probability.
    #[serde(default)]
    pub acoustic_loss: Option<Range>,
    /// Ranging timing noise (standard deviation), s.
    #[serde(default)]
    pub ranging_noise_sd_s: Option<Range>,
    /// Chance of a deaf window of the follower's modem.
    #[serde(default)]
    pub deaf_probability: f64,
    /// Length of the deaf window, s.
    #[serde(default = "deaf_len")]
    pub deaf_s: Range,
    /// Start of the deaf window, s.
    #[serde(default = "deaf_start")]
    pub deaf_start_s: Range,
}

fn one_outlet() -> Vec<u32> {
    vec![1]
}
fn second_along() -> Range {
    [10.0, 30.0]
}
fn second_cross() -> Range {
    [-6.0, 6.0]
}
fn second_fraction() -> Range {
    [0.3, 1.0]
}
fn reach_freshness() -> f64 {
    0.02
}
fn start_along_min() -> f64 {
    15.0
}
fn cross_sigmas() -> f64 {
    1.5
}
fn rtk_only() -> Vec<GpsGrade> {
    vec![GpsGrade::Rtk]
}
fn consumer_sigma() -> Range {
    [2.0, 5.0]
}
fn deaf_len() -> Range {
    [10.0, 60.0]
}
fn deaf_start() -> Range {
    [30.0, 300.0]
}

/// A drawn team site.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TeamSite {
    /// Outlets: position, m, and rate.
    pub outlets: Vec<([f64; 2], Option<f64>)>,
    /// Medium salinity, ppt, if drawn.
    pub medium_ppt: Option<f64>,
    /// Formation scale, m, if drawn.
    pub d_m: Option<f64>,
    /// The plume's reach, m.
    pub reach_m: f64,
    /// Start distance down-flow of the outlet, m.
    pub start_along_m: f64,
    /// Start offset across the flow (to the left looking up-flow), m.
    pub start_cross_m: f64,
    /// Start positions by vehicle index, m.
    pub starts: Vec<(usize, [f64; 2])>,
    /// Start heading, compass deg.
    pub heading_deg: f64,
    /// Leader GPS grade and its error, m.
    pub gps: GpsGrade,
    /// Leader GPS error, m.
    pub gps_sigma_m: f64,
    /// Acoustic loss, if drawn.
    pub acoustic_loss: Option<f64>,
    /// Ranging timing noise, s, if drawn.
    pub ranging_noise_sd_s: Option<f64>,
    /// Follower deaf window, s.
    pub deaf_s: Option<[f64; 2]>,
}

impl TeamSite {
    /// The drawn values, `(name, text)`, for a site file's opening comment.
    pub fn values(&self) -> Vec<(&'static str, String)> {
        let opt = |v: Option<f64>, d: usize| v.map_or(String::new(), |v| format!("{v:.d$}"));
        vec![
            ("team_outlets", self.outlets.len().to_string()),
            ("team_medium_ppt", opt(self.medium_ppt, 2)),
            ("team_d_m", opt(self.d_m, 2)),
            ("team_reach_m", format!("{:.1}", self.reach_m)),
            ("team_start_along_m", format!("{:.1}", self.start_along_m)),
            ("team_start_cross_m", format!("{:.2}", self.start_cross_m)),
            (
                "team_gps",
                plumetrace_core::variant_name(&self.gps)
                    .unwrap_or("?")
                    .into(),
            ),
            ("team_gps_sigma_m", format!("{:.2}", self.gps_sigma_m)),
            ("team_acoustic_loss", opt(self.acoustic_loss, 3)),
            ("team_ranging_noise_sd_s", opt(self.ranging_noise_sd_s, 5)),
            (
                "team_deaf_s",
                self.deaf_s
                    .map_or(String::new(), |[a, b]| format!("{a:.0}-{b:.0}")),
            ),
        ]
    }
}

/// The roles of a formation base: (follower, right leader, left leader) vehicle indices.
struct Roles {
    follower: usize,
    right: usize,
    left: usize,
    follower_planner: String,
    leader_planners: Vec<String>,
}

/// The planner table a vehicle of `base` flies, with its name.
fn planner_of(base: &toml::Table, v: &toml::Value) -> Option<(String, toml::Table)> {
    let name = v.get("planner")?.as_str()?;
    let t = base.get("planners")?.get(name)?.as_table()?;
    Some((name.to_string(), t.clone()))
}

/// Finds the formation roles in `base`; errors name what is missing.
fn roles(base: &toml::Table, base_origin: &Origin, path: &Path) -> Result<Roles, ScenarioError> {
    let vehicles = base
        .get("vehicles")
        .and_then(toml::Value::as_array)
        .cloned()
        .unwrap_or_default();
    let kind = |t: &toml::Table| {
        t.get("kind")
            .and_then(toml::Value::as_str)
            .map(String::from)
    };
    let follower = vehicles.iter().enumerate().find_map(|(k, v)| {
        let (name, t) = planner_of(base, v)?;
        (kind(&t).as_deref() == Some("formation_follower")).then_some((k, name, t))
    });
    let Some((follower, follower_planner, ft)) = follower else {
        return Err(invalid(
            path,
            "team",
            format!(
                "{base_origin} has no vehicle flying a formation_follower planner; [team] draws \
                 formation sites (remove [team] to move a team of another kind as one)"
            ),
        ));
    };
    let index = |key: &str, default: i64| -> Result<usize, ScenarioError> {
        let i = ft
            .get(key)
            .and_then(toml::Value::as_integer)
            .unwrap_or(default);
        usize::try_from(i)
            .ok()
            .filter(|&i| i < vehicles.len() && i != follower)
            .ok_or_else(|| {
                invalid(
                    path,
                    "team",
                    format!(
                        "{base_origin}: planners.{follower_planner}.{key} = {i} is not one of \
                         the other vehicles (0..{})",
                        vehicles.len()
                    ),
                )
            })
    };
    let (right, left) = (index("right_leader", 1)?, index("left_leader", 2)?);
    let leader_planners = [right, left]
        .iter()
        .filter_map(|&k| planner_of(base, &vehicles[k]).map(|p| p.0))
        .collect();
    Ok(Roles {
        follower,
        right,
        left,
        follower_planner,
        leader_planners,
    })
}

/// Checks `[team]` against its base (called by the family's parse).
pub(crate) fn check(
    f: &FamilyFile,
    base: &toml::Table,
    base_origin: &Origin,
    path: &Path,
) -> Result<(), ScenarioError> {
    let Some(t) = &f.team else { return Ok(()) };
    roles(base, base_origin, path)?;
    let range = |key: &str, r: Option<Range>| -> Result<(), ScenarioError> {
        let Some([a, b]) = r else { return Ok(()) };
        let key = format!("team.{key}");
        let ranged = format!("{key}[]");
        let (lo, hi, why) = if FAMILY_LIMITS.iter().any(|l| l.0 == ranged) {
            family_bound(&ranged)
        } else {
            family_bound(&key)
        };
        for v in [a, b] {
            if !(v.is_finite() && v >= lo && v <= hi) {
                return Err(invalid(
                    path,
                    &key,
                    format!("must be a finite number >= {lo} and <= {hi} ({why}), got {v}"),
                ));
            }
        }
        if a > b {
            return Err(invalid(
                path,
                &key,
                format!("[low, high] needs low <= high, got [{a}, {b}]"),
            ));
        }
        Ok(())
    };
    range("outlet_from_end_m", Some(t.outlet_from_end_m))?;
    range("outlet_cross_m", t.outlet_cross_m)?;
    range("second_along_m", Some(t.second_along_m))?;
    range("second_cross_m", Some(t.second_cross_m))?;
    range("second_fraction", Some(t.second_fraction))?;
    range("medium_ppt", t.medium_ppt)?;
    range("d_m", t.d_m)?;
    range("reach_freshness_ppt", Some([t.reach_freshness_ppt; 2]))?;
    range("start_along_fraction", Some(t.start_along_fraction))?;
    range("start_along_min_m", Some([t.start_along_min_m; 2]))?;
    range("start_cross_sigmas", Some([t.start_cross_sigmas; 2]))?;
    range("consumer_sigma_m", Some(t.consumer_sigma_m))?;
    range("acoustic_loss", t.acoustic_loss)?;
    range("ranging_noise_sd_s", t.ranging_noise_sd_s)?;
    range("deaf_probability", Some([t.deaf_probability; 2]))?;
    range("deaf_s", Some(t.deaf_s))?;
    range("deaf_start_s", Some(t.deaf_start_s))?;
    if t.outlets.is_empty() || t.outlets.iter().any(|&n| n == 0 || n > 2) {
        return Err(invalid(
            path,
            "team.outlets",
            format!("name 1 or 2 outlets (e.g. [1, 2]), got {:?}", t.outlets),
        ));
    }
    let model = base
        .get("plume")
        .and_then(|p| p.get("model"))
        .and_then(toml::Value::as_str);
    if t.outlets.contains(&2) && model == Some("gaussian") {
        return Err(invalid(
            path,
            "team.outlets",
            format!(
                "{base_origin} has a gaussian plume, which takes exactly one source: use \
                 outlets = [1], or a base whose plume model takes several"
            ),
        ));
    }
    if t.gps.is_empty() {
        return Err(invalid(
            path,
            "team.gps",
            "name at least one grade: \"rtk\" or \"consumer\"".into(),
        ));
    }
    Ok(())
}

fn float_of(t: &toml::Table, section: &str, key: &str) -> Option<f64> {
    let v = t.get(section)?.get(key)?;
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

/// Whether `p` is at least `inset` inside the axis-`u` rectangle of `length` by `width` centred
/// on the origin.
fn inside(p: Vec2, u: Vec2, w: Vec2, length: f64, width: f64, inset: f64) -> bool {
    p.dot(&u).abs() <= length / 2.0 - inset && p.dot(&w).abs() <= width / 2.0 - inset
}

/// Draws the team part of a site (the family part `site` is drawn already).
pub(crate) fn draw(
    t: &TeamDraw,
    base: &toml::Table,
    base_origin: &Origin,
    site: &Site,
    seed: u64,
) -> Option<TeamSite> {
    let roles = roles(base, base_origin, Path::new("")).ok()?;
    let mut rng = stream_rng(seed, StreamId::Custom(TEAM_STREAM));
    let (u, w) = (unit(site.axis_deg), unit(site.axis_deg + 90.0));
    let down = unit(site.flow_toward_deg);
    // Looking up-flow, the left axis.
    let left = unit(site.flow_toward_deg + 90.0);
    let (length, width) = (site.length_m, site.width_m);
    let from_end = uniform(&mut rng, t.outlet_from_end_m);
    let cross = t.outlet_cross_m.map_or(0.0, |r| uniform(&mut rng, r));
    let up_end = if u.dot(&down) >= 0.0 { -1.0 } else { 1.0 };
    let outlet = u * (up_end * (length / 2.0 - from_end)) + w * cross;
    let n_outlets = t.outlets[rng.random_range(0..t.outlets.len())];
    let medium = t.medium_ppt.map(|r| uniform(&mut rng, r));
    let d = t.d_m.map(|r| uniform(&mut rng, r));
    let d_m = d.unwrap_or(10.0);
    // The plume's reach: Q / (2 pi x sqrt(Ky Kz)) kg/m^3 on the surface centre line.
    let q = site
        .mass_rate_per_s
        .or_else(|| {
            base.get("sources")?
                .as_array()?
                .first()?
                .get("mass_rate_per_s")?
                .as_float()
        })
        .unwrap_or(1.0);
    let ky = float_of(base, "plume", "horizontal_diffusivity_m2ps").unwrap_or(0.012);
    let kz = float_of(base, "plume", "vertical_diffusivity_m2ps").unwrap_or(0.0004);
    let s = medium.unwrap_or(35.0);
    let reach =
        s * q / (FRESH_KG_M3 * std::f64::consts::TAU * (ky * kz).sqrt()) / t.reach_freshness_ppt;
    let mut along = (t
        .start_along_min_m
        .max(reach * uniform(&mut rng, t.start_along_fraction)))
    .min(reach.max(t.start_along_min_m));
    let sigma = |x: f64| (2.0 * ky * x / site.flow_speed_mps).sqrt();
    let k = t.start_cross_sigmas;
    let cross_unit = if k > 0.0 {
        rng.random_range(-k..=k)
    } else {
        0.0
    };
    let place = |along: f64| {
        let c = outlet + down * along + left * (cross_unit * sigma(along));
        (
            c,
            [
                (roles.right, c - left * (d_m / 2.0)),
                (roles.left, c + left * (d_m / 2.0)),
                (roles.follower, c + down * (0.9 * d_m)),
            ],
        )
    };
    // Pull the team up-flow until every vehicle starts at least 2 m inside the basin.
    let mut starts = place(along);
    for _ in 0..400 {
        if starts
            .1
            .iter()
            .all(|(_, p)| inside(*p, u, w, length, width, 2.0))
            || along <= 1.0
        {
            break;
        }
        along *= 0.98;
        starts = place(along);
    }
    let mut outlets = vec![([outlet.x, outlet.y], site.mass_rate_per_s)];
    let second = (
        uniform(&mut rng, t.second_along_m),
        uniform(&mut rng, t.second_cross_m),
        uniform(&mut rng, t.second_fraction),
    );
    if n_outlets == 2 {
        let p = outlet + down * second.0 + left * second.1;
        outlets.push(([p.x, p.y], Some(q * second.2)));
    }
    let gps = t.gps[rng.random_range(0..t.gps.len())];
    let consumer = uniform(&mut rng, t.consumer_sigma_m);
    let gps_sigma_m = match gps {
        GpsGrade::Rtk => 0.02,
        GpsGrade::Consumer => consumer,
    };
    let acoustic_loss = t.acoustic_loss.map(|r| uniform(&mut rng, r));
    let ranging_noise_sd_s = t.ranging_noise_sd_s.map(|r| uniform(&mut rng, r));
    let deaf_on = rng.random::<f64>() < t.deaf_probability;
    let deaf_len = uniform(&mut rng, t.deaf_s);
    let deaf_at = uniform(&mut rng, t.deaf_start_s);
    let c = starts.0 - outlet;
    Some(TeamSite {
        outlets,
        medium_ppt: medium,
        d_m: d,
        reach_m: reach,
        start_along_m: c.dot(&down),
        start_cross_m: c.dot(&left),
        starts: starts.1.iter().map(|(k, p)| (*k, [p.x, p.y])).collect(),
        heading_deg: (site.flow_toward_deg + 180.0).rem_euclid(360.0),
        gps,
        gps_sigma_m,
        acoustic_loss,
        ranging_noise_sd_s,
        deaf_s: deaf_on.then_some([deaf_at, deaf_at + deaf_len]),
    })
}

/// Vehicle `k` of `t` as a table.
fn vehicle(t: &mut toml::Table, k: usize) -> Option<&mut toml::Table> {
    t.get_mut("vehicles")?
        .as_array_mut()?
        .get_mut(k)?
        .as_table_mut()
}

/// Writes a team site into the scenario table `t` (the family part is written already, with
/// every base vehicle kept).
pub(crate) fn apply(
    team: &TeamSite,
    f: &FamilyFile,
    site: &Site,
    base: &toml::Table,
    t: &mut toml::Table,
) {
    let Some(roles) = roles(base, &Origin::Preset(String::new()), Path::new("")).ok() else {
        return;
    };
    // Outlets: the first is the family's source; a second is a copy of it.
    if let Some(toml::Value::Array(sources)) = t.get_mut("sources")
        && let Some(first) = sources.first().cloned()
    {
        sources.truncate(1);
        for (k, (p, q)) in team.outlets.iter().enumerate() {
            let mut s = first.as_table().cloned().unwrap_or_default();
            s.insert("x_m".into(), float(round(p[0], 2)));
            s.insert("y_m".into(), float(round(p[1], 2)));
            if let Some(q) = q {
                s.insert("mass_rate_per_s".into(), float(round(*q, 4)));
            }
            if k == 0 {
                sources[0] = toml::Value::Table(s);
            } else {
                sources.push(toml::Value::Table(s));
            }
        }
    }
    for (k, p) in &team.starts {
        let grade = *k != roles.follower;
        if let Some(v) = vehicle(t, *k) {
            v.insert("x_m".into(), float(round(p[0], 2)));
            v.insert("y_m".into(), float(round(p[1], 2)));
            v.insert("heading_deg".into(), float(round(team.heading_deg, 2)));
            if let Some(m) = team.medium_ppt
                && let Some(c) = table_at(v, "chem_sensor")
            {
                c.insert("medium_salinity_ppt".into(), float(round(m, 3)));
            }
            if grade && let Some(nav) = table_at(v, "nav") {
                let (interval, sigma) = match team.gps {
                    GpsGrade::Rtk => (0.2, 0.02),
                    GpsGrade::Consumer => (1.0, round(team.gps_sigma_m, 3)),
                };
                nav.insert("fix_interval_s".into(), float(interval));
                nav.insert("fix_sigma_m".into(), float(sigma));
            }
            if !grade
                && let Some([a, b]) = team.deaf_s
                && let Some(modem) = table_at(v, "modem")
            {
                modem.insert("deaf_start_s".into(), float(round(a, 1)));
                modem.insert("deaf_end_s".into(), float(round(b, 1)));
            }
        }
    }
    let _ = roles.right + roles.left;
    if let Some(planners) = table_at(t, "planners") {
        let mut names = roles.leader_planners.clone();
        names.push(roles.follower_planner.clone());
        for name in &names {
            let Some(p) = planners.get_mut(name).and_then(toml::Value::as_table_mut) else {
                continue;
            };
            if let Some(d) = team.d_m {
                p.insert("d_m".into(), float(round(d, 3)));
            }
            if let Some(m) = team.medium_ppt {
                p.insert("s_max_ppt".into(), float(round(m, 3)));
            }
            if *name != roles.follower_planner {
                p.insert(
                    "current_speed_mps".into(),
                    float(round(site.flow_speed_mps, 4)),
                );
            }
        }
    }
    if let Some(comms) = table_at(t, "comms") {
        if let Some(l) = team.acoustic_loss
            && let Some(a) = table_at(comms, "acoustic")
        {
            a.insert("loss_probability".into(), float(round(l, 4)));
        }
        if let Some(n) = team.ranging_noise_sd_s
            && let Some(r) = table_at(comms, "ranging")
        {
            r.insert("timing_noise_sd_s".into(), float(round(n, 6)));
        }
    }
    // The basin is the domain: the op-area's bounding box with the family's margin.
    let m = f.domain_margin_m;
    let xs = site.op_area.iter().map(|p| p[0]);
    let ys = site.op_area.iter().map(|p| p[1]);
    let (x0, x1) = (
        xs.clone().fold(f64::MAX, f64::min),
        xs.fold(f64::MIN, f64::max),
    );
    let (y0, y1) = (
        ys.clone().fold(f64::MAX, f64::min),
        ys.fold(f64::MIN, f64::max),
    );
    if let Some(domain) = table_at(t, "domain") {
        for (k, v) in [
            ("x_min_m", x0 - m),
            ("x_max_m", x1 + m),
            ("y_min_m", y0 - m),
            ("y_max_m", y1 + m),
        ] {
            domain.insert(k.into(), float(round(v, 1)));
        }
    }
    // A steady plume needs no spin-up.
    if base
        .get("mission")
        .and_then(|m| m.get("spinup_s"))
        .is_none()
        && let Some(mission) = table_at(t, "mission")
    {
        mission.remove("spinup_s");
    }
}

/// Moves every vehicle of a base with several (no `[team]`): the first to the drawn start and
/// heading, the others kept where they were relative to it.
pub(crate) fn move_team(site: &Site, t: &mut toml::Table) {
    let Some(toml::Value::Array(vs)) = t.get_mut("vehicles") else {
        return;
    };
    let get = |v: &toml::Value, k: &str| {
        v.get(k)
            .and_then(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
            .unwrap_or(0.0)
    };
    let Some(first) = vs.first() else { return };
    let p0 = Vec2::new(get(first, "x_m"), get(first, "y_m"));
    let turn = (site.start_heading_deg - get(first, "heading_deg")).to_radians();
    let (sin, cos) = turn.sin_cos();
    let to = Vec2::new(site.start_pos[0], site.start_pos[1]);
    let mut moved = Vec::new();
    for v in vs.iter_mut() {
        let r = Vec2::new(get(v, "x_m"), get(v, "y_m")) - p0;
        // Compass turn: clockwise by `turn` in the East-North frame.
        let p = to + Vec2::new(r.x * cos + r.y * sin, -r.x * sin + r.y * cos);
        let h = (get(v, "heading_deg") + turn.to_degrees()).rem_euclid(360.0);
        if let Some(v) = v.as_table_mut() {
            v.insert("x_m".into(), float(round(p.x, 2)));
            v.insert("y_m".into(), float(round(p.y, 2)));
            v.insert("heading_deg".into(), float(round(h, 2)));
        }
        moved.push(p);
    }
    // The domain holds every member, with 5 m to spare.
    if let Some(toml::Value::Table(domain)) = t.get_mut("domain") {
        for (key, pick, low) in [
            ("x_min_m", 0, true),
            ("x_max_m", 0, false),
            ("y_min_m", 1, true),
            ("y_max_m", 1, false),
        ] {
            let Some(now) = domain.get(key).and_then(toml::Value::as_float) else {
                continue;
            };
            let need = moved.iter().map(|p| if pick == 0 { p.x } else { p.y });
            let v = if low {
                need.fold(now, |a, x| a.min(round(x - 5.0, 1)))
            } else {
                need.fold(now, |a, x| a.max(round(x + 5.0, 1)))
            };
            domain.insert(key.into(), float(v));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Family;

    const FORMATION: &str = include_str!("../../../examples/families/formation.family.toml");

    fn formation(text: &str) -> Result<Family, ScenarioError> {
        Family::parse(text, Path::new("examples/families/formation.family.toml"))
    }

    fn build(f: &Family, seed: u64) -> crate::BuiltScenario {
        let origin = Origin::Preset("formation".into());
        let cfg = crate::from_table(f.scenario(seed), &origin)
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        crate::build(&cfg, &origin, Some(seed)).unwrap_or_else(|e| panic!("seed {seed}: {e}"))
    }

    #[test]
    fn formation_sites_keep_the_team_and_build() {
        let f = formation(FORMATION).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(f.draw(3), f.draw(3));
        let mut grades = std::collections::BTreeSet::new();
        for seed in 0..40 {
            let site = f.draw(seed);
            let team = site.team.clone().unwrap_or_else(|| panic!("seed {seed}"));
            let built = build(&f, seed);
            assert_eq!(built.vehicles.len(), 3, "seed {seed}");
            // The team starts down-flow of the outlet, heading up-flow, inside the basin.
            assert!(team.start_along_m > 0.0, "seed {seed}: {team:?}");
            for (_, p) in &team.starts {
                assert!(inside(
                    Vec2::new(p[0], p[1]),
                    unit(site.axis_deg),
                    unit(site.axis_deg + 90.0),
                    site.length_m,
                    site.width_m,
                    1.9
                ));
            }
            let d = team.d_m.unwrap_or_default();
            assert!((7.0..=13.0).contains(&d), "{d}");
            grades.insert(format!("{:?}", team.gps));
            let text = site.to_toml(&f.file, &f.base, seed, "s");
            assert!(text.contains("#   team_d_m = "), "{text}");
            assert!(text.contains(&format!("d_m = {}", round(d, 3))), "{text}");
        }
        assert_eq!(grades.len(), 2, "both GPS grades drawn: {grades:?}");
    }

    #[test]
    fn a_team_base_without_team_draws_moves_the_whole_team() {
        let text = FORMATION
            .split("[team]")
            .next()
            .unwrap_or_default()
            .to_string();
        let f = formation(&text).unwrap_or_else(|e| panic!("{e}"));
        for seed in 0..10 {
            let built = build(&f, seed);
            assert_eq!(built.vehicles.len(), 3);
            // The leaders keep their 10 m from each other.
            let p = |k: usize| built.vehicles[k].vehicle.state.pos_m;
            assert!(((p(1) - p(2)).norm() - 10.0).abs() < 0.05, "seed {seed}");
        }
    }

    #[test]
    fn every_team_row_bounds_its_key() {
        let rows: Vec<_> = FAMILY_LIMITS
            .iter()
            .filter(|l| l.0.starts_with("team."))
            .collect();
        assert!(rows.len() >= 17, "{}", rows.len());
        for (key, _, hi, why) in rows {
            let name = key.trim_start_matches("team.");
            let (name, ranged) = match name.strip_suffix("[]") {
                Some(n) => (n, true),
                None => (name, false),
            };
            let over = hi * 2.0 + 1.0;
            let value = if ranged {
                format!("[{over:?}, {over:?}]")
            } else {
                format!("{over:?}")
            };
            // Drop any line of the key already in the file, then set it above its bound.
            let text: String = FORMATION
                .lines()
                .filter(|l| !l.trim_start().starts_with(&format!("{name} =")))
                .map(|l| format!("{l}\n"))
                .collect::<String>()
                .replace("[team]\n", &format!("[team]\n{name} = {value}\n"));
            let e = formation(&text).map(|_| ()).unwrap_err().to_string();
            let shown = format!("team.{name}");
            assert!(e.contains(&shown) && e.contains(why), "{key}: {e}");
        }
    }

    #[test]
    fn bad_team_keys_are_located() {
        let cases = [
            (
                FORMATION.replace("outlets = [1]", "outlets = [1, 2]"),
                "team.outlets",
                "exactly one source",
            ),
            (
                FORMATION.replace("d_m = [7.0, 13.0]", "d_m = [13.0, 7.0]"),
                "team.d_m",
                "low <= high",
            ),
            (
                FORMATION.replace("acoustic_loss = [0.0, 0.3]", "acoustic_loss = [0.0, 3.0]"),
                "team.acoustic_loss",
                "<= 1",
            ),
            (
                FORMATION.replace(
                    "gps = [\"rtk\", \"consumer\"]",
                    "gps = [\"rtk\", \"phone\"]",
                ),
                "team.gps",
                "unknown variant",
            ),
            (
                FORMATION.replace("base = \"soares-freshwater\"", "base = \"demo\""),
                "team",
                "no vehicle flying a formation_follower",
            ),
        ];
        for (text, key, what) in cases {
            let e = formation(&text).map(|_| ()).unwrap_err().to_string();
            assert!(e.contains(key) && e.contains(what), "{key}: {e}");
            assert!(e.contains("formation.family.toml"), "{e}");
        }
    }
}
