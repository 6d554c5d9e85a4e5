"""The Dask executor on a 2-worker LocalCluster gives the local executor's results bit for bit."""

from __future__ import annotations

import pytest

from mitos_cli.study import run_study

distributed = pytest.importorskip("distributed")

from test_study_cli import TINY  # noqa: E402
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


def test_real_simulator_on_dask_equals_serial(tmp_path, client):
    from mitos_cli.study import Study, make_choices

    world = tmp_path / "tiny.yaml"
    world.write_text(TINY)
    study = Study([str(world)], make_choices(["fuzzy", "potential_field"], ["product"], [], []),
                  runs=2, seed=5)
    serial = run_study(study, tmp_path / "serial", workers=1)
    dask = run_study(study, tmp_path / "dask", executor="dask", client=client)
    assert dask.rows == serial.rows and len(serial.rows) == 4


def test_dask_resume_skips_finished(tmp_path, client):
    study = small_study(runs=4)
    half = small_study(runs=2)
    run_study(half, tmp_path, executor="dask", client=client, task_fn=fake_sim)
    out = run_study(study, tmp_path, executor="dask", client=client, resume=True,
                    task_fn=fake_sim)
    assert (out.skipped, out.executed) == (12, 12)
    assert out.rows == run_study(study, tmp_path / "fresh", workers=1, task_fn=fake_sim).rows


def test_unreachable_scheduler_is_a_clear_error():
    from mitos_cli.study.executors import dask_client
    from mitos_cli.study.store import StudyError

    with pytest.raises(StudyError) as exc:
        dask_client("tcp://127.0.0.1:9", 2, timeout="0.5s")
    assert "cannot reach the Dask scheduler at tcp://127.0.0.1:9" in exc.value.message
    assert "dask scheduler" in exc.value.hint
