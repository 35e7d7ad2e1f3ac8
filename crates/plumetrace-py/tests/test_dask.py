"""A campaign's shards on a Dask LocalCluster of two workers equal one local run."""

import pytest

import plumetrace

distributed = pytest.importorskip("dask.distributed")
import plumetrace.dask  # noqa: E402

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
            report = plumetrace.dask.run_on_dask(client, f, tmp_path / "dask", shards=3)
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


def test_the_number_of_seeds_is_chosen_per_call(tmp_path):
    f = tmp_path / "c.toml"
    f.write_text(CAMPAIGN)
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                       dashboard_address=None)
    try:
        with distributed.Client(cluster) as client:
            report = plumetrace.dask.run_on_dask(client, f, tmp_path / "d", shards=2, seeds=1)
    finally:
        cluster.close()
    assert report["runs"] == report["expected"] == 2
