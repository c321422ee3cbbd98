"""kdm.sample: the full KDM sampler, as `kdm sample` runs it."""
from __future__ import annotations

from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np

from . import _checks, _kdm


@_checks.other_name("d", "dim", "d= is kdm.BlueNoise's, SciPy's name")
def sample(
    n: int,
    density: Any = None,
    *,
    dim: int = 2,
    domain: Optional[str] = None,
    temperature: float = 0.5,
    seed: int = 1,
    threads: int = 0,
    aspect: Union[None, float, Sequence[float]] = None,
    gamma: float = 1.0,
    invert: bool = False,
    classes: Optional[Sequence[Any]] = None,
    sweeps: Optional[int] = None,
    coarse_sweeps: Optional[int] = None,
    sets: Optional[int] = None,
    vectorized: bool = False,
) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray]]:
    """Draw exactly `n` blue-noise points from the KDM model (the full sampler, `kdm sample`).

    Parameters
    ----------
    n : int
        The number of points, 1 to 2**31. The sampler's grid (at most 2**27 nodes) holds about 8 million
        points in 2-D and 3 million in 3-D (fewer with a wide density range or a long domain); more raise
        ValueError saying so.
    density : None, float, str, 2-D or 3-D array, or callable
        The target density (only its shape matters: the sampler scales it to `n` points). None or a
        number > 0: uniform. A callable ``f(x, y)`` (``f(x, y, z)`` with dim=3) of coordinates in
        [0, 1) returning a real number >= 0 (an int, float, bool or numpy scalar; anything else raises
        TypeError, a value that is not finite and >= 0 ValueError, each naming the point), in a box
        unless `domain` says otherwise. Its values are kept as floats as they come: its largest must lie
        in 1e-30 ... 1e30, else ValueError (divide or multiply it by a constant). It is called once per
        node of the sampler's grid, one Python call each, and the grid's resolution goes in steps, so the
        calls per point vary with n. For a uniform density (measured): in 2-D about 16 per point from
        3,000 points up, 20 at 1,000, 30 at 300, 70 to 80 under 100; in 3-D 40 to 96 from 1,000 points
        up, by where n falls between the grid's steps (96 at 1,000, 42 at 6,000, 84 at 8,000, 40 at
        30,000 and at 100,000 or more), up to about 260 under 100 points. More where the density varies,
        as the grid is fine enough for its densest part: 99 for 0.1 + x·y at 20,000 points; with
        `vectorized`, a handful of calls on arrays instead. A str: what
        ``kdm sample --density`` accepts, "const:V", the test maps "ramp:R" and "radial:R", or an image
        file whose darkness (to the power `gamma`; its luminance with `invert`) is the density. A 2-D
        array: density values (finite, >= 0, not all zero; at any scale: the scale does not change the
        points' distribution, but one that is not a power of two rounds the values differently, so the
        points differ; an array whose largest value lies outside 1e-30 ... 1e30 is divided by it first),
        bilinear between pixel centres (not piecewise constant: a step between two columns is a ramp one
        pixel wide, so 4 × 8 pixels of 1 and 3 put 0.734 of the points in the right half, not 0.75),
        stretched over the domain, with row 0 at the TOP, as pictures are stored (and as an image file is
        read). A 3-D array
        of shape (depth, height, width), with dim=3: a volume of densities (values as a 2-D array's),
        trilinear between voxel centres, stretched over the domain; ``a[k]`` is the slice at
        z = (k + 0.5) / depth (slice 0 at z near 0), each slice laid out as a 2-D array (row 0 at the top,
        y near 1; the last axis is x), as ``kdm sample --dim 3 --density vol.npy`` reads
        ``np.save("vol.npy", a)``.
    dim : int
        2 or 3 (images and 2-D arrays are 2-D, 3-D arrays 3-D).
    domain : {"torus", "box"} or None
        Periodic or bounded. None: a box for images, arrays, volumes, callables and "ramp:R", a torus for None,
        a number, "const:V" and "radial:R". For Monte Carlo integration: the torus is unbiased over
        the square (sets under about 256 points keep a faint ripple of the sampler's grid, period
        1/(4 sqrt(n)), which a random shift modulo 1 per set removes) and best for periodic integrands; a smooth integrand that is not periodic has a 3-6x lower error
        in a box, whose sets of up to a few hundred points are nearly the same grid for every seed and
        bias sharp features (docs/limits.md, "The full sampler in a box").
    temperature : float
        0 to 1000; 0.5 is the paper's look with the default sweeps, lower is more ordered down to about
        0.1, 0 a deterministic descent, 100 and up near white noise (reached with sweeps=300). The
        set is the chain after its sweeps, not at equilibrium: more sweeps order it further
        (docs/design.md §2.1).
    seed : int
        0 to 2**64 - 1. The points depend on the arguments and the seed only, never on `threads`.
    threads : int
        Worker threads; 0: OMP_NUM_THREADS if set, else the CPUs this process may use.
    aspect : float, (x, y, z) or None
        Width / height of the domain (in 3-D, its x side over its y and z sides, as ``kdm sample
        --aspect``); in 3-D also three sides ``(x, y, z)``, relative lengths each > 0 (``--aspect X:Y:Z``);
        None: the image's or 2-D array's width / height, a 3-D array's (width, height, depth), else 1.
        Points are normalised to [0, 1) on every axis whatever the aspect: give ``kdm.analyze`` the same
        aspect to measure them in their domain.
    gamma, invert
        How an image file's pixels become density (as ``kdm sample --gamma/--invert``).
    classes : sequence of densities, optional
        Several kinds of points at once (instead of `density`; 2-D), as ``kdm sample --class``: 1 to 8
        densities (numbers, str or 2-D arrays as `density` takes them; images of one shape), highest
        priority first. `n` counts all of them, split by each density's integral (a number keeps its
        value: ``classes=[1, 2]`` gives a third and two thirds; each class's cumulative share rounded,
        so equal classes may give the spare points to a later one; 0 or a blank image: no points). Class 0 is a KDM sample at its own
        density, each later class is sampled around the earlier ones, then all are swept together at the
        sum (docs/multiclass.md).

    sweeps, coarse_sweeps : int or None
        Metropolis-Hastings sweeps on the finest level and on each level between the coarsest and the
        finest, 0 to 100000 (``kdm sample --sweeps/--coarse-sweeps``; None: 30 and 15). A set of
        up to about 256 points has one level, which runs at least 30. More finest sweeps
        with a lower temperature give a more ordered set (docs/quality.md: T = 0.2, 100 sweeps).
    sets : int or None
        Many independent sets at once (Monte Carlo: a set per pixel or per frame), as ``kdm sample
        --sets``: 1 to 2**20 sets of `n` points each, at most 2**27 points in all, drawn with the seeds
        ``seed, seed + 1, ..., seed + sets - 1`` (their last at most 2**64 - 1); set k is exactly
        ``kdm.sample(n, ..., seed=seed + k)``. The sets run in parallel, one per thread (a small set runs
        on one thread anyway), with the GIL released: on two cores about twice the sets per second of a
        loop of calls (docs/design.md §2.9). A callable density is called as for one set. Not with
        `classes`. None: one set, returned as (n, dim).
    vectorized : bool
        For a callable density: True if f takes arrays, ``f(x, y)`` (``f(x, y, z)``) of float64 arrays
        of one length (runs of the sampler's grid nodes, up to 65,536 positions a call) -> an array of that
        length (or one number for all of them), as ``Tileset.query(..., vectorized=True)`` takes it. One
        call per 65,536 positions instead of one per node (for 100,000 points of ``0.1 + x * y`` in 2-D,
        151 calls instead of 9.8 million), on one thread with the GIL held for each call only; the same
        points as the scalar callable giving the same values. A result that is not an array of real
        numbers raises TypeError, another length or a value that is not finite and >= 0 ValueError, each
        naming the (first) position. Measured with time.perf_counter, threads=1, 100,000 points in 2-D:
        ``0.1 + np.exp(-((x - 0.5)**2 + (y - 0.5)**2) / 0.05)`` took 9.3 s called per node and 4.0 s
        vectorized (the same points); ``0.1 + x * y`` 4.3 s and 3.65 s, where the sweeps take most of the
        time.

    Returns
    -------
    numpy.ndarray
        (n, dim) float64 in [0, 1)^dim: the same bits as ``kdm sample`` with the same arguments. Rows come
        in the sampler's order, cell by cell of its grid, so neighbouring rows are neighbouring points: a
        prefix ``x[:k]`` is a few patches of the domain (cells of the grid), not a thinner set (for k points, sample k; for a random
        subset, index by ``rng.permutation(n)[:k]``). With `classes`: ``(points, labels)``, the points
        (n, 2) class 0's first and labels (n,) uint8 each point's class. With `sets`: (sets, n, dim),
        ``x[k]`` the set of seed ``seed + k``.
    """
    n = _checks.integer("n", n, 1, 2**31)
    dim = _checks.integer("dim", dim, 2, 3)
    if domain is not None:
        domain = _checks.choice("domain", domain, ("torus", "box"))
    temperature = _checks.temperature(temperature)
    seed = _checks.integer("seed", seed, 0, 2**64 - 1)
    threads = _checks.threads(threads)
    aspect, sides = _checks.aspect_or_sides(aspect, dim)
    sweeps = None if sweeps is None else _checks.integer("sweeps", sweeps, 0, 100000)
    coarse_sweeps = None if coarse_sweeps is None else _checks.integer("coarse_sweeps", coarse_sweeps, 0, 100000)
    more = dict(sweeps=sweeps, coarse_sweeps=coarse_sweeps)
    if sets is not None:
        sets = _checks.integer("sets", sets, 1, 2**20)
        if seed + sets - 1 > 2**64 - 1:
            raise ValueError(f"seed {seed} with sets={sets} runs past the largest seed, 2**64 - 1")
    vectorized = _checks.flag("vectorized", vectorized)
    if vectorized and not (callable(density) and not isinstance(density, (np.ndarray, str))):
        raise ValueError("vectorized is for a callable density only")
    if classes is not None:
        if sets is not None:
            raise ValueError("sets draws one class: give density, not classes")
        if density is not None:
            raise ValueError("give either density or classes, not both")
        if dim != 2:
            raise ValueError("classes are sampled in 2-D: use dim=2")
        specs = _checks.class_specs(classes, gamma, invert)
        return _kdm.sample_classes(n, specs, domain, temperature, seed, threads, aspect, **more)
    if callable(density) and not isinstance(density, (np.ndarray, str)):
        if gamma != 1.0 or invert:
            raise ValueError("gamma and invert apply to image files only, and density is a function")
        _checks.density_function("density", density, dim)
        return _kdm.sample_function(n, density, dim, domain, temperature, seed, threads, aspect, sides=sides,
                                    sets=sets, vectorized=vectorized, **more)
    spec = _checks.sampler_density(density, gamma, invert, dim=dim)
    if spec is not None and spec.kind == "volume" and dim != 3:
        raise ValueError(f"density: a 3-D array of shape ({spec.depth}, {spec.height}, {spec.width}) is a volume "
                         "(depth, height, width): use dim=3")
    if spec is not None and spec.kind == "image" and dim == 3:
        raise ValueError("image and array densities are 2-D; use dim=2 (a 3-D density is an array of shape "
                         "(depth, height, width))")
    return _kdm.sample(n, spec, dim, domain, temperature, seed, threads, aspect, sides=sides, sets=sets, **more)
