"""`plumetrace.run`: the same mission as the command line, errors as exceptions."""

import json

import numpy as np
import pytest

import plumetrace
from conftest import run_cli

WALL_CLOCK = {"wall_s", "real_time_factor", "spinup_wall_s", "stage_times"}


def test_a_preset_gives_the_command_lines_summary_for_the_same_seed(cli, tmp_path):
    r = plumetrace.run("demo", seed=7)
    run_cli(cli, "run", "--preset", "demo", "--seed", "7", "--out", str(tmp_path))
    cli_summary = json.loads((tmp_path / "summary.json").read_text())
    for k in WALL_CLOCK:
        cli_summary.pop(k, None)
    assert r.summary == cli_summary
    # The trajectory is the command line's too (trajectory.csv rounds to its printed digits).
    csv = np.genfromtxt(tmp_path / "trajectory.csv", delimiter=",", names=True, dtype=None,
                        encoding="utf-8")
    assert len(csv) == len(r.trajectory["t_s"])
    assert np.allclose(csv["true_x_m"], r.trajectory["true_x_m"], atol=0.006)
    assert np.allclose(csv["reading_v"], r.trajectory["reading_v"], atol=0.0006)
    events = [json.loads(line) for line in (tmp_path / "events.jsonl").read_text().splitlines()]
    assert r.events == events


def test_overrides_reach_the_planner_and_the_scenario():
    base = plumetrace.run("demo", seed=3, trajectory=False)
    assert base.trajectory["t_s"].size == 0
    other = plumetrace.run("demo", seed=3, trajectory=False, declaration="along_and_cross_flow",
                           set={"sources.0.mass_rate_per_s": 2.0})
    assert other.summary != base.summary


def test_the_same_seed_gives_the_same_run_and_another_seed_another():
    a = plumetrace.run("demo", seed=11)
    b = plumetrace.run("demo", seed=11)
    c = plumetrace.run("demo", seed=12)
    assert a.summary == b.summary
    assert np.array_equal(a.trajectory["true_x_m"], b.trajectory["true_x_m"])
    assert a.summary != c.summary


@pytest.mark.parametrize(
    "call, words",
    [
        (lambda: plumetrace.run("no-such-preset"), ["no-such-preset", "neither a preset"]),
        (lambda: plumetrace.run("demo", no_such_key=1), ["no_such_key"]),
        (lambda: plumetrace.run("demo", set={"sources.9.x_m": 1.0}), ["sources.9"]),
        (lambda: plumetrace.run("demo", seed=-1), ["seed -1"]),
        (lambda: plumetrace.run("demo", threshold_v=float("nan")), ["threshold_v", "finite"]),
    ],
)
def test_bad_input_is_an_exception_that_names_what_and_where(call, words):
    with pytest.raises(plumetrace.PlumetraceError) as e:
        call()
    for w in words:
        assert w in str(e.value)


def test_a_bad_scenario_file_names_the_file_and_key(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text('name = "x"\n[domain]\nx_min_m = "west"\n')
    with pytest.raises(plumetrace.PlumetraceError) as e:
        plumetrace.run(str(p))
    assert "bad.toml" in str(e.value)
    assert "x_min_m" in str(e.value)


def test_lists_come_from_the_registries():
    assert "demo" in [n for n, _ in plumetrace.presets()]
    assert {"amp", "moth", "lawnmower"} <= {k for k, _ in plumetrace.planners()}


def test_frames_when_pandas_is_installed():
    pd = pytest.importorskip("pandas")
    r = plumetrace.run("demo", seed=2)
    f = r.trajectory_frame()
    assert isinstance(f, pd.DataFrame)
    assert len(f) == len(r.trajectory["t_s"])
    assert set(r.events_frame().columns) >= {"t_s", "event"}


def test_a_runs_metrics_are_the_campaign_columns_of_its_summary():
    r = plumetrace.run("demo", seed=7, trajectory=False)
    names = [c["name"] for c in plumetrace.run_columns()]
    assert set(r.metrics) < set(names)
    assert list(r.metrics) == [n for n in names if n in r.metrics]
    assert r.metrics["declared"] == r.summary["declared"]
    assert r.metrics["sim_time_s"] == r.summary["sim_time_s"]
    assert r.metrics["team_converged_s"] is None


def test_read_runs_reads_each_column_by_its_kind(tmp_path):
    f = tmp_path / "c.toml"
    f.write_text('name = "k"\nseed = 5\nseeds = 1\nscenarios = ["demo"]\n')
    plumetrace.campaign(f, tmp_path / "o", progress=False)
    rows = plumetrace.read_runs(tmp_path / "o", frame=False)
    assert list(rows) == [c["name"] for c in plumetrace.run_columns()]
    assert isinstance(rows["seed"][0], int) and isinstance(rows["success"][0], bool)
    assert rows["scenario"] == ["demo"] and rows["message"] == [""]
