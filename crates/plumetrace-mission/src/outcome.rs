//! How a mission ends and what it comes to, decided apart from the step loop.
//!
//! Each vehicle has a [`VehicleStatus`]. A planner that finishes or aborts, and a vehicle that
//! leaves the domain or hits an obstacle, stops that vehicle; the mission ends when no vehicle
//! with a planner is active ([`EndReason::PlannersDone`]) or at the time limit
//! ([`EndReason::TimeLimit`]). Its [`Outcome`] is, in this order: the first failure of a vehicle
//! with a planner (an abort or an incident, even after a declaration; a vehicle without a planner
//! that drifts away is recorded but fails nothing), else `declared` if any planner declared (even
//! if the time ran out during a mapping pattern), else `no_declaration` if every planner finished,
//! else `timed_out`. The summary keeps the declaration and the end apart, each with its time.

use plumetrace_sim::Incident;
use serde::{Deserialize, Serialize};

/// What a mission came to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// A source was declared (and no vehicle failed).
    Declared,
    /// Every planner finished without declaring (e.g. every subregion timed out).
    NoDeclaration,
    /// The time limit came first.
    TimedOut,
    /// A planner's cage aborted the mission (far outside the op-area).
    AbortedByCage,
    /// A planner aborted for another reason.
    Aborted,
    /// A vehicle left the simulated domain.
    LeftDomain,
    /// A vehicle entered an obstacle.
    Collided,
}

impl Outcome {
    /// Every outcome, in table order.
    pub const ALL: [Outcome; 7] = [
        Outcome::Declared,
        Outcome::NoDeclaration,
        Outcome::TimedOut,
        Outcome::AbortedByCage,
        Outcome::Aborted,
        Outcome::LeftDomain,
        Outcome::Collided,
    ];

    /// The name used in files (serde's).
    pub fn name(self) -> &'static str {
        plumetrace_core::variant_name(&self).unwrap_or("?")
    }

    /// The outcome of a planner that aborted with these events (a cage abort says so).
    pub fn of_abort(events: &[plumetrace_core::PlannerEvent]) -> Self {
        if events
            .iter()
            .any(|e| matches!(e, plumetrace_core::PlannerEvent::CageAbort { .. }))
        {
            Outcome::AbortedByCage
        } else {
            Outcome::Aborted
        }
    }

    /// The outcome of a vehicle stopped by an incident.
    pub fn of_incident(what: Incident) -> Self {
        match what {
            Incident::LeftDomain => Outcome::LeftDomain,
            // The seabed is an obstacle too: campaigns count it with the collisions, and the
            // event names it.
            Incident::Collided | Incident::HitBottom => Outcome::Collided,
        }
    }
}

/// Why the mission stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EndReason {
    /// No vehicle with a planner is active any more (finished, aborted or stopped).
    PlannersDone,
    /// The mission's time limit.
    TimeLimit,
}

/// The end of a mission.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MissionEnd {
    /// Why it stopped.
    pub reason: EndReason,
    /// Mission time at the end, s.
    pub t_s: f64,
}

/// Where a vehicle stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VehicleStatus {
    /// Flying its planner.
    Active,
    /// Without a planner: keeps its last command.
    NoPlanner,
    /// Its planner finished.
    Finished,
    /// Its planner aborted.
    Aborted,
    /// It left the domain.
    LeftDomain,
    /// It entered an obstacle.
    Collided,
}

impl VehicleStatus {
    /// The status after an incident.
    pub fn of_incident(what: Incident) -> Self {
        match what {
            Incident::LeftDomain => VehicleStatus::LeftDomain,
            Incident::Collided | Incident::HitBottom => VehicleStatus::Collided,
        }
    }
}

/// What the mission itself records about a vehicle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "event")]
pub enum MissionEvent {
    /// Its planner finished; the vehicle stops.
    PlannerFinished,
    /// Its planner aborted; the vehicle stops.
    PlannerAborted,
}

/// The outcome from the first failure, whether anything was declared and whether every planner
/// finished.
pub fn judge(first_failure: Option<Outcome>, declared: bool, all_finished: bool) -> Outcome {
    match first_failure {
        Some(f) => f,
        None if declared => Outcome::Declared,
        None if all_finished => Outcome::NoDeclaration,
        None => Outcome::TimedOut,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outcome_table() {
        let cases = [
            (
                Some(Outcome::AbortedByCage),
                true,
                false,
                Outcome::AbortedByCage,
            ),
            (Some(Outcome::Collided), false, true, Outcome::Collided),
            (None, true, false, Outcome::Declared),
            (None, true, true, Outcome::Declared),
            (None, false, true, Outcome::NoDeclaration),
            (None, false, false, Outcome::TimedOut),
        ];
        for (failure, declared, finished, want) in cases {
            assert_eq!(judge(failure, declared, finished), want);
        }
    }

    #[test]
    fn names_come_from_serde() {
        for o in Outcome::ALL {
            let json = serde_json::to_string(&o).unwrap_or_default();
            assert_eq!(json, format!("\"{}\"", o.name()));
        }
        assert_eq!(Outcome::AbortedByCage.name(), "aborted_by_cage");
        let back: Outcome = serde_json::from_str("\"left_domain\"").unwrap_or(Outcome::Declared);
        assert_eq!(back, Outcome::LeftDomain);
    }
}
