#!/usr/bin/env python3
"""A density function of numpy arrays from Python: `Tileset.query(..., vectorized=True)` against the same
function called point by point, in smooth mode at 1, 3 and 12 times the built-in set's top level (past it,
tiles hand over to their subtiles and their ancestors' points are read ahead). The region shrinks as the
scale grows, so each query holds about 450,000 points.

Usage: PYTHONPATH=build/python /usr/bin/python3 benchmarks/python_vectorized.py [--runs 3]
Prints the fastest of --runs interleaved runs as a markdown table.
"""
import argparse
import time

import numpy as np

import kdm


def bump(x, y):
    return 0.6 + 0.4 * np.exp(-((x - 2.0) ** 2 + (y - 2.0) ** 2) / 4.0)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=3)
    runs = parser.parse_args().runs
    tiles = kdm.Tileset.builtin()
    top = tiles.info["max_points_per_tile"]
    print("| scale | points | point by point (s) | vectorized (s) | speedup |")
    print("|---|---|---|---|---|")
    for times_top in (1, 3, 12):
        side = 4.0 / np.sqrt(times_top)
        rect = (2 - side / 2, 2 - side / 2, 2 + side / 2, 2 + side / 2)
        best = {False: float("inf"), True: float("inf")}
        points = 0
        for _ in range(runs):
            for vectorized in (False, True):
                t0 = time.perf_counter()
                r = tiles.query(rect, scale=times_top * top, density=bump, density_max=1.0, mode="smooth",
                                vectorized=vectorized)
                best[vectorized] = min(best[vectorized], time.perf_counter() - t0)
                points = len(r)
        print("| %d× the top level | %s | %.3f | %.3f | %.1f× |" % (
            times_top, f"{points:,}", best[False], best[True], best[False] / best[True]))


if __name__ == "__main__":
    main()
