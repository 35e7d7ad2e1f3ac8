//! The filament (puff) plume model of Farrell et al. (2002).
//!
//! Each source releases filaments as a Poisson process. A filament is a 3-D Gaussian puff of
//! chemical with mass `Q`, centre `(x, y, z)` and radius `r`; its concentration at distance `d`
//! is `Q / ((2 pi)^(3/2) r^3) exp(-d^2 / (2 r^2))`, cut off beyond `cutoff_radii` radii. Each step:
//! 1. every source releases `Poisson(rate dt)` new filaments at its position with radius `r0`;
//! 2. every filament moves with the local flow plus a centre-relative random walk, and grows:
//!    `r^2 = r0^2 + gamma (t - t_birth)`;
//! 3. filaments are reflected at the seabed (and at the surface, when a water depth is given);
//! 4. filaments that leave the domain horizontally are removed, and their mass is counted.
//!
//! # Centre-relative dispersion and pompy compatibility
//! The random walk is a proper diffusion: each step displaces a filament by a Gaussian of
//! variance `2 K dt` per axis, with horizontal and vertical diffusivities `K_h`, `K_v` in m^2/s.
//! Statistics then do not depend on the time step. The reference implementation pompy (and
//! GADEN) add `scale * N(0, 1) * dt` instead, whose variance `scale^2 dt^2` per step gives an
//! effective diffusivity `scale^2 dt / 2` that shrinks with the step. The
//! [`Dispersion::PompyCompatible`] option reproduces that scaling so the two can be compared
//! side by side; do not use it for new work.
//!
//! # Soft obstacles
//! Filaments pass through soft obstacles (kelp): the plume model does not see them at all.
//!
//! # Queries
//! Point and batch concentration queries use a uniform grid of cells over the domain, built
//! lazily on the first query after a step (so stepping never pays for it), with filaments sorted
//! by cell into contiguous arrays. A query visits only the cells within the largest cut-off radius.

mod column;
mod exp_lanes;
mod filament;
mod index;

pub use filament::{
    Dispersion, DownflowSink, FilamentParams, FilamentPlume, PlumeStats, Source, VerticalBoundary,
};
