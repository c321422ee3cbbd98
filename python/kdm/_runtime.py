"""The runtime from Python: tile sets (kdm.Tileset), their queries (kdm.QueryResult) and the baker."""
from __future__ import annotations

import numbers
import os
from typing import Any, Callable, Dict, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _checks, _kdm

# The argument types query() and positions() share.
_Rect = Sequence[float]
_Density = Union[float, str, np.ndarray, Callable[[float, float], float], None]
_Bounds = Callable[[float, float, float, float], Tuple[float, float]]


class QueryResult:
    """The points of a query, in the runtime's order (tiles row by row, ranks ascending; cell by cell in
    a tile the region meets only a small part of).

    `points` holds the runtime's own 40-byte records, as the query wrote them; `xy`, `tile` and `rank`
    are views of them (strided, not copied: ``np.ascontiguousarray(r.xy)`` makes a packed copy).

    Attributes
    ----------
    points : numpy.ndarray
        (m,) structured: fields x, y (float64), tile_x, tile_y (int64), rank, depth (uint32). Past the
        tile set's top level (smooth mode) points come from subtiles m**depth times smaller than a tile,
        and tile_x, tile_y count those.
    xy : numpy.ndarray
        (m, 2) float64: world positions minus the query's origin.
    tile : numpy.ndarray
        (m, 2) int64: each point's tile (tile_x, tile_y); with `rank` and `depth`, its stable id.
    rank : numpy.ndarray
        (m,) uint32: the point's index in its tile, in emission order.
    level : numpy.ndarray
        (m,) uint32: the pyramid level the rank belongs to.
    depth : numpy.ndarray
        (m,) uint32: 0, or past the top level the subtiles' depth that tile and rank count in (ranks
        repeat across depths: key points on tile, rank and depth together).
    classes : numpy.ndarray or None
        (m,) uint8: each point's class, for a query with `classes` (None otherwise).
    keys : numpy.ndarray
        (m,) uint64: each point's id in one number, as ``positions(keys=True)`` gives it (tile x and y
        modulo 2**21, rank, depth): unique within any region less than 2,097,152 tiles across, so usable
        as a dict key or to join with positions' keys; thresholds() needs the result itself.

    ``r[i]``, ``r[a:b]``, ``r[mask]`` and ``r[indices]`` give a new QueryResult of those points (copied);
    an integer past either end (``-len(r) <= i < len(r)``, as numpy's) is an IndexError. Iterating
    yields ``r[0]``, ``r[1]``, ...: one-point QueryResults (slow for many points; the arrays are the bulk
    route, and ``np.asarray(r)`` is a TypeError that names them). A result pickles its points alone, not
    the buffer a reused ``out`` left behind it.
    """

    __slots__ = ("points", "xy", "tile", "rank", "level", "classes", "_storage")

    @classmethod
    def _of(cls, points: np.ndarray, level: np.ndarray, classes: Optional[np.ndarray]) -> "QueryResult":
        """A result over `points` (a packed (m,) record array, owned): xy, tile and rank view it."""
        points = np.ascontiguousarray(points)
        m, step = len(points), points.dtype.itemsize

        def view(dtype: Any, offset: int, shape: Tuple[int, ...], strides: Tuple[int, ...]) -> np.ndarray:
            return np.ndarray(shape, dtype, buffer=points, offset=offset if m else 0, strides=strides)

        xy = view(np.float64, 0, (m, 2), (step, 8))
        tile = view(np.int64, 16, (m, 2), (step, 8))
        rank = view(np.uint32, 32, (m,), (step,))
        return cls(points, xy, tile, rank, np.ascontiguousarray(level, dtype=np.uint32),
                   classes=None if classes is None else np.ascontiguousarray(classes, dtype=np.uint8))

    @property
    def keys(self) -> np.ndarray:
        mask = np.uint64((1 << 21) - 1)
        tile = self.tile.astype(np.uint64)  # two's complement, as C++'s cast: the low bits of a negative tile
        return (tile[:, 0] & mask) | (tile[:, 1] & mask) << np.uint64(21) | \
            self.rank.astype(np.uint64) << np.uint64(42) | self.depth.astype(np.uint64) << np.uint64(61)

    def __getitem__(self, index: Any) -> "QueryResult":
        if isinstance(index, numbers.Integral):
            m, i = len(self), int(index)
            if not -m <= i < m:  # as numpy's (an empty result instead would never end iteration)
                raise IndexError(f"index {i} is out of range for a QueryResult of {m} points")
            index = slice(i % m, i % m + 1)  # a one-point result
        return QueryResult._of(self.points[index].copy(), self.level[index],
                               None if self.classes is None else self.classes[index])

    def __reduce__(self) -> Tuple[Any, ...]:
        return (QueryResult._of, (self.points.copy(), self.level.copy(),
                                  None if self.classes is None else self.classes.copy()))

    def __init__(
        self, points: np.ndarray, xy: np.ndarray, tile: np.ndarray, rank: np.ndarray, level: np.ndarray,
        storage: Any = None, classes: Optional[np.ndarray] = None,
    ) -> None:
        self.points, self.xy, self.tile, self.rank, self.level = points, xy, tile, rank, level
        self.classes = classes
        self._storage = storage  # the memory these are the first rows of (query's `out` refills it)

    @property
    def depth(self) -> np.ndarray:
        return self.points["depth"]

    def __len__(self) -> int:
        return len(self.xy)

    def __iter__(self) -> Iterator["QueryResult"]:
        return (self[i] for i in range(len(self)))

    def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
        # Without it numpy would walk the one-point results as nested sequences, for minutes.
        raise TypeError("a QueryResult is not an array: pass its .xy (positions less the origin), or .tile, "
                        ".rank, .keys, .classes")

    def __repr__(self) -> str:
        return f"<kdm.QueryResult: {len(self)} points>"


class DensityMap:
    """A query's density prepared once for many queries: ``Tileset.query(rect, density=m)``, in `classes`
    and in ``positions()``. A map (an array, an image file or a test map) read each time costs what the
    whole map does (a 1,024 x 1,024 array: about 7 ms a query, however small the chunk); prepared, a chunk
    costs what its own points do. The same points as giving the density and ``density_rect`` each time.

    Parameters
    ----------
    density : float, str or 2-D array
        As ``Tileset.query(density=...)`` takes it (not a callable: a function is read where it is asked).
    rect : (x0, y0, x1, y1)
        The world rectangle the map is stretched over (a query's ``density_rect``, which a query given a
        DensityMap must not repeat; other image classes of that query are stretched over it too). Needed
        for an array, image or test map; ignored for a constant.
    gamma, invert
        How an image file's pixels become density (read once: a pickle holds the densities, not the
        path).
    """

    def __init__(self, density: Any, rect: Optional[_Rect] = None, *, gamma: float = 1.0,
                 invert: bool = False) -> None:
        if _is_callable(density) or isinstance(density, DensityMap):
            raise TypeError(f"density must be a number, a str or a 2-D array, got {type(density).__name__}")
        spec = _checks.density_spec(density, gamma, invert)
        if spec is None:
            raise TypeError("density must be a number, a str or a 2-D array, got None")
        constant = spec.kind == "const"
        if not constant and rect is None:
            raise ValueError("rect is needed: the world rectangle the map is stretched over")
        self._rect = None if constant else _checks.rect("rect", rect)
        self._spec = spec
        self._ready = _kdm.PreparedDensity(spec, self._rect or (0.0, 0.0, 1.0, 1.0))

    @property
    def rect(self) -> Optional[Tuple[float, ...]]:
        """The world rectangle the map is stretched over (None for a constant)."""
        return self._rect

    def at(self, x: Any, y: Any) -> np.ndarray:
        """The density at world positions (arrays of x and y), as a query reads it: what fading objects in
        by their thresholds needs (docs/runtime.md, "Fading objects in"). 0 where x or y is NaN or
        infinite (no position: as the C kdm_density_image_at)."""
        x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
        if x.shape != y.shape:
            raise ValueError(f"x and y must have one shape, got {x.shape} and {y.shape}")
        return self._ready.at(x.ravel(), y.ravel()).reshape(x.shape)

    def __reduce__(self) -> Tuple[Any, Tuple[Any, ...]]:
        # The densities the map holds (an image file's as read, gamma applied), the text of a test map or
        # the constant's value: never the path, whose file may change or be elsewhere where it is unpickled.
        s = self._spec
        density = s.values if s.kind == "image" else s.text if s.kind != "const" else self._ready.at(
            np.zeros(1), np.zeros(1))[0]
        return (_density_map, (density, self._rect, 1.0, False))

    @property
    def kind(self) -> str:
        """"const", "image" (an array or an image file), "ramp" or "radial" (the test maps)."""
        return self._spec.kind

    def __repr__(self) -> str:
        return f"kdm.DensityMap({self._spec!r}, rect={self._rect})"


def _density_map(density: Any, rect: Any, gamma: float, invert: bool) -> DensityMap:
    """A DensityMap from its arguments (what pickling it keeps)."""
    return DensityMap(density, rect, gamma=gamma, invert=invert)


class Tileset:
    """A loaded, immutable tile set: the runtime's source of points for any region and density.

    Get one with Tileset.builtin(), Tileset.load(path), Tileset.from_bytes(data) or kdm.bake(recipe).
    Any number of threads may query one at once. It pickles (as its file's bytes, 14 MB for a set the size
    of the built-in one; the built-in set as itself, 79 bytes), and copies are the set itself: it never
    changes. For a process pool, load a set from a file once in each worker (the pool's initializer)
    rather than sending it with every task.
    """

    __slots__ = ("_handle",)
    _builtin: Optional["Tileset"] = None

    def __init__(self, handle: Any) -> None:
        if not isinstance(handle, _kdm.Tileset):
            raise TypeError("use Tileset.builtin(), Tileset.load(path) or kdm.bake(recipe)")
        self._handle = handle

    @classmethod
    def builtin(cls) -> "Tileset":
        """The tile set compiled into the library (tilesets/default.kdmt), decoded on the first call."""
        if cls._builtin is None:
            cls._builtin = cls(_kdm.Tileset.builtin())
        return cls._builtin

    @classmethod
    def load(cls, path: Any) -> "Tileset":
        """Loads and validates a .kdmt file. Raises OSError (the command line's message) if it cannot:
        FileNotFoundError for a missing file, IsADirectoryError for a directory, as open() raises them."""
        return cls(_kdm.Tileset.load(_checks.path("path", path)))

    @classmethod
    def from_bytes(cls, data: Any) -> "Tileset":
        """Loads and validates a .kdmt file's bytes (bytes, or any buffer of them: bytearray, memoryview, a
        uint8 array). Raises ValueError, naming the problem, for bytes that are no valid tile set."""
        if not isinstance(data, bytes):
            try:
                data = memoryview(data).cast("B").tobytes()
            except TypeError:
                raise TypeError(f"data must be bytes or a buffer of them, got {type(data).__name__}") from None
        return cls(_kdm.Tileset.from_bytes(data))

    def to_bytes(self) -> bytes:
        """The set as a .kdmt file's bytes (what save() writes)."""
        return self._handle.to_bytes()

    def save(self, path: Any) -> None:
        """Writes the set as a .kdmt file (atomically). Raises OSError if it cannot."""
        self._handle.save(_checks.path("path", path))

    def __reduce__(self) -> Tuple[Any, ...]:
        if self is Tileset._builtin:
            return (Tileset.builtin, ())
        return (Tileset.from_bytes, (self.to_bytes(),))

    def __copy__(self) -> "Tileset":
        return self

    def __deepcopy__(self, memo: Any) -> "Tileset":
        return self

    @property
    def info(self) -> Dict[str, Any]:
        """What the set holds: levels, level_points (nominal points per tile, cumulative), keyframes,
        max_points_per_tile (the stable-mode limit), smooth_limit_per_tile (the smooth-mode limit: with a
        hand-over to subtiles, max_points_per_tile * subtiles_per_side**8), subtiles_per_side (0 without a
        hand-over), handover_level (the subtiles' level it glides onto), handover_slack (keyframes
        past their first above that level at which they are handed over), colours, tiles, format_version, resident_bytes, recipe, generator_version and
        glide_reach (tile sides)."""
        return self._handle.info

    def thresholds(self, result: Any, *, near_tile: Optional[Sequence[int]] = None) -> np.ndarray:
        """Each point's emission threshold: the expected count per tile above which it is emitted.

        A point of `result` (a QueryResult of this set) is present where its tile's expected count,
        density * scale * (tile_size / m**depth)**2 at the point, exceeds its threshold. To fade objects
        in as the density rises instead of letting them pop up, weigh each by
        ``np.clip((count / threshold - 1) / f, 0, 1)``: 0 as it appears, 1 once the density has risen a
        fraction f. For a result with classes, the count is that of the classes' summed density (the
        points of all classes are the one-class query's at their sum). Returns an (m,) float64 array.
        Raises TypeError for anything but a QueryResult and ValueError for a point this set does not
        have (a result of another set). `result` may also be the keys of ``positions(..., keys=True)``
        with `near_tile`, a tile (tx, ty) of the query's region in tiles of its tile_size, such as
        ``(floor(x0 / tile_size), floor(y0 / tile_size))``: a key names its tile modulo 2**21.
        """
        if isinstance(result, np.ndarray) and result.dtype == np.uint64:
            if near_tile is None:
                raise ValueError("keys need near_tile: a tile (tx, ty) of the query's region")
            tx, ty = (_checks.integer("near_tile", v, -2**62, 2**62) for v in near_tile)
            return self._handle.key_thresholds(result, tx, ty)
        if not isinstance(result, QueryResult):
            raise TypeError(f"result must be a kdm.QueryResult or positions' keys, got {type(result).__name__}")
        if near_tile is not None:
            raise ValueError("near_tile is for keys only: a QueryResult holds its tiles")
        return self._handle.thresholds(result.tile, result.rank, result.points["depth"])

    def stable_positions(self, result: Any, *, tile_size: float = 1.0, origin: Sequence[float] = (0.0, 0.0)
                         ) -> np.ndarray:
        """Each point's stable position: where a stable query puts it and where a smooth query's point
        glides from, as (m, 2) float64 world positions minus `origin`, for the `tile_size` and `origin` the
        query of `result` (a QueryResult of this set) was made with. The density that decides a point's
        emission is read there: a fade weight by ``thresholds(result)`` read at these positions follows the
        query's rule in smooth mode too, where the density at the shown position makes it blink as a point
        glides across a change of density. Raises TypeError for anything but a QueryResult and ValueError
        for a point this set does not have or a bad tile_size or origin.
        """
        if not isinstance(result, QueryResult):
            raise TypeError(f"result must be a kdm.QueryResult, got {type(result).__name__}")
        tile_size = _checks.number("tile_size", tile_size, 0.0, strict=True)
        ox, oy = _checks.numbers_tuple("origin", origin, 2)
        return self._handle.stable_positions(result.tile, result.rank, result.points["depth"], tile_size, ox, oy)

    def __repr__(self) -> str:
        i = self.info
        return (
            f"<kdm.Tileset: {i['tiles']} tiles, {i['levels']} levels, "
            f"up to {i['max_points_per_tile']} points per tile>"
        )

    def query(
        self,
        rect: _Rect,
        *,
        scale: float,
        density: _Density = None,
        classes: Optional[Sequence[Union[float, str, np.ndarray]]] = None,
        density_rect: Optional[_Rect] = None,
        density_max: Optional[float] = None,
        density_bounds: Optional[Union[_Bounds, Sequence[Optional[_Bounds]]]] = None,
        vectorized: bool = False,
        tile_size: float = 1.0,
        mode: str = "stable",
        origin: Sequence[float] = (0.0, 0.0),
        gamma: float = 1.0,
        invert: bool = False,
        out: Optional["QueryResult"] = None,
        glide_together: bool = False,
        threads: Optional[int] = None,
    ) -> QueryResult:
        """The points of the world rectangle `rect` = (x0, y0, x1, y1), half-open (``kdm query``); none
        when x1 <= x0 or y1 <= y0, as in C and C++. There is no seed: another draw is a rectangle
        elsewhere, sharing the set's tiles (far from independent); for independent sets use sample()'s
        seeds.

        Parameters
        ----------
        scale : float
            Points per unit area where the density is 1.
        density : float, str, 2-D array or callable
            A constant >= 0; a str as ``kdm query --density`` takes it (an image, "const:V", "ramp:R",
            "radial:R"); a 2-D array of densities (finite, >= 0; its values as they are, integer arrays
            too: divide an 8-bit mask by 255) with row 0 at the TOP, the largest y of `density_rect`;
            either of the last two stretched over `density_rect` (default: `rect`; fix it to query parts
            of one region), bilinear between texel centres, its edge texels going on past it. Or a
            callable f(x, y) -> float of world coordinates, called for every candidate point (with the
            GIL held; an exception it raises is raised here once the query ends, a value that is no
            real number TypeError and one that is not finite and >= 0 ValueError, each naming the
            point), which needs `density_max` (> 0), a true upper bound of
            its values (a larger one raises ValueError; smooth mode also reads up to twice the glide's
            reach, ``info["glide_reach"]`` tile sides, outside `rect`). Or a DensityMap, a map prepared once
            with its rectangle: for a map queried chunk by chunk, whose array would otherwise be
            converted and mipped at every query (7 ms for 1,024 x 1,024). Default: 1.
        vectorized : bool
            For a callable density: True if f takes arrays, f(x, y) -> array of the same length (x and y
            float64 arrays of up to 128 positions, a tile's candidates at a time; scipy's `vectorized`).
            One call then serves many points: for a numpy expression about ten times faster than
            calling it point by point. The same points as the scalar callable. Past the top level
            (smooth mode) the arrays are shorter (about 50 positions). With `classes`: every callable
            class is vectorized.
        density_bounds : callable, optional
            For a callable density: f(x0, y0, x1, y1) -> (lo, hi), bounds of the density over a world
            rectangle, 0 <= lo <= hi (else ValueError). Asked once per tile, it lets the query call the
            density only where a point's emission is in doubt (several times fewer calls in stable mode),
            giving the same points as long as the bounds hold.
        classes : sequence of densities, optional
            Several kinds of points in one query, instead of `density`: 1 to 8 densities (numbers, str,
            2-D arrays, DensityMaps over one rect, or callables f(x, y) -> float as `density` takes them),
            highest priority first
            (largest objects first). Every point gets a class (`classes` of the result). All classes
            together are the points of one query at the summed density; in stable mode class 0 alone is
            exactly the query at its own density. Callable classes need `density_max`: one bound for
            all of them, or a sequence with one entry per class (None for the others); they are called
            point by point, or on arrays with `vectorized`; `density_bounds` then holds one bounds
            function (or None) per class. Classes that are all 2-D arrays (or image files) of one
            shape, with at most 2**20 texels in all, are read by their running sums, added texel by
            texel in float32: the union is then exactly the query at that sum, and the query reads one
            image instead of one per class (larger ones are read one by one; the choice never depends on
            the region, so chunks give the whole's points). As ``kdm query --class``.
        tile_size : float
            World units per tile side. A tile expects density * scale * tile_size**2 points, at most
            info["max_points_per_tile"] where the density is highest in stable mode, or
            info["smooth_limit_per_tile"] in smooth mode (far more with a set that hands over to subtiles),
            or the query is refused.
        mode : {"stable", "smooth"}
            stable: a point never moves once it appears (placing objects); smooth: points glide with the
            density, so every density is even blue noise (stippling, sample patterns).
        glide_together : bool
            Smooth mode with a varying density: each point glides by the most density around it, so that
            neighbours do not close up where the density changes from one dot to the next (pictures,
            textures). The same points; about twice as slow (8 more density reads a point).
        origin : (float, float)
            Subtracted from every position (keep it near the region in large worlds).
        gamma, invert
            How an image file's pixels become density.
        out : QueryResult, optional
            An earlier result whose memory this query refills, where it is large enough (its arrays are
            overwritten): a loop of queries then writes into warm memory instead of new memory. Not with
            `classes` (ValueError).
        threads : int or None
            None (the default) runs one query; N splits it over N threads as positions() does (the same
            points for any N, in this order unless a tile holds more points than a unit of the split; 0
            for the CPUs this process may use, at most 64): for large regions and maps. A density (or
            class) that is a Python function runs one query whatever `threads` says: the GIL lets one
            thread call it at a time, and two threads waiting on it ran 4 to 20 times slower.

        Returns
        -------
        QueryResult
            Positions, ids and levels; any partition of a region gives the region's points, and the same
            arguments give the same bits as ``kdm query ... -o points.csv``. A query of more than 2**25
            points raises ValueError (1 GiB of records): split the region. A constant's count is known
            before querying, and an image's lower bound (its least value over blocks of the map), so such
            a query is refused at once where that bound passes 2**25; otherwise once 2**25 points are
            collected (seconds, and a few GB, for a map with empty parts, such as a river of zeros).
        """
        class_max = density_max  # a number or one entry per class, checked with the classes
        rect, scale, tile_size, mode, origin, density_rect, density_max = _query_args(
            rect, scale, tile_size, mode, origin, density_rect, None if classes is not None else density_max,
            glide_together)
        workers = _workers(threads)
        if classes is not None:
            return self._query_classes(rect, scale, density, classes, density_rect, class_max, density_bounds,
                                       vectorized, tile_size, mode, origin, gamma, invert, out, workers)
        spec, call, ready = _density_arg(density, gamma, invert)
        if out is not None and not isinstance(out, QueryResult):
            raise TypeError(f"out must be a QueryResult, got {type(out).__name__}")
        if density_bounds is not None and not callable(density_bounds):
            raise TypeError(f"density_bounds must be callable, got {type(density_bounds).__name__}")
        return QueryResult(*_kdm.query(
            self._handle, rect, scale, spec, ready, call, _checks.flag("vectorized", vectorized), density_bounds,
            density_rect, density_max, tile_size, mode, origin, out._storage if out is not None else None,
            workers,
        ))


    def positions(
        self,
        rect: _Rect,
        *,
        scale: float,
        density: _Density = None,
        density_rect: Optional[_Rect] = None,
        density_max: Optional[float] = None,
        density_bounds: Optional[Union[_Bounds, Sequence[Optional[_Bounds]]]] = None,
        vectorized: bool = False,
        tile_size: float = 1.0,
        mode: str = "stable",
        origin: Sequence[float] = (0.0, 0.0),
        gamma: float = 1.0,
        invert: bool = False,
        glide_together: bool = False,
        keys: bool = False,
        threads: Optional[int] = None,
        classes: Optional[Sequence[_Density]] = None,
    ) -> Union[np.ndarray, Tuple[np.ndarray, ...]]:
        """The points of `rect` as positions only: the fast path for callers that need no ids.

        The arguments are query()'s. Returns an (n, 2) float32 array of positions relative to `origin`
        (keep it near `rect`: float32 holds about 7 digits), the same points as query() within
        2**-21 * (|position| + tile_size) (plus 2**-50 of the world coordinate: query()'s own rounding far
        from the world origin; a `rect` more than 2**21 point spacings from `origin`, where points would
        fall together, raises ValueError); with ``keys=True`` also an (n,) uint64 array of point keys
        (tile x and y modulo 2**21, rank and depth packed: the same in every query, unique within any
        region under 2**21 tiles across). ``threads=N`` splits the query over N threads (units of the
        region in a fixed order: the same bits for any N, in query()'s order unless a tile holds more
        points than a unit; 0 for the CPUs this process may use, at most 64; a Python function density
        runs one query, as in query()); the default runs one query, in query()'s order. ``classes=[...]`` (as query()'s, instead of `density`; `threads` too)
        appends an (n,) uint8 array of each point's class: ``(xy, classes)`` or ``(xy, keys, classes)``.
        More than 2**25 points raise ValueError, as query() does.
        """
        class_max = density_max  # a number or one entry per class, checked with the classes
        rect, scale, tile_size, mode, origin, density_rect, density_max = _query_args(
            rect, scale, tile_size, mode, origin, density_rect, None if classes is not None else density_max,
            glide_together)
        keys = _checks.flag("keys", keys)  # the one rule for flags: bool or numpy's
        workers = _workers(threads)
        if classes is not None:
            if density is not None:
                raise ValueError("give either density or classes, not both")
            specs, ready, callables, maxima, bounds = _class_args(classes, gamma, invert, class_max,
                                                                  density_bounds)
            xy, key, labels = _kdm.class_positions(
                self._handle, rect, scale, specs, ready, callables, maxima, bounds, _checks.flag("vectorized", vectorized),
                density_rect, tile_size, mode, origin, keys, workers)
            return (xy, key, labels) if keys else (xy, labels)
        spec, call, ready = _density_arg(density, gamma, invert)
        if density_bounds is not None and not callable(density_bounds):
            raise TypeError(f"density_bounds must be callable, got {type(density_bounds).__name__}")
        xy, key = _kdm.positions(self._handle, rect, scale, spec, ready, call, _checks.flag("vectorized", vectorized),
                                 density_bounds, density_rect, density_max, tile_size, mode, origin, keys, workers)
        return (xy, key) if keys else xy

    def _query_classes(
        self, rect: Any, scale: float, density: Any, classes: Any, density_rect: Any, density_max: Any,
        density_bounds: Any, vectorized: Any, tile_size: float, mode: str, origin: Any, gamma: Any, invert: Any,
        out: Any, workers: int,
    ) -> QueryResult:
        if density is not None:
            raise ValueError("give either density or classes, not both")
        if out is not None:
            raise ValueError("out does not apply to a query with classes")
        specs, ready, callables, maxima, bounds = _class_args(classes, gamma, invert, density_max, density_bounds)
        *fields, labels = _kdm.query_classes(
            self._handle, rect, scale, specs, ready, callables, maxima, bounds, _checks.flag("vectorized", vectorized),
            density_rect, tile_size, mode, origin, workers)
        return QueryResult(*fields, classes=labels)


def _workers(threads: Any) -> int:
    """`threads` as query() and positions() take it: None, one query (0); else the workers of a parallel
    query, 0 standing for the CPUs this process may use."""
    if threads is None:
        return 0
    if isinstance(threads, bool) or not isinstance(threads, numbers.Integral):
        raise TypeError(f"threads must be an int, got {type(threads).__name__}")
    if not 0 <= threads <= 64:
        raise ValueError(f"threads must be 0 (the CPUs this process may use) or 1 to 64, got {threads}")
    return int(threads) or max(1, min(64, len(os.sched_getaffinity(0))))


def _query_args(rect: Any, scale: Any, tile_size: Any, mode: Any, origin: Any, density_rect: Any,
                density_max: Any, glide_together: Any = False) -> Tuple[Any, ...]:
    """A query's common arguments, checked (ValueError, TypeError) and normalised."""
    rect = _checks.rect("rect", rect, allow_empty=True)
    scale = _checks.number("scale", scale)
    tile_size = _checks.number("tile_size", tile_size)
    mode = _checks.choice("mode", mode, ("stable", "smooth"))
    if _checks.flag("glide_together", glide_together):
        mode += "/together"  # the extension's spelling of QueryParams::glide_together
    origin = _checks.numbers_tuple("origin", origin, 2)
    if density_rect is not None:
        density_rect = _checks.rect("density_rect", density_rect)
    if density_max is not None:  # 0 would never call the callable: no points, and no check of its values
        density_max = _checks.number("density_max", density_max, 0.0, strict=True)
    return rect, scale, tile_size, mode, origin, density_rect, density_max


def _is_callable(density: Any) -> bool:
    return callable(density) and not isinstance(density, (np.ndarray, numbers.Real, str))


def _class_args(classes: Any, gamma: Any, invert: Any, density_max: Any,
                density_bounds: Any = None) -> Tuple[List[Any], List[Any], List[Any], List[float], List[Any]]:
    """A query's classes as (specs, ready, callables, maxima, bounds), one each per class, checked
    (TypeError, ValueError): a class is its spec (prepared, where it is a DensityMap: ready), or its callable
    (not None) bounded by its maximum, from `density_max` (one number for every callable class, or one
    entry per class), with its bounds function if `density_bounds` (one entry per class) gives one."""
    if isinstance(classes, np.ndarray) and classes.ndim == 1:  # constant densities, one per class
        classes = [float(v) for v in classes]
    if isinstance(classes, (str, numbers.Real)) or not isinstance(classes, Sequence):
        raise TypeError(f"classes must be a sequence of densities, got {type(classes).__name__}")
    if not 1 <= len(classes) <= 8:
        raise ValueError(f"classes must hold 1 to 8 densities, got {len(classes)}")
    per_class = density_max is not None and not isinstance(density_max, numbers.Real)
    if per_class and (isinstance(density_max, (str, bytes)) or not hasattr(density_max, "__len__")):
        raise TypeError(f"density_max must be a number or a sequence, got {type(density_max).__name__}")
    if per_class and len(density_max) != len(classes):
        raise ValueError(f"density_max must hold one entry per class ({len(classes)}), got {len(density_max)}")
    if density_max is not None and not any(_is_callable(d) for d in classes):
        raise ValueError("density_max applies to callable classes only")
    if density_bounds is not None:
        if callable(density_bounds) or isinstance(density_bounds, (str, bytes)) or not hasattr(
                density_bounds, "__len__"):
            raise TypeError("density_bounds with classes must be a sequence of one callable or None per class, "
                            f"got {type(density_bounds).__name__}")
        if len(density_bounds) != len(classes):
            raise ValueError(f"density_bounds must hold one entry per class ({len(classes)}), "
                             f"got {len(density_bounds)}")
    specs, ready, callables, maxima, bounds = [], [], [], [], []
    for k, d in enumerate(classes):
        name = f"classes[{k}]"
        b = density_bounds[k] if density_bounds is not None else None
        if b is not None and not callable(b):
            raise TypeError(f"density_bounds[{k}] must be callable or None, got {type(b).__name__}")
        bounds.append(b)
        ready.append(d._ready if isinstance(d, DensityMap) else None)
        if isinstance(d, DensityMap):
            if per_class and density_max[k] is not None:
                raise ValueError(f"density_max[{k}] is given but {name} is not a callable (give None there)")
            if b is not None:
                raise ValueError(f"density_bounds[{k}] is given but {name} is not a callable")
            specs.append(d._spec)
            callables.append(None)
            maxima.append(0.0)
            continue
        if _is_callable(d):
            bound = density_max[k] if per_class else density_max
            if bound is None:
                raise ValueError(f"{name} is a callable: density_max must give an upper bound of its values")
            _checks.density_function(name, d, 2, None)
            specs.append(_kdm.DensitySpec.constant(0.0))
            callables.append(d)
            maxima.append(_checks.number(f"density_max[{k}]" if per_class else "density_max", bound, 0.0,
                                         strict=True))
            continue
        if per_class and density_max[k] is not None:
            raise ValueError(f"density_max[{k}] is given but {name} is not a callable (give None there)")
        if b is not None:
            raise ValueError(f"density_bounds[{k}] is given but {name} is not a callable")
        if d is None:
            raise TypeError(f"{name} must be a number, a str, a 2-D array or a callable, got None")
        text = isinstance(d, (str, os.PathLike))
        specs.append(_checks.density_spec(d, gamma if text else 1.0, invert if text else False, name,
                                          one_of_several=True, callable_ok=True))
        callables.append(None)
        maxima.append(0.0)
    reshaped = _checks.number("gamma", gamma, 0.0, strict=True) != 1.0 or _checks.flag("invert", invert)
    if reshaped and any(isinstance(d, DensityMap) for d in classes):
        raise ValueError("gamma and invert are a DensityMap's own: give them to DensityMap()")
    files = [s for d, s in zip(classes, specs) if isinstance(d, (str, os.PathLike))]
    if reshaped and not any(s.kind == "image" for s in files):
        raise ValueError("gamma and invert apply to image files only, and no class is one")
    return specs, ready, callables, maxima, bounds


def _density_arg(density: Any, gamma: Any, invert: Any) -> Tuple[Any, Any, Any]:
    """A query's density as (spec, callable, ready): spec or callable None, ready the prepared density of a
    DensityMap (else None); no density is the constant 1."""
    if isinstance(density, DensityMap):
        if _checks.number("gamma", gamma, 0.0, strict=True) != 1.0 or _checks.flag("invert", invert):
            raise ValueError("gamma and invert are the DensityMap's own: give them to DensityMap()")
        return density._spec, None, density._ready
    if _is_callable(density):
        _checks.density_function("density", density, 2, None)
        return None, density, None
    spec = _checks.density_spec(density, gamma, invert, callable_ok=True)
    return (spec if spec is not None else _kdm.DensitySpec.constant(1.0)), None, None


def bake(recipe_text: str, *, threads: int = 0) -> Tileset:
    """Bakes a tile set from recipe text ("key value" lines, as ``kdm bake`` reads from a file).

    A recipe gives the same set for any `threads` (worker threads; 0: one per core). Real sets take
    minutes to hours; a recipe of a few small levels bakes in seconds. Ctrl-C stops it after the runs it is
    sampling. Raises ValueError for a bad recipe, some values only once baking finds them (a hand-over
    whose subtiles hold too few points: the message names the key to change).
    """
    if isinstance(recipe_text, os.PathLike):
        raise TypeError("recipe_text is the recipe's text: read the file first (pathlib.Path(p).read_text())")
    if not isinstance(recipe_text, str):
        raise TypeError(f"recipe_text must be a str, got {type(recipe_text).__name__}")
    if recipe_text and not any(c.isspace() for c in recipe_text.strip()) and os.path.exists(recipe_text):
        raise ValueError(f"recipe_text '{recipe_text}' names a file: give its text (open(...).read())")
    threads = _checks.threads(threads)
    return Tileset(_kdm.bake(recipe_text, threads))
