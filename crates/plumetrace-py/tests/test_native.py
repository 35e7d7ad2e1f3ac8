"""The package behaves as Python users expect: array arguments as numpy reads them, settings
checked at `gym.make`, episodes that say why they ended, runs saved as the command line writes
them, a namespace of its API only, `python -m plumetrace`, campaign tables with one schema
whatever the file, a picklable `Plume` and plume-only runs."""

import json
import pickle
import subprocess
import sys

import numpy as np
import pytest

import plumetrace
from conftest import REPO, run_cli

WALL = ("wall_s", "real_time_factor", "spinup_wall_s", "stage_times")


# 1. Array arguments


@pytest.fixture(scope="module")
def plume():
    p = plumetrace.Plume("plume-demo", seed=3)
    p.step(300)
    return p


def test_points_are_anything_numpy_reads(plume):
    pts = plume.filaments()[:4, :3]  # filament centres: concentrations above zero
    want = plume.concentrations(pts)
    assert want.shape == (4,) and want.min() > 0
    assert np.array_equal(plume.concentrations(pts.tolist()), want)
    f32 = pts.astype(np.float32)
    assert np.array_equal(plume.concentrations(f32), plume.concentrations(f32.astype(float)))
    ints = np.round(pts).astype(int)
    assert np.array_equal(plume.concentrations(ints), plume.concentrations(ints.astype(float)))
    one = plume.concentrations(list(pts[0]))
    assert isinstance(one, float) and one == want[0]
    assert plume.concentrations(pts.reshape(2, 2, 3)).shape == (2, 2)


def test_points_without_z_are_at_the_output_height(plume):
    xy = plume.filaments()[:5, :2]
    at_z = np.column_stack([xy, np.full(len(xy), plume.z_m)])
    assert np.array_equal(plume.concentrations(xy), plume.concentrations(at_z))
    at_2 = np.column_stack([xy, np.full(len(xy), 2.0)])
    assert np.array_equal(plume.concentrations(xy, z=2.0), plume.concentrations(at_2))
    assert plume.flow([[0, 0], [10, 5]]).shape == (2, 2)
    assert plume.flow([0, 0, 1]).shape == (2,)
    assert plume.concentration_grid([0, 10, 20], range(-5, 6, 5)).shape == (3, 3)


# 2 and 3. The Gymnasium environment


def test_a_typo_in_a_setting_fails_at_make_naming_the_setting():
    gym = pytest.importorskip("gymnasium")
    import plumetrace.gym  # noqa: F401

    with pytest.raises(plumetrace.PlumetraceError) as e:
        gym.make("plumetrace/PlumeTracing-v1", scenario="demo", max_turn_dgr=10)
    text = str(e.value)
    assert "max_turn_dgr: not a setting of plumetrace/PlumeTracing-v1" in text
    assert "did you mean max_turn_deg?" in text
    assert "decision_period_s" in text  # the settings are listed
    with pytest.raises(plumetrace.PlumetraceError, match="no_such_key"):
        gym.make("plumetrace/PlumeTracing-v1", scenario="demo", no_such_key=1)
    # A planner key is still an override, and fine.
    gym.make("plumetrace/PlumeTracing-v1", scenario="demo", declaration="along_flow")


def _episode(env, action, seed=2, limit=20000):
    obs, info = env.reset(seed=seed)
    for _ in range(limit):
        obs, r, term, trunc, info = env.step(np.asarray(action, dtype=float))
        if term or trunc:
            return term, trunc, info
        assert info["reason"] == ""
    raise AssertionError("the episode did not end")


def test_episodes_end_with_a_specific_reason():
    pytest.importorskip("gymnasium")
    import plumetrace.gym as pg

    env = pg.PlumeTracingEnv("demo")
    term, trunc, info = _episode(env, [0.0, 1.0, -1.0])  # straight on at full speed
    assert term and info["reason"] == "left_op_area"
    short = pg.PlumeTracingEnv("demo", set={"mission.time_limit_s": 30.0})
    term, trunc, info = _episode(short, [0.0, 0.0, -1.0])
    assert trunc and info["reason"] == "time_limit"
    # An op-area as large as the domain: leaving the domain ends the mission.
    wide = pg.PlumeTracingEnv(
        "demo", set={"mission.op_area": [[0, -150], [520, -150], [520, 150], [0, 150]]}
    )
    term, trunc, info = _episode(wide, [0.0, 1.0, -1.0])
    assert term and info["reason"] == "left_domain"
    v = pg.PlumeTracingVecEnv(num_envs=2, scenario="demo", set={"mission.time_limit_s": 30.0})
    v.reset(seed=1)
    for _ in range(40):
        _, _, term, trunc, info = v.step(np.zeros((2, 3)) - 1.0)
        if trunc.any():
            assert list(info["reason"]) == ["time_limit", "time_limit"]
            break
    else:
        raise AssertionError("no truncation")


# 4. RunResult.save


def _same_files(a, b):
    names = sorted(p.name for p in a.iterdir())
    assert names == sorted(p.name for p in b.iterdir())
    for n in names:
        x, y = (a / n).read_bytes(), (b / n).read_bytes()
        if n in ("summary.json", "stats.json"):
            jx, jy = json.loads(x), json.loads(y)
            for k in WALL + ("sim_s_per_wall_s",):
                assert (k in jx) == (k in jy), k
                jx.pop(k, None), jy.pop(k, None)
            assert jx == jy, n
        else:
            assert x == y, n
    return names


def test_save_writes_the_command_lines_files(cli, tmp_path):
    run_cli(cli, "run", "--preset", "demo", "--seed", "7", "--out", str(tmp_path / "cli"))
    r = plumetrace.run("demo", seed=7)
    written = r.save(tmp_path / "py")
    names = _same_files(tmp_path / "cli", tmp_path / "py")
    assert sorted(written) == names
    assert {"summary.json", "trajectory.csv", "events.jsonl", "plot.svg", "replay.html",
            "snapshots.jsonl.gz"} <= set(names)


def test_a_team_mission_saves_its_team_figure(cli, tmp_path):
    run_cli(cli, "run", "--preset", "soares-freshwater", "--seed", "7", "--out", str(tmp_path / "cli"))
    r = plumetrace.run("soares-freshwater", seed=7)
    assert "team.svg" in r.save(tmp_path / "py")
    _same_files(tmp_path / "cli", tmp_path / "py")


def test_a_result_without_its_record_says_why_it_cannot_be_saved(tmp_path):
    r = plumetrace.run("demo", seed=7, outputs=False)
    with pytest.raises(plumetrace.PlumetraceError, match="outputs=True"):
        r.save(tmp_path)
    again = pickle.loads(pickle.dumps(plumetrace.run("demo", seed=7)))
    assert again.outcome == "declared"
    with pytest.raises(plumetrace.PlumetraceError, match="pickled"):
        again.save(tmp_path)


# 5. The namespace and `python -m plumetrace`


def test_the_namespace_holds_only_the_api():
    public = {n for n in dir(plumetrace) if not n.startswith("_")}
    modules = {"gym", "dask", "sites", "sb3"}
    assert public <= set(plumetrace.__all__) | modules, public - set(plumetrace.__all__)
    for n in ("np", "os", "csv", "json", "Dict", "annotations"):
        assert not hasattr(plumetrace, n), n
    for n in plumetrace.__all__:
        assert getattr(plumetrace, n) is not None


def _module(*args):
    return subprocess.run([sys.executable, "-m", "plumetrace", *args], capture_output=True,
                          text=True)


def test_python_m_plumetrace_runs_as_the_command_line(cli, tmp_path):
    line = run_cli(cli, "run", "--preset", "demo", "--seed", "7", "--out", str(tmp_path / "cli"))
    out = _module("run", "--preset", "demo", "--seed", "7", "--out", str(tmp_path / "py"))
    assert out.returncode == 0, out.stderr
    # The same verdict, in the same words, as the command line's line.
    verdict = out.stdout.split("; outcome")[0]
    assert verdict.startswith("demo: located: declared ") and "(success radius 50" in verdict
    assert verdict in line
    _same_files(tmp_path / "cli", tmp_path / "py")
    run_cli(cli, "run", "--preset", "pompy", "--seed", "7", "--out", str(tmp_path / "cli-p"))
    out = _module("run", "--preset", "pompy", "--seed", "7", "--out", str(tmp_path / "py-p"))
    assert out.returncode == 0, out.stderr
    _same_files(tmp_path / "cli-p", tmp_path / "py-p")
    bad = _module("run", "--preset", "dmeo")
    assert bad.returncode == 2 and "error: 'dmeo' is neither a preset" in bad.stderr
    assert "nor a file; did you mean demo?" in bad.stderr
    assert "demo" in _module("presets").stdout


# 6. Campaign tables


def test_csv_and_parquet_read_to_the_same_typed_table(tmp_path):
    pd = pytest.importorskip("pandas")
    pytest.importorskip("pyarrow")
    fam = REPO / "examples" / "families" / "coastal.family.toml"
    f = tmp_path / "c.toml"
    f.write_text(f'name = "typed"\nseed = 5\nseeds = 3\nscenarios = ["demo", "{fam}"]\n'
                 '[[configs]]\nname = "amp"\n[configs.set]\nmapping = false\n')
    plumetrace.campaign(f, tmp_path / "o", progress=False)
    assert (tmp_path / "o" / "runs.parquet").exists()
    a = plumetrace.read_runs(tmp_path / "o" / "runs.csv")
    b = plumetrace.read_runs(tmp_path / "o" / "runs.parquet")
    pd.testing.assert_frame_equal(a, b)
    schema = {c["name"]: c["dtype"] for c in plumetrace.run_columns()}
    assert {n: str(t) for n, t in a.dtypes.items()} == schema
    assert str(a["site_flow_fault"].dtype) == "boolean"
    assert str(a["source_errors_m"].dtype) == "string"
    # Seeds are exact, above 2^63 too.
    text = (tmp_path / "o" / "runs.csv").read_text().splitlines()
    col = text[0].split(",").index("seed")
    exact = [int(line.split(",")[col]) for line in text[1:]]
    assert any(s >= 2**63 for s in exact)
    assert [int(s) for s in a["seed"]] == exact
    assert plumetrace.read_runs(tmp_path / "o" / "runs.csv", frame=False) == \
        plumetrace.read_runs(tmp_path / "o" / "runs.parquet", frame=False)


# 7. Plume: pickling and plume-only runs


def test_a_plume_pickles_to_the_same_state():
    p = plumetrace.Plume("plume-demo", seed=4, set={"sources.0.mass_rate_per_s": 2.0})
    p.spin_up(100.0)
    p.step(37)
    q = pickle.loads(pickle.dumps(p))
    assert q.time_s == p.time_s and q.seed == p.seed
    assert np.array_equal(q.filaments(), p.filaments())
    p.step(10)
    q.step(10)
    assert np.array_equal(q.filaments(), p.filaments())


def test_a_plume_of_a_scenario_file_pickles_with_the_files_text(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text((REPO / "examples" / "plumes" / "duck-onset.toml").read_text())
    p = plumetrace.Plume(str(f), seed=1)
    p.step(20)
    data = pickle.dumps(p)
    f.unlink()  # re-created from the text it was read from
    q = pickle.loads(data)
    assert np.array_equal(q.filaments(), p.filaments())


def test_run_on_a_plume_only_scenario_says_what_to_use_instead():
    with pytest.raises(plumetrace.PlumetraceError, match="plume-only scenario.*run_plume"):
        plumetrace.run("pompy")


def test_run_plume_writes_the_command_lines_files(cli, tmp_path):
    run_cli(cli, "run", "--preset", "pompy", "--seed", "5", "--out", str(tmp_path / "cli"))
    stats = plumetrace.run_plume("pompy", tmp_path / "py", seed=5)
    assert stats["seed"] == 5
    _same_files(tmp_path / "cli", tmp_path / "py")


def test_a_probe_series():
    p = plumetrace.Plume("plume-demo", seed=2)
    s = p.probe_series(60.0, every_s=2 * p.dt_s, points=[[10, 0], [20, 0]])
    n = round(60.0 / (2 * p.dt_s))
    assert s["t_s"].shape == (n,) and s["concentration"].shape == (n, 2)
    assert s["points"][1, 2] == p.z_m
    assert p.time_s == pytest.approx(60.0)
