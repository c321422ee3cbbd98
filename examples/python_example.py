"""kdm from Python: sample, query, stipple, and the spectrum of a point set (plotted with matplotlib when it
is installed). Run from the checkout after scripts/install-python:

    /usr/bin/python3 examples/python_example.py [output folder]
"""
import sys
from pathlib import Path

import numpy as np

import kdm

here = Path(__file__).resolve().parent
out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
out.mkdir(parents=True, exist_ok=True)

# 1. The full sampler: exactly 4096 points, uniform on the torus, then following a picture's darkness.
points = kdm.sample(4096, seed=1)
shaded = kdm.sample(8192, str(here / "sphere.png"))
print(f"sample: {points.shape} uniform, {shaded.shape} following sphere.png")

# 2. The runtime: the points of a world region from the built-in tile set, with stable ids. Split the
# region any way you like: the parts hold exactly the whole region's points. Rocks at 2 per m² where the
# density is 1, rising from 0.2 to 1 across 200 m: 32 m tiles expect 410 to 2,048 points each (README).
tiles = kdm.Tileset.builtin()
density = lambda x, y: 0.2 + 0.8 * x / 200  # noqa: E731
rocks = tiles.query((0, 0, 200, 200), scale=2, tile_size=32, density=density, density_max=1.0)
print(f"query: {len(rocks)} points, ids like tile {tuple(rocks.tile[0])} rank {rocks.rank[0]}")
# A function of numpy arrays reads many positions a call (vectorized=True): the same points, faster.
hills = lambda x, y: 0.6 + 0.4 * np.sin(x / 20) * np.cos(y / 30)  # noqa: E731
bushes = tiles.query((0, 0, 200, 200), scale=2, tile_size=32, density=hills, density_max=1.0, vectorized=True)
print(f"query: {len(bushes)} bushes on the hills")

# Several kinds at once, as float32 positions (the fast path): trees first (the largest), then rocks.
xy, kinds = tiles.positions((0, 0, 200, 200), scale=2, tile_size=32, classes=[0.1, 0.4])
print(f"positions: {len(xy)} points, {np.count_nonzero(kinds == 0)} trees")

# A painted map streamed chunk by chunk: prepared once (kdm.DensityMap), each chunk costs what its own
# points do; the chunks hold exactly the whole region's points.
forest = kdm.DensityMap(np.random.default_rng(1).random((256, 256)), rect=(0, 0, 200, 200))
chunks = [tiles.positions((x, y, x + 50, y + 50), scale=2, tile_size=32, density=forest)
          for x in range(0, 200, 50) for y in range(0, 200, 50)]
print(f"chunks: {sum(len(c) for c in chunks)} points in 16 chunks of a painted map")

# 3. Stippling a picture to PNG with the runtime's tiles, in grey and in colour (an ink per class).
dots = kdm.stipple(str(here / "sphere.png"), points=10000, output=out / "sphere-dots.png")
print(f"stipple: {len(dots)} dots -> {out / 'sphere-dots.png'}")
channels, inks = kdm.separate(here / "coffee.png", colours="cmyk")
dots, ink_of_dot, _ = kdm.stipple(str(here / "coffee.png"), points=20000, colours="cmyk",
                                  output=out / "coffee-dots.png")
print(f"stipple: inks {inks}, mean coverage {np.round(channels.mean(axis=(1, 2)), 2)} -> {out / 'coffee-dots.png'}")

# 4. The measures `kdm analyze` reports; the radially averaged power spectrum of blue noise is low at low
# frequencies, then a peak near the mean spacing's frequency.
metrics = kdm.analyze(points, energy=False)
spectrum = metrics["spectrum"]
print(f"analyze: δmin {metrics['nearest_neighbour']['dmin']:.3f}, lowP {spectrum['low_p']:.3f}")

# 5. As a SciPy QMC engine (scipy.stats.qmc), when SciPy is installed.
try:
    from scipy.stats import qmc
except ImportError:
    qmc = None
if qmc is not None:
    engine = kdm.BlueNoise(d=2, seed=np.random.default_rng(7))
    print(f"BlueNoise: centred discrepancy {qmc.discrepancy(engine.random(1024)):.2e}")

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: no plot")
else:
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4.5))
    left.scatter(points[:, 0], points[:, 1], s=1, c="black")
    left.set_aspect("equal")
    left.set_title("kdm.sample(4096)")
    right.plot(spectrum["raps_f"], spectrum["raps"])
    right.set_xlabel("frequency |k| / sqrt(n)")
    right.set_ylabel("radially averaged power")
    right.set_title("spectrum")
    fig.savefig(out / "spectrum.png", dpi=100)
    print(f"plot -> {out / 'spectrum.png'}")
