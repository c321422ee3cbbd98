"""kdm.analyze: point-set metrics (docs/design.md section 6), the measures `kdm analyze` writes."""
from __future__ import annotations

import json
import warnings
import numbers
import os
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

from . import _checks, _kdm


def _arrays(value: Any) -> Any:
    """metrics.json's lists of numbers as float64 arrays, and its nulls (non-finite values) as NaN."""
    if value is None:
        return np.nan
    if isinstance(value, dict):
        return {k: _arrays(v) for k, v in value.items()}
    if isinstance(value, list):
        if all(v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)) for v in value):
            return np.array([np.nan if v is None else v for v in value], dtype=np.float64)
        return [_arrays(v) for v in value]
    return value


def _infinite_lattice(metrics: Dict[str, Any]) -> None:
    """JSON has no infinity: a lattice power ratio written as null over lattice frequencies that were
    compared is infinite (a strictly periodic set), not missing."""
    tiling = metrics.get("tiling")
    if tiling and np.isnan(tiling.get("lattice_power_ratio", 0.0)) and tiling.get("lattice_power_frequencies", 0):
        tiling["lattice_power_ratio"] = np.inf


def _class_densities(class_densities: Any, gamma: Any, invert: Any) -> List[Any]:
    """class_densities as the C++ side takes them: each a _kdm.DensitySpec or a callable (`gamma` and
    `invert` reshape image files' tones; the caller checks that some density is one)."""
    _checks.unmasked("class_densities", class_densities, "class_densities.filled(0), no density where it is masked")
    if isinstance(class_densities, np.ndarray) and class_densities.ndim == 1:  # constants, one per class
        class_densities = [float(v) for v in class_densities]
    if isinstance(class_densities, (str, bytes, numbers.Real, np.ndarray)) or not isinstance(
            class_densities, (list, tuple)):
        raise TypeError("class_densities must be a list of densities, one per class, got "
                        f"{type(class_densities).__name__}")
    out: List[Any] = []
    for k, d in enumerate(class_densities):
        name = f"class_densities[{k}]"
        if callable(d) and not isinstance(d, (np.ndarray, str)):
            _checks.density_function(name, d, 2, None)  # classes are 2-D points' labels
            out.append(d)
            continue
        text = isinstance(d, (str, os.PathLike))
        spec = _checks.density_spec(d, gamma if text else 1.0, invert if text else False, name,
                                    one_of_several=True, callable_ok=True)
        if spec is None:
            raise TypeError(f"{name} must be a number, a str, a 2-D array or a callable, got None")
        out.append(spec)
    if not any(callable(d) and not isinstance(d, _kdm.DensitySpec) or d.max_value > 0 for d in out):
        raise ValueError("class_densities: every density is zero everywhere")
    return out


def _labels(name: str, value: Any) -> np.ndarray:
    """One set's class labels as uint8. Labels are integers, as kdm.sample returns them: a float array is
    refused (TypeError) even where its values are whole, as a float count is everywhere in kdm, so that a
    density or a coordinate passed by mistake is never read as classes."""
    try:
        a = np.asarray(value)
    except ValueError as e:  # ragged nested lists
        raise ValueError(f"{name} must be an (n,) array of integer labels 0 to 255: {e}") from None
    if a.dtype.kind not in "iu":
        whole = a.dtype.kind == "f" and a.size and np.all(np.isfinite(a)) and np.all(a == np.round(a))
        hint = " (whole numbers as floats: convert them with .astype(int))" if whole else ""
        raise TypeError(f"{name} must be an (n,) array of integer labels 0 to 255, got dtype {a.dtype}{hint}")
    if a.ndim != 1 or (a.size and (a.min() < 0 or a.max() > 255)):
        raise ValueError(f"{name} must be an (n,) array of integer labels 0 to 255" + (
            f", got shape {a.shape}" if a.ndim != 1 else f", got {a.min()} to {a.max()}"))
    return np.ascontiguousarray(a, dtype=np.uint8)


def analyze(
    points: Any,
    classes: Any = None,
    *,
    box: bool = False,
    density: Any = None,
    class_densities: Any = None,
    tile_size: Optional[float] = None,
    fmax: float = 2.5,
    threads: int = 0,
    energy: bool = True,
    gamma: float = 1.0,
    invert: bool = False,
    min_expected: float = 20.0,
    density_bands: int = 10,
    holes_min_density: float = 0.0,
    aspect: Any = None,
    periodogram: bool = False,
) -> Dict[str, Any]:
    """Measure point sets as ``kdm analyze`` does, returning what it writes to metrics.json.

    Parameters
    ----------
    points : array or list of arrays
        One (n, 2) or (n, 3) set with coordinates in [0, 1], or a list of such sets (arrays or nested
        lists) of one dimension: statistics are pooled over them, as over the sets of one file; sets more
        than 10% apart in count get no spectrum (their frequencies would not line up: the result's
        "spectrum_skipped" says so).
        Distances are those of the unit square (cube), or with `aspect` of the domain the set was drawn
        in.
    classes : array or list of arrays, optional
        Labelled points (several classes, as ``kdm.sample(classes=...)`` or a class query returns them,
        so ``kdm.analyze(*kdm.sample(n, classes=...))`` works):
        each point's class, an (n,) array of integers 0 to 255 per set (a float array is a TypeError,
        whole numbers too: ``labels.astype(int)``; a label out of range a ValueError). Each class is then
        also analysed alone, as ``kdm analyze`` does a labelled file: the result's "classes" holds
        classes.json
        (``cross_class_closest`` in d_hex of all points, local ones where `density` is given, per
        class its "class" and "metrics", and in
        "too_small", an integer array, the classes present with fewer than 2 points in every set, which
        are not analysed).
    box : bool
        Bounded-box distances instead of periodic (torus) ones. An array carries no domain, unlike a
        ``.txt`` file whose header ``kdm analyze`` reads: give ``box=True`` for a bounded set
        (``kdm.stipple``'s dots, a query's points normalised to its rectangle, a sample in a box: of an
        image, array or callable, or ``domain="box"``) and `aspect` for its shape; else it is measured as
        a torus of the unit square.
    density : None, float, str, 2-D array or callable
        The target density, as kdm.sample takes it (default: uniform): for the density accuracy test,
        and the local spacing empty circles are measured in. A callable ``f(x, y)`` of coordinates in
        [0, 1] is called point by point (its exception is raised, and as kdm.sample says it, TypeError
        for a value that is no real number, ValueError for one that is not finite and >= 0). With
        `class_densities` it judges the whole set only (default there: their sum).
    class_densities : list, optional
        With `classes`: one target density per class, class 0 first, at least as many as the labels run
        (largest label + 1; the list given to ``kdm.sample(classes=...)``, whose classes of density 0 have
        no points), each anything `density` takes (a
        number, str, 2-D array or callable), as ``kdm analyze --class-density``. Each class alone is
        judged against its own (density test, bands, empty circles in its local spacings), the whole set
        against their sum unless `density` is given, and the closest pair of different classes is in local
        spacings of the sum. Only each density's shape matters to its class's test; their integrals
        together predict each class's share of the points: the result's "classes" then holds "shares", per
        class its "class", predicted "share", observed "count", "expected" count, binomial "sd" and "z"
        (a sampler that gives a class the wrong count shows a large z). ValueError for fewer densities
        than the labels run to, or a class with points whose density is zero everywhere.
    gamma, invert
        How an image file's pixels become density, as kdm.sample takes them.
    tile_size : float or None
        Tile side in unit-square units (1 / tile_size an integer) for the periodicity and seam
        statistics.
    fmax : float
        The periodogram's limit in normalised frequency |k| / sqrt(n).
    threads : int
        Worker threads (0: the default count); the results do not depend on it.
    energy : bool
        Compute E/n under the KDM model (``energy_per_point``).
    aspect : float, (x, y, z) or None
        The domain the points were drawn in, as ``kdm.sample(aspect=...)`` takes it: width / height (in
        3-D the x side over the others), or in 3-D three sides ``(x, y, z)``. The normalised points are
        measured in that box scaled to unit area (volume): spacings, nearest neighbours, g(r), holes,
        density windows and the spectrum (on the rectangle's own frequencies) are the domain's; the
        result's "sides" gives its sides. None or 1: the unit square (cube). ValueError for a side that is
        not > 0, or with `tile_size` or `classes` (square tiles and the classes' closest pair need the
        square); TypeError for a value that is no number or sequence.
    periodogram : bool
        Also return the set-averaged periodogram the spectrum's measures come from, as
        spectrum.periodogram (a key metrics.json does not hold): P(k) = |Σ_j exp(-2πi k·x_j)|² / n, a
        (2 ky_max + 1, 2 kx_max + 1) array, P(kx, ky) at row ky + ky_max and column kx + kx_max (integer
        frequencies of the unit square, over each side's length in a longer domain; NaN outside the disc
        |k| <= kmax that is computed). 2-D sets only.
    min_expected, density_bands, holes_min_density
        As ``kdm analyze --min-expected/--density-bands/--holes-min-density``: the density test's
        windows expect at least that many points; its bias table has that many bands; empty circles
        count only where the density is at least that fraction of its largest value. The last two need a
        density (`density` or `class_densities`): without one, another value than the default is a
        ValueError.

    Returns
    -------
    dict
        metrics.json's keys (inputs, dim, domain, sets, points_*, nearest_neighbour, spectrum,
        empty_circles, pair_correlation, density, tiling, energy_per_point, seconds: those that apply;
        spectrum, empty_circles, density and tiling are 2-D measures, which a 3-D set does not get), with
        its lists of numbers (spectrum.raps_f, spectrum.raps, pair_correlation.r and .g, ...) as numpy
        arrays, and its nulls as NaN, but tiling.lattice_power_ratio as inf for a strictly periodic set
        (no power off the tile lattice; NaN when no lattice frequency lies in the spectrum). The nearest-
        neighbour histogram's last bin counts every distance from histogram_max on (histogram_overflow of
        them). spectrum.nonuniform, present for a set that is not uniform, says why: its spectrum then
        measures its density's variation, not blue-noise quality. A min_expected above a set's count leaves one window (z = 0) and warns. Empty circles' rates per 10^5 points are per point their judged triangles stand for (half
        their count): with ``box=True`` circles centred within two spacings of a side are left out.
    """
    # A list whose entries are 2-D (arrays or nested lists) is several sets; else it is one set's points.
    several = isinstance(points, (list, tuple)) and len(points) > 0
    # An empty entry (np.empty((0, 2)), []) is one of several sets too, so that its error names it.
    if several and all(_checks.is_array(p) and (np.ndim(p) == 2 or np.size(p) == 0) for p in points):
        raw, names = list(points), [f"points[{i}]" for i in range(len(points))]
    else:
        raw, names = [points], ["points"]
    for name, p in zip(names, raw):
        if p is None:
            raise TypeError(f"{name} must be an (n, 2) or (n, 3) array of points, got None")
        if _checks.is_array(p) and np.asarray(p).dtype == np.bool_:
            raise TypeError(f"{name} must hold coordinates, got booleans")
        if _checks.is_array(p) and np.size(p) == 0:
            raise ValueError(f"{name} holds no points: every set needs at least 2 points")
    sets = [_checks.array2d(name, p, f"np.ma.compress_rows({name}), its points without a masked coordinate")
            for name, p in zip(names, raw)]
    for name, s in zip(names, sets):
        if s.shape[1] not in (2, 3):
            hint = f" (transposed? {name}.T has shape {s.shape[::-1]})" if s.shape[0] in (2, 3) else ""
            raise ValueError(f"{name} must be an (n, 2) or (n, 3) array of points, got shape {s.shape}{hint}")
        if s.shape[0] < 2:
            raise ValueError(f"{name} holds {s.shape[0]} point: every set needs at least 2 points")
    box = _checks.flag("box", box)
    function = None
    if class_densities is not None and classes is None:
        raise ValueError("class_densities needs classes (each point's class)")
    own = [] if class_densities is None else _class_densities(class_densities, gamma, invert)
    if own:  # gamma and invert reshape any image file among the densities (and must find one)
        text = isinstance(density, (str, os.PathLike))
        if callable(density) and not isinstance(density, (np.ndarray, str)):
            function, spec = density, None
        else:
            spec = None if density is None else _checks.sampler_density(
                density, gamma if text else 1.0, invert if text else False)
        reshaped = _checks.number("gamma", gamma, 0.0, strict=True) != 1.0 or _checks.flag("invert", invert)
        images = [d for d, given in zip(own + [spec], list(class_densities) + [density])
                  if isinstance(d, _kdm.DensitySpec) and d.kind == "image" and isinstance(given, (str, os.PathLike))]
        if reshaped and not images:
            raise ValueError("gamma and invert apply to image files only, and no density given is one")
    elif callable(density) and not isinstance(density, (np.ndarray, str)):
        if gamma != 1.0 or invert:
            raise ValueError("gamma and invert apply to image files only, and density is a function")
        function, spec = density, None
    else:
        spec = _checks.sampler_density(density, gamma, invert)
    if function is not None:  # called with the points' coordinates
        _checks.density_function("density", function, sets[0].shape[1], None)
    tile = 0.0 if tile_size is None else _checks.number("tile_size", tile_size, 0.0, strict=True)
    fmax = _checks.number("fmax", fmax, 0.0, strict=True)
    threads = _checks.threads(threads)
    energy = _checks.flag("energy", energy)
    periodogram = _checks.flag("periodogram", periodogram)
    if sets[0].shape[1] == 3 and (spec is not None or function is not None or tile_size is not None):
        warnings.warn("density windows and tiling diagnostics are 2D only; skipped (a density still sets "
                      "the energy, as kdm analyze's does)", stacklevel=2)
        tile = 0.0
    min_expected = _checks.number("min_expected", min_expected, 0.0, strict=True)
    density_bands = _checks.integer("density_bands", density_bands, 1, 1000)
    holes_min_density = _checks.number("holes_min_density", holes_min_density, 0.0)
    if spec is None and function is None and not own:  # they would do nothing: refused, as gamma is
        idle = "holes_min_density" if holes_min_density != 0 else "density_bands" if density_bands != 10 else None
        if idle:
            raise ValueError(f"{idle} applies with a density (density or class_densities), and none is given")
    if sets[0].shape[1] == 2 and isinstance(aspect, (Sequence, np.ndarray)) and not isinstance(aspect, (str, bytes)):
        raise ValueError("aspect=(x, y, z) gives a 3-D domain's sides, and the points are 2-D: give one number "
                         "(width / height)")
    one, sides = _checks.aspect_or_sides(aspect, sets[0].shape[1])
    extent = list(sides) if sides is not None else [1.0 if one is None else one, 1.0, 1.0]
    if extent[0] != extent[1] or extent[1] != extent[2]:
        if tile is not None and tile > 0:
            raise ValueError("tile_size takes square tiles of the unit square, and aspect gives another domain")
        if classes is not None:
            raise ValueError("labelled points (classes) are analysed in the unit square only: leave out aspect")
    labels = []
    if classes is not None:
        listed = several and isinstance(classes, (list, tuple))
        given = list(classes) if listed else [classes]
        if len(given) != len(sets):
            raise ValueError(f"classes must hold one array of labels per set ({len(sets)}), got {len(given)}")
        for k, c in enumerate(given):
            labels.append(_labels(f"classes[{k}]" if listed else "classes", c))
    if own:
        runs = 1 + max(int(a.max()) if a.size else -1 for a in labels)
        if runs != len(own):
            raise ValueError(f"class_densities holds {len(own)} densit{'y' if len(own) == 1 else 'ies'}, but the classes run 0 to {runs - 1} "
                             f"({runs} classes): give one per class, class 0 first")
    text, classes_text, power = _kdm.analyze(sets, names, box, spec, function, tile, fmax, threads, energy,
                                                   labels, min_expected, density_bands, holes_min_density, own,
                                                   extent)
    result = _arrays(json.loads(text))
    if periodogram and power is not None and "spectrum" in result:
        result["spectrum"]["periodogram"] = power
    _infinite_lattice(result)
    density_result = result.get("density")
    if density_result and density_result["mean_expected"] < min_expected:
        warnings.warn(f"no density window expects min_expected={min_expected:g} points (a set has "
                      f"{result['points_min']}): one window a set, whose z says nothing", stacklevel=2)
    if classes_text is not None:
        result["classes"] = _arrays(json.loads(classes_text))
        for c in result["classes"]["classes"]:
            _infinite_lattice(c["metrics"])
        # Class labels, not measures: integers (an empty list too).
        result["classes"]["too_small"] = np.asarray(result["classes"]["too_small"], dtype=np.int64)
    return result
