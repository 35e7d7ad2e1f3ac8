//! The source-likelihood map: a posterior over candidate source cells of the op-area, built from
//! every chemical sample (after Pang and Farrell 2006).
//!
//! **Cells.** Square cells of `resolution_m` over the op-area's bounding box; cells whose centres
//! lie outside the op-area are not candidates. The prior is uniform over the candidates. The
//! posterior is kept as log-probabilities; an update touches only the cells of the sample's
//! footprint, and the map is normalised (log-sum-exp) before it is read, so what is read always
//! has mass 1 to rounding.
//!
//! **Flow history.** The current is taken as uniform over the area but varying in time, as the
//! vehicle measures it: each flow reading is held until the next, and the cumulative displacement
//! `X(t)` of a water parcel is kept at every reading (a ring buffer of `window_s` plus the newest
//! reading), so the displacement over any interval costs one binary search. Before the first
//! reading the first one is assumed; after the last, the last.
//!
//! **Back-projection.** A sample taken at `x_k` at time `t_k` may carry chemical released at
//! `t_k - T` for any travel time `T` in `0..=window_s`; that chemical left
//! `e(T) = x_k - (X(t_k) - X(t_k - T))`. The release point is uncertain by a Gaussian spread
//! `sigma(T)^2 = spread0_m^2 + 2 diffusivity_m2ps T` (turbulent dispersion and flow error both
//! grow with travel time). Travel times are taken at steps of one spread of flow travel (at
//! least one second and half a cell), so successive footprints overlap.
//!
//! **Spread along the flow.** The spread need not be the same in every direction: with
//! `along_ratio` below 1 it grows along the flow's path by `2 along_ratio diffusivity T` and
//! across it by `2 diffusivity T`, an ellipse whose long axis lies across the displacement
//! `X(t_k) - X(t_k - T)`. The meander moves chemical across the mean flow more than along it;
//! a round spread as wide as the meander also said that a sample saw sources downflow of where
//! the flow carried its chemical from, which moved the map's peak downflow. Successive
//! footprints are then one along-flow spread apart. With `along_speed_mps` positive the ratio
//! follows the measured current instead, `min(1, U / along_speed_mps)`: round in a current at
//! least that fast, narrower along the path the slower the current runs.
//!
//! **Vertical mixing.** The source is on the bottom and the vehicle samples at altitude `z`.
//! Chemical released at the bed spreads upwards as a reflected Gaussian with vertical diffusivity
//! `K_z`: after travel time `T` the concentration at height `z` is `exp(-z^2 / (4 K_z T))` of the
//! concentration at the bed. Near the source (small `T`) the chemical has not reached the
//! vehicle's altitude, so a sample there says little about the cells just upflow of it; far
//! downflow the factor approaches 1. `K_z = 0`, or an unknown altitude, turns the factor off.
//! `K_z` is an effective value, not the plume's own vertical diffusivity: a filament's own size
//! and a threshold detector bring chemical to the vehicle's altitude sooner than diffusion of
//! the filaments' centres alone (on Duck-like sites whose plume diffuses vertically at
//! 0.001 m^2/s, a map with `K_z` of 0.001-0.003 placed the source 10-100 m upflow of it).
//! With `vertical_mixing_length_m` positive, `K_z` is that length times the measured flow speed
//! instead (a bottom boundary layer mixes in proportion to its friction velocity, itself about
//! proportional to the current), so the distance downflow at which the chemical reaches the
//! vehicle, about `z^2 / (4 l)`, no longer depends on the current.
//!
//! **Dilution.** The mean concentration of a plume from a point source falls as its cross-section
//! grows, about as one over travel time once diffusion dominates: beyond `dilution_s` the chance
//! of a detection is scaled by `dilution_s / T`, so a detection favours sources a moderate travel
//! time upflow over sources far upflow that would reach the vehicle only diluted.
//!
//! **Footprint and likelihood.** A cell's footprint value is `s(c) = max_T m(T) d(T) g_T(c)` with
//! `g_T` the Gaussian of `e(T)` and `sigma(T)` (1 at its centre), `m(T)` the vertical factor and
//! `d(T)` the dilution: how strongly the sample sees a source in `c`. With the source in `c`, a sample detects with
//! probability `P(c) = p_false + (p_detect - p_false) s(c)`: `p_detect` below 1 is the plume's
//! intermittency (inside the plume most samples still read nothing, so a non-detection there
//! lowers a cell only by `1 - p_detect` at most), and `p_false` is the chance of a detection from
//! a source elsewhere (background, another source, a spike). A detection multiplies each cell by
//! `P(c)`, a non-detection by `1 - P(c)`; cells outside the footprint take the same factor,
//! which normalisation removes, so only footprint cells are touched. Samples of the same outcome
//! closer together than `correlation_s` are not independent (the vehicle sees the same filament,
//! or the same stretch of clean water): each sample's log likelihood is weighed by the time since
//! the previous sample *of the same outcome* over `correlation_s` (at most 1). A detection after a
//! quiet spell is therefore a whole look, however many non-detections came before it, and a spell
//! inside the plume or out of it adds about one look per `correlation_s`. (Weighing every sample by
//! the time since the previous one, whatever it read, made a contact of a second or two count as a
//! tenth of a look against minutes of non-detections: the map then placed the source downflow of
//! the most upflow detections.)
//!
//! A non-detection's factor is at most that of the cells it says nothing about, so it never
//! raises a cell relative to them; a detection's is at least theirs.

use plumetrace_core::Vec2;
use plumetrace_guidance::OpArea;
use std::collections::VecDeque;

/// The likelihood model's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapModel {
    /// Cell size, m.
    pub resolution_m: f64,
    /// Longest travel time back-projected, s.
    pub window_s: f64,
    /// Spread of the release point at zero travel time, m.
    pub spread0_m: f64,
    /// Growth of the spread: `sigma^2 = spread0^2 + 2 diffusivity T`, m^2/s.
    pub diffusivity_m2ps: f64,
    /// Growth of the spread along the flow as a fraction of `diffusivity_m2ps` (1: the same
    /// spread in every direction).
    pub along_ratio: f64,
    /// When positive, the along-flow ratio is `min(1, U / along_speed_mps)` with `U` the measured
    /// flow speed, replacing `along_ratio`, m/s.
    pub along_speed_mps: f64,
    /// Vertical diffusivity for the bottom source's mixing up to the vehicle (0: off), m^2/s.
    pub vertical_diffusivity_m2ps: f64,
    /// When positive, the vertical diffusivity is this length times the measured flow speed
    /// instead of `vertical_diffusivity_m2ps` (bottom boundary-layer mixing), m.
    pub vertical_mixing_length_m: f64,
    /// Probability that a sample inside the plume detects (intermittency).
    pub p_detect: f64,
    /// Probability that a sample detects with the source elsewhere.
    pub p_false: f64,
    /// Samples closer together than this count as one, s.
    pub correlation_s: f64,
    /// Dilution: beyond this travel time the chance of a detection falls as `dilution_s / T`
    /// (the mean concentration of a diffusing plume falls as one over travel time; 0: off), s.
    pub dilution_s: f64,
    /// When positive, dilution begins this far downflow instead (after `dilution_m` over the
    /// measured flow speed, replacing `dilution_s`), m.
    pub dilution_m: f64,
}

impl Default for MapModel {
    fn default() -> Self {
        MapModel {
            resolution_m: 5.0,
            window_s: 3600.0,
            spread0_m: 3.0,
            diffusivity_m2ps: 0.1,
            along_ratio: 1.0,
            along_speed_mps: 0.0,
            vertical_diffusivity_m2ps: 0.01,
            vertical_mixing_length_m: 0.0,
            p_detect: 0.1,
            p_false: 0.002,
            correlation_s: 10.0,
            dilution_s: 60.0,
            dilution_m: 0.0,
        }
    }
}

/// Cumulative water displacement from flow readings held between samples.
#[derive(Debug, Clone, PartialEq, Default)]
struct FlowHistory {
    /// `(time, displacement at that time, velocity from then on)`, oldest first.
    samples: VecDeque<(f64, Vec2, Vec2)>,
}

impl FlowHistory {
    fn add(&mut self, t_s: f64, v_mps: Vec2, keep_s: f64) {
        if !(t_s.is_finite() && v_mps.x.is_finite() && v_mps.y.is_finite()) {
            return;
        }
        match self.samples.back().copied() {
            Some((t0, _, _)) if t_s <= t0 => {
                // Same time (or out of order): the newer reading replaces the velocity.
                if let Some(last) = self.samples.back_mut() {
                    last.2 = v_mps;
                }
                return;
            }
            Some((t0, x0, v0)) => self.samples.push_back((t_s, x0 + v0 * (t_s - t0), v_mps)),
            None => self.samples.push_back((t_s, Vec2::zeros(), v_mps)),
        }
        while self.samples.len() > 2 && self.samples[1].0 < t_s - keep_s {
            self.samples.pop_front();
        }
    }

    /// The displacement at `t_s` (relative to an arbitrary origin).
    fn at(&self, t_s: f64) -> Vec2 {
        let Some(&(t_first, x_first, v_first)) = self.samples.front() else {
            return Vec2::zeros();
        };
        if t_s <= t_first {
            return x_first + v_first * (t_s - t_first);
        }
        let i = self.samples.partition_point(|s| s.0 <= t_s);
        let (t0, x0, v0) = self.samples[i - 1];
        x0 + v0 * (t_s - t0)
    }

    fn speed_mps(&self) -> f64 {
        self.samples.back().map_or(0.0, |s| s.2.norm())
    }
}

/// The source-likelihood map of one vehicle (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SourceMap {
    model: MapModel,
    x0: f64,
    y0: f64,
    nx: usize,
    ny: usize,
    /// Candidate index of each grid cell (`u32::MAX`: outside the op-area).
    index: Vec<u32>,
    /// Centre of each candidate.
    centres: Vec<Vec2>,
    /// Normalised log-probability of each candidate.
    log_p: Vec<f64>,
    /// Its probability.
    p: Vec<f64>,
    flow: FlowHistory,
    /// Time of the last sample of each outcome: `[non-detection, detection]`.
    last_sample_s: [Option<f64>; 2],
    /// Scratch: footprint value per candidate (zero outside the last footprint) and the touched
    /// candidates.
    scratch: Vec<f64>,
    touched: Vec<usize>,
    /// Scratch: the Gaussian along x of one splat.
    gx: Vec<f64>,
    /// Updates since the last normalisation.
    dirty: bool,
    updates: u64,
}

/// Footprint values below this are taken as zero (the cell is left alone).
const FOOTPRINT_FLOOR: f64 = 1e-4;

/// Raises candidate `k`'s footprint value (none for a cell outside the op-area) to `v` where `v`
/// is above it and at least [`FOOTPRINT_FLOOR`], noting the candidates it touches.
#[inline]
fn raise(scratch: &mut [f64], touched: &mut Vec<usize>, k: u32, v: f64) {
    if k == u32::MAX || v < FOOTPRINT_FLOOR {
        return;
    }
    let k = k as usize;
    if v > scratch[k] {
        if scratch[k] == 0.0 {
            touched.push(k);
        }
        scratch[k] = v;
    }
}

/// The most grid cells a map may have.
pub const MAX_CELLS: usize = 4_000_000;

impl SourceMap {
    /// A uniform map over `area` with the given model; `None` when no cell centre lies inside
    /// the area or the grid would exceed [`MAX_CELLS`].
    pub fn new(area: &OpArea, model: MapModel) -> Option<Self> {
        let v = area.vertices();
        let (mut x_lo, mut x_hi, mut y_lo, mut y_hi) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for p in v {
            x_lo = x_lo.min(p.x);
            x_hi = x_hi.max(p.x);
            y_lo = y_lo.min(p.y);
            y_hi = y_hi.max(p.y);
        }
        let r = model.resolution_m;
        if !(r > 0.0 && x_hi > x_lo && y_hi > y_lo) {
            return None;
        }
        let nx = ((x_hi - x_lo) / r).ceil().max(1.0);
        let ny = ((y_hi - y_lo) / r).ceil().max(1.0);
        if nx * ny > MAX_CELLS as f64 {
            return None;
        }
        let (nx, ny) = (nx as usize, ny as usize);
        let mut index = vec![u32::MAX; nx * ny];
        let mut centres = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let c = Vec2::new(x_lo + (i as f64 + 0.5) * r, y_lo + (j as f64 + 0.5) * r);
                if area.contains(c) {
                    index[j * nx + i] = centres.len() as u32;
                    centres.push(c);
                }
            }
        }
        let n = centres.len();
        if n == 0 {
            return None;
        }
        let lp = -(n as f64).ln();
        Some(SourceMap {
            model,
            x0: x_lo,
            y0: y_lo,
            nx,
            ny,
            index,
            centres,
            log_p: vec![lp; n],
            p: vec![1.0 / n as f64; n],
            flow: FlowHistory::default(),
            last_sample_s: [None; 2],
            scratch: vec![0.0; n],
            touched: Vec::new(),
            gx: Vec::new(),
            dirty: false,
            updates: 0,
        })
    }

    /// [`SourceMap::new`] over the polygon `vertices` (`None` also for a polygon that is not
    /// an op-area).
    pub fn from_vertices(vertices: &[Vec2], model: MapModel) -> Option<Self> {
        OpArea::new(vertices.to_vec())
            .ok()
            .and_then(|a| Self::new(&a, model))
    }

    /// The model.
    pub fn model(&self) -> &MapModel {
        &self.model
    }

    /// Number of candidate cells.
    pub fn len(&self) -> usize {
        self.centres.len()
    }

    /// Whether there are no candidates (never, for a built map).
    pub fn is_empty(&self) -> bool {
        self.centres.is_empty()
    }

    /// The grid: lower-left corner, cell size and cells along x and y.
    pub fn grid(&self) -> (Vec2, f64, usize, usize) {
        (
            Vec2::new(self.x0, self.y0),
            self.model.resolution_m,
            self.nx,
            self.ny,
        )
    }

    /// Centre of each candidate.
    pub fn centres(&self) -> &[Vec2] {
        &self.centres
    }

    /// Probability of each candidate (sums to 1).
    pub fn probabilities(&mut self) -> &[f64] {
        self.normalise();
        &self.p
    }

    /// Log-probability of each candidate (normalised).
    pub fn log_probabilities(&mut self) -> &[f64] {
        self.normalise();
        &self.log_p
    }

    /// Samples taken into account so far.
    pub fn updates(&self) -> u64 {
        self.updates
    }

    /// Adds a flow reading taken at `t_s`.
    pub fn add_flow(&mut self, t_s: f64, velocity_mps: Vec2) {
        self.flow.add(t_s, velocity_mps, self.model.window_s);
    }

    /// The candidate whose cell holds `p`, if any.
    pub fn candidate_at(&self, p: Vec2) -> Option<usize> {
        let r = self.model.resolution_m;
        let i = ((p.x - self.x0) / r).floor();
        let j = ((p.y - self.y0) / r).floor();
        if !(i >= 0.0 && j >= 0.0 && (i as usize) < self.nx && (j as usize) < self.ny) {
            return None;
        }
        let k = self.index[j as usize * self.nx + i as usize];
        (k != u32::MAX).then_some(k as usize)
    }

    /// Computes the footprint of a sample at `pos_m`, time `t_s`, altitude `altitude_m` into
    /// the scratch buffer (see the module docs); the touched candidates are in `self.touched`.
    fn footprint(&mut self, pos_m: Vec2, t_s: f64, altitude_m: Option<f64>) {
        self.footprint_clear();
        let m = self.model;
        let r = m.resolution_m;
        let z2 = altitude_m.filter(|z| z.is_finite()).map_or(0.0, |z| z * z);
        let measured = self.flow.speed_mps();
        let speed = measured.max(0.01);
        let kz = if m.vertical_mixing_length_m > 0.0 {
            m.vertical_mixing_length_m * speed
        } else {
            m.vertical_diffusivity_m2ps
        };
        let dilution_s = if m.dilution_m > 0.0 {
            m.dilution_m / speed
        } else {
            m.dilution_s
        };
        let along_ratio = if m.along_speed_mps > 0.0 {
            (measured / m.along_speed_mps).min(1.0)
        } else {
            m.along_ratio
        };
        let x_now = self.flow.at(t_s);
        let mut travel = 0.0_f64;
        while travel <= m.window_s {
            let sigma = (m.spread0_m * m.spread0_m + 2.0 * m.diffusivity_m2ps * travel).sqrt();
            let sigma_along = if along_ratio == 1.0 {
                sigma
            } else {
                (m.spread0_m * m.spread0_m + 2.0 * along_ratio * m.diffusivity_m2ps * travel).sqrt()
            };
            let vertical = if kz > 0.0 && z2 > 0.0 {
                if travel > 0.0 {
                    (-z2 / (4.0 * kz * travel)).exp()
                } else {
                    0.0
                }
            } else {
                1.0
            };
            let dilution = if dilution_s > 0.0 && travel > dilution_s {
                dilution_s / travel
            } else {
                1.0
            };
            let vertical = vertical * dilution;
            if vertical > 1e-3 {
                let moved = x_now - self.flow.at(t_s - travel);
                let e = pos_m - moved;
                let along = moved.norm();
                if sigma_along != sigma && along > 1e-9 {
                    self.splat_along(e, moved / along, sigma_along, sigma, vertical);
                } else {
                    self.splat(e, sigma, vertical);
                }
            }
            // One spread along the flow's path between footprints, so that they overlap.
            travel += (sigma_along / speed).max(1.0).max(0.5 * r / speed);
        }
    }

    /// Sets the footprint to zero.
    fn footprint_clear(&mut self) {
        for &k in &self.touched {
            self.scratch[k] = 0.0;
        }
        self.touched.clear();
    }

    /// Raises the footprint to `peak * exp(-d^2 / (2 sigma^2))` within 3 sigma of `centre` (the
    /// Gaussian is separable: one exponential per row and per column).
    fn splat(&mut self, centre: Vec2, sigma: f64, peak: f64) {
        let r = self.model.resolution_m;
        let reach = 3.0 * sigma + 0.5 * r;
        let i_lo = ((centre.x - reach - self.x0) / r).floor().max(0.0);
        let i_hi = ((centre.x + reach - self.x0) / r)
            .ceil()
            .min(self.nx as f64);
        let j_lo = ((centre.y - reach - self.y0) / r).floor().max(0.0);
        let j_hi = ((centre.y + reach - self.y0) / r)
            .ceil()
            .min(self.ny as f64);
        if !(i_lo < i_hi && j_lo < j_hi) {
            return;
        }
        let (i_lo, i_hi, j_lo, j_hi) = (i_lo as usize, i_hi as usize, j_lo as usize, j_hi as usize);
        let inv = 1.0 / (2.0 * sigma * sigma);
        let gauss = |offset: f64| (-offset * offset * inv).exp();
        self.gx.clear();
        self.gx
            .extend((i_lo..i_hi).map(|i| gauss(self.x0 + (i as f64 + 0.5) * r - centre.x)));
        for j in j_lo..j_hi {
            let gy = peak * gauss(self.y0 + (j as f64 + 0.5) * r - centre.y);
            if gy < FOOTPRINT_FLOOR {
                continue;
            }
            let row = &self.index[j * self.nx + i_lo..j * self.nx + i_hi];
            for (&k, &gx) in row.iter().zip(&self.gx) {
                raise(&mut self.scratch, &mut self.touched, k, gy * gx);
            }
        }
    }

    /// Raises the footprint to `peak * exp(-a^2 / (2 sigma_along^2) - c^2 / (2 sigma_across^2))`
    /// with `a` and `c` a cell's offset from `centre` along `dir` (a unit vector) and across it,
    /// where that is at least [`FOOTPRINT_FLOOR`]. Along a row the exponent is a quadratic in the
    /// column, so each row costs three exponentials and a product per cell.
    fn splat_along(
        &mut self,
        centre: Vec2,
        dir: Vec2,
        sigma_along: f64,
        sigma_across: f64,
        peak: f64,
    ) {
        if peak.is_nan() || peak < FOOTPRINT_FLOOR {
            return;
        }
        let r = self.model.resolution_m;
        let (wa, wc) = (
            0.5 / (sigma_along * sigma_along),
            0.5 / (sigma_across * sigma_across),
        );
        // exponent = -(qa x^2 + 2 qb x y + qc y^2) for the offset (x, y)
        let qa = dir.x * dir.x * wa + dir.y * dir.y * wc;
        let qc = dir.y * dir.y * wa + dir.x * dir.x * wc;
        let qb = dir.x * dir.y * (wa - wc);
        // Within three spreads (as the round splat) and above the floor.
        let limit = (peak / FOOTPRINT_FLOOR).ln().min(4.5);
        // The ellipse exponent = -limit: its extent in y is sqrt(limit qa / (qa qc - qb^2)).
        let det = qa * qc - qb * qb;
        if !(det > 0.0 && qa > 0.0) {
            return;
        }
        let half_y = (limit * qa / det).sqrt();
        let j_lo = ((centre.y - half_y - self.y0) / r - 0.5).ceil().max(0.0);
        let j_hi = ((centre.y + half_y - self.y0) / r - 0.5).floor() + 1.0;
        let j_hi = j_hi.min(self.ny as f64);
        if j_lo >= j_hi {
            return;
        }
        for j in j_lo as usize..j_hi as usize {
            let y = self.y0 + (j as f64 + 0.5) * r - centre.y;
            // Along the row: qa x^2 + 2 qb y x + qc y^2 <= limit.
            let disc = qb * qb * y * y - qa * (qc * y * y - limit);
            if disc < 0.0 {
                continue;
            }
            let root = disc.sqrt();
            let (x_lo, x_hi) = ((-qb * y - root) / qa, (-qb * y + root) / qa);
            let i_lo = ((centre.x + x_lo - self.x0) / r - 0.5).ceil().max(0.0);
            let i_hi = (((centre.x + x_hi - self.x0) / r - 0.5).floor() + 1.0).min(self.nx as f64);
            if i_lo >= i_hi {
                continue;
            }
            let (i_lo, i_hi) = (i_lo as usize, i_hi as usize);
            let x = self.x0 + (i_lo as f64 + 0.5) * r - centre.x;
            // g(k + 1) = g(k) * step, step(k + 1) = step(k) * exp(-2 qa r^2).
            let mut g = peak * (-(qa * x * x + 2.0 * qb * x * y + qc * y * y)).exp();
            let mut step = (-(qa * (2.0 * x * r + r * r) + 2.0 * qb * r * y)).exp();
            let shrink = (-2.0 * qa * r * r).exp();
            for &k in &self.index[j * self.nx + i_lo..j * self.nx + i_hi] {
                raise(&mut self.scratch, &mut self.touched, k, g);
                g *= step;
                step *= shrink;
            }
        }
    }

    /// Takes one chemical sample into account: taken at `pos_m` (estimated), time `t_s`,
    /// altitude `altitude_m` (if known), detection or not.
    pub fn observe(&mut self, pos_m: Vec2, t_s: f64, altitude_m: Option<f64>, detected: bool) {
        if !(pos_m.x.is_finite() && pos_m.y.is_finite() && t_s.is_finite()) {
            return;
        }
        let last = &mut self.last_sample_s[usize::from(detected)];
        let weight = match *last {
            Some(l) if self.model.correlation_s > 0.0 => {
                ((t_s - l) / self.model.correlation_s).clamp(0.0, 1.0)
            }
            _ => 1.0,
        };
        *last = Some(t_s);
        self.updates += 1;
        if weight <= 0.0 {
            return;
        }
        self.footprint(pos_m, t_s, altitude_m);
        let (pd, pf) = (self.model.p_detect, self.model.p_false);
        for &k in &self.touched {
            let p = pf + (pd - pf) * self.scratch[k];
            // Relative to the cells outside the footprint (factor pf or 1 - pf).
            let l = if detected {
                (p / pf).ln()
            } else {
                ((1.0 - p) / (1.0 - pf)).ln()
            };
            self.log_p[k] += weight * l;
        }
        self.dirty = true;
    }

    /// Normalises the posterior if samples came since the last time (reading the map does this,
    /// so what is read always sums to 1).
    fn normalise(&mut self) {
        if !self.dirty {
            return;
        }
        self.dirty = false;
        let max = self.log_p.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if !max.is_finite() {
            return;
        }
        let s: f64 = self.log_p.iter().map(|l| (l - max).exp()).sum();
        let lse = max + s.ln();
        for (l, p) in self.log_p.iter_mut().zip(self.p.iter_mut()) {
            *l -= lse;
            *p = l.exp();
        }
    }

    /// For a candidate move: the probability of at least one detection among `samples`
    /// independent samples taken at `pos_m` at time `t_s` (flow held at its last reading), for
    /// every candidate source cell, into `out`.
    pub fn hit_probabilities(
        &mut self,
        pos_m: Vec2,
        t_s: f64,
        altitude_m: Option<f64>,
        samples: f64,
        out: &mut Vec<f64>,
    ) {
        let (pd, pf) = (self.model.p_detect, self.model.p_false);
        let n = samples.max(1.0);
        let any = |p: f64| 1.0 - (1.0 - p).powf(n);
        out.clear();
        out.resize(self.len(), any(pf));
        self.footprint(pos_m, t_s, altitude_m);
        for &k in &self.touched {
            out[k] = any(pf + (pd - pf) * self.scratch[k]);
        }
    }

    /// Back to the uniform prior (the flow history is kept).
    pub fn reset(&mut self) {
        let n = self.len();
        self.log_p.fill(-(n as f64).ln());
        self.p.fill(1.0 / n as f64);
        self.dirty = false;
    }

    /// The posterior as telemetry: `log10 p` per grid cell, rounded to 0.01, floored at -12
    /// (cells outside the op-area too).
    pub fn raster(&mut self) -> plumetrace_core::Telemetry {
        self.normalise();
        let log10_p = self
            .index
            .iter()
            .map(|&k| {
                let l = if k == u32::MAX {
                    -12.0
                } else {
                    (self.log_p[k as usize] / std::f64::consts::LN_10).max(-12.0)
                };
                ((l * 100.0).round() / 100.0) as f32
            })
            .collect();
        plumetrace_core::Telemetry::SourceMapRaster {
            origin_m: Vec2::new(self.x0, self.y0),
            cell_m: self.model.resolution_m,
            nx: self.nx,
            ny: self.ny,
            log10_p,
        }
    }

    /// The entropy of the posterior, bits.
    pub fn entropy_bits(&mut self) -> f64 {
        crate::estimate::entropy_bits(self.probabilities())
    }

    /// The most likely candidate: its centre and probability.
    pub fn most_likely(&mut self) -> (Vec2, f64) {
        self.normalise();
        let (k, p) = self
            .p
            .iter()
            .enumerate()
            .fold((0, f64::MIN), |b, (k, &p)| if p > b.1 { (k, p) } else { b });
        (self.centres[k], p)
    }

    /// The posterior mass within `radius_m` of `centre`.
    pub fn mass_within(&mut self, centre: Vec2, radius_m: f64) -> f64 {
        self.within(centre, radius_m).0
    }

    /// The posterior mean of the candidates within `radius_m` of `centre` (`centre` itself when
    /// they hold no mass): the source position the map gives once it has settled on a region,
    /// not bound to a cell centre.
    pub fn mean_within(&mut self, centre: Vec2, radius_m: f64) -> Vec2 {
        let (m, sum) = self.within(centre, radius_m);
        if m > 0.0 && m.is_finite() {
            centre + sum / m
        } else {
            centre
        }
    }

    /// Mass within `radius_m` of `centre` and the mass-weighted sum of the candidates' offsets
    /// from it.
    fn within(&mut self, centre: Vec2, radius_m: f64) -> (f64, Vec2) {
        self.normalise();
        let r = self.model.resolution_m;
        let i_lo = ((centre.x - radius_m - self.x0) / r).floor().max(0.0) as usize;
        let i_hi = ((centre.x + radius_m - self.x0) / r)
            .ceil()
            .clamp(0.0, self.nx as f64) as usize;
        let j_lo = ((centre.y - radius_m - self.y0) / r).floor().max(0.0) as usize;
        let j_hi = ((centre.y + radius_m - self.y0) / r)
            .ceil()
            .clamp(0.0, self.ny as f64) as usize;
        let mut m = 0.0;
        let mut sum = Vec2::zeros();
        for j in j_lo..j_hi {
            for i in i_lo..i_hi {
                let k = self.index[j * self.nx + i];
                if k == u32::MAX {
                    continue;
                }
                let d = self.centres[k as usize] - centre;
                if d.norm() <= radius_m {
                    let p = self.p[k as usize];
                    m += p;
                    sum += d * p;
                }
            }
        }
        (m, sum)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area() -> OpArea {
        OpArea::rectangle(0.0, 400.0, 0.0, 200.0).unwrap_or_else(|e| panic!("{e}"))
    }

    fn model() -> MapModel {
        MapModel {
            resolution_m: 5.0,
            window_s: 2000.0,
            vertical_diffusivity_m2ps: 0.0,
            ..MapModel::default()
        }
    }

    /// A deterministic stream of samples from a source at (100, 100) in a uniform current of
    /// 0.2 m/s towards East: the vehicle zigzags across the plume 100-300 m downflow; a sample
    /// detects when it is within 10 m of the centreline, one in three of those (a fixed pattern).
    fn detections(map: &mut SourceMap, steps: usize, check: &mut dyn FnMut(&mut SourceMap)) {
        for k in 0..steps {
            let t = k as f64;
            map.add_flow(t, Vec2::new(0.2, 0.0));
            let x = 300.0 - (k as f64 * 0.5) % 200.0;
            let y = 100.0 + 40.0 * ((k as f64) * 0.05).sin();
            let near = (y - 100.0).abs() < 10.0;
            map.observe(Vec2::new(x, y), t, Some(2.0), near && k % 3 == 0);
            check(map);
        }
    }

    /// 200 samples a second, one in seven a detection, along a line across an eastward current
    /// of `speed` at `altitude_m`: the map's log-probabilities after them.
    fn fly_across(speed: f64, model: MapModel, altitude_m: Option<f64>) -> Vec<f64> {
        let mut m = SourceMap::new(&area(), model).unwrap_or_else(|| panic!("no map"));
        for k in 0..200 {
            let t = k as f64;
            m.add_flow(t, Vec2::new(speed, 0.0));
            m.observe(Vec2::new(300.0, 90.0 + 0.1 * t), t, altitude_m, k % 7 == 0);
        }
        m.log_probabilities().to_vec()
    }

    #[test]
    fn detections_from_a_known_source_concentrate_the_map_on_it() {
        let mut m = SourceMap::new(&area(), model()).unwrap_or_else(|| panic!("no map"));
        let h0 = m.entropy_bits();
        detections(&mut m, 1500, &mut |_| {});
        let (best, _) = m.most_likely();
        let upflow_mass = m.mass_within(Vec2::new(100.0, 100.0), 60.0);
        assert!(m.entropy_bits() < h0 - 3.0, "{} vs {h0}", m.entropy_bits());
        assert!((best.y - 100.0).abs() < 15.0, "across: {best:?}");
        assert!(
            best.x < 200.0,
            "upflow of where the vehicle sampled: {best:?}"
        );
        assert!(upflow_mass > 0.3, "{upflow_mass}");
    }

    #[test]
    fn the_local_mean_is_the_posterior_mean_of_the_cells_within_the_radius() {
        let mut m = SourceMap::new(&area(), model()).unwrap_or_else(|| panic!("no map"));
        detections(&mut m, 1500, &mut |_| {});
        let (best, _) = m.most_likely();
        let mean = m.mean_within(best, 10.0);
        // By brute force over every candidate.
        let p = m.probabilities().to_vec();
        let (mut w, mut sum) = (0.0, Vec2::zeros());
        for (c, p) in m.centres().iter().zip(&p) {
            if (c - best).norm() <= 10.0 {
                w += p;
                sum += c * *p;
            }
        }
        assert!((mean - sum / w).norm() < 1e-9, "{mean:?} vs {:?}", sum / w);
        assert!((mean - best).norm() <= 10.0);
        assert!(
            (mean - best).norm() > 1e-6,
            "the mean is not bound to a cell centre"
        );
        // No candidate within the radius: the centre itself.
        let outside = Vec2::new(-100.0, -100.0);
        assert_eq!(m.mean_within(outside, 10.0), outside);
    }

    #[test]
    fn the_mass_is_one_after_every_update() {
        let mut m = SourceMap::new(&area(), model()).unwrap_or_else(|| panic!("no map"));
        let mut worst: f64 = 0.0;
        detections(&mut m, 400, &mut |m| {
            let s: f64 = m.probabilities().iter().sum();
            worst = worst.max((s - 1.0).abs());
        });
        assert!(worst < 1e-9, "{worst}");
        assert_eq!(m.updates(), 400);
    }

    #[test]
    fn non_detections_never_raise_a_cell_above_the_cells_they_say_nothing_about() {
        let mut m = SourceMap::new(&area(), model()).unwrap_or_else(|| panic!("no map"));
        // A far corner the footprints never reach (they run upflow, West, of y 100 +- 40).
        let far = m
            .candidate_at(Vec2::new(390.0, 5.0))
            .unwrap_or_else(|| panic!("no cell"));
        for k in 0..300 {
            let t = k as f64;
            m.add_flow(t, Vec2::new(0.2, 0.0));
            let before = m.probabilities().to_vec();
            let x = 300.0 - k as f64 * 0.5;
            m.observe(Vec2::new(x, 100.0), t, Some(2.0), false);
            let after = m.probabilities().to_vec();
            let ratio_far = after[far] / before[far];
            for (a, b) in after.iter().zip(&before) {
                assert!(
                    a / b <= ratio_far * (1.0 + 1e-12),
                    "a cell rose: {a} from {b}"
                );
            }
        }
        let (best, _) = m.most_likely();
        // The cells upflow of the track lost mass; the argmax is not among them.
        assert!((best.y - 100.0).abs() > 10.0 || best.x > 300.0, "{best:?}");
    }

    #[test]
    fn an_ellipse_whose_spreads_agree_is_the_round_splat_in_every_direction() {
        let mut m = SourceMap::new(&area(), model()).unwrap_or_else(|| panic!("no map"));
        let centre = Vec2::new(201.3, 97.8);
        m.splat(centre, 12.0, 0.8);
        let round = m.scratch.clone();
        let mut compared = 0;
        for deg in [0.0_f64, 17.0, 45.0, 90.0, 133.0, 200.0, 301.0] {
            let dir = Vec2::new(deg.to_radians().cos(), deg.to_radians().sin());
            m.footprint_clear();
            m.splat_along(centre, dir, 12.0, 12.0, 0.8);
            for (k, (&a, &b)) in m.scratch.iter().zip(&round).enumerate() {
                let d2 = (m.centres[k] - centre).norm_squared();
                // Both cover the disc of three spreads; the round one also its box's corners.
                if d2 < (2.9 * 12.0_f64).powi(2) {
                    assert!(
                        (a - b).abs() <= 1e-12 * b,
                        "{deg} deg, cell {k}: {a} vs {b}"
                    );
                    compared += 1;
                } else if d2 > (3.1 * 12.0_f64).powi(2) {
                    assert_eq!(a, 0.0, "{deg} deg, cell {k} beyond three spreads");
                }
            }
        }
        assert!(compared > 7 * 150, "{compared}");
    }

    #[test]
    fn a_narrow_spread_along_the_flow_says_less_about_cells_downflow_of_the_sample() {
        // One detection at (200, 100) after 200 s of current at 0.2 m/s, spread 1 m^2/s, the
        // current towards several directions: with the spread along the flow at 0.3 of it the
        // cells downflow of the sample fall and the cells up the flow's path keep their
        // footprint.
        for deg in [0.0_f64, 30.0, 135.0, 250.0] {
            let u = Vec2::new(deg.to_radians().cos(), deg.to_radians().sin());
            let n = Vec2::new(-u.y, u.x);
            let sample = Vec2::new(200.0, 100.0);
            let footprint = |along_ratio: f64| {
                let model = MapModel {
                    diffusivity_m2ps: 1.0,
                    along_ratio,
                    dilution_s: 0.0,
                    ..model()
                };
                let mut m = SourceMap::new(&area(), model).unwrap_or_else(|| panic!("no map"));
                for k in 0..=200 {
                    m.add_flow(k as f64, u * 0.2);
                }
                m.footprint(sample, 200.0, None);
                let at = |p: Vec2| m.scratch[m.candidate_at(p).unwrap_or(0)];
                (
                    at(sample + u * 20.0),
                    at(sample - u * 40.0),
                    at(sample - u * 40.0 + n * 25.0),
                )
            };
            let (down_round, up_round, side_round) = footprint(1.0);
            let (down, up, side) = footprint(0.3);
            assert!(
                down < 0.5 * down_round,
                "{deg} deg downflow: {down} against {down_round}"
            );
            assert!(
                up > 0.9 * up_round,
                "{deg} deg upflow: {up} against {up_round}"
            );
            assert!(
                side > 0.5 * side_round,
                "{deg} deg across: {side} against {side_round}"
            );
        }
    }

    #[test]
    fn an_along_speed_makes_the_ratio_follow_the_measured_current() {
        // The same samples in currents of 0.15 and 0.6 m/s: with an along speed of 0.3 m/s the
        // map equals one with a fixed ratio of 0.5 in the slower current and the round map in
        // the faster one (the fixed ratio is then ignored), and the two ratios differ.
        let fly = |speed: f64, model: MapModel| fly_across(speed, model, None);
        let base = MapModel {
            diffusivity_m2ps: 1.0,
            dilution_s: 0.0,
            ..model()
        };
        let following = MapModel {
            along_speed_mps: 0.3,
            along_ratio: 0.2,
            ..base
        };
        let fixed = |along_ratio: f64| MapModel {
            along_ratio,
            ..base
        };
        assert_eq!(fly(0.15, following), fly(0.15, fixed(0.5)));
        assert_eq!(fly(0.6, following), fly(0.6, fixed(1.0)));
        assert_ne!(fly(0.15, fixed(0.5)), fly(0.15, fixed(1.0)));
    }

    #[test]
    fn the_same_samples_give_the_same_map() {
        let run = || {
            let mut m = SourceMap::new(&area(), model()).unwrap_or_else(|| panic!("no map"));
            detections(&mut m, 300, &mut |_| {});
            m
        };
        let (mut a, mut b) = (run(), run());
        assert_eq!(a.log_probabilities(), b.log_probabilities());
    }

    #[test]
    fn a_bottom_source_is_not_seen_from_altitude_close_by() {
        let model = MapModel {
            vertical_diffusivity_m2ps: 0.002,
            dilution_s: 0.0,
            ..model()
        };
        let mut m = SourceMap::new(&area(), model).unwrap_or_else(|| panic!("no map"));
        m.add_flow(0.0, Vec2::new(0.2, 0.0));
        m.observe(Vec2::new(300.0, 100.0), 0.0, Some(2.0), true);
        // 2 m up with K_z = 0.002: exp(-4 / (0.008 T)) is small for T < 100 s (20 m).
        let (i_near, i_mid) = (
            m.candidate_at(Vec2::new(290.0, 100.0)).unwrap_or(0),
            m.candidate_at(Vec2::new(100.0, 100.0)).unwrap_or(0),
        );
        let p = m.probabilities();
        let (near, mid) = (p[i_near], p[i_mid]);
        assert!(mid > 5.0 * near, "{mid} vs {near}");
    }

    #[test]
    fn a_mixing_length_makes_the_vertical_diffusivity_follow_the_measured_current() {
        // The same samples in currents of 0.1 and 0.3 m/s: with a mixing length of 0.1 m the map
        // equals one with a fixed diffusivity of 0.1 m x the current (the fixed key is then
        // ignored), and the vertical diffusivity changes the map.
        let fly = |speed: f64, model: MapModel| fly_across(speed, model, Some(2.0));
        let mixing = MapModel {
            vertical_mixing_length_m: 0.1,
            vertical_diffusivity_m2ps: 0.5,
            ..model()
        };
        for speed in [0.1, 0.3] {
            let fixed = MapModel {
                vertical_diffusivity_m2ps: 0.1 * speed,
                ..model()
            };
            assert_eq!(fly(speed, mixing), fly(speed, fixed), "at {speed} m/s");
        }
        let (slow, fast) = (
            MapModel {
                vertical_diffusivity_m2ps: 0.01,
                ..model()
            },
            MapModel {
                vertical_diffusivity_m2ps: 0.03,
                ..model()
            },
        );
        assert_ne!(fly(0.1, slow), fly(0.1, fast));
    }

    #[test]
    fn a_detection_after_a_quiet_spell_counts_as_a_whole_look() {
        // A minute of non-detections at 10 Hz far across the flow, then one detection: the
        // detection weighs as much as it would alone (the non-detections do not make it a
        // repeat of them); two cells upflow of it, out of the non-detections' reach, compare the
        // same in both maps.
        let mut quiet = SourceMap::new(&area(), model()).unwrap_or_else(|| panic!("no map"));
        let mut alone = SourceMap::new(&area(), model()).unwrap_or_else(|| panic!("no map"));
        for k in 0..600 {
            let t = k as f64 * 0.1;
            quiet.add_flow(t, Vec2::new(0.2, 0.0));
            quiet.observe(Vec2::new(300.0, 10.0), t, Some(2.0), false);
        }
        let t = 60.0;
        quiet.add_flow(t, Vec2::new(0.2, 0.0));
        alone.add_flow(0.0, Vec2::new(0.2, 0.0));
        quiet.observe(Vec2::new(300.0, 170.0), t, Some(2.0), true);
        alone.observe(Vec2::new(300.0, 170.0), t, Some(2.0), true);
        let (near, far) = (Vec2::new(290.0, 170.0), Vec2::new(150.0, 170.0));
        let ratio = |m: &mut SourceMap| {
            let (a, b) = (
                m.candidate_at(near).unwrap_or(0),
                m.candidate_at(far).unwrap_or(0),
            );
            let lp = m.log_probabilities();
            lp[b] - lp[a]
        };
        let (q, a) = (ratio(&mut quiet), ratio(&mut alone));
        assert!(a.abs() > 0.5, "the detection tells the cells apart: {a}");
        assert!((q - a).abs() < 1e-9, "{q} vs {a}");
    }

    #[test]
    fn flow_history_integrates_held_readings() {
        let mut f = FlowHistory::default();
        f.add(0.0, Vec2::new(1.0, 0.0), 100.0);
        f.add(10.0, Vec2::new(0.0, 1.0), 100.0);
        let d = f.at(15.0) - f.at(5.0);
        assert!((d - Vec2::new(5.0, 5.0)).norm() < 1e-12, "{d:?}");
        let before = f.at(-5.0) - f.at(0.0);
        assert!((before - Vec2::new(-5.0, 0.0)).norm() < 1e-12);
    }
}
