"""A campaign spread over a Dask cluster: one shard per task, merged at the end.

    python dask_campaign.py CAMPAIGN.toml OUT_DIR [--seeds N] [--shards N] [--workers N]
    python dask_campaign.py --example OUT_DIR --seeds 2     # a small built-in campaign

Needs dask.distributed (`pip install "plumetrace[dask]"`). With no scheduler address it starts
a `LocalCluster`; on a Slurm cluster, make the client from dask-jobqueue instead:

    from dask_jobqueue import SLURMCluster
    cluster = SLURMCluster(cores=8, memory="16GB", walltime="02:00:00")
    cluster.scale(jobs=4)
    client = Client(cluster)

Each shard runs in its own directory (`OUT_DIR/shards/K-of-N`); a shard that fails or is
killed keeps what it finished, and running the script again resumes every shard. The merged
campaign is `OUT_DIR/merged`.
"""

import argparse
import os
import sys

import plumetrace

EXAMPLE = """
name = "dask-example"
seed = 5
seeds = 4
scenarios = ["demo"]
[[configs]]
name = "along-flow"
[configs.set]
declaration = "along_flow"
mapping = false
[[configs]]
name = "crossflow-aware"
[configs.set]
declaration = "along_and_cross_flow"
mapping = false
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaign", nargs="?", help="the campaign file (or --example)")
    ap.add_argument("out")
    ap.add_argument("--example", action="store_true", help="run a small built-in campaign")
    ap.add_argument("--seeds", type=int, help="seeds per group (overrides the file's)")
    ap.add_argument("--shards", type=int, default=4)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--scheduler", help="address of a running Dask scheduler")
    args = ap.parse_args()
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        sys.exit("this example needs dask.distributed: pip install 'plumetrace[dask]'")
    import plumetrace.dask

    file = args.campaign
    if args.example:
        os.makedirs(args.out, exist_ok=True)
        file = os.path.join(args.out, "campaign.toml")
        with open(file, "w") as f:
            f.write(EXAMPLE)
    elif file is None:
        ap.error("give a campaign file or --example")
    if args.scheduler:
        client = Client(args.scheduler)
    else:
        client = Client(LocalCluster(n_workers=args.workers, threads_per_worker=1,
                                     dashboard_address=None))
    with client:
        report = plumetrace.dask.run_on_dask(client, file, args.out, args.shards,
                                             seeds=args.seeds)
    print(f"merged {report['runs']} of {report['expected']} runs into {report['out']}")
    runs = plumetrace.read_runs(report["out"])
    if hasattr(runs, "groupby"):
        print(runs.groupby("config")["success"].mean() if "success" in runs else runs.head())


if __name__ == "__main__":
    main()
