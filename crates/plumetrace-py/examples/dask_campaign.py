"""A campaign spread over a Dask cluster: one shard per task, merged at the end.

    python dask_campaign.py CAMPAIGN.toml OUT_DIR [--shards N] [--workers N]

With no scheduler address it starts a `LocalCluster`; on a Slurm cluster, make the client
from dask-jobqueue instead (see the README):

    from dask_jobqueue import SLURMCluster
    cluster = SLURMCluster(cores=8, memory="16GB", walltime="02:00:00")
    cluster.scale(jobs=4)
    client = Client(cluster)

Each shard runs in its own directory (`OUT_DIR/shards/K-of-N`); a shard that fails or is
killed keeps what it finished, and running the script again resumes every shard.
"""

from __future__ import annotations

import argparse
import os
from typing import List

import plumetrace


def run_shard(file: str, out: str, k: int, n: int, jobs: int) -> str:
    """Runs shard k of n into its own directory; returns the directory."""
    d = os.path.join(out, "shards", f"{k}-of-{n}")
    plumetrace.campaign(file, d, shard=(k, n), jobs=jobs, progress=False)
    return d


def run_on_dask(client, file: str, out: str, shards: int, jobs_per_shard: int = 1) -> dict:
    """Runs `file` as `shards` tasks on `client`'s cluster and merges them into `out/merged`."""
    futures = [
        client.submit(run_shard, os.path.abspath(file), os.path.abspath(out), k, shards,
                      jobs_per_shard, pure=False)
        for k in range(1, shards + 1)
    ]
    dirs: List[str] = client.gather(futures)
    return plumetrace.merge(dirs, os.path.join(out, "merged"))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaign")
    ap.add_argument("out")
    ap.add_argument("--shards", type=int, default=4)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--scheduler", help="address of a running Dask scheduler")
    args = ap.parse_args()
    from dask.distributed import Client, LocalCluster

    if args.scheduler:
        client = Client(args.scheduler)
    else:
        client = Client(LocalCluster(n_workers=args.workers, threads_per_worker=1))
    report = run_on_dask(client, args.campaign, args.out, args.shards)
    print(f"merged {report['runs']} of {report['expected']} runs into {report['out']}")


if __name__ == "__main__":
    main()
