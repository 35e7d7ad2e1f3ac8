"""The package's functions and result types (re-exported by ``plumetrace``)."""

from __future__ import annotations

import csv
import json
import os
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _plumetrace
from ._plumetrace import PlumetraceError

PathLike = Union[str, "os.PathLike[str]"]


def _tqdm(total: Optional[float], unit: str, desc: str) -> Any:
    """A tqdm bar when tqdm is installed, else None."""
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None
    return tqdm(total=total, unit=unit, desc=desc)


@dataclass
class RunResult:
    """What a mission produced.

    Attributes:
        name: the scenario's name.
        summary: the key numbers (the same dict as the command line's ``summary.json``
            without its wall-clock fields).
        events: the event stream, one dict per event (``events.jsonl``).
        trajectory: every step of every vehicle as numpy arrays of equal length: ``t_s``,
            ``vehicle``, ``true_x_m``, ``true_y_m``, ``true_z_m``, ``est_x_m``, ``est_y_m`` (NaN
            for a vehicle without a position estimate, see ``has_estimate``), ``heading_deg``,
            ``speed_mps``, ``behaviour`` (strings, empty before the first decision),
            ``reading_v``, ``detection``.
        vehicles: vehicle names, by index.
        warnings: what ``plumetrace check`` would warn about.
        verdict: whether the mission located the source, in the words of ``plumetrace run``'s
            line (``located: declared 6.3 m from the source (success radius 50 m)``, ``NOT
            located: ...``; the radius is the scenario's ``mission.success_radius_m``).
        metrics: the run's metrics as a campaign's ``runs.csv`` records them (its metric
            columns, see :func:`run_columns`; ``success`` within the scenario's success radius), missing
            numbers as None.

    A result pickles without what :meth:`save` writes from (that stays in the process that
    flew the mission).
    """

    name: str
    summary: Dict[str, Any]
    events: List[Dict[str, Any]]
    trajectory: Dict[str, np.ndarray]
    vehicles: List[str]
    warnings: List[str] = field(default_factory=list)
    metrics: Dict[str, Any] = field(default_factory=dict)
    verdict: str = ""
    _record: Any = field(default=None, repr=False, compare=False)

    def __getstate__(self) -> Dict[str, Any]:
        state = dict(self.__dict__)
        state["_record"] = None
        return state

    def save(self, out: PathLike) -> List[str]:
        """Writes the run's files into the directory ``out`` (created if needed), the same
        files as ``plumetrace run --out``: ``summary.json``, ``trajectory.csv``,
        ``events.jsonl``, ``plot.svg``, ``team.svg`` (a team mission), ``replay.html`` and
        ``snapshots.jsonl.gz``, written by the same Rust functions (byte for byte the same for the
        same scenario and seed, but for ``summary.json``'s wall-clock fields). Returns the names
        of the files written.
        """
        if self._record is None:
            raise PlumetraceError(
                "this result keeps nothing to save: run it with outputs=True (the default) "
                "and save it in the process that ran it (a pickled result has no files)"
            )
        return list(self._record.save(os.fspath(out)))

    @property
    def outcome(self) -> str:
        """The mission's outcome (``declared``, ``timed_out``, ...)."""
        return str(self.summary["outcome"])


    def trajectory_frame(self) -> Any:
        """The trajectory as a pandas DataFrame (requires pandas)."""
        import pandas as pd

        return pd.DataFrame(self.trajectory)

    def events_frame(self) -> Any:
        """The events as a pandas DataFrame (requires pandas)."""
        import pandas as pd

        return pd.DataFrame(self.events)


def run(
    scenario: str,
    seed: Optional[int] = None,
    *,
    set: Optional[Mapping[str, Any]] = None,
    planner: Any = None,
    vehicle: int = 0,
    trajectory: bool = True,
    progress: bool = False,
    outputs: bool = True,
    **overrides: Any,
) -> RunResult:
    """Flies a mission and returns its :class:`RunResult`.

    Args:
        scenario: a preset name (see :func:`presets`) or a scenario file.
        seed: the run seed (default: the scenario's).
        set: overrides with dotted keys, e.g. ``{"sources.0.mass_rate_per_s": 2.0}``.
        planner: a Python planner flown instead of the vehicle's registered planner: an object
            with ``decide(snapshot) -> command`` (dicts; see the README) and optionally
            ``decision_period_s`` (default 1 s).
        vehicle: which vehicle the Python planner flies.
        trajectory: keep every step of every vehicle.
        progress: show a tqdm bar (when tqdm is installed).
        outputs: record what :meth:`RunResult.save` writes (the time-averaged plume of the
            figure, the replay page's plume frames, the snapshot log), as ``plumetrace run``
            does; False runs a little faster and cannot be saved.
        **overrides: planner keys of the scenario's planner (``declaration="along_flow"``), as a
            campaign's ``set`` table takes them.
    """
    bar = _tqdm(None, "s", "mission") if progress else None
    try:
        raw = _plumetrace.run(
            os.fspath(scenario),
            seed=seed,
            set=dict(set) if set else None,
            planner=planner,
            vehicle=vehicle,
            trajectory=trajectory,
            progress=(bar.update if bar is not None else None),
            outputs=outputs,
            **overrides,
        )
    finally:
        if bar is not None:
            bar.close()
    traj = dict(raw["trajectory"])
    traj["behaviour"] = np.asarray(traj["behaviour"], dtype=str)
    return RunResult(
        name=raw["name"],
        summary=json.loads(raw["summary"]),
        events=[json.loads(e) for e in raw["events"]],
        trajectory=traj,
        vehicles=list(raw["vehicles"]),
        warnings=list(raw["warnings"]),
        metrics=json.loads(raw["metrics"]),
        verdict=str(raw["verdict"]),
        _record=raw.get("record"),
    )


def run_plume(
    scenario: str,
    out: PathLike,
    seed: Optional[int] = None,
    *,
    set: Optional[Mapping[str, Any]] = None,
    **overrides: Any,
) -> Dict[str, Any]:
    """Runs a plume-only scenario (no ``[mission]`` table) and writes its files into ``out``,
    as ``plumetrace run`` does (``snapshot.csv``, ``filaments.csv``, ``plume.svg``,
    ``stats.json`` and, when ``[output]`` asks, ``probes.csv`` and ``filament_series.csv``).
    Returns the statistics (``stats.json``). To step and query a plume from Python, use
    :class:`Plume`.
    """
    raw = _plumetrace.run_plume(
        os.fspath(scenario), os.fspath(out), seed=seed, set=dict(set) if set else None,
        **overrides,
    )
    return dict(json.loads(raw))


def presets() -> List[Tuple[str, str]]:
    """The built-in scenarios as ``(name, summary)`` pairs."""
    return list(_plumetrace.presets())


def planners() -> List[Tuple[str, str]]:
    """The registered planners as ``(kind, summary)`` pairs."""
    return list(_plumetrace.planners())


def campaign(
    file: PathLike,
    out: PathLike,
    *,
    jobs: Optional[int] = None,
    shard: Union[None, str, Tuple[int, int]] = None,
    seeds: Optional[int] = None,
    progress: Union[bool, Callable[[int, int], None]] = True,
) -> Dict[str, Any]:
    """Runs (or resumes) a campaign file into ``out``, as ``plumetrace campaign`` does.

    Args:
        file: the campaign file (TOML).
        out: the output directory (running again into it resumes).
        jobs: worker threads (default one per core); results do not depend on it.
        shard: ``"K/N"`` or ``(K, N)``: only every N-th run, starting with the K-th.
        seeds: seeds per group (overrides the file's).
        progress: True for a tqdm bar (when tqdm is installed), or a callable
            ``progress(done, total)``.

    Returns:
        What it did: ``planned``, ``skipped`` (already recorded), ``ran``, ``failed``, ``out``.
    """
    bar = None
    callback: Optional[Callable[[int, int], None]] = None
    if callable(progress):
        callback = progress
    elif progress:
        bar = _tqdm(None, "runs", "campaign")
        if bar is not None:
            done_so_far = [0]

            def callback(done: int, total: int) -> None:
                bar.total = total
                bar.update(done - done_so_far[0])
                done_so_far[0] = done

    try:
        return dict(
            _plumetrace.campaign(
                os.fspath(file),
                os.fspath(out),
                jobs=jobs,
                shard=shard,
                seeds=seeds,
                progress=callback,
            )
        )
    finally:
        if bar is not None:
            bar.close()


def _planner_factory(planner: Any) -> Callable[[str, int], Any]:
    """``planner(scenario, seed)`` when it takes two arguments, else ``planner()``: a fresh
    planner object per run. A class without ``decide`` is refused before anything flies."""
    import inspect

    what = getattr(planner, "__name__", type(planner).__name__)
    if isinstance(planner, type) and not callable(getattr(planner, "decide", None)):
        raise PlumetraceError(
            f"the planner class {what} has no decide(snapshot) method: a Python planner "
            "answers decide(snapshot) with a command dict (see plumetrace.run)"
        )
    try:
        sig = inspect.signature(planner)
    except (TypeError, ValueError):
        return lambda scenario, seed: planner(scenario, seed)
    try:
        sig.bind("scenario", 0)
        return lambda scenario, seed: planner(scenario, seed)
    except TypeError:
        pass
    try:
        sig.bind()
        return lambda scenario, seed: planner()
    except TypeError:
        raise PlumetraceError(
            f"the planner {what}{sig} cannot be made for a run: it is called as "
            f"{what}(scenario, seed) or {what}()"
        ) from None


def benchmark(
    planner: Union[None, str, Sequence[str], Any] = None,
    out: Optional[PathLike] = None,
    *,
    name: Optional[str] = None,
    tasks: Union[None, str, Sequence[str]] = None,
    seeds_per_task: Optional[int] = None,
    jobs: Optional[int] = None,
    progress: Union[bool, Callable[[str, int, int], None]] = True,
) -> Dict[str, Dict[str, Dict[str, Any]]]:
    """Flies the benchmark's tasks on their test seeds, as ``plumetrace benchmark`` does (the
    same loop: the same runs, the same numbers), and writes the leaderboard into ``out``.

    Args:
        planner: a registered planner's name (``"amp"``) or a list of names, flown at their
            defaults in parallel; or a planner written in Python: a class (or any callable)
            called as ``planner(scenario, seed)`` for each run (``planner()`` when it takes no
            arguments) and returning an object with ``decide(snapshot)`` (the seam of
            :func:`run`, and of ``plumetrace.gym.PolicyPlanner``). ``scenario`` is the task's
            scenario (a family file's path, or a preset's name) and ``seed`` the run seed; the
            planner flies the first vehicle. Python planners fly one run at a time. Default:
            every task's own planners.
        out: the output directory (a campaign directory per task, ``leaderboard.md``,
            ``leaderboard.json``); running again into it resumes.
        name: the Python planner's name in the tables (default: its ``__name__``).
        tasks: task names (default: every task an entrant enters; a Python planner enters
            every task but the team's).
        seeds_per_task: test seeds per task, the first ones (default: each task's ``seeds``).
        jobs: worker threads for registered planners (default one per core); results do not
            depend on it.
        progress: True for a tqdm bar per task (when tqdm is installed), or a callable
            ``progress(task, done, total)``.

    Returns:
        ``results[task][planner]``: one dict per task and planner, the leaderboard's entry
        (the keys of ``leaderboard.json``'s entries: ``runs``, ``successes``, ``success_rate``,
        ``success_ci95``, ``error_median_m``, ...; ``None`` where it has ``null``), tasks in the
        task set's order and planners best first.
    """
    if out is None:
        raise PlumetraceError("benchmark needs out=: the directory the results go to")
    names: List[str] = []
    factory = None
    factory_name = None
    if isinstance(planner, str):
        names = [planner]
    elif planner is None:
        names = []
    elif isinstance(planner, (list, tuple)) and all(isinstance(p, str) for p in planner):
        names = list(planner)
    elif callable(planner):
        factory = _planner_factory(planner)
        factory_name = name or getattr(planner, "__name__", None)
        if not factory_name or factory_name == "<lambda>":
            raise PlumetraceError(
                f"the planner {planner!r} has no name of its own: give it one with name= "
                "(it names the planner's rows in the leaderboard)"
            )
    else:
        raise PlumetraceError(
            f"planner={planner!r}: give a registered planner's name, a list of names, or a "
            "Python planner class"
        )
    if isinstance(tasks, str):
        tasks = [tasks]
    bar: List[Any] = [None, ""]
    callback: Optional[Callable[[str, int, int], None]] = None
    if callable(progress):
        callback = progress
    elif progress:

        def callback(task: str, done: int, total: int) -> None:
            if bar[1] != task:
                if bar[0] is not None:
                    bar[0].close()
                bar[0] = _tqdm(total, "runs", task)
                bar[1] = task
            if bar[0] is not None:
                bar[0].update(done - bar[0].n)

    try:
        r = _plumetrace.benchmark(
            os.fspath(out),
            names=names,
            factory=factory,
            factory_name=factory_name,
            tasks=list(tasks or []),
            seeds_per_task=seeds_per_task,
            jobs=jobs,
            progress=callback,
        )
    finally:
        if bar[0] is not None:
            bar[0].close()
    for note in r["notes"]:
        import warnings

        warnings.warn(note, stacklevel=2)
    board = json.loads(r["board"])
    return {
        t["task"]["name"]: {e["planner"]: e for e in t["entries"]} for t in board["tasks"]
    }


def merge(dirs: Sequence[PathLike], out: PathLike) -> Dict[str, Any]:
    """Merges shard directories of one campaign into ``out`` (``plumetrace merge``)."""
    return dict(_plumetrace.merge([os.fspath(d) for d in dirs], os.fspath(out)))


#: The column kinds of ``runs.csv`` and the pandas dtype :func:`read_runs` gives each.
DTYPES: Dict[str, str] = {
    "text": "string",
    "u64": "UInt64",
    "u32": "UInt32",
    "bool": "boolean",
    "opt_bool": "boolean",
    "opt_f64": "Float64",
    "opt_u64": "UInt64",
}


def run_columns() -> List[Dict[str, str]]:
    """The columns of a campaign's ``runs.csv`` (and ``runs.parquet``), in order: the
    published schema of :func:`read_runs`.

    Each is a dict with ``name``, ``kind`` (``text``, ``u64``, ``u32``, ``bool``, ``opt_bool``,
    ``opt_f64`` or ``opt_u64``), ``dtype`` (the pandas dtype :func:`read_runs` gives it:
    ``string``, ``UInt64``, ``UInt32``, ``boolean`` or ``Float64``, nullable), ``unit`` (empty
    for counts, flags, text and ratios) and ``description``: the run's keys and outcome, the
    mission's metrics, the drawn site of a family and the failure message.
    """
    return [
        {"name": n, "kind": k, "dtype": DTYPES[k], "unit": u, "description": d}
        for n, k, u, d in _plumetrace.run_columns()
    ]


def _value(kind: Optional[str], text: str) -> Any:
    """A field of ``runs.csv`` read by its column's kind (empty fields as None, text as is)."""
    if kind == "text":
        return text
    if text == "":
        return None
    if kind in ("u64", "u32", "opt_u64"):
        return int(text)
    if kind == "opt_f64":
        return float(text)
    if kind in ("bool", "opt_bool"):
        return text == "true"
    return text


def _from_stored(kind: Optional[str], v: Any) -> Any:
    """A Parquet value as :func:`_value` gives the CSV's (optional whole numbers are stored as
    doubles)."""
    if v is None:
        return "" if kind == "text" else None
    if kind in ("u64", "u32", "opt_u64"):
        return int(v)
    return v


def _typed_frame(columns: Dict[str, List[Any]], kinds: Dict[str, str]) -> Any:
    """A DataFrame of the columns, each with its kind's nullable dtype."""
    import pandas as pd

    data = {}
    for name, values in columns.items():
        dtype = DTYPES.get(kinds.get(name, "text"), "string")
        data[name] = pd.array(values, dtype=dtype)
    return pd.DataFrame(data)


def read_runs(path: PathLike, *, frame: Optional[bool] = None) -> Any:
    """Reads a campaign's ``runs.csv`` or ``runs.parquet`` (or the one in a directory, the CSV
    first) with the published schema (:func:`run_columns`): the same column types whichever
    file it reads.

    Returns a pandas DataFrame when pandas is installed (or ``frame=True``) whose columns have
    nullable dtypes: seeds ``UInt64`` (exact above 2^63), counts ``UInt32``/``UInt64``, flags
    ``boolean`` (``site_flow_fault`` included), numbers ``Float64``, text ``string``
    (``source_errors_m``, the per-source errors joined by ``;``, included); missing values are
    ``<NA>``. Else (``frame=False``) a dict of column name to list: whole numbers as int,
    numbers as float, flags as bool, text as str, missing values as None. Parquet needs pyarrow.
    """
    kinds = {c["name"]: c["kind"] for c in run_columns()}
    p = os.fspath(path)
    if os.path.isdir(p):
        csv_path = os.path.join(p, "runs.csv")
        p = csv_path if os.path.exists(csv_path) else os.path.join(p, "runs.parquet")
    if frame is None:
        try:
            import pandas  # noqa: F401

            frame = True
        except ImportError:
            frame = False
    if p.endswith(".parquet"):
        import pyarrow.parquet as pq

        table = pq.read_table(p)
        columns = {
            name: [_from_stored(kinds.get(name), v) for v in table.column(name).to_pylist()]
            for name in table.column_names
        }
    else:
        with open(p, newline="") as f:
            rows = list(csv.DictReader(f))
            names = list(rows[0]) if rows else []
        if not rows:
            with open(p, newline="") as f:
                names = next(csv.reader(f), [])
        columns = {k: [_value(kinds.get(k), r[k]) for r in rows] for k in names}
    if frame:
        return _typed_frame(columns, kinds)
    return columns
