"""The executor interface (boundest.parallel) on a Dask LocalCluster on loopback: pavings and
batches identical to in-process runs, a worker killed mid-run, a failing input named.

The cluster (2 worker processes, 1 thread each) is started and closed by this module."""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest

from boundest.expr import Var
from boundest.interval import Interval
from boundest.parallel import TaskError, client_executor, map_chunked, run_batch
from boundest.paving import Subpaving, image, sivia

distributed = pytest.importorskip("distributed")

#: Dask LocalClusters of worker processes: slow, run by `pytest -m slow` (and CI)
pytestmark = pytest.mark.slow

X, Y, Z = Var("x"), Var("y"), Var("z")
SHELL = {"f": X**2 + Y**2 + Z**2 + 0.5 * X * Y, "y": Interval([1], [4])}
CUBE = Interval([-3, -3, -3], [3, 3, 3])


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       host="127.0.0.1", dashboard_address=None)
    cl = distributed.Client(cluster)
    try:
        yield cl
    finally:
        cl.close()
        cluster.close()


def _same(a: Subpaving, b: Subpaving) -> None:
    """Bit-identical boxes, labels and outside boxes, in the same order."""
    assert a.boxes.shape == b.boxes.shape
    assert np.array_equal(a.boxes.lo, b.boxes.lo) and np.array_equal(a.boxes.hi, b.boxes.hi)
    assert np.array_equal(a.inside, b.inside)
    assert np.array_equal(a.outside.lo, b.outside.lo)
    assert np.array_equal(a.outside.hi, b.outside.hi)


def _satellite_row(seed: int) -> dict:
    """One simulated satellite trajectory (Jaulin 2002) estimated by the CSP's fixed point."""
    from boundest.scenarios import satellite as sat

    truth, meas = sat.simulate(30, seed=seed)
    res = sat.solve(meas, progress=False)
    inside = bool(((res.x_lo <= truth) & (truth <= res.x_hi)).all())
    return {"seed": seed, "x_lo": res.x_lo, "x_hi": res.x_hi, "consistent": res.consistent,
            "truth_inside": inside}


def _fails_on_3(v: int) -> float:
    if v == 3:
        raise ZeroDivisionError("three is not welcome")
    return v / 2


def _slow_square(v: float) -> float:
    time.sleep(0.05)
    return v * v


def test_sivia_on_cluster_is_the_in_process_paving(client):
    ref = sivia(CUBE, eps=0.25, keep_outside=True, **SHELL)
    on2 = sivia(CUBE, eps=0.25, keep_outside=True, executor=client.get_executor(), split=256,
                tasks=16, **SHELL)
    with ThreadPoolExecutor(1) as one:
        on1 = sivia(CUBE, eps=0.25, keep_outside=True, executor=one, split=256, tasks=16,
                    **SHELL)
    _same(on2, on1)  # any number of workers: the same arrays, in the same order
    _same(on2.sorted(), ref.sorted())  # the in-process boxes, neither lost nor duplicated
    assert {k: on2.stats[k] for k in ref.stats} == ref.stats
    assert on2.stats["parallel"]["tasks"] == 16 and len(on2.stats["parallel"]["task_s"]) == 16
    assert len(ref) > 1000 and ref.stats["iterations"] > 8  # the split did happen
    # the merged paving has no holes: its volume is the in-process one, and points are
    # classified the same
    pts = np.random.default_rng(0).uniform(-3, 3, (2000, 3))
    assert np.array_equal(on2.contains(pts), ref.contains(pts))


def test_sivia_small_paving_never_leaves_the_process(client):
    ref = sivia(CUBE, eps=1.0, **SHELL)
    got = sivia(CUBE, eps=1.0, executor=client.get_executor(), **SHELL)  # split 16384: not hit
    _same(got, ref)


def test_sivia_refuses_max_boxes_with_an_executor():
    with ThreadPoolExecutor(1) as ex, pytest.raises(ValueError, match="max_boxes"):
        sivia(CUBE, eps=0.1, max_boxes=100, executor=ex, **SHELL)


def test_batch_on_cluster_is_the_in_process_table(client):
    seeds = list(range(6))
    ref = run_batch(_satellite_row, seeds, progress=False)
    got = run_batch(_satellite_row, seeds, client.get_executor(), chunk=2, progress=False)
    assert list(got) == ["seed", "x_lo", "x_hi", "consistent", "truth_inside"]
    for k in ref:
        assert np.array_equal(ref[k], got[k]), k
    assert got["seed"].tolist() == seeds and got["x_lo"].shape == (6, 32, 4)
    assert got["truth_inside"].all() and got["consistent"].all()
    assert set(got.to_json()) == set(ref)


def test_process_pool_gives_the_same_table():
    with ProcessPoolExecutor(2) as ex:
        got = run_batch(abs, [-1.5, 2.0, -3.0, 0.0, -0.25], ex, chunk=2, progress=False)
    assert got["value"].tolist() == [1.5, 2.0, 3.0, 0.0, 0.25]


@pytest.mark.parametrize("where", ["in-process", "cluster"])
def test_failing_input_is_named(client, where):
    ex = None if where == "in-process" else client.get_executor()
    with pytest.raises(TaskError) as info:
        run_batch(_fails_on_3, [0, 1, 2, 3, 4, 5], ex, chunk=2, progress=False)
    err = info.value
    assert err.index == 3 and err.input_repr == "3"
    assert "ZeroDivisionError: three is not welcome" in str(err)
    assert str(err).startswith("input 3 (3) failed")
    assert "_fails_on_3" in err.worker_traceback


def test_unpicklable_task_is_named():
    with ProcessPoolExecutor(1) as ex, pytest.raises(TaskError, match="could not run"):
        map_chunked(lambda v: v, [1, 2], ex, chunk=1)


def test_scheduler_without_distributed_says_what_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(RuntimeError, match=r"pip install 'boundest\[distributed\]'"):
        client_executor("tcp://127.0.0.1:1")


def _kill_one_worker_mid_run(client, job):
    """Run ``job()`` in a thread; once both workers are busy, SIGKILL one worker process;
    return the job's result and whether the killed worker had a task running."""
    result: dict = {}
    thread = threading.Thread(target=lambda: result.setdefault("value", job()))
    pids = client.run(os.getpid)
    thread.start()
    busy = {}
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        busy = {w: t for w, t in client.processing().items() if t}
        if len(busy) == 2:
            break
        time.sleep(0.01)
    victim = sorted(busy)[0] if busy else sorted(pids)[0]
    os.kill(pids[victim], signal.SIGKILL)
    thread.join(timeout=120)
    assert not thread.is_alive()
    return result["value"], bool(busy)


def test_worker_killed_mid_run_loses_and_duplicates_nothing(client):
    ref = sivia(CUBE, eps=0.1, **SHELL)
    ex = client.get_executor()
    got, was_busy = _kill_one_worker_mid_run(
        client, lambda: sivia(CUBE, eps=0.1, executor=ex, split=512, tasks=64, **SHELL))
    assert was_busy
    _same(got.sorted(), ref.sorted())
    assert {k: got.stats[k] for k in ref.stats} == ref.stats

    client.wait_for_workers(2, timeout=60)  # the nanny restarts the killed worker
    values = [float(v) for v in range(40)]
    table, was_busy = _kill_one_worker_mid_run(
        client, lambda: run_batch(_slow_square, values, client.get_executor(), chunk=2,
                                  progress=False))
    assert was_busy
    assert table["value"].tolist() == [v * v for v in values]


def test_pool_monte_carlo_on_cluster_is_the_in_process_count(client):
    from boundest.scenarios.pool_mc import pool_monte_carlo

    # short missions (120 pings, 1.5 windows): one batch of two in-process, two tasks of one
    ref = pool_monte_carlo(2, chunk=2, n_samples=120, progress=False)
    got = pool_monte_carlo(2, chunk=1, n_samples=120, executor=client.get_executor(),
                           progress=False)
    for k in ("inside", "windows_ok", "inside_when_ok", "window_probability", "t"):
        assert np.array_equal(getattr(ref, k), getattr(got, k)), k
    assert got.empty_steps == ref.empty_steps and got.missions == 2
    assert (got.inside_when_ok == got.windows_ok).all()  # the guarantee, mission by mission
    lo, hi = got.ci()
    freq = got.frequency()
    assert ((lo <= freq) & (freq <= hi)).all()


def _ring_image(x: Interval) -> Interval:
    """``x -> 3 (sin(x1 + x2), cos(x1 + x2))`` (Jaulin et al. 2001, equation 21), vectorised."""
    from boundest import interval as iv

    s = x[:, 0] + x[:, 1]
    a, b = 3 * iv.sin(s), 3 * iv.cos(s)
    return Interval.trusted(np.stack([a.lo, b.lo], 1), np.stack([a.hi, b.hi], 1))


def test_image_on_cluster_is_the_in_process_image(client):
    v = Subpaving.from_box(Interval([-1.0, -1.0], [1.0, 1.0]))
    ref = image(v, _ring_image, eps=0.02)
    on2 = image(v, _ring_image, eps=0.02, executor=client.get_executor(), split=64, tasks=8)
    with ThreadPoolExecutor(1) as one:
        on1 = image(v, _ring_image, eps=0.02, executor=one, split=64, tasks=8)
    _same(on2, on1)
    _same(on2, ref)  # pave() sorts its cells: the same subpaving, box for box
    assert on2.stats == ref.stats and ref.stats["bisected"] > 64  # the split did happen
    # sound: images of sampled points of V lie in the paving
    pts = np.random.default_rng(1).uniform(-1, 1, (3000, 2))
    s = pts.sum(1)
    assert (on2.contains(np.stack([3 * np.sin(s), 3 * np.cos(s)], 1)) >= 0).all()
    # a budget that binds: each part gets its share, still an enclosure, same on any workers
    small = image(v, _ring_image, eps=0.02, max_boxes=200, executor=client.get_executor(),
                  split=64, tasks=8)
    with ThreadPoolExecutor(2) as two:
        _same(small, image(v, _ring_image, eps=0.02, max_boxes=200, executor=two, split=64,
                           tasks=8))
    assert (small.contains(np.stack([3 * np.sin(s), 3 * np.cos(s)], 1)) >= 0).all()
