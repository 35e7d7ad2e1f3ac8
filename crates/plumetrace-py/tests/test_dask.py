"""A campaign's shards on a Dask LocalCluster of two workers equal one local run."""

import pathlib
import sys

import pytest

import plumetrace

distributed = pytest.importorskip("dask.distributed")
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "examples"))
import dask_campaign  # noqa: E402

CAMPAIGN = """
name = "py-dask"
seed = 5
seeds = 2
scenarios = ["demo"]
[[configs]]
name = "paper"
[configs.set]
declaration = "along_flow"
mapping = false
[[configs]]
name = "crossflow-aware"
[configs.set]
declaration = "along_and_cross_flow"
mapping = false
"""


def test_shards_on_two_dask_workers_merge_to_the_local_campaign(tmp_path):
    f = tmp_path / "c.toml"
    f.write_text(CAMPAIGN)
    local = plumetrace.campaign(f, tmp_path / "local", jobs=2, progress=False)
    assert local["ran"] == 4 and local["failed"] == 0
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    try:
        with distributed.Client(cluster) as client:
            report = dask_campaign.run_on_dask(client, str(f), str(tmp_path / "dask"), shards=3)
    finally:
        cluster.close()
    assert report["runs"] == report["expected"] == 4
    merged = (tmp_path / "dask" / "merged" / "runs.csv").read_bytes()
    assert merged == (tmp_path / "local" / "runs.csv").read_bytes()
    rows = plumetrace.read_runs(tmp_path / "dask" / "merged")
    assert len(rows) == 4


def test_a_resumed_campaign_skips_what_it_has(tmp_path):
    f = tmp_path / "c.toml"
    f.write_text(CAMPAIGN)
    seen = []
    first = plumetrace.campaign(f, tmp_path / "o", shard="1/2", progress=lambda d, t: seen.append((d, t)))
    assert first["ran"] == 2 and seen[-1] == (2, 2)
    again = plumetrace.campaign(f, tmp_path / "o", shard="1/2", progress=False)
    assert again["ran"] == 0 and again["skipped"] == 2


def test_a_bad_campaign_names_the_file(tmp_path):
    f = tmp_path / "bad.toml"
    f.write_text('name = "x"\nseeds = 0\n')
    with pytest.raises(plumetrace.PlumetraceError, match="bad.toml"):
        plumetrace.campaign(f, tmp_path / "o", progress=False)
