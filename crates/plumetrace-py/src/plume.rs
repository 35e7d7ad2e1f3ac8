//! `Plume`: a scenario's environment stepped and queried from Python, a drop-in for pompy's
//! simulator, array generator and statistics.
//!
//! Points are anything `numpy.asarray(x, float)` reads (lists, integer or float32 arrays) with
//! a last axis of 3 (x, y, z) or 2 (x, y at the scenario's output height `z_m`); the result has
//! the points' other axes (a single point gives a float). A `Plume` pickles as its recipe (the
//! scenario, the seed, the overrides) and the steps it has taken, and is re-created by replaying
//! them: the same bits, on any machine with the same package version.

use crate::error::{msg, to_py};
use crate::scenario::{Recipe, Source, overrides};
use numpy::ndarray::{Array1, Array2, ArrayD, IxDyn};
use numpy::{IntoPyArray, PyArray2, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use plumetrace_core::{Vec2, Vec3};
use plumetrace_env::{ConcentrationField, Environment, GridSpec, MeanConcentrationGrid};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use serde::{Deserialize, Serialize};

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
    output: plumetrace_scenario::OutputSpec,
    /// How to build it again (pickling).
    recipe: PlumeState,
}

/// What a pickled `Plume` holds: how it was built and what it did since.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct PlumeState {
    recipe: Recipe,
    seed: Option<u64>,
    overrides: Vec<(String, toml::Value)>,
    ops: Vec<Op>,
}

/// A call that moved the plume on.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
enum Op {
    /// `n` steps of the scenario's step.
    Steps(u64),
    /// `spin_up(duration_s, dt_s)`.
    SpinUp(f64, f64),
}

/// `obj` as a float64 array, as `numpy.asarray(obj, float)` reads it.
fn float_array<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let py = obj.py();
    let kw = PyDict::new(py);
    kw.set_item("dtype", "float64")?;
    let a = py
        .import("numpy")?
        .getattr("asarray")?
        .call((obj,), Some(&kw))
        .map_err(|e| msg(format!("{what} is not an array of numbers: {e}")))?;
    a.cast_into::<PyArrayDyn<f64>>()
        .map_err(|e| msg(format!("{what}: {e}")))
}

/// Points from anything array-like with a last axis of 3 (x, y, z) or 2 (x, y at `z_m`), and
/// the shape of the other axes (empty for a single point).
fn points(obj: &Bound<'_, PyAny>, what: &str, z_m: f64) -> PyResult<(Vec<Vec3>, Vec<usize>)> {
    let a = float_array(obj, what)?;
    let shape = a.shape().to_vec();
    let Some((&last, lead)) = shape.split_last().filter(|(l, _)| **l == 2 || **l == 3) else {
        return Err(msg(format!(
            "{what} must have shape (3,) or (N, 3) for x, y, z in metres, or (N, 2) for x, y at \
             the output height z_m = {z_m} m (any leading axes), not {}",
            shape_text(&shape)
        )));
    };
    let n: usize = lead.iter().product();
    if n > MAX_POINTS {
        return Err(msg(format!(
            "{what}: {n} points is above the limit of {MAX_POINTS}"
        )));
    }
    let ro = a.readonly();
    let flat: Vec<f64> = ro.as_array().iter().copied().collect();
    let mut out = Vec::with_capacity(n);
    for (i, row) in flat.chunks(last).enumerate() {
        let p = Vec3::new(row[0], row[1], if last == 3 { row[2] } else { z_m });
        if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
            return Err(msg(format!(
                "{what}[{i}] = ({}, {}, {}) is not finite",
                p.x, p.y, p.z
            )));
        }
        out.push(p);
    }
    Ok((out, lead.to_vec()))
}

/// A shape as Python prints it.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// Values laid out in `lead` (a float when `lead` is empty).
fn shaped<'py>(py: Python<'py>, values: Vec<f64>, lead: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    if lead.is_empty() {
        return Ok(values
            .first()
            .copied()
            .unwrap_or(0.0)
            .into_pyobject(py)?
            .into_any());
    }
    let a = ArrayD::from_shape_vec(IxDyn(lead), values).map_err(|e| msg(e.to_string()))?;
    Ok(a.into_pyarray(py).into_any())
}

/// A 1-D axis of at least 2 finite values.
fn axis(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    let v = values1(obj, what)?;
    if v.len() < 2 {
        return Err(msg(format!("{what} needs at least 2 values")));
    }
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(msg(format!("{what}[{i}] is not finite")));
    }
    Ok(v)
}

/// A 1-D array of values.
fn values1(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    let a = float_array(obj, what)?;
    if a.ndim() != 1 {
        return Err(msg(format!(
            "{what} must be 1-D, not of shape {}",
            shape_text(a.shape())
        )));
    }
    let ro = a.readonly();
    Ok(ro.as_array().iter().copied().collect())
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
        let state = PlumeState {
            recipe: source.recipe(),
            seed: crate::scenario::seed(seed)?,
            overrides: overrides(set, kwargs)?,
            ops: Vec::new(),
        };
        Plume::build(py, &source, state)
    }

    /// Height of the scenario's output grid, m: the height of points given as x, y only.
    #[getter]
    fn z_m(&self) -> f64 {
        self.output.grid.z_m
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
        let done = py.detach(|| {
            let mut done = 0;
            for _ in 0..n {
                if let Err(e) = env.step() {
                    return (done, Some(e));
                }
                done += 1;
            }
            (done, None)
        });
        self.record(Op::Steps(done.0));
        done.1.map_or(Ok(()), |e| Err(to_py(e)))
    }

    /// Develops the plume for `duration_s` in steps of `dt_s` (default the scenario's step).
    #[pyo3(signature = (duration_s, dt_s=None))]
    fn spin_up(&mut self, py: Python<'_>, duration_s: f64, dt_s: Option<f64>) -> PyResult<()> {
        let dt = dt_s.unwrap_or(self.env.dt_s());
        let env = &mut self.env;
        // Errors name the arguments as a scenario's [mission] keys, as they always have.
        py.detach(|| env.spin_up(duration_s, dt))
            .map_err(|e| to_py(e.under("mission")))?;
        self.record(Op::SpinUp(duration_s, dt));
        Ok(())
    }

    /// Concentrations at `points`: anything array-like of shape `(3,)`, `(N, 3)` (x, y, z in
    /// metres) or `(N, 2)` (x, y at height `z`, default `z_m`), any leading axes; the result has
    /// the points' shape without its last axis (a float for one point). Evaluated in parallel;
    /// the same at any thread count.
    #[pyo3(signature = (points, z=None))]
    fn concentrations<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        z: Option<f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (pts, lead) = self::points(points, "points", self.height(z)?)?;
        let mut out = vec![0.0; pts.len()];
        let plume = self.env.plume();
        py.detach(|| plume.concentrations(&pts, &mut out));
        shaped(py, out, &lead)
    }

    /// Concentrations on the grid `x` by `y` at height `z` (default `z_m`): an array of shape
    /// `(len(y), len(x))`, rows along y.
    #[pyo3(signature = (x, y, z=None))]
    fn concentration_grid<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
        y: &Bound<'py, PyAny>,
        z: Option<f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let xs = values1(x, "x")?;
        let ys = values1(y, "y")?;
        let pts = grid_points(&xs, &ys, self.height(z)?)?;
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

    /// The flow at `points` (x, y, as for `concentrations`; a z column is ignored): east and
    /// north velocity, m/s, of shape `points.shape[:-1] + (2,)`.
    fn flow<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (pts, lead) = self::points(points, "points", self.output.grid.z_m)?;
        let mut flat = Vec::with_capacity(pts.len() * 2);
        for p in &pts {
            let u = self.env.flow_at(Vec2::new(p.x, p.y));
            flat.extend_from_slice(&[u.x, u.y]);
        }
        let mut shape = lead;
        shape.push(2);
        let a = ArrayD::from_shape_vec(IxDyn(&shape), flat).map_err(|e| msg(e.to_string()))?;
        Ok(a.into_pyarray(py).into_any())
    }

    /// Steps for `duration_s`, sampling the grid `x` by `y` at height `z` every `every_s`;
    /// returns `(mean, intermittency)`, each of shape `(len(y), len(x))`. Intermittency is the
    /// fraction of samples above `threshold` (default the scenario's `output.threshold`).
    #[pyo3(signature = (x, y, z, duration_s, every_s, threshold=None))]
    #[allow(clippy::too_many_arguments)]
    fn mean_maps<'py>(
        &mut self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
        y: &Bound<'py, PyAny>,
        z: f64,
        duration_s: f64,
        every_s: f64,
        threshold: Option<f64>,
    ) -> PyResult<Maps<'py>> {
        let xs = axis(x, "x")?;
        let ys = axis(y, "y")?;
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
        let (done, grid) = py.detach(|| {
            let mut grid = MeanConcentrationGrid::new(spec, threshold);
            for k in 1..=steps {
                if let Err(e) = env.step() {
                    return (k - 1, Err(e));
                }
                if k % every == 0 {
                    grid.accumulate(env.plume());
                }
            }
            if grid.samples() == 0 {
                grid.accumulate(env.plume());
            }
            (steps, Ok(grid))
        });
        self.record(Op::Steps(done));
        let grid = grid.map_err(to_py)?;
        let shape = (ys.len(), xs.len());
        let mean = Array2::from_shape_vec(shape, grid.mean()).map_err(|e| msg(e.to_string()))?;
        let inter =
            Array2::from_shape_vec(shape, grid.intermittency()).map_err(|e| msg(e.to_string()))?;
        Ok((mean.into_pyarray(py), inter.into_pyarray(py)))
    }

    /// Steps for `duration_s`, sampling the concentration at `points` (as for `concentrations`;
    /// default the scenario's `[output]` probes) every `every_s` (default the scenario's probe
    /// interval, else the step). Returns a dict: `t_s` (shape `(T,)`), `concentration`
    /// (`(T, P)`) and `points` (`(P, 3)`).
    #[pyo3(signature = (duration_s, every_s=None, points=None))]
    fn probe_series<'py>(
        &mut self,
        py: Python<'py>,
        duration_s: f64,
        every_s: Option<f64>,
        points: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let dt = self.env.dt_s();
        let pts = match points {
            Some(p) => self::points(p, "points", self.output.grid.z_m)?.0,
            None => self.output.probes.clone(),
        };
        if pts.is_empty() {
            return Err(msg(
                "no points: give points=, or probes in the scenario's [output] table",
            ));
        }
        if !(duration_s.is_finite() && duration_s >= 0.0) {
            return Err(msg(format!("duration_s = {duration_s} must be >= 0")));
        }
        let every_s = every_s.unwrap_or(self.output.probe_every_steps.max(1) as f64 * dt);
        if !(every_s.is_finite() && every_s >= dt) {
            return Err(msg(format!(
                "every_s = {every_s} must be at least the step ({dt} s)"
            )));
        }
        let steps = (duration_s / dt).round() as u64;
        let every = (every_s / dt).round().max(1.0) as u64;
        let env = &mut self.env;
        let (done, series) = py.detach(|| {
            let (mut t, mut c) = (Vec::new(), Vec::new());
            let mut row = vec![0.0; pts.len()];
            for k in 1..=steps {
                if let Err(e) = env.step() {
                    return (k - 1, Err(e));
                }
                if k % every == 0 {
                    env.plume().concentrations(&pts, &mut row);
                    t.push(env.elapsed_s());
                    c.extend_from_slice(&row);
                }
            }
            (steps, Ok((t, c)))
        });
        self.record(Op::Steps(done));
        let (t, c) = series.map_err(to_py)?;
        let n = t.len();
        let d = PyDict::new(py);
        d.set_item("t_s", Array1::from(t).into_pyarray(py))?;
        let c = Array2::from_shape_vec((n, pts.len()), c).map_err(|e| msg(e.to_string()))?;
        d.set_item("concentration", c.into_pyarray(py))?;
        let flat: Vec<f64> = pts.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
        let p = Array2::from_shape_vec((pts.len(), 3), flat).map_err(|e| msg(e.to_string()))?;
        d.set_item("points", p.into_pyarray(py))?;
        Ok(d)
    }

    /// Pickling: the recipe and the steps taken, replayed by `_plume_from_state`.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let state = serde_json::to_string(&self.recipe).map_err(|e| msg(e.to_string()))?;
        let f = py
            .import("plumetrace._plumetrace")?
            .getattr("_plume_from_state")?;
        Ok((f, PyTuple::new(py, [state])?))
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

impl Plume {
    /// Builds the plume of `state`'s recipe and replays its steps.
    fn build(py: Python<'_>, source: &Source, state: PlumeState) -> PyResult<Self> {
        let sc = py.detach(|| source.build(state.seed, &state.overrides))?;
        let mut p = Plume {
            threshold: sc.output.threshold,
            output: sc.output,
            name: sc.name,
            seed: sc.seed,
            env: sc.env,
            recipe: PlumeState {
                ops: Vec::new(),
                ..state.clone()
            },
        };
        let env = &mut p.env;
        py.detach(|| {
            for op in &state.ops {
                match *op {
                    Op::Steps(n) => {
                        for _ in 0..n {
                            env.step().map_err(|e| crate::error::located(&e))?;
                        }
                    }
                    Op::SpinUp(d, dt) => {
                        env.spin_up(d, dt).map_err(|e| crate::error::located(&e))?
                    }
                }
            }
            Ok::<(), String>(())
        })
        .map_err(|e| msg(format!("re-creating the plume: {e}")))?;
        p.recipe.ops = state.ops;
        Ok(p)
    }

    /// Notes a call that moved the plume on (consecutive steps merge).
    fn record(&mut self, op: Op) {
        match (self.recipe.ops.last_mut(), op) {
            (_, Op::Steps(0)) => {}
            (Some(Op::Steps(n)), Op::Steps(m)) => *n += m,
            _ => self.recipe.ops.push(op),
        }
    }

    /// The height of points given as x, y.
    fn height(&self, z: Option<f64>) -> PyResult<f64> {
        let z = z.unwrap_or(self.output.grid.z_m);
        if !z.is_finite() {
            return Err(msg(format!("z = {z} is not finite")));
        }
        Ok(z)
    }
}

/// A pickled `Plume` re-created: its recipe built and its steps replayed.
#[pyfunction]
pub fn _plume_from_state(py: Python<'_>, state: &str) -> PyResult<Plume> {
    let state: PlumeState =
        serde_json::from_str(state).map_err(|e| msg(format!("a pickled Plume: {e}")))?;
    let source = Source::from_recipe(&state.recipe)?;
    Plume::build(py, &source, state)
}
