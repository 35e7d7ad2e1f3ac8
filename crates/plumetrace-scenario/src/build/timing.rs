//! `[sim]` and the environment's step (`mission.env_dt_s`): steps of the run, and the bound on
//! steps (of the vehicles and of the flow's sub-steps) that keeps a run within a day of computing.

use super::Invalid;
use crate::config::ScenarioConfig;
use crate::limits::{MAX_FLOW_NODE_STEPS, MAX_STEPS};

/// The run's clock.
#[derive(Debug, Clone, Copy)]
pub(super) struct Timing {
    /// The vehicles' step, s (`sim.dt_s`).
    pub dt_s: f64,
    /// The environment's step, s (`mission.env_dt_s`, by default `sim.dt_s`).
    pub env_dt_s: f64,
    /// `sim.duration_s`.
    pub duration_s: f64,
    /// Steps of `dt_s` in the run.
    pub steps: u64,
}

/// Reads `[sim]` and `mission.env_dt_s`.
pub(super) fn timing(cfg: &ScenarioConfig) -> Result<Timing, Invalid> {
    let dt_s = cfg.sim.dt_s;
    let duration_s = cfg.sim.duration_s;
    if !(duration_s.is_finite() && duration_s >= dt_s) {
        return Err(Invalid::new(
            "sim.duration_s",
            format!("must be a finite number >= sim.dt_s ({dt_s}), got {duration_s:?}"),
        ));
    }
    let env_dt_s = match cfg.mission.as_ref().and_then(|m| m.env_dt_s) {
        None => dt_s,
        Some(env_dt_s) => {
            if plumetrace_sim::steps_per_env_step(env_dt_s, dt_s).is_none() {
                return Err(Invalid::new(
                    "mission.env_dt_s",
                    format!("must be a whole multiple of sim.dt_s ({dt_s}), got {env_dt_s:?}"),
                ));
            }
            env_dt_s
        }
    };
    let steps_f = (duration_s / dt_s).round();
    if steps_f > MAX_STEPS {
        return Err(Invalid::new(
            "sim.duration_s",
            format!(
                "sim.duration_s / sim.dt_s = {steps_f:.3e} steps; at most {MAX_STEPS:.0e} (about \
                 a day of computing): shorten the run or lengthen the step"
            ),
        ));
    }
    Ok(Timing {
        dt_s,
        env_dt_s,
        duration_s,
        steps: steps_f as u64,
    })
}

impl Timing {
    /// Bounds the flow's sub-steps (within its stable limit) over `sim.duration_s`.
    pub(super) fn check_run_flow_steps(
        &self,
        flow: &dyn plumetrace_env::FlowField,
    ) -> Result<(), Invalid> {
        let flow_steps = self.duration_s / self.env_dt_s
            * plumetrace_env::environment::flow_substeps(flow, self.env_dt_s) as f64;
        check_flow_steps(flow, flow_steps, "the run")
    }
}

/// Refuses `flow_steps` flow steps of `what` beyond [`MAX_STEPS`], or more node updates (steps
/// times the grid's nodes) than [`MAX_FLOW_NODE_STEPS`], naming the flow grid whose stable step
/// makes them.
pub(super) fn check_flow_steps(
    flow: &dyn plumetrace_env::FlowField,
    flow_steps: f64,
    what: &str,
) -> Result<(), Invalid> {
    let limit = flow.max_stable_dt_s().unwrap_or(f64::INFINITY);
    if flow_steps > MAX_STEPS {
        return Err(Invalid::new(
            "flow.farrell",
            format!(
                "the flow grid's stable step is {limit:.4e} s, so {what} would take \
                 {flow_steps:.3e} flow steps; at most {MAX_STEPS:.0e}: use a coarser grid or \
                 larger diffusivities"
            ),
        ));
    }
    let nodes = flow.nodes() as f64;
    let work = flow_steps * nodes;
    if work > MAX_FLOW_NODE_STEPS {
        return Err(Invalid::new(
            "flow.farrell",
            format!(
                "the flow grid's stable step is {limit:.4e} s, so {what} would take \
                 {flow_steps:.3e} flow steps of {nodes} grid nodes each, {work:.3e} node updates; \
                 at most {MAX_FLOW_NODE_STEPS:.0e} (about an hour of computing): use a coarser \
                 grid, smaller diffusivities or a shorter run"
            ),
        ));
    }
    Ok(())
}
