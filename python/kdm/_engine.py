"""kdm.BlueNoise: the full sampler as a SciPy quasi-Monte Carlo engine (scipy.stats.qmc.QMCEngine).

Code written for ``qmc.PoissonDisk(d=2, seed=rng)`` through the engine interface (``random``, ``reset``,
``fast_forward``, ``integers``) switches by changing that line to ``kdm.BlueNoise(d=2, seed=rng)``;
PoissonDisk's own ``radius``, ``hypersphere``, ``ncandidates``, ``optimization`` and ``fill_space`` have no
counterpart (the count is ``random``'s n). Without SciPy the class has the same interface on a small base
of its own.
"""
from __future__ import annotations

import copy
import numbers
from typing import Any, Optional, Sequence, Union

import numpy as np

from . import _checks, _kdm


def _generator(seed: Any) -> Any:
    """SciPy's check_random_state: an int or None seeds a new Generator, a Generator is used as it is."""
    if seed is None or isinstance(seed, numbers.Integral):
        return np.random.default_rng(seed)
    if isinstance(seed, (np.random.Generator, np.random.RandomState)):
        return seed
    raise ValueError(f"{seed!r} cannot be used to seed a numpy.random.Generator instance")


class _Engine:
    """QMCEngine's conventions where SciPy is not installed: d, rng, rng_seed, num_generated, random,
    reset and fast_forward, with seeds handled as SciPy 1.10 handles them."""

    def __init__(self, d: int, *, seed: Any = None) -> None:
        if not isinstance(d, numbers.Integral) or d < 0:
            raise ValueError("d must be a non-negative integer value")
        self.d = d
        self.rng = _generator(seed)
        self.rng_seed = copy.deepcopy(seed)
        self.num_generated = 0

    def random(self, n: int = 1, *, workers: int = 1) -> np.ndarray:
        """n points in [0, 1)^d, shape (n, d)."""
        points = self._random(n, workers=workers)
        self.num_generated += n
        return points

    def reset(self) -> "_Engine":
        """Back to the engine's first draw."""
        self.rng = _generator(copy.deepcopy(self.rng_seed))
        self.num_generated = 0
        return self

    def fast_forward(self, n: int) -> "_Engine":
        self.random(n=n)
        return self

    def integers(
        self, l_bounds: Any, *, u_bounds: Any = None, n: int = 1, endpoint: bool = False, workers: int = 1
    ) -> np.ndarray:
        """n integer points in [l_bounds, u_bounds) ([l_bounds, u_bounds] with endpoint), shape (n, d)."""
        if u_bounds is None:
            u_bounds, l_bounds = l_bounds, 0
        low, high = np.atleast_1d(l_bounds), np.atleast_1d(u_bounds)
        if not (np.issubdtype(low.dtype, np.integer) and np.issubdtype(high.dtype, np.integer)):
            raise ValueError("'u_bounds' and 'l_bounds' must be integers or array-like of integers")
        high = high + (1 if endpoint else 0)
        try:  # SciPy's checks, in its words
            low, high = np.broadcast_to(low, self.d), np.broadcast_to(high, self.d)
        except ValueError:
            raise ValueError("'l_bounds' and 'u_bounds' must be broadcastable and respect the sample "
                             "dimension") from None
        if np.any(low >= high):
            raise ValueError("Bounds are not consistent 'l_bounds' < 'u_bounds'")
        return np.floor(self.random(n=n) * (high - low) + low).astype(np.int64)


try:
    from scipy.stats.qmc import QMCEngine as _Base
except ImportError:  # SciPy is optional
    _Base = _Engine


class BlueNoise(_Base):  # type: ignore[valid-type, misc]
    """Blue-noise points from the full KDM sampler, as a SciPy QMC engine.

    Each ``random(n)`` returns `n` fresh points (a whole set drawn with a new seed taken from the engine's
    generator, so it is blue noise by itself); ``reset()`` replays the same sets; ``fast_forward(n)``
    skips one set of n (its seed; its points are never computed). Points lie in [0, 1)^d, in the
    sampler's order (kdm.sample: a prefix of a set is a few patches of the domain, not a thinner set). An engine pickles and
    copies (a process pool's workers get it): its density is read again where it is unpickled, so an
    image file must be there too. A copy (``copy.copy``, ``copy.deepcopy`` or a pickle) is an engine of
    its own, its generator a copy at the same state: it draws the sets the original would draw next, so
    workers given copies draw the same sets: give each its own seed (``np.random.SeedSequence(s).spawn(k)``).
    As everywhere in kdm, a
    count or dimension that is not an integer (``random(2.0)``) raises TypeError, a value out of range
    ValueError: catch both where SciPy's engines are given values a user typed.

    Parameters
    ----------
    d : int
        2 or 3.
    seed, rng : None, int, numpy.random.Generator, SeedSequence or BitGenerator
        As SciPy's engines take it (``seed`` up to SciPy 1.14, ``rng`` from 1.15; give one): an int, a
        SeedSequence or a BitGenerator seeds a new ``numpy.random.default_rng``, None one seeded from
        fresh entropy (kept, so that reset() replays it too); a Generator is used as it is (and replayed
        from a copy by reset()). Unlike
        ``kdm.sample``, whose default seed is 1, two engines made without one draw different sets.
    aspect : float, (x, y, z) or None
        The domain the points are spaced evenly in, as kdm.sample takes it for dimension d: width / height
        (with d=3 the x side over the y and z sides), or with d=3 three sides ``(x, y, z)``; None: the
        density array's, volume's or image's shape, else 1. The points are normalised to [0, 1)^d whatever
        it is, as a QMC engine's are (and kdm.sample's): scale them by the sides to place them in the box.
        So aspect=1 spaces them evenly in the unit square (cube) whatever the density's shape.
    temperature, domain, density, threads, vectorized
        As kdm.sample takes them (domain None: a box for images, arrays, callables and "ramp:R", a
        torus for a uniform density and "radial:R";
        for integration take the torus: small box sets are biased, as kdm.sample says;
        an array density is copied, and ``density`` returns that read-only copy);
        ``random(n)`` returns what ``kdm.sample(n, density, dim=d, seed=s, ...)`` does for the seed s it
        draws; ``random(n, workers=k)`` draws with k threads (-1: every core) as SciPy's engines do. A
        draw that fails or is interrupted uses no seed. There is no ``optimization``: the points are
        blue noise already.
    """

    @_checks.other_name("dim", "d", "SciPy's name for the dimension; dim= is kdm.sample's")
    def __init__(
        self,
        d: int = 2,
        *,
        seed: Any = None,
        rng: Any = None,
        temperature: float = 0.5,
        domain: Optional[str] = None,
        density: Any = None,
        threads: int = 0,
        aspect: Union[None, float, Sequence[float]] = None,
        vectorized: bool = False,
    ) -> None:
        d = _checks.integer("d", d, 2, 3)
        if rng is not None:  # SciPy 1.15's name for it
            if seed is not None:
                raise TypeError("give seed or rng, not both")
            seed = rng
        if isinstance(seed, (np.random.SeedSequence, np.random.BitGenerator)):  # as default_rng takes them
            seed = np.random.default_rng(seed)
        seeds = (numbers.Integral, np.random.Generator, np.random.RandomState)
        if not (seed is None or isinstance(seed, seeds)):
            raise TypeError(
                "seed must be None, an int, a numpy.random.Generator, SeedSequence or BitGenerator, got "
                f"{type(seed).__name__}"
            )
        if isinstance(seed, numbers.Integral) and seed < 0:  # numpy's own refusal does not name it
            raise ValueError(f"seed must be a non-negative int, got {seed}")
        if seed is None:  # fresh entropy, kept as an int so that reset() replays it
            seed = np.random.SeedSequence().entropy
        super().__init__(d=d, seed=seed)
        self.temperature = _checks.temperature(temperature)
        self.domain = None if domain is None else _checks.choice("domain", domain, ("torus", "box"))
        self.threads = _checks.threads(threads)
        self.density = density
        self.vectorized = _checks.flag("vectorized", vectorized)
        self._check_vectorized()
        one, sides = _checks.aspect_or_sides(aspect, d, "d")  # refused now, not at the first draw
        self.aspect = one if sides is None else sides

    @property
    def density(self) -> Any:
        """The density, as kdm.sample takes it; set it to draw from another (checked when set)."""
        return self._density

    @density.setter
    def density(self, value: Any) -> None:
        if callable(value) and not isinstance(value, (np.ndarray, str)):  # called at each draw
            _checks.density_function("density", value, self.d, "d")
            self._density = self._spec = value
            return
        spec = _checks.sampler_density(value, 1.0, False, dim=self.d)  # read once, refused now if bad
        if self.d != 2 and spec is not None and spec.kind == "image":
            raise ValueError("image and array densities are 2-D; use d=2")  # now, not at the first draw
        if self.d != 3 and spec is not None and spec.kind == "volume":
            raise ValueError(f"density: a 3-D array of shape ({spec.depth}, {spec.height}, {spec.width}) is a "
                             "volume (depth, height, width): use d=3")
        if _checks.is_array(value):  # what is drawn from: later changes to the caller's array are not
            value = np.array(value, dtype=np.float64)
            value.flags.writeable = False
        self._density, self._spec = value, spec

    def _check_vectorized(self) -> bool:
        vectorized = _checks.flag("vectorized", self.vectorized)
        if vectorized and not callable(self._spec):
            raise ValueError("vectorized is for a callable density only")
        return vectorized

    def __copy__(self) -> "BlueNoise":
        # A shallow copy would share the generator, and each engine's draws would advance the other's.
        twin = type(self).__new__(type(self))
        twin.__dict__.update(self.__dict__)
        twin.rng = copy.deepcopy(self.rng)
        twin.rng_seed = copy.deepcopy(self.rng_seed)
        return twin

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        del state["_spec"]  # the density as read (C++), read again from _density
        return state

    def __setstate__(self, state: dict) -> None:
        density = state.pop("_density")
        self.__dict__.update(state)
        self.density = density  # read again, and kept read-only

    def random(self, n: int = 1, *, workers: int = 1) -> np.ndarray:
        """A new blue-noise set of `n` points in [0, 1)^d, drawn with the engine's next seed.

        Parameters
        ----------
        n : int
            Points in the set (0 to 2**31; the sampler's grid limits it as kdm.sample says).
        workers : int
            Threads for this draw: 1 (the default) the engine's `threads`, -1 every core, else that
            many. The points do not depend on it.

        Returns
        -------
        numpy.ndarray
            (n, d) float64.
        """
        return super().random(n, workers=workers)

    def _draw_seed(self) -> int:
        if hasattr(self.rng, "integers"):
            return int(self.rng.integers(0, 2**63, dtype=np.int64))
        return int(self.rng.randint(0, 2**63, dtype=np.int64))  # a legacy RandomState

    def _random(self, n: int = 1, *, workers: int = 1) -> np.ndarray:
        # `workers` as SciPy's engines take it: -1 every core, 1 (the default) the engine's `threads`.
        if isinstance(workers, bool) or not isinstance(workers, numbers.Integral) or not (
                workers == -1 or workers >= 1):
            raise ValueError(f"Invalid number of workers: {workers!r}, must be -1 or > 0")
        n = _checks.integer("n", n, 0, 2**31)
        if n == 0:
            return np.empty((0, self.d))
        # Attributes may have been set since __init__: checked again, before a seed is drawn.
        threads = _checks.threads(self.threads) if workers == 1 else (0 if workers == -1 else workers)
        threads = _checks.threads(threads)
        temperature = _checks.temperature(self.temperature)
        domain = None if self.domain is None else _checks.choice("domain", self.domain, ("torus", "box"))
        aspect, sides = _checks.aspect_or_sides(self.aspect, self.d, "d")
        vectorized = self._check_vectorized()
        state = copy.deepcopy(self.rng.bit_generator.state if hasattr(self.rng, "bit_generator")
                              else self.rng.get_state())
        seed = self._draw_seed()
        try:
            if callable(self._spec):
                return _kdm.sample_function(n, self._spec, self.d, domain, temperature, seed, threads, aspect,
                                            sides=sides, vectorized=vectorized)
            return _kdm.sample(n, self._spec, self.d, domain, temperature, seed, threads, aspect, sides=sides)
        except BaseException:  # a refused or interrupted draw uses no seed: the next is the one it was
            if hasattr(self.rng, "bit_generator"):
                self.rng.bit_generator.state = state
            else:
                self.rng.set_state(state)
            raise

    def fast_forward(self, n: int) -> "BlueNoise":
        """Skip what ``random(n)`` would return: one set's seed, whatever n (each call draws a whole set
        from one seed), without computing its points.

        Parameters
        ----------
        n : int
            The size of the skipped set (0 skips nothing); counted in ``num_generated``.

        Returns
        -------
        BlueNoise
            The engine, advanced.
        """
        n = _checks.integer("n", n, 0, 2**31)
        if n > 0:
            self._draw_seed()
        self.num_generated += n
        return self
