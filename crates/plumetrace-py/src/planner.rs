//! A planner written in Python, flown through the same `Planner` seam as the built-in ones.
//!
//! The Python object has a method `decide(snapshot) -> command`. The snapshot is a plain dict
//! with the snapshot log's layout (`time_s`, `vehicle`, `nav`, `chem`, `flow`, `ranges`,
//! `inbox`); the command is a dict:
//!
//! - `heading_deg` (compass, required), `speed_mps` (>= 0, required);
//! - one of `altitude_m`, `depth_m` or `surface = True` (required in the first command, kept
//!   afterwards when left out);
//! - optional: `behaviour` (a behaviour name, for figures and statistics), `declare = (x, y)`
//!   (declares a source there), `source_estimate = (x, y)` (telemetry), `done = True` (the
//!   mission is over for this vehicle).
//!
//! An optional attribute `decision_period_s` (default 1 s) sets how often it is asked. An optional
//! method `run_ended(t_s) -> None or (x, y)` is called once when the run ends for a reason the
//! planner did not choose (the time limit, a collision, leaving the domain): a point it returns
//! is declared then (a point it was holding for a later declaration). A Python exception in
//! `decide` or `run_ended`, or an answer that breaks these rules, stops the vehicle and is raised
//! by `run` once the mission has ended.

use crate::error::msg;
use plumetrace_core::{
    BehaviourKind, Command, Decision, DeclarationKind, Heading, PlanStatus, Planner, PlannerEvent,
    SensorSnapshot, Telemetry, Vec2, VerticalCommand,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::{Arc, Mutex};

/// The first error a Python planner met, kept for `run` to raise.
pub type ErrorSlot = Arc<Mutex<Option<PyErr>>>;

/// A Python object behind [`Planner`].
pub struct PyPlanner {
    obj: Py<PyAny>,
    period_s: f64,
    last: Option<Command>,
    behaviour: Option<BehaviourKind>,
    error: ErrorSlot,
    failed: bool,
}

impl PyPlanner {
    /// Wraps `obj`; errors go to `error`.
    pub fn new(obj: &Bound<'_, PyAny>, error: ErrorSlot) -> PyResult<Self> {
        if !obj.hasattr("decide")? {
            return Err(msg(format!(
                "the planner {} has no decide(snapshot) method",
                obj.get_type().name()?
            )));
        }
        let period_s = if obj.hasattr("decision_period_s")? {
            let p: f64 = obj
                .getattr("decision_period_s")?
                .extract()
                .map_err(|_| msg("the planner's decision_period_s is not a number".to_string()))?;
            if !(p.is_finite() && (0.0..=3600.0).contains(&p)) {
                return Err(msg(format!(
                    "the planner's decision_period_s = {p} is outside 0..=3600 s"
                )));
            }
            p
        } else {
            1.0
        };
        Ok(PyPlanner {
            obj: obj.clone().unbind(),
            period_s,
            last: None,
            behaviour: None,
            error,
            failed: false,
        })
    }

    fn ask(&mut self, py: Python<'_>, snapshot: &SensorSnapshot) -> PyResult<Decision> {
        let text = serde_json::to_string(snapshot)
            .map_err(|e| msg(format!("the snapshot at {} s: {e}", snapshot.time_s)))?;
        let snap = py.import("json")?.call_method1("loads", (text,))?;
        let answer = self.obj.bind(py).call_method1("decide", (snap,))?;
        let at = format!("the command at {:.1} s", snapshot.time_s);
        let d = answer.cast::<PyDict>().map_err(|_| {
            msg(format!(
                "{at} is not a dict (got {})",
                answer
                    .get_type()
                    .name()
                    .map(|n| n.to_string())
                    .unwrap_or_default()
            ))
        })?;
        let num = |key: &str| -> PyResult<Option<f64>> {
            match d.get_item(key)? {
                None => Ok(None),
                Some(v) if v.is_none() => Ok(None),
                Some(v) => {
                    let x: f64 = v
                        .extract()
                        .map_err(|_| msg(format!("{at}: {key} = {v} is not a number")))?;
                    if x.is_finite() {
                        Ok(Some(x))
                    } else {
                        Err(msg(format!("{at}: {key} = {x} is not a finite number")))
                    }
                }
            }
        };
        let point = |key: &str| -> PyResult<Option<Vec2>> {
            match d.get_item(key)? {
                None => Ok(None),
                Some(v) if v.is_none() => Ok(None),
                Some(v) => {
                    let (x, y): (f64, f64) = v
                        .extract()
                        .map_err(|_| msg(format!("{at}: {key} = {v} is not a pair (x, y)")))?;
                    if x.is_finite() && y.is_finite() {
                        Ok(Some(Vec2::new(x, y)))
                    } else {
                        Err(msg(format!("{at}: {key} = ({x}, {y}) is not finite")))
                    }
                }
            }
        };
        let flag = |key: &str| -> PyResult<bool> {
            match d.get_item(key)? {
                None => Ok(false),
                Some(v) => v
                    .is_truthy()
                    .map_err(|_| msg(format!("{at}: {key} is not a truth value"))),
            }
        };
        let heading = num("heading_deg")?.ok_or_else(|| msg(format!("{at} has no heading_deg")))?;
        let speed = num("speed_mps")?.ok_or_else(|| msg(format!("{at} has no speed_mps")))?;
        if speed < 0.0 {
            return Err(msg(format!("{at}: speed_mps = {speed} is negative")));
        }
        let vertical = match (num("altitude_m")?, num("depth_m")?, flag("surface")?) {
            (Some(a), None, false) if a >= 0.0 => VerticalCommand::Altitude(a),
            (None, Some(z), false) if z >= 0.0 => VerticalCommand::Depth(z),
            (None, None, true) => VerticalCommand::Surface,
            (None, None, false) => self.last.map(|c| c.vertical).ok_or_else(|| {
                msg(format!(
                    "{at}: the first command must give altitude_m, depth_m or surface = True"
                ))
            })?,
            _ => {
                return Err(msg(format!(
                    "{at}: give one of altitude_m (>= 0), depth_m (>= 0) or surface = True"
                )));
            }
        };
        let command = Command {
            heading: Heading::from_deg(heading),
            speed_mps: speed,
            vertical,
        };
        let mut decision = Decision::new(
            command,
            if flag("done")? {
                PlanStatus::Finished
            } else {
                PlanStatus::Running
            },
        );
        if let Some(b) = d.get_item("behaviour")?
            && !b.is_none()
        {
            let name: String = b
                .extract()
                .map_err(|_| msg(format!("{at}: behaviour {b} is not a string")))?;
            let kind: BehaviourKind =
                serde_json::from_value(serde_json::Value::String(name.clone())).map_err(|_| {
                    let names: Vec<&str> = BehaviourKind::ALL
                        .iter()
                        .filter_map(|k| plumetrace_core::variant_name(k))
                        .collect();
                    msg(format!(
                        "{at}: behaviour '{name}' is not one of {}",
                        names.join(", ")
                    ))
                })?;
            if self.behaviour != Some(kind) {
                self.behaviour = Some(kind);
                decision
                    .events
                    .push(PlannerEvent::Behaviour { behaviour: kind });
            }
        }
        if let Some(p) = point("declare")? {
            decision.events.push(PlannerEvent::Declared {
                pos_m: p,
                rule: DeclarationKind::CUSTOM,
            });
        }
        if let Some(p) = point("source_estimate")? {
            decision
                .telemetry
                .push(Telemetry::SourceEstimate { pos_m: p });
        }
        self.last = Some(command);
        Ok(decision)
    }
}

impl Planner for PyPlanner {
    fn decide(&mut self, snapshot: &SensorSnapshot) -> Decision {
        let hold = self.last.unwrap_or(Command {
            heading: snapshot.nav.heading,
            speed_mps: 0.0,
            vertical: VerticalCommand::Surface,
        });
        if self.failed {
            return Decision::new(hold, PlanStatus::Abort);
        }
        match Python::attach(|py| self.ask(py, snapshot)) {
            Ok(d) => d,
            Err(e) => {
                self.failed = true;
                if let Ok(mut slot) = self.error.lock() {
                    slot.get_or_insert(e);
                }
                Decision::new(hold, PlanStatus::Abort)
            }
        }
    }

    fn decision_period_s(&self) -> f64 {
        self.period_s
    }

    fn run_ended(&mut self, t_s: f64) -> Vec<PlannerEvent> {
        if self.failed {
            return Vec::new();
        }
        match Python::attach(|py| self.held_point(py, t_s)) {
            Ok(point) => point
                .map(|pos_m| PlannerEvent::Declared {
                    pos_m,
                    rule: DeclarationKind::CUSTOM,
                })
                .into_iter()
                .collect(),
            Err(e) => {
                self.failed = true;
                if let Ok(mut slot) = self.error.lock() {
                    slot.get_or_insert(e);
                }
                Vec::new()
            }
        }
    }
}

impl PyPlanner {
    /// What the object's optional `run_ended(t_s)` returns: `None`, or a point to declare.
    fn held_point(&self, py: Python<'_>, t_s: f64) -> PyResult<Option<Vec2>> {
        let obj = self.obj.bind(py);
        if !obj.hasattr("run_ended")? {
            return Ok(None);
        }
        let answer = obj.call_method1("run_ended", (t_s,))?;
        if answer.is_none() {
            return Ok(None);
        }
        let bad = || {
            msg(format!(
                "run_ended at {t_s:.1} s returned {answer}, not None or a point (x, y) of finite \
                 numbers"
            ))
        };
        let (x, y): (f64, f64) = answer.extract().map_err(|_| bad())?;
        if !(x.is_finite() && y.is_finite()) {
            return Err(bad());
        }
        Ok(Some(Vec2::new(x, y)))
    }
}
