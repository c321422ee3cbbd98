"""Bad arguments raise TypeError (wrong type), ValueError (bad value) or OSError (a file that cannot be read
or written), with one clear line, and never crash the interpreter: explicit cases, then random ones."""
import inspect
import math
import re
import subprocess

import numpy as np
import pytest

import kdm
from conftest import SPHERE

TILES = kdm.Tileset.builtin()
NAN, INF = math.nan, math.inf


def raises(kind, match, call, *args, **kwargs):
    with pytest.raises(kind, match=match) as info:
        call(*args, **kwargs)
    assert type(info.value) is kind or kind is OSError, f"{type(info.value).__name__}: {info.value}"
    assert "\n" not in str(info.value)  # one line


@pytest.mark.parametrize("kind,match,kwargs", [
    (ValueError, "n must be >= 1", dict(n=-5)),
    (ValueError, "n must be >= 1", dict(n=0)),
    (ValueError, "n must be <= 2147483648", dict(n=2**40)),
    (TypeError, "n must be an integer, got float", dict(n=100.0)),
    (TypeError, "n must be an integer, got str", dict(n="100")),
    (TypeError, "n must be an integer, got bool", dict(n=True)),
    (ValueError, "density must be a finite number", dict(n=10, density=NAN)),
    (ValueError, "density must be >= 0", dict(n=10, density=-1.0)),
    (ValueError, "a density of 0 has nothing to sample", dict(n=10, density=0)),
    (TypeError, "density must be None, a number, a str", dict(n=10, density={"a": 1})),
    (ValueError, "must be a 2-D array", dict(n=10, density=np.ones(5))),
    (ValueError, r"a 3-D array .* is a volume .*: use dim=3", dict(n=10, density=np.ones((2, 2, 2)))),
    (ValueError, "density volume is empty", dict(n=10, dim=3, density=np.ones((0, 2, 2)))),
    (ValueError, r"or with dim=3 a 3-D array \(depth, height, width\), got shape \(2, 3, 4, 5\)",
     dict(n=10, dim=3, density=np.ones((2, 3, 4, 5)))),
    (ValueError, "density array is empty", dict(n=10, density=np.ones((0, 4)))),
    (ValueError, "finite and >= 0", dict(n=10, density=np.array([[1.0, NAN]]))),
    (ValueError, "finite and >= 0", dict(n=10, density=np.array([[1.0, -2.0]]))),
    (ValueError, "finite and >= 0", dict(n=10, density=np.array([[1.0, INF]]))),
    (ValueError, "zero everywhere has nothing to sample", dict(n=10, density=np.zeros((3, 3)))),
    (TypeError, "must hold real numbers", dict(n=10, density=np.array([["a", "b"]]))),
    (TypeError, "must hold real numbers", dict(n=10, density=np.ones((2, 2)) * 1j)),
    (ValueError, "must be a 2-D array", dict(n=10, density=[[1, 2], [3]])),
    (ValueError, "gamma and invert apply to image files only", dict(n=10, density=np.ones((2, 2)), gamma=2)),
    (ValueError, "dim must be <= 3", dict(n=10, dim=4)),
    (ValueError, "domain must be one of 'torus', 'box'", dict(n=10, domain="sphere")),
    (ValueError, "temperature must be a finite number", dict(n=10, temperature=NAN)),
    (ValueError, "temperature must be >= 0", dict(n=10, temperature=-1)),
    (ValueError, "temperature must be at most 1000", dict(n=10, temperature=1e4)),
    (ValueError, "seed must be >= 0", dict(n=10, seed=-1)),
    (ValueError, "seed must be <= ", dict(n=10, seed=2**64)),
    (ValueError, "threads must be >= 0", dict(n=10, threads=-1)),
    (ValueError, "threads must be <= 256", dict(n=10, threads=1000)),  # as the command line's
    (ValueError, "aspect must be > 0", dict(n=10, aspect=0)),
    (ValueError, "gamma must be > 0", dict(n=10, density="const:1", gamma=0)),
    (ValueError, "image files only, and density 'const:1' is not one", dict(n=10, density="const:1", gamma=2)),
    (ValueError, "image files only, and no density is given", dict(n=10, invert=True)),
    (TypeError, "invert must be True or False", dict(n=10, density="const:1", invert="yes")),
    (ValueError, "const:V needs a finite V >= 0", dict(n=10, density="const:x")),
    (ValueError, r"ramp:R needs a dynamic range R in \[1, 1e9\]", dict(n=10, density="ramp:0.5")),
    (ValueError, "image and array densities are 2-D", dict(n=10, density=np.ones((2, 2)), dim=3)),
    (ValueError, r"a 3-D array of shape \(2, 3, 4\) is a volume \(depth, height, width\): use dim=3",
     dict(n=10, density=np.ones((2, 3, 4)))),
    (ValueError, r"density volume values must be finite and >= 0.*got -1 at \[1, 2, 0\]",
     dict(n=10, dim=3, density=np.where(np.arange(24).reshape(2, 3, 4) == 20, -1.0, 1.0))),
    (ValueError, "zero everywhere has nothing to sample", dict(n=10, dim=3, density=np.zeros((2, 2, 2)))),
    (ValueError, "gamma and invert apply to image files only", dict(n=10, dim=3, density=np.ones((2, 2, 2)), gamma=2)),
    (ValueError, "must be a 2-D array", dict(n=10, dim=3, density=np.ones((2, 2, 2, 2)))),
    (ValueError, r"aspect must be a number or three sides \(x, y, z\), got 2 values", dict(n=10, dim=3, aspect=(1, 2))),
    (ValueError, r"aspect=\(x, y, z\) sets a 3-D domain's sides: use dim=3", dict(n=10, aspect=(1, 2, 3))),
    (ValueError, r"aspect\[1\] must be > 0", dict(n=10, dim=3, aspect=(1, 0, 2))),
    (ValueError, r"aspect\[2\] must be a finite number", dict(n=10, dim=3, aspect=(1, 1, NAN))),
    (TypeError, "aspect must be a number or a sequence of three sides", dict(n=10, dim=3, aspect="1:2:3")),
    (ValueError, r"aspect=\(x, y, z\) sets a 3-D domain's sides", dict(n=10, density=lambda x, y: 1.0, aspect=(1, 2, 3))),
    (ValueError, r"density must be a 3-D array \(depth, height, width\) for 3-D points: ",
     dict(n=10, dim=3, density=[[[1, 2], [3]]])),
    (TypeError, r"with dim=3 the density is called as f\(x, y, z\), with 3 coordinates, but this callable "
     r"takes \(x, y\)", dict(n=10, dim=3, density=lambda x, y: 1.0)),
    (TypeError, r"with dim=2 the density is called as f\(x, y\)", dict(n=10, density=lambda x, y, z: 1.0)),
])
def test_sample_refusals(kind, match, kwargs):
    raises(kind, match, kdm.sample, **kwargs)


def test_a_type_error_inside_a_density_callable_is_its_own():
    # The callable takes f(x, y, z): its own TypeError is not mistaken for a wrong number of coordinates.
    def density(x, y, z):
        return len(x)  # a float has no len()
    raises(TypeError, "has no len", kdm.sample, 10, density, dim=3)
    raises(TypeError, r"with d=3 the density is called as f\(x, y, z\)", kdm.BlueNoise, d=3,
           density=lambda x, y: 1.0)


def test_the_dimension_keyword_of_the_other_interface_says_which_to_use():
    raises(TypeError, r"sample\(\) takes dim=, not d=", kdm.sample, 10, d=3)
    raises(TypeError, r"BlueNoise\(\) takes d=, not dim=", kdm.BlueNoise, dim=3)
    assert "dim" in inspect.signature(kdm.sample).parameters  # the wrapper keeps the signature


def cli_message(cli_path, *args):
    done = subprocess.run([cli_path, *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 1
    line = done.stderr.strip()
    assert line.startswith("kdm: error: ")
    return line[len("kdm: error: "):]


def test_unreadable_files_raise_oserror_with_the_cli_message(cli, tmp_path, tiny_tileset):
    import os
    kdm_cli = os.environ["KDM_CLI"]
    missing = tmp_path / "missing.png"
    not_an_image = tmp_path / "notes.png"
    not_an_image.write_text("hello")
    for path in (missing, not_an_image):
        message = cli_message(kdm_cli, "sample", "--n", 10, "--density", path, "-o", tmp_path / "x.txt")
        with pytest.raises(OSError) as info:
            kdm.sample(10, str(path))
        assert str(info.value) == message
        with pytest.raises(OSError) as info:
            kdm.stipple(path)
        if path == missing:  # an image, not "a density is a picture, const:V, ..."
            assert str(info.value) == cli_message(kdm_cli, "stipple", path, "-o", tmp_path / "x.png")
        with pytest.raises(OSError):
            TILES.query((0, 0, 1, 1), scale=10, density=str(path))
    damaged = tmp_path / "damaged.kdmt"
    damaged.write_bytes(b"KDMT" + bytes(100))
    # The subclass of OSError that open() raises for a missing file or a directory; OSError for a damaged one.
    for path, kind in ((tmp_path / "missing.kdmt", FileNotFoundError), (damaged, OSError),
                       (tmp_path, IsADirectoryError)):
        message = cli_message(kdm_cli, "query", "--tileset", path, "--rect", "0,0,1,1",
                              "-o", tmp_path / "x.csv")
        with pytest.raises(OSError) as info:
            kdm.Tileset.load(path)
        assert str(info.value) == message and type(info.value) is kind
        with pytest.raises(kind):
            kdm.stipple(SPHERE, points=100, tileset=path)
    # A missing image file too, wherever it is read.
    for call in (lambda: kdm.sample(10, str(missing)), lambda: kdm.stipple(missing),
                 lambda: kdm.stipple(missing, colours="cmyk"), lambda: kdm.separate(missing),
                 lambda: TILES.query((0, 0, 1, 1), scale=10, density=str(missing)),
                 lambda: kdm.analyze(kdm.sample(50), density=str(missing))):
        with pytest.raises(FileNotFoundError):
            call()
    assert type(pytest.raises(OSError, kdm.sample, 10, str(not_an_image)).value) is OSError
    with pytest.raises(OSError, match="cannot|No such|directory"):
        kdm.stipple(SPHERE, points=100, output=tmp_path / "no" / "such" / "dir" / "x.png")
    with pytest.raises(OSError):
        tiny_tileset.save(tmp_path / "no" / "such" / "x.kdmt")  # (the built-in set takes 30 s to encode)


def test_a_npy_file_of_bad_values_is_a_value_error_and_a_cut_one_an_os_error(tmp_path):
    # The same array in memory raises ValueError: a file that reads but holds no density is bad values.
    values = np.ones((4, 4))
    values[1, 2] = NAN
    bad = tmp_path / "nan.npy"
    np.save(bad, values)
    wrong_shape = tmp_path / "flat.npy"
    np.save(wrong_shape, np.ones(5))
    cut = tmp_path / "cut.npy"
    np.save(cut, np.ones((64, 64)))
    cut.write_bytes(cut.read_bytes()[:200])
    calls = (lambda p: kdm.sample(10, str(p)), lambda p: TILES.query((0, 0, 1, 1), scale=10, density=str(p)),
             lambda p: kdm.DensityMap(str(p), rect=(0, 0, 1, 1)))
    for call in calls:
        raises(ValueError, r"nan\.npy.*a value of nan at \[1, 2\]: densities must be finite", call, bad)
        raises(ValueError, r"an array of shape \(5\)", call, wrong_shape)
        with pytest.raises(OSError, match="cut short"):
            call(cut)


@pytest.mark.parametrize("kind,match,kwargs", [
    (ValueError, "density_rect is empty or inverted",
     dict(density=np.ones((4, 4)), density_rect=(0, 0, 0, 1))),
    (ValueError, r"rect\[2\] must be a finite number, got an integer of 1329 bits", dict(rect=(0, 0, 10**400, 1))),
    (ValueError, r"rect\[1\] must be a finite number", dict(rect=(0, NAN, 1, 1))),
    (ValueError, "rect must hold 4 numbers", dict(rect=(0, 0, 1))),
    (TypeError, "rect must be a sequence of 4 numbers", dict(rect="0,0,1,1")),
    (TypeError, "scale must be a number", dict(scale="10")),
    (ValueError, "scale must be a finite number", dict(scale=INF)),
    (ValueError, "'scale' must be >= 0, got -1", dict(scale=-1)),
    (ValueError, r"more points per tile than .* use scale= 32768 or less", dict(scale=1e300)),
    (ValueError, "'tile_size' must be > 0, got 0$", dict(tile_size=0)),
    (ValueError, "too far from the world origin.*move the origin",
     dict(rect=(1e15, 0, 1e15 + 1, 1), scale=1000)),
    (ValueError, "mode must be one of 'stable', 'smooth'", dict(mode="fast")),
    (ValueError, "origin must hold 2 numbers", dict(origin=(1, 2, 3))),
    (ValueError, "density_rect needs an image, an array or a test map", dict(density_rect=(0, 0, 1, 1))),
    (ValueError, "density image rectangle .* texels per unit to be finite",
     dict(density=np.ones((4, 4)), density_rect=(0, 0, 5e-324, 5e-324))),
    (ValueError, "density image rectangle .* texels per unit to be finite",
     dict(density=np.ones((4, 4)), density_rect=(-1e308, -1e308, 1e308, 1e308))),
    (ValueError, "density_max is for a callable density only", dict(density=0.5, density_max=1)),
    (ValueError, "a callable density needs density_max", dict(density=lambda x, y: 1.0)),
    (ValueError, "density_max must be > 0", dict(density=lambda x, y: 1.0, density_max=-1)),
    (ValueError, "density_max must be > 0, got 0", dict(density=lambda x, y: 1.0, density_max=0)),
    (ValueError, "density must be >= 0", dict(density=-0.5)),
    (ValueError, "finite and >= 0", dict(density=np.full((3, 3), NAN))),
    # More than a query collects: refused before querying, an image's count from its values.
    (ValueError, r"would emit at least 2e\+10 points, more than 2\^25; lower the scale \(scale=\)",
     dict(rect=(0, 0, 2000, 2000), scale=20000, density=np.full((4, 4), 0.25))),
    # A query's values are densities (the sampler's only a shape, scaled into float32's range).
    (ValueError, r"at most 3\.4e38 \(kept as floats\), got 1e\+308 at \[0, 0\]$", dict(density=np.full((2, 2), 1e308))),
    (TypeError, "density must be None, a number, .* 2-D array or a callable, got object", dict(density=object())),
    (TypeError, r"classes\[0\] must be a number, .* 2-D array or a callable, got bool", dict(classes=[True])),
    (ValueError, "image files only, and no density is given", dict(gamma=2)),
    (ValueError, "image files only, and no class is one", dict(classes=[1.0, "const:0.5"], gamma=2)),
])
def test_query_refusals(kind, match, kwargs):
    args = dict(rect=(0, 0, 1, 1), scale=100)
    args.update(kwargs)
    raises(kind, match, TILES.query, args.pop("rect"), **args)


# What a density callable may return wrongly: a wrong type is a TypeError naming it, a bad value a
# ValueError; in kdm.sample, kdm.analyze and queries alike, each naming the point it was called at.
NOT_NUMBERS = [
    (None, "NoneType"), ("a", "str"), (1 + 1j, "complex"), (np.complex64(1), "complex64"),
    (np.array([1.0, 2.0]), r"ndarray of shape \(2,\)"), ([1.0], "list"),
]
POINT = r"\(-?[0-9.e+-]+, -?[0-9.e+-]+\)"  # (x, y)
POINT3 = r"\(-?[0-9.e+-]+, -?[0-9.e+-]+, -?[0-9.e+-]+\)"  # (x, y, z)


@pytest.mark.parametrize("value,name", NOT_NUMBERS)
def test_a_density_callable_returning_no_number_is_a_type_error(value, name):
    points = kdm.sample(300, threads=1)
    said = rf"^density callable returned {name} at {POINT}: a density must be a real number$"
    raises(TypeError, said, kdm.sample, 200, lambda x, y: value)
    raises(TypeError, said, kdm.analyze, points, density=lambda x, y: value, energy=False)
    raises(TypeError, said, TILES.query, (0, 0, 1, 1), scale=100, density=lambda x, y: value, density_max=1)
    raises(TypeError, said, kdm.BlueNoise(2, seed=1, density=lambda x, y: value).random, 100)
    raises(TypeError, rf"^density callable returned {name} at {POINT3}: a density must be a real number$",
           kdm.sample, 200, lambda x, y, z: value, dim=3)
    raises(TypeError, rf"^class_densities\[1\] callable returned {name} at {POINT}:", kdm.analyze, points,
           np.arange(300) % 2, class_densities=[1.0, lambda x, y: value], energy=False)
    raises(TypeError, rf"^classes\[0\] callable returned {name} at {POINT}:", TILES.query, (0, 0, 1, 1),
           scale=100, classes=[lambda x, y: value], density_max=1)


@pytest.mark.parametrize("value", [NAN, INF, -0.5, 10**400])
def test_a_density_callable_returning_no_density_is_a_value_error(value):
    shown = {NAN: "nan", INF: "inf", -0.5: "-0.5", 10**400: "inf"}[value]
    said = rf"^density callable returned {shown} at {POINT}: a density must be finite and >= 0$"
    raises(ValueError, said, kdm.sample, 200, lambda x, y: value)
    raises(ValueError, said, kdm.analyze, kdm.sample(300), density=lambda x, y: value, energy=False)
    raises(ValueError, said, TILES.query, (0, 0, 1, 1), scale=100, density=lambda x, y: value, density_max=1)


def test_a_density_callable_may_return_any_real_number():
    # Python and numpy numbers, and a 0-d array (what numpy reductions may give): the same points as a float.
    points = kdm.sample(200, lambda x, y: 1.0 + x, seed=3, threads=1)
    for kind in (np.float32, np.float64, lambda v: np.array(v)):
        assert np.array_equal(kdm.sample(200, lambda x, y: kind(1.0 + x), seed=3, threads=1), points)
    ones = kdm.sample(200, lambda x, y: 1.0, seed=3, threads=1)
    for one in (1, np.int64(1), True, np.uint8(1)):
        assert np.array_equal(kdm.sample(200, lambda x, y: one, seed=3, threads=1), ones)


def test_a_vectorized_density_callable_returning_no_numbers_is_a_type_error():
    for value, name in [(None, "NoneType"), (np.array(["a"] * 2), "ndarray of dtype <U1"), (1j, "complex")]:
        raises(TypeError, rf"^density callable returned {name} for \d+ positions from {POINT}: a vectorized "
               "density must return an array of real numbers$", TILES.query, (0, 0, 1, 1), scale=100,
               density=lambda x, y: value, density_max=1, vectorized=True)


def test_density_arrays_and_callables_say_the_range_they_take():
    # The sampler takes an array at any scale (only its shape matters: it is scaled into float32's range);
    # a callable's values are kept as floats as they come, so its peak must lie in 1e-30 ... 1e30.
    ramp = np.tile(np.linspace(1.0, 4.0, 8), (6, 1))
    for scale in (1e-300, 1e300):
        scaled = ramp * scale
        assert np.array_equal(kdm.sample(300, scaled, seed=2, threads=1),
                              kdm.sample(300, scaled / scaled.max(), seed=2, threads=1))
    ramp[1, 2] = NAN
    raises(ValueError, r"^density array values must be finite and >= 0 \(at any scale: only their shape "
           r"matters\), got nan at \[1, 2\]$", kdm.sample, 10, ramp)
    raises(ValueError, r"^density volume values must be finite and >= 0 \(at any scale: .*\), got inf at "
           r"\[0, 0, 1\]$", kdm.sample, 10, np.array([[[1.0, INF]]]), dim=3)
    for peak, fix in ((1e35, "divide"), (1e-35, "multiply")):
        raises(ValueError, re.escape(f"density peaks at {peak:.3g}, outside 1e-30 ... 1e+30 (kept as floats); "
                                     f"only its shape matters, so {fix} it by a constant"),
               kdm.sample, 100, lambda x, y: peak)


def test_gamma_reshapes_an_image_file_or_is_refused():
    # As the command line's --gamma and --invert: ignored silently nowhere.
    points = kdm.sample(200)
    raises(ValueError, "no density is given", kdm.analyze, points, gamma=2)
    raises(ValueError, "density 'ramp:4' is not one", kdm.analyze, points, density="ramp:4", invert=True)
    # Among classes, one image file is enough: gamma reshapes it, and the constant is left as it is.
    plain = TILES.query((0, 0, 1, 1), scale=400, classes=[str(SPHERE), "const:0.5"])
    darker = TILES.query((0, 0, 1, 1), scale=400, classes=[str(SPHERE), "const:0.5"], gamma=0.5)
    assert (darker.classes == 0).sum() > (plain.classes == 0).sum()


@pytest.mark.parametrize("kind,match,call", [
    (ValueError, "unknown key", lambda: kdm.bake("colours 2\nbogus 1\n")),
    (TypeError, "recipe_text must be a str", lambda: kdm.bake(b"colours 2")),
    (TypeError, "use Tileset.builtin", lambda: kdm.Tileset("x")),
    (TypeError, "path must be a path", lambda: kdm.Tileset.load(5)),
    (ValueError, "points must be >= 1", lambda: kdm.stipple(SPHERE, points=0)),
    (ValueError, "scale must be > 0", lambda: kdm.stipple(SPHERE, scale=-1)),
    (ValueError, "method must be one of", lambda: kdm.stipple(SPHERE, method="fast")),
    (ValueError, "meeting the image", lambda: kdm.stipple(SPHERE, region=(1.5, 0, 2, 1))),
    (ValueError, "region zooms more than 2", lambda: kdm.stipple(SPHERE, region=(0, 0, 0.1, 0.1), mode="stable")),
    (ValueError, "needs method='tiles'", lambda: kdm.stipple(SPHERE, method="full", region=(0, 0, 1, 1))),
    (ValueError, "width must be <= 65536", lambda: kdm.stipple(SPHERE, width=10**6)),
    (ValueError, "dot_size must be >= 0", lambda: kdm.stipple(SPHERE, dot_size=-1)),
    (ValueError, "dot_size 120 is more than a quarter of the 200x200 picture's shorter side: at most 50 pixels",
     lambda: kdm.stipple(SPHERE, points=100, width=200, dot_size=120, output="never.svg")),
    (ValueError, "^colours must be cmyk, rgb, a number of inks", lambda: kdm.stipple(SPHERE, colours="9")),
    (TypeError, r"^colours must be 'cmyk', 'rgb', a number of inks \(2 to 8\), or pens as a str \('#e00000,#0000aa'\) "
     r"or a list of them \(\['#e00000', '#0000aa'\]\), got set", lambda: kdm.stipple(SPHERE, colours={"#ff0000"})),
    (TypeError, "or a list of them", lambda: kdm.separate(SPHERE, colours=1.5)),
    (TypeError, r"colours\[1\] must be a pen as a str \('#e00000'\), got int",
     lambda: kdm.stipple(SPHERE, colours=["#ff0000", 0])),
    (ValueError, r"colours\[0\] must be a pen as #rrggbb \('#e00000'\), got '3'",
     lambda: kdm.stipple(SPHERE, colours=["3"])),
    (ValueError, "colours is an empty list", lambda: kdm.separate(SPHERE, colours=[])),
    (ValueError, "at most 8 inks", lambda: kdm.stipple(SPHERE, colours=["#%06x" % k for k in range(1, 10)])),
    (ValueError, "unknown output format", lambda: kdm.stipple(SPHERE, points=100, output="x.gif")),
    (ValueError, "luminances in", lambda: kdm.stipple(np.full((4, 4), 2.0))),
    (ValueError, r"luminances in \[0, 1\], got 1e\+300 \(8-bit", lambda: kdm.stipple(np.full((4, 4), 1e300))),
    (ValueError, r"got 255 \(8-bit pixels: pass them as uint8", lambda: kdm.stipple(np.full((4, 4), 255.0))),
    (ValueError, "integer arrays must be uint8", lambda: kdm.stipple(np.zeros((4, 4), dtype=np.int64))),
    (ValueError, r"got int64 \(as a list of Python ints makes\): pass 8-bit levels as np.asarray\(image, "
     r"np.uint8\), or luminances as floats in \[0, 1\]", lambda: kdm.stipple([[0, 0], [0, 0]])),
    (ValueError, r"values must be in \[0, 1\] \(8-bit pixels", lambda: kdm.stipple(np.full((4, 4, 3), 2.0))),
    (ValueError, r"or \(rows, columns, k\): k = 1 grey, 2 grey and alpha, 3 or 4 colour \(RGB, RGBA\), got "
     r"shape \(4, 4, 5\)", lambda: kdm.stipple(np.zeros((4, 4, 5)))),
    (ValueError, "stipple needs an image", lambda: kdm.stipple("const:1")),
    (TypeError, "image must be a path or an array", lambda: kdm.stipple(3)),
    (ValueError, "names a file: give its text", lambda: kdm.bake(str(SPHERE))),
    (TypeError, "read the file first", lambda: kdm.bake(SPHERE)),
    (OSError, "cannot open .default.", lambda: kdm.stipple(SPHERE, tileset="default")),
    (TypeError, "tileset must be a kdm.Tileset, a tile-set file", lambda: kdm.stipple(SPHERE, tileset=3)),
    (ValueError, r"points must be an \(n, 2\) or \(n, 3\) array", lambda: kdm.analyze(np.ones((5, 4)))),
    (ValueError, "must be a 2-D array", lambda: kdm.analyze(np.ones(5))),
    (TypeError, r"points must be an \(n, 2\) or \(n, 3\) array of points, got None", lambda: kdm.analyze(None)),
    (ValueError, "sweeps must be >= 0, got -1", lambda: kdm.sample(10, sweeps=-1)),
    (ValueError, "coarse_sweeps must be <= 100000", lambda: kdm.sample(10, coarse_sweeps=10**6)),
    (ValueError, "outside|inside", lambda: kdm.analyze(np.full((5, 2), 1.5))),
    (ValueError, r"outside the unit domain \(coordinate 1e\+300\)", lambda: kdm.analyze(np.full((5, 2), 1e300))),
    (ValueError, r"\(coordinate 1.0000001\); normalise points to \[0, 1\]",
     lambda: kdm.analyze(np.array([[1.0000001, 0.5], [0.2, 0.3], [0.4, 0.4]]))),
    (TypeError, "points must hold coordinates, got booleans", lambda: kdm.analyze(np.ones((5, 2)) > 0.5)),
    (ValueError, "finite|non-finite", lambda: kdm.analyze(np.full((5, 2), NAN))),
    (ValueError, "at least 2 points", lambda: kdm.analyze(np.full((1, 2), 0.5))),
    (ValueError, "1 / tile size must be an", lambda: kdm.analyze(np.random.rand(50, 2), tile_size=0.3)),
    (ValueError, "fmax must be > 0", lambda: kdm.analyze(np.random.rand(50, 2), fmax=0)),
    (ValueError, "periodogram grid too large", lambda: kdm.analyze(np.random.rand(50, 2), fmax=1e300)),
    (ValueError, "mix dimensions", lambda: kdm.analyze([np.random.rand(5, 2), np.random.rand(5, 3)])),
    (ValueError, "d must be >= 2", lambda: kdm.BlueNoise(1)),
])
def test_other_refusals(kind, match, call):
    raises(kind, match, call)


# Values no argument of kdm should take, or only in a few places: anything may be passed anywhere.
GARBAGE = [
    None, "", "nonsense", "const:-1", "ramp:nan", b"bytes", -1, -(2**70), 2**70, 0, NAN, INF, -INF, 1e308,
    -0.0, True, 1j, [], [1], [[1, 2], [3]], (NAN, 0, 1, 1), (0, 0, -1, -1), np.array([]), np.zeros((0, 3)),
    np.full((2, 2), NAN), np.array([["a"]]), np.ones((3, 3, 3)), np.float32(-2), object(), {}, lambda: 0,
]


def cheap_calls():
    """Each public call with every parameter given, its defaults but for a few that make it quick."""
    quick = {
        kdm.sample: dict(n=64, threads=1),
        TILES.query: dict(rect=(0, 0, 1, 1), scale=50.0),
        kdm.stipple: dict(image=np.full((8, 8), 0.5), points=100, width=64, threads=1),
        kdm.analyze: dict(points=np.random.default_rng(1).random((64, 2)), energy=False, threads=1),
        kdm.BlueNoise: dict(d=2, seed=1, threads=1),
        kdm.Tileset.load: dict(path="/nonexistent/set.kdmt"),
    }
    calls = []
    for call, given in quick.items():
        params = inspect.signature(call).parameters.values()
        kwargs = {p.name: p.default for p in params if p.default is not inspect.Parameter.empty}
        calls.append((call, {**kwargs, **given}))
    return calls


def test_masked_arrays_are_refused_saying_what_to_pass():
    # np.asarray drops a mask: the values it hides would be read as densities, pixels or points.
    mask = [[1, 0], [0, 0]]
    density = np.ma.masked_array(np.ones((2, 2)), mask)
    fill = r"is a masked array, and kdm would ignore its mask .*: pass density.filled\(0\)"
    for call in (lambda: kdm.sample(10, density), lambda: kdm.sample(10, np.ma.masked_array(np.ones((2, 2, 2))), dim=3),
                 lambda: kdm.DensityMap(density, (0, 0, 1, 1)), lambda: TILES.query((0, 0, 1, 1), scale=10, density=density),
                 lambda: kdm.analyze(kdm.sample(50, seed=1), density=density, energy=False)):
        raises(TypeError, fill, call)
    raises(TypeError, r"classes\[1\] is a masked array.*classes\[1\].filled\(0\)",
           lambda: kdm.sample(10, classes=[1.0, density]))
    raises(TypeError, r"classes is a masked array", lambda: kdm.sample(10, classes=np.ma.masked_array([1.0, 2.0], [1, 0])))
    raises(TypeError, r"class_densities is a masked array", lambda: kdm.analyze(
        kdm.sample(50, seed=1), np.arange(50) % 2, class_densities=np.ma.masked_array([1.0, 2.0], [1, 0])))
    image = np.ma.masked_array(np.full((2, 2), 0.5), mask)
    for call in (lambda: kdm.stipple(image), lambda: kdm.separate(np.ma.masked_array(np.ones((2, 2, 3))))):
        raises(TypeError, r"image is a masked array.*image.filled\(white\)", call)
    raises(TypeError, r"points is a masked array.*np.ma.compress_rows\(points\)",
           lambda: kdm.analyze(np.ma.masked_array(np.random.default_rng(1).random((10, 2)))))
    assert len(kdm.sample(10, density.filled(0), seed=1)) == 10  # as suggested


def test_random_bad_arguments_never_crash():
    rng = np.random.default_rng(2024)
    outcomes = {"ok": 0, "refused": 0}
    for _ in range(600):
        call, base = cheap_calls()[rng.integers(6)]
        kwargs = dict(base)
        for name in rng.choice(list(kwargs), size=min(len(kwargs), rng.integers(1, 3)), replace=False):
            kwargs[name] = GARBAGE[rng.integers(len(GARBAGE))]
        if call is TILES.query:
            rect = kwargs.pop("rect")
            args = (rect,)
        else:
            args = ()
        try:
            call(*args, **kwargs)
            outcomes["ok"] += 1
        except (TypeError, ValueError, OSError) as e:
            assert str(e) and "\n" not in str(e), repr(e)
            outcomes["refused"] += 1
    assert outcomes["refused"] > 300  # most garbage is refused; the rest happened to be valid


def test_the_compiled_layer_checks_too():
    # kdm._kdm is private, but its own checks keep a caller who skips kdm's from crashing anything.
    from kdm import _kdm
    handle = _kdm.Tileset.builtin()
    spec = _kdm.DensitySpec.constant(1.0)
    calls = [
        lambda: _kdm.sample(-1, None, 2, None, 0.5, 1, 0, None),
        lambda: _kdm.sample(10, None, 5, None, 0.5, 1, 0, None),
        lambda: _kdm.sample(10, None, 2, "cube", 0.5, 1, 0, None),
        lambda: _kdm.sample(10, None, 2, None, NAN, 1, 0, None),
        lambda: _kdm.sample(10, None, 2, None, 0.5, 1, -3, None),
        lambda: _kdm.sample(10, None, 2, None, 0.5, 1, 0, -2.0),
        lambda: _kdm.sample(10, _kdm.DensitySpec.constant(0.0), 2, None, 0.5, 1, 0, None),
        lambda: _kdm.DensitySpec.constant(NAN),
        lambda: _kdm.DensitySpec.from_values(np.ones((2, 2, 2))),
        lambda: _kdm.DensitySpec.from_values(np.full((2, 2), -1.0)),
        lambda: _kdm.DensitySpec.from_luminance(np.ones((2, 2)), 0.0, False),
        lambda: _kdm.query(handle, (0, 0, NAN, 1), 10, spec, None, None, None, 1, "stable", (0, 0)),
        lambda: _kdm.query(handle, (0, 0, 1, 1), 10, None, None, None, None, 1, "stable", (0, 0)),
        lambda: _kdm.query(handle, (0, 0, 1, 1), 10, spec, None, None, None, 1, "wobbly", (0, 0)),
        lambda: _kdm.query(handle, (0, 0, 1, 1), NAN, spec, None, None, None, 1, "stable", (0, 0)),
        lambda: _kdm.query(handle, (0, 0, 1, 1), 10, spec, None, None, None, 1, "stable", (INF, 0)),
        lambda: _kdm.query(handle, (0, 0, 1, 1), 10, None, lambda x, y: 1, None, INF, 1, "stable", (0, 0)),
        lambda: _kdm.stipple(spec, "x", 10, 0, "tiles", "smooth", None, 1, None, None, 64, 0, 0),
        lambda: _kdm.stipple(spec, "x", 0, NAN, "tiles", "smooth", None, 1, None, None, 64, 0, 0),
        lambda: _kdm.stipple_density(str(SPHERE), 1.0, False, 100, 0.0, None, NAN),
        lambda: _kdm.stipple_density(str(SPHERE), 1.0, False, 100, 0.0, None, 1.0),  # white, for a PNG
        lambda: _kdm.separate(str(SPHERE), "cmyk", 1.0, None, None, -1.0),
        lambda: _kdm.analyze([np.ones((4, 2)) * 0.5], ["a"], False, None, NAN, 2.5, 0, False),
        lambda: _kdm.analyze([], [], False, None, 0, 2.5, 0, False),
        lambda: _kdm.bake("levels 0\n", 0),
    ]
    for call in calls:
        with pytest.raises((ValueError, TypeError)):
            call()


def test_an_image_finer_than_any_grid_is_not_refused_by_its_samples():
    # Every third texel column set: samples on a grid can all land on set columns and count three times the
    # points (4e7, past 2**25). The count refused before querying is a lower bound, so this query of
    # 1.35e7 points is served.
    stripes = np.zeros((2, 384))
    stripes[:, ::3] = 1.0
    xy = TILES.positions((0, 0, 635, 635), scale=100, density=stripes)
    assert 1.2e7 < len(xy) < 1.5e7


def test_positions_past_what_is_collected_are_refused_before_querying():
    # An image's or a constant's count is known from its values; a callable's is found by querying, and
    # threads stop once the 2**25 + 1 slots are full rather than count the whole region (minutes here).
    big = dict(scale=20000, density=np.full((4, 4), 0.25))
    for threads in (None, 2):
        with pytest.raises(ValueError, match=r"would emit at least 2e\+10 points"):
            TILES.positions((0, 0, 2000, 2000), threads=threads, **big)
        with pytest.raises(ValueError, match="would emit at least"):
            TILES.positions((0, 0, 2000, 2000), threads=threads, scale=20000, classes=[0.25, np.ones((4, 4))])
