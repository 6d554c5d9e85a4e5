"""The Dask executor on a 2-worker LocalCluster gives the local executor's results bit for bit."""

from __future__ import annotations

import pytest

from mitos_cli.study import run_study

distributed = pytest.importorskip("distributed")

from test_study_core import fake_sim, small_study  # noqa: E402


@pytest.fixture(scope="module")
def client():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as c:
        yield c


def test_dask_equals_local_bit_for_bit(tmp_path, client):
    study = small_study(runs=8)
    local = run_study(study, tmp_path / "local", workers=2, task_fn=fake_sim)
    dask = run_study(study, tmp_path / "dask", executor="dask", client=client, task_fn=fake_sim)
    assert dask.executed == len(dask.rows) == 48
    assert dask.rows == local.rows                      # floats compared exactly


def test_dask_resume_skips_finished(tmp_path, client):
    study = small_study(runs=4)
    half = small_study(runs=2)
    run_study(half, tmp_path, executor="dask", client=client, task_fn=fake_sim)
    out = run_study(study, tmp_path, executor="dask", client=client, resume=True,
                    task_fn=fake_sim)
    assert (out.skipped, out.executed) == (12, 12)
    assert out.rows == run_study(study, tmp_path / "fresh", workers=1, task_fn=fake_sim).rows
