"""Campaigns on a Dask cluster: one shard per task, merged at the end (needs
``dask.distributed``: ``pip install "plumetrace[dask]"``).

::

    from dask.distributed import Client, LocalCluster
    import plumetrace.dask

    client = Client(LocalCluster(n_workers=2, threads_per_worker=1))
    report = plumetrace.dask.run_on_dask(client, "campaign.toml", "out", shards=4, seeds=20)

On Slurm, make the client from dask-jobqueue instead
(``SLURMCluster(cores=8, memory="16GB")``, ``cluster.scale(jobs=4)``, ``Client(cluster)``).
Each shard runs in its own directory (``OUT/shards/K-of-N``) and the merged campaign is
``OUT/merged``: a shard that fails or is killed keeps what it finished, and calling
``run_on_dask`` again resumes every shard. The merged ``runs.csv`` is byte for byte the one a
single local run writes.
"""

from __future__ import annotations

import os as _os
from typing import Any, Dict, List, Optional

from . import _api

__all__ = ["run_on_dask", "run_shard"]


def run_shard(
    file: str, out: str, k: int, n: int, jobs: int = 1, seeds: Optional[int] = None
) -> str:
    """Runs shard ``k`` of ``n`` of the campaign ``file`` into ``out/shards/K-of-N`` (``seeds``
    per group overrides the file's); returns that directory. This is what each Dask task
    runs."""
    d = _os.path.join(out, "shards", f"{k}-of-{n}")
    _api.campaign(file, d, shard=(k, n), jobs=jobs, seeds=seeds, progress=False)
    return d


def run_on_dask(
    client: Any,
    file: Any,
    out: Any,
    shards: int = 4,
    *,
    seeds: Optional[int] = None,
    jobs_per_shard: int = 1,
) -> Dict[str, Any]:
    """Runs the campaign ``file`` as ``shards`` tasks on ``client``'s cluster and merges them
    into ``out/merged``.

    Args:
        client: a ``dask.distributed.Client``.
        file: the campaign file (TOML), readable from the workers.
        out: the output directory, shared with the workers.
        shards: tasks to split the runs into.
        seeds: seeds per group (overrides the file's ``seeds``).
        jobs_per_shard: threads each task runs.

    Returns:
        The merge's report: ``runs``, ``expected``, ``partial`` and ``out``.
    """
    if shards < 1:
        raise ValueError(f"shards = {shards} must be at least 1")
    file = _os.path.abspath(_os.fspath(file))
    out = _os.path.abspath(_os.fspath(out))
    futures = [
        client.submit(run_shard, file, out, k, shards, jobs_per_shard, seeds, pure=False)
        for k in range(1, shards + 1)
    ]
    dirs: List[str] = client.gather(futures)
    return _api.merge(dirs, _os.path.join(out, "merged"))
