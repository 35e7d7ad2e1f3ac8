//! The meandering flow field of Farrell et al. (2002).
//!
//! A regular grid of `nx` x `ny` nodes covers the region, surrounded by a ring of boundary nodes one
//! grid step outside it (the layout of the reference implementation, pompy). At each step:
//! 1. the four corners of the ring are set to the mean flow plus second-order coloured noise, one
//!    independent channel per corner and component ([`ColouredNoise`]);
//! 2. the ring's edges are filled by linear ramps between the corners;
//! 3. the interior is advanced one explicit Euler step of
//!    `du/dt = -(u du/dx + v du/dy) + k_x/2 d2u/dx2 + k_y/2 d2u/dy2` (and the same for `v`) with
//!    centred differences.
//!
//! The environment advances the grid with the plume, in sub-steps within its stable limit, or,
//! with `step_s` longer than the plume's step, once per block of plume steps
//! ([`crate::environment::flow_schedule`]).
//!
//! Velocities between nodes are **bilinear** interpolations of the four surrounding nodes (the
//! reference uses a cubic spline; bilinear is cheaper and keeps the field within the range of its
//! nodes). Positions outside the grid take the value at the nearest edge.
//!
//! The corner noise can be integrated exactly (`noise_scheme = "exact"`, see [`ColouredNoise`]),
//! so that its statistics do not depend on the step. The interior's explicit scheme is stable only for small enough steps;
//! [`FarrellFlow::max_stable_dt_s`] gives the limit (the smaller of the diffusion limit
//! `1 / (2 (Dx/dx^2 + Dy/dy^2))` with `D = k/2`, the centred-advection limit `2 min(D) / U^2`
//! and the Courant limit `min(dx, dy) / U`, where `U` bounds the speed at the corners: mean speed
//! plus four standard deviations of the corner noise; with the Euler schemes of the corner noise
//! (`noise_scheme = "euler"`, or `original_noise_updates`) also the corner oscillator's
//! explicit-Euler limit `2 z / w`, beyond which a lightly damped oscillator
//! grows without bound, 1 s for pompy's parameters). Building the field with a step at or above
//! the limit is an error: at the limit itself the scheme is only marginally stable.

use super::{FlowField, MeanFlow, axis_weight};
use crate::error::{EnvError, require_non_negative, require_positive};
use crate::{Rect, SimRng};
use plumetrace_core::Vec2;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// Parameters of the Farrell flow field (defaults: pompy's `WindModel`). Read as is from a
/// scenario's `[flow.farrell]` table: unknown keys are errors, omitted ones take the defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FarrellParams {
    /// Grid nodes along x (East), [`FarrellParams::MIN_NODES`] to [`FarrellParams::MAX_NODES`].
    pub nx: usize,
    /// Grid nodes along y (North), as `nx`.
    pub ny: usize,
    /// Diffusivity along x, m^2/s (`k_x` of the paper).
    pub diffusivity_x_m2ps: f64,
    /// Diffusivity along y, m^2/s.
    pub diffusivity_y_m2ps: f64,
    /// Noise input gain `G` (dimensionless).
    pub noise_gain: f64,
    /// Noise damping ratio `z` (dimensionless).
    pub noise_damping: f64,
    /// Noise bandwidth (undamped natural frequency) `w`, rad/s.
    pub noise_bandwidth_radps: f64,
    /// Use the original Farrell update, which scales the noise by `dt` instead of `sqrt(dt)` (its
    /// amplitude then depends on the time step; always explicit Euler). Off by default.
    pub original_noise_updates: bool,
    /// How the corner noise is integrated (ignored with `original_noise_updates`).
    pub noise_scheme: NoiseScheme,
    /// The grid's own step, s, when the plume steps more finely: the grid then advances once
    /// per this many seconds (a whole number of plume steps, at most half the stable limit) and
    /// the filaments in between move in that grid ([`crate::environment::flow_schedule`]).
    /// 0 (the default): the grid steps with the plume.
    pub step_s: f64,
}

/// The integration of the corner noise.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseScheme {
    /// The oscillator's exact discretisation (the default): the same statistics at every step.
    #[default]
    Exact,
    /// Explicit Euler-Maruyama, as in the reference implementation: its stationary variance
    /// grows with the step, and it limits the step to the oscillator's Euler limit.
    Euler,
}

impl FarrellParams {
    /// The fewest grid nodes along an axis.
    pub const MIN_NODES: usize = 3;
    /// The most grid nodes along an axis: a million nodes at most (memory and step time).
    pub const MAX_NODES: usize = 1000;

    /// Checks every parameter; errors name the field (`nx`).
    pub fn validate(&self) -> Result<(), EnvError> {
        for (key, n) in [("nx", self.nx), ("ny", self.ny)] {
            if !(Self::MIN_NODES..=Self::MAX_NODES).contains(&n) {
                return Err(EnvError::invalid(
                    key,
                    format!(
                        "must be >= {} and <= {}, got {n}",
                        Self::MIN_NODES,
                        Self::MAX_NODES
                    ),
                ));
            }
        }
        require_positive("diffusivity_x_m2ps", self.diffusivity_x_m2ps)?;
        require_positive("diffusivity_y_m2ps", self.diffusivity_y_m2ps)?;
        require_non_negative("noise_gain", self.noise_gain)?;
        require_non_negative("step_s", self.step_s)?;
        require_positive("noise_damping", self.noise_damping)?;
        require_positive("noise_bandwidth_radps", self.noise_bandwidth_radps)
    }
}

impl Default for FarrellParams {
    fn default() -> Self {
        FarrellParams {
            nx: 21,
            ny: 21,
            diffusivity_x_m2ps: 20.0,
            diffusivity_y_m2ps: 20.0,
            noise_gain: 2.0,
            noise_damping: 0.1,
            noise_bandwidth_radps: 0.2,
            original_noise_updates: false,
            noise_scheme: NoiseScheme::Exact,
            step_s: 0.0,
        }
    }
}

/// Second-order coloured noise: per channel the damped, driven oscillator
/// `dx0 = x1 dt; dx1 = -(w^2 x0 + 2 z w x1) dt + G w^2 dW`.
///
/// Its stationary variance is `G^2 w / (4 z)` (for `z > 0`), and its correlation time is about
/// `1 / (z w)`.
///
/// With [`NoiseUpdates::Exact`] each step is the oscillator's **exact discretisation**: the state `s = (x0, x1)`
/// moves to `Phi s + L n`, with `Phi = exp(A dt)` the oscillator's transition matrix and `L` the
/// Cholesky factor of the covariance `Q = P - Phi P Phi^T` that the driving noise adds over the
/// step (`P = diag(G^2 w / (4 z), G^2 w^3 / (4 z))`, the stationary covariance, which is diagonal
/// because `x1` is the derivative of `x0`), `n` two standard normal draws. The stationary variance
/// is then the same at every step size and the scheme is stable at any step. `Phi` and `L` are
/// computed once per step size.
///
/// The other [`NoiseUpdates`] are explicit Euler steps (one draw per channel and step): with
/// the noise scaled by `sqrt(dt)` (Euler-Maruyama, whose stationary variance grows with the step)
/// or by `dt` (the original Farrell update, whose amplitude depends on the step); both diverge
/// beyond the oscillator's Euler limit (see `FarrellFlow`).
#[derive(Debug, Clone)]
pub struct ColouredNoise {
    x0: Vec<f64>,
    x1: Vec<f64>,
    gain: f64,
    damping: f64,
    bandwidth: f64,
    updates: NoiseUpdates,
    /// The exact step's matrices for the last step size: `(dt, Phi, L)`.
    exact: Option<(f64, Mat2, Mat2)>,
}

/// A 2 x 2 matrix, row-major.
type Mat2 = [[f64; 2]; 2];

/// How [`ColouredNoise`] steps its channels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoiseUpdates {
    /// The exact discretisation.
    Exact,
    /// Explicit Euler-Maruyama (noise scaled by `sqrt(dt)`).
    EulerMaruyama,
    /// The original Farrell update (explicit Euler, noise scaled by `dt`).
    Original,
}

impl NoiseUpdates {
    /// The updates a Farrell parameter set asks for.
    pub fn of(params: &FarrellParams) -> Self {
        match (params.original_noise_updates, params.noise_scheme) {
            (true, _) => NoiseUpdates::Original,
            (false, NoiseScheme::Exact) => NoiseUpdates::Exact,
            (false, NoiseScheme::Euler) => NoiseUpdates::EulerMaruyama,
        }
    }
}

impl ColouredNoise {
    /// `channels` independent channels starting at rest.
    pub fn new(
        channels: usize,
        gain: f64,
        damping: f64,
        bandwidth_radps: f64,
        updates: NoiseUpdates,
    ) -> Self {
        ColouredNoise {
            x0: vec![0.0; channels],
            x1: vec![0.0; channels],
            gain,
            damping,
            bandwidth: bandwidth_radps,
            updates,
            exact: None,
        }
    }

    /// Advances every channel by `dt_s`.
    pub fn update(&mut self, dt_s: f64, rng: &mut SimRng) {
        match self.updates {
            NoiseUpdates::Exact => {}
            NoiseUpdates::EulerMaruyama => return self.update_euler(dt_s, dt_s.sqrt(), rng),
            NoiseUpdates::Original => return self.update_euler(dt_s, dt_s, rng),
        }
        let (phi, l) = match self.exact {
            Some((dt, phi, l)) if dt == dt_s => (phi, l),
            _ => {
                let (phi, l) = self.exact_step(dt_s);
                self.exact = Some((dt_s, phi, l));
                (phi, l)
            }
        };
        for (x0, x1) in self.x0.iter_mut().zip(self.x1.iter_mut()) {
            let n0: f64 = StandardNormal.sample(rng);
            let n1: f64 = StandardNormal.sample(rng);
            let (p, q) = (*x0, *x1);
            *x0 = phi[0][0] * p + phi[0][1] * q + l[0][0] * n0;
            *x1 = phi[1][0] * p + phi[1][1] * q + l[1][0] * n0 + l[1][1] * n1;
        }
    }

    /// One explicit Euler step, the noise scaled by `noise_scale`.
    fn update_euler(&mut self, dt_s: f64, noise_scale: f64, rng: &mut SimRng) {
        let w = self.bandwidth;
        let a = w * w;
        let b = 2.0 * self.damping * w;
        let c = self.gain * w * w;
        for (x0, x1) in self.x0.iter_mut().zip(self.x1.iter_mut()) {
            let n: f64 = StandardNormal.sample(rng);
            let (p, q) = (*x0, *x1);
            *x0 = p + dt_s * q;
            *x1 = q - dt_s * (a * p + b * q) + c * noise_scale * n;
        }
    }

    /// The transition matrix `exp(A dt)` of the oscillator and the Cholesky factor (lower
    /// triangular) of the covariance the noise adds over `dt`.
    fn exact_step(&self, dt_s: f64) -> (Mat2, Mat2) {
        let phi = oscillator_transition(self.damping, self.bandwidth, dt_s);
        let [p0, p1] = self.stationary_covariance();
        // Q = P - Phi P Phi^T (P diagonal).
        let q00 = p0 - (phi[0][0] * phi[0][0] * p0 + phi[0][1] * phi[0][1] * p1);
        let q01 = -(phi[0][0] * phi[1][0] * p0 + phi[0][1] * phi[1][1] * p1);
        let q11 = p1 - (phi[1][0] * phi[1][0] * p0 + phi[1][1] * phi[1][1] * p1);
        // Rounding can leave a tiny negative where the added variance is ~0 (a zero gain).
        let l00 = q00.max(0.0).sqrt();
        let l10 = if l00 > 0.0 { q01 / l00 } else { 0.0 };
        let l11 = (q11 - l10 * l10).max(0.0).sqrt();
        (phi, [[l00, 0.0], [l10, l11]])
    }

    /// Current outputs (the `x0` of each channel).
    pub fn output(&self) -> &[f64] {
        &self.x0
    }

    /// The stationary variance `G^2 w / (4 z)` of each channel's output.
    pub fn stationary_variance(&self) -> f64 {
        self.gain * self.gain * self.bandwidth / (4.0 * self.damping)
    }

    /// The stationary variances of `x0` and `x1` (their covariance is zero).
    fn stationary_covariance(&self) -> [f64; 2] {
        let v0 = self.stationary_variance();
        [v0, v0 * self.bandwidth * self.bandwidth]
    }
}

/// `exp(A dt)` for the oscillator `A = [[0, 1], [-w^2, -2 z w]]`, through the closed form for a
/// 2 x 2 matrix: with `m = tr(A) / 2 = -z w` and `s^2 = m^2 - det(A) = w^2 (z^2 - 1)`,
/// `exp(A dt) = exp(m dt) (c I + g (A - m I))` where `c = cosh(s dt)` and `g = sinh(s dt) / s`
/// (overdamped), `c = cos(|s| dt)` and `g = sin(|s| dt) / |s|` (underdamped), or their series
/// near critical damping.
fn oscillator_transition(z: f64, w: f64, dt: f64) -> Mat2 {
    let m = -z * w;
    let s2 = w * w * (z * z - 1.0);
    let x = s2 * dt * dt;
    // `c` and `g` already multiplied by exp(m dt).
    let (c, g) = if x.abs() < 1e-8 {
        // cosh(s dt) = 1 + x/2 + x^2/24, sinh(s dt)/s = dt (1 + x/6 + x^2/120).
        let e = (m * dt).exp();
        (
            e * (1.0 + x / 2.0 + x * x / 24.0),
            e * dt * (1.0 + x / 6.0 + x * x / 120.0),
        )
    } else if s2 > 0.0 {
        // Overdamped: the two modes' exponentials, each at most 1 (m + s <= 0), so nothing
        // overflows however strong the damping.
        let s = s2.sqrt();
        let (slow, fast) = (((m + s) * dt).exp(), ((m - s) * dt).exp());
        (0.5 * (slow + fast), 0.5 * (slow - fast) / s)
    } else {
        let s = (-s2).sqrt();
        let e = (m * dt).exp();
        (e * (s * dt).cos(), e * (s * dt).sin() / s)
    };
    // A - m I = [[z w, 1], [-w^2, -z w]].
    [[c + g * z * w, g], [-g * w * w, c - g * z * w]]
}

/// One grid cell's bilinear coefficients, `u` then `v`: `a + b tx + c ty + d tx ty` over the
/// cell's unit square, worked out in `f64` from the nodes and kept in single precision (the
/// filaments' transport is), so that a lookup reads 32 aligned bytes (see `FarrellFlow::cells`).
#[derive(Debug, Clone, Copy)]
#[repr(align(32))]
struct Cell([f32; 8]);

/// The Farrell et al. (2002) meandering flow field (see the module docs).
#[derive(Debug, Clone)]
pub struct FarrellFlow {
    params: FarrellParams,
    mean: MeanFlow,
    region: Rect,
    dx_m: f64,
    dy_m: f64,
    inv_dx: f64,
    inv_dy: f64,
    /// Row-major `(ny + 2) x (nx + 2)`: index `j * (nx + 2) + i`, ring included.
    u: Vec<f64>,
    v: Vec<f64>,
    /// Buffers the next interior is written to before they are swapped with `u` and `v` (their
    /// ring is stale until the next boundary update rewrites it).
    u_next: Vec<f64>,
    v_next: Vec<f64>,
    /// Per grid cell `(i, j)` (index `j * (nx - 1) + i`), its coefficients ([`Cell`]), rebuilt
    /// after every step.
    cells: Vec<Cell>,
    /// The ring's fractions along a row (`i / (nx + 1)`, `i` in `0..nx + 2`) and along a
    /// column (`j / (ny + 1)`), for the boundary's interpolation between the corners.
    ring_x: Vec<f64>,
    ring_y: Vec<f64>,
    noise: ColouredNoise,
    time_s: f64,
    max_stable_dt_s: f64,
    max_speed_mps: f64,
}

impl FarrellFlow {
    /// Builds the field over `region`, checking that `dt_s` is within the stable limit. Errors
    /// name the parameters' fields (`nx`), the mean flow's under `mean` and the step as `dt_s`.
    pub fn new(
        region: Rect,
        mean: MeanFlow,
        params: FarrellParams,
        dt_s: f64,
    ) -> Result<Self, EnvError> {
        require_positive("dt_s", dt_s)?;
        let flow = Self::build(region, mean, params, dt_s)?;
        if dt_s >= flow.max_stable_dt_s {
            return Err(EnvError::invalid(
                "dt_s",
                format!(
                    "{dt_s} s is above the Farrell flow grid's stable limit of {:.4} s \
                     (grid step {:.2} m x {:.2} m); use a smaller dt_s, a coarser grid or larger diffusivities",
                    flow.max_stable_dt_s, flow.dx_m, flow.dy_m
                ),
            ));
        }
        Ok(flow)
    }

    /// Builds the field over `region` for an [`crate::Environment`], which advances it in
    /// sub-steps within its stable limit whatever the environment's step
    /// ([`crate::environment::flow_substeps`]). With the original noise updates, whose
    /// amplitude grows with the step, the limit is computed for the corner oscillator's own
    /// Euler limit, the longest step they can take.
    pub fn substepped(
        region: Rect,
        mean: MeanFlow,
        params: FarrellParams,
    ) -> Result<Self, EnvError> {
        let mut flow = Self::build(region, mean, params, 1.0)?;
        if params.original_noise_updates {
            flow.max_stable_dt_s = flow.stable_dt_limit(flow.noise_limit());
        }
        Ok(flow)
    }

    /// The field with its stable limit for steps of `dt_s` (which only the original noise
    /// updates' amplitude depends on).
    fn build(
        region: Rect,
        mean: MeanFlow,
        params: FarrellParams,
        dt_s: f64,
    ) -> Result<Self, EnvError> {
        mean.validate().map_err(|e| e.under("mean"))?;
        params.validate()?;
        let dx_m = region.width_m() / (params.nx - 1) as f64;
        let dy_m = region.height_m() / (params.ny - 1) as f64;
        let noise = ColouredNoise::new(
            8,
            params.noise_gain,
            params.noise_damping,
            params.noise_bandwidth_radps,
            NoiseUpdates::of(&params),
        );
        let v0 = mean.velocity_at(0.0);
        let n_all = (params.nx + 2) * (params.ny + 2);
        let mut flow = FarrellFlow {
            params,
            mean,
            region,
            dx_m,
            dy_m,
            inv_dx: 1.0 / dx_m,
            inv_dy: 1.0 / dy_m,
            u: vec![v0.x; n_all],
            v: vec![v0.y; n_all],
            u_next: vec![v0.x; n_all],
            v_next: vec![v0.y; n_all],
            cells: Vec::new(),
            ring_x: fractions(params.nx + 2),
            ring_y: fractions(params.ny + 2),
            noise,
            time_s: 0.0,
            max_stable_dt_s: 0.0,
            max_speed_mps: v0.norm(),
        };
        flow.max_stable_dt_s = flow.stable_dt_limit(dt_s);
        flow.build_cells_on(crate::simd::best());
        Ok(flow)
    }

    fn stable_dt_limit(&self, dt_s: f64) -> f64 {
        let dxx = 0.5 * self.params.diffusivity_x_m2ps;
        let dyy = 0.5 * self.params.diffusivity_y_m2ps;
        let diffusion =
            1.0 / (2.0 * (dxx / (self.dx_m * self.dx_m) + dyy / (self.dy_m * self.dy_m)));
        // Corner noise amplitude; the original update's amplitude scales with sqrt(dt).
        let mut sd = self.noise.stationary_variance().sqrt();
        if self.params.original_noise_updates {
            sd *= dt_s.sqrt();
        }
        let u_bound = self.mean.max_speed_mps() + 4.0 * sd * std::f64::consts::SQRT_2;
        if u_bound <= 0.0 {
            return diffusion.min(self.noise_limit());
        }
        let advection = 2.0 * dxx.min(dyy) / (u_bound * u_bound);
        let courant = self.dx_m.min(self.dy_m) / u_bound;
        diffusion
            .min(advection)
            .min(courant)
            .min(self.noise_limit())
    }

    /// With the original updates (explicit Euler), the corner oscillator is stable only while `|1 + lambda dt| < 1` for both
    /// eigenvalues: underdamped (`z < 1`, `lambda = w (-z +- i sqrt(1 - z^2))`) that is
    /// `dt < 2 z / w`; overdamped (`z >= 1`, real `lambda = w (-z +- sqrt(z^2 - 1))`) it is
    /// `dt < 2 / (w (z + sqrt(z^2 - 1)))`, set by the faster mode (a damping of 21 with the
    /// default bandwidth once passed the first bound and diverged).
    fn noise_limit(&self) -> f64 {
        if NoiseUpdates::of(&self.params) == NoiseUpdates::Exact {
            // The exact discretisation is stable at any step.
            return f64::INFINITY;
        }
        let (z, w) = (self.params.noise_damping, self.params.noise_bandwidth_radps);
        if z < 1.0 {
            2.0 * z / w
        } else {
            2.0 / (w * (z + (z * z - 1.0).sqrt()))
        }
    }

    /// The model parameters.
    pub fn params(&self) -> &FarrellParams {
        &self.params
    }

    /// The largest speed at any node after the last step, m/s.
    pub fn max_speed_mps(&self) -> f64 {
        self.max_speed_mps
    }

    /// Current corner noise outputs (u of the four corners, then v).
    pub fn corner_noise(&self) -> &[f64] {
        self.noise.output()
    }

    /// Interior node positions and velocities, for plots: `(x, y, u, v)` per node.
    pub fn nodes(&self) -> Vec<[f64; 4]> {
        let (nx, ny) = (self.params.nx, self.params.ny);
        let mut out = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let k = (j + 1) * (nx + 2) + i + 1;
                out.push([
                    self.region.x_min_m + i as f64 * self.dx_m,
                    self.region.y_min_m + j as f64 * self.dy_m,
                    self.u[k],
                    self.v[k],
                ]);
            }
        }
        out
    }

    fn apply_boundary(&mut self, mean: Vec2) {
        let (nx2, ny2) = (self.params.nx + 2, self.params.ny + 2);
        let n = self.noise.output();
        // Corners: (i=0,j=0), (i=last,j=0), (i=0,j=last), (i=last,j=last).
        let cu = [mean.x + n[0], mean.x + n[1], mean.x + n[2], mean.x + n[3]];
        let cv = [mean.y + n[4], mean.y + n[5], mean.y + n[6], mean.y + n[7]];
        for (field, c) in [(&mut self.u, cu), (&mut self.v, cv)] {
            let last_j = (ny2 - 1) * nx2;
            for (i, &t) in self.ring_x.iter().enumerate() {
                field[i] = c[0] + t * (c[1] - c[0]);
                field[last_j + i] = c[2] + t * (c[3] - c[2]);
            }
            for (j, &t) in self.ring_y.iter().enumerate() {
                field[j * nx2] = c[0] + t * (c[2] - c[0]);
                field[j * nx2 + nx2 - 1] = c[1] + t * (c[3] - c[1]);
            }
        }
    }

    #[inline(always)]
    fn step_interior(&mut self, dt_s: f64) {
        let (nx, ny) = (self.params.nx, self.params.ny);
        let nx2 = nx + 2;
        let hx = 0.5 * self.inv_dx * dt_s;
        let hy = 0.5 * self.inv_dy * dt_s;
        let kx = 0.5 * self.params.diffusivity_x_m2ps * self.inv_dx * self.inv_dx * dt_s;
        let ky = 0.5 * self.params.diffusivity_y_m2ps * self.inv_dy * self.inv_dy * dt_s;
        // One run over the rows from the first interior node to the last, the ring's columns
        // between them included: the values written there are never read (the next boundary
        // update rewrites the ring before the next step, and nothing else reads it), and one
        // long run fills the vector lanes where rows of a small grid would leave remainders.
        // Every neighbour column is cut to the run's length, so the loop has no bounds checks.
        let first = nx2 + 1;
        let len = (ny - 1) * nx2 + nx;
        let (u, v) = (&self.u, &self.v);
        let (uw, uc, ue) = (
            span(u, first - 1, len),
            span(u, first, len),
            span(u, first + 1, len),
        );
        let (us, un) = (span(u, first - nx2, len), span(u, first + nx2, len));
        let (vw, vc, ve) = (
            span(v, first - 1, len),
            span(v, first, len),
            span(v, first + 1, len),
        );
        let (vs, vn) = (span(v, first - nx2, len), span(v, first + nx2, len));
        let uo = &mut self.u_next[first..first + len];
        let vo = &mut self.v_next[first..first + len];
        for i in 0..len {
            let (uw0, uc0, ue0, u_s, u_n) = (uw[i], uc[i], ue[i], us[i], un[i]);
            let (vw0, vc0, ve0, v_s, v_n) = (vw[i], vc[i], ve[i], vs[i], vn[i]);
            let du = -(uc0 * (ue0 - uw0) * hx + vc0 * (u_n - u_s) * hy)
                + kx * (ue0 - 2.0 * uc0 + uw0)
                + ky * (u_n - 2.0 * uc0 + u_s);
            let dv = -(uc0 * (ve0 - vw0) * hx + vc0 * (v_n - v_s) * hy)
                + kx * (ve0 - 2.0 * vc0 + vw0)
                + ky * (v_n - 2.0 * vc0 + v_s);
            uo[i] = uc0 + du;
            vo[i] = vc0 + dv;
        }
        std::mem::swap(&mut self.u, &mut self.u_next);
        std::mem::swap(&mut self.v, &mut self.v_next);
        self.max_speed_mps = self.largest_speed();
    }

    /// The largest node speed of the interior, NaN when any node is not finite. Reduced in
    /// eight lanes (the largest square and the sum of squares, which is not finite exactly when
    /// some square is not or the field has run away past 1e150 m/s), so the loop runs in vector
    /// lanes; the maximum does not depend on the order.
    #[inline(always)]
    fn largest_speed(&self) -> f64 {
        const LANES: usize = 8;
        let (nx, ny) = (self.params.nx, self.params.ny);
        let nx2 = nx + 2;
        let mut top = [0.0f64; LANES];
        let mut sum = [0.0f64; LANES];
        let mut tail_top = 0.0f64;
        let mut tail_sum = 0.0f64;
        for j in 1..=ny {
            let c = j * nx2 + 1;
            let (u, v) = (&self.u[c..c + nx], &self.v[c..c + nx]);
            let mut uc = u.chunks_exact(LANES);
            let mut vc = v.chunks_exact(LANES);
            for (a, b) in (&mut uc).zip(&mut vc) {
                for l in 0..LANES {
                    let sq = a[l] * a[l] + b[l] * b[l];
                    top[l] = if sq > top[l] { sq } else { top[l] };
                    sum[l] += sq;
                }
            }
            for (a, b) in uc.remainder().iter().zip(vc.remainder()) {
                let sq = a * a + b * b;
                tail_top = if sq > tail_top { sq } else { tail_top };
                tail_sum += sq;
            }
        }
        let top = top.iter().fold(tail_top, |m, &t| if t > m { t } else { m });
        let sum = sum.iter().sum::<f64>() + tail_sum;
        if sum.is_finite() {
            top.sqrt()
        } else {
            f64::NAN
        }
    }

    /// [`FarrellFlow::build_cells`] on the vector unit `arch`: AVX-512's own version
    /// ([`BuildCellsV4`]), AVX2's ([`BuildCellsV3`]), else the plain loop compiled for any CPU.
    fn build_cells_on(&mut self, arch: pulp::Arch) {
        match arch {
            #[cfg(target_arch = "x86_64")]
            pulp::Arch::V4(simd) => pulp::Simd::vectorize(simd, BuildCellsV4 { simd, flow: self }),
            #[cfg(target_arch = "x86_64")]
            pulp::Arch::V3(simd) => pulp::Simd::vectorize(simd, BuildCellsV3 { simd, flow: self }),
            _ => self.build_cells(),
        }
    }

    /// Rebuilds the cells' bilinear coefficients from the interior nodes.
    fn build_cells(&mut self) {
        for (cells, nodes) in self.cell_rows() {
            nodes.fill(cells);
        }
    }

    /// The cells (sized for the grid), row by row, each row with the nodes it reads.
    #[inline(always)]
    fn cell_rows(&mut self) -> impl Iterator<Item = (&mut [Cell], RowNodes<'_>)> {
        let (nx, ny) = (self.params.nx, self.params.ny);
        let nx2 = nx + 2;
        let row = nx - 1;
        self.cells.resize(row * (ny - 1), Cell([0.0; 8]));
        let (u, v) = (&self.u, &self.v);
        self.cells
            .chunks_exact_mut(row)
            .enumerate()
            .map(move |(j, cells)| {
                // Interior node (i, j) sits at (i + 1, j + 1) in the ring-padded arrays; the
                // cells of row j read nodes i and i + 1 of rows j and j + 1.
                let lo = (j + 1) * nx2 + 1;
                let hi = lo + nx2;
                let nodes = RowNodes {
                    us: span(u, lo, nx),
                    un: span(u, hi, nx),
                    vs: span(v, lo, nx),
                    vn: span(v, hi, nx),
                };
                (cells, nodes)
            })
    }

    #[inline(always)]
    fn interp(&self, x: f64, y: f64) -> (f64, f64) {
        let (nx, ny) = (self.params.nx, self.params.ny);
        let (i, tx) = axis_weight(x, self.region.x_min_m, self.inv_dx, nx);
        let (j, ty) = axis_weight(y, self.region.y_min_m, self.inv_dy, ny);
        bilinear(&self.cells[j * (nx - 1) + i], tx, ty)
    }
}

/// The nodes a row of cells reads: the row's nodes (`us`, `vs`) and the next row's (`un`, `vn`),
/// `nx` of each; cell `i` reads nodes `i` and `i + 1`.
struct RowNodes<'a> {
    us: &'a [f64],
    un: &'a [f64],
    vs: &'a [f64],
    vn: &'a [f64],
}

impl RowNodes<'_> {
    /// The row's cells, one at a time.
    #[inline(always)]
    fn fill(&self, cells: &mut [Cell]) {
        let pairs = self
            .us
            .windows(2)
            .zip(self.un.windows(2))
            .zip(self.vs.windows(2).zip(self.vn.windows(2)));
        for (cell, ((a, b), (c, d))) in cells.iter_mut().zip(pairs) {
            cell.0 = cell_coefficients([a[0], a[1]], [b[0], b[1]], [c[0], c[1]], [d[0], d[1]])
                .map(|c| c as f32);
        }
    }
}

/// A cell's coefficients from the pairs of neighbouring nodes along rows j (`us`, `vs`) and
/// j + 1 (`un`, `vn`): each component's `f00, f10 - f00, f01 - f00, f11 - f10 - f01 + f00`.
#[inline(always)]
fn cell_coefficients(us: [f64; 2], un: [f64; 2], vs: [f64; 2], vn: [f64; 2]) -> [f64; 8] {
    let (a, b, c, d) = (us, un, vs, vn);
    [
        a[0],
        a[1] - a[0],
        b[0] - a[0],
        b[1] - a[1] - b[0] + a[0],
        c[0],
        c[1] - c[0],
        d[0] - c[0],
        d[1] - c[1] - d[0] + c[0],
    ]
}

/// `k / (n - 1)` for `k` in `0..n`: the places of `n` evenly spaced points from 0 to 1.
fn fractions(n: usize) -> Vec<f64> {
    (0..n).map(|k| k as f64 / (n - 1) as f64).collect()
}

/// `len` values of `f` from `start`.
#[inline(always)]
fn span(f: &[f64], start: usize, len: usize) -> &[f64] {
    &f[start..start + len]
}

/// The velocity at `(x, y)` in a cell's unit square.
#[inline(always)]
fn bilinear(c: &Cell, x: f64, y: f64) -> (f64, f64) {
    let c = c.0.map(f64::from);
    let xy = x * y;
    let a = c[0] + c[1] * x + c[2] * y + c[3] * xy;
    let b = c[4] + c[5] * x + c[6] * y + c[7] * xy;
    (a, b)
}

/// Points per batch of a batch lookup: small enough for the batch to stay in L1 cache.
const BATCH: usize = 64;

/// The 8 x 8 transpose of `r` (`r[i]` lane `j` becomes lane `i` of the `j`-th vector), in
/// three rounds of eight shuffles.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn transpose8(
    f: pulp::core_arch::x86::Avx512f,
    r: [core::arch::x86_64::__m512d; 8],
) -> [core::arch::x86_64::__m512d; 8] {
    use core::arch::x86_64::__m512d;
    // t[0] = (r0, r1) at lanes 0 2 4 6, t[1] at 1 3 5 7, t[2], t[3] (r2, r3), ...
    let t: [__m512d; 8] = core::array::from_fn(|l| {
        let (a, b) = (r[l & !1], r[l | 1]);
        if l & 1 == 0 {
            f._mm512_unpacklo_pd(a, b)
        } else {
            f._mm512_unpackhi_pd(a, b)
        }
    });
    // Lanes pairs 0 and 2 of `a`, then of `b` (or 1 and 3).
    let q = |a: __m512d, b: __m512d, odd: bool| {
        if odd {
            f._mm512_shuffle_f64x2::<0xDD>(a, b)
        } else {
            f._mm512_shuffle_f64x2::<0x88>(a, b)
        }
    };
    // s[0]: lanes 0 and 4 of r0-r3, s[1]: 2 and 6, s[2]: 1 and 5, s[3]: 3 and 7 (from t[0]
    // with t[2], and t[1] with t[3]); s[4..] the same of r4-r7.
    let s: [__m512d; 8] = core::array::from_fn(|l| {
        let a = (l >> 1 & 1) + (l >> 2) * 4;
        q(t[a], t[a + 2], l & 1 == 1)
    });
    // Vector j: lane j of r0-r7, from s[0, 2, 1, 3] with s[4, 6, 5, 7].
    core::array::from_fn(|j| {
        let a = [0, 2, 1, 3][j & 3];
        q(s[a], s[a + 4], j >= 4)
    })
}

/// [`axis_weight`] in single precision and floating point only: the lower node's index (as a
/// whole `f32`, at most `last - 1`) and the fraction towards the next, for a grid of `last + 1`
/// nodes (`last >= 1`). Positions outside the grid take the nearest edge, NaN the first node;
/// the floor is taken by rounding through `1.5 * 2^23` (the grid has at most 1,000 nodes along an
/// axis, far below `2^22`) and stepping down where that rounded up, so no libm call and no
/// integer conversion is needed.
#[inline(always)]
fn grid_floor(pos: f32, origin: f32, inv_step: f32, last: f32) -> (f32, f32) {
    const ROUND: f32 = 12_582_912.0;
    let f = (pos - origin) * inv_step;
    let f = if f > 0.0 { f } else { 0.0 };
    let f = if f < last { f } else { last };
    let r = (f + ROUND) - ROUND;
    let i = if r > f { r - 1.0 } else { r };
    let i = if i < last - 1.0 { i } else { last - 1.0 };
    (i, f - i)
}

/// The velocity at `(x, y)` in a cell's unit square, in single precision.
#[inline(always)]
fn bilinear_f32(c: &Cell, x: f32, y: f32) -> (f32, f32) {
    let c = &c.0;
    let xy = x * y;
    let a = c[0] + c[1] * x + c[2] * y + c[3] * xy;
    let b = c[4] + c[5] * x + c[6] * y + c[7] * xy;
    (a, b)
}

/// The grid's origin, inverse steps and last node indices in single precision.
#[derive(Clone, Copy)]
struct Axes32 {
    x0: f32,
    y0: f32,
    inv_dx: f32,
    inv_dy: f32,
    lx: f32,
    ly: f32,
    row: f32,
}

impl FarrellFlow {
    /// The grid's axes for positions measured from `origin`.
    fn axes_f32(&self, origin: [f64; 2]) -> Axes32 {
        let (nx, ny) = (self.params.nx, self.params.ny);
        Axes32 {
            x0: (self.region.x_min_m - origin[0]) as f32,
            y0: (self.region.y_min_m - origin[1]) as f32,
            inv_dx: self.inv_dx as f32,
            inv_dy: self.inv_dy as f32,
            lx: (nx - 1) as f32,
            ly: (ny - 1) as f32,
            row: (nx - 1) as f32,
        }
    }
}

/// Per point of a batch, its cell's index (a whole `f32`) and fractions, in single precision.
#[inline(always)]
fn cells_and_fractions(
    a: Axes32,
    xs: &[f32],
    ys: &[f32],
    cell: &mut [f32; BATCH],
    tx: &mut [f32; BATCH],
    ty: &mut [f32; BATCH],
) -> usize {
    let m = xs.len().min(ys.len()).min(BATCH);
    for k in 0..m {
        let (i, fx) = grid_floor(xs[k], a.x0, a.inv_dx, a.lx);
        let (j, fy) = grid_floor(ys[k], a.y0, a.inv_dy, a.ly);
        cell[k] = j * a.row + i;
        tx[k] = fx;
        ty[k] = fy;
    }
    m
}

/// The cell of whole-number index `at` (below the cell count, exactly; the last cell for
/// anything beyond).
#[inline(always)]
fn cell_at(cells: &[Cell], at: f32) -> &Cell {
    &cells[(at as usize).min(cells.len() - 1)]
}

/// The single-precision batch lookup's points and where their velocities go.
struct Velocities<'a> {
    flow: &'a FarrellFlow,
    /// The grid's axes for positions measured from the caller's origin.
    axes: Axes32,
    x: &'a [f32],
    y: &'a [f32],
    u: &'a mut [f32],
    v: &'a mut [f32],
}

/// A vector unit's lookup of `L` points at once (their cells' indices as whole `f32`s, below the
/// cell count, and their fractions), the same operations in the same order as
/// [`bilinear_f32`]: one point at a time ([`OneByOne`], for any CPU), or written with a unit's
/// instructions (see `crate::simd` on closures).
trait LookupGroup<const L: usize>: Copy {
    /// The velocities `(u, v)` of the `L` points.
    fn lookup(
        self,
        cells: &[Cell],
        at: &[f32; L],
        tx: [f32; L],
        ty: [f32; L],
        u: &mut [f32; L],
        v: &mut [f32; L],
    );
}

/// [`Velocities`] in groups of `L` points looked up by `group`, the points left over one at a
/// time.
#[inline(always)]
fn velocities_in_groups<const L: usize>(group: impl LookupGroup<L>, inner: Velocities<'_>) {
    let Velocities {
        flow,
        axes: a,
        x,
        y,
        u,
        v,
    } = inner;
    let mut cell = [0.0f32; BATCH];
    let mut tx = [0.0f32; BATCH];
    let mut ty = [0.0f32; BATCH];
    let cells = &flow.cells[..];
    let points = x.chunks(BATCH).zip(y.chunks(BATCH));
    let places = u.chunks_mut(BATCH).zip(v.chunks_mut(BATCH));
    for ((xs, ys), (us, vs)) in points.zip(places) {
        let m = cells_and_fractions(a, xs, ys, &mut cell, &mut tx, &mut ty);
        let m = m.min(us.len()).min(vs.len());
        let (us, vs) = (&mut us[..m], &mut vs[..m]);
        let (cell_l, _) = cell[..m].as_chunks::<L>();
        let (tx_l, _) = tx[..m].as_chunks::<L>();
        let (ty_l, _) = ty[..m].as_chunks::<L>();
        let (u_l, _) = us.as_chunks_mut::<L>();
        let (v_l, _) = vs.as_chunks_mut::<L>();
        let groups = cell_l.iter().zip(tx_l).zip(ty_l).zip(u_l).zip(v_l);
        for ((((at, &tx), &ty), u), v) in groups {
            group.lookup(cells, at, tx, ty, u, v);
        }
        for k in m / L * L..m {
            (us[k], vs[k]) = bilinear_f32(cell_at(cells, cell[k]), tx[k], ty[k]);
        }
    }
}

/// The plain lookup, one point at a time (the portable version; compiled for a vector unit, the
/// compiler may take several points at once).
#[derive(Clone, Copy)]
struct OneByOne;

impl LookupGroup<1> for OneByOne {
    #[inline(always)]
    fn lookup(
        self,
        cells: &[Cell],
        at: &[f32; 1],
        tx: [f32; 1],
        ty: [f32; 1],
        u: &mut [f32; 1],
        v: &mut [f32; 1],
    ) {
        (u[0], v[0]) = bilinear_f32(cell_at(cells, at[0]), tx[0], ty[0]);
    }
}

/// AVX-512's lookup: sixteen points at a time, their sixteen cells read as eight vectors of two
/// cells each and taken apart so that each coefficient is one vector of sixteen lanes.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
struct GroupV4(pulp::x86::V4);

#[cfg(target_arch = "x86_64")]
impl LookupGroup<16> for GroupV4 {
    #[inline(always)]
    fn lookup(
        self,
        cells: &[Cell],
        at: &[f32; 16],
        tx: [f32; 16],
        ty: [f32; 16],
        u: &mut [f32; 16],
        v: &mut [f32; 16],
    ) {
        use core::arch::x86_64::{__m256, __m512};
        let simd = self.0;
        let f = simd.avx512f;
        let last = f._mm512_set1_epi32(cells.len().saturating_sub(1) as i32);
        let at = f._mm512_cvttps_epu32(pulp::cast(*at));
        let at: [u32; 16] = pulp::cast(f._mm512_min_epu32(at, last));
        let c = |l: usize| -> __m256 { pulp::cast(cells[at[l] as usize].0) };
        // r[i]: cells i and i + 4 (i < 4), or 8 + i and 12 + i (i >= 4), each as
        // [u coefficients, v coefficients] in its two 128-bit lanes.
        let pair = |lo: usize, hi: usize| -> __m512 {
            simd.avx512dq
                ._mm512_insertf32x8::<1>(f._mm512_castps256_ps512(c(lo)), c(hi))
        };
        let r: [__m512; 8] = core::array::from_fn(|i| {
            if i < 4 {
                pair(i, i + 4)
            } else {
                pair(4 + i, 8 + i)
            }
        });
        // 4 x 4 transposes within each 128-bit lane: t[k] (from r[0..4]) and s[k] (from
        // r[4..8]) hold coefficient k (u's in lanes 0 and 2, v's in lanes 1 and 3).
        let four = |q: &[__m512]| -> [__m512; 4] {
            let t0 = f._mm512_unpacklo_ps(q[0], q[1]);
            let t1 = f._mm512_unpackhi_ps(q[0], q[1]);
            let t2 = f._mm512_unpacklo_ps(q[2], q[3]);
            let t3 = f._mm512_unpackhi_ps(q[2], q[3]);
            [
                f._mm512_shuffle_ps::<0x44>(t0, t2),
                f._mm512_shuffle_ps::<0xEE>(t0, t2),
                f._mm512_shuffle_ps::<0x44>(t1, t3),
                f._mm512_shuffle_ps::<0xEE>(t1, t3),
            ]
        };
        let (t, s) = (four(&r[..4]), four(&r[4..]));
        let cu: [__m512; 4] = core::array::from_fn(|k| f._mm512_shuffle_f32x4::<0x88>(t[k], s[k]));
        let cv: [__m512; 4] = core::array::from_fn(|k| f._mm512_shuffle_f32x4::<0xDD>(t[k], s[k]));
        let (x, y): (__m512, __m512) = (pulp::cast(tx), pulp::cast(ty));
        let xy = f._mm512_mul_ps(x, y);
        let sum = |c: &[__m512; 4]| {
            let a = f._mm512_add_ps(c[0], f._mm512_mul_ps(c[1], x));
            let a = f._mm512_add_ps(a, f._mm512_mul_ps(c[2], y));
            f._mm512_add_ps(a, f._mm512_mul_ps(c[3], xy))
        };
        *u = pulp::cast(sum(&cu));
        *v = pulp::cast(sum(&cv));
    }
}

/// AVX2's lookup: eight points at a time. A cell's four `u` coefficients and its four `v`
/// coefficients are a 128-bit half each; the halves of cells `i` and `i + 4` are read into one
/// vector and four such vectors taken apart within their 128-bit lanes, so that each coefficient
/// is one vector of eight lanes in the points' order.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
struct GroupV3(pulp::x86::V3);

#[cfg(target_arch = "x86_64")]
impl LookupGroup<8> for GroupV3 {
    #[inline(always)]
    fn lookup(
        self,
        cells: &[Cell],
        at: &[f32; 8],
        tx: [f32; 8],
        ty: [f32; 8],
        u: &mut [f32; 8],
        v: &mut [f32; 8],
    ) {
        use core::arch::x86_64::{__m128, __m256};
        let (avx, avx2) = (self.0.avx, self.0.avx2);
        let last = avx._mm256_set1_epi32(cells.len().saturating_sub(1) as i32);
        // Whole numbers from 0 to the last cell (an index is exact in f32).
        let at = avx._mm256_cvttps_epi32(pulp::cast(*at));
        let at: [u32; 8] = pulp::cast(
            avx2._mm256_min_epi32(avx2._mm256_max_epi32(at, avx._mm256_setzero_si256()), last),
        );
        // Half `h` (0: u, 4: v) of the cells of points `l` and `l + 4`.
        macro_rules! half {
            ($l:expr, $h:expr) => {{
                let c = &cells[at[$l] as usize].0;
                let lo: __m128 = pulp::cast([c[$h], c[$h + 1], c[$h + 2], c[$h + 3]]);
                let c = &cells[at[$l + 4] as usize].0;
                let hi: __m128 = pulp::cast([c[$h], c[$h + 1], c[$h + 2], c[$h + 3]]);
                avx._mm256_insertf128_ps::<1>(avx._mm256_castps128_ps256(lo), hi)
            }};
        }
        // A 4 x 4 transpose within each 128-bit lane: coefficient k of the half starting at
        // `h`, for points 0-3 in the low lane and 4-7 in the high one.
        macro_rules! four {
            ($h:expr) => {{
                let (q0, q1) = (half!(0, $h), half!(1, $h));
                let (q2, q3) = (half!(2, $h), half!(3, $h));
                let t0 = avx._mm256_unpacklo_ps(q0, q1);
                let t1 = avx._mm256_unpackhi_ps(q0, q1);
                let t2 = avx._mm256_unpacklo_ps(q2, q3);
                let t3 = avx._mm256_unpackhi_ps(q2, q3);
                [
                    avx._mm256_shuffle_ps::<0x44>(t0, t2),
                    avx._mm256_shuffle_ps::<0xEE>(t0, t2),
                    avx._mm256_shuffle_ps::<0x44>(t1, t3),
                    avx._mm256_shuffle_ps::<0xEE>(t1, t3),
                ]
            }};
        }
        let (cu, cv) = (four!(0), four!(4));
        let (x, y): (__m256, __m256) = (pulp::cast(tx), pulp::cast(ty));
        let xy = avx._mm256_mul_ps(x, y);
        macro_rules! sum {
            ($c:expr) => {{
                let a = avx._mm256_add_ps($c[0], avx._mm256_mul_ps($c[1], x));
                let a = avx._mm256_add_ps(a, avx._mm256_mul_ps($c[2], y));
                avx._mm256_add_ps(a, avx._mm256_mul_ps($c[3], xy))
            }};
        }
        *u = pulp::cast(sum!(cu));
        *v = pulp::cast(sum!(cv));
    }
}

/// [`Velocities`] in groups of `L` points of a lookup, as a [`pulp::WithSimd`] operation.
struct VelocitiesIn<'a, G, const L: usize> {
    group: G,
    inner: Velocities<'a>,
}

impl<G: LookupGroup<L>, const L: usize> pulp::WithSimd for VelocitiesIn<'_, G, L> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        velocities_in_groups(self.group, self.inner);
    }
}

impl FarrellFlow {
    /// [`FlowField::velocities_f32`] on the vector unit `arch` (see [`crate::simd`]).
    fn velocities_f32_on(
        &self,
        arch: pulp::Arch,
        origin: [f64; 2],
        x: &[f32],
        y: &[f32],
        u: &mut [f32],
        v: &mut [f32],
    ) {
        let inner = Velocities {
            flow: self,
            axes: self.axes_f32(origin),
            x,
            y,
            u,
            v,
        };
        match arch {
            #[cfg(target_arch = "x86_64")]
            pulp::Arch::V4(simd) => {
                let group = GroupV4(simd);
                pulp::Simd::vectorize(simd, VelocitiesIn { group, inner })
            }
            #[cfg(target_arch = "x86_64")]
            pulp::Arch::V3(simd) => {
                let group = GroupV3(simd);
                pulp::Simd::vectorize(simd, VelocitiesIn { group, inner })
            }
            _ => arch.dispatch(VelocitiesIn {
                group: OneByOne,
                inner,
            }),
        }
    }
}

/// The cells' rebuild on AVX-512: eight cells of a row at a time, each coefficient of the eight
/// taken in lanes (the same operations in the same order as [`FarrellFlow::build_cells`], so the
/// same bits), then transposed into the eight cells and rounded to single precision; the last
/// eight cells of a row again where the row is not a multiple of eight, and a row shorter than
/// eight one cell at a time. (Compiled for AVX-512 without this, the plain loop writes each
/// coefficient to its eight cells with scattered stores, slower than one cell at a time.)
#[cfg(target_arch = "x86_64")]
struct BuildCellsV4<'a> {
    simd: pulp::x86::V4,
    flow: &'a mut FarrellFlow,
}

#[cfg(target_arch = "x86_64")]
impl pulp::WithSimd for BuildCellsV4<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        use core::arch::x86_64::__m512d;
        let f = self.simd.avx512f;
        for (cells, n) in self.flow.cell_rows() {
            fn eights(f: &[f64]) -> &[[f64; 8]] {
                f.as_chunks::<8>().0
            }
            let row = cells.len();
            if row < 8 {
                n.fill(cells);
                continue;
            }
            // `f00, f10 - f00, f01 - f00, f11 - f10 - f01 + f00` of eight cells, left to right,
            // from nodes i and i + 1 of the two rows.
            let coefficients = |s0: &[f64; 8], s1: &[f64; 8], n0: &[f64; 8], n1: &[f64; 8]| {
                let (a0, a1): (__m512d, __m512d) = (pulp::cast(*s0), pulp::cast(*s1));
                let (b0, b1): (__m512d, __m512d) = (pulp::cast(*n0), pulp::cast(*n1));
                let d = f._mm512_sub_pd(f._mm512_sub_pd(b1, a1), b0);
                [
                    a0,
                    f._mm512_sub_pd(a1, a0),
                    f._mm512_sub_pd(b0, a0),
                    f._mm512_add_pd(d, a0),
                ]
            };
            // Cells `at..at + 8` (`at + 8 <= row`).
            let group = |at: usize| {
                let pick = |v: &[f64], from: usize| eights(&v[from..from + 8])[0];
                let [c0, c1, c2, c3] = coefficients(
                    &pick(n.us, at),
                    &pick(n.us, at + 1),
                    &pick(n.un, at),
                    &pick(n.un, at + 1),
                );
                let [c4, c5, c6, c7] = coefficients(
                    &pick(n.vs, at),
                    &pick(n.vs, at + 1),
                    &pick(n.vn, at),
                    &pick(n.vn, at + 1),
                );
                transpose8(f, [c0, c1, c2, c3, c4, c5, c6, c7])
            };
            let (us0, us1) = (eights(&n.us[..row]), eights(&n.us[1..]));
            let (un0, un1) = (eights(&n.un[..row]), eights(&n.un[1..]));
            let (vs0, vs1) = (eights(&n.vs[..row]), eights(&n.vs[1..]));
            let (vn0, vn1) = (eights(&n.vn[..row]), eights(&n.vn[1..]));
            let (groups, _) = cells.as_chunks_mut::<8>();
            for (g, group) in groups.iter_mut().enumerate() {
                let [c0, c1, c2, c3] = coefficients(&us0[g], &us1[g], &un0[g], &un1[g]);
                let [c4, c5, c6, c7] = coefficients(&vs0[g], &vs1[g], &vn0[g], &vn1[g]);
                let rows = transpose8(f, [c0, c1, c2, c3, c4, c5, c6, c7]);
                for (cell, r) in group.iter_mut().zip(rows) {
                    cell.0 = pulp::cast(f._mm512_cvtpd_ps(r));
                }
            }
            // The last eight cells again where the row is not a multiple of eight (the same
            // cells, the same values), so that no cell is built one at a time.
            if row % 8 != 0 {
                let at = row - 8;
                for (cell, r) in cells[at..].iter_mut().zip(group(at)) {
                    cell.0 = pulp::cast(f._mm512_cvtpd_ps(r));
                }
            }
        }
    }
}

/// The cells' rebuild on AVX2: four cells of a row at a time, each coefficient of the four
/// taken in lanes (the same operations in the same order as [`FarrellFlow::build_cells`], so the
/// same bits) and rounded to single precision, then transposed into the four cells; the last
/// four cells of a row again where the row is not a multiple of four, and a row shorter than
/// four one cell at a time.
#[cfg(target_arch = "x86_64")]
struct BuildCellsV3<'a> {
    simd: pulp::x86::V3,
    flow: &'a mut FarrellFlow,
}

#[cfg(target_arch = "x86_64")]
impl pulp::WithSimd for BuildCellsV3<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        use core::arch::x86_64::{__m128, __m256d};
        let (avx, sse) = (self.simd.avx, self.simd.sse);
        for (cells, n) in self.flow.cell_rows() {
            let row = cells.len();
            if row < 4 {
                n.fill(cells);
                continue;
            }
            // Macros, not closures: a closure is compiled without the vector unit's
            // instructions and would call each of them.
            // Nodes `at..at + 4` of `v`.
            macro_rules! four {
                ($v:expr, $at:expr) => {{
                    let q: [f64; 4] = $v[$at..$at + 4]
                        .try_into()
                        .unwrap_or_else(|_| unreachable!("four nodes"));
                    let q: __m256d = pulp::cast(q);
                    q
                }};
            }
            // `f00, f10 - f00, f01 - f00, f11 - f10 - f01 + f00` of cells `at..at + 4` from
            // nodes of rows `s` (south) and `n` (north), in single precision.
            macro_rules! coefficients {
                ($s:expr, $n:expr, $at:expr) => {{
                    let (a0, a1) = (four!($s, $at), four!($s, $at + 1));
                    let (b0, b1) = (four!($n, $at), four!($n, $at + 1));
                    let d = avx._mm256_sub_pd(avx._mm256_sub_pd(b1, a1), b0);
                    [
                        avx._mm256_cvtpd_ps(a0),
                        avx._mm256_cvtpd_ps(avx._mm256_sub_pd(a1, a0)),
                        avx._mm256_cvtpd_ps(avx._mm256_sub_pd(b0, a0)),
                        avx._mm256_cvtpd_ps(avx._mm256_add_pd(d, a0)),
                    ]
                }};
            }
            // The 4 x 4 transpose: vector `p` of the result holds cell `p`'s four coefficients.
            macro_rules! transpose {
                ($c:expr) => {{
                    let c: [__m128; 4] = $c;
                    let t0 = sse._mm_unpacklo_ps(c[0], c[1]);
                    let t1 = sse._mm_unpacklo_ps(c[2], c[3]);
                    let t2 = sse._mm_unpackhi_ps(c[0], c[1]);
                    let t3 = sse._mm_unpackhi_ps(c[2], c[3]);
                    [
                        sse._mm_movelh_ps(t0, t1),
                        sse._mm_movehl_ps(t1, t0),
                        sse._mm_movelh_ps(t2, t3),
                        sse._mm_movehl_ps(t3, t2),
                    ]
                }};
            }
            // Cells `at..at + 4` (`at + 4 <= row`).
            macro_rules! group {
                ($at:expr) => {{
                    let at = $at;
                    let u = transpose!(coefficients!(n.us, n.un, at));
                    let v = transpose!(coefficients!(n.vs, n.vn, at));
                    for (p, cell) in cells[at..at + 4].iter_mut().enumerate() {
                        let (u, v): ([f32; 4], [f32; 4]) = (pulp::cast(u[p]), pulp::cast(v[p]));
                        cell.0 = [u[0], u[1], u[2], u[3], v[0], v[1], v[2], v[3]];
                    }
                }};
            }
            for g in 0..row / 4 {
                group!(4 * g);
            }
            // The last four cells again where the row is not a multiple of four (the same
            // cells, the same values), so that no cell is built one at a time.
            if row % 4 != 0 {
                group!(row - 4);
            }
        }
    }
}

/// The interior's step and the cells' rebuild, as a [`pulp::WithSimd`] operation (see
/// [`crate::simd`]).
struct GridStep<'a> {
    flow: &'a mut FarrellFlow,
    dt_s: f64,
}

impl pulp::WithSimd for GridStep<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        self.flow.step_interior(self.dt_s);
    }
}

impl FlowField for FarrellFlow {
    fn name(&self) -> &'static str {
        "farrell"
    }
    fn time_s(&self) -> f64 {
        self.time_s
    }
    fn velocity(&self, pos_m: Vec2) -> Vec2 {
        let (u, v) = self.interp(pos_m.x, pos_m.y);
        Vec2::new(u, v)
    }
    fn velocities_f32(&self, origin: [f64; 2], x: &[f32], y: &[f32], u: &mut [f32], v: &mut [f32]) {
        self.velocities_f32_on(crate::simd::best(), origin, x, y, u, v);
    }
    fn advance(&mut self, t_new_s: f64, dt_s: f64, rng: &mut SimRng) -> Result<(), EnvError> {
        self.noise.update(dt_s, rng);
        self.apply_boundary(self.mean.velocity_at(t_new_s));
        let arch = crate::simd::best();
        arch.dispatch(GridStep { flow: self, dt_s });
        self.build_cells_on(arch);
        self.time_s = t_new_s;
        // A runaway field is a bug or an unstable set-up: stop rather than emit garbage.
        let limit = 100.0 * (1.0 + self.mean.max_speed_mps());
        if !(self.max_speed_mps.is_finite() && self.max_speed_mps < limit) {
            return Err(EnvError::Diverged {
                time_s: t_new_s,
                message: format!(
                    "largest node speed {:?} m/s (limit {limit:?} m/s): the meandering field is \
                     unstable with these settings; lower sim.dt_s (mission.env_dt_s, \
                     mission.spinup_dt_s) or flow.farrell.noise_gain, or raise \
                     flow.farrell.noise_damping",
                    self.max_speed_mps
                ),
            });
        }
        Ok(())
    }
    fn max_stable_dt_s(&self) -> Option<f64> {
        Some(self.max_stable_dt_s)
    }
    fn nodes(&self) -> usize {
        self.params.nx * self.params.ny
    }
    fn own_step_s(&self) -> Option<f64> {
        (self.params.step_s > 0.0).then_some(self.params.step_s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{StreamId, stream_rng};

    fn pompy_region() -> Rect {
        Rect {
            x_min_m: 0.0,
            x_max_m: 100.0,
            y_min_m: -50.0,
            y_max_m: 50.0,
        }
    }

    fn steady(speed: f64, toward: f64) -> MeanFlow {
        MeanFlow::Steady {
            speed_mps: speed,
            toward_deg: toward,
        }
    }

    /// Sample variance of the channels' output after `steps` steps of `dt` (after ten
    /// correlation times of burn-in), sampled about once per correlation time.
    fn sample_variance(noise: &mut ColouredNoise, dt: f64, steps: usize, seed: u64) -> f64 {
        let mut rng = stream_rng(seed, StreamId::Flow);
        let corr = 1.0 / (noise.damping * noise.bandwidth);
        let burn = (10.0 * corr / dt).ceil() as usize;
        for _ in 0..burn {
            noise.update(dt, &mut rng);
        }
        let every = ((0.5 * corr / dt).round() as usize).max(1);
        let (mut sum, mut sum_sq, mut n) = (0.0, 0.0, 0.0);
        for step in 0..steps {
            noise.update(dt, &mut rng);
            if step % every == 0 {
                for &x in noise.output() {
                    sum += x;
                    sum_sq += x * x;
                    n += 1.0;
                }
            }
        }
        let mean = sum / n;
        sum_sq / n - mean * mean
    }

    #[test]
    fn coloured_noise_variance_is_the_same_at_every_step() {
        // pompy's G = 2, w = 0.2, z = 0.1 (variance 2.0, correlation time 50 s) at steps from
        // 0.1 s to 10 s (explicit Euler was 12 % off at 0.1 s and diverged beyond 1 s), and the
        // Duck presets' slow meander z = 0.2, w = 0.02 (correlation time 250 s).
        let cases: [(f64, f64, f64, &[f64]); 2] = [
            (2.0, 0.1, 0.2, &[0.1, 1.0, 5.0, 10.0]),
            // The Duck presets' environment step, spin-up step, and beyond.
            (0.5, 0.2, 0.02, &[0.5, 5.0, 10.0]),
        ];
        for (gain, z, w, steps_s) in cases {
            let corr = 1.0 / (z * w);
            for &dt in steps_s {
                // About 400,000 samples half a correlation time apart: standard error of the
                // variance about 0.3 % (sampled twice per correlation time they are only weakly
                // correlated).
                let mut noise = ColouredNoise::new(1000, gain, z, w, NoiseUpdates::Exact);
                let steps = (200.0 * corr / dt).round() as usize;
                let var = sample_variance(&mut noise, dt, steps, 3);
                let want = noise.stationary_variance();
                eprintln!("z {z} w {w} dt {dt}: variance {var:.5}, theory {want:.5}");
                assert!(
                    (var - want).abs() / want < 0.02,
                    "z {z}, w {w}, dt {dt}: variance {var}, theory {want}"
                );
            }
        }
    }

    #[test]
    fn euler_maruyama_variance_depends_on_the_step() {
        // The same measurement as above finds the Euler scheme's bias (about 12 % at 0.1 s for
        // pompy's parameters), so a 2 % tolerance there is a real test.
        let mut noise = ColouredNoise::new(1000, 2.0, 0.1, 0.2, NoiseUpdates::EulerMaruyama);
        let var = sample_variance(&mut noise, 0.1, (200.0 * 50.0 / 0.1) as usize, 3);
        let want = noise.stationary_variance();
        eprintln!("Euler-Maruyama at 0.1 s: variance {var:.5}, theory {want:.5}");
        assert!((var - want) / want > 0.06, "variance {var}, theory {want}");
    }

    #[test]
    fn exact_step_keeps_the_stationary_covariance() {
        // Algebra of the exact step: P = Phi P Phi^T + L L^T for under-, critically and
        // overdamped channels, at small and large steps (a wrong Phi or L breaks it).
        for (z, w) in [
            (0.1, 0.2),
            (0.2, 0.02),
            (1.0, 0.3),
            (1.0 + 1e-9, 0.3),
            (21.0, 0.2),
        ] {
            for dt in [1e-3, 0.1, 1.0, 5.0, 10.0, 100.0] {
                let noise = ColouredNoise::new(1, 2.0, z, w, NoiseUpdates::Exact);
                let (phi, l) = noise.exact_step(dt);
                let [p0, p1] = noise.stationary_covariance();
                let p = [[p0, 0.0], [0.0, p1]];
                let q = [
                    [l[0][0] * l[0][0], l[0][0] * l[1][0]],
                    [l[0][0] * l[1][0], l[1][0] * l[1][0] + l[1][1] * l[1][1]],
                ];
                for i in 0..2 {
                    for j in 0..2 {
                        let mut v = q[i][j];
                        for k in 0..2 {
                            v += phi[i][k] * p[k][k] * phi[j][k];
                        }
                        let scale = (p[i][i] * p[j][j]).sqrt();
                        assert!(
                            (v - p[i][j]).abs() <= 1e-9 * scale,
                            "z {z} w {w} dt {dt} ({i},{j}): {v} vs {}",
                            p[i][j]
                        );
                    }
                }
                // Phi is the flow of the noiseless oscillator: d Phi/dt = A Phi at small steps.
                let small = oscillator_transition(z, w, 1e-6);
                assert!(
                    (small[0][1] - 1e-6).abs() < 1e-9 && (small[1][0] + w * w * 1e-6).abs() < 1e-9
                );
                assert!(phi.iter().flatten().all(|x| x.is_finite()));
            }
        }
        // Composition: two half steps equal one full step.
        let (z, w) = (0.1, 0.2);
        let half = oscillator_transition(z, w, 2.5);
        let full = oscillator_transition(z, w, 5.0);
        for i in 0..2 {
            for j in 0..2 {
                let v = half[i][0] * half[0][j] + half[i][1] * half[1][j];
                assert!(
                    (v - full[i][j]).abs() < 1e-12,
                    "({i},{j}) {v} vs {}",
                    full[i][j]
                );
            }
        }
    }

    #[test]
    fn no_noise_keeps_uniform_mean() {
        let params = FarrellParams {
            noise_gain: 0.0,
            ..FarrellParams::default()
        };
        let mut f = FarrellFlow::new(pompy_region(), steady(1.0, 90.0), params, 0.01).unwrap();
        let mut rng = stream_rng(1, StreamId::Flow);
        for k in 1..=500 {
            assert!(f.advance(f64::from(k) * 0.01, 0.01, &mut rng).is_ok());
        }
        let v = f.velocity(Vec2::new(37.0, 12.0));
        assert!((v.x - 1.0).abs() < 1e-9 && v.y.abs() < 1e-9, "{v:?}");
    }

    #[test]
    fn long_run_stays_finite_and_bounded() {
        let mut f = FarrellFlow::new(
            pompy_region(),
            steady(1.0, 90.0),
            FarrellParams::default(),
            0.05,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let mut rng = stream_rng(11, StreamId::Flow);
        let mut worst: f64 = 0.0;
        for k in 1..=40_000u32 {
            f.advance(f64::from(k) * 0.05, 0.05, &mut rng)
                .unwrap_or_else(|e| panic!("{e}"));
            worst = worst.max(f.max_speed_mps());
        }
        // 2000 s: corner noise sd is sqrt(2) m/s, so speeds stay well within 1 + 6 sd.
        assert!(
            worst.is_finite() && worst < 1.0 + 6.0 * 2f64.sqrt(),
            "max speed {worst}"
        );
        assert!(worst > 1.2, "the field never meandered: max speed {worst}");
    }

    #[test]
    fn the_corner_oscillator_limits_the_step_of_the_original_updates() {
        // Damping 0.1, bandwidth 0.2 rad/s: with the original (explicit Euler) updates
        // dt < 2 z / w = 1 s. A small gain keeps the other limits (advection, diffusion, Courant)
        // far above it.
        let region = Rect {
            x_min_m: 0.0,
            x_max_m: 1000.0,
            y_min_m: 0.0,
            y_max_m: 1000.0,
        };
        let params = FarrellParams {
            noise_gain: 0.1,
            original_noise_updates: true,
            ..FarrellParams::default()
        };
        let err = FarrellFlow::new(region, steady(0.1, 90.0), params, 2.0)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(err.starts_with("dt_s") && err.contains("1.0000"), "{err}");
        // The check is strict: at the limit itself Euler is only marginally stable.
        assert!(FarrellFlow::new(region, steady(0.1, 90.0), params, 1.0).is_err());
        assert!(FarrellFlow::new(region, steady(0.1, 90.0), params, 0.999).is_ok());
        let f = FarrellFlow::new(region, steady(0.1, 90.0), params, 0.5).unwrap();
        assert!((f.max_stable_dt_s().unwrap() - 1.0).abs() < 1e-12);
        // A run at 2 s (what the check forbids) does blow up.
        let mut g = FarrellFlow::new(region, steady(0.1, 90.0), params, 0.5).unwrap();
        let mut rng = stream_rng(1, StreamId::Flow);
        let mut diverged = false;
        for k in 1..=5_000u32 {
            if g.advance(f64::from(k) * 2.0, 2.0, &mut rng).is_err() {
                diverged = true;
                break;
            }
        }
        assert!(diverged, "explicit Euler beyond 2 z / w should diverge");
    }

    #[test]
    fn an_overdamped_oscillator_is_limited_by_its_fast_mode_in_the_original_updates() {
        // Damping 21, bandwidth 0.05 rad/s, original (explicit Euler) updates: 2 z / w = 840 s
        // would allow any step, but the fast real eigenvalue w (z + sqrt(z^2 - 1)) = 2.0988 rad/s
        // limits dt to about 0.953 s.
        let region = Rect {
            x_min_m: 0.0,
            x_max_m: 1000.0,
            y_min_m: 0.0,
            y_max_m: 1000.0,
        };
        let params = FarrellParams {
            noise_gain: 0.1,
            noise_damping: 21.0,
            noise_bandwidth_radps: 0.05,
            original_noise_updates: true,
            ..FarrellParams::default()
        };
        let want = 2.0 / (0.05 * (21.0 + (21.0_f64 * 21.0 - 1.0).sqrt()));
        assert!((want - 0.953).abs() < 1e-3, "{want}");
        let err = FarrellFlow::new(region, steady(0.1, 90.0), params, 2.0)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(err.starts_with("dt_s"), "{err}");
        let f = FarrellFlow::new(region, steady(0.1, 90.0), params, 0.5).unwrap();
        assert!((f.max_stable_dt_s().unwrap() - want).abs() < 1e-12);
        // Stepping at 2 s with these parameters diverges, at 0.5 s it stays bounded.
        let run = |dt: f64| {
            let mut g = FarrellFlow::new(region, steady(0.1, 90.0), params, 0.5).unwrap();
            let mut rng = stream_rng(1, StreamId::Flow);
            (1..=2_000u32).all(|k| g.advance(f64::from(k) * dt, dt, &mut rng).is_ok())
        };
        assert!(
            !run(2.0),
            "explicit Euler beyond the fast mode's limit should diverge"
        );
        assert!(run(0.5));
    }

    #[test]
    fn the_exact_corner_noise_allows_any_step() {
        // The two set-ups above, with the default (exact) corner noise: the oscillator no longer
        // limits the step, and stepping at 2 s and 10 s stays bounded with the same corner
        // statistics (the interior's own limits are far above these steps).
        let region = Rect {
            x_min_m: 0.0,
            x_max_m: 1000.0,
            y_min_m: 0.0,
            y_max_m: 1000.0,
        };
        for (z, w) in [(0.1, 0.2), (21.0, 0.05)] {
            let params = FarrellParams {
                noise_gain: 0.1,
                noise_damping: z,
                noise_bandwidth_radps: w,
                noise_scheme: NoiseScheme::Exact,
                ..FarrellParams::default()
            };
            for dt in [2.0, 10.0] {
                let mut g = FarrellFlow::new(region, steady(0.1, 90.0), params, dt)
                    .unwrap_or_else(|e| panic!("z {z} dt {dt}: {e}"));
                assert!(g.max_stable_dt_s().is_some_and(|l| l > dt));
                let mut rng = stream_rng(1, StreamId::Flow);
                for k in 1..=2_000u32 {
                    g.advance(f64::from(k) * dt, dt, &mut rng)
                        .unwrap_or_else(|e| panic!("z {z} dt {dt}: {e}"));
                }
                assert!(g.max_speed_mps() < 0.1 + 6.0 * g.noise.stationary_variance().sqrt());
            }
        }
    }

    #[test]
    fn rejects_unstable_dt() {
        // 101 x 101 nodes over 100 m with k = 20: diffusion limit 1/(2*10*2) = 0.025 s.
        let params = FarrellParams {
            nx: 101,
            ny: 101,
            ..FarrellParams::default()
        };
        let err = FarrellFlow::new(pompy_region(), steady(1.0, 90.0), params, 0.05)
            .err()
            .map(|e| e.to_string());
        let err = err.unwrap_or_default();
        assert!(
            err.starts_with("dt_s") && err.contains("stable limit"),
            "{err}"
        );
        assert!(FarrellFlow::new(pompy_region(), steady(1.0, 90.0), params, 0.02).is_ok());
    }

    /// pompy's field after 3 s of meander at its own 0.01 s step (seeded).
    fn meandering_pompy_flow(seed: u64) -> FarrellFlow {
        meandering_flow(seed, FarrellParams::default())
    }

    /// Pompy's flow on the grid of `params`, after 3 s of meander.
    fn meandering_flow(seed: u64, params: FarrellParams) -> FarrellFlow {
        let mut f = FarrellFlow::new(pompy_region(), steady(1.0, 60.0), params, 0.01)
            .unwrap_or_else(|e| panic!("{e}"));
        let mut rng = stream_rng(seed, StreamId::Flow);
        for k in 1..=300u32 {
            f.advance(f64::from(k) * 0.01, 0.01, &mut rng)
                .unwrap_or_else(|e| panic!("{e}"));
        }
        f
    }

    #[test]
    fn batch_velocities_are_the_single_point_ones_bit_for_bit() {
        // The batch path (floors in floating point, sixteen points at a time on AVX-512, eight on
        // AVX2) and a
        // lookup of one point at a time with integer floors (written out here) give the same
        // bits everywhere:
        // inside, on nodes, outside the grid, NaN; on every vector unit this CPU has.
        let f = meandering_pompy_flow(3);
        // The special points first (in the vector lanes) and last (one at a time).
        let special_x = [0.0, 5.0, 100.0, 99.999_99, f32::NAN, 50.0, f32::INFINITY];
        let special_y = [0.0, -50.0, 50.0, 12.5, 3.0, f32::NAN, f32::NEG_INFINITY];
        let mut xs = special_x.to_vec();
        let mut ys = special_y.to_vec();
        for k in 0..990u32 {
            let t = f64::from(k);
            xs.push((-20.0 + (t * 0.1371).rem_euclid(1.0) * 140.0) as f32);
            ys.push((-70.0 + (t * 0.7193).rem_euclid(1.0) * 140.0) as f32);
        }
        xs.extend(special_x);
        ys.extend(special_y);
        let (nx, ny) = (f.params.nx, f.params.ny);
        let a = f.axes_f32([0.0, 0.0]);
        let weight = |p: f32, origin: f32, inv: f32, n: usize| -> (usize, f32) {
            let g = (p - origin) * inv;
            let g = if g > 0.0 { g } else { 0.0 };
            let g = g.min((n - 1) as f32);
            let i = (g as usize).min(n - 2);
            (i, g - i as f32)
        };
        for arch in crate::simd::every() {
            let mut u = vec![0.0; xs.len()];
            let mut v = vec![0.0; xs.len()];
            f.velocities_f32_on(arch, [0.0, 0.0], &xs, &ys, &mut u, &mut v);
            for k in 0..xs.len() {
                let (i, tx) = weight(xs[k], a.x0, a.inv_dx, nx);
                let (j, ty) = weight(ys[k], a.y0, a.inv_dy, ny);
                let (wu, wv) = bilinear_f32(&f.cells[j * (nx - 1) + i], tx, ty);
                assert_eq!(
                    (u[k].to_bits(), v[k].to_bits()),
                    (wu.to_bits(), wv.to_bits()),
                    "at ({}, {}) on {arch:?}",
                    xs[k],
                    ys[k]
                );
            }
        }
    }

    #[test]
    fn every_vector_unit_steps_the_grid_to_the_same_bits() {
        // Rows of 20 cells (pompy's grid): two groups of eight and the last eight again on
        // AVX-512, five groups of four on AVX2; of 22: the last four again on AVX2 too; of 10:
        // one group and the last eight again on AVX-512, two groups and the last four again on
        // AVX2; of 3: one cell at a time on both.
        for nx in [21, 23, 11, 4] {
            let params = FarrellParams {
                nx,
                ..FarrellParams::default()
            };
            vector_units_step_the_grid_to_the_same_bits(&meandering_flow(5, params));
        }
    }

    /// [`every_vector_unit_steps_the_grid_to_the_same_bits`] for one flow.
    fn vector_units_step_the_grid_to_the_same_bits(f: &FarrellFlow) {
        let bits = |f: &FarrellFlow| -> Vec<u64> {
            let cells = f
                .cells
                .iter()
                .flat_map(|c| c.0)
                .map(|c| u64::from(c.to_bits()));
            f.u.iter()
                .chain(&f.v)
                .map(|v| v.to_bits())
                .chain(cells)
                .collect()
        };
        let mut reference = None;
        for arch in crate::simd::every() {
            let mut g = f.clone();
            arch.dispatch(GridStep {
                flow: &mut g,
                dt_s: 0.01,
            });
            g.build_cells_on(arch);
            let got = (bits(&g), g.max_speed_mps.to_bits());
            match &reference {
                None => {
                    assert_ne!(got.0, bits(f));
                    reference = Some(got);
                }
                Some(r) => assert!(*r == got, "{arch:?} differs from the portable version"),
            }
        }
    }

    #[test]
    fn bilinear_interpolation_is_exact_on_nodes_and_linear_between() {
        let mut f = FarrellFlow::new(
            pompy_region(),
            steady(0.0, 0.0),
            FarrellParams::default(),
            0.01,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        // Impose u = x / 10 on the interior and check interpolation reproduces the linear field.
        let nx = f.params.nx;
        for j in 0..f.params.ny {
            for i in 0..nx {
                f.u[(j + 1) * (nx + 2) + i + 1] = (i as f64 * f.dx_m) / 10.0;
            }
        }
        f.build_cells();
        for x in [0.0_f64, 2.5, 5.0, 33.3, 99.9, 100.0, 120.0, -5.0] {
            let want = x.clamp(0.0, 100.0) / 10.0;
            let got = f.velocity(Vec2::new(x, 7.0)).x;
            assert!((got - want).abs() < 1e-9, "u({x}) = {got}, want {want}");
        }
    }
}
