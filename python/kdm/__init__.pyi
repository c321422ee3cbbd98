# Type hints of the kdm package (the implementation is kdm/*.py over the compiled kdm._kdm).
import os
from typing import Any, Callable, Dict, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt
from scipy.stats.qmc import QMCEngine as _QMCEngine  # type: ignore[import]

__version__: str
__all__: list[str]

_Path = Union[str, os.PathLike[str]]
_Density = Union[None, float, _Path, npt.ArrayLike]
_Rect = Sequence[float]
_Bounds = Callable[[float, float, float, float], Tuple[float, float]]
_Function = Callable[[float, float], float]

def sample(
    n: int,
    density: Union[_Density, Callable[..., float]] = ...,  # a 3-D array (depth, height, width) with dim=3
    *,
    dim: int = ...,
    domain: Optional[str] = ...,
    temperature: float = ...,
    seed: int = ...,
    threads: int = ...,
    aspect: Union[None, float, Tuple[float, float, float]] = ...,  # in 3-D also the three sides (x, y, z)
    gamma: float = ...,
    invert: bool = ...,
    classes: Optional[Sequence[_Density]] = ...,
    sweeps: Optional[int] = ...,
    coarse_sweeps: Optional[int] = ...,
    sets: Optional[int] = ...,  # (sets, n, dim) for seeds seed, seed + 1, ...
    vectorized: bool = ...,  # density f takes coordinate arrays and returns an array
) -> Union[npt.NDArray[np.float64], Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint8]]]: ...

class QueryResult:
    points: npt.NDArray[np.void]
    xy: npt.NDArray[np.float64]
    tile: npt.NDArray[np.int64]
    rank: npt.NDArray[np.uint32]
    level: npt.NDArray[np.uint32]
    classes: Optional[npt.NDArray[np.uint8]]
    @property
    def depth(self) -> npt.NDArray[np.uint32]: ...
    @property
    def keys(self) -> npt.NDArray[np.uint64]: ...
    def __getitem__(self, index: Union[int, slice, npt.ArrayLike]) -> QueryResult: ...
    def __init__(
        self,
        points: npt.NDArray[np.void],
        xy: npt.NDArray[np.float64],
        tile: npt.NDArray[np.int64],
        rank: npt.NDArray[np.uint32],
        level: npt.NDArray[np.uint32],
        storage: Any = ...,
        classes: Optional[npt.NDArray[np.uint8]] = ...,
    ) -> None: ...
    def __len__(self) -> int: ...
    def __iter__(self) -> Iterator[QueryResult]: ...

class DensityMap:
    @property
    def rect(self) -> Optional[Tuple[float, ...]]: ...
    def at(self, x: npt.ArrayLike, y: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def __init__(
        self, density: Union[float, _Path, npt.ArrayLike], rect: Optional[_Rect] = ..., *, gamma: float = ...,
        invert: bool = ...
    ) -> None: ...
    @property
    def kind(self) -> str: ...

_QueryDensity = Union[_Density, DensityMap, _Function]

class Tileset:
    def __init__(self, handle: Any) -> None: ...
    @classmethod
    def builtin(cls) -> Tileset: ...
    @classmethod
    def load(cls, path: _Path) -> Tileset: ...
    @classmethod
    def from_bytes(cls, data: Union[bytes, bytearray, memoryview]) -> Tileset: ...
    def to_bytes(self) -> bytes: ...
    def save(self, path: _Path) -> None: ...
    @property
    def info(self) -> Dict[str, Any]: ...
    def thresholds(
        self, result: Union[QueryResult, npt.NDArray[np.uint64]], *, near_tile: Optional[Sequence[int]] = ...
    ) -> npt.NDArray[np.float64]: ...
    def stable_positions(
        self, result: QueryResult, *, tile_size: float = ..., origin: Sequence[float] = ...
    ) -> npt.NDArray[np.float64]: ...
    def query(
        self,
        rect: _Rect,
        *,
        scale: float,
        density: _QueryDensity = ...,
        classes: Optional[Sequence[_QueryDensity]] = ...,
        density_rect: Optional[_Rect] = ...,
        density_max: Union[float, Sequence[Optional[float]], None] = ...,
        density_bounds: Optional[Union[_Bounds, Sequence[Optional[_Bounds]]]] = ...,
        vectorized: bool = ...,
        tile_size: float = ...,
        mode: str = ...,
        origin: Sequence[float] = ...,
        gamma: float = ...,
        invert: bool = ...,
        glide_together: bool = ...,
        threads: Optional[int] = ...,
        out: Optional[QueryResult] = ...,
    ) -> QueryResult: ...
    def positions(
        self,
        rect: _Rect,
        *,
        scale: float,
        density: _QueryDensity = ...,
        density_rect: Optional[_Rect] = ...,
        density_max: Union[float, Sequence[Optional[float]], None] = ...,
        density_bounds: Optional[Union[_Bounds, Sequence[Optional[_Bounds]]]] = ...,
        vectorized: bool = ...,
        tile_size: float = ...,
        mode: str = ...,
        origin: Sequence[float] = ...,
        gamma: float = ...,
        invert: bool = ...,
        glide_together: bool = ...,
        keys: bool = ...,
        threads: Optional[int] = ...,
        classes: Optional[Sequence[_QueryDensity]] = ...,
    ) -> Union[npt.NDArray[np.float32], Tuple[npt.NDArray[Any], ...]]: ...

class Ink(str):
    colour: str
    def __new__(cls, name: str, colour: str) -> Ink: ...

def bake(recipe_text: str, *, threads: int = ...) -> Tileset: ...
def zoom_regions(region: Sequence[float], frames: int) -> npt.NDArray[np.float64]: ...
def separate(
    image: _Path,
    *,
    colours: Union[str, int, Sequence[str]] = ...,
    gamma: float = ...,
    white: Optional[float] = ...,
) -> Tuple[npt.NDArray[np.float32], List[Ink]]: ...
def stipple(
    image: Union[_Path, npt.ArrayLike],
    *,
    points: int = ...,
    scale: Optional[float] = ...,
    method: str = ...,
    mode: Optional[str] = ...,
    region: Optional[_Rect] = ...,
    gamma: float = ...,
    invert: bool = ...,
    seed: int = ...,
    tileset: Union[Tileset, _Path, None] = ...,
    output: Optional[_Path] = ...,
    width: Optional[int] = ...,
    dot_size: Optional[float] = ...,
    threads: int = ...,
    colours: Union[str, int, Sequence[str], None] = ...,
    fade: float = ...,
    paper_width: Optional[str] = ...,
    height: Optional[int] = ...,
    white: Optional[float] = ...,
    ids: bool = ...,
) -> Any: ...
def analyze(
    points: Union[npt.ArrayLike, Sequence[npt.NDArray[np.float64]]],
    classes: Optional[Union[npt.ArrayLike, Sequence[npt.ArrayLike]]] = ...,
    *,
    box: bool = ...,
    density: Union[_Density, _Function] = ...,
    class_densities: Optional[Sequence[Union[_Density, _Function]]] = ...,
    tile_size: Optional[float] = ...,
    fmax: float = ...,
    threads: int = ...,
    energy: bool = ...,
    gamma: float = ...,
    invert: bool = ...,
    min_expected: float = ...,
    density_bands: int = ...,
    holes_min_density: float = ...,
    aspect: Union[None, float, Tuple[float, float, float]] = ...,  # the domain's shape, as kdm.sample's
    periodogram: bool = ...,
) -> Dict[str, Any]: ...

_Seed = Union[None, int, np.random.Generator, np.random.RandomState, np.random.SeedSequence, np.random.BitGenerator]
_Aspect = Union[None, float, Tuple[float, float, float]]  # the three sides (x, y, z) with d=3

# At runtime BlueNoise derives from SciPy's QMCEngine where SciPy is installed (else from a base of the same
# interface, kdm._engine._Engine).
class BlueNoise(_QMCEngine):
    d: int
    rng: Union[np.random.Generator, np.random.RandomState]
    rng_seed: Any
    num_generated: int
    temperature: float
    domain: Optional[str]
    density: Union[_Density, Callable[..., float]]
    threads: int
    aspect: _Aspect
    vectorized: bool
    def __init__(
        self,
        d: int = ...,
        *,
        seed: _Seed = ...,
        rng: _Seed = ...,
        temperature: float = ...,
        domain: Optional[str] = ...,
        density: Union[_Density, Callable[..., float]] = ...,
        threads: int = ...,
        aspect: _Aspect = ...,
        vectorized: bool = ...,  # density f takes coordinate arrays and returns an array
    ) -> None: ...
    def __copy__(self) -> BlueNoise: ...
    def random(self, n: int = ..., *, workers: int = ...) -> npt.NDArray[np.float64]: ...
    def reset(self) -> BlueNoise: ...
    def fast_forward(self, n: int) -> BlueNoise: ...
    def integers(
        self,
        l_bounds: npt.ArrayLike,
        *,
        u_bounds: Optional[npt.ArrayLike] = ...,
        n: int = ...,
        endpoint: bool = ...,
        workers: int = ...,
    ) -> npt.NDArray[np.int64]: ...
