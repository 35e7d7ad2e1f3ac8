//! Plume runs: the environment of a scenario without vehicles stepped to its end, writing a
//! concentration snapshot, the time-averaged concentration and intermittency, the final
//! filaments and statistics, and when `[output]` asks for them the probe series and filament
//! snapshots ([`series`]; with the `netcdf` feature also `plume.nc`, module `netcdf`). The
//! figure is drawn by the caller ([`PlumeFigure`]).

#[cfg(feature = "netcdf")]
pub mod netcdf;
mod run;
pub mod series;

pub use run::{FigureError, PlumeFigure, PlumeRunError, PlumeRunStats, run_plume};
pub use series::{FilamentSeries, ProbeSeries, SeriesError, time_decimals};
