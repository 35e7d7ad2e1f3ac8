//! Benchmarks of plumetrace, each a function from plain options to a serialisable result (the
//! `plumetrace bench` subcommands print them as JSON):
//!
//! - [`plume()`]: the filament plume's cost per filament-step and per point query
//!   ([`plume`](mod@plume));
//! - [`missions()`]: missions per second of a mission preset on several thread counts;
//! - [`map()`]: the source-likelihood map's update at an op-area's size;
//! - [`raster()`]: the display rasters a run draws (the figure's averaged plume, the page's
//!   frames), per query;
//! - [`infotaxis()`]: infotaxis in the windy grid world of the published benchmark
//!   ([`gridworld`]).
//!
//! Times are CPU times of the process ([`cpu_time::ProcessTime`]) unless a field says wall time;
//! every other field depends on the options only.

mod error;
pub mod gridworld;
pub mod map;
pub mod missions;
pub mod plume;
pub mod raster;

pub use error::BenchError;
pub use gridworld::{InfotaxisBench, InfotaxisBenchOptions, Policy, infotaxis};
pub use map::{MapBench, MapBenchOptions, map};
pub use missions::{MissionBench, MissionBenchOptions, MissionBenchRow, StageSplit, missions};
pub use plume::{Case, PlumeBench, PlumeBenchOptions, plume};
pub use raster::{RasterBench, RasterBenchOptions, RasterGrid, raster};

/// The median of a list (NaN for an empty one).
pub(crate) fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_median_of_odd_even_and_empty_lists() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&[]).is_nan());
    }
}
