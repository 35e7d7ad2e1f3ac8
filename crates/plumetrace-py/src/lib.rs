//! Python bindings of plumetrace: the `plumetrace._plumetrace` extension module.
//!
//! The Python package (`python/plumetrace`) wraps these functions in a friendlier surface
//! (result objects, DataFrames, progress bars, the Gymnasium environment). Everything long
//! (missions, plume steps, campaigns, environment steps) runs with the interpreter detached, so
//! other Python threads go on meanwhile.

mod benchmark;
mod campaign;
mod error;
mod gym;
mod gym_vec;
mod planner;
mod plume;
mod run;
mod scenario;

use pyo3::prelude::*;

/// The extension module.
#[pymodule]
fn _plumetrace(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add(
        "PlumetraceError",
        m.py().get_type::<error::PlumetraceError>(),
    )?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(run::presets, m)?)?;
    m.add_function(wrap_pyfunction!(run::planners, m)?)?;
    m.add_function(wrap_pyfunction!(run::run_plume, m)?)?;
    m.add_function(wrap_pyfunction!(run::scenario_kind, m)?)?;
    m.add_function(wrap_pyfunction!(run::derive_seed, m)?)?;
    m.add_function(wrap_pyfunction!(plume::_plume_from_state, m)?)?;
    m.add_class::<run::RunRecord>()?;
    m.add_function(wrap_pyfunction!(benchmark::benchmark, m)?)?;
    m.add_function(wrap_pyfunction!(campaign::campaign, m)?)?;
    m.add_function(wrap_pyfunction!(campaign::merge, m)?)?;
    m.add_function(wrap_pyfunction!(campaign::run_columns, m)?)?;
    m.add_class::<plume::Plume>()?;
    m.add_class::<gym::EnvCore>()?;
    m.add_class::<gym::ObsCore>()?;
    m.add_class::<gym_vec::VecEnvCore>()?;
    Ok(())
}
