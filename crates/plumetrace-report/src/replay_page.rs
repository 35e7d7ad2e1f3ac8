//! The replay page: one self-contained HTML file that plays a mission in a browser.
//!
//! The page embeds its data as JSON (`<script type="application/json">`) and its script and
//! style inline; a content security policy forbids every request, so it works offline and from
//! a file. It draws the op-area, subregions, obstacles, every vehicle's true and estimated track
//! up to the current time coloured by behaviour, detections, lost points, reference targets,
//! links between vehicles when messages arrive, declarations, navigation fixes, faults and
//! aborts; the plume as a concentration raster sampled during the run with the flow as arrows;
//! a time slider with play/pause, speed, zoom (wheel) and pan (drag); and a panel with the
//! readings and the behaviour in control against time.
//!
//! The page's state is readable from the DOM for tests: `<body>` carries `data-loaded`,
//! `data-t` (current time, s), `data-t-end`, `data-frames` (animation frames drawn),
//! `data-vehicles`, `data-behaviour` (the first planned vehicle's behaviour at the current
//! time), `data-ended` and `data-blocked` (requests the security policy refused).
//! The address's fragment sets the start: `#speed=N` (simulated seconds per second),
//! `#t=S` (start time), `#paused`.
//!
//! [`PageData`] is what the page shows; it is made from a flown mission
//! ([`PageData::from_run`]) or built by hand (a replayed log, which has no truth and no plume).

use crate::error::ReportError;
use crate::figure::style::{behaviour_colour, behaviour_label};
use plumetrace_core::{BehaviourKind, Vec2};
use plumetrace_log::snapshot::{Replayed, same};
use plumetrace_mission::{EventKind, EventRecord, MissionRun, PlumeFrames, lost_points};
use serde::Serialize;
use serde_json::{Value, json};
use std::collections::BTreeMap;

/// The page template; `__PLUMETRACE_DATA__` is replaced by the data.
const TEMPLATE: &str = include_str!("replay_page.html");

/// Track points kept per vehicle at most (the interval between kept points grows to match).
pub const MAX_TRACK_POINTS: usize = 20_000;

/// A vehicle's track as the page shows it (parallel arrays, one entry per kept point).
#[derive(Debug, Clone, Default, Serialize)]
pub struct PageTrack {
    /// Time, s.
    pub t: Vec<f64>,
    /// True position, m (empty when unknown, as in a replayed log).
    pub tx: Vec<f64>,
    /// True position, m.
    pub ty: Vec<f64>,
    /// Estimated position, m (empty when the vehicle has no position estimate).
    pub ex: Vec<f64>,
    /// Estimated position, m.
    pub ey: Vec<f64>,
    /// Behaviour in control: an index into [`PageData`]'s behaviour list, -1 for none.
    pub b: Vec<i8>,
    /// Highest reading since the previous kept point, V.
    pub r: Vec<f64>,
    /// Whether any reading since the previous kept point was a detection (0/1).
    pub d: Vec<u8>,
}

/// One vehicle on the page.
#[derive(Debug, Clone, Serialize)]
pub struct PageVehicle {
    /// Name.
    pub name: String,
    /// `auv` or `surface`.
    pub kind: String,
    /// Its planner's kind, if any.
    pub planner: Option<String>,
    /// Fault windows: start, end (s) and what was wrong.
    pub faults: Vec<(f64, f64, String)>,
    /// Its track.
    pub track: PageTrack,
    /// Its sensor's unit (`V`, `ppt`; empty when the source does not say, as in a log).
    pub unit: String,
}

/// Where a replayed planner first decided otherwise than the logged one.
#[derive(Debug, Clone, Serialize)]
pub struct PageDivergence {
    /// When, s.
    pub t_s: f64,
    /// Which vehicle.
    pub vehicle: u32,
    /// Where it was (its logged estimate), m.
    pub pos_m: [f64; 2],
}

/// The plume sampled during the run: a level (0-255, square root of the concentration over the
/// run's maximum) per grid point and frame, base64, and the flow on a coarser grid.
#[derive(Debug, Clone, Serialize)]
pub struct PagePlume {
    /// Grid bounds, m: west, east, south, north.
    pub bounds: [f64; 4],
    /// Concentration grid size.
    pub nx: usize,
    /// Concentration grid size.
    pub ny: usize,
    /// Flow grid size.
    pub flow_nx: usize,
    /// Flow grid size.
    pub flow_ny: usize,
    /// Height of the sampled plane above the seabed, m.
    pub z_m: f64,
    /// The concentration that level 255 stands for.
    pub max_concentration: f64,
    /// Frame times, s.
    pub t: Vec<f64>,
    /// Levels, one base64 string per frame (row by row from the south-west).
    pub levels: Vec<String>,
    /// Flow per frame: east, north, east, north, ... m/s.
    pub flow: Vec<Vec<f64>>,
}

/// Everything the page shows.
#[derive(Debug, Clone, Serialize)]
pub struct PageData {
    /// Heading of the page.
    pub title: String,
    /// A line under it (outcome, declaration error, ...).
    pub subtitle: String,
    /// End of the mission, s.
    pub t_end: f64,
    /// Op-area polygon.
    pub op_area: Vec<[f64; 2]>,
    /// Subregions.
    pub subregions: Vec<Vec<[f64; 2]>>,
    /// Obstacle outlines.
    pub obstacles: Vec<Vec<[f64; 2]>>,
    /// True sources (empty when unknown).
    pub sources: Vec<[f64; 2]>,
    /// Behaviours: serde name, label and colour (`#rrggbb`), indexed by [`PageTrack::b`].
    pub behaviours: Vec<(String, String, String)>,
    /// Vehicles.
    pub vehicles: Vec<PageVehicle>,
    /// Events as in `events.jsonl` (`t_s`, `vehicle`, `event` and its fields).
    pub events: Vec<Value>,
    /// The plume, if sampled.
    pub plume: Option<PagePlume>,
    /// A replayed log's page.
    pub replayed: bool,
    /// A replayed log: the first decision that differs from the logged one.
    pub divergence: Option<PageDivergence>,
}

/// Rounds to `digits` decimals (shorter JSON).
fn round(x: f64, digits: i32) -> f64 {
    let k = 10f64.powi(digits);
    let r = (x * k).round() / k;
    if r.is_finite() { r } else { 0.0 }
}

fn xy(p: &Vec2) -> [f64; 2] {
    [round(p.x, 2), round(p.y, 2)]
}

/// The behaviour list of every page.
fn behaviours() -> Vec<(String, String, String)> {
    BehaviourKind::ALL
        .iter()
        .map(|&b| {
            let c = behaviour_colour(b);
            (
                plumetrace_core::variant_name(&b).unwrap_or("?").to_string(),
                behaviour_label(b).to_string(),
                format!("#{:02x}{:02x}{:02x}", c.0, c.1, c.2),
            )
        })
        .collect()
}

/// The index of `b` in every page's behaviour list ([`PageData::behaviours`]), -1 for none.
pub fn behaviour_index(b: Option<BehaviourKind>) -> i8 {
    b.and_then(|b| BehaviourKind::ALL.iter().position(|&k| k == b))
        .map_or(-1, |i| i as i8)
}

/// Base64 (standard alphabet, padded).
fn base64(bytes: &[u8]) -> String {
    const ABC: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &b)| n | (u32::from(b) << (16 - 8 * i)));
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(char::from(ABC[((n >> (18 - 6 * k)) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

impl PagePlume {
    /// The frames as the page stores them.
    pub fn from_frames(f: &PlumeFrames) -> Option<Self> {
        if f.frames.is_empty() {
            return None;
        }
        let max = f
            .frames
            .iter()
            .flat_map(|fr| fr.concentration.iter())
            .copied()
            .filter(|c| c.is_finite())
            .fold(0.0f32, f32::max);
        let levels = f
            .frames
            .iter()
            .map(|fr| {
                let bytes: Vec<u8> = fr
                    .concentration
                    .iter()
                    .map(|&c| {
                        if max > 0.0 && c > 0.0 {
                            ((c / max).sqrt() * 255.0).round().clamp(0.0, 255.0) as u8
                        } else {
                            0
                        }
                    })
                    .collect();
                base64(&bytes)
            })
            .collect();
        let g = f.grid;
        Some(PagePlume {
            bounds: [g.x_min_m, g.x_max_m, g.y_min_m, g.y_max_m].map(|v| round(v, 2)),
            nx: g.nx,
            ny: g.ny,
            flow_nx: f.flow_grid.nx,
            flow_ny: f.flow_grid.ny,
            z_m: g.z_m,
            max_concentration: f64::from(max),
            t: f.frames.iter().map(|fr| round(fr.t_s, 1)).collect(),
            levels,
            flow: f
                .frames
                .iter()
                .map(|fr| {
                    fr.flow_mps
                        .iter()
                        .flat_map(|v| [round(f64::from(v[0]), 3), round(f64::from(v[1]), 3)])
                        .collect()
                })
                .collect(),
        })
    }
}

impl PageTrack {
    /// Adds a point; `reading` and `detection` are folded into the last kept point when this one
    /// is not kept (so thinning never hides a detection).
    #[allow(clippy::too_many_arguments)]
    fn push(
        &mut self,
        keep: bool,
        t: f64,
        truth: Option<Vec2>,
        est: Option<Vec2>,
        behaviour: Option<BehaviourKind>,
        reading: f64,
        detection: bool,
    ) {
        if !keep && let (Some(r), Some(d)) = (self.r.last_mut(), self.d.last_mut()) {
            *r = r.max(round(reading, 3));
            *d |= u8::from(detection);
            return;
        }
        self.t.push(round(t, 1));
        if let Some(p) = truth {
            self.tx.push(round(p.x, 2));
            self.ty.push(round(p.y, 2));
        }
        if let Some(p) = est {
            self.ex.push(round(p.x, 2));
            self.ey.push(round(p.y, 2));
        }
        self.b.push(behaviour_index(behaviour));
        self.r.push(round(reading, 3));
        self.d.push(u8::from(detection));
    }
}

/// One row for [`tracks`]: vehicle, time (s), true and estimated position (m, if known),
/// behaviour, reading (V), detection.
pub type TrackRow = (
    u32,
    f64,
    Option<Vec2>,
    Option<Vec2>,
    Option<BehaviourKind>,
    f64,
    bool,
);

/// Tracks of `n` vehicles from rows in time order (see [`TrackRow`]), keeping a point at least
/// every `interval_s` (and never more than [`MAX_TRACK_POINTS`] per vehicle over `t_end`) and at
/// every behaviour switch.
pub fn tracks(
    n: usize,
    rows: impl Iterator<Item = TrackRow>,
    t_end: f64,
    interval_s: f64,
) -> Vec<PageTrack> {
    let every = interval_s.max(t_end / MAX_TRACK_POINTS as f64);
    let mut out = vec![PageTrack::default(); n];
    let mut next = vec![f64::NEG_INFINITY; n];
    for (v, t, truth, est, b, r, d) in rows {
        let k = v as usize;
        let Some(track) = out.get_mut(k) else {
            continue;
        };
        // A behaviour switch is kept too, so colours change where they did.
        let switched = track
            .b
            .last()
            .is_some_and(|&last| last != behaviour_index(b));
        let keep = t >= next[k] || switched;
        if keep {
            next[k] = t + every;
        }
        track.push(keep, t, truth, est, b, r, d);
    }
    out
}

impl PageData {
    /// The page of a flown mission (its trajectory, events and plume frames as recorded).
    pub fn from_run(run: &MissionRun, title: &str) -> Self {
        let s = &run.summary;
        let t_end = s.ended.t_s;
        let rows = run.trajectory.iter().map(|r| {
            (
                r.vehicle,
                r.t_s,
                Some(Vec2::new(r.true_x_m, r.true_y_m)),
                r.est_x_m.zip(r.est_y_m).map(|(x, y)| Vec2::new(x, y)),
                r.behaviour,
                r.reading_v,
                r.detection,
            )
        });
        let tracks = tracks(run.vehicles.len(), rows, t_end, 1.0);
        let vehicles = run
            .vehicles
            .iter()
            .zip(tracks)
            .map(|(v, track)| PageVehicle {
                name: v.name.clone(),
                kind: plumetrace_core::variant_name(&v.kind)
                    .unwrap_or("?")
                    .to_string(),
                planner: v.planner.map(|k| k.name().to_string()),
                faults: v
                    .faults
                    .iter()
                    .map(|f| (f.start_s, f.end_s, f.what.to_string()))
                    .collect(),
                track,
                unit: v.reading_unit.to_string(),
            })
            .collect();
        let result = match &s.first_declaration {
            Some(d) if s.sources.len() <= 1 => format!(
                "declared at {:.0} s, {:.1} m from the source",
                d.t_s, d.error_m
            ),
            Some(_) => format!(
                "{} of {} sources located",
                s.sources_located,
                s.sources.len()
            ),
            None => "no source declared".into(),
        };
        // The outcome's word once: "declared at 702 s, ..." rather than "declared: declared at".
        let outcome = s.outcome.name();
        let result = if result.starts_with(outcome) {
            result
        } else {
            format!("{outcome}: {result}")
        };
        PageData {
            title: title.to_string(),
            subtitle: format!(
                "{result}; ended at {:.0} s ({}); seed {}",
                t_end,
                plumetrace_core::variant_name(&s.ended.reason).unwrap_or("?"),
                s.seed
            ),
            t_end: round(t_end, 1),
            op_area: run.op_area.iter().map(xy).collect(),
            subregions: run
                .subregions
                .iter()
                .map(|r| r.iter().map(xy).collect())
                .collect(),
            obstacles: run
                .obstacles
                .iter()
                .map(|o| o.iter().map(xy).collect())
                .collect(),
            sources: run.sources.iter().map(|p| xy(&p.xy())).collect(),
            behaviours: behaviours(),
            vehicles,
            events: events_json(&run.events),
            plume: run.plume_frames.as_ref().and_then(PagePlume::from_frames),
            replayed: false,
            divergence: None,
        }
    }

    /// A page without truth or plume (e.g. a replayed log): geometry, vehicles (names, kinds,
    /// planners, tracks) and events.
    pub fn bare(
        title: &str,
        subtitle: &str,
        op_area: &[Vec2],
        subregions: &[Vec<Vec2>],
        vehicles: Vec<PageVehicle>,
        events: &[EventRecord],
    ) -> Self {
        let t_end = vehicles
            .iter()
            .filter_map(|v| v.track.t.last().copied())
            .fold(0.0, f64::max);
        PageData {
            title: title.into(),
            subtitle: subtitle.into(),
            t_end,
            op_area: op_area.iter().map(xy).collect(),
            subregions: subregions
                .iter()
                .map(|r| r.iter().map(xy).collect())
                .collect(),
            obstacles: Vec::new(),
            sources: Vec::new(),
            behaviours: behaviours(),
            vehicles,
            events: events_json(events),
            plume: None,
            replayed: false,
            divergence: None,
        }
    }

    /// The page as one HTML file.
    pub fn html(&self) -> Result<String, ReportError> {
        if let Some(at) = plumetrace_core::first_non_finite(self) {
            return Err(ReportError::NonFinite(at));
        }
        let data = serde_json::to_string(self).map_err(ReportError::Encode)?;
        // Inside <script>, "</script" would end the element and "<!--" change how it is read:
        // '<' only occurs inside JSON strings, where "\u003c" stands for it.
        let data = data.replace('<', "\\u003c");
        let title = html_escape(&self.title);
        Ok(TEMPLATE
            .replacen("__PLUMETRACE_TITLE__", &title, 1)
            .replacen("__PLUMETRACE_DATA__", &data, 1))
    }
}

/// Collects a replayed log ([`plumetrace_log::snapshot::replay_with`]) into a page: each vehicle's
/// estimated track as logged, its readings, and the *replayed* planner's behaviours and events
/// (so a page of a log replayed with another configuration shows what that one would have
/// decided along the logged track). A log holds no truth and no plume.
#[derive(Debug, Default)]
pub struct LogPageBuilder {
    rows: Vec<TrackRow>,
    events: Vec<EventRecord>,
    behaviour: std::collections::BTreeMap<u32, BehaviourKind>,
    vehicles: std::collections::BTreeMap<u32, (String, String, Option<String>)>,
    geometry: Option<(Vec<Vec2>, Vec<Vec<Vec2>>)>,
    divergence: Option<PageDivergence>,
}

impl LogPageBuilder {
    /// Takes one replayed decision.
    pub fn add(&mut self, r: Replayed<'_>) {
        if self.geometry.is_none() {
            for v in &r.header.vehicles {
                let kind = v
                    .planner
                    .parse::<toml::Table>()
                    .ok()
                    .and_then(|t| t.get("kind").and_then(|k| k.as_str()).map(str::to_string));
                self.vehicles.insert(
                    v.id,
                    (
                        v.name.clone(),
                        plumetrace_core::variant_name(&v.context.vehicle_kind)
                            .unwrap_or("?")
                            .to_string(),
                        kind,
                    ),
                );
            }
            self.geometry = r.header.vehicles.first().map(|v| {
                let g = &v.context.geometry;
                (
                    g.op_area_vertices().to_vec(),
                    g.subregions.iter().map(|a| a.vertices().to_vec()).collect(),
                )
            });
        }
        let (l, d) = (r.line, r.replayed);
        let t = l.snapshot.time_s;
        let v = l.vehicle;
        if self.divergence.is_none() && !same(d, &l.decision) {
            // Where the vehicle believed it was (the origin when it had no estimate).
            let p = l.snapshot.nav.pos_m.unwrap_or_default();
            self.divergence = Some(PageDivergence {
                t_s: round(t, 1),
                vehicle: v,
                pos_m: [round(p.x, 2), round(p.y, 2)],
            });
        }
        if let Some(b) = d
            .events
            .iter()
            .rev()
            .find_map(plumetrace_core::PlannerEvent::behaviour)
        {
            self.behaviour.insert(v, b);
        }
        let reading = l
            .snapshot
            .chem
            .iter()
            .map(|c| c.reading)
            .filter(|r| r.is_finite())
            .fold(f64::NEG_INFINITY, f64::max);
        let detection = r.threshold_v.is_some_and(|th| reading > th);
        self.rows.push((
            v,
            t,
            None,
            l.snapshot.nav.pos_m,
            self.behaviour.get(&v).copied(),
            if reading.is_finite() { reading } else { 0.0 },
            detection,
        ));
        self.events.extend(d.events.iter().map(|e| EventRecord {
            t_s: t,
            vehicle: v,
            event: EventKind::Planner(e.clone()),
        }));
        self.events.extend(d.telemetry.iter().map(|e| EventRecord {
            t_s: t,
            vehicle: v,
            event: EventKind::Telemetry(e.clone()),
        }));
    }

    /// The page.
    pub fn page(self, title: &str, subtitle: &str) -> PageData {
        let n = self
            .vehicles
            .keys()
            .chain(self.rows.iter().map(|r| &r.0))
            .max()
            .map_or(0, |&m| m as usize + 1);
        let t_end = self.rows.iter().map(|r| r.1).fold(0.0, f64::max);
        let tracks = tracks(n, self.rows.into_iter(), t_end, 1.0);
        let vehicles = tracks
            .into_iter()
            .enumerate()
            .map(|(k, track)| {
                let (name, kind, planner) = self
                    .vehicles
                    .get(&(k as u32))
                    .cloned()
                    .unwrap_or_else(|| (format!("vehicle {k}"), "?".into(), None));
                PageVehicle {
                    name,
                    kind,
                    planner,
                    faults: Vec::new(),
                    track,
                    unit: String::new(),
                }
            })
            .collect();
        let (op_area, subregions) = self.geometry.unwrap_or_default();
        let mut page = PageData::bare(
            title,
            subtitle,
            &op_area,
            &subregions,
            vehicles,
            &self.events,
        );
        page.replayed = true;
        page.divergence = self.divergence;
        page
    }
}

/// Events as JSON values, numbers rounded for size; whole source-map rasters are left out (the
/// page does not draw them, and each is a value per map cell). A lost point that its planner
/// moved carries its moves, `moved: [[t_s, x_m, y_m], ...]`, so that the page draws it where it
/// was at the time shown.
fn events_json(events: &[EventRecord]) -> Vec<Value> {
    let mut moves: BTreeMap<usize, Vec<Value>> = BTreeMap::new();
    for l in lost_points(events)
        .into_iter()
        .filter(|l| !l.moves.is_empty())
    {
        let m = l.moves.iter().map(|(t, p)| json!([round(*t, 1), p.x, p.y]));
        moves.insert(l.saved, m.collect());
    }
    events
        .iter()
        .enumerate()
        .filter(|(_, e)| {
            !matches!(
                e.event,
                EventKind::Telemetry(plumetrace_core::Telemetry::SourceMapRaster { .. })
            )
        })
        .filter_map(|(k, e)| Some((k, serde_json::to_value(e).ok()?)))
        .map(|(k, mut v)| {
            if let Some(t) = v.get("t_s").and_then(Value::as_f64) {
                v["t_s"] = json!(round(t, 1));
            }
            if let Some(m) = moves.remove(&k) {
                v["moved"] = Value::Array(m);
            }
            v
        })
        .collect()
}

/// Text safe inside HTML.
fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The replay page of a flown mission.
pub fn replay_page(run: &MissionRun, title: &str) -> Result<String, ReportError> {
    PageData::from_run(run, title).html()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_moved_lost_point_carries_its_moves_and_the_raster_is_left_out() {
        use plumetrace_core::{PlannerEvent, Telemetry};
        let at = |t_s: f64, event: EventKind| EventRecord {
            t_s,
            vehicle: 0,
            event,
        };
        let p = |x: f64, y: f64| Vec2::new(x, y);
        let lost = |t_s: f64, x: f64, y: f64| {
            at(
                t_s,
                EventKind::Planner(PlannerEvent::LostPoint { pos_m: p(x, y) }),
            )
        };
        let raster = Telemetry::SourceMapRaster {
            origin_m: p(0.0, 0.0),
            cell_m: 5.0,
            nx: 1,
            ny: 1,
            log10_p: vec![0.0],
        };
        let moved = PlannerEvent::LostPointMoved {
            from_m: p(5.0, 5.0),
            to_m: p(6.5, 4.25),
        };
        let events = [
            lost(10.0, 1.0, 2.0),
            at(20.0, EventKind::Telemetry(raster)),
            lost(30.0, 5.0, 5.0),
            at(300.04, EventKind::Planner(moved)),
        ];
        let v = events_json(&events);
        let kinds: Vec<&str> = v.iter().filter_map(|e| e["event"].as_str()).collect();
        assert_eq!(kinds, ["lost_point", "lost_point", "lost_point_moved"]);
        assert!(v[0].get("moved").is_none(), "{}", v[0]);
        assert_eq!(v[1]["moved"], json!([[300.0, 6.5, 4.25]]), "{}", v[1]);
        assert_eq!(v[2]["to_m"], json!([6.5, 4.25]));
    }

    #[test]
    fn base64_matches_the_rfc_vectors() {
        // RFC 4648, section 10.
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), coded, "{plain:?}");
        }
        assert_eq!(base64(&[0xff, 0x00, 0x80]), "/wCA");
    }

    #[test]
    fn thinning_keeps_every_detection_and_every_behaviour_switch() {
        let rows = (0..1000).map(|k| {
            let t = f64::from(k) * 0.1;
            let b = if k < 500 {
                BehaviourKind::Find
            } else {
                BehaviourKind::TrackIn
            };
            (
                0u32,
                t,
                Some(Vec2::new(t, 0.0)),
                Some(Vec2::new(t, 1.0)),
                Some(b),
                if k == 333 { 4.0 } else { 0.1 },
                k == 333,
            )
        });
        let t = tracks(1, rows, 100.0, 1.0);
        let tr = &t[0];
        // 100 s at one point a second, plus the switch at 50.0 s (a kept point itself).
        assert_eq!(tr.t.len(), 100);
        assert_eq!(tr.t.len(), tr.ex.len());
        assert_eq!(tr.d.iter().filter(|&&d| d == 1).count(), 1);
        assert_eq!(tr.r.iter().copied().fold(0.0, f64::max), 4.0);
        let find = behaviour_index(Some(BehaviourKind::Find));
        let track_in = behaviour_index(Some(BehaviourKind::TrackIn));
        let switch = tr.b.iter().position(|&b| b == track_in);
        assert_eq!(switch.map(|k| tr.t[k]), Some(50.0));
        assert!(tr.b[..switch.unwrap_or(0)].iter().all(|&b| b == find));
    }

    #[test]
    fn the_data_cannot_end_the_script_element() {
        let page = PageData::bare(
            "a </script><script>alert(1)</script> title",
            "</script>",
            &[
                Vec2::new(0.0, 0.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(0.0, 1.0),
            ],
            &[],
            Vec::new(),
            &[],
        );
        let html = page.html().unwrap_or_default();
        assert_eq!(
            html.matches("</script>").count(),
            3,
            "only the page's own three (the head's counter, the data, the script)"
        );
        assert!(!html.contains("<script>alert"));
    }
}
