"""Argument checks shared by kdm's functions.

A value of the wrong type raises TypeError and a bad value ValueError, each naming the argument, before
anything reaches the C++ libraries (which check again, so nothing a caller passes can crash them).
"""
from __future__ import annotations

import functools
import inspect
import math
import numbers
import os
import re
import warnings
from typing import Any, Callable, Optional, Sequence, Tuple

import numpy as np

from . import _kdm


def integer(name: str, value: Any, minimum: Optional[int] = None, maximum: Optional[int] = None) -> int:
    """`value` as an int (numpy integers too, never bool), within [minimum, maximum]."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__}")
    value = int(value)
    if minimum is not None and value < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {value}")
    if maximum is not None and value > maximum:
        raise ValueError(f"{name} must be <= {maximum}, got {value}")
    return value


def number(name: str, value: Any, minimum: Optional[float] = None, strict: bool = False) -> float:
    """`value` as a finite float, at least `minimum` (above it when `strict`)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a number, got {type(value).__name__}")
    try:
        value = float(value)
    except OverflowError:  # an int past a double's range
        raise ValueError(f"{name} must be a finite number, got an integer of {value.bit_length()} bits") from None
    if not math.isfinite(value):
        raise ValueError(f"{name} must be a finite number, got {value}")
    if minimum is not None and (value <= minimum if strict else value < minimum):
        raise ValueError(f"{name} must be {'>' if strict else '>='} {minimum:g}, got {value:g}")
    return value


def temperature(value: Any) -> float:
    """The sampler's temperature: 0 to 1000, as `kdm sample --temperature` takes it."""
    value = number("temperature", value, 0.0)
    if value > 1000:
        raise ValueError("temperature must be at most 1000: past it nearly every move is refused and the points "
                         "keep their starting places (100 and up already give near white noise)")
    return value


def white(value: Any, file: bool) -> float:
    """A Radiance picture's luminance that is white, as `kdm stipple --white` takes it: None (0: its brightest
    pixel's) or finite and > 0, for an image `file` (the C++ side refuses one that is no Radiance picture)."""
    if value is None:
        return 0.0
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise TypeError(f"white must be a number, got {type(value).__name__}")
    try:
        white = float(value)
    except OverflowError:  # an int past a double's range
        white = math.inf
    if not (white > 0 and math.isfinite(white)):
        raise ValueError(f"white must be a finite number > 0 (the luminance that is white), got {white:g}")
    if not file:
        raise ValueError("white sets the luminance that is white in a Radiance .hdr picture, and an array or PIL "
                         "image is none (its white is already its type's: 1.0, 255 or 65535)")
    return white


def aspect(value: Any) -> Optional[float]:
    """A domain's width / height (in 3-D, its x side over its y and z sides), or None."""
    return None if value is None else number("aspect", value, 0.0, strict=True)


def aspect_or_sides(value: Any, dim: int, dim_name: str = "dim"
                    ) -> Tuple[Optional[float], Optional[Tuple[float, float, float]]]:
    """kdm.sample's aspect: None, one number (the x side over the others), or in 3-D three sides (x, y, z),
    each finite and > 0 (their ratios count). Returns (number or None, sides or None). `dim_name` is the
    caller's name for the dimension (kdm.sample's dim, BlueNoise's d), for the messages."""
    if value is None or isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_)):
        return aspect(value), None
    if isinstance(value, (str, bytes)) or not isinstance(value, (Sequence, np.ndarray)):
        raise TypeError(f"aspect must be a number or a sequence of three sides (x, y, z), got {type(value).__name__}")
    values = list(value)
    if len(values) != 3:
        raise ValueError(f"aspect must be a number or three sides (x, y, z), got {len(values)} values")
    if dim != 3:
        raise ValueError(f"aspect=(x, y, z) sets a 3-D domain's sides: use {dim_name}=3, or give one number "
                         "(width / height)")
    sides = tuple(number(f"aspect[{k}]", v, 0.0, strict=True) for k, v in enumerate(values))
    return None, sides  # type: ignore[return-value]


def threads(value: Any) -> int:
    """A worker-thread count: 0 for the default (OMP_NUM_THREADS, else the CPUs this process may use), at
    most _kdm.MAX_THREADS (256) as on the command line."""
    return integer("threads", value, 0, _kdm.MAX_THREADS)


def flag(name: str, value: Any) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {type(value).__name__}")
    return bool(value)


def choice(name: str, value: Any, options: Sequence[str]) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a str, got {type(value).__name__}")
    if value not in options:
        raise ValueError(f"{name} must be one of {', '.join(repr(o) for o in options)}, got {value!r}")
    return value


def path(name: str, value: Any) -> str:
    """A file name: a str or an os.PathLike of one."""
    if isinstance(value, os.PathLike):
        value = os.fspath(value)
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a path (str or os.PathLike), got {type(value).__name__}")
    return value


def numbers_tuple(name: str, value: Any, count: int) -> Tuple[float, ...]:
    """A sequence of `count` finite numbers, as floats."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or not hasattr(value, "__getitem__"):
        raise TypeError(f"{name} must be a sequence of {count} numbers, got {type(value).__name__}")
    if len(value) != count:
        raise ValueError(f"{name} must hold {count} numbers, got {len(value)}")
    return tuple(number(f"{name}[{i}]", value[i]) for i in range(count))


def rect(name: str, value: Any, allow_empty: bool = False) -> Tuple[float, ...]:
    """(x0, y0, x1, y1) with x0 < x1 and y0 < y1, or with `allow_empty` any four finite numbers (a query's
    region: none of its points when x1 <= x0 or y1 <= y0, as in C and C++)."""
    r = numbers_tuple(name, value, 4)
    if not allow_empty and not (r[0] < r[2] and r[1] < r[3]):
        raise ValueError(f"{name} is empty or inverted (needs x0 < x1 and y0 < y1): {r}")
    return r


def unmasked(name: str, value: Any, fill: str) -> None:
    """Refuses a numpy masked array (TypeError): np.asarray drops its mask, so its masked entries would be
    read as whatever values they hide. `fill` says what to pass instead."""
    if isinstance(value, np.ma.MaskedArray):
        raise TypeError(f"{name} is a masked array, and kdm would ignore its mask (reading the values it hides): "
                        f"pass {fill}")


def _real_array(name: str, value: Any, fill: Optional[str] = None,
                shapes: str = "a 2-D array (rows, columns)") -> np.ndarray:
    """`value` as a numpy array of real numbers (bool, integer or float), else ValueError or TypeError.
    A masked array is refused (unmasked()); `fill` says what to pass instead (default: the density's
    .filled(0)); `shapes` what a ragged one should have been."""
    unmasked(name, value, fill or f"{name}.filled(0), no density where it is masked")
    try:
        a = np.asarray(value)
    except ValueError as e:  # ragged nested lists
        raise ValueError(f"{name} must be {shapes}: {e}") from None
    except Exception as e:  # an object whose __array__ fails
        raise TypeError(f"{name} must be a 2-D array of numbers: {e}") from None
    if a.dtype.kind not in "biuf":
        raise TypeError(f"{name} must hold real numbers, got dtype {a.dtype}")
    return a


def array2d(name: str, value: Any, fill: Optional[str] = None) -> np.ndarray:
    """A 2-D array of numbers as C-contiguous float64 (copied only when it is not that already); `fill` as
    _real_array's."""
    a = _real_array(name, value, fill)
    if a.ndim != 2:
        raise ValueError(f"{name} must be a 2-D array (rows, columns), got shape {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float64)


# What a masked image should be filled with: paper.
_PAPER = "image.filled(white) (1.0 for floats, 255 for uint8, 65535 for uint16): no ink where it is masked"


def _samples(name: str, value: Any) -> Tuple[np.ndarray, int]:
    """An image array as float32 samples in [0, 1] (uint8 and uint16 divided by 255 and 65535) and its
    channel count (1 for a 2-D array)."""
    a = _real_array(name, value, _PAPER)
    if not (a.ndim == 2 or (a.ndim == 3 and a.shape[2] in (1, 2, 3, 4))):
        raise ValueError(f"{name} must be a 2-D array (rows, columns) of luminance, or (rows, columns, k): k = 1 "
                         f"grey, 2 grey and alpha, 3 or 4 colour (RGB, RGBA), got shape {a.shape}")
    full = {np.dtype(np.uint8): 255, np.dtype(np.uint16): 65535}.get(a.dtype)
    if full is None and a.dtype.kind != "f":  # int64, say, has no white: 8-bit levels or 0 and 1?
        plain = " (as a list of Python ints makes)" if a.dtype == np.dtype(int) else ""
        raise ValueError(f"{name}: integer arrays must be uint8 (0-255) or uint16 (0-65535), got {a.dtype}{plain}: "
                         f"pass 8-bit levels as np.asarray({name}, np.uint8), or luminances as floats in [0, 1]")
    p = a.astype(np.float32) / np.float32(full or 1)
    if full is None and not (np.isfinite(p).all() and p.min(initial=0) >= 0 and p.max(initial=0) <= 1):
        raise ValueError(f"{name}: values must be in [0, 1] (8-bit pixels: pass them as uint8, or divide by 255)")
    return (p[..., None] if a.ndim == 2 else p), (1 if a.ndim == 2 else a.shape[2])


def colour(name: str, value: Any) -> Tuple[np.ndarray, Optional[np.ndarray]]:
    """An image array as load_colour_image reads a file: (rows, columns, 3) float32 red, green and blue
    composited on white (grey: three equal channels), and its alpha (rows, columns) or None."""
    unmasked(name, value, _PAPER)
    p, channels = _samples(name, np.asarray(value) if hasattr(value, "__array_interface__") else value)
    alpha = p[..., 1] if channels == 2 else p[..., 3] if channels == 4 else None
    colour = p[..., :1].repeat(3, axis=2) if channels < 3 else p[..., :3]
    a = np.float32(1) if alpha is None else alpha[..., None]
    rgb = np.clip(colour * a + (np.float32(1) - a), 0, 1).astype(np.float32)
    return np.ascontiguousarray(rgb), None if alpha is None else np.ascontiguousarray(alpha)


_PENS = re.compile(r"\s*#?[0-9a-fA-F]{6}\s*")


def colour_scheme(value: Any) -> str:
    """colours as `kdm stipple --colours` takes them: "cmyk", "rgb", a number of inks (an int too), or pens as
    one str "#e00000,#0000aa" or a list or tuple of them, each "#rrggbb" or "rrggbb" (joined into that str)."""
    if isinstance(value, numbers.Integral) and not isinstance(value, (bool, np.bool_)):
        return str(int(value))
    if isinstance(value, (list, tuple)):
        if not value:
            raise ValueError("colours is an empty list: give 1 to 8 pens, as ['#e00000', '#0000aa']")
        for k, pen in enumerate(value):
            if not isinstance(pen, str):
                raise TypeError(f"colours[{k}] must be a pen as a str ('#e00000'), got {type(pen).__name__}")
            if not _PENS.fullmatch(pen):  # said here: joined, '3' would be read as a number of inks
                raise ValueError(f"colours[{k}] must be a pen as #rrggbb ('#e00000'), got {pen!r}")
        # Each with its '#', so that one pen alone is read as a pen, as in a list of several.
        return ",".join("#" + pen.strip().lstrip("#") for pen in value)
    if not isinstance(value, str):
        raise TypeError("colours must be 'cmyk', 'rgb', a number of inks (2 to 8), or pens as a str "
                        f"('#e00000,#0000aa') or a list of them (['#e00000', '#0000aa']), got {type(value).__name__}")
    return value


def luminance(name: str, value: Any) -> Tuple[np.ndarray, Optional[np.ndarray]]:
    """An image array as load_grey_image reads a file: (luminance in [0, 1], 2-D float64; its alpha, 2-D
    float64, or None). Float values as they are; uint8 and uint16 divided by 255 and 65535; (rows, columns,
    3 or 4) RGB(A), or 2 (grey and alpha), to 0.2126 R + 0.7152 G + 0.0722 B composited on white paper, in
    float32 as kdm reads files (the same densities as the file's pixels; with the alpha, inverted ones on
    black paper too). A PIL image is an array too."""
    unmasked(name, value, _PAPER)
    a = np.asarray(value) if is_array(value) or hasattr(value, "__array_interface__") else value
    if getattr(a, "ndim", 0) == 2 and getattr(a, "dtype", None) is not None and a.dtype.kind == "f":
        return np.ascontiguousarray(a, dtype=np.float64), None  # luminance as given (checked in [0, 1] after)
    p, channels = _samples(name, a)
    lum = p[..., 0] if channels < 3 else (np.float32(0.2126) * p[..., 0] + np.float32(0.7152) * p[..., 1]
                                          + np.float32(0.0722) * p[..., 2])
    alpha = p[..., 1] if channels == 2 else p[..., 3] if channels == 4 else None
    a = np.float32(1) if alpha is None else alpha
    grey = np.ascontiguousarray(np.clip(lum * a + (np.float32(1) - a), 0, 1), dtype=np.float64)
    return grey, None if alpha is None else np.ascontiguousarray(alpha, dtype=np.float64)


def image_size(value: Any) -> None:
    """Refuses an image array or PIL image of more pixels than kdm takes (ValueError, the C++ side's rule and
    words), from its shape alone: before anything converts or copies it (gigabytes for a large one)."""
    size = getattr(value, "size", None)
    if isinstance(size, tuple) and len(size) == 2 and hasattr(value, "mode"):  # PIL: (width, height)
        rows, columns = size[1], size[0]
    else:
        shape = getattr(value, "shape", None)
        if not isinstance(shape, tuple) or len(shape) < 2:
            return  # a list is converted to see its shape; a bad shape is refused after
        rows, columns = shape[0], shape[1]
    if isinstance(rows, numbers.Integral) and isinstance(columns, numbers.Integral):
        _kdm.check_image_size("image array", int(rows), int(columns))


def pil_pixels(value: Any) -> Any:
    """A PIL image as the array of pixels luminance() and colour() read, as an image file of it is read: grey,
    grey and alpha, RGB and RGBA as they are (16-bit grey too); grey and RGB with a transparent colour
    (info["transparency"], a PNG's tRNS) with an alpha, 0 at that colour; a palette, CMYK, YCbCr and the
    other modes converted to RGB, or RGBA where they hold transparency. Anything else is returned as it is."""
    mode = getattr(value, "mode", None)
    if not isinstance(mode, str) or not hasattr(value, "convert") or not hasattr(value, "info"):
        return value
    key = value.info.get("transparency")
    if mode in ("LA", "RGBA") or mode in ("L", "RGB", "I;16", "I;16L", "I;16B") and key is None:
        return value
    if mode == "1":
        if key is None:
            return value.convert("L")
        a = np.asarray(value)
        return _keyed(a.astype(np.uint8) * np.uint8(255), a == bool(key))
    if mode == "I":  # how Pillow opens some 16-bit grey files: 32-bit integers holding 0 .. 65535
        a = np.asarray(value)
        if a.size and (a.min() < 0 or a.max() > 65535):
            raise ValueError("a PIL image of mode 'I' must hold 16-bit grey levels 0 to 65535")
        if a.size and 0 < a.max() <= 255:  # an 8-bit image converted to "I" would be drawn near black
            warnings.warn("a PIL image of mode 'I' is read as 16-bit grey (0 to 65535), but every level of this "
                          "one is 255 or less: if they are 8-bit levels, pass image.convert('L')", UserWarning,
                          stacklevel=3)  # the line that called stipple() or separate()
        return a.astype(np.uint16) if key is None else _keyed(a.astype(np.uint16), a == key)
    if mode in ("L", "I;16", "I;16L", "I;16B"):  # with a key: Pillow's convert("LA") ignores a 16-bit one
        a = np.asarray(value).astype(np.uint8 if mode == "L" else np.uint16)
        return _keyed(a, a == key)
    if mode == "RGB":
        a = np.asarray(value)
        return _keyed(a, (a == np.asarray(key)).all(axis=2))
    if mode == "F":
        raise ValueError("a PIL image of mode 'F' has no set range: give an array of luminances in [0, 1]")
    transparent = "A" in mode or "a" in mode or "transparency" in value.info
    return value.convert("RGBA" if transparent else "RGB")


def _keyed(pixels: np.ndarray, transparent: np.ndarray) -> np.ndarray:
    """Grey (rows, columns) or RGB (rows, columns, 3) pixels with an alpha channel appended: 0 where
    `transparent`, full (255 or 65535 by the pixels' dtype) elsewhere."""
    full = np.iinfo(pixels.dtype).max
    alpha = np.where(transparent, 0, full).astype(pixels.dtype)
    return np.dstack([pixels, alpha])


def is_array(value: Any) -> bool:
    return isinstance(value, (np.ndarray, list, tuple)) or hasattr(value, "__array__")


def scalar_if_0d(value: Any) -> Any:
    """A 0-d array of a real number as that number: np.asarray(0.5) is the density 0.5, as np.float32(0.5)
    is. Anything else as it is."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "fiu":
        return value.item()
    return value


def density_spec(density: Any, gamma: Any = 1.0, invert: Any = False, name: str = "density",
                 one_of_several: bool = False, callable_ok: bool = False) -> Any:
    """A density as the C++ side takes it (_kdm.DensitySpec), or None for None.

    A number is a constant (finite, >= 0); a str or path is what `--density` accepts ("const:V", "ramp:R",
    "radial:R" or an image file, whose darkness to the power `gamma` is the density, or its luminance with
    `invert`); a 2-D array holds densities with row 0 at the top. `gamma` or `invert` with no image file
    is refused (they would be ignored), unless `one_of_several` (the caller checks the densities together:
    then None is no density either). `callable_ok`: the caller takes callables too (the TypeError says so).
    """
    density = scalar_if_0d(density)
    gamma = number("gamma", gamma, 0.0, strict=True)
    invert = flag("invert", invert)
    reshaped = gamma != 1.0 or invert
    if density is None:
        if reshaped and not one_of_several:
            raise ValueError("gamma and invert apply to image files only, and no density is given")
        return None
    if isinstance(density, (str, os.PathLike)):
        spec = _kdm.DensitySpec.parse(path(name, density), gamma, invert)
        if reshaped and spec.kind != "image" and not one_of_several:
            raise ValueError(f"gamma and invert apply to image files only, and {name} {spec.text!r} is not one")
        return spec
    if reshaped:
        raise ValueError("gamma and invert apply to image files only (an array or a number is the density)")
    if isinstance(density, numbers.Real) and not isinstance(density, (bool, np.bool_)):
        return _kdm.DensitySpec.constant(number(name, density, 0.0))
    if is_array(density):
        try:
            return _kdm.DensitySpec.from_values(array2d(name, density))
        except ValueError as e:  # the C++ side's messages do not know the name
            raise ValueError(str(e) if name == "density" or str(e).startswith(name) else f"{name}: {e}") from None
    kinds = ([] if one_of_several else ["None"]) + ["a number", "a str (const:V, ramp:R, radial:R or an image "
                                                    "path)", "a 2-D array"] + (["a callable"] if callable_ok else [])
    raise TypeError(f"{name} must be {', '.join(kinds[:-1])} or {kinds[-1]}, got {type(density).__name__}")


def array3d(name: str, value: Any) -> np.ndarray:
    """A 3-D array of numbers (depth, height, width) as C-contiguous float64."""
    a = _real_array(name, value)
    if a.ndim != 3:
        raise ValueError(f"{name} must be a 3-D array (depth, height, width), got shape {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float64)


def _shape_of_density(name: str, values: np.ndarray) -> np.ndarray:
    """The sampler's array of densities, of which only the shape matters: every value finite and >= 0, at any
    scale. Values past float32's range (the C++ side's) are divided by the largest, rather than flushed to
    0 or infinity; those within it are kept as they are."""
    bad = ~(np.isfinite(values) & (values >= 0))
    if bad.any():
        at = np.unravel_index(int(np.argmax(bad)), values.shape)
        what = "volume" if values.ndim == 3 else "array"
        raise ValueError(f"{name} {what} values must be finite and >= 0 (at any scale: only their shape matters), "
                         f"got {float(values[at]):.6g} at [{', '.join(str(int(i)) for i in at)}]")
    top = float(np.max(values)) if values.size else 0.0
    return values / top if top > 0 and not 1e-30 <= top <= 1e30 else values


def sampler_density(density: Any, gamma: Any, invert: Any, name: str = "density",
                    dim: Optional[int] = None) -> Any:
    """density_spec() for the full sampler, which needs something to sample. A 3-D array is a volume
    (depth, height, width) for dim=3. An array's values may have any scale (_shape_of_density). `dim`,
    if known, is the sample's (for messages)."""
    density = scalar_if_0d(density)
    ndim = 0
    if is_array(density) and not isinstance(density, (str, bytes)):
        shapes = {2: "a 2-D array (rows, columns)", 3: "a 3-D array (depth, height, width) for 3-D points"}.get(
            dim, "a 2-D array (rows, columns), or with dim=3 a 3-D array (depth, height, width)")
        ndim = _real_array(name, density, shapes=shapes).ndim
    if ndim == 3:
        if number("gamma", gamma, 0.0, strict=True) != 1.0 or flag("invert", invert):
            raise ValueError("gamma and invert apply to image files only (an array or a number is the density)")
        spec = _kdm.DensitySpec.from_volume(_shape_of_density(name, array3d(name, density)))
        if not spec.max_value > 0:
            raise ValueError(f"{name}: an array that is zero everywhere has nothing to sample (it needs some "
                             "density > 0)")
        return spec
    if ndim > 3:
        raise ValueError(f"{name} must be a 2-D array (rows, columns), or with dim=3 a 3-D array (depth, "
                         f"height, width), got shape {np.shape(density)}")
    if ndim == 2:
        density = _shape_of_density(name, array2d(name, density))
    spec = density_spec(density, gamma, invert, name)
    if spec is not None and not spec.max_value > 0:  # now, not at the first draw
        if spec.text in ("array", "number"):
            what = "an array that is zero everywhere" if spec.text == "array" else "a density of 0"
            raise ValueError(f"{name}: {what} has nothing to sample (it needs some density > 0)")
        ink = "; an all-white image has no ink" if spec.kind == "image" else ""
        raise ValueError(f"{name} {spec.text!r} is zero everywhere: nothing to sample{ink}")
    return spec


def other_name(wrong: str, right: str, why: str) -> Callable:
    """A decorator that refuses the keyword `wrong` (TypeError) saying to use `right` instead: kdm.sample's
    dim= and kdm.BlueNoise's d= (SciPy's name) are each the other's mistake, and Python's own refusal does
    not say which to use."""
    def wrap(f: Callable) -> Callable:
        @functools.wraps(f)
        def checked(*args: Any, **kwargs: Any) -> Any:
            if wrong in kwargs:
                raise TypeError(f"{f.__qualname__.split('.')[0]}() takes {right}=, not {wrong}= ({why})")
            return f(*args, **kwargs)
        return checked
    return wrap


def density_function(name: str, f: Any, dim: int, dim_name: Optional[str] = "dim") -> None:
    """Refuses (TypeError) a callable density that cannot take `dim` coordinates, f(x, y) or f(x, y, z), by
    its signature before any call: a TypeError raised inside a callable that takes them stays its own.
    `dim_name` names the argument that sets the dimension (None: the caller has none)."""
    try:
        signature = inspect.signature(f)
    except (TypeError, ValueError):  # some builtins have none to read: their calls will tell
        return
    try:
        signature.bind(*([0.0] * dim))
    except TypeError:
        call = "f(x, y, z)" if dim == 3 else "f(x, y)"
        given = f"with {dim_name}={dim} " if dim_name else ""
        raise TypeError(f"{name}: {given}the density is called as {call}, with {dim} coordinates, but this "
                        f"callable takes {signature}") from None


def class_specs(classes: Any, gamma: Any, invert: Any) -> list:
    """The full sampler's classes: 1 to 8 densities (numbers, str or 2-D arrays), as _kdm.DensitySpec."""
    unmasked("classes", classes, "classes.filled(0), no density where it is masked")
    if isinstance(classes, np.ndarray) and classes.ndim == 1:  # constant densities, one per class
        classes = [float(v) for v in classes]
    if isinstance(classes, (str, bytes, numbers.Real)) or not isinstance(classes, Sequence):
        raise TypeError(f"classes must be a sequence of densities, got {type(classes).__name__}")
    if not 1 <= len(classes) <= 8:
        raise ValueError(f"classes must hold 1 to 8 densities, got {len(classes)}")
    specs = []
    for k, d in enumerate(classes):
        if d is None or callable(d) and not isinstance(d, (np.ndarray, numbers.Real, str)):
            raise TypeError(f"classes[{k}] must be a number, a str or a 2-D array, got {type(d).__name__}")
        text = isinstance(d, (str, os.PathLike))
        try:
            specs.append(density_spec(d, gamma if text else 1.0, invert if text else False, f"classes[{k}]",
                                      one_of_several=True))
        except ValueError as e:  # the C++ side's messages do not know the name
            raise ValueError(str(e) if str(e).startswith(f"classes[{k}]") else f"classes[{k}]: {e}") from None
    reshaped = number("gamma", gamma, 0.0, strict=True) != 1.0 or flag("invert", invert)
    if reshaped and not any(s.kind == "image" for d, s in zip(classes, specs) if isinstance(d, (str, os.PathLike))):
        raise ValueError("gamma and invert apply to image files only, and no class is one")
    if not any(s.max_value > 0 for s in specs):
        raise ValueError("classes: every density is zero: nothing to sample")
    return specs
