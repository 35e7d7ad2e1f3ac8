"""`plumetrace.Plume`: stepping and querying a plume from Python gives the Rust results."""

import tomllib

import numpy as np
import pytest

import plumetrace
from conftest import REPO, run_cli


def test_the_grid_query_equals_the_command_lines_snapshot(cli, tmp_path):
    spec = tomllib.loads((REPO / "crates/plumetrace-scenario/presets/plume-demo.toml").read_text())
    run_cli(cli, "run", "--preset", "plume-demo", "--out", str(tmp_path))
    snap = np.genfromtxt(tmp_path / "snapshot.csv", delimiter=",", names=True)
    p = plumetrace.Plume("plume-demo")
    steps = round(spec["sim"]["duration_s"] / spec["sim"]["dt_s"])
    p.step(steps)
    o = spec["output"]
    # The grid spans the domain (its edges are round numbers, printed exactly).
    x = np.linspace(snap["x_m"].min(), snap["x_m"].max(), o["nx"])
    y = np.linspace(snap["y_m"].min(), snap["y_m"].max(), o["ny"])
    grid = p.concentration_grid(x, y, o["z_m"])
    assert grid.shape == (o["ny"], o["nx"])
    assert grid.size > 10_000
    cli_c = snap["concentration"].reshape(o["ny"], o["nx"])
    assert np.count_nonzero(cli_c) > 100
    # snapshot.csv prints 7 significant digits.
    assert np.allclose(grid, cli_c, rtol=1e-6, atol=1e-300)


def test_a_batch_of_10000_points_equals_the_points_one_by_one():
    p = plumetrace.Plume("plume-demo")
    p.step(3000)
    rng = np.random.default_rng(5)
    x0, x1, y0, y1 = p.domain
    pts = np.column_stack([
        rng.uniform(x0, min(x1, x0 + 150.0), 10_000),
        rng.uniform(-15.0, 15.0, 10_000),
        rng.uniform(0.0, 4.0, 10_000),
    ])
    batch = p.concentrations(pts)
    assert batch.shape == (10_000,)
    assert np.count_nonzero(batch) > 500
    one = np.array([p.concentrations(pts[i:i + 1])[0] for i in range(0, 10_000, 50)])
    assert np.array_equal(batch[::50], one)


def test_filaments_flow_and_maps():
    p = plumetrace.Plume("plume-demo", seed=3)
    p.spin_up(120.0)
    f = p.filaments()
    assert f.ndim == 2 and f.shape[1] == 4 and len(f) == p.stats()["live"] > 0
    assert np.all(f[:, 3] > 0)
    u = p.flow(np.array([[10.0, 0.0], [50.0, 5.0]]))
    assert u.shape == (2, 2) and np.all(np.isfinite(u))
    x = np.linspace(0.0, 100.0, 21)
    y = np.linspace(-20.0, 20.0, 9)
    mean, inter = p.mean_maps(x, y, 2.0, duration_s=60.0, every_s=1.0)
    assert mean.shape == inter.shape == (9, 21)
    assert mean.max() > 0 and 0 <= inter.min() and inter.max() <= 1
    assert p.time_s == pytest.approx(180.0)


def test_the_same_seed_gives_the_same_plume():
    a = plumetrace.Plume("plume-demo", seed=9)
    b = plumetrace.Plume("plume-demo", seed=9)
    a.step(500)
    b.step(500)
    assert np.array_equal(a.filaments(), b.filaments())


@pytest.mark.parametrize(
    "points, words",
    [
        (np.zeros((4, 4)), ["(N, 3)", "(N, 2)", "not (4, 4)"]),
        (np.zeros(5), ["(3,)", "not (5,)"]),
        (7.0, ["(3,)", "not ()"]),
        ([[0.0, 1.0, 2.0], [1.0]], ["points is not an array of numbers"]),
        (np.array([[0.0, np.nan, 1.0]]), ["points[0]", "not finite"]),
    ],
)
def test_bad_points_are_refused(points, words):
    p = plumetrace.Plume("plume-demo")
    with pytest.raises(plumetrace.PlumetraceError) as e:
        p.concentrations(points)
    for w in words:
        assert w in str(e.value)
