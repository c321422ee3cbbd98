#!/usr/bin/env python3
"""kdm on a busy machine, as in a parallel build: wall and CPU time of `kdm sample --n 65536` and of a
small `kdm bake`, on one and on two threads, on an idle machine and with BUSY other CPU-bound processes
running (what `make -j2` does to a 2-core machine). Two threads must never be slower than one under load,
and their CPU time must stay close to one thread's: waiting threads sleep instead of spinning.

Usage: benchmarks/busy_machine.py [--kdm build/tools/kdm] [--runs 3] [--busy 2]
Prints a markdown table: the median of --runs runs of each, wall and CPU (user + system) seconds.
"""
import argparse
import multiprocessing
import os
import resource
import statistics
import subprocess
import tempfile
import time

SMALL_RECIPE = """# a small tile set: 2 colours (16 tiles), 2 levels of 32 and 128 points per tile
seed 1
colours 2
levels 2
base_points 32
sweeps 40
"""


def spin(stop):
    while not stop.is_set():
        pass


def timed(command):
    """Wall and CPU seconds of one run of `command` (its children included)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--kdm", default="build/tools/kdm")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--busy", type=int, default=2, help="CPU-bound processes sharing the machine")
    args = parser.parse_args()

    work = tempfile.mkdtemp(prefix="kdm-busy-")
    recipe = os.path.join(work, "small.recipe")
    with open(recipe, "w") as f:
        f.write(SMALL_RECIPE)
    jobs = {
        "sample --n 65536": lambda t: [args.kdm, "sample", "--n", "65536", "--seed", "5", "--threads", str(t),
                                       "-o", os.path.join(work, "s.txt")],
        "bake (16 tiles, 2 levels)": lambda t: [args.kdm, "bake", recipe, "-o", os.path.join(work, "t.kdmt"),
                                              "--threads", str(t)],
    }
    print(f"kdm on {os.cpu_count()} CPUs, {args.runs} runs each (medians); busy = {args.busy} other CPU-bound "
          f"processes; {time.strftime('%Y-%m-%d %H:%M')}")
    print()
    print("| command | machine | threads | wall s | CPU s | CPU / 1-thread CPU |")
    print("|---|---|---|---|---|---|")
    for name, command in jobs.items():
        timed(command(1))  # warm the page cache
        for load in ("idle", "busy"):
            stop = multiprocessing.Event()
            spinners = [multiprocessing.Process(target=spin, args=(stop,)) for _ in range(args.busy if load == "busy" else 0)]
            for p in spinners:
                p.start()
            try:
                results = {}
                for threads in (1, 2):
                    runs = [timed(command(threads)) for _ in range(args.runs)]
                    results[threads] = (statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs))
            finally:
                stop.set()
                for p in spinners:
                    p.join()
            for threads, (wall, cpu) in results.items():
                print(f"| {name} | {load} | {threads} | {wall:.2f} | {cpu:.2f} | {cpu / results[1][1]:.2f} |")


if __name__ == "__main__":
    main()
