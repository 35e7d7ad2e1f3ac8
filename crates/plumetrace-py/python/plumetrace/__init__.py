"""plumetrace from Python: missions, plumes, campaigns and planners written in Python.

The simulation runs in Rust (the same code as the ``plumetrace`` command line); long calls
release the interpreter. Errors are raised as :class:`PlumetraceError` with the command line's
messages, naming the file and the key.

Example::

    import plumetrace

    r = plumetrace.run("demo", seed=1)
    print(r.outcome, r.summary["first_declaration"]["error_m"])
    r.save("out")          # the files of `plumetrace run --out out`

Submodules: ``plumetrace.gym`` (a Gymnasium environment, needs gymnasium) and
``plumetrace.dask`` (campaigns on a Dask cluster, needs dask.distributed);
``python -m plumetrace`` is a small command line.
"""

from ._api import (
    RunResult,
    benchmark,
    campaign,
    merge,
    planners,
    presets,
    read_runs,
    run,
    run_columns,
    run_plume,
)
from ._plumetrace import Plume, PlumetraceError, __version__, derive_seed
from . import sites

__all__ = [
    "Plume",
    "PlumetraceError",
    "RunResult",
    "benchmark",
    "campaign",
    "derive_seed",
    "merge",
    "planners",
    "presets",
    "read_runs",
    "run",
    "run_columns",
    "run_plume",
    "__version__",
]
