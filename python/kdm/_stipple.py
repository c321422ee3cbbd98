"""kdm.stipple: an image as dots, as `kdm stipple` draws it (one picture; no zoom sequence); kdm.separate: its inks."""
from __future__ import annotations

import os
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from . import _checks, _kdm
from ._runtime import Tileset


class Ink(str):
    """An ink's name as ``kdm stipple`` prints it and an SVG's layer is called ("cyan", "ink-0-red"), a
    str, with its colour in pictures as ``.colour``, "#rrggbb": what a caller drawing the dots, or
    choosing pens for them, needs."""

    colour: str

    def __new__(cls, name: str, colour: str) -> "Ink":
        ink = super().__new__(cls, name)
        ink.colour = colour
        return ink

    def __getnewargs__(self) -> Tuple[str, str]:  # type: ignore[override]
        return str(self), self.colour


def _inks(pairs: Any) -> List[Ink]:
    return [Ink(name, colour) for name, colour in pairs]


def stipple(
    image: Any,
    *,
    points: int = 20000,
    scale: Optional[float] = None,
    method: str = "tiles",
    mode: Optional[str] = None,
    region: Optional[Sequence[float]] = None,
    gamma: float = 1.0,
    invert: bool = False,
    seed: int = 1,
    tileset: Optional[Tileset] = None,
    output: Any = None,
    width: Optional[int] = None,
    dot_size: Optional[float] = None,
    threads: int = 0,
    colours: Any = None,
    fade: float = 0.0,
    paper_width: Optional[str] = None,
    height: Optional[int] = None,
    white: Optional[float] = None,
    ids: bool = False,
) -> Any:
    """Stipple an image: its darkness becomes dot density (``kdm stipple``).

    Parameters
    ----------
    image : str, os.PathLike, array or PIL image
        An image file (PNG, JPEG, ...), or an array with row 0 at the TOP (as pictures are stored), its
        samples floats in [0, 1], uint8 or uint16: luminance (rows, columns) or (rows, columns, 1); grey and
        alpha (rows, columns, 2); or colour (rows, columns, 3 or 4), RGB(A), made luminance as a file is
        (0.2126 R + 0.7152 G + 0.0722 B); an alpha channel lays the image on paper, white (black with
        `invert`: transparent pixels get no dots either way), as a file with alpha is read. The
        image is stretched over [0, width/height] x [0, 1] in the tiling's units (`scale` counts dots
        per unit area there); the dots come back normalised (Returns). An image with no ink gives no dots.
        A file of up to 2^28 pixels (16384 x 16384) is averaged down as it is read to what its dots need (as ``kdm stipple``
        reads it: docs/limits.md, "Large pictures"); an array is used as it is.
        A path to a NumPy .npy file is read as ``kdm stipple`` reads one: not as a picture but as the density
        itself, a 2-D array (row 0 at the top) of values >= 0 at any scale, the larger the denser (1 dense,
        0 no dots); `gamma`, `invert` and `colours` are refused with it. An array is a picture instead: its
        luminance is the paper's (1, 255 or 65535 white: no dots; 0 black: the densest); with
        ``invert=True`` its values are the density (to the power `gamma`), so an array `d` of values in
        [0, 1] with ``invert=True`` gives the dots of a .npy file of `d` (scale densities into [0, 1]
        first: ``d / d.max()``).
    points : int
        Dots over the whole image (ignored when `scale` is given).
    scale : float or None
        Dots per unit area at full darkness (image height = 1 unit), instead of `points`. With tiles
        the dots then depend on `scale` and `seed`, not on the image (where its inks sum to at most full
        darkness): the frames of an animated image keep their dots where their tone stays, which
        `points` (rescaled by each frame's mean tone) does not.
    method : {"tiles", "full"}
        tiles: the runtime and a tile set (fast, zoom-coherent); full: the full KDM sampler (best, slow).
    mode : {"smooth", "stable"} or None
        For tiles: dots glide with the tone (smooth, the default) or never move (stable); refused with
        method "full", which has no tiles.
    region : (x0, y0, x1, y1) or None
        Part of the image's UV square [0, 1]^2 (y up) to render at the whole image's dot size (tiles
        only; past the square is blank paper, as in the first frames of zoom_regions()), a zoom of
        1 / its width, at most 2x in stable mode; in smooth mode with a tile set that hands over to m x m
        subtiles past its top level, 2 * m**4 x. None: the whole image.
    gamma, invert
        Darkness ** gamma is the density; invert: luminance instead of darkness (an array's values as the
        density: see `image`).
    seed : int
        Method "full": the sampler's seed. Method "tiles": where the image lies in the tile set's endless
        tiling (another seed, other dots; one seed, the same dots in every region).
    tileset : Tileset, str, os.PathLike or None
        For method "tiles": a set, or a tile-set file to load (default: the built-in set). When 1% or
        more of the dots lie where the picture asks fewer points per tile than the set's coarsest level
        holds (a set of few levels), they come out clumpy there: a UserWarning says so, as kdm stipple does.
    output : str, os.PathLike or None
        Also write .png (antialiased dots), .svg (circles, whole within a margin as wide as a dot around the
        picture, at the PNG's pixel coordinates: a pen plotter's drawing) or .txt/.csv (points), as kdm stipple does
        (another extension, .npy too, is a ValueError: the dots are returned as an array).
    width, dot_size
        The picture's width in pixels (None: 1024, or what `height` makes it; for a .png or .svg `output`
        only, refused with a points file), and the dot radius in pixels (None or 0: the size at which the
        whole image's dots cover as much of the picture as the image's mean darkness, in colour the
        inks' summed coverage, so that the picture keeps the image's tone), at most a quarter of the
        picture's shorter side.
    height : int or None
        The picture's height in pixels instead of `width` (which then follows the picture's shape), 1
        to 65536: for tall images (``kdm stipple --height``).
    paper_width : str or None
        For an .svg `output`: its printed width, a number and a unit ("180mm", "7.5in"; mm, cm, in, pt,
        pc or px), the height in proportion (``kdm stipple --paper-width``). None: `width` pixels.
    threads : int
        For method "full": worker threads (0: the default count); the dots do not depend on it.
    colours : {"cmyk", "rgb"}, int, str or list of pens, or None
        A colour stipple of the image, a file or an array (``kdm stipple --colours``): "cmyk" (black by under-colour
        removal), "rgb" (light on black), a number of inks, 2 to 8 (chosen among the image's own colours,
        the set whose mixes draw it best; fewer if another would draw it under 5% better, one black ink for
        a grey image), or
        your own pens as "#e00000,#0000aa,#000000" or a list or tuple of them, ["#e00000", "#0000aa"]
        (1 to 8); each pixel's colour is split over the inks; one class of dots per ink, all of them one
        blue-noise set.
    fade : float
        For method "tiles", in the picture written to `output`: a dot's area grows from 0 where it
        appears to full once the density there is this fraction higher (``kdm stipple --fade``), so
        that the dots of a zoom sequence grow in instead of popping up; it lightens the picture by about
        1 - ln(1 + fade) / fade (31% at 1, 64% at 5; the sphere measured 30% and 64%). 0 (off) to 10.
        The same dots are returned (to float precision).
    white : float or None
        For a Radiance .hdr file: the luminance that is white paper, brighter clipped to white (``kdm stipple
        --white``). None: its brightest pixel's. Refused for other images.

    ids : bool
        Also return each dot's id (method "tiles"): a uint64 that names the dot in every region, frame
        and tone of the image, as the id column of ``kdm stipple``'s .csv does, for following dots across
        the frames of a zoom or an animation (motion blur, instancing). Refused with method "full",
        whose dots are placed anew for every picture.

    Returns
    -------
    numpy.ndarray, or with `colours` a tuple (dots, classes, inks); with `ids`, the ids after them
        dots: (m, 2) float64, normalised to the rendered image or region, [0, 1) on both axes, y up;
        classes: (m,) uint8, each dot's ink; inks: the inks in class order (separate()'s), each an Ink:
        its name, a str, with its colour as ``.colour`` ("#rrggbb"); ids: (m,) uint64.
    """
    gamma = _checks.number("gamma", gamma, 0.0, strict=True)
    invert = _checks.flag("invert", invert)
    if isinstance(image, (str, os.PathLike)):
        label = _checks.path("image", image)
        white = _checks.white(white, True)
        if not label.startswith(("const:", "ramp:", "radial:")):
            try:  # said as colours' loader says it, not "a density is a picture, const:V, ..."
                os.stat(label)
            except OSError as e:
                raise type(e)(f"cannot read image '{label}': {e.strerror}") from None
            if colours is not None:  # as kdm stipple --colours says it, not as an image of no known type
                with open(label, "rb") as f:
                    if f.read(6) == b"\x93NUMPY":
                        raise ValueError(
                            f"'{label}' is a NumPy array of densities: stipple it without colours")
        spec = None  # read below, at the size its dots need
        rgb = alpha = None
    elif _checks.is_array(image) or hasattr(image, "__array_interface__"):  # a PIL image too
        white = _checks.white(white, False)
        _checks.image_size(image)
        label, image = "array", _checks.pil_pixels(image)
        grey, alpha = _checks.luminance("image", image)
        spec = _kdm.DensitySpec.from_luminance(grey, gamma, invert, alpha)
        rgb, alpha = _checks.colour("image", image) if colours is not None else (None, None)
    else:
        raise TypeError(f"image must be a path or an array (luminance or colour), got {type(image).__name__}")
    if scale is None:
        points = _checks.integer("points", points, 1, 2**31)
        scale = 0.0
    else:
        scale = _checks.number("scale", scale, 0.0, strict=True)
        points = 0
    method = _checks.choice("method", method, ("tiles", "full"))
    if mode is not None and method == "full":
        raise ValueError("mode applies to method='tiles' (the full sampler has no tiles)")
    mode = _checks.choice("mode", "smooth" if mode is None else mode, ("smooth", "stable"))
    if region is not None:
        region = _checks.numbers_tuple("region", region, 4)
    seed = _checks.integer("seed", seed, 0, 2**64 - 1)
    if isinstance(tileset, (str, os.PathLike)):  # a tile-set file, as kdm stipple --tileset takes
        tileset = Tileset.load(tileset)
    if tileset is not None and not isinstance(tileset, Tileset):
        raise TypeError(f"tileset must be a kdm.Tileset, a tile-set file or None, got {type(tileset).__name__}")
    if output is not None:
        output = _checks.path("output", output)
    if width is not None and height is not None:
        raise ValueError("give width or height, not both (the other follows the picture's shape)")
    sized = [name for name, v in (("width", width), ("height", height), ("dot_size", dot_size)) if v is not None]
    if sized and output is not None and os.path.splitext(output)[1].lower() not in (".png", ".svg"):
        raise ValueError(f"{sized[0]} sizes pictures: write .png or .svg (points files hold positions only)")
    width = 1024 if width is None else _checks.integer("width", width, 1, 65536)
    height = 0 if height is None else _checks.integer("height", height, 1, 65536)
    dot_size = 0.0 if dot_size is None else _checks.number("dot_size", dot_size, 0.0)
    threads = _checks.threads(threads)
    fade = _checks.number("fade", fade, 0.0)
    if fade > 10:
        raise ValueError(f"fade must be a fraction of density from 0 (off) to 10, got {fade}")
    if fade > 0 and method == "full":
        raise ValueError("fade needs method='tiles' (dots that appear)")
    ids = _checks.flag("ids", ids)
    if ids and method == "full":
        raise ValueError("ids name the tiles' dots: method='full' places its dots anew for every picture")
    if colours is not None:
        if invert:
            raise ValueError("invert does not apply to colours (each ink has its own channel)")
        colours = _checks.colour_scheme(colours)
    if paper_width is not None and not isinstance(paper_width, str):
        raise TypeError(f"paper_width must be a str such as '180mm', got {type(paper_width).__name__}")
    if paper_width == "":
        raise ValueError("paper_width must be a number and a unit ('180mm', '7.5in'), got ''")
    handle = tileset._handle if tileset is not None else None
    if spec is None:
        spec = _kdm.stipple_density(label, gamma, invert, points, scale, region, white)
    result = _kdm.stipple(
        spec, label, points, scale, method, mode, region, seed, handle, output, width, dot_size, threads,
        colours, gamma, fade, rgb, alpha, "" if paper_width is None else paper_width, height, white,
    )
    dots, classes, inks, keys = result
    if ids:
        # An empty picture has no dots to name, whatever the method.
        if keys is None and len(dots):
            raise ValueError("ids: the tile set's tiles hold more than 2^19 points, more than an id names")
        keys = np.zeros(0, np.uint64) if keys is None else keys
        if colours is None:
            return dots, keys
        return dots, classes, _inks(inks), keys
    if colours is None:
        return dots
    return dots, classes, _inks(inks)


def zoom_regions(region: Sequence[float], frames: int) -> np.ndarray:
    """The regions of a zoom into `region`, as ``kdm stipple --region R --frames K`` renders them.

    Frame 0 is the smallest rectangle of the region's shape that holds the whole image, frame K - 1 the
    region; the zoom grows geometrically about a fixed point of the region, so each rectangle holds the
    next and every dot that stays in view is kept. Stipple each with ``stipple(image, region=r, ...)``
    (with `fade` and `output` for pictures). Dots glide where a frame zooms at most about 1.0125x the one
    before, through the hand-overs between depths too (1.05x is enough between them; docs/limits.md).
    Returns a (frames, 4) float64 array of (x0, y0, x1, y1) in
    the image's UV square [0, 1]^2, y up. Raises ValueError for a region outside [0, 1]^2, empty or
    inverted, or `frames` not 2 to 10000.
    """
    r = _checks.rect("region", region)
    if not (r[0] >= 0 and r[1] >= 0 and r[2] <= 1 and r[3] <= 1):
        raise ValueError(f"region must lie in [0, 1]^2 (0 <= x0 < x1 <= 1, 0 <= y0 < y1 <= 1), got {r}")
    frames = _checks.integer("frames", frames, 2, 10000)
    return _kdm.zoom_regions(r, frames)


def separate(
    image: Any, *, colours: Any = "cmyk", gamma: float = 1.0, white: Optional[float] = None
) -> Tuple[np.ndarray, List[str]]:
    """The inks of an image (a file, an array or a PIL image) as ``stipple(image, colours=...)`` separates
    them, to preview or measure.

    Returns ``(channels, inks)``: channels a (k, height, width) float32 array, each ink's density in [0, 1]
    (its coverage raised to `gamma`), row 0 at the top as in the picture; inks the inks (Ink: a name with
    its ``.colour``, "#rrggbb"), in class order: the inks of least coverage first (a later class's tone carries the earlier classes' count
    errors, the more the smaller its share), except that inks under a tenth of the total coverage come last.
    `white`: for a Radiance .hdr file, the luminance that is white, as in stipple().
    """
    if isinstance(image, (str, os.PathLike)):
        label, rgb, alpha = _checks.path("image", image), None, None
        white = _checks.white(white, True)
    else:  # an array or a PIL image, as stipple() takes it
        white = _checks.white(white, False)
        _checks.image_size(image)
        label, (rgb, alpha) = "array", _checks.colour("image", _checks.pil_pixels(image))
    gamma = _checks.number("gamma", gamma, 0.0, strict=True)
    colours = _checks.colour_scheme(colours)
    channels, inks = _kdm.separate(label, colours, gamma, rgb, alpha, white)
    return channels, _inks(inks)
