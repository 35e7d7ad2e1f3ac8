"""plumetrace from Python: missions, plumes, campaigns and planners written in Python.

The simulation runs in Rust (the same code as the ``plumetrace`` command line); long calls
release the interpreter. Errors are raised as :class:`PlumetraceError` with the command line's
messages, naming the file and the key.

Example::

    import plumetrace

    r = plumetrace.run("demo", seed=1)
    print(r.outcome, r.summary["first_declaration"]["error_m"])
"""

from __future__ import annotations

import csv
import json
import os
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _plumetrace
from ._plumetrace import Plume, PlumetraceError, __version__

__all__ = [
    "Plume",
    "PlumetraceError",
    "RunResult",
    "campaign",
    "merge",
    "planners",
    "presets",
    "read_runs",
    "run",
    "run_columns",
    "__version__",
]

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
        metrics: the run's metrics as a campaign's ``runs.csv`` records them (its metric
            columns, see :func:`run_columns`; ``success`` without a success radius), missing
            numbers as None.
    """

    name: str
    summary: Dict[str, Any]
    events: List[Dict[str, Any]]
    trajectory: Dict[str, np.ndarray]
    vehicles: List[str]
    warnings: List[str] = field(default_factory=list)
    metrics: Dict[str, Any] = field(default_factory=dict)

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
    )


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


def merge(dirs: Sequence[PathLike], out: PathLike) -> Dict[str, Any]:
    """Merges shard directories of one campaign into ``out`` (``plumetrace merge``)."""
    return dict(_plumetrace.merge([os.fspath(d) for d in dirs], os.fspath(out)))


def run_columns() -> List[Dict[str, str]]:
    """The columns of a campaign's ``runs.csv`` (and ``runs.parquet``), in order.

    Each is a dict with ``name``, ``kind`` (``text``, ``u64``, ``u32``, ``bool``, ``opt_bool``,
    ``opt_f64`` or ``opt_u64``), ``unit`` (empty for counts, flags, text and ratios) and
    ``description``: the run's keys and outcome, the mission's metrics, the drawn site of a
    family and the failure message.
    """
    return [
        {"name": n, "kind": k, "unit": u, "description": d}
        for n, k, u, d in _plumetrace.run_columns()
    ]


def _value(kind: Optional[str], text: str) -> Any:
    """A field of ``runs.csv`` read by its column's kind (empty fields as None)."""
    if text == "":
        return None
    if kind in ("u64", "u32", "opt_u64"):
        return int(text)
    if kind == "opt_f64":
        return float(text)
    if kind in ("bool", "opt_bool"):
        return text == "true"
    if kind == "text":
        return text
    return _number(text)


def _number(text: str) -> Any:
    if text == "":
        return None
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


def read_runs(path: PathLike, *, frame: Optional[bool] = None) -> Any:
    """Reads a campaign's ``runs.csv`` (or ``runs.parquet``), or the one in a directory.

    Returns a pandas DataFrame when pandas is installed (or ``frame=True``), else a dict of
    column name to list (each field read by its column's kind, see :func:`run_columns`: whole
    numbers as int, numbers as float, flags as bool, empty fields as None). Parquet needs pandas
    and pyarrow.
    """
    kinds = {c["name"]: c["kind"] for c in run_columns()}
    p = os.fspath(path)
    if os.path.isdir(p):
        p = os.path.join(p, "runs.csv")
    if frame is None:
        try:
            import pandas  # noqa: F401

            frame = True
        except ImportError:
            frame = False
    if p.endswith(".parquet"):
        import pandas as pd

        return pd.read_parquet(p)
    if frame:
        import pandas as pd

        return pd.read_csv(p, dtype={n: str for n, k in kinds.items() if k == "text"})
    with open(p, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        return {}
    return {k: [_value(kinds.get(k), r[k]) for r in rows] for k in rows[0]}
