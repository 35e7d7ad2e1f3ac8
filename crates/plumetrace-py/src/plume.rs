//! `Plume`: a scenario's environment stepped and queried from Python, a drop-in for pompy's
//! simulator, array generator and statistics.

use crate::error::{msg, to_py};
use crate::scenario::{Source, overrides};
use numpy::ndarray::{Array1, Array2};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods,
};
use plumetrace_core::{Vec2, Vec3};
use plumetrace_env::{ConcentrationField, Environment, GridSpec, MeanConcentrationGrid};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The mean and intermittency maps.
type Maps<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// At most this many points per query (a 4,000 x 4,000 grid).
const MAX_POINTS: usize = 16_000_000;

/// The flow and plume of a scenario (a plume scenario, or a mission scenario's environment
/// without its vehicles), stepped on the scenario's `dt_s`.
#[pyclass(module = "plumetrace._plumetrace")]
pub struct Plume {
    env: Environment,
    name: String,
    seed: u64,
    threshold: f64,
}

fn points3(a: &PyReadonlyArray2<'_, f64>, what: &str) -> PyResult<Vec<Vec3>> {
    let shape = a.shape();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(msg(format!(
            "{what} must have shape (N, 3) (x, y, z in metres), not {shape:?}"
        )));
    }
    if shape[0] > MAX_POINTS {
        return Err(msg(format!(
            "{what}: {} points is above the limit of {MAX_POINTS}",
            shape[0]
        )));
    }
    let v = a.as_array();
    let mut out = Vec::with_capacity(shape[0]);
    for (i, row) in v.outer_iter().enumerate() {
        let p = Vec3::new(row[0], row[1], row[2]);
        if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
            return Err(msg(format!("{what}[{i}] = {p:?} is not finite")));
        }
        out.push(p);
    }
    Ok(out)
}

fn axis(a: &PyReadonlyArray1<'_, f64>, what: &str) -> PyResult<Vec<f64>> {
    let v: Vec<f64> = a.as_array().iter().copied().collect();
    if v.len() < 2 {
        return Err(msg(format!("{what} needs at least 2 values")));
    }
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(msg(format!("{what}[{i}] is not finite")));
    }
    Ok(v)
}

fn grid_points(x: &[f64], y: &[f64], z: f64) -> PyResult<Vec<Vec3>> {
    if x.len() * y.len() > MAX_POINTS {
        return Err(msg(format!(
            "a {} x {} grid is above the limit of {MAX_POINTS} points",
            x.len(),
            y.len()
        )));
    }
    if !z.is_finite() {
        return Err(msg(format!("z = {z} is not finite")));
    }
    let mut pts = Vec::with_capacity(x.len() * y.len());
    for &yj in y {
        for &xi in x {
            pts.push(Vec3::new(xi, yj, z));
        }
    }
    Ok(pts)
}

#[pymethods]
impl Plume {
    /// Builds the environment of `scenario` (a preset name or a scenario file), with `seed`
    /// and overrides as for `run`. The plume starts empty at t = 0; call `spin_up` or `step`.
    #[new]
    #[pyo3(signature = (scenario, seed=None, set=None, **kwargs))]
    fn new(
        py: Python<'_>,
        scenario: &str,
        seed: Option<&Bound<'_, PyAny>>,
        set: Option<&Bound<'_, PyDict>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let source = Source::open(scenario)?;
        let seed = crate::scenario::seed(seed)?;
        let ov = overrides(set, kwargs)?;
        let sc = py.detach(|| source.build(seed, &ov))?;
        Ok(Plume {
            threshold: sc.output.threshold,
            name: sc.name,
            seed: sc.seed,
            env: sc.env,
        })
    }

    /// Scenario name.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// Run seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.seed
    }

    /// Simulated time since the start (spin-up included), s.
    #[getter]
    fn time_s(&self) -> f64 {
        self.env.elapsed_s()
    }

    /// The step, s.
    #[getter]
    fn dt_s(&self) -> f64 {
        self.env.dt_s()
    }

    /// The domain `(x_min, x_max, y_min, y_max)`, m.
    #[getter]
    fn domain(&self) -> (f64, f64, f64, f64) {
        let d = self.env.domain();
        (d.x_min_m, d.x_max_m, d.y_min_m, d.y_max_m)
    }

    /// Advances `n` steps of `dt_s`.
    #[pyo3(signature = (n=1))]
    fn step(&mut self, py: Python<'_>, n: u64) -> PyResult<()> {
        let env = &mut self.env;
        py.detach(|| {
            for _ in 0..n {
                env.step()?;
            }
            Ok::<(), plumetrace_env::EnvError>(())
        })
        .map_err(to_py)
    }

    /// Develops the plume for `duration_s` in steps of `dt_s` (default the scenario's step).
    #[pyo3(signature = (duration_s, dt_s=None))]
    fn spin_up(&mut self, py: Python<'_>, duration_s: f64, dt_s: Option<f64>) -> PyResult<()> {
        let dt = dt_s.unwrap_or(self.env.dt_s());
        let env = &mut self.env;
        // Errors name the arguments as a scenario's [mission] keys, as they always have.
        py.detach(|| env.spin_up(duration_s, dt))
            .map_err(|e| to_py(e.under("mission")))
    }

    /// Concentrations at `points` (an `(N, 3)` array of x, y, z in metres), evaluated in
    /// parallel; the same at any thread count.
    fn concentrations<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let pts = points3(&points, "points")?;
        let mut out = vec![0.0; pts.len()];
        let plume = self.env.plume();
        py.detach(|| plume.concentrations(&pts, &mut out));
        Ok(Array1::from(out).into_pyarray(py))
    }

    /// Concentrations on the grid `x` by `y` at height `z` (an array of shape
    /// `(len(y), len(x))`, rows along y).
    fn concentration_grid<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, f64>,
        y: PyReadonlyArray1<'py, f64>,
        z: f64,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let xs: Vec<f64> = x.as_array().iter().copied().collect();
        let ys: Vec<f64> = y.as_array().iter().copied().collect();
        let pts = grid_points(&xs, &ys, z)?;
        let mut out = vec![0.0; pts.len()];
        let plume = self.env.plume();
        py.detach(|| plume.concentrations(&pts, &mut out));
        let a =
            Array2::from_shape_vec((ys.len(), xs.len()), out).map_err(|e| msg(e.to_string()))?;
        Ok(a.into_pyarray(py))
    }

    /// The live filaments as an `(N, 4)` array: x, y, z (m) and radius (m); empty for a
    /// steady plume.
    fn filaments<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let mut flat = Vec::new();
        if let Some(f) = self.env.plume().filaments() {
            for (p, r2) in f.filaments() {
                flat.extend_from_slice(&[p.x, p.y, p.z, r2.sqrt()]);
            }
        }
        let n = flat.len() / 4;
        let a = Array2::from_shape_vec((n, 4), flat).map_err(|e| msg(e.to_string()))?;
        Ok(a.into_pyarray(py))
    }

    /// The flow at `points` (an `(N, 2)` array of x, y), as an `(N, 2)` array of east and
    /// north velocity, m/s.
    fn flow<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let shape = points.shape();
        if shape.len() != 2 || shape[1] != 2 {
            return Err(msg(format!(
                "points must have shape (N, 2) (x, y in metres), not {shape:?}"
            )));
        }
        let v = points.as_array();
        let mut flat = Vec::with_capacity(shape[0] * 2);
        for (i, row) in v.outer_iter().enumerate() {
            if !(row[0].is_finite() && row[1].is_finite()) {
                return Err(msg(format!("points[{i}] is not finite")));
            }
            let u = self.env.flow_at(Vec2::new(row[0], row[1]));
            flat.extend_from_slice(&[u.x, u.y]);
        }
        let a = Array2::from_shape_vec((shape[0], 2), flat).map_err(|e| msg(e.to_string()))?;
        Ok(a.into_pyarray(py))
    }

    /// Steps for `duration_s`, sampling the grid `x` by `y` at height `z` every `every_s`;
    /// returns `(mean, intermittency)`, each of shape `(len(y), len(x))`. Intermittency is the
    /// fraction of samples above `threshold` (default the scenario's `output.threshold`).
    #[pyo3(signature = (x, y, z, duration_s, every_s, threshold=None))]
    #[allow(clippy::too_many_arguments)]
    fn mean_maps<'py>(
        &mut self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, f64>,
        y: PyReadonlyArray1<'py, f64>,
        z: f64,
        duration_s: f64,
        every_s: f64,
        threshold: Option<f64>,
    ) -> PyResult<Maps<'py>> {
        let xs = axis(&x, "x")?;
        let ys = axis(&y, "y")?;
        let dt = self.env.dt_s();
        if !(duration_s.is_finite() && duration_s >= 0.0) {
            return Err(msg(format!("duration_s = {duration_s} must be >= 0")));
        }
        if !(every_s.is_finite() && every_s >= dt) {
            return Err(msg(format!(
                "every_s = {every_s} must be at least the step ({dt} s)"
            )));
        }
        let regular = |v: &[f64]| {
            let d = (v[v.len() - 1] - v[0]) / (v.len() - 1) as f64;
            d > 0.0
                && v.windows(2)
                    .all(|w| ((w[1] - w[0]) - d).abs() <= 1e-9 * d.abs().max(1.0))
        };
        if !regular(&xs) || !regular(&ys) {
            return Err(msg(
                "x and y must be increasing and evenly spaced (e.g. numpy.linspace)".to_string(),
            ));
        }
        let spec = GridSpec {
            x_min_m: xs[0],
            x_max_m: xs[xs.len() - 1],
            y_min_m: ys[0],
            y_max_m: ys[ys.len() - 1],
            nx: xs.len(),
            ny: ys.len(),
            z_m: z,
        };
        spec.validate().map_err(|e| to_py(e.under("grid")))?;
        let threshold = threshold.unwrap_or(self.threshold);
        let steps = (duration_s / dt).round() as u64;
        let every = (every_s / dt).round().max(1.0) as u64;
        let env = &mut self.env;
        let grid = py
            .detach(|| {
                let mut grid = MeanConcentrationGrid::new(spec, threshold);
                for k in 1..=steps {
                    env.step()?;
                    if k % every == 0 {
                        grid.accumulate(env.plume());
                    }
                }
                if grid.samples() == 0 {
                    grid.accumulate(env.plume());
                }
                Ok::<_, plumetrace_env::EnvError>(grid)
            })
            .map_err(to_py)?;
        let shape = (ys.len(), xs.len());
        let mean = Array2::from_shape_vec(shape, grid.mean()).map_err(|e| msg(e.to_string()))?;
        let inter =
            Array2::from_shape_vec(shape, grid.intermittency()).map_err(|e| msg(e.to_string()))?;
        Ok((mean.into_pyarray(py), inter.into_pyarray(py)))
    }

    /// Filament statistics: live, released, exited, dropped (beyond a mission's downflow sink),
    /// suppressed (a filament plume), or an empty dict (a steady plume).
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        if let Some(f) = self.env.plume().filaments() {
            let s = f.stats();
            d.set_item("live", s.live)?;
            d.set_item("released", s.released)?;
            d.set_item("released_mass", s.released_mass)?;
            d.set_item("exited", s.exited)?;
            d.set_item("exited_mass", s.exited_mass)?;
            d.set_item("dropped", s.dropped)?;
            d.set_item("dropped_mass", s.dropped_mass)?;
            d.set_item("suppressed", s.suppressed)?;
        }
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "Plume('{}', seed={}, t={:.1} s)",
            self.name,
            self.seed,
            self.env.elapsed_s()
        )
    }
}
