"""kdm: blue-noise point sets from Fattal's kernel density model (SIGGRAPH 2011).

- ``kdm.sample(n, density)``: exactly n points from the full sampler (``kdm sample``).
- ``kdm.BlueNoise(d, seed=...)``: the same as a SciPy QMC engine (``scipy.stats.qmc.QMCEngine``).
- ``kdm.Tileset.builtin().query(rect, scale=...)``: the runtime, points of any region in real time
  (``kdm query``); ``kdm.DensityMap(array, rect)`` prepares a map once for many chunk queries;
  ``kdm.bake(recipe)`` bakes tile sets.
- ``kdm.stipple(image)``: an image as dots (``kdm stipple``), ``kdm.separate(image)`` its inks;
  ``kdm.analyze(points)``: point-set metrics (``kdm analyze``).

Arrays in are converted to float64 as needed; 2-D density and image arrays have row 0 at the top, as
pictures are stored. Wrong types raise TypeError, bad values ValueError, unreadable files OSError (as
open() raises it: FileNotFoundError for a missing file, IsADirectoryError for a directory). The
C++ work runs with the GIL released, so Python threads sample and query in parallel; Ctrl-C stops a long
sample, bake, analysis or full stipple within its current step.
"""
from typing import Any as _Any, List as _List

from . import _kdm
from ._analysis import analyze
from ._runtime import DensityMap, QueryResult, Tileset, bake
from ._sampling import sample
from ._stipple import Ink, separate, stipple, zoom_regions

__version__: str = _kdm.__version__

__all__ = [
    "BlueNoise", "DensityMap", "Ink", "QueryResult", "Tileset", "analyze", "bake", "sample", "separate", "stipple", "zoom_regions",
    "__version__",
]


def __getattr__(name: str) -> _Any:
    # BlueNoise subclasses SciPy's QMCEngine when SciPy is installed: loaded on first use, so that
    # `import kdm` does not import scipy.stats.
    if name == "BlueNoise":
        from ._engine import BlueNoise

        globals()["BlueNoise"] = BlueNoise
        return BlueNoise
    raise AttributeError(f"module 'kdm' has no attribute {name!r}")


def __dir__() -> _List[str]:
    # The names loaded on first use (__getattr__) are listed before they are loaded, without loading them.
    return sorted(set(globals()) | set(__all__))
