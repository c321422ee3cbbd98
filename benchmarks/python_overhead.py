#!/usr/bin/env python3
"""The Python package's overhead, against the same C++ work timed in the same process and build
(kdm._kdm.time_sample, kdm._kdm.time_query):

- kdm.sample(65536) against gen::sample (target: at most 5% slower);
- a query of about 10^6 points into numpy against tools::query_all into a new vector, as `kdm query` runs
  it, and against query_points into a buffer reused from an earlier call, as runtime_benchmark runs it
  (target: at least 0.5 of the C++ speed);
- two Python threads sampling at once (threads=1 each) against one (target: at most 0.6 of twice one's
  time, i.e. the GIL does not serialise them).

Usage: PYTHONPATH=build-py/python /usr/bin/python3 benchmarks/python_overhead.py [--runs 5]
Prints medians of --runs runs as a markdown table.
"""
import argparse
import os
import platform
import statistics
import threading
import time

import kdm
from kdm import _kdm


def wall(call):
    t0 = time.perf_counter()
    call()
    return time.perf_counter() - t0


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def two_at_once(call):
    start = threading.Barrier(2)

    def work():
        start.wait()
        call()

    threads = [threading.Thread(target=work) for _ in range(2)]
    t0 = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return time.perf_counter() - t0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    runs = range(args.runs)
    median = statistics.median
    rows = []

    kdm.sample(65536)  # warm up: thread teams, page cache
    py, cpp = [], []
    for _ in runs:  # interleaved, so that a change in the machine's load falls on both
        py.append(wall(lambda: kdm.sample(65536, seed=1)))
        cpp.append(_kdm.time_sample(65536, 1, 0))
    rows.append(("kdm.sample(65536), default threads", median(cpp), median(py),
                 f"{median(py) / median(cpp) - 1:+.1%} time", "at most +5%"))

    tiles = kdm.Tileset.builtin()
    for mode in ("stable", "smooth"):
        query = lambda: tiles.query((0, 0, 8, 8), scale=15625, mode=mode)  # noqa: E731
        previous = query()
        points = len(previous)
        refill = lambda: tiles.query((0, 0, 8, 8), scale=15625, mode=mode, out=previous)  # noqa: E731
        py, again, cpp = [], [], []
        for _ in runs:
            py.append(wall(query))
            # As time_query's reused buffer, which it touches just before timing: on this kind of virtual
            # machine memory left untouched while 80 MB of other memory was written refills up to 10x slower.
            refill()
            again.append(wall(refill))
            cpp.append(_kdm.time_query(tiles._handle, 8, 8, 15625, mode == "smooth"))
        fresh, reused = median(c[0] for c in cpp), median(c[1] for c in cpp)
        rows.append((f"query, {points:,} points, {mode}: new arrays vs query_all (new vector)", fresh,
                     median(py), f"{fresh / median(py):.2f} of C++ speed", "at least 0.5"))
        rows.append((f"query, {points:,} points, {mode}: new arrays vs a reused buffer", reused, median(py),
                     f"{reused / median(py):.2f} of C++ speed", "–"))
        rows.append((f"query, {points:,} points, {mode}: `out=` an earlier result vs a reused buffer", reused,
                     median(again), f"{reused / median(again):.2f} of C++ speed", "at least 0.5"))

    one, two = [], []
    for _ in runs:
        one.append(wall(lambda: kdm.sample(65536, seed=1, threads=1)))
        two.append(two_at_once(lambda: kdm.sample(65536, seed=1, threads=1)))
    rows.append(("two threads sampling 65536 (threads=1 each) vs one", 2 * median(one), median(two),
                 f"{median(two) / (2 * median(one)):.2f} of twice one", "at most 0.6"))

    load = ", load average %.2f %.2f %.2f" % os.getloadavg() if hasattr(os, "getloadavg") else ""
    print(f"{cpu_model()}, {os.cpu_count()} CPUs{load}, Python {platform.python_version()}, "
          f"kdm {kdm.__version__}, {time.strftime('%Y-%m-%d')}, medians of {args.runs} runs\n")
    print("| measure | C++ (s) | Python (s) | result | target |")
    print("|---|---|---|---|---|")
    for name, c, p, result, target in rows:
        print(f"| {name} | {c:.4f} | {p:.4f} | {result} | {target} |")


if __name__ == "__main__":
    main()
