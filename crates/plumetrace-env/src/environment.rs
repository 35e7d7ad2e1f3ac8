//! The environment: a flow field and a plume advanced together on a fixed time step.

use crate::field::{ConcentrationField, GridSpec};
use crate::flow::{FlowField, FlowModel};
use crate::obstacle::ObstacleSet;
use crate::plume::FilamentPlume;
use crate::seabed::Seabed;
use crate::{EnvError, Rect, SimRng, StreamId, stream_rng};
use plumetrace_core::{Vec2, Vec3};
use rand::RngCore;
use std::sync::Arc;

/// The plume models: a live filament plume or a steady field.
pub enum Plume {
    /// Farrell filaments, advanced with the flow.
    Filaments(Box<FilamentPlume>),
    /// A steady field (Gaussian plume or a gridded file); it does not change with time.
    Steady(Box<dyn ConcentrationField>),
}

impl std::fmt::Debug for Plume {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Plume::Filaments(p) => write!(f, "Plume::Filaments({} live)", p.len()),
            Plume::Steady(_) => write!(f, "Plume::Steady"),
        }
    }
}

impl Plume {
    /// The filament plume, if this is one.
    pub fn filaments(&self) -> Option<&FilamentPlume> {
        match self {
            Plume::Filaments(p) => Some(p),
            Plume::Steady(_) => None,
        }
    }
}

impl ConcentrationField for Plume {
    fn concentration(&self, p: Vec3) -> f64 {
        match self {
            Plume::Filaments(f) => f.concentration(p),
            Plume::Steady(s) => s.concentration(p),
        }
    }
    fn concentrations(&self, points: &[Vec3], out: &mut [f64]) {
        match self {
            Plume::Filaments(f) => f.concentrations(points, out),
            Plume::Steady(s) => s.concentrations(points, out),
        }
    }
    fn grid_concentrations(&self, grid: &GridSpec, points: &[Vec3], out: &mut [f64]) {
        match self {
            Plume::Filaments(f) => f.grid_concentrations(grid, points, out),
            Plume::Steady(s) => s.grid_concentrations(grid, points, out),
        }
    }
    fn display_grid_concentrations(&self, grid: &GridSpec, points: &[Vec3], out: &mut [f64]) {
        match self {
            Plume::Filaments(f) => f.display_grid_concentrations(grid, points, out),
            Plume::Steady(s) => s.display_grid_concentrations(grid, points, out),
        }
    }
}

/// The simulated ocean: domain, flow, plume and obstacles, stepped at a fixed `dt`.
///
/// Time is the integer step count times `dt`. The plume steps at `dt` (and the spin-up's step);
/// a flow with a stability limit (the Farrell grid) is advanced in as many equal sub-steps as
/// keep each at most half its limit ([`flow_substeps`]), so the plume's step is free of it, and
/// a flow with a step of its own longer than the plume's advances once per block of plume steps
/// ([`flow_schedule`]). The flow and the plume each draw from their own
/// random stream, so what vehicles do never changes the plume they meet.
#[derive(Debug)]
pub struct Environment {
    domain: Rect,
    flow: FlowModel,
    plume: Plume,
    obstacles: ObstacleSet,
    /// The seabed, if not flat at `z = 0`.
    seabed: Option<Arc<Seabed>>,
    dt_s: f64,
    step: u64,
    /// Simulated time spent in spin-up before step 0, s.
    spinup_s: f64,
    flow_stepper: FlowStepper,
    flow_rng: SimRng,
    plume_rng: SimRng,
}

impl Environment {
    /// An environment at t = 0 with random streams derived from `seed`.
    pub fn new(
        domain: Rect,
        flow: FlowModel,
        plume: Plume,
        obstacles: ObstacleSet,
        dt_s: f64,
        seed: u64,
    ) -> Result<Self, EnvError> {
        crate::error::require_positive("dt_s", dt_s)?;
        let mut plume = plume;
        if let Plume::Filaments(p) = &mut plume {
            p.check_step(dt_s, &flow)?;
            p.set_key_seed(stream_rng(seed, StreamId::PlumeKeys).next_u64());
        }
        Ok(Environment {
            domain,
            flow,
            plume,
            obstacles,
            seabed: None,
            dt_s,
            step: 0,
            spinup_s: 0.0,
            flow_stepper: FlowStepper::default(),
            flow_rng: stream_rng(seed, StreamId::Flow),
            plume_rng: stream_rng(seed, StreamId::Plume),
        })
    }

    /// Refuses a step of `dt_s` that moves a filament plume's filaments by too little for their
    /// single-precision positions ([`FilamentPlume::check_step`]; key `dt_s`). [`Environment::new`]
    /// checks its step and [`Environment::spin_up`] its own; a caller that names its keys
    /// otherwise checks them first.
    pub fn check_step(&self, dt_s: f64) -> Result<(), EnvError> {
        match &self.plume {
            Plume::Filaments(p) => p.check_step(dt_s, &self.flow),
            Plume::Steady(_) => Ok(()),
        }
    }

    /// [`Environment::check_step`] for a spin-up of `duration_s` in steps of `dt_s`, its error
    /// keyed `spinup_dt_s`; a spin-up that takes no step has none to check.
    pub fn check_spin_up(&self, duration_s: f64, dt_s: f64) -> Result<(), EnvError> {
        if (duration_s / dt_s).round() < 1.0 {
            return Ok(());
        }
        self.check_step(dt_s).map_err(|e| e.renamed("spinup_dt_s"))
    }

    /// Develops the plume before the run starts: `duration_s` of simulated time in steps of
    /// `dt_s` (coarser than the run's step: the physics does not depend on the step, and a
    /// kilometre of plume in a 0.1 m/s current needs hours to form). The run's clock then starts
    /// at 0; [`Environment::elapsed_s`] includes the spin-up. Errors name the arguments as the
    /// mission's keys do (`spinup_s`, `spinup_dt_s`).
    pub fn spin_up(&mut self, duration_s: f64, dt_s: f64) -> Result<(), EnvError> {
        crate::error::require_non_negative("spinup_s", duration_s)?;
        crate::error::require_positive("spinup_dt_s", dt_s)?;
        self.check_spin_up(duration_s, dt_s)?;
        let n = (duration_s / dt_s).round() as u64;
        let start = self.elapsed_s();
        for k in 1..=n {
            let t = start + k as f64 * dt_s;
            self.advance(t, dt_s)?;
        }
        self.spinup_s += n as f64 * dt_s;
        Ok(())
    }

    /// Advances the flow (by its [`FlowStepper`]) and then the plume (in one step) to `t_new_s`.
    fn advance(&mut self, t_new_s: f64, dt_s: f64) -> Result<(), EnvError> {
        self.flow_stepper
            .advance(&mut self.flow, t_new_s, dt_s, &mut self.flow_rng)?;
        if let Plume::Filaments(p) = &mut self.plume {
            p.step(&self.flow, t_new_s, dt_s, &mut self.plume_rng);
        }
        Ok(())
    }

    /// How the flow is being stepped (where it is in its current block).
    pub fn flow_stepper(&self) -> &FlowStepper {
        &self.flow_stepper
    }

    /// Simulated time spent in spin-up, s.
    pub fn spun_up_s(&self) -> f64 {
        self.spinup_s
    }

    /// A copy of the whole state (flow, filaments, clocks and random streams), so that stepping
    /// the copy gives the same bits as stepping the original; `None` for a steady plume (its
    /// field is shared, not copied, and a steady plume needs no spin-up worth sharing).
    pub fn try_clone(&self) -> Option<Self> {
        let plume = match &self.plume {
            Plume::Filaments(p) => Plume::Filaments(Box::new(p.copy_state())),
            Plume::Steady(_) => return None,
        };
        Some(Environment {
            domain: self.domain,
            flow: self.flow.clone(),
            plume,
            obstacles: self.obstacles.clone(),
            seabed: self.seabed.clone(),
            dt_s: self.dt_s,
            step: self.step,
            spinup_s: self.spinup_s,
            flow_stepper: self.flow_stepper.clone(),
            flow_rng: self.flow_rng.clone(),
            plume_rng: self.plume_rng.clone(),
        })
    }

    /// Simulated time including any spin-up, s (the flow and plume clocks).
    pub fn elapsed_s(&self) -> f64 {
        self.spinup_s + self.step as f64 * self.dt_s
    }

    /// Concentration at one point; cheaper than the query index when only a few points are
    /// sampled between steps (a vehicle's sensor), since it needs no index build.
    pub fn sample_concentration(&self, p: Vec3) -> f64 {
        match &self.plume {
            Plume::Filaments(f) => f.concentration_scan(p),
            Plume::Steady(s) => s.concentration(p),
        }
    }

    /// Advances the flow, then the plume, by one step.
    pub fn step(&mut self) -> Result<(), EnvError> {
        let t_new = self.spinup_s + (self.step + 1) as f64 * self.dt_s;
        self.advance(t_new, self.dt_s)?;
        self.step += 1;
        Ok(())
    }

    /// Current time, s.
    pub fn time_s(&self) -> f64 {
        self.step as f64 * self.dt_s
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.step
    }

    /// The time step, s.
    pub fn dt_s(&self) -> f64 {
        self.dt_s
    }

    /// The simulated region.
    pub fn domain(&self) -> Rect {
        self.domain
    }

    /// The flow field.
    pub fn flow(&self) -> &FlowModel {
        &self.flow
    }

    /// The plume.
    pub fn plume(&self) -> &Plume {
        &self.plume
    }

    /// Mutable plume access (e.g. to seed filaments at t = 0).
    pub fn plume_mut(&mut self) -> &mut Plume {
        &mut self.plume
    }

    /// Puts a seabed under the environment (`None`: flat at `z = 0`), the filament plume's too.
    pub fn set_seabed(&mut self, seabed: Option<Arc<Seabed>>) {
        if let Plume::Filaments(p) = &mut self.plume {
            p.set_seabed(seabed.clone());
        }
        self.seabed = seabed;
    }

    /// The seabed, if not flat.
    pub fn seabed(&self) -> Option<&Seabed> {
        self.seabed.as_deref()
    }

    /// The seabed's height at `p`, m: 0 over a flat seabed.
    pub fn seabed_height_at(&self, p: Vec2) -> f64 {
        self.seabed.as_ref().map_or(0.0, |s| s.height_at(p.x, p.y))
    }

    /// The obstacles.
    pub fn obstacles(&self) -> &ObstacleSet {
        &self.obstacles
    }

    /// Water velocity at `p`, m/s.
    pub fn flow_at(&self, p: Vec2) -> Vec2 {
        self.flow.velocity(p)
    }

    /// Concentration at `p`.
    pub fn concentration_at(&self, p: Vec3) -> f64 {
        self.plume.concentration(p)
    }
}

/// Steps a flow along plume steps as [`flow_schedule`] says: in sub-steps at every plume step,
/// or once per block of plume steps. It remembers where it is in the current block, so one
/// stepper goes with one flow.
#[derive(Debug, Clone, Default)]
pub struct FlowStepper {
    /// Plume steps left in the current block; 0 starts a block.
    block_left: u64,
}

impl FlowStepper {
    /// Advances `flow` for the plume step of `dt_s` that ends at `t_new_s`.
    pub fn advance<F: FlowField>(
        &mut self,
        flow: &mut F,
        t_new_s: f64,
        dt_s: f64,
        rng: &mut SimRng,
    ) -> Result<(), EnvError> {
        let (every, n) = flow_schedule(flow, dt_s);
        let t0 = t_new_s - dt_s;
        if every > 1 {
            // At a block's first step the flow advances to the block's middle plus half a step:
            // each plume step of the block then meets, on average, the flow of its own end, as
            // with the flow stepped at every plume step.
            if self.block_left == 0 {
                let to = t0 + 0.5 * (every as f64 * dt_s + dt_s);
                flow.advance(to, to - flow.time_s(), rng)?;
                self.block_left = every;
            }
            self.block_left -= 1;
        } else {
            self.block_left = 0;
            let h = dt_s / n as f64;
            for k in 1..=n {
                let t = if k == n { t_new_s } else { t0 + k as f64 * h };
                flow.advance(t, h, rng)?;
            }
        }
        Ok(())
    }
}

/// How a flow is stepped along plume steps of `dt_s`: `(every, substeps)`, the flow advancing
/// once every `every` plume steps by `every * dt_s` in `substeps` equal sub-steps.
///
/// A flow with its own step ([`FlowField::own_step_s`]) longer than `dt_s` (and `dt_s` within
/// half its stable limit) advances once per block of `every` plume steps, the most whose total
/// is at most its own step and at most half its stable limit: at the block's first step, in one
/// step to the block's middle plus half a plume step; the filaments of the block move in that
/// flow (on average each plume step meets the flow of its own end, as without blocks).
/// Otherwise it advances at every plume step, in [`flow_substeps`] sub-steps. [`FlowStepper`]
/// carries it out.
pub fn flow_schedule(flow: &dyn FlowField, dt_s: f64) -> (u64, u64) {
    let n = flow_substeps(flow, dt_s);
    let Some(own) = flow.own_step_s() else {
        return (1, n);
    };
    if n > 1 || own <= dt_s {
        return (1, n);
    }
    let cap = match flow.max_stable_dt_s() {
        Some(limit) if limit > 0.0 => own.min(0.5 * limit),
        _ => own,
    };
    // A whole number of steps (at least one: `dt_s` is within both bounds), with a margin for
    // steps like 0.1 / 0.01 that divide in decimal.
    ((cap / dt_s * (1.0 + 1e-9)).floor().max(1.0) as u64, 1)
}

/// The number of equal sub-steps a flow takes for an environment step of `dt_s`: one when `dt_s`
/// is at most half the flow's stable limit (or it has none), else the fewest that make each
/// sub-step at most half the limit (strictly below it, where the explicit scheme is stable with
/// margin).
pub fn flow_substeps(flow: &dyn FlowField, dt_s: f64) -> u64 {
    match flow.max_stable_dt_s() {
        Some(limit) if limit > 0.0 && dt_s > 0.5 * limit => {
            ((dt_s / (0.5 * limit)).ceil() as u64).max(1)
        }
        _ => 1,
    }
}
