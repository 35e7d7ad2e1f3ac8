//! The mission's key numbers (`summary.json`): how it ended, every declaration with its errors
//! against the true sources, and per-vehicle paths.
//!
//! Mission-level path and detection numbers are those of the *lead* vehicle: the one that made
//! the first declaration, or the first vehicle with a planner when nothing was declared.

use crate::outcome::{EndReason, MissionEnd, Outcome, VehicleStatus};
use crate::record::VehicleTrack;
use plumetrace_core::{BehaviourKind, DeclarationKind, Heading, Vec2, Vec3, VehicleKind};
use plumetrace_planner::PlannerKind;
use serde::Serialize;

/// A declaration with its errors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DeclarationRecord {
    /// Time, s.
    pub t_s: f64,
    /// The declaring vehicle.
    pub vehicle: u32,
    /// Declared position.
    pub x_m: f64,
    /// Declared position.
    pub y_m: f64,
    /// Nearest true source.
    pub source_x_m: f64,
    /// Nearest true source.
    pub source_y_m: f64,
    /// Distance to it, m.
    pub error_m: f64,
    /// Along the mean flow at the source (positive: declared downflow of it), m.
    pub error_along_m: f64,
    /// Across the flow (positive: to the right looking downflow), m.
    pub error_cross_m: f64,
    /// What made the planner declare.
    pub rule: DeclarationKind,
}

/// A true source and how well the declarations found it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SourceRecord {
    /// Position, m.
    pub x_m: f64,
    /// Position, m.
    pub y_m: f64,
    /// Declarations nearer to this source than to any other (edge declarations of a
    /// multi-source mission included).
    pub declarations: usize,
    /// Distance of the nearest declaration, m (`None`: none).
    pub nearest_error_m: Option<f64>,
    /// A declaration lies within the mission's success radius (`success_radius_m`).
    pub located: bool,
}

/// One vehicle's part.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VehicleSummary {
    /// Index.
    pub id: u32,
    /// Name.
    pub name: String,
    /// AUV or surface craft.
    pub kind: VehicleKind,
    /// Its planner's kind (`None`: no planner).
    pub planner: Option<PlannerKind>,
    /// Where it stands at the end.
    pub status: VehicleStatus,
    /// Distance over ground, m.
    pub path_length_m: f64,
    /// Time of its planner's first detection, s.
    pub first_detection_s: Option<f64>,
    /// Its declarations.
    pub declarations: usize,
    /// The longest time it spent in one behaviour without a reading above its planner's
    /// detection threshold, s.
    pub longest_quiet_s: Option<f64>,
    /// That behaviour.
    pub longest_quiet_behaviour: Option<BehaviourKind>,
    /// The farthest its true position went outside the op-area, m.
    pub max_outside_m: f64,
    /// When it reached the seabed (a seabed from `[bathymetry]`; its status is then
    /// `collided`), s; absent when it did not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hit_bottom_s: Option<f64>,
}

/// The mission's key numbers.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Scenario name.
    pub scenario: String,
    /// Run seed.
    pub seed: u64,
    /// What the mission came to.
    pub outcome: Outcome,
    /// Why and when it stopped.
    pub ended: MissionEnd,
    /// Whether any source was declared.
    pub declared: bool,
    /// Whether the mission found what it looked for: with one true source, its first
    /// declaration lies within `success_radius_m` of it; with several, or with subregions
    /// searched in turn, every source is located.
    pub success: bool,
    /// The first declaration (its time against `ended.t_s` tells which came first).
    pub first_declaration: Option<DeclarationRecord>,
    /// Time of the lead vehicle's first detection, s.
    pub first_detection_s: Option<f64>,
    /// Distance over ground of the lead vehicle, m.
    pub path_length_m: f64,
    /// Distance the lead vehicle travelled from its first detection to its first declaration,
    /// m.
    pub trace_length_m: Option<f64>,
    /// Straight line from the lead vehicle's first detection to the source, m.
    pub detection_to_source_m: Option<f64>,
    /// Mission time, s.
    pub sim_time_s: f64,
    /// Every declaration, in time order.
    pub declarations: Vec<DeclarationRecord>,
    /// A source counts as located when a declaration lies within this distance of it, m (the
    /// scenario's `mission.success_radius_m`).
    pub success_radius_m: f64,
    /// Sources with a declaration within `success_radius_m`.
    pub sources_located: usize,
    /// Every true source, with its nearest declaration.
    pub sources: Vec<SourceRecord>,
    /// Subregions searched in turn (`mission.subregions`; absent without them). A search of
    /// more than one declares once per subregion, at a source or at the subregion's edge, so it
    /// is judged by the sources it located, not by its first declaration.
    #[serde(skip_serializing_if = "is_zero")]
    pub subregions: usize,
    /// The longest any vehicle with a planner spent in one behaviour without a detection, s.
    pub longest_quiet_s: Option<f64>,
    /// The farthest any vehicle with a planner went outside the op-area (true position), m.
    pub max_outside_m: f64,
    /// Every vehicle.
    pub vehicles: Vec<VehicleSummary>,
    /// What the team did together (missions with two or more planners).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub team: Option<crate::team::TeamSummary>,
}

/// What the summary is made from.
pub(crate) struct SummaryInput<'a> {
    pub scenario: String,
    pub seed: u64,
    pub end: MissionEnd,
    pub first_failure: Option<Outcome>,
    pub statuses: &'a [VehicleStatus],
    pub tracks: &'a [VehicleTrack],
    pub vehicles: Vec<(String, VehicleKind, Option<PlannerKind>)>,
    pub sources: &'a [Vec3],
    pub success_radius_m: f64,
    pub subregions: usize,
    pub mean_flow_mps: Vec2,
    pub team: Option<crate::team::TeamSummary>,
}

impl Summary {
    pub(crate) fn new(i: SummaryInput<'_>) -> Self {
        let mut declarations: Vec<DeclarationRecord> = i
            .tracks
            .iter()
            .enumerate()
            .flat_map(|(v, t)| {
                t.declarations
                    .iter()
                    .map(move |(at, p, rule)| (*at, v, *p, rule.clone()))
            })
            .map(|(t, v, p, rule)| {
                declaration_record(t, v as u32, p, rule, i.sources, i.mean_flow_mps)
            })
            .collect();
        // Time order; a stable sort keeps vehicle order within a step.
        declarations.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        let has_planner: Vec<bool> = i.vehicles.iter().map(|v| v.2.is_some()).collect();
        let planned = i
            .statuses
            .iter()
            .zip(&has_planner)
            .filter(|(_, p)| **p)
            .map(|(s, _)| *s);
        let all_finished =
            planned.clone().count() > 0 && planned.clone().all(|s| s == VehicleStatus::Finished);
        let outcome =
            crate::outcome::judge(i.first_failure, !declarations.is_empty(), all_finished);
        let first = declarations.first().cloned();
        let lead = first
            .as_ref()
            .map(|d| d.vehicle as usize)
            .unwrap_or_else(|| has_planner.iter().position(|p| *p).unwrap_or(0));
        let track = i.tracks.get(lead).cloned().unwrap_or_default();
        let src0 = first
            .as_ref()
            .map(|r| Vec2::new(r.source_x_m, r.source_y_m))
            .or_else(|| i.sources.first().map(|s| s.xy()));
        let sources = source_records(i.sources, &declarations, i.success_radius_m);
        let vehicles = i
            .vehicles
            .into_iter()
            .enumerate()
            .map(|(k, (name, kind, planner))| {
                let t = i.tracks.get(k).cloned().unwrap_or_default();
                VehicleSummary {
                    id: k as u32,
                    name,
                    kind,
                    planner,
                    status: i
                        .statuses
                        .get(k)
                        .copied()
                        .unwrap_or(VehicleStatus::NoPlanner),
                    path_length_m: t.path_length_m,
                    first_detection_s: t.first_detection.map(|d| d.0),
                    declarations: t.declarations.len(),
                    longest_quiet_s: t.longest_quiet.map(|q| q.0),
                    longest_quiet_behaviour: t.longest_quiet.map(|q| q.1),
                    max_outside_m: t.max_outside_m,
                    hit_bottom_s: t.hit_bottom_s,
                }
            })
            .collect::<Vec<_>>();
        let with_planner = vehicles.iter().filter(|v| v.planner.is_some());
        let longest_quiet_s = with_planner
            .clone()
            .filter_map(|v| v.longest_quiet_s)
            .max_by(f64::total_cmp);
        let max_outside_m = with_planner.map(|v| v.max_outside_m).fold(0.0, f64::max);
        let mut summary = Summary {
            scenario: i.scenario,
            seed: i.seed,
            outcome,
            ended: i.end,
            declared: first.is_some(),
            success: false,
            first_detection_s: track.first_detection.map(|d| d.0),
            path_length_m: track.path_length_m,
            trace_length_m: first.as_ref().map(|_| track.trace_length_m),
            detection_to_source_m: track
                .first_detection
                .zip(src0)
                .map(|((_, p), s)| (p - s).norm()),
            sim_time_s: i.end.t_s,
            first_declaration: first,
            declarations,
            success_radius_m: i.success_radius_m,
            sources_located: sources.iter().filter(|s| s.located).count(),
            sources,
            subregions: i.subregions,
            longest_quiet_s,
            max_outside_m,
            vehicles,
            team: i.team,
        };
        summary.success = summary.success_within(i.success_radius_m);
        summary
    }

    /// Sources with a declaration within `radius_m` of them.
    pub fn located_within(&self, radius_m: f64) -> usize {
        self.sources
            .iter()
            .filter(|src| src.nearest_error_m.is_some_and(|e| e <= radius_m))
            .count()
    }

    /// Judged by the sources located rather than by the first declaration: several sources,
    /// or subregions searched in turn.
    pub fn judged_by_sources(&self) -> bool {
        self.sources.len() > 1 || self.subregions > 1
    }

    /// Whether the mission succeeded with this success radius: with one true source, its first
    /// declaration lies within `radius_m` of it; with several (or subregions searched in turn),
    /// every source has a declaration within `radius_m`.
    pub fn success_within(&self, radius_m: f64) -> bool {
        if self.judged_by_sources() {
            self.located_within(radius_m) == self.sources.len()
        } else {
            self.first_declaration
                .as_ref()
                .is_some_and(|d| d.error_m <= radius_m)
        }
    }

    /// Whether the mission succeeded, in words, with the error and the success radius:
    /// `located: declared 8.2 m from the source (success radius 50 m)`, `NOT located: declared
    /// 258.5 m from the source (success radius 50 m)`, `NOT located: no declaration (time
    /// limit)`; with several sources, how many were located.
    pub fn verdict(&self) -> String {
        let word = if self.success {
            "located"
        } else {
            "NOT located"
        };
        let r = self.success_radius_m;
        let Some(first) = &self.first_declaration else {
            let why = plumetrace_core::variant_name(&self.ended.reason).unwrap_or("?");
            return format!("{word}: no declaration ({})", why.replace('_', " "));
        };
        if self.judged_by_sources() {
            format!(
                "{word}: {} of {} {} declared within the success radius ({r} m)",
                self.sources_located,
                self.sources.len(),
                if self.sources.len() == 1 {
                    "source"
                } else {
                    "sources"
                }
            )
        } else {
            format!(
                "{word}: declared {:.1} m from the source (success radius {r} m)",
                first.error_m
            )
        }
    }

    /// Whether the time limit stopped the mission.
    pub fn hit_time_limit(&self) -> bool {
        self.ended.reason == EndReason::TimeLimit
    }
}

fn declaration_record(
    t: f64,
    vehicle: u32,
    p: Vec2,
    rule: DeclarationKind,
    sources: &[Vec3],
    mean_flow: Vec2,
) -> DeclarationRecord {
    let src = nearest_source(p, sources).map_or(p, |i| sources[i].xy());
    let d = p - src;
    let along = Heading::of_vector(mean_flow).unwrap_or(Heading::NORTH);
    let u = along.unit();
    let right = along.turned_deg(90.0).unit();
    DeclarationRecord {
        t_s: t,
        vehicle,
        x_m: p.x,
        y_m: p.y,
        source_x_m: src.x,
        source_y_m: src.y,
        error_m: d.norm(),
        error_along_m: d.dot(&u),
        error_cross_m: d.dot(&right),
        rule,
    }
}

/// Index of the true source nearest to `p` (the first of equals).
fn nearest_source(p: Vec2, sources: &[Vec3]) -> Option<usize> {
    sources
        .iter()
        .enumerate()
        .min_by(|a, b| (a.1.xy() - p).norm().total_cmp(&(b.1.xy() - p).norm()))
        .map(|(i, _)| i)
}

/// Each true source with the declarations attributed to it (those nearest to it).
fn source_records(
    sources: &[Vec3],
    declarations: &[DeclarationRecord],
    radius_m: f64,
) -> Vec<SourceRecord> {
    let owner: Vec<Option<usize>> = declarations
        .iter()
        .map(|d| nearest_source(Vec2::new(d.x_m, d.y_m), sources))
        .collect();
    sources
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let mine: Vec<f64> = declarations
                .iter()
                .zip(&owner)
                .filter(|(_, o)| **o == Some(k))
                .map(|(d, _)| d.error_m)
                .collect();
            let nearest = mine.iter().copied().reduce(f64::min);
            SourceRecord {
                x_m: s.x,
                y_m: s.y,
                declarations: mine.len(),
                nearest_error_m: nearest,
                located: nearest.is_some_and(|e| e <= radius_m),
            }
        })
        .collect()
}

/// Serde's test for a count left out of `summary.json` when 0.
fn is_zero(n: &usize) -> bool {
    *n == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One vehicle's summary of a mission with one source at the origin, declared first 300 m
    /// away at a subregion's upflow edge and then 2 m from it, searching `subregions`.
    fn one_source_two_declarations(subregions: usize) -> Summary {
        let mut track = VehicleTrack::default();
        track.declarations = vec![
            (
                100.0,
                Vec2::new(0.0, 300.0),
                DeclarationKind::new("upflow_edge"),
            ),
            (
                900.0,
                Vec2::new(2.0, 0.0),
                DeclarationKind::new("along_flow"),
            ),
        ];
        Summary::new(SummaryInput {
            scenario: "s".into(),
            seed: 1,
            end: MissionEnd {
                reason: EndReason::PlannersDone,
                t_s: 1000.0,
            },
            first_failure: None,
            statuses: &[VehicleStatus::Finished],
            tracks: &[track],
            vehicles: vec![("auv".into(), VehicleKind::Auv, None)],
            sources: &[Vec3::new(0.0, 0.0, 0.0)],
            success_radius_m: 50.0,
            subregions,
            mean_flow_mps: Vec2::new(0.0, -0.2),
            team: None,
        })
    }

    #[test]
    fn a_search_of_subregions_is_judged_by_the_sources_it_located() {
        let plain = one_source_two_declarations(0);
        assert!(
            !plain.success,
            "one source: the first declaration, 300 m away"
        );
        assert!(
            plain.verdict().starts_with("NOT located: declared 300.0 m"),
            "{}",
            plain.verdict()
        );
        let json = serde_json::to_string(&plain).unwrap_or_default();
        assert!(!json.contains("subregions"), "{json}");
        let one = one_source_two_declarations(1);
        assert!(!one.success, "a single subregion is the op-area");
        let searched = one_source_two_declarations(4);
        assert!(searched.success);
        assert_eq!(
            searched.verdict(),
            "located: 1 of 1 source declared within the success radius (50 m)"
        );
        let json = serde_json::to_string(&searched).unwrap_or_default();
        assert!(json.contains("\"subregions\":4"), "{json}");
        // The campaign's columns: the edge declaration is off the source.
        let m =
            crate::metrics::RunMetrics::new(&searched, &crate::metrics::MetricContext::default());
        assert_eq!(
            (m.declarations, m.declarations_off_source, m.subregions),
            (2, 1, 4)
        );
        assert!(m.success);
        let m = crate::metrics::RunMetrics::new(&plain, &crate::metrics::MetricContext::default());
        assert_eq!((m.declarations_off_source, m.subregions), (1, 0));
        assert!(!m.success);
    }

    #[test]
    fn declarations_are_attributed_to_their_nearest_source() {
        let sources = [Vec3::new(300.0, 860.0, 0.0), Vec3::new(700.0, 820.0, 0.0)];
        let flow = Vec2::new(0.05, -0.25);
        let decl: Vec<DeclarationRecord> = [
            (
                100.0,
                Vec2::new(340.0, 550.0),
                DeclarationKind::new("upflow_edge"),
            ),
            (
                900.0,
                Vec2::new(298.0, 852.0),
                DeclarationKind::new("along_flow"),
            ),
            (
                1500.0,
                Vec2::new(305.0, 845.0),
                DeclarationKind::new("along_flow"),
            ),
        ]
        .iter()
        .map(|(t, p, rule)| declaration_record(*t, 0, *p, rule.clone(), &sources, flow))
        .collect();
        let recs = source_records(&sources, &decl, 50.0);
        assert_eq!(recs[0].declarations, 3, "the edge declaration counts too");
        assert_eq!(recs[0].nearest_error_m, Some(68f64.sqrt()));
        assert!(recs[0].located);
        assert_eq!(recs[1].declarations, 0);
        assert_eq!(recs[1].nearest_error_m, None);
        assert!(!recs[1].located);
        // Only the edge declaration: attributed, but 300 m away is not located.
        let recs = source_records(&sources, &decl[..1], 50.0);
        assert_eq!(recs[0].declarations, 1);
        assert!(recs[0].nearest_error_m.is_some_and(|e| e > 50.0) && !recs[0].located);
        assert_eq!(decl[0].rule, DeclarationKind::new("upflow_edge"));
    }

    #[test]
    fn errors_split_along_and_across_the_mean_flow() {
        // Flow towards East; declared 10 m East (downflow) and 3 m South (right of East).
        let r = declaration_record(
            1.0,
            0,
            Vec2::new(10.0, -3.0),
            DeclarationKind::new("along_flow"),
            &[Vec3::zeros()],
            Vec2::new(0.2, 0.0),
        );
        assert!((r.error_along_m - 10.0).abs() < 1e-12);
        assert!((r.error_cross_m - 3.0).abs() < 1e-12);
    }
}
