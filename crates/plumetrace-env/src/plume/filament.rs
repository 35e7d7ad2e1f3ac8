//! Filament storage, release, transport and growth.

use super::column::Column;
use super::index::{CellIndex, TermExp};
use crate::error::{EnvError, require_finite, require_non_negative, require_positive};
use crate::field::ConcentrationField;
use crate::flow::FlowField;
use crate::seabed::Seabed;
use crate::{Rect, SimRng};
use plumetrace_core::Vec3;
use rand::{Rng, RngCore};
use rand_distr::{Distribution, Poisson};
use serde::{Deserialize, Serialize};
use std::sync::{Arc, OnceLock};

/// A chemical source.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Source {
    /// Position `(east, north, height above seabed)`, m.
    pub pos_m: Vec3,
    /// Chemical released per second (mass units / s; concentrations come out in mass units / m^3).
    pub mass_rate_per_s: f64,
    /// Mean filament release rate, filaments / s (Poisson).
    pub filament_rate_hz: f64,
}

/// How filaments behave at the seabed (z = 0) and surface.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum VerticalBoundary {
    /// The seabed reflects filaments (and, with a depth, so does the surface); concentrations add
    /// the mirror image so that no chemical is lost through the boundary.
    Reflecting {
        /// Water depth, m: where the surface reflects; `None` for no surface.
        depth_m: Option<f64>,
    },
    /// No vertical boundary (the pompy behaviour).
    Unbounded,
}

/// The centre-relative random walk of filaments.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Dispersion {
    /// Displacement variance `2 K dt` per axis per step.
    Physical {
        /// Horizontal diffusivity, m^2/s.
        horizontal_m2ps: f64,
        /// Vertical diffusivity, m^2/s.
        vertical_m2ps: f64,
    },
    /// pompy's scaling: displacement `scale * N(0, 1) * dt` per axis per step (dt-dependent).
    PompyCompatible {
        /// pompy's `centre_rel_diff_scale`, m/s, per axis `[x, y, z]`.
        scale_mps: [f64; 3],
    },
}

/// Parameters of the filament model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FilamentParams {
    /// Centre-relative dispersion.
    pub dispersion: Dispersion,
    /// Radius at release, m.
    pub init_radius_m: f64,
    /// Growth rate `gamma` of the squared radius, m^2/s.
    pub growth_rate_m2ps: f64,
    /// Concentration is cut off beyond this many radii.
    pub cutoff_radii: f64,
    /// At most this many live filaments; releases beyond it are suppressed and counted.
    pub max_filaments: usize,
    /// Vertical boundary behaviour.
    pub vertical: VerticalBoundary,
}

impl Default for FilamentParams {
    /// pompy's defaults for puff size and growth, a physical random walk, a reflecting seabed.
    fn default() -> Self {
        FilamentParams {
            dispersion: Dispersion::Physical {
                horizontal_m2ps: 0.02,
                vertical_m2ps: 0.002,
            },
            init_radius_m: 0.0316,
            growth_rate_m2ps: 0.001,
            cutoff_radii: 3.0,
            max_filaments: 2_000_000,
            vertical: VerticalBoundary::Reflecting { depth_m: None },
        }
    }
}

impl FilamentParams {
    /// Checks every parameter; errors name the scenario's `[plume]` key of each
    /// (`init_radius_m`, `horizontal_diffusivity_m2ps`), the water depth as `depth_m`.
    pub fn validate(&self) -> Result<(), EnvError> {
        match self.dispersion {
            Dispersion::Physical {
                horizontal_m2ps,
                vertical_m2ps,
            } => {
                require_non_negative("horizontal_diffusivity_m2ps", horizontal_m2ps)?;
                require_non_negative("vertical_diffusivity_m2ps", vertical_m2ps)?;
            }
            Dispersion::PompyCompatible { scale_mps } => {
                for s in scale_mps {
                    require_non_negative("pompy_diff_scale_mps", s)?;
                }
            }
        }
        require_positive("init_radius_m", self.init_radius_m)?;
        require_non_negative("growth_rate_m2ps", self.growth_rate_m2ps)?;
        require_positive("cutoff_radii", self.cutoff_radii)?;
        if self.max_filaments == 0 {
            return Err(EnvError::invalid("max_filaments", "must be at least 1"));
        }
        if let VerticalBoundary::Reflecting { depth_m: Some(d) } = self.vertical {
            require_positive("depth_m", d)?;
        }
        Ok(())
    }
}

/// Running totals of the plume.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct PlumeStats {
    /// Filaments alive now.
    pub live: usize,
    /// Filaments released so far.
    pub released: u64,
    /// Mass released so far.
    pub released_mass: f64,
    /// Filaments removed on leaving the domain.
    pub exited: u64,
    /// Mass removed on leaving the domain.
    pub exited_mass: f64,
    /// Releases suppressed by `max_filaments`.
    pub suppressed: u64,
    /// Filaments dropped beyond the downflow sink (out of every sensor's reach).
    pub dropped: u64,
    /// Mass dropped beyond the downflow sink.
    pub dropped_mass: f64,
}

/// A half-plane far downflow of everything that samples the plume: a filament whose cut-off
/// sphere lies entirely beyond it is dropped ([`FilamentPlume::set_sink`]).
///
/// Dropping is exact (the readings elsewhere are the same bits) as long as no dropped filament
/// would ever have come back within reach: the caller places the sink where the mean flow
/// carries filaments away from every sensor and never back ([`DownflowSink`]'s use in a
/// mission is documented with the scenario key that sets its margin). Each filament's random
/// walk depends only on its own key and the step count, so removing one changes no other.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DownflowSink {
    /// Unit vector `(east, north)` of the direction filaments are carried away in.
    pub dir: [f64; 2],
    /// A filament is dropped when `dir . (x, y) - cut-off radius > beyond_m`, m.
    pub beyond_m: f64,
}

/// The filament plume: filaments stored as parallel arrays (structure of arrays).
#[derive(Debug)]
pub struct FilamentPlume {
    params: FilamentParams,
    domain: Rect,
    sources: Vec<Source>,
    release: Vec<Option<Poisson<f64>>>,
    release_dt_s: f64,
    /// Where the positions are measured from: the domain's centre, so that single precision
    /// resolves a position to within 6e-8 of the domain's half-width wherever the domain lies.
    pub(crate) origin: [f64; 2],
    /// Positions, m, from `origin` (`z` as it is), in single precision (the transport's
    /// arithmetic too; every query reads them widened to `f64`).
    pub(crate) x: Column<f32>,
    pub(crate) y: Column<f32>,
    pub(crate) z: Column<f32>,
    /// Release time of each filament, s: `r^2 = r0^2 + gamma (t - birth)` is computed when
    /// needed, so stepping never touches it.
    pub(crate) birth_s: Column<f64>,
    pub(crate) mass: Column<f64>,
    pub(crate) source: Column<u16>,
    /// Each filament's noise key, drawn at its release: its random walk at transport step `n`
    /// comes from `key + n` alone (see [`FilamentPlume::step`]), so it does not depend on which
    /// other filaments exist.
    key: Column<u64>,
    /// The seed of the keys ([`FilamentPlume::set_key_seed`]).
    key_seed: u64,
    /// Keys given so far.
    keys_given: u64,
    /// Transport steps taken (the counter of the filaments' noise).
    transport_steps: u64,
    /// Where filaments are dropped as out of every sensor's reach, if anywhere.
    sink: Option<DownflowSink>,
    /// The seabed filaments reflect at, if not flat at `z = 0` ([`FilamentPlume::set_seabed`]).
    seabed: Option<Arc<Seabed>>,
    /// Plume time, s (the end of the last step).
    time_s: f64,
    stats: PlumeStats,
    index: OnceLock<CellIndex>,
    /// Bounding boxes of consecutive blocks of filaments and of runs of [`SCAN_GROUP`] blocks,
    /// for the sensor's scan (built by the first scan after a change, so stepping alone never
    /// pays for them).
    boxes: OnceLock<ScanBoxes>,
    /// The transport's working columns, kept between steps so that a step does not clear them
    /// (7 kB: a sizeable part of a step of a few hundred filaments).
    scratch: Box<TransportScratch>,
    /// Which runs of the last transport's filaments hold one that may go, for the removal that
    /// follows it.
    strays: Strays,
}

/// Per run of [`STRAY_RUN`] filaments moved by the last transport (from the first), whether any
/// of them may be outside the domain or past the sink's line (a test in single precision that
/// flags at least what [`FilamentPlume::remove_outside`]'s test takes); the removal reads them
/// instead of testing every filament again, and runs past
/// `moved` (filaments released after the transport) are tested in full.
#[derive(Debug, Clone, Default)]
struct Strays {
    runs: Vec<bool>,
    moved: usize,
}

/// An axis along which a step moves filaments too little for their positions
/// ([`FilamentPlume::check_step`]).
#[derive(Debug, Clone, Copy)]
struct ShortAxis {
    axis: &'static str,
    /// The step's move, m.
    step: f64,
    /// The least move the positions hold, m.
    least: f64,
    /// The largest rounding along the axis, m, and where it is taken (m from where positions
    /// are measured from).
    rounding: f64,
    at: f64,
    /// Whether the move is the random walk's (else the current's).
    walk: bool,
    /// The shortest step that would move filaments by `least` along this axis, s.
    shortest_s: f64,
}

/// `v > 0` rounded up to four significant digits (strictly above `v` where `v` has four).
fn up_to_four_digits(v: f64) -> f64 {
    if !(v.is_finite() && v > 0.0) {
        return v;
    }
    let unit = 10f64.powi(v.log10().floor() as i32 - 3);
    let n = (v / unit).ceil();
    let n = if n * unit > v { n } else { n + 1.0 };
    // As written with four digits, so that the value suggested is the value read back.
    format!("{:.3e}", n * unit).parse().unwrap_or(n * unit)
}

/// Filaments per run of the removal's test.
const STRAY_RUN: usize = 64;
// The transport notes whole runs in each of its chunks (but for the last chunk's last run).
const _: () = assert!(TRANSPORT_CHUNK.is_multiple_of(STRAY_RUN));

/// Filaments per velocity batch of the transport: small enough for the batch to stay in L1
/// cache.
const TRANSPORT_CHUNK: usize = 256;

/// The transport's working columns for one batch of filaments (see [`Transport`]).
#[derive(Debug, Clone)]
struct TransportScratch {
    u: [f32; TRANSPORT_CHUNK],
    v: [f32; TRANSPORT_CHUNK],
    words: [u64; TRANSPORT_CHUNK],
    n0: [f32; TRANSPORT_CHUNK],
    n1: [f32; TRANSPORT_CHUNK],
    n2: [f32; TRANSPORT_CHUNK],
}

impl TransportScratch {
    fn new() -> Box<Self> {
        Box::new(TransportScratch {
            u: [0.0; TRANSPORT_CHUNK],
            v: [0.0; TRANSPORT_CHUNK],
            words: [0; TRANSPORT_CHUNK],
            n0: [0.0; TRANSPORT_CHUNK],
            n1: [0.0; TRANSPORT_CHUNK],
            n2: [0.0; TRANSPORT_CHUNK],
        })
    }
}

/// Filaments per block of the sensor scan's pruning boxes.
pub const SCAN_BLOCK: usize = 64;
/// Blocks per group: the scan tests a group's box before its blocks' boxes.
pub const SCAN_GROUP: usize = 16;

/// The sensor scan's two levels of boxes.
#[derive(Debug)]
struct ScanBoxes {
    blocks: Vec<BlockBox>,
    groups: Vec<BlockBox>,
}

/// The horizontal extent and the oldest release time of a block of [`SCAN_BLOCK`] consecutive
/// filaments: no filament of the block reaches a point farther from the box than the cut-off of
/// the block's widest (oldest) filament.
#[derive(Debug, Clone, Copy)]
struct BlockBox {
    x_min: f64,
    x_max: f64,
    y_min: f64,
    y_max: f64,
    birth_min_s: f64,
}

impl BlockBox {
    const EMPTY: BlockBox = BlockBox {
        x_min: f64::INFINITY,
        x_max: f64::NEG_INFINITY,
        y_min: f64::INFINITY,
        y_max: f64::NEG_INFINITY,
        birth_min_s: f64::INFINITY,
    };

    /// The box of this one and `o`.
    fn union(self, o: BlockBox) -> BlockBox {
        BlockBox {
            x_min: self.x_min.min(o.x_min),
            x_max: self.x_max.max(o.x_max),
            y_min: self.y_min.min(o.y_min),
            y_max: self.y_max.max(o.y_max),
            birth_min_s: self.birth_min_s.min(o.birth_min_s),
        }
    }

    /// Whether no filament of the box reaches `p` (`(r0^2, gamma, t, cutoff^2)` of the plume):
    /// `p` is farther from the box than the cut-off of its oldest filament. Differences,
    /// squares and sums are monotone in floating point, so a box holding another's filaments
    /// is beyond `p` only if the other is too.
    #[inline]
    fn beyond(&self, p: Vec3, (r0sq, gamma, t, cut2): (f64, f64, f64, f64)) -> bool {
        let ddx = (self.x_min - p.x).max(p.x - self.x_max).max(0.0);
        let ddy = (self.y_min - p.y).max(p.y - self.y_max).max(0.0);
        let widest = r0sq + gamma * (t - self.birth_min_s).max(0.0);
        ddx * ddx + ddy * ddy > cut2 * widest
    }
}

impl FilamentPlume {
    /// The most sources of a plume: the step and the query time grow with them (and a filament
    /// keeps its source's index in 16 bits).
    pub const MAX_SOURCES: usize = 1000;
    const _SOURCE_INDEX_FITS: () = assert!(Self::MAX_SOURCES <= u16::MAX as usize);

    /// A plume with no filaments yet. Errors name the parameters as [`FilamentParams::validate`]
    /// does and a source as `sources[k]`.
    pub fn new(
        domain: Rect,
        sources: Vec<Source>,
        params: FilamentParams,
    ) -> Result<Self, EnvError> {
        params.validate()?;
        if sources.len() > Self::MAX_SOURCES {
            return Err(EnvError::invalid(
                "sources",
                format!("at most {} sources", Self::MAX_SOURCES),
            ));
        }
        for (k, s) in sources.iter().enumerate() {
            let key = |f: &str| format!("sources[{k}].{f}");
            require_finite(&key("x_m"), s.pos_m.x)?;
            require_finite(&key("y_m"), s.pos_m.y)?;
            require_non_negative(&key("z_m"), s.pos_m.z)?;
            require_non_negative(&key("mass_rate_per_s"), s.mass_rate_per_s)?;
            require_non_negative(&key("filament_rate_hz"), s.filament_rate_hz)?;
            if !domain.contains_xy(s.pos_m.x, s.pos_m.y) {
                return Err(EnvError::invalid(
                    key("x_m"),
                    format!(
                        "source at ({}, {}) is outside the domain",
                        s.pos_m.x, s.pos_m.y
                    ),
                ));
            }
            if let VerticalBoundary::Reflecting { depth_m: Some(d) } = params.vertical
                && s.pos_m.z > d
            {
                return Err(EnvError::invalid(
                    key("z_m"),
                    format!("{} m is above the surface ({d} m)", s.pos_m.z),
                ));
            }
        }
        Ok(FilamentPlume {
            params,
            origin: [
                0.5 * (domain.x_min_m + domain.x_max_m),
                0.5 * (domain.y_min_m + domain.y_max_m),
            ],
            domain,
            release: vec![None; sources.len()],
            sources,
            release_dt_s: f64::NAN,
            x: Column::new(),
            y: Column::new(),
            z: Column::new(),
            birth_s: Column::new(),
            mass: Column::new(),
            source: Column::new(),
            key: Column::new(),
            key_seed: 0,
            keys_given: 0,
            transport_steps: 0,
            sink: None,
            seabed: None,
            time_s: 0.0,
            stats: PlumeStats::default(),
            index: OnceLock::new(),
            boxes: OnceLock::new(),
            scratch: TransportScratch::new(),
            strays: Strays::default(),
        })
    }

    /// A copy of the plume's state (filaments, clock, statistics, release rates); the query
    /// caches are rebuilt by the copy's first query.
    pub fn copy_state(&self) -> Self {
        FilamentPlume {
            params: self.params,
            origin: self.origin,
            domain: self.domain,
            sources: self.sources.clone(),
            release: self.release.clone(),
            release_dt_s: self.release_dt_s,
            x: self.x.copy_live(),
            y: self.y.copy_live(),
            z: self.z.copy_live(),
            birth_s: self.birth_s.copy_live(),
            mass: self.mass.copy_live(),
            source: self.source.copy_live(),
            key: self.key.copy_live(),
            key_seed: self.key_seed,
            keys_given: self.keys_given,
            transport_steps: self.transport_steps,
            sink: self.sink,
            seabed: self.seabed.clone(),
            time_s: self.time_s,
            stats: self.stats,
            index: OnceLock::new(),
            boxes: OnceLock::new(),
            scratch: TransportScratch::new(),
            strays: Strays::default(),
        }
    }

    /// Puts a seabed under the plume (`None`: flat at `z = 0`): filaments then reflect at the
    /// seabed's height where they are, and concentrations add their images in it. Only with a
    /// reflecting boundary; the sources' heights are the caller's (on the seabed or above it).
    pub fn set_seabed(&mut self, seabed: Option<Arc<Seabed>>) {
        self.index = OnceLock::new();
        self.seabed = seabed;
    }

    /// The seabed under the plume, if not flat.
    pub fn seabed(&self) -> Option<&Seabed> {
        self.seabed.as_deref()
    }

    /// The sources.
    pub fn sources(&self) -> &[Source] {
        &self.sources
    }

    /// The model parameters.
    pub fn params(&self) -> &FilamentParams {
        &self.params
    }

    /// The least random walk a step may take along an axis, in units of the largest rounding of
    /// a stored position along it ([`FilamentPlume::check_step`]). At the bound the rounding
    /// adds at most 1.3 % to the walk's variance per step (`1 / (3 x 5^2)`: a rounding lies
    /// evenly within its bound once the walk spreads positions over more than its spacing), and
    /// the walk's spread leaves the current's move unbiased.
    pub const MIN_WALK_IN_ROUNDINGS: f64 = 5.0;

    /// The least move of the current a step may take along an axis where there is no random
    /// walk, in units of the largest rounding ([`FilamentPlume::check_step`]): without a walk a
    /// steady move is rounded the same way step after step, so the rounding is a bias, at most
    /// a hundredth of the move here.
    pub const MIN_DRIFT_IN_ROUNDINGS: f64 = 100.0;

    /// The largest rounding of a stored position, m, east, north and up, and where it is taken:
    /// half the spacing of `f32` at the domain's half-width and half-height from its centre
    /// (filaments are carried to the domain's edges), and for heights at the highest source
    /// (a random walk of a few roundings a step would need far more steps than a run may take
    /// to carry a filament high enough above its source for the rounding to grow tenfold), or
    /// over a seabed at the surface (the current carries filaments up the seabed's slopes).
    pub fn position_rounding_m(&self) -> [(f64, f64); 3] {
        fn half_spacing(m: f64) -> f64 {
            // The spacing just above `m`: at a power of two, the wider of the two around it.
            let f = (m.abs() as f32).max(f32::MIN_POSITIVE);
            0.5 * (f64::from(f.next_up()) - f64::from(f))
        }
        let (w, h) = (0.5 * self.domain.width_m(), 0.5 * self.domain.height_m());
        let source = self
            .sources
            .iter()
            .map(|s| s.pos_m.z.abs())
            .fold(0.0, f64::max);
        // Over a seabed, the current carries filaments up its slopes: heights up to the surface.
        let top = match &self.seabed {
            Some(sb) => source.max(sb.surface_m()),
            None => source,
        };
        [
            (half_spacing(w), w),
            (half_spacing(h), h),
            (half_spacing(top), top),
        ]
    }

    /// Refuses a step of `dt_s` that moves filaments too little for their single-precision
    /// positions to hold the move (see [`FilamentPlume::position_rounding_m`]): a random walk
    /// under [`FilamentPlume::MIN_WALK_IN_ROUNDINGS`] roundings a step along any axis, or,
    /// where nothing walks across the plane, the current's move under
    /// [`FilamentPlume::MIN_DRIFT_IN_ROUNDINGS`] of the coarser horizontal rounding (the
    /// slowest current at a source, `flow` as it is now; still water moves nothing). The
    /// error's key is `dt_s`; it gives the shortest step, to four digits, that passes on every
    /// axis.
    pub fn check_step(&self, dt_s: f64, flow: &dyn FlowField) -> Result<(), EnvError> {
        // Without a walk, the move the rounding must not bias.
        let speed = self.slowest_current(flow);
        let all = self.short_axes(dt_s, speed, self.walk_sd(dt_s));
        let Some(&short) = all.first() else {
            return Ok(());
        };
        // The shortest step every axis takes (a walk grows with the step, so does the
        // current's move), rounded up to four digits and raised until it passes as written.
        let needed = all.iter().map(|a| a.shortest_s).fold(dt_s, f64::max);
        let mut shortest = up_to_four_digits(needed);
        for _ in 0..100 {
            if self
                .short_axes(shortest, speed, self.walk_sd(shortest))
                .is_empty()
            {
                break;
            }
            shortest = up_to_four_digits(shortest * (1.0 + 1e-4));
        }
        let ShortAxis {
            axis,
            step,
            least,
            rounding,
            at,
            walk,
            ..
        } = short;
        let pompy = matches!(self.params.dispersion, Dispersion::PompyCompatible { .. });
        let walk_key = match (pompy, axis) {
            (true, _) => "plume.pompy_diff_scale_mps",
            (false, "up") => "plume.vertical_diffusivity_m2ps",
            (false, _) => "plume.horizontal_diffusivity_m2ps",
        };
        let (what, cure) = match (walk, axis) {
            (true, "up") => (
                "the random walk's standard deviation",
                format!("a larger {walk_key}"),
            ),
            (true, _) => {
                // A walk too small to hold may be no walk at all where the current's move alone
                // is held.
                let (_, _, up) = self.walk_sd(dt_s);
                let cure = if speed > 0.0 && self.short_axes(dt_s, speed, (0.0, 0.0, up)).is_empty()
                {
                    format!(
                        "a larger {walk_key}, a narrower domain, or no random walk ({walk_key} \
                         = 0: the current's move alone is held)"
                    )
                } else {
                    format!("a larger {walk_key} or a narrower domain")
                };
                ("the random walk's standard deviation", cure)
            }
            (false, _) => (
                "the current at the sources, with no random walk",
                format!("a random walk ({walk_key}) or a narrower domain"),
            ),
        };
        let (where_, from) = match axis {
            "up" => ("at the highest a filament is carried to,", "up"),
            _ => ("at the domain's edge,", "from its centre"),
        };
        // Rounded down, so that it never reads as the bound it is under.
        let times = (step / rounding * 100.0).floor() / 100.0;
        let others: Vec<&str> = all[1..].iter().map(|a| a.axis).collect();
        let also = if others.is_empty() {
            String::new()
        } else {
            format!(" (the step is short {} too)", others.join(" and "))
        };
        Err(EnvError::invalid(
            "dt_s",
            format!(
                "a step of {dt_s} s moves filaments {axis} by about {step:.3e} m ({what}), \
                 {times} times the largest rounding of a position kept in single precision \
                 ({rounding:.3e} m, {where_} {at:.1} m {from}), where the positions need at \
                 least {} times ({least:.3e} m) to hold the move; it takes a step of at least \
                 {shortest:.3e} s{also}, or {cure}",
                least / rounding
            ),
        ))
    }

    /// The slowest current at a source, m/s (`flow` as it is now; 0 without sources).
    fn slowest_current(&self, flow: &dyn FlowField) -> f64 {
        let speed = self
            .sources
            .iter()
            .map(|s| flow.velocity(s.pos_m.xy()).norm())
            .fold(f64::INFINITY, f64::min);
        if speed.is_finite() { speed } else { 0.0 }
    }

    /// The axes along which a step of `dt_s` moves filaments too little
    /// ([`FilamentPlume::check_step`]), in the order east, north, across the plane, up: `speed`
    /// is the slowest current at a source, `walk` the random walk's standard deviations.
    fn short_axes(&self, dt_s: f64, speed: f64, walk: (f64, f64, f64)) -> Vec<ShortAxis> {
        let rounding = self.position_rounding_m();
        let pompy = matches!(self.params.dispersion, Dispersion::PompyCompatible { .. });
        // Without a walk, the current's move across the plane against the coarser of the two
        // horizontal roundings.
        let plane = if rounding[0].0 >= rounding[1].0 {
            rounding[0]
        } else {
            rounding[1]
        };
        let drift = if walk.0.max(walk.1) > 0.0 { 0.0 } else { speed };
        let axes = [
            ("east", walk.0, 0.0, rounding[0]),
            ("north", walk.1, 0.0, rounding[1]),
            ("across the plane", 0.0, drift, plane),
            ("up", walk.2, 0.0, rounding[2]),
        ];
        let mut short = Vec::new();
        for (axis, walk, current, (r, at)) in axes {
            let (step, least, shortest_s) = if walk > 0.0 {
                let least = Self::MIN_WALK_IN_ROUNDINGS * r;
                // A walk grows as the step's square root (in proportion, with pompy's scaling).
                let grow = least / walk;
                let shortest = if pompy { grow } else { grow * grow };
                (walk, least, dt_s * shortest)
            } else {
                let least = Self::MIN_DRIFT_IN_ROUNDINGS * r;
                (current * dt_s, least, least / current)
            };
            if step > 0.0 && step < least {
                short.push(ShortAxis {
                    axis,
                    step,
                    least,
                    rounding: r,
                    at,
                    walk: walk > 0.0,
                    shortest_s,
                });
            }
        }
        short
    }

    /// Running totals.
    pub fn stats(&self) -> PlumeStats {
        PlumeStats {
            live: self.x.len(),
            ..self.stats
        }
    }

    /// Number of live filaments.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether there are no live filaments.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Total mass of the live filaments.
    pub fn live_mass(&self) -> f64 {
        self.mass.iter().sum()
    }

    /// Filament centres `(x, y, z)` and squared radii, for statistics and plots.
    pub fn filaments(&self) -> impl Iterator<Item = (Vec3, f64)> + '_ {
        (0..self.x.len()).map(|k| {
            (
                Vec3::new(
                    f64::from(self.x[k]) + self.origin[0],
                    f64::from(self.y[k]) + self.origin[1],
                    f64::from(self.z[k]),
                ),
                self.radius_sq(k),
            )
        })
    }

    /// Squared radius of filament `k` now.
    #[inline]
    pub(crate) fn radius_sq(&self, k: usize) -> f64 {
        self.radius_sq_born(self.birth_s[k])
    }

    /// Squared radius now of a filament released at `birth_s`.
    #[inline]
    pub(crate) fn radius_sq_born(&self, birth_s: f64) -> f64 {
        let r0 = self.params.init_radius_m;
        r0 * r0 + self.params.growth_rate_m2ps * (self.time_s - birth_s).max(0.0)
    }

    /// Plume time, s.
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Seeds the filaments' noise keys (an [`crate::Environment`] does it from its run seed)
    /// and re-keys the filaments already there, in order.
    pub fn set_key_seed(&mut self, seed: u64) {
        self.key_seed = seed;
        self.keys_given = 0;
        for k in 0..self.key.len() {
            self.key[k] = self.next_key();
        }
    }

    /// The next filament's noise key.
    fn next_key(&mut self) -> u64 {
        let k = splitmix64_mix(self.key_seed ^ self.keys_given.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        self.keys_given += 1;
        k
    }

    /// Drops filaments beyond `sink` from the next step on (`None`: keep every filament until it
    /// leaves the domain).
    pub fn set_sink(&mut self, sink: Option<DownflowSink>) {
        self.sink = sink;
    }

    /// The downflow sink, if any.
    pub fn sink(&self) -> Option<DownflowSink> {
        self.sink
    }

    /// Releases `n` filaments at source `k` now (also used to seed a plume at t = 0).
    pub fn release_at_source(&mut self, k: usize, n: u64) {
        self.release_at(k, n, self.time_s);
    }

    fn release_at(&mut self, k: usize, n: u64, birth_s: f64) {
        let Some(s) = self.sources.get(k).copied() else {
            return;
        };
        let room = self.params.max_filaments.saturating_sub(self.x.len()) as u64;
        let take = n.min(room);
        self.stats.suppressed += n - take;
        if take == 0 {
            return;
        }
        self.index = OnceLock::new();
        self.boxes = OnceLock::new();
        // The source from the origin, kept inside the domain (a source on its edge could
        // otherwise round to just outside it).
        let d = self.local_domain();
        let x = ((s.pos_m.x - self.origin[0]) as f32)
            .clamp(f32_at_least(d.x_min_m), f32_at_most(d.x_max_m));
        let y = ((s.pos_m.y - self.origin[1]) as f32)
            .clamp(f32_at_least(d.y_min_m), f32_at_most(d.y_max_m));
        let q = if s.filament_rate_hz > 0.0 {
            s.mass_rate_per_s / s.filament_rate_hz
        } else {
            0.0
        };
        for _ in 0..take {
            // Keys follow the release count, so a plume's filaments get the same keys whatever
            // happens to them; spread by SplitMix64 so that neighbouring keys are unrelated.
            let key = self.next_key();
            self.key.push(key);
            self.x.push(x);
            self.y.push(y);
            self.z.push(s.pos_m.z as f32);
            self.birth_s.push(birth_s);
            self.mass.push(q);
            self.source.push(k as u16);
        }
        self.stats.released += take;
        self.stats.released_mass += q * take as f64;
    }

    /// Advances the plume by one step of `dt_s` to time `t_new_s`, in `flow` (already advanced to
    /// the new time).
    ///
    /// With physical dispersion, the filaments a source releases during the step are born at
    /// uniformly drawn times within it (with their Poisson count, a Poisson process) and placed
    /// where they are at its end: carried by the flow at the source for their age and spread by
    /// the random walk of that age. A long step therefore releases a stream, not a clump of
    /// filaments of one age at one point, and the plume does not depend on the step. With
    /// pompy's dispersion they are born at the step's start and move with the whole step, as in
    /// the reference implementation.
    pub fn step(&mut self, flow: &dyn FlowField, t_new_s: f64, dt_s: f64, rng: &mut SimRng) {
        self.index = OnceLock::new();
        self.boxes = OnceLock::new();
        let spread = match self.params.dispersion {
            Dispersion::Physical { .. } => true,
            Dispersion::PompyCompatible { .. } => false,
        };
        if !spread {
            self.release(t_new_s - dt_s, dt_s, rng);
        }
        self.time_s = t_new_s;
        let (mut left, beyond) = self.transport(flow, dt_s);
        if spread {
            left |= self.release_spread(flow, t_new_s, dt_s, rng);
        }
        // Filaments out of the domain go at once; those beyond the sink can wait until they
        // are a thirty-second of the plume (they reach nothing meanwhile, and a filament's walk
        // does not depend on the others), so the arrays are compacted now and then, not at
        // every step.
        if left || beyond * 32 > self.x.len() {
            self.remove_outside();
        }
        // The transport's findings hold for this step's removal only.
        self.strays.moved = 0;
    }

    /// The random walk's standard deviations per axis over `dt_s`.
    fn walk_sd(&self, dt_s: f64) -> (f64, f64, f64) {
        match self.params.dispersion {
            Dispersion::Physical {
                horizontal_m2ps,
                vertical_m2ps,
            } => {
                let h = (2.0 * horizontal_m2ps * dt_s).sqrt();
                (h, h, (2.0 * vertical_m2ps * dt_s).sqrt())
            }
            Dispersion::PompyCompatible { scale_mps } => (
                scale_mps[0] * dt_s,
                scale_mps[1] * dt_s,
                scale_mps[2] * dt_s,
            ),
        }
    }

    /// The domain, from the origin (where the positions are measured from).
    fn local_domain(&self) -> Rect {
        let [ox, oy] = self.origin;
        Rect {
            x_min_m: self.domain.x_min_m - ox,
            x_max_m: self.domain.x_max_m - ox,
            y_min_m: self.domain.y_min_m - oy,
            y_max_m: self.domain.y_max_m - oy,
        }
    }

    /// The sink's direction and line, from the origin (without a sink nothing lies beyond it).
    fn local_sink(&self) -> ([f64; 2], f64) {
        let [ox, oy] = self.origin;
        self.sink.map_or(([0.0, 0.0], f64::INFINITY), |s| {
            (s.dir, s.beyond_m - (s.dir[0] * ox + s.dir[1] * oy))
        })
    }

    /// The heights where filaments reflect.
    fn floor_ceiling(&self) -> (f64, f64) {
        match self.params.vertical {
            VerticalBoundary::Reflecting { depth_m } => (0.0, depth_m.unwrap_or(f64::INFINITY)),
            VerticalBoundary::Unbounded => (f64::NEG_INFINITY, f64::INFINITY),
        }
    }

    /// Moves every filament by the flow and the random walk over `dt_s`; whether any left the
    /// domain, and how many certainly lie beyond the sink (beyond it by more than the cut-off
    /// radius a filament as old as the plume's clock would have).
    fn transport(&mut self, flow: &dyn FlowField, dt_s: f64) -> (bool, usize) {
        self.transport_on(crate::simd::best(), flow, dt_s)
    }

    /// [`FilamentPlume::transport`] on the vector unit `arch` (see [`crate::simd`]).
    fn transport_on(&mut self, arch: pulp::Arch, flow: &dyn FlowField, dt_s: f64) -> (bool, usize) {
        let (sx, sy, sz) = self.walk_sd(dt_s);
        let (floor, ceiling) = self.floor_ceiling();
        // The step's offset of every filament's noise counter (SplitMix64's increment).
        let offset = self.transport_steps.wrapping_mul(0x9e37_79b9_7f4a_7c15);
        self.transport_steps += 1;
        // The sink's line (from the origin) moved out by the widest filament's cut-off (none:
        // nothing beyond).
        let (sink_dir, stray_line) = self.local_sink();
        // No filament is older than the plume's clock.
        let widest =
            self.params.init_radius_m.powi(2) + self.params.growth_rate_m2ps * self.time_s.max(0.0);
        let sink_line = stray_line + self.params.cutoff_radii * widest.sqrt();
        self.strays.runs.clear();
        self.strays.moved = self.x.len();
        let d = self.local_domain();
        // The removal tests the positions widened to f64; the transport's test in f32 flags at
        // least every filament that test would take (the domain's bounds rounded inwards, the
        // sink's line lowered by far more than the f32 sum's rounding).
        let extent = d.x_min_m.abs().max(d.x_max_m.abs()) + d.y_min_m.abs().max(d.y_max_m.abs());
        let bounds = [
            f32_at_least(d.x_min_m),
            f32_at_most(d.x_max_m),
            f32_at_least(d.y_min_m),
            f32_at_most(d.y_max_m),
        ];
        let stray_line = f32_at_most(stray_line - 1e-5 * (extent + 1.0));
        let (left, beyond) = arch.dispatch(Transport {
            x: &mut self.x,
            y: &mut self.y,
            z: &mut self.z,
            key: &self.key,
            flow,
            origin: self.origin,
            dt_s: dt_s as f32,
            sd: [sx as f32, sy as f32, sz as f32],
            // Rounded inwards, so that a reflected height stays in the water.
            floor_ceiling: (f32_at_least(floor), f32_at_most(ceiling)),
            bounds,
            offset,
            sink: (
                [sink_dir[0] as f32, sink_dir[1] as f32],
                sink_line as f32,
                stray_line,
            ),
            scratch: &mut self.scratch,
            stray_runs: &mut self.strays.runs,
        });
        if let (Some(sb), VerticalBoundary::Reflecting { .. }) =
            (&self.seabed, self.params.vertical)
        {
            // The pass above reflected at the datum (the seabed's lowest point); here each
            // filament reflects at the seabed where it is.
            let (xs, ys, zs) = (&*self.x, &*self.y, &mut *self.z);
            let [ox, oy] = self.origin;
            for k in 0..zs.len() {
                let f = sb.height_at(f64::from(xs[k]) + ox, f64::from(ys[k]) + oy);
                let z = f64::from(zs[k]);
                if z < f {
                    // Rounded up, so that it stays on or above the seabed.
                    zs[k] = f32_at_least(reflect(z, f, ceiling));
                }
            }
        }
        (left, beyond)
    }

    /// Releases the step's filaments at uniformly drawn birth times within it, each placed where
    /// its age has taken it (see [`FilamentPlume::step`]); whether any is outside the domain.
    fn release_spread(
        &mut self,
        flow: &dyn FlowField,
        t_new_s: f64,
        dt_s: f64,
        rng: &mut SimRng,
    ) -> bool {
        self.update_release_rates(dt_s);
        let (floor, ceiling) = self.floor_ceiling();
        let local = self.local_domain();
        let mut left = false;
        for k in 0..self.sources.len() {
            let n = match &self.release[k] {
                Some(p) => p.sample(rng) as u64,
                None => 0,
            };
            if n == 0 {
                continue;
            }
            let src = self.sources[k].pos_m;
            let vel = flow.velocity(plumetrace_core::Vec2::new(src.x, src.y));
            let first = self.x.len();
            self.release_at(k, n, t_new_s);
            for i in first..self.x.len() {
                let age = dt_s * rng.random::<f64>();
                let (sx, sy, sz) = self.walk_sd(age);
                let n3 = crate::normal::normal_triple(rng.next_u64());
                self.birth_s[i] = t_new_s - age;
                // From the origin, the source first: the same steps wherever the domain lies.
                let [ox, oy] = self.origin;
                let x = ((src.x - ox) + vel.x * age + sx * n3[0]) as f32;
                let y = ((src.y - oy) + vel.y * age + sy * n3[1]) as f32;
                self.x[i] = x;
                self.y[i] = y;
                let (xw, yw) = (f64::from(x), f64::from(y));
                let floor = match (&self.seabed, self.params.vertical) {
                    (Some(sb), VerticalBoundary::Reflecting { .. }) => {
                        sb.height_at(xw + ox, yw + oy)
                    }
                    _ => floor,
                };
                // Rounded up, so that it stays on or above the seabed.
                self.z[i] = f32_at_least(reflect(src.z + sz * n3[2], floor, ceiling));
                left |= !local.contains_xy(xw, yw);
            }
        }
        left
    }

    /// Removes the filaments outside the domain or beyond the sink, keeping the others in
    /// order.
    ///
    /// The filaments that go are nearly all among the oldest, at the columns' front: the kept
    /// filaments before the last one that goes move back over the gaps and the columns start
    /// later, so the filaments behind it are not moved (see [`Column`]).
    fn remove_outside(&mut self) {
        // Both from the origin, as the positions are.
        let d = self.local_domain();
        let (dir, beyond_m) = self.local_sink();
        let cut = self.params.cutoff_radii;
        // The filaments that go, in order, each with whether it left the domain (else it lies
        // beyond the sink); most filaments are passed by comparisons alone.
        let mut gone: Vec<(usize, bool)> = Vec::new();
        // A run of filaments is passed at once when none of them is out of the domain or past
        // the sink's line: as the transport found it for the filaments it moved, else by a
        // test without branches, which the compiler vectorises. (The transport's test, in
        // single precision, flags at least every run this one takes on the same positions.)
        const RUN: usize = STRAY_RUN;
        let strays = &self.strays;
        let (xs, ys) = (&*self.x, &*self.y);
        let stays = |x: f32, y: f32| {
            let (x, y) = (f64::from(x), f64::from(y));
            (x >= d.x_min_m)
                & (x <= d.x_max_m)
                & (y >= d.y_min_m)
                & (y <= d.y_max_m)
                & (dir[0] * x + dir[1] * y <= beyond_m)
        };
        for (run, (rx, ry)) in xs.chunks(RUN).zip(ys.chunks(RUN)).enumerate() {
            let passed = match strays.runs.get(run) {
                Some(&any) if run * RUN + rx.len() <= strays.moved => !any,
                _ => rx
                    .iter()
                    .zip(ry)
                    .fold(true, |all, (&x, &y)| all & stays(x, y)),
            };
            if passed {
                continue;
            }
            for (i, (&x, &y)) in rx.iter().zip(ry).enumerate() {
                if stays(x, y) {
                    continue;
                }
                let k = run * RUN + i;
                let (x, y) = (f64::from(x), f64::from(y));
                if !d.contains_xy(x, y) {
                    gone.push((k, true));
                } else if dir[0] * x + dir[1] * y - cut * self.radius_sq(k).sqrt() > beyond_m {
                    gone.push((k, false));
                }
            }
        }
        let Some(&(last, _)) = gone.last() else {
            return;
        };
        for &(k, exited) in &gone {
            if exited {
                self.stats.exited += 1;
                self.stats.exited_mass += self.mass[k];
            } else {
                self.stats.dropped += 1;
                self.stats.dropped_mass += self.mass[k];
            }
        }
        // The kept filaments of 0..=last, last first, to the back of that range.
        let mut goes = gone.iter().rev().map(|g| g.0).peekable();
        let mut to = last;
        for k in (0..=last).rev() {
            if goes.next_if_eq(&k).is_some() {
                continue;
            }
            if to != k {
                self.x.copy(k, to);
                self.y.copy(k, to);
                self.z.copy(k, to);
                self.birth_s.copy(k, to);
                self.mass.copy(k, to);
                self.source.copy(k, to);
                self.key.copy(k, to);
            }
            to = to.wrapping_sub(1);
        }
        let n = gone.len();
        self.x.drop_front(n);
        self.y.drop_front(n);
        self.z.drop_front(n);
        self.birth_s.drop_front(n);
        self.mass.drop_front(n);
        self.source.drop_front(n);
        self.key.drop_front(n);
    }

    /// The Poisson release counts for a step of `dt_s` (rebuilt when the step changes).
    fn update_release_rates(&mut self, dt_s: f64) {
        if dt_s != self.release_dt_s {
            self.release_dt_s = dt_s;
            self.release = self
                .sources
                .iter()
                .map(|s| Poisson::new(s.filament_rate_hz * dt_s).ok())
                .collect();
        }
    }

    fn release(&mut self, t_s: f64, dt_s: f64, rng: &mut SimRng) {
        self.update_release_rates(dt_s);
        for k in 0..self.sources.len() {
            let n = match &self.release[k] {
                Some(p) => p.sample(rng),
                None => 0.0,
            };
            if n > 0.0 {
                self.release_at(k, n as u64, t_s);
            }
        }
    }

    fn index(&self) -> &CellIndex {
        self.index.get_or_init(|| self.new_index())
    }

    /// A query index of the filaments as they are now.
    fn new_index(&self) -> CellIndex {
        CellIndex::build(
            self,
            self.domain,
            self.params.cutoff_radii,
            self.params.vertical,
            self.seabed.as_deref(),
        )
    }

    /// The blocks' and groups' bounding boxes, built on first use after a change.
    fn boxes(&self) -> &ScanBoxes {
        self.boxes.get_or_init(|| {
            let blocks = crate::simd::best().dispatch(BlockBoxes {
                x: &self.x,
                y: &self.y,
                birth_s: &self.birth_s,
            });
            let groups = blocks
                .chunks(SCAN_GROUP)
                .map(|g| g.iter().fold(BlockBox::EMPTY, |a, b| a.union(*b)))
                .collect();
            ScanBoxes { blocks, groups }
        })
    }

    /// Concentration at `p` by scanning the filaments (no index): for a few points per step
    /// this is cheaper than building the index. Groups of blocks, then blocks of filaments,
    /// whose bounding box is beyond the cut-off of their oldest filament are skipped; every
    /// filament of such a box would have been skipped by the full scan too (the test is
    /// conservative in floating point: differences, squares and sums are monotone, and a
    /// group's box holds its blocks'), and the others are summed in the same order, so the
    /// result is bit for bit [`FilamentPlume::concentration_full_scan`]'s.
    pub fn concentration_scan(&self, p: Vec3) -> f64 {
        crate::simd::best().dispatch(Scan { plume: self, p })
    }

    /// [`FilamentPlume::concentration_scan`] (inlined into the vector unit's dispatch, so the
    /// filaments' horizontal test is taken in its lanes).
    #[inline(always)]
    fn scan(&self, p: Vec3) -> f64 {
        let p = self.measured_from_origin(p);
        let k = self.scan_terms();
        let boxes = self.boxes();
        let mut c = 0.0;
        for (g, gb) in boxes.groups.iter().enumerate() {
            if gb.beyond(p, k.box_constants()) {
                continue;
            }
            let first = g * SCAN_GROUP;
            let last = (first + SCAN_GROUP).min(boxes.blocks.len());
            for b in first..last {
                if boxes.blocks[b].beyond(p, k.box_constants()) {
                    continue;
                }
                let end = ((b + 1) * SCAN_BLOCK).min(self.x.len());
                c = self.sum_filaments(p, b * SCAN_BLOCK..end, c, &k);
            }
        }
        c
    }

    /// Concentration at `p` by scanning every filament: the reference the pruned scan is
    /// tested and benchmarked against.
    pub fn concentration_full_scan(&self, p: Vec3) -> f64 {
        let p = self.measured_from_origin(p);
        self.sum_filaments(p, 0..self.x.len(), 0.0, &self.scan_terms())
    }

    /// `p` measured from the origin, as the positions are.
    #[inline(always)]
    fn measured_from_origin(&self, p: Vec3) -> Vec3 {
        Vec3::new(p.x - self.origin[0], p.y - self.origin[1], p.z)
    }

    /// What a scan needs besides the point, worked out once per scan.
    fn scan_terms(&self) -> ScanTerms {
        let r0 = self.params.init_radius_m;
        let (floor, ceiling) = match self.params.vertical {
            VerticalBoundary::Reflecting { depth_m } => (Some(0.0), depth_m),
            VerticalBoundary::Unbounded => (None, None),
        };
        ScanTerms {
            r0sq: r0 * r0,
            gamma: self.params.growth_rate_m2ps,
            t: self.time_s,
            cut2: self.params.cutoff_radii * self.params.cutoff_radii,
            norm: (2.0 * std::f64::consts::PI).powf(1.5),
            floor,
            ceiling,
        }
    }

    /// `c` plus the contributions at `p` of the filaments in `range`, in order. The filaments
    /// beyond their cut-off in the plane (most of those a scan reaches) are found first, up to
    /// 64 at a time (one bit each) and without a branch per filament; the others are then summed
    /// in order.
    #[inline(always)]
    fn sum_filaments(
        &self,
        p: Vec3,
        range: std::ops::Range<usize>,
        mut c: f64,
        k: &ScanTerms,
    ) -> f64 {
        let (xs, ys, births) = (&*self.x, &*self.y, &*self.birth_s);
        let (r0sq, gamma, t, cut2) = k.box_constants();
        let mut start = range.start;
        while start < range.end {
            let end = (start + u64::BITS as usize).min(range.end);
            // Bit i: filament start + i is within its cut-off in the plane (or a NaN says
            // nothing either way, as in the test below).
            let mut near = 0u64;
            for (i, ((&x, &y), &birth)) in xs[start..end]
                .iter()
                .zip(&ys[start..end])
                .zip(&births[start..end])
                .enumerate()
            {
                let dx = p.x - f64::from(x);
                let dy = p.y - f64::from(y);
                let dxy2 = dx * dx + dy * dy;
                let lim2 = cut2 * (r0sq + gamma * (t - birth).max(0.0));
                let far = dxy2 > lim2;
                near |= u64::from(!far) << i;
            }
            while near != 0 {
                let i = near.trailing_zeros() as usize;
                near &= near - 1;
                c = self.add_filament(p, start + i, c, k);
            }
            start = end;
        }
        c
    }

    /// `c` plus filament `k`'s contribution at `p` (and its images').
    #[inline(always)]
    fn add_filament(&self, p: Vec3, k: usize, mut c: f64, terms: &ScanTerms) -> f64 {
        let ScanTerms {
            r0sq,
            gamma,
            t,
            cut2,
            norm,
            floor,
            ceiling,
        } = *terms;
        let (x, y) = (f64::from(self.x[k]), f64::from(self.y[k]));
        let dx = p.x - x;
        let dy = p.y - y;
        let dxy2 = dx * dx + dy * dy;
        let r2 = r0sq + gamma * (t - self.birth_s[k]).max(0.0);
        let lim2 = cut2 * r2;
        if dxy2 > lim2 {
            return c;
        }
        let amp = self.mass[k] / (norm * r2 * r2.sqrt());
        let k2 = -0.5 / r2;
        let z = f64::from(self.z[k]);
        // Over a seabed, the image is in the seabed where the filament is.
        let floor = match (&self.seabed, floor) {
            (Some(sb), Some(_)) => Some(sb.height_at(x + self.origin[0], y + self.origin[1])),
            _ => floor,
        };
        for zc in [
            Some(z),
            floor.map(|f| 2.0 * f - z),
            ceiling.map(|s| 2.0 * s - z),
        ]
        .into_iter()
        .flatten()
        {
            let dz = p.z - zc;
            let d2 = dxy2 + dz * dz;
            if d2 < lim2 {
                c += amp * (d2 * k2).exp();
            }
        }
        c
    }

    /// Builds the query index now (it is otherwise built by the first query after a step); lets a
    /// benchmark time the build apart from the queries.
    pub fn prepare_queries(&self) {
        let _ = self.index();
    }

    /// Builds a query index and drops it, leaving the plume's own as it is: what the first
    /// grid or point query after a step pays, for a benchmark to time again and again.
    pub fn build_query_index_apart(&self) {
        // Kept from the optimiser's sight, so that the unread index is still built.
        drop(std::hint::black_box(self.new_index()));
    }
}

/// The point scan's constants (see [`FilamentPlume::concentration_scan`]).
#[derive(Debug, Clone, Copy)]
struct ScanTerms {
    r0sq: f64,
    gamma: f64,
    t: f64,
    cut2: f64,
    /// `(2 pi)^1.5`.
    norm: f64,
    floor: Option<f64>,
    ceiling: Option<f64>,
}

impl ScanTerms {
    /// `(r0^2, gamma, t, cutoff^2)`, what a box's test needs.
    #[inline(always)]
    fn box_constants(&self) -> (f64, f64, f64, f64) {
        (self.r0sq, self.gamma, self.t, self.cut2)
    }
}

/// A point scan on the best vector unit ([`FilamentPlume::concentration_scan`]).
struct Scan<'a> {
    plume: &'a FilamentPlume,
    p: Vec3,
}

impl pulp::WithSimd for Scan<'_> {
    type Output = f64;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> f64 {
        self.plume.scan(self.p)
    }
}

/// The bounding boxes of consecutive blocks of [`SCAN_BLOCK`] filaments (see
/// [`FilamentPlume::boxes`]), as a [`pulp::WithSimd`] operation: each column's extremes over a
/// block are kept in one vector, then folded.
struct BlockBoxes<'a> {
    x: &'a [f32],
    y: &'a [f32],
    birth_s: &'a [f64],
}

impl pulp::WithSimd for BlockBoxes<'_> {
    type Output = Vec<BlockBox>;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> Vec<BlockBox> {
        // The least and the greatest of positions `v`, widened, a NaN passed over as `f32::min`
        // does: each lane takes a value only where it compares below (above) the lane's
        // extreme, which a NaN never does, so no lane is ever NaN (a vector minimum instruction
        // would not do: some give NaN back, as Arm's does).
        #[inline(always)]
        fn extremes<S: pulp::Simd>(simd: S, v: &[f32]) -> (f64, f64) {
            let (head, tail) = S::as_simd_f32s(v);
            let mut least = simd.splat_f32s(f32::INFINITY);
            let mut most = simd.splat_f32s(f32::NEG_INFINITY);
            for &c in head {
                least = simd.select_f32s(simd.less_than_f32s(c, least), c, least);
                most = simd.select_f32s(simd.greater_than_f32s(c, most), c, most);
            }
            let (mut l, mut m) = (simd.reduce_min_f32s(least), simd.reduce_max_f32s(most));
            for &t in tail {
                l = l.min(t);
                m = m.max(t);
            }
            (f64::from(l), f64::from(m))
        }
        // The least of release times `v`, the same way.
        #[inline(always)]
        fn least<S: pulp::Simd>(simd: S, v: &[f64]) -> f64 {
            let (head, tail) = S::as_simd_f64s(v);
            let mut least = simd.splat_f64s(f64::INFINITY);
            for &c in head {
                least = simd.select_f64s(simd.less_than_f64s(c, least), c, least);
            }
            tail.iter()
                .fold(simd.reduce_min_f64s(least), |l, &t| l.min(t))
        }
        let BlockBoxes { x, y, birth_s } = self;
        x.chunks(SCAN_BLOCK)
            .zip(y.chunks(SCAN_BLOCK))
            .zip(birth_s.chunks(SCAN_BLOCK))
            .map(|((bx, by), bb)| {
                let (x_min, x_max) = extremes(simd, bx);
                let (y_min, y_max) = extremes(simd, by);
                BlockBox {
                    x_min,
                    x_max,
                    y_min,
                    y_max,
                    birth_min_s: least(simd, bb),
                }
            })
            .collect()
    }
}

/// One transport pass over the filament columns (see `FilamentPlume::transport`), as a
/// [`pulp::WithSimd`] operation so that all of it is compiled for the vector unit chosen.
struct Transport<'a> {
    x: &'a mut [f32],
    y: &'a mut [f32],
    z: &'a mut [f32],
    key: &'a [u64],
    flow: &'a dyn FlowField,
    /// Where the positions are measured from.
    origin: [f64; 2],
    dt_s: f32,
    sd: [f32; 3],
    floor_ceiling: (f32, f32),
    /// The domain's `[x_min, x_max, y_min, y_max]`, rounded inwards.
    bounds: [f32; 4],
    offset: u64,
    /// The sink's direction, the line beyond which a filament certainly lies past it, and the
    /// line past which one may go (see [`Strays`]).
    sink: ([f32; 2], f32, f32),
    scratch: &'a mut TransportScratch,
    stray_runs: &'a mut Vec<bool>,
}

impl pulp::WithSimd for Transport<'_> {
    type Output = (bool, usize);

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> (bool, usize) {
        let Transport {
            x,
            y,
            z,
            key,
            flow,
            origin,
            dt_s,
            sd: [sx, sy, sz],
            floor_ceiling: (floor, ceiling),
            bounds: [x_min, x_max, y_min, y_max],
            offset,
            sink: (sink_dir, sink_line, stray_line),
            scratch,
            stray_runs,
        } = self;
        let TransportScratch {
            u,
            v,
            words,
            n0,
            n1,
            n2,
        } = scratch;
        let mut left = false;
        let mut beyond = 0usize;
        for (((xs, ys), zs), keys) in x
            .chunks_mut(TRANSPORT_CHUNK)
            .zip(y.chunks_mut(TRANSPORT_CHUNK))
            .zip(z.chunks_mut(TRANSPORT_CHUNK))
            .zip(key.chunks(TRANSPORT_CHUNK))
        {
            let m = xs.len();
            flow.velocities_f32(origin, xs, ys, &mut u[..m], &mut v[..m]);
            for (w, k) in words.iter_mut().zip(keys) {
                *w = splitmix64_mix(k.wrapping_add(offset));
            }
            crate::normal::fill_normal_columns(&words[..m], &mut n0[..], &mut n1[..], &mut n2[..]);
            // Every column cut to the chunk's length, so the loop has no bounds checks.
            let (ys, zs, u, v) = (&mut ys[..m], &mut zs[..m], &u[..m], &v[..m]);
            let (n0, n1, n2) = (&n0[..m], &n1[..m], &n2[..m]);
            // Run by run (chunks are whole runs but for the last), whether any may go.
            for start in (0..m).step_by(STRAY_RUN) {
                let mut stray = false;
                // Counted in 32 bits within the run, so the loop keeps sixteen lanes.
                let mut run_beyond = 0u32;
                for k in start..(start + STRAY_RUN).min(m) {
                    let (x, y, z) = (&mut xs[k], &mut ys[k], &mut zs[k]);
                    *x += u[k] * dt_s + sx * n0[k];
                    *y += v[k] * dt_s + sy * n1[k];
                    *z = reflect(*z + sz * n2[k], floor, ceiling);
                    let inside = (*x >= x_min) & (*x <= x_max) & (*y >= y_min) & (*y <= y_max);
                    let along = sink_dir[0] * *x + sink_dir[1] * *y;
                    left |= !inside;
                    run_beyond += u32::from(along > sink_line);
                    stray |= !(inside & (along <= stray_line));
                }
                beyond += run_beyond as usize;
                stray_runs.push(stray);
            }
        }
        (left, beyond)
    }
}

/// SplitMix64's output function: a bijective mix of 64 bits, so `mix(key + n * gamma)` over
/// `n` is a SplitMix64 stream starting at `key`.
#[inline(always)]
fn splitmix64_mix(z: u64) -> u64 {
    let z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    let z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The least `f32` at or above `v` (an infinity or NaN as it is).
fn f32_at_least(v: f64) -> f32 {
    let f = v as f32;
    if f64::from(f) < v { f.next_up() } else { f }
}

/// The greatest `f32` at or below `v`.
fn f32_at_most(v: f64) -> f32 {
    let f = v as f32;
    if f64::from(f) > v { f.next_down() } else { f }
}

/// A height reflected at the seabed `floor` and the surface `ceiling` (once each: a step moves a
/// filament far less than the water's depth), in either precision (`floor + floor` is
/// `2 floor` exactly).
#[inline(always)]
fn reflect<T>(z: T, floor: T, ceiling: T) -> T
where
    T: Copy + PartialOrd + std::ops::Add<Output = T> + std::ops::Sub<Output = T>,
{
    let mut z = z;
    if z < floor {
        z = floor + floor - z;
    }
    if z > ceiling {
        let down = ceiling + ceiling - z;
        z = if down > floor { down } else { floor };
    }
    z
}

impl ConcentrationField for FilamentPlume {
    fn concentration(&self, p: Vec3) -> f64 {
        self.index().concentration(p)
    }
    fn grid_concentrations(&self, grid: &crate::GridSpec, points: &[Vec3], out: &mut [f64]) {
        let bands = rayon::current_num_threads();
        self.grid_query(grid, points, out, TermExp::Standard, bands);
    }
    /// On the calling thread: a run samples its figure's and page's grids (about a millisecond
    /// each) once a minute of mission, and waking the pool's threads for each, which then spin
    /// for work while the run goes on, cost a `duck-2003-st` run about 6 % more CPU on 2 threads
    /// (docs/results/performance.md). Points that are not the grid's are queried as a batch
    /// ([`ConcentrationField::concentrations`], in parallel).
    fn display_grid_concentrations(
        &self,
        grid: &crate::GridSpec,
        points: &[Vec3],
        out: &mut [f64],
    ) {
        self.grid_query(grid, points, out, TermExp::Lanes, 1);
    }
}

impl FilamentPlume {
    /// A grid query with the exponentials taken `how`, in `bands` bands of rows; point by point
    /// if `points` and `out` are not the grid's.
    fn grid_query(
        &self,
        grid: &crate::GridSpec,
        points: &[Vec3],
        out: &mut [f64],
        how: TermExp,
        bands: usize,
    ) {
        if points.len() == grid.nx * grid.ny && out.len() == points.len() {
            self.index().grid_concentrations(grid, out, how, bands);
        } else {
            self.concentrations(points, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flow::{FarrellFlow, FarrellParams, MeanFlow};
    use crate::{StreamId, stream_rng};

    /// The 0-100 m square most tests here use.
    fn square() -> Rect {
        Rect::new(0.0, 100.0, 0.0, 100.0).unwrap_or_else(|e| panic!("{e}"))
    }

    /// A plume over `region` with one source at `(x, y)`, 1 m above the seabed, releasing one
    /// mass unit a second in `rate_hz` filaments a second.
    fn plume_with_source(
        region: Rect,
        (x, y): (f64, f64),
        rate_hz: f64,
        params: FilamentParams,
    ) -> FilamentPlume {
        let source = Source {
            pos_m: Vec3::new(x, y, 1.0),
            mass_rate_per_s: 1.0,
            filament_rate_hz: rate_hz,
        };
        FilamentPlume::new(region, vec![source], params).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn single_precision_bounds_round_inwards() {
        for v in [
            0.0,
            100.1,
            -0.3,
            1e-40,
            3.0e38,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ] {
            let (lo, hi) = (f32_at_least(v), f32_at_most(v));
            assert!(f64::from(lo) >= v && f64::from(hi) <= v, "{v}: {lo} {hi}");
            assert!(
                lo == hi || lo == hi.next_up(),
                "{v}: {lo} {hi} not neighbours"
            );
        }
    }

    #[test]
    fn the_transport_flags_every_run_the_removal_would_take_from() {
        // Filaments held still (no flow, no walk) on the f32 values around bounds that f32
        // cannot hold: the transport tests in f32, the removal in f64 on the same positions,
        // so every run with a filament the removal's test takes must be flagged.
        let region = Rect {
            x_min_m: -0.3,
            x_max_m: 100.1,
            y_min_m: 0.0,
            y_max_m: 99.7,
        };
        let params = FilamentParams {
            dispersion: Dispersion::PompyCompatible {
                scale_mps: [0.0; 3],
            },
            ..FilamentParams::default()
        };
        let mut p = plume_with_source(region, (50.0, 50.0), 1.0, params);
        p.release_at_source(0, 64 * 6);
        // A sink line across the domain at 80 degrees, so that its test rounds in both axes.
        let a = 80f64.to_radians();
        let sink = DownflowSink {
            dir: [a.cos(), a.sin()],
            beyond_m: 70.3,
        };
        p.set_sink(Some(sink));
        // Positions are from the plume's origin (the domain's centre), as the removal sees them.
        let d = p.local_domain();
        let (dir, line) = p.local_sink();
        let near = |v: f64| [f32_at_most(v), f32_at_least(v)];
        // The least f32 height at x = 0 past the sink's line.
        let past = {
            let mut y = f32_at_least(line / dir[1]);
            while dir[1] * f64::from(y) <= line {
                y = y.next_up();
            }
            y
        };
        // Run r gets its odd filament at slot 7; run 0 none.
        let odd = [
            None,
            Some((near(d.x_max_m)[1], 0.0)),
            Some((near(d.x_min_m)[0], 0.0)),
            Some((0.0, past)),
            Some((near(d.x_min_m)[1], 0.0)),
            Some((0.0, f32::NAN)),
        ];
        for (r, o) in odd.iter().enumerate() {
            for i in 0..64 {
                let k = r * 64 + i;
                (p.x[k], p.y[k]) = match (*o, i) {
                    (Some(xy), 7) => xy,
                    _ => (-10.0, -20.0),
                };
            }
        }
        let flow = crate::flow::UniformFlow::new(MeanFlow::Steady {
            speed_mps: 0.0,
            toward_deg: 0.0,
        })
        .unwrap_or_else(|e| panic!("{e}"));
        // The removal's test.
        let takes = |x: f32, y: f32| {
            let (x, y) = (f64::from(x), f64::from(y));
            !((x >= d.x_min_m)
                & (x <= d.x_max_m)
                & (y >= d.y_min_m)
                & (y <= d.y_max_m)
                & (dir[0] * x + dir[1] * y <= line))
        };
        for arch in crate::simd::every() {
            let mut q = p.copy_state();
            q.transport_on(arch, &flow, 0.1);
            let taken: Vec<bool> = (0..odd.len())
                .map(|r| (r * 64..r * 64 + 64).any(|k| takes(q.x[k], q.y[k])))
                .collect();
            // The removal's test takes runs 1, 2, 3 and 5 (not 4, just inside), and the
            // positions did not move.
            assert_eq!(taken, [false, true, true, true, false, true], "{arch:?}");
            assert_eq!(q.y[3 * 64 + 7], past);
            for (r, &t) in taken.iter().enumerate() {
                assert!(q.strays.runs[r] || !t, "run {r} not flagged on {arch:?}");
            }
            assert!(!q.strays.runs[0], "a run well inside flagged on {arch:?}");
        }
    }

    #[test]
    fn a_domain_far_from_the_frame_s_origin_moves_its_filaments_as_one_near_it() {
        // Positions are kept from the domain's centre: the same plume 500 km east and 5,000 km
        // north (coordinates as large as UTM's) takes the same steps, bit for bit, where
        // positions from the frame's origin would be rounded to 0.5 m.
        let (dx, dy) = (500_000.0, 5_000_000.0);
        let near = Rect {
            x_min_m: 0.0,
            x_max_m: 1000.0,
            y_min_m: 0.0,
            y_max_m: 400.0,
        };
        let far = Rect {
            x_min_m: near.x_min_m + dx,
            x_max_m: near.x_max_m + dx,
            y_min_m: near.y_min_m + dy,
            y_max_m: near.y_max_m + dy,
        };
        let flow = crate::flow::UniformFlow::new(MeanFlow::Steady {
            speed_mps: 0.1,
            toward_deg: 80.0,
        })
        .unwrap_or_else(|e| panic!("{e}"));
        let params = FilamentParams::default();
        let mut a = plume_with_source(near, (100.0, 200.0), 2.0, params);
        let mut b = plume_with_source(far, (100.0 + dx, 200.0 + dy), 2.0, params);
        let (mut ra, mut rb) = (
            stream_rng(5, StreamId::Plume),
            stream_rng(5, StreamId::Plume),
        );
        for k in 1..=300u32 {
            a.step(&flow, f64::from(k), 1.0, &mut ra);
            b.step(&flow, f64::from(k), 1.0, &mut rb);
        }
        assert!(a.len() > 400, "{} filaments", a.len());
        let bits = |p: &FilamentPlume| -> Vec<[u32; 3]> {
            (0..p.len())
                .map(|k| [p.x[k].to_bits(), p.y[k].to_bits(), p.z[k].to_bits()])
                .collect()
        };
        assert!(bits(&a) == bits(&b));
        // Read back in the frame, a filament of the far plume is its near twin moved by (dx, dy).
        for ((pa, _), (pb, _)) in a.filaments().zip(b.filaments()) {
            assert!((pb.x - pa.x - dx).abs() < 1e-6 && (pb.y - pa.y - dy).abs() < 1e-6);
        }
        let q = |p: &FilamentPlume, x: f64, y: f64| p.concentration_full_scan(Vec3::new(x, y, 1.0));
        let (ca, cb) = (q(&a, 130.0, 205.0), q(&b, 130.0 + dx, 205.0 + dy));
        assert!(ca > 0.0 && (ca - cb).abs() <= 1e-6 * ca, "{ca} {cb}");
    }

    /// A still or steady current of `speed_mps` toward the east.
    fn current_east(speed_mps: f64) -> crate::flow::UniformFlow {
        crate::flow::UniformFlow::new(MeanFlow::Steady {
            speed_mps,
            toward_deg: 90.0,
        })
        .unwrap_or_else(|e| panic!("{e}"))
    }

    /// 200 km east by 100 m north: positions 100 km from the centre round to 3.9 mm.
    fn long_strip() -> Rect {
        Rect::new(0.0, 200_000.0, 0.0, 100.0).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn a_step_too_short_for_single_precision_positions_is_refused() {
        let walk = |horizontal_m2ps, vertical_m2ps| FilamentParams {
            dispersion: Dispersion::Physical {
                horizontal_m2ps,
                vertical_m2ps,
            },
            ..FilamentParams::default()
        };
        let err = |p: &FilamentPlume, dt: f64, flow: &dyn FlowField| {
            p.check_step(dt, flow).err().map(|e| e.to_string())
        };
        // The step an error suggests passes as written, and the four-digit step below it
        // does not.
        let suggestion_holds = |p: &FilamentPlume, e: &str, flow: &dyn FlowField| {
            let s = e
                .split("a step of at least ")
                .nth(1)
                .and_then(|t| t.split(' ').next())
                .unwrap_or_else(|| panic!("no step suggested in {e}"));
            let dt: f64 = s.parse().unwrap_or_else(|_| panic!("{s:?}"));
            let unit = 10f64.powi(dt.log10().floor() as i32 - 3);
            assert_eq!(err(p, dt, flow), None, "{s} suggested in {e}");
            assert!(
                err(p, dt - unit, flow).is_some(),
                "{} passes too",
                dt - unit
            );
        };
        let still = current_east(0.0);
        let wide = plume_with_source(long_strip(), (150_000.0, 50.0), 1.0, walk(0.01, 0.0));
        let [east, north, up] = wide.position_rounding_m();
        // Half of f32's spacing between 65,536 and 131,072; the source is 1 m up.
        assert_eq!(east, (1.0 / 256.0, 100_000.0));
        assert!(
            north.0 < 1e-5 && up == (0.5f64.powi(24), 1.0),
            "{north:?} {up:?}"
        );
        // The walk: sqrt(2 K dt) = 1.4 cm at 0.01 s, under 5 x 3.9 mm; the error says that
        // 0.01 (0.0195 / 0.0141)^2 = 0.019073 s would do, as 0.01908 s.
        let e = err(&wide, 0.01, &still).unwrap_or_else(|| panic!("0.01 s over 200 km accepted"));
        for part in [
            "dt_s: a step of 0.01 s moves filaments east by about 1.414e-2 m",
            "3.62 times the largest rounding",
            "at the domain's edge, 100000.0 m from its centre",
            "need at least 5 times (1.953e-2 m)",
            "a step of at least 1.908e-2 s, or a larger plume.horizontal_diffusivity_m2ps or a \
             narrower domain",
        ] {
            assert!(e.contains(part), "{part:?} not in {e}");
        }
        suggestion_holds(&wide, &e, &still);
        // A current does not make up for a walk that is lost, though no walk at all would do
        // where the current's move alone is held (5 m/s over 0.2 s: a metre, 256 roundings).
        let e = err(&wide, 0.01, &current_east(5.0)).unwrap_or_default();
        assert!(!e.contains("no random walk"), "{e}");
        let e = err(&wide, 0.2, &current_east(5.0)).unwrap_or_default();
        assert!(e.is_empty(), "{e}");
        let tiny = plume_with_source(long_strip(), (150_000.0, 50.0), 1.0, walk(1e-9, 0.0));
        let e = err(&tiny, 0.2, &current_east(5.0)).unwrap_or_default();
        assert!(
            e.contains("or no random walk (plume.horizontal_diffusivity_m2ps = 0"),
            "{e}"
        );
        // Without a walk, the current's whole move against 100 roundings (a steady move is
        // rounded the same way at every step): 0.5 m/s east moves 5 mm in 0.01 s (refused),
        // and 0.78125 s would move it 100 roundings (suggested as 0.7813 s).
        let drift = plume_with_source(long_strip(), (150_000.0, 50.0), 1.0, walk(0.0, 0.0));
        let e = err(&drift, 0.01, &current_east(0.5)).unwrap_or_default();
        for part in [
            "moves filaments across the plane by about 5.000e-3 m (the current at the sources, \
             with no random walk), 1.28 times",
            "need at least 100 times (3.906e-1 m)",
            "a step of at least 7.813e-1 s, or a random walk (plume.horizontal_diffusivity_m2ps) \
             or a narrower domain",
        ] {
            assert!(e.contains(part), "{part:?} not in {e}");
        }
        suggestion_holds(&drift, &e, &current_east(0.5));
        // The bias is a hundredth of the whole move at most, whichever way it points: a
        // current toward 8 degrees of 0.5 m/s over 0.01 s is refused as the eastward one is.
        let toward_8 = crate::flow::UniformFlow::new(MeanFlow::Steady {
            speed_mps: 0.5,
            toward_deg: 8.0,
        })
        .unwrap_or_else(|e| panic!("{e}"));
        assert!(err(&drift, 0.01, &toward_8).is_some());
        // Short along two axes: the error names the first and suggests the step both take.
        let mut both = walk(0.005, 1e-12);
        both.vertical = VerticalBoundary::Reflecting { depth_m: None };
        let two = FilamentPlume::new(
            long_strip(),
            vec![Source {
                pos_m: Vec3::new(150_000.0, 50.0, 5.0),
                mass_rate_per_s: 1.0,
                filament_rate_hz: 1.0,
            }],
            both,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let e = err(&two, 0.01, &still).unwrap_or_default();
        assert!(
            e.contains("filaments east") && e.contains("(the step is short up too)"),
            "{e}"
        );
        suggestion_holds(&two, &e, &still);
        // Nothing moves, nothing to hold.
        assert_eq!(err(&drift, 0.01, &still), None);
        // Heights at the highest source: a vertical walk of 4.5e-6 m a step is lost 5,000 m
        // up (0.24 mm roundings) and held near the seabed.
        let mut high = walk(0.01, 1e-9);
        high.vertical = VerticalBoundary::Reflecting {
            depth_m: Some(6000.0),
        };
        let source = |z: f64| Source {
            pos_m: Vec3::new(50.0, 50.0, z),
            mass_rate_per_s: 1.0,
            filament_rate_hz: 1.0,
        };
        let at = |z: f64| {
            FilamentPlume::new(square(), vec![source(z)], high).unwrap_or_else(|e| panic!("{e}"))
        };
        let e = err(&at(5000.0), 0.01, &still).unwrap_or_default();
        assert!(
            e.contains("filaments up")
                && e.contains("at the highest a filament is carried to, 5000.0 m up"),
            "{e}"
        );
        assert!(
            e.contains("a larger plume.vertical_diffusivity_m2ps"),
            "{e}"
        );
        suggestion_holds(&at(5000.0), &e, &still);
        assert_eq!(err(&at(0.0), 0.01, &still), None);
        assert_eq!(err(&at(1.0), 0.01, &still), None);
        // Over a seabed 100 m to 6,000 m deep the current carries filaments up its slope: a
        // source on its deepest floor counts the surface, 6,000 m above the datum.
        let slope = Seabed::from_depths(square(), 2, 2, &[6000.0, 100.0, 6000.0, 100.0])
            .unwrap_or_else(|e| panic!("{e}"));
        let mut floor = at(0.0);
        floor.set_seabed(Some(Arc::new(slope)));
        let e = err(&floor, 0.01, &still).unwrap_or_default();
        assert!(e.contains("carried to, 6000.0 m up"), "{e}");
        // pompy's scaling: the key to raise is its scale.
        let pompy = FilamentParams {
            dispersion: Dispersion::PompyCompatible {
                scale_mps: [2.0, 2.0, 1e-7],
            },
            ..high
        };
        let p = FilamentPlume::new(square(), vec![source(5000.0)], pompy)
            .unwrap_or_else(|e| panic!("{e}"));
        suggestion_holds(&p, &err(&p, 0.01, &still).unwrap_or_default(), &still);
        let e = err(&p, 0.01, &still).unwrap_or_default();
        assert!(
            e.contains("up") && e.contains("a larger plume.pompy_diff_scale_mps"),
            "{e}"
        );
    }

    #[test]
    fn a_walk_at_the_refused_bound_keeps_its_variance_and_one_below_it_is_lost() {
        // 80,000 filaments 99 km east of the centre of a 200 km strip (positions rounded to
        // 3.9 mm), walking 100 steps in still water with a standard deviation of `sd` a step:
        // the spread of their moves against the walk's own, 100 sd^2.
        let spread = |sd: f64| -> f64 {
            let k = 0.01;
            let dt = sd * sd / (2.0 * k);
            let params = FilamentParams {
                dispersion: Dispersion::Physical {
                    horizontal_m2ps: k,
                    vertical_m2ps: 0.0,
                },
                ..FilamentParams::default()
            };
            let mut p = plume_with_source(long_strip(), (199_000.0, 50.0), 1.0, params);
            p.set_key_seed(11);
            p.release_at_source(0, 80_000);
            let start: Vec<f64> = p.x.iter().map(|&x| f64::from(x)).collect();
            assert!(start.iter().all(|&x| x == 99_000.0));
            let still = current_east(0.0);
            for _ in 0..100 {
                p.transport_on(crate::simd::best(), &still, dt);
            }
            let moves: Vec<f64> =
                p.x.iter()
                    .zip(&start)
                    .map(|(&x, s)| f64::from(x) - s)
                    .collect();
            let n = moves.len() as f64;
            let mean = moves.iter().sum::<f64>() / n;
            let var = moves.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (n - 1.0);
            var / (100.0 * sd * sd)
        };
        let r = 1.0 / 256.0;
        // At the bound the rounding adds at most 1.3 % (the estimate's own error is about half
        // a percent); at 3 roundings it would add 3.7 %.
        let at_bound = spread(FilamentPlume::MIN_WALK_IN_ROUNDINGS * r);
        assert!((at_bound - 1.0).abs() < 0.025, "{at_bound}");
        // And the check puts the bound there: the step of a walk of 5 roundings passes, one a
        // hundredth shorter does not.
        let k = 0.01;
        let params = FilamentParams {
            dispersion: Dispersion::Physical {
                horizontal_m2ps: k,
                vertical_m2ps: 0.0,
            },
            ..FilamentParams::default()
        };
        let p = plume_with_source(long_strip(), (199_000.0, 50.0), 1.0, params);
        let sd = FilamentPlume::MIN_WALK_IN_ROUNDINGS * r;
        let dt = sd * sd / (2.0 * k);
        let still = current_east(0.0);
        assert!(p.check_step(dt * 1.000_001, &still).is_ok());
        assert!(p.check_step(dt * 0.99, &still).is_err());
        // A walk of a quarter of the rounding is all but lost: a move shorter than the rounding
        // leaves a position where it was.
        let lost = spread(0.25 * r);
        assert!(lost < 0.1, "{lost}");
    }

    #[test]
    fn without_a_walk_a_steady_move_is_rounded_the_same_way_every_step() {
        // A filament 99 km east of the strip's centre (roundings of 3.9 mm) carried east by a
        // steady current with no random walk, 1,000 steps: its speed against the current's.
        let speed_ratio = |move_in_roundings: f64| -> f64 {
            let r = 1.0 / 256.0;
            let params = FilamentParams {
                dispersion: Dispersion::Physical {
                    horizontal_m2ps: 0.0,
                    vertical_m2ps: 0.0,
                },
                ..FilamentParams::default()
            };
            let mut p = plume_with_source(long_strip(), (199_000.0, 50.0), 1.0, params);
            p.release_at_source(0, 1);
            let flow = current_east(1.0);
            let dt = move_in_roundings * r;
            for _ in 0..1000 {
                p.transport_on(crate::simd::best(), &flow, dt);
            }
            (f64::from(p.x[0]) - 99_000.0) / (1000.0 * dt)
        };
        // 5.5 roundings a step come out as 6 (three spacings): 9 % fast.
        let coarse = speed_ratio(5.5);
        assert!((coarse - 6.0 / 5.5).abs() < 1e-9, "{coarse}");
        // At the bound for a move without a walk the bias is at most a hundredth.
        let fine = speed_ratio(FilamentPlume::MIN_DRIFT_IN_ROUNDINGS + 1.3);
        assert!((fine - 1.0).abs() <= 0.01, "{fine}");
    }

    /// A Farrell flow over `region` with a mean of `speed_mps` toward 80 degrees, stepped at
    /// `dt`.
    fn farrell_toward_80(region: Rect, speed_mps: f64, dt: f64) -> FarrellFlow {
        let mean = MeanFlow::Steady {
            speed_mps,
            toward_deg: 80.0,
        };
        FarrellFlow::new(region, mean, FarrellParams::default(), dt)
            .unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn removal_keeps_the_others_in_order_wherever_the_leavers_are() {
        // 300 filaments along x in a 0-100 m square with a sink at x = 80 m: those out of the
        // square or beyond the sink go, at the front, in the middle and last; the rest keep
        // their order and every column stays aligned, over several removals in a row, and
        // without the sink.
        let mut p = plume_with_source(square(), (50.0, 50.0), 1.0, FilamentParams::default());
        p.set_sink(Some(DownflowSink {
            dir: [1.0, 0.0],
            beyond_m: 80.0,
        }));
        // Round 3 has no sink: a filament beyond its line then stays.
        for round in 0..4 {
            if round == 3 {
                p.set_sink(None);
            }
            p.release_at_source(0, 300 - p.len() as u64);
            let n = p.len();
            let mut kept = Vec::new();
            for k in 0..n {
                // Out of the square; beyond the sink; past its line but reaching back over it
                // (a filament's cut-off is about 0.1 m); inside.
                let (x, y, stays) = match (k + round) % 7 {
                    0 => (-1.0, 50.0, false),
                    3 => (90.0, 50.0, round == 3),
                    5 => (80.05, 50.0, true),
                    _ => (10.0 + (k % 60) as f64, 50.0, true),
                };
                // Stored from the plume's origin.
                let (x, y) = ((x - p.origin[0]) as f32, (y - p.origin[1]) as f32);
                p.x[k] = x;
                p.y[k] = y;
                p.mass[k] = k as f64;
                if stays {
                    kept.push((x, k as f64, p.key[k]));
                }
            }
            let before = p.stats();
            p.remove_outside();
            let after = p.stats();
            let now: Vec<_> = (0..p.len())
                .map(|k| (p.x[k], p.mass[k], p.key[k]))
                .collect();
            assert_eq!(now, kept, "round {round}");
            let exited = (0..n).filter(|k| (k + round) % 7 == 0).count() as u64;
            assert_eq!(after.exited - before.exited, exited);
            assert_eq!(
                after.dropped - before.dropped,
                (n - kept.len()) as u64 - exited
            );
            // Summed in order, as before.
            let mass = (0..n)
                .filter(|k| (k + round) % 7 == 0)
                .fold(before.exited_mass, |m, k| m + k as f64);
            assert_eq!(after.exited_mass, mass);
            assert_eq!(p.y.len(), p.len());
            assert_eq!(p.birth_s.len(), p.len());
            assert_eq!(p.source.len(), p.len());
        }
    }

    #[test]
    fn the_removal_after_a_transport_is_the_removal_of_a_full_test() {
        // A current of 1 m/s carries filaments from x = 40 m past a sink at x = 55 m, over 400
        // steps of 0.1 s; after each transport a few filaments are released and one of them put
        // outside the square (after the transport: its run is tested in full). The removal that reads
        // the transport's runs and one on a copy that tests every filament keep the same
        // filaments, bit for bit, and count the same leavers.
        let dt = 0.1;
        let mut flow = farrell_toward_80(square(), 1.0, dt);
        let mut p = plume_with_source(square(), (40.0, 50.0), 1.0, FilamentParams::default());
        p.set_key_seed(3);
        p.set_sink(Some(DownflowSink {
            dir: [1.0, 0.0],
            beyond_m: 55.0,
        }));
        let mut flow_rng = stream_rng(3, StreamId::Flow);
        let (mut removed, mut flagged) = (0, 0);
        for k in 1..=400u32 {
            let t = f64::from(k) * dt;
            flow.advance(t, dt, &mut flow_rng)
                .unwrap_or_else(|e| panic!("{e}"));
            p.release_at_source(0, 20);
            p.transport(&flow, dt);
            p.release_at_source(0, 3);
            let last = p.len() - 1;
            // At x = -5 m, from the origin.
            p.x[last] = (-5.0 - p.origin[0]) as f32;
            flagged += p.strays.runs.iter().filter(|&&r| r).count();
            let mut full = p.copy_state();
            assert!(full.strays.runs.is_empty());
            let before = p.len();
            p.remove_outside();
            full.remove_outside();
            removed += before - p.len();
            let columns = |q: &FilamentPlume| {
                (0..q.len())
                    .map(|k| {
                        [q.x[k], q.y[k], q.z[k]]
                            .map(|v| u64::from(v.to_bits()))
                            .into_iter()
                            .chain([q.birth_s[k], q.mass[k]].map(f64::to_bits))
                            .collect::<Vec<_>>()
                    })
                    .zip(q.key.iter().copied())
                    .collect::<Vec<_>>()
            };
            let (kept, all) = (columns(&p), columns(&full));
            let first = kept.iter().zip(&all).position(|(a, b)| a != b);
            assert!(
                kept.len() == all.len() && first.is_none(),
                "step {k}: {} filaments kept against {}, first difference at {first:?}",
                kept.len(),
                all.len()
            );
            assert_eq!(p.stats(), full.stats(), "step {k}");
        }
        let stats = p.stats();
        assert!(stats.exited == 400 && stats.dropped > 2_000, "{stats:?}");
        assert!(removed > 2_400 && flagged > 400, "{removed} {flagged}");
    }

    #[test]
    fn every_vector_unit_scans_as_a_plain_loop_over_every_filament() {
        // 1,031 filaments (a partial last block) spread over a 100 m square at several ages,
        // some NaN: on every vector unit, at points on and off the plume, the scan (boxes,
        // then the filaments' test in lanes) gives bit for bit the sum of every filament in
        // order, each tested on its own.
        use rand::Rng;
        let mut rng = stream_rng(5, StreamId::Plume);
        let params = FilamentParams {
            vertical: VerticalBoundary::Reflecting {
                depth_m: Some(12.0),
            },
            ..FilamentParams::default()
        };
        let mut p = plume_with_source(square(), (50.0, 50.0), 1.0, params);
        p.release_at_source(0, 1031);
        p.time_s = 600.0;
        for k in 0..p.len() {
            // Clusters 20 m wide, so that some blocks are near a point and others not.
            let centre = (k / 64 % 4) as f64 * 25.0 + 10.0;
            p.x[k] = (centre + rng.random::<f64>() * 20.0 - p.origin[0]) as f32;
            p.y[k] = (centre + rng.random::<f64>() * 20.0 - p.origin[1]) as f32;
            p.z[k] = (rng.random::<f64>() * 3.0) as f32;
            p.birth_s[k] = rng.random::<f64>() * 600.0;
            p.mass[k] = 1.0 + rng.random::<f64>();
            if k % 97 == 13 {
                p.x[k] = f32::NAN;
            }
        }
        p.boxes = OnceLock::new();
        let terms = p.scan_terms();
        let mut reached = 0;
        for i in 0..60 {
            let q = Vec3::new(
                rng.random::<f64>() * 100.0,
                rng.random::<f64>() * 100.0,
                if i % 3 == 0 { 0.5 } else { 2.0 },
            );
            // `add_filament` takes the point from the origin, as the scan gives it.
            let measured_from_origin = p.measured_from_origin(q);
            let plain = (0..p.len()).fold(0.0, |c, k| {
                p.add_filament(measured_from_origin, k, c, &terms)
            });
            reached += usize::from(plain > 0.0);
            for arch in crate::simd::every() {
                let scanned = arch.dispatch(Scan { plume: &p, p: q });
                assert_eq!(scanned.to_bits(), plain.to_bits(), "{arch:?} at {q:?}");
            }
            assert_eq!(p.concentration_full_scan(q).to_bits(), plain.to_bits());
        }
        assert!(
            reached > 10 && reached < 60,
            "{reached} of 60 points reached"
        );
    }

    #[test]
    fn every_vector_unit_boxes_the_blocks_as_a_plain_loop() {
        use rand::Rng;
        let mut rng = stream_rng(17, StreamId::Plume);
        // Lengths short of a vector, of a block, and with a partial last block; every column
        // with zeros, infinities and NaN among its values (a NaN is passed over, as
        // `f64::min` does).
        for n in [1_usize, 7, 64, 65, 200, 1031] {
            // Special values at several places in a block (in its vectors and in its tail),
            // the others so drawn that zeros are a block's least or greatest in some blocks.
            let mut column = |shift: usize| -> Vec<f64> {
                (0..n)
                    .map(|k| match ((k + shift) % 300, (k + shift) % 37) {
                        (150, _) => f64::INFINITY,
                        (250, _) => f64::NEG_INFINITY,
                        (_, 3 | 30) => f64::NAN,
                        (_, 5) => -0.0,
                        (_, 6) => 0.0,
                        _ if k % 128 < 64 => rng.random::<f64>() * 1000.0,
                        _ => -rng.random::<f64>() * 1000.0,
                    })
                    .collect()
            };
            let single = |v: Vec<f64>| -> Vec<f32> { v.into_iter().map(|v| v as f32).collect() };
            let (x, y, birth_s) = (single(column(0)), single(column(9)), column(20));
            let plain: Vec<BlockBox> = (0..n.div_ceil(SCAN_BLOCK))
                .map(|b| {
                    let mut bb = BlockBox::EMPTY;
                    for k in b * SCAN_BLOCK..((b + 1) * SCAN_BLOCK).min(n) {
                        bb.x_min = bb.x_min.min(f64::from(x[k]));
                        bb.x_max = bb.x_max.max(f64::from(x[k]));
                        bb.y_min = bb.y_min.min(f64::from(y[k]));
                        bb.y_max = bb.y_max.max(f64::from(y[k]));
                        bb.birth_min_s = bb.birth_min_s.min(birth_s[k]);
                    }
                    bb
                })
                .collect();
            for arch in crate::simd::every() {
                let boxes = arch.dispatch(BlockBoxes {
                    x: &x,
                    y: &y,
                    birth_s: &birth_s,
                });
                assert_eq!(boxes.len(), plain.len());
                for (b, p) in boxes.iter().zip(&plain) {
                    // Equal as numbers (a zero's sign may differ; the scan's test reads it
                    // either way alike).
                    let same = [
                        (b.x_min, p.x_min),
                        (b.x_max, p.x_max),
                        (b.y_min, p.y_min),
                        (b.y_max, p.y_max),
                        (b.birth_min_s, p.birth_min_s),
                    ]
                    .iter()
                    .all(|(u, v)| u == v);
                    assert!(same, "{arch:?}, {n} filaments: {b:?} against {p:?}");
                }
            }
        }
    }

    #[test]
    fn every_vector_unit_steps_the_filaments_to_the_same_bits() {
        // A Farrell flow across a 200 m square, a shallow water column (the filaments reflect
        // at both the seabed and the surface) and a sink, so that every branch of the
        // step is taken; then one more step on each vector unit this CPU has.
        let region = Rect::new(0.0, 200.0, -100.0, 100.0).unwrap_or_else(|e| panic!("{e}"));
        let dt = 0.2;
        let mut flow = farrell_toward_80(region, 0.5, dt);
        let params = FilamentParams {
            vertical: VerticalBoundary::Reflecting { depth_m: Some(3.0) },
            ..FilamentParams::default()
        };
        let mut plume = plume_with_source(region, (10.0, 0.0), 40.0, params);
        plume.set_key_seed(7);
        let mut flow_rng = stream_rng(7, StreamId::Flow);
        let mut rng = stream_rng(7, StreamId::Plume);
        for k in 1..=600u32 {
            let t = f64::from(k) * dt;
            flow.advance(t, dt, &mut flow_rng)
                .unwrap_or_else(|e| panic!("{e}"));
            plume.step(&flow, t, dt, &mut rng);
        }
        // The sink set now, so that none has been dropped yet.
        plume.set_sink(Some(DownflowSink {
            dir: [1.0, 0.0],
            beyond_m: 30.0,
        }));
        // Several chunks of 256, the last one partial.
        assert!(
            plume.len() > 600 && !plume.len().is_multiple_of(256),
            "{} filaments",
            plume.len()
        );
        let bits = |p: &FilamentPlume| -> Vec<[u32; 3]> {
            (0..p.len())
                .map(|k| [p.x[k].to_bits(), p.y[k].to_bits(), p.z[k].to_bits()])
                .collect()
        };
        let mut reference = None;
        for arch in crate::simd::every() {
            let mut p = plume.copy_state();
            let out = p.transport_on(arch, &flow, dt);
            let got = (out, bits(&p));
            match &reference {
                None => {
                    // The step moved the filaments and found some beyond the sink.
                    assert_ne!(got.1, bits(&plume));
                    assert!(out.1 > 0, "{out:?}");
                    reference = Some(got);
                }
                Some(r) => assert!(*r == got, "{arch:?} differs from the portable version"),
            }
        }
        // Where the CPU has AVX2 and FMA, more than the portable version was compared.
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            assert!(crate::simd::every().len() >= 2);
        }
    }
}
