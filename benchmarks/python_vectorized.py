#!/usr/bin/env python3
"""A density function of numpy arrays from Python: `Tileset.query(..., vectorized=True)` against the same
function called point by point, in smooth mode at 1, 3 and 12 times the built-in set's top level (past it,
tiles hand over to their subtiles and their ancestors' points are read ahead); then three classes, two of
them such functions and one a constant, at 1 and 3 times the top level. The region shrinks as the scale
grows, so each query holds about 450,000 points.

Usage: PYTHONPATH=build/python /usr/bin/python3 benchmarks/python_vectorized.py [--runs 3]
Prints the fastest of --runs interleaved runs as a markdown table.
"""
import argparse
import time

import numpy as np

import kdm


def bump(x, y):
    return 0.6 + 0.4 * np.exp(-((x - 2.0) ** 2 + (y - 2.0) ** 2) / 4.0)


def ramp(x, y):
    # Held at its ends: smooth mode reads a little outside the region, where the bound must hold too.
    return 0.1 + 0.05 * np.clip(x, 0.0, 4.0)


def measure(tiles, runs, label, times_top, **kwargs):
    """Prints the row of one query, point by point and vectorized."""
    top = tiles.info["max_points_per_tile"]
    side = 4.0 / np.sqrt(times_top)
    rect = (2 - side / 2, 2 - side / 2, 2 + side / 2, 2 + side / 2)
    best = {False: float("inf"), True: float("inf")}
    points = 0
    for _ in range(runs):
        for vectorized in (False, True):
            t0 = time.perf_counter()
            r = tiles.query(rect, scale=times_top * top, mode="smooth", vectorized=vectorized, **kwargs)
            best[vectorized] = min(best[vectorized], time.perf_counter() - t0)
            points = len(r)
    print("| %s | %s | %.3f | %.3f | %.1f× |" % (
        label, f"{points:,}", best[False], best[True], best[False] / best[True]))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=3)
    runs = parser.parse_args().runs
    tiles = kdm.Tileset.builtin()
    print("| scale | points | point by point (s) | vectorized (s) | speedup |")
    print("|---|---|---|---|---|")
    for times_top in (1, 3, 12):
        measure(tiles, runs, "%d× the top level" % times_top, times_top, density=bump, density_max=1.0)
    # Three classes summing to at most 1.0, as the one density's bump.
    for times_top in (1, 3):
        measure(tiles, runs, "3 classes, %d× the top level" % times_top, times_top,
                classes=[lambda x, y: 0.5 * bump(x, y), 0.2, ramp], density_max=[0.5, None, 0.3])


if __name__ == "__main__":
    main()
