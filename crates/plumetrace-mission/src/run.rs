//! Running a mission and summarising it.

use crate::planner_config::{PlannerError, amp_params};
use plumetrace_core::{Heading, PlanStatus, Planner, PlannerEvent, Vec2, Vec3, VehicleKind};
use plumetrace_env::{EnvError, FlowField, GridSpec, MeanConcentrationGrid};
use plumetrace_guidance::OpArea;
use plumetrace_planner::Amp;
use plumetrace_scenario::BuiltScenario;
use plumetrace_scenario::config::PlannerKind;
use plumetrace_sim::{Incident, SimVehicle, StageTimes, World};
use serde::Serialize;

/// Why a mission could not run.
#[derive(Debug, thiserror::Error)]
pub enum MissionError {
    /// The scenario has no `[mission]`, `[planner]` or AUV.
    #[error("{0}")]
    NotAMission(String),
    /// A planner setting is bad.
    #[error(transparent)]
    Planner(#[from] PlannerError),
    /// The environment failed (a bad setting or a diverging flow).
    #[error(transparent)]
    Env(#[from] EnvError),
}

/// How a mission ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// A source was declared (and the mapping flown, if any).
    Declared,
    /// The planner finished without declaring (e.g. every subregion timed out).
    NoDeclaration,
    /// The time limit came first.
    TimedOut,
    /// The cage aborted the mission (far outside the op-area).
    AbortedByCage,
    /// The vehicle left the simulated domain.
    LeftDomain,
    /// The vehicle entered an obstacle.
    Collided,
}

impl Outcome {
    /// The name used in files.
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Declared => "declared",
            Outcome::NoDeclaration => "no_declaration",
            Outcome::TimedOut => "timed_out",
            Outcome::AbortedByCage => "aborted_by_cage",
            Outcome::LeftDomain => "left_domain",
            Outcome::Collided => "collided",
        }
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
    /// Estimated position, m.
    pub est_x_m: f64,
    /// Estimated position, m.
    pub est_y_m: f64,
    /// True heading, deg.
    pub heading_deg: f64,
    /// Water-relative speed, m/s.
    pub speed_mps: f64,
    /// Active behaviour.
    pub behaviour: &'static str,
    /// Latest chemical reading, V.
    pub reading_v: f64,
    /// Whether the latest sample was a detection.
    pub detection: bool,
}

/// One timestamped event.
#[derive(Debug, Clone, Serialize)]
pub struct EventRecord {
    /// Time, s.
    pub t_s: f64,
    /// Vehicle index.
    pub vehicle: u32,
    /// The event.
    #[serde(flatten)]
    pub event: EventKind,
}

/// Planner events plus what the world reports.
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum EventKind {
    /// From the planner.
    Planner(PlannerEvent),
    /// A navigation fix.
    Fix {
        /// Always "nav_fix".
        event: &'static str,
        /// Estimate jump, m.
        jump_m: f64,
        /// Estimate after the fix.
        to_m: Vec2,
    },
    /// An incident.
    Incident {
        /// Always "incident".
        event: &'static str,
        /// What happened.
        what: Incident,
    },
}

/// A declaration with its errors.
#[derive(Debug, Clone, Serialize)]
pub struct DeclarationRecord {
    /// Time, s.
    pub t_s: f64,
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
    /// The rule that declared it (`along_flow`, `along_and_cross_flow`, `upflow_edge`, ...).
    pub rule: &'static str,
}

/// A source counts as located when a declaration lies within this distance of it, m. The field
/// declarations were within 31 m of the sonar positions, and the plume of a bottom source reaches
/// a vehicle 1.5-2 m up only some tens of metres downflow.
pub const LOCATED_RADIUS_M: f64 = 50.0;

/// A true source and how well the declarations found it.
#[derive(Debug, Clone, Serialize)]
pub struct SourceRecord {
    /// Position, m.
    pub x_m: f64,
    /// Position, m.
    pub y_m: f64,
    /// Declarations nearer to this source than to any other (edge declarations of a
    /// multi-source mission included).
    pub declarations: usize,
    /// Distance of the nearest declaration, m (NaN if none).
    pub nearest_error_m: f64,
    /// A declaration lies within [`LOCATED_RADIUS_M`].
    pub located: bool,
}

/// The mission's key numbers (written as `summary.json`).
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Scenario name.
    pub scenario: String,
    /// Run seed.
    pub seed: u64,
    /// Outcome.
    pub outcome: &'static str,
    /// Whether a source was declared.
    pub declared: bool,
    /// First declared position (NaN if none).
    pub declared_x: f64,
    /// First declared position.
    pub declared_y: f64,
    /// Nearest true source to it (the first source if none declared).
    pub source_x: f64,
    /// Nearest true source.
    pub source_y: f64,
    /// Declaration error, m.
    pub error_m: f64,
    /// Along-flow error (positive downflow), m.
    pub error_along_m: f64,
    /// Crossflow error, m.
    pub error_cross_m: f64,
    /// Time of the first detection, s (NaN if none).
    pub first_detection_s: f64,
    /// Time of the first declaration, s (NaN if none).
    pub declaration_s: f64,
    /// Distance travelled over ground by the first AUV, m.
    pub path_length_m: f64,
    /// Distance it travelled from its first detection to the first declaration, m (NaN if none
    /// declared).
    pub trace_length_m: f64,
    /// Straight-line distance from the first detection to the source, m (NaN without detection).
    pub detection_to_source_m: f64,
    /// Mission time, s.
    pub sim_time_s: f64,
    /// Every declaration.
    pub declarations: Vec<DeclarationRecord>,
    /// Sources with a declaration within [`LOCATED_RADIUS_M`].
    pub sources_located: usize,
    /// Every true source, with its nearest declaration.
    pub sources: Vec<SourceRecord>,
}

/// Everything a mission produced.
#[derive(Debug)]
pub struct MissionRun {
    /// How it ended.
    pub outcome: Outcome,
    /// Key numbers.
    pub summary: Summary,
    /// Every step of every vehicle.
    pub trajectory: Vec<TrajectoryRow>,
    /// The event stream.
    pub events: Vec<EventRecord>,
    /// Wall time per stage.
    pub stage_times: StageTimes,
    /// Time-averaged concentration at the planner's altitude over the op-area, for the figure.
    pub mean_plume: MeanConcentrationGrid,
    /// True sources.
    pub sources: Vec<Vec3>,
    /// Op-area and subregions.
    pub op_area: Vec<Vec2>,
    /// Subregions.
    pub subregions: Vec<Vec<Vec2>>,
    /// Mean flow at the first source over the mission, m/s.
    pub mean_flow_mps: Vec2,
}

/// What a mission records besides its summary and events.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MissionOptions {
    /// Accumulate the time-averaged plume over the op-area for the figure (costs a grid of
    /// concentration queries every 20 s).
    pub mean_plume: bool,
    /// Keep every step of the trajectory (otherwise `trajectory` stays empty).
    pub trajectory: bool,
}

impl Default for MissionOptions {
    fn default() -> Self {
        MissionOptions {
            mean_plume: true,
            trajectory: true,
        }
    }
}

/// Runs a scenario's mission recording everything; `progress` is called with the mission time
/// now and then.
pub fn run_mission(
    sc: BuiltScenario,
    progress: &mut dyn FnMut(f64, f64),
) -> Result<MissionRun, MissionError> {
    run_mission_with(sc, MissionOptions::default(), progress)
}

/// Runs a scenario's mission recording what `options` asks for.
pub fn run_mission_with(
    sc: BuiltScenario,
    options: MissionOptions,
    progress: &mut dyn FnMut(f64, f64),
) -> Result<MissionRun, MissionError> {
    let BuiltScenario {
        name,
        seed,
        mut env,
        vehicles: setups,
        mission,
        planner,
        dt_s,
        depth_m,
        ..
    } = sc;
    let spec = mission
        .ok_or_else(|| MissionError::NotAMission("the scenario has no [mission] table".into()))?;
    let pc = planner
        .ok_or_else(|| MissionError::NotAMission("the scenario has no [planner] table".into()))?;
    let params = match pc.strategy {
        PlannerKind::Amp => amp_params(&pc)?,
    };
    let area = OpArea::new(spec.op_area.clone())
        .map_err(|e| MissionError::NotAMission(format!("mission.op_area: {e}")))?;
    let mut regions = Vec::new();
    for (k, r) in spec.subregions.iter().enumerate() {
        regions.push(
            OpArea::new(r.clone())
                .map_err(|e| MissionError::NotAMission(format!("mission.subregions[{k}]: {e}")))?,
        );
    }
    env.spin_up(spec.spinup_s, spec.spinup_dt_s)?;
    let sources: Vec<Vec3> = env
        .plume()
        .filaments()
        .map(|f| f.sources().iter().map(|s| s.pos_m).collect())
        .unwrap_or_default();
    let mut vehicles = Vec::new();
    let mut planners: Vec<Option<Box<dyn Planner>>> = Vec::new();
    for v in &setups {
        vehicles.push(SimVehicle::new(
            v.name.clone(),
            v.vehicle.clone(),
            v.nav,
            v.chem_sensor,
            v.flow_sensor,
            v.range_sensor,
            seed,
        ));
        planners.push(match v.vehicle.params.kind {
            VehicleKind::Auv => Some(Box::new(Amp::new(
                params,
                area.clone(),
                regions.clone(),
                Heading::from_deg(spec.prior_flow_toward_deg),
            ))),
            VehicleKind::Surface => None,
        });
    }
    let mut world = World::new(env, vehicles, dt_s, depth_m)?;

    // The figure's plume: time-averaged concentration at the planner's altitude, every 20 s.
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in &spec.op_area {
        (x0, x1, y0, y1) = (x0.min(p.x), x1.max(p.x), y0.min(p.y), y1.max(p.y));
    }
    let pad = 0.05 * (x1 - x0).max(y1 - y0);
    let d = world.env().domain();
    let grid = GridSpec {
        x_min_m: (x0 - pad).max(d.x_min_m),
        x_max_m: (x1 + pad).min(d.x_max_m),
        y_min_m: (y0 - pad).max(d.y_min_m),
        y_max_m: (y1 + pad).min(d.y_max_m),
        nx: 160,
        ny: (160.0 * (y1 - y0) / (x1 - x0).max(1e-9)).clamp(40.0, 400.0) as usize,
        z_m: params.altitude_m,
    };
    let mut mean_plume = MeanConcentrationGrid::new(grid, 0.0);
    let sample_every = (20.0 / dt_s).round().max(1.0) as u64;
    let mut flow_sum = Vec2::zeros();
    let mut flow_n = 0.0;

    let mut trajectory = Vec::new();
    let mut events = Vec::new();
    let mut behaviour: Vec<&'static str> = vec!["go_to"; setups.len()];
    let mut finished = vec![false; setups.len()];
    let mut outcome = None;
    let mut first_detection = f64::NAN;
    let mut first_detection_pos = None;
    let mut declarations: Vec<(f64, Vec2, &'static str)> = Vec::new();
    // Distance over ground of the first AUV, in total and from its first detection to its first
    // declaration (the traced path).
    let tracer = setups
        .iter()
        .position(|v| v.vehicle.params.kind == VehicleKind::Auv)
        .unwrap_or(0);
    let mut path_length_m = 0.0;
    let mut trace_length_m = 0.0;
    let mut last_pos: Option<Vec2> = None;
    let steps = (spec.time_limit_s / dt_s).round() as u64;
    for k in 0..steps {
        let t = world.time_s();
        let report = world.step(&mut planners, &mut |_, _| {})?;
        for (i, d) in report.decisions.iter().enumerate() {
            let Some(d) = d else { continue };
            for e in &d.events {
                match e {
                    PlannerEvent::Behaviour { name } => behaviour[i] = name,
                    PlannerEvent::Detection { pos_m } if first_detection.is_nan() => {
                        first_detection = t;
                        first_detection_pos = Some(*pos_m);
                    }
                    PlannerEvent::Declared { pos_m, rule } => {
                        declarations.push((t, *pos_m, rule));
                    }
                    _ => {}
                }
                events.push(EventRecord {
                    t_s: t,
                    vehicle: i as u32,
                    event: EventKind::Planner(e.clone()),
                });
            }
            match d.status {
                PlanStatus::Running => {}
                PlanStatus::Finished => finished[i] = true,
                PlanStatus::Abort => {
                    outcome.get_or_insert(Outcome::AbortedByCage);
                    world.stop(plumetrace_core::VehicleId(i as u32));
                }
            }
        }
        for (id, fix) in &report.fixes {
            events.push(EventRecord {
                t_s: t,
                vehicle: id.0,
                event: EventKind::Fix {
                    event: "nav_fix",
                    jump_m: fix.jump_m(),
                    to_m: fix.after_m,
                },
            });
        }
        for (id, what) in &report.incidents {
            events.push(EventRecord {
                t_s: t,
                vehicle: id.0,
                event: EventKind::Incident {
                    event: "incident",
                    what: *what,
                },
            });
            outcome.get_or_insert(match what {
                Incident::LeftDomain => Outcome::LeftDomain,
                Incident::Collided => Outcome::Collided,
            });
        }
        if let Some(v) = world.vehicles().get(tracer) {
            let p = v.vehicle.state.pos_m;
            if let Some(q) = last_pos {
                let step = (p - q).norm();
                path_length_m += step;
                if !first_detection.is_nan() && declarations.is_empty() {
                    trace_length_m += step;
                }
            }
            last_pos = Some(p);
        }
        let recorded: &[SimVehicle] = if options.trajectory {
            world.vehicles()
        } else {
            &[]
        };
        for v in recorded {
            let s = v.vehicle.state;
            let est = v.nav.estimate_m();
            let chem = v.last_chem;
            trajectory.push(TrajectoryRow {
                t_s: world.time_s(),
                vehicle: v.vehicle.id.0,
                true_x_m: s.pos_m.x,
                true_y_m: s.pos_m.y,
                true_z_m: s.z_m,
                est_x_m: est.x,
                est_y_m: est.y,
                heading_deg: s.heading.deg(),
                speed_mps: s.speed_mps,
                behaviour: behaviour[v.vehicle.id.0 as usize],
                reading_v: chem.map_or(0.0, |c| c.reading),
                detection: chem.is_some_and(|c| c.detection),
            });
        }
        if k.is_multiple_of(sample_every) {
            if options.mean_plume {
                mean_plume.accumulate(world.env().plume());
            }
            if let Some(s) = sources.first() {
                flow_sum += world.env().flow().velocity(s.xy());
                flow_n += 1.0;
            }
        }
        if k.is_multiple_of(600) {
            progress(world.time_s(), spec.time_limit_s);
        }
        let auvs_done = planners
            .iter()
            .zip(&finished)
            .all(|(p, f)| p.is_none() || *f);
        if outcome.is_some() || auvs_done {
            break;
        }
    }
    let sim_time = world.time_s();
    // A failure (abort, incident) is the outcome even after a declaration; otherwise a mission
    // that declared counts as declared even if the time ran out during the mapping pattern.
    let outcome = outcome.unwrap_or(if !declarations.is_empty() {
        Outcome::Declared
    } else if planners
        .iter()
        .zip(&finished)
        .all(|(p, f)| p.is_none() || *f)
    {
        Outcome::NoDeclaration
    } else {
        Outcome::TimedOut
    });
    let mean_flow = if flow_n > 0.0 {
        flow_sum / flow_n
    } else {
        Vec2::zeros()
    };
    let records: Vec<DeclarationRecord> = declarations
        .iter()
        .map(|(t, p, rule)| declaration_record(*t, *p, rule, &sources, mean_flow))
        .collect();
    let source_records = source_records(&sources, &records);
    let first = records.first();
    let src0 = first
        .map(|r| Vec2::new(r.source_x_m, r.source_y_m))
        .or_else(|| sources.first().map(|s| s.xy()))
        .unwrap_or_else(Vec2::zeros);
    let summary = Summary {
        scenario: name,
        seed,
        outcome: outcome.name(),
        declared: first.is_some(),
        declared_x: first.map_or(f64::NAN, |r| r.x_m),
        declared_y: first.map_or(f64::NAN, |r| r.y_m),
        source_x: src0.x,
        source_y: src0.y,
        error_m: first.map_or(f64::NAN, |r| r.error_m),
        error_along_m: first.map_or(f64::NAN, |r| r.error_along_m),
        error_cross_m: first.map_or(f64::NAN, |r| r.error_cross_m),
        first_detection_s: first_detection,
        declaration_s: first.map_or(f64::NAN, |r| r.t_s),
        path_length_m,
        trace_length_m: if first.is_some() {
            trace_length_m
        } else {
            f64::NAN
        },
        detection_to_source_m: first_detection_pos.map_or(f64::NAN, |p| (p - src0).norm()),
        sim_time_s: sim_time,
        declarations: records,
        sources_located: source_records.iter().filter(|s| s.located).count(),
        sources: source_records,
    };
    Ok(MissionRun {
        outcome,
        summary,
        trajectory,
        events,
        stage_times: world.stage_times(),
        mean_plume,
        sources,
        op_area: spec.op_area,
        subregions: spec.subregions,
        mean_flow_mps: mean_flow,
    })
}

fn declaration_record(
    t: f64,
    p: Vec2,
    rule: &'static str,
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
fn source_records(sources: &[Vec3], declarations: &[DeclarationRecord]) -> Vec<SourceRecord> {
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
            let nearest = mine.iter().copied().fold(f64::NAN, f64::min);
            SourceRecord {
                x_m: s.x,
                y_m: s.y,
                declarations: mine.len(),
                nearest_error_m: nearest,
                located: nearest <= LOCATED_RADIUS_M,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn declarations_are_attributed_to_their_nearest_source() {
        let sources = [Vec3::new(300.0, 860.0, 0.0), Vec3::new(700.0, 820.0, 0.0)];
        let flow = Vec2::new(0.05, -0.25);
        let decl: Vec<DeclarationRecord> = [
            (100.0, Vec2::new(340.0, 550.0), "upflow_edge"),
            (900.0, Vec2::new(298.0, 852.0), "along_flow"),
            (1500.0, Vec2::new(305.0, 845.0), "along_flow"),
        ]
        .iter()
        .map(|(t, p, rule)| declaration_record(*t, *p, rule, &sources, flow))
        .collect();
        let recs = source_records(&sources, &decl);
        assert_eq!(recs[0].declarations, 3, "the edge declaration counts too");
        assert!((recs[0].nearest_error_m - 68f64.sqrt()).abs() < 1e-12);
        assert!(recs[0].located);
        assert_eq!(recs[1].declarations, 0);
        assert!(recs[1].nearest_error_m.is_nan());
        assert!(!recs[1].located);
        // Only the edge declaration: attributed, but 300 m away is not located.
        let recs = source_records(&sources, &decl[..1]);
        assert_eq!(recs[0].declarations, 1);
        assert!(recs[0].nearest_error_m > LOCATED_RADIUS_M && !recs[0].located);
        assert_eq!(decl[0].rule, "upflow_edge");
    }
}
