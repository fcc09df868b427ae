"""A batch over several volumes on dask.distributed's LocalCluster (the
python/examples/dask_batch.py pattern): each chunk equals the same views
rendered in this process. Skipped when dask.distributed is not installed
(scripts/test-python.sh installs it)."""

import pathlib
import sys

import numpy as np
import pytest

distributed = pytest.importorskip("dask.distributed")

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "examples"))

import dask_batch  # noqa: E402

import fvr  # noqa: E402


def test_local_cluster_matches_in_process():
    volumes = ["gaussians@32:1", "gaussians@32:2"]
    rotations = dask_batch.random_rotations(6, seed=3)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        images = dask_batch.render_many(client, volumes, rotations, 32, chunk=4)
    assert images.shape == (2, 6, 32, 32)
    for spec, got in zip(volumes, images):
        want = fvr.Renderer(spec).project(rotations, size=32)
        assert np.array_equal(got, want)
