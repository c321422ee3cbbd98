"""The GIL is released while C++ works: Python threads sample, query, stipple and analyse at once and get
what one thread gets. (Speed is measured in benchmarks/python_overhead.py, never asserted here.)"""
import threading

import numpy as np
import pytest

import kdm
from conftest import SPHERE


def run_together(*jobs):
    """Runs each job on its own thread, all started together; returns their results in order."""
    results = [None] * len(jobs)
    errors = []
    start = threading.Barrier(len(jobs))

    def work(i, job):
        try:
            start.wait()
            results[i] = job()
        except BaseException as e:  # re-raised below, on the test's thread
            errors.append(e)

    threads = [threading.Thread(target=work, args=(i, job)) for i, job in enumerate(jobs)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert not any(t.is_alive() for t in threads), "a thread did not finish"
    if errors:
        raise errors[0]
    return results


def test_two_samplers_at_once_equal_one_at_a_time():
    alone = [kdm.sample(20000, seed=s, threads=1) for s in (1, 2)]
    together = run_together(lambda: kdm.sample(20000, seed=1, threads=1),
                            lambda: kdm.sample(20000, seed=2, threads=1))
    assert all(np.array_equal(a, b) for a, b in zip(alone, together))


def separate_many_times():
    for _ in range(15):  # 8 inks clustered from every pixel: about 0.02 s a call
        kdm.separate(str(SPHERE.parent / "coffee.png"), colours="8")


@pytest.mark.parametrize("work", [lambda: kdm.sample(30000, threads=1), separate_many_times],
                         ids=["sample", "separate"])
def test_the_gil_is_free_while_cpp_works(work):
    # A counting thread keeps running Python while this one samples (or separates an image's colours).
    # Were the GIL held, it would count for at most a switch interval (5 ms) around each call; a quarter of
    # its free-running rate over the whole work separates the two by a factor of 10 or more.
    import time
    done = threading.Event()
    count = [0]

    def counter():
        while not done.is_set():
            count[0] += 1

    thread = threading.Thread(target=counter)
    thread.start()
    try:
        c0, t0 = count[0], time.perf_counter()
        time.sleep(0.1)  # sleeping releases the GIL: the counter's free-running rate
        rate = (count[0] - c0) / (time.perf_counter() - t0)
        c0, t0 = count[0], time.perf_counter()
        work()
        during = count[0] - c0
        elapsed = time.perf_counter() - t0
    finally:
        done.set()
        thread.join()
    assert elapsed > 0.1 and during > 0.25 * rate * elapsed


def test_queries_stipples_and_analyses_at_once():
    tiles = kdm.Tileset.builtin()
    jobs = [
        lambda: tiles.query((0, 0, 6, 6), scale=3000, mode="smooth").xy,
        lambda: tiles.query((0, 0, 6, 6), scale=3000, density="ramp:8").xy,
        lambda: kdm.stipple(str(SPHERE), points=5000),
        lambda: kdm.analyze(kdm.sample(3000, seed=3), energy=False)["nearest_neighbour"]["davg"],
    ]
    alone = [job() for job in jobs]
    together = run_together(*jobs)
    assert all(np.array_equal(a, b) for a, b in zip(alone, together))


def _sample_and_analyse(seed):
    points = kdm.sample(3000, seed=seed, threads=2)
    return points, kdm.analyze(points, threads=2)["nearest_neighbour"]["davg"]


def test_forked_workers_sample_and_analyse_with_threads():
    # multiprocessing's default start method on Linux forks a process whose threads are gone: a child must
    # not wait for the parent's workers. The parent's own threads run first so that there are some.
    multiprocessing = pytest.importorskip("multiprocessing")
    expected = [_sample_and_analyse(s) for s in (1, 2)]
    with multiprocessing.get_context("fork").Pool(2) as pool:
        got = pool.map_async(_sample_and_analyse, [1, 2]).get(timeout=120)  # a hang fails, not blocks
    for (points, davg), (want_points, want_davg) in zip(got, expected):
        assert np.array_equal(points, want_points)
        assert davg == want_davg
