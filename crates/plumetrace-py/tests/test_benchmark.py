"""`plumetrace.benchmark`: the command line's benchmark from Python, by name (the same numbers as
`plumetrace benchmark`, exactly) and for a planner written in Python (flown by the same loop as
`plumetrace.run` flies it), resumable, with the errors a new user meets."""

import csv
import json
import tomllib

import pytest

import plumetrace
from conftest import REPO, run_cli


class Northward:
    """Heads north for two minutes, then declares where it is and stops."""

    made = 0

    def __init__(self, scenario, seed):
        Northward.made += 1
        Northward.last = (scenario, seed)

    def decide(self, s):
        if s["time_s"] >= 120.0 and s["nav"]["pos_m"] is not None:
            x, y = s["nav"]["pos_m"][:2]
            return {"heading_deg": 0.0, "speed_mps": 0.0, "altitude_m": 3.0,
                    "declare": (x, y), "done": True}
        return {"heading_deg": 0.0, "speed_mps": 1.5, "altitude_m": 3.0}


class NoDecide:
    def __init__(self, scenario, seed):
        pass


class Raises:
    def decide(self, s):
        raise RuntimeError("planner bug")


def test_benchmark_by_name_gives_the_command_lines_numbers_exactly(cli, tmp_path):
    run_cli(cli, "benchmark", "--planner", "amp", "--tasks", "coastal,kelp",
            "--seeds-per-task", "2", "--out", str(tmp_path / "cli"))
    results = plumetrace.benchmark("amp", tmp_path / "py", tasks=["coastal", "kelp"],
                                   seeds_per_task=2, progress=False)
    board = json.loads((tmp_path / "cli" / "leaderboard.json").read_text())
    assert json.loads((tmp_path / "py" / "leaderboard.json").read_text()) == board
    assert ((tmp_path / "py" / "leaderboard.md").read_text()
            == (tmp_path / "cli" / "leaderboard.md").read_text())
    # The returned dicts are the leaderboard's entries, number for number.
    assert list(results) == ["coastal", "kelp"]
    for t in board["tasks"]:
        (entry,) = t["entries"]
        assert results[t["task"]["name"]]["amp"] == entry
        assert entry["runs"] == 2
    for task in ("coastal", "kelp"):
        assert ((tmp_path / "py" / task / "runs.csv").read_text()
                == (tmp_path / "cli" / task / "runs.csv").read_text())


def test_a_python_planner_flies_the_test_seeds_as_run_flies_them_and_resumes(tmp_path):
    out = tmp_path / "b"
    Northward.made = 0
    results = plumetrace.benchmark(Northward, out, tasks="coastal", seeds_per_task=2,
                                   progress=False)
    assert Northward.made == 2
    # Made for the task's family file (where its sites are drawn), not the family's base preset.
    assert Northward.last[0] == str(out / "tasks" / "coastal.family.toml")
    entry = results["coastal"]["Northward"]
    assert entry["runs"] == 2 and entry["failed"] == 0
    rows = list(csv.DictReader((out / "coastal" / "runs.csv").open()))
    assert [r["config"] for r in rows] == ["Northward", "Northward"]
    # The task's first test seeds, as every planner meets them.
    tasks = tomllib.loads((REPO / "benchmarks" / "tasks-v1.toml").read_text())["tasks"]
    test_seed = next(t["test_seed"] for t in tasks if t["name"] == "coastal")
    assert [int(r["seed"]) for r in rows] == [plumetrace.derive_seed(test_seed, k)
                                               for k in range(2)]
    family = out / "tasks" / "coastal.family.toml"
    for r in rows:
        alone = plumetrace.run(str(family), seed=int(r["seed"]),
                               planner=Northward(str(family), int(r["seed"])),
                               trajectory=False, outputs=False)
        assert r["declared"] == "true"
        for key in ("path_length_m", "error_m", "declaration_s"):
            assert repr(alone.metrics[key]) == r[key], key
    # Again into the same directory: nothing is flown, the same results come back.
    Northward.made = 0
    before = (out / "coastal" / "runs.csv").read_text()
    assert plumetrace.benchmark(Northward, out, tasks="coastal", seeds_per_task=2,
                                progress=False) == results
    assert Northward.made == 0
    assert (out / "coastal" / "runs.csv").read_text() == before
    assert json.loads((out / "leaderboard.json").read_text())["tasks"][0]["entries"][0] == entry


def test_benchmark_errors_name_what_is_wrong(tmp_path):
    with pytest.raises(plumetrace.PlumetraceError,
                       match=r"no planner 'amq' \(did you mean 'amp'\?\); planners: amp, "):
        plumetrace.benchmark("amq", tmp_path / "a")
    with pytest.raises(plumetrace.PlumetraceError,
                       match=r"no task 'coastel' in task set v1 \(did you mean 'coastal'\?\)"):
        plumetrace.benchmark("amp", tmp_path / "a", tasks="coastel")
    with pytest.raises(plumetrace.PlumetraceError,
                       match=r"the planner class NoDecide has no decide\(snapshot\) method"):
        plumetrace.benchmark(NoDecide, tmp_path / "a")
    with pytest.raises(plumetrace.PlumetraceError,
                       match=r"task 'freshwater-team' is not flown by 'Northward': its planners "
                             r"are formation \(a team"):
        plumetrace.benchmark(Northward, tmp_path / "a", tasks="freshwater-team")
    with pytest.raises(plumetrace.PlumetraceError,
                       match=r"has no name of its own: give it one with name="):
        plumetrace.benchmark(lambda scenario, seed: Northward(scenario, seed), tmp_path / "a")
    assert not (tmp_path / "a").exists()
    # A directory holding another planner's benchmark is refused before anything is written.
    plumetrace.benchmark(Northward, tmp_path / "b", tasks="coastal", seeds_per_task=1,
                         progress=False)
    with pytest.raises(plumetrace.PlumetraceError,
                       match=r"holds task 'coastal' flown by Northward; this call enters amp: "
                             r"give another output directory"):
        plumetrace.benchmark("amp", tmp_path / "b", tasks="coastal", seeds_per_task=1)
    # A planner that raises: the run is not recorded, and its exception is the cause.
    with pytest.raises(plumetrace.PlumetraceError,
                       match=r"benchmark task 'coastal': configuration 'Raises', run seed \d+: "
                             r"RuntimeError\('planner bug'\)") as e:
        plumetrace.benchmark(Raises, tmp_path / "c", tasks="coastal", seeds_per_task=1)
    assert isinstance(e.value.__cause__, RuntimeError)
    runs = (tmp_path / "c" / "coastal" / "runs.csv").read_text().splitlines()
    assert len(runs) == 1, runs
