"""kdm.Tileset and its queries: the command line's bits, partitions, densities of every kind, loading,
saving and baking."""
import math
import pickle
import warnings

import numpy as np
import pytest

import kdm
from conftest import SPHERE, TINY_RECIPE, interrupted, read_query_csv

BUILTIN = kdm.Tileset.builtin()


def same(a, b):
    """Whether two query results (or their arrays as tuples) are equal bit for bit."""
    def fields(r):
        return (r.xy, r.tile, r.rank, r.level) if isinstance(r, kdm.QueryResult) else r
    return all(np.array_equal(x, y) for x, y in zip(fields(a), fields(b)))


def test_builtin_info():
    info = BUILTIN.info
    assert set(info) >= {"levels", "level_points", "keyframes", "max_points_per_tile", "colours", "tiles",
                         "format_version", "resident_bytes", "recipe", "generator_version"}
    assert info["levels"] == len(info["level_points"])
    assert info["max_points_per_tile"] == info["level_points"][-1]
    assert info["tiles"] == info["colours"] ** 4 and info["keyframes"][-1] == info["max_points_per_tile"]
    assert info["smooth_limit_per_tile"] == info["max_points_per_tile"] * max(info["subtiles_per_side"], 1) ** 8
    m = info["subtiles_per_side"]
    assert m == 0 or info["level_points"][info["handover_level"]] * m * m == info["max_points_per_tile"]
    assert 0 <= info["handover_slack"] <= 16 and (m or not info["handover_slack"])
    assert info["format_version"] == (7 if info["handover_slack"] else 6 if info["handover_level"] else 5 if m else 4)
    assert "seed" in info["recipe"] and info["resident_bytes"] > 0
    assert kdm.Tileset.builtin() is BUILTIN


@pytest.mark.parametrize("args,kwargs", [
    ([], {}),
    (["--mode", "smooth", "--scale", "333.3"], dict(mode="smooth", scale=333.3)),
    (["--density", "radial:30", "--tile-size", "0.5"], dict(density="radial:30", tile_size=0.5)),
    (["--density", "const:0.37", "--mode", "smooth"], dict(density=0.37, mode="smooth")),
])
def test_same_bits_as_kdm_query(cli, tmp_path, args, kwargs):
    out = tmp_path / "q.csv"
    cli("query", "--rect", "-1.5,0.25,2,3", *args, "-o", out)
    kwargs.setdefault("scale", 1000.0)
    r = BUILTIN.query((-1.5, 0.25, 2, 3), **kwargs)
    assert len(r) > 1000
    assert same(r, read_query_csv(out))


def test_same_bits_with_an_image_density(cli, tmp_path, gradient_png):
    out = tmp_path / "q.csv"
    cli("query", "--rect", "0,0,3,2", "--density", gradient_png, "--density-rect", "-0.5,0,3,2.5",
        "--scale", 800, "--mode", "smooth", "--invert", "-o", out)
    r = BUILTIN.query((0, 0, 3, 2), scale=800, density=str(gradient_png), density_rect=(-0.5, 0, 3, 2.5),
                      mode="smooth", invert=True)
    assert same(r, read_query_csv(out))
    # The image as an array (row 0 at the top, its luminance as density) is the same density.
    luminance = kdm._kdm.load_luminance(str(gradient_png)).astype(np.float64)
    a = BUILTIN.query((0, 0, 3, 2), scale=800, density=luminance, density_rect=(-0.5, 0, 3, 2.5),
                      mode="smooth")
    assert same(a, r)


@pytest.mark.parametrize("bounds, error, message", [
    (None, TypeError, r"must return a pair \(lo, hi\), got NoneType"),
    ("ab", TypeError, r"must return a pair \(lo, hi\), got str"),
    ((0.0, "x"), TypeError, r"two real numbers \(lo, hi\), got \(float, str\)"),
    ((0.0, 1.0, 2.0), ValueError, r"must return a pair \(lo, hi\), got 3 values"),
])
def test_density_bounds_of_the_wrong_type_or_length_are_named(bounds, error, message):
    with pytest.raises(error, match=message):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=lambda x, y: 1.0, density_max=1.0,
                      density_bounds=lambda *r: bounds)


@pytest.mark.parametrize("mode", ["stable", "smooth"])
def test_partitions_concatenate_to_the_whole(mode):
    density = np.random.default_rng(3).random((16, 16))
    kw = dict(scale=500, mode=mode, density=density, density_rect=(0, 0, 4, 4))
    whole = BUILTIN.query((0, 0, 4, 4), **kw)
    parts = [BUILTIN.query((x0, y0, x1, y1), **kw)
             for (x0, x1) in ((0, 1.3), (1.3, 4)) for (y0, y1) in ((0, 2.5), (2.5, 4))]
    def key(xy, tile, rank):
        return sorted(zip(tile[:, 0], tile[:, 1], rank, xy[:, 0], xy[:, 1]))
    joined = [np.concatenate([getattr(p, f) for p in parts]) for f in ("xy", "tile", "rank")]
    assert key(*joined) == key(whole.xy, whole.tile, whole.rank)
    assert sum(len(p) for p in parts) == len(whole)


def test_results_are_deterministic_and_origin_shifts():
    a = BUILTIN.query((10, 10, 13, 12), scale=300, mode="smooth")
    again = BUILTIN.query((10, 10, 13, 12), scale=300, mode="smooth")
    assert same(again, a)
    b = BUILTIN.query((10, 10, 13, 12), scale=300, mode="smooth", origin=(10, 10))
    assert np.array_equal(a.tile, b.tile) and np.array_equal(a.rank, b.rank)
    assert np.allclose(a.xy - 10, b.xy, atol=1e-12) and b.xy.min() < 0.1


def test_result_arrays():
    r = BUILTIN.query((0, 0, 2, 2), scale=2000)
    assert r.xy.dtype == np.float64 and r.xy.shape == (len(r), 2)
    assert r.tile.dtype == np.int64 and r.tile.shape == (len(r), 2)
    assert r.rank.dtype == np.uint32 and r.level.dtype == np.uint32 and r.level.shape == (len(r),)
    # xy, tile and rank view the runtime's records, which `points` holds: nothing is copied.
    assert r.points.shape == (len(r),) and r.points.dtype.itemsize == 40
    assert r.points.dtype.names == ("x", "y", "tile_x", "tile_y", "rank", "depth")
    for view in (r.xy, r.tile, r.rank):
        assert np.shares_memory(view, r.points) and not view.flags["OWNDATA"]
    assert np.array_equal(r.xy[:, 0], r.points["x"]) and np.array_equal(r.tile[:, 1], r.points["tile_y"])
    assert np.array_equal(r.rank, r.points["rank"])
    packed = np.ascontiguousarray(r.xy)
    assert packed.flags["C_CONTIGUOUS"] and np.array_equal(packed, r.xy)
    assert ((r.xy >= 0) & (r.xy < 2)).all()
    assert np.array_equal(r.tile, np.floor(r.xy).astype(np.int64))  # tile_size 1
    # Levels follow ranks: level k ends at about level_points[k] points per tile.
    first = (r.tile == [0, 0]).all(axis=1)
    assert (np.diff(r.level[first].astype(int)) >= 0).all() and (np.diff(r.rank[first].astype(int)) > 0).all()
    assert r.level.max() == np.searchsorted(BUILTIN.info["level_points"], 2000)
    empty = BUILTIN.query((0, 0, 2, 2), scale=0)
    assert len(empty) == 0 and empty.xy.shape == (0, 2)


def test_a_callable_density_equals_the_same_map():
    # radial:R and ramp:R over a map rectangle, computed in Python: the C++ maps' formula, so the same
    # points; the maps' own bounds (which skip a tile far from the peak unread: radial:1e9 over 4,096²
    # tiles at 32,000 points per tile took hours) change none of them.
    for rect, mapped, r in (((0.0, 0.0, 3.0, 2.0), None, 40.0), ((0.0, 0.0, 3.0, 2.0), (-1.0, 0.5, 5.0, 1.5), 1e9)):
        m = mapped or rect
        def unit(x, y):
            return (min(max((x - m[0]) / (m[2] - m[0]), 0.0), 1.0), min(max((y - m[1]) / (m[3] - m[1]), 0.0), 1.0))
        def radial(x, y):
            u, v = unit(x, y)
            return math.exp(-math.log(r) * min(1.0, 2 * math.sqrt((u - 0.5) ** 2 + (v - 0.5) ** 2)))
        def ramp(x, y):
            return math.exp(-math.log(r) * unit(x, y)[0])
        for mode in ("stable", "smooth"):
            for name, f in (("radial", radial), ("ramp", ramp)):
                a = BUILTIN.query(rect, scale=20000, density=f, density_max=1.0, mode=mode)
                b = BUILTIN.query(rect, scale=20000, density=f"{name}:{r:g}", density_rect=mapped, mode=mode)
                # The same ids; positions within an ulp or two (Python's arithmetic for the map's is not
                # always C++'s to the last bit: one point of 12,838 at radial:40).
                assert len(a) > 200 and np.array_equal(a.tile, b.tile) and np.array_equal(a.rank, b.rank)
                np.testing.assert_allclose(a.xy, b.xy, rtol=0, atol=1e-12, err_msg=f"{name}:{r:g} {mode}")


def test_a_callable_density_gets_numbers_and_may_return_numpy_values():
    calls = []
    def f(x, y):
        calls.append((type(x), type(y)))
        return np.float32(0.5)
    r = BUILTIN.query((0, 0, 1, 1), scale=400, density=f, density_max=0.5)
    assert len(r) > 100 and calls and set(calls) == {(float, float)}
    assert same(r, (BUILTIN.query((0, 0, 1, 1), scale=400, density=0.5).xy, r.tile, r.rank, r.level))


def test_an_exception_in_the_callable_propagates():
    class Boom(Exception):
        pass
    def f(x, y):
        if x > 0.5:
            raise Boom("no density here")
        return 1.0
    with pytest.raises(Boom, match="no density here"):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=f, density_max=1)
    with pytest.raises(TypeError, match=r"density callable returned str at \(.*\): a density must be a real number"):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=lambda x, y: "dense", density_max=1)
    # A callable of the wrong arity is told by its signature, before any call, as kdm.sample tells it.
    with pytest.raises(TypeError, match=r"density: the density is called as f\(x, y\), with 2 coordinates, "
                                        r"but this callable takes \(x\)"):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=lambda x: 1.0, density_max=1)
    with pytest.raises(TypeError, match=r"classes\[1\]: the density is called as f\(x, y\)"):
        BUILTIN.query((0, 0, 2, 2), scale=100, classes=[1.0, lambda x, y, z: 1.0], density_max=[None, 1])
    # Still usable afterwards.
    assert len(BUILTIN.query((0, 0, 1, 1), scale=100)) > 0


@pytest.mark.parametrize("bad", [math.nan, math.inf, -0.5])
def test_a_callable_density_that_returns_no_density_is_an_error(bad):
    # Counted as 0 by the C++ query, such a value from Python is a bug in the callable: said where.
    def f(x, y):
        return bad if x > 1.0 else 1.0
    with pytest.raises(ValueError, match=r"density callable returned .* at \(1\.\d+, .*finite and >= 0"):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=f, density_max=1)
    with pytest.raises(ValueError, match="density callable returned"):
        BUILTIN.positions((0, 0, 2, 2), scale=100, density=f, density_max=1)


def test_a_callable_density_above_its_density_max_is_an_error():
    # The C++ query would count 1.5 as the bound 1 (too few points there, silently): said where. Smooth
    # mode reads beyond the rect too, so a value above the bound just outside it is found as well.
    def f(x, y):
        return 1.5 if x > 1.0 else 1.0
    with pytest.raises(ValueError, match=r"returned 1\.5 at \(1\.\d+, .*above density_max 1:"):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=f, density_max=1)
    with pytest.raises(ValueError, match="above density_max 1:"):
        BUILTIN.positions((0, 0, 2, 2), scale=100, density=f, density_max=1, mode="smooth")
    with pytest.raises(ValueError, match="above density_max 1:"):
        BUILTIN.query((0, 0, 1, 1), scale=100, density=lambda x, y: np.where(x > 0.5, 2.0, 1.0), density_max=1,
                      vectorized=True)
    with pytest.raises(ValueError, match="above density_max 0.5:"):
        BUILTIN.query((0, 0, 1, 1), scale=100, classes=[lambda x, y: 0.2, lambda x, y: 0.7],
                      density_max=[1, 0.5])
    with pytest.raises(ValueError, match="above density_max 1:"):
        BUILTIN.query((0, 0, 0.98, 0.5), scale=1000, density=lambda x, y: 1.0 if x < 1 else 3.0, density_max=1,
                      mode="smooth")
    # Rounding above the bound passes: a maximum computed another way may differ in its last bits.
    top = 1 + 1e-12
    assert same(BUILTIN.query((0, 0, 1, 1), scale=100, density=lambda x, y: top, density_max=1),
                BUILTIN.query((0, 0, 1, 1), scale=100, density=lambda x, y: 1.0, density_max=1))


def test_positions_refuse_an_origin_where_floats_lose_the_tiles():
    # float32 positions 10^20 from the origin would all be the same number: refused, not returned.
    with pytest.raises(ValueError, match="origin_x"):
        BUILTIN.positions((0, 0, 2, 2), scale=100, origin=(1e20, 0))
    assert len(BUILTIN.positions((0, 0, 2, 2), scale=100, origin=(1e3, 0))) > 0
    # Nearer, but float32's step 4e6 out (0.5) is 50 spacings of 10^4 points per unit area: refused too;
    # with the origin at the region every point keeps its own place.
    far = (4e6, 4e6, 4e6 + 1, 4e6 + 1)
    with pytest.raises(ValueError, match=r"'origin_x'.*origin= nearer the region"):
        BUILTIN.positions(far, scale=1e4)
    xy = BUILTIN.positions(far, scale=1e4, origin=(4e6, 4e6))
    assert len(xy) > 9000 and len(np.unique(xy, axis=0)) == len(xy)


def test_a_0d_array_is_the_number_it_holds():
    # np.asarray(0.5) turns up wherever a pipeline normalises its inputs; np.float32(0.5) was taken already.
    rect = (0, 0, 3, 2)
    assert same(BUILTIN.query(rect, scale=300, density=np.asarray(0.5)),
                BUILTIN.query(rect, scale=300, density=0.5))
    assert same(BUILTIN.query(rect, scale=300, classes=[np.asarray(0.3), np.asarray(2)]),
                BUILTIN.query(rect, scale=300, classes=[0.3, 2.0]))
    assert np.array_equal(kdm.sample(50, np.asarray(0.5), seed=3), kdm.sample(50, 0.5, seed=3))
    with pytest.raises(ValueError, match="density must be >= 0"):
        BUILTIN.query(rect, scale=300, density=np.asarray(-1.0))


@pytest.mark.parametrize("bounds", [(math.nan, 1.0), (2.0, 1.0), (-1.0, 1.0), (0.0, math.nan)])
def test_density_bounds_that_are_no_bounds_are_an_error(bounds):
    with pytest.raises(ValueError, match=r"density_bounds returned .*0 <= lo <= hi"):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=lambda x, y: 1.0, density_max=1.0,
                      density_bounds=lambda *r: bounds)


@pytest.mark.parametrize("mode", ["stable", "smooth"])
def test_a_vectorized_density_gives_the_points_of_the_scalar_one(mode):
    # A bump by numpy over tiles of about 2,000 candidates, cut by the region's sides, with and without
    # bounds; positions() through two threads too. Arithmetic only: numpy's vectorised exp differs from its
    # scalar one in the last bit for about 1 value in 10^4, which moves a smooth point's bits.
    def bump(x, y):
        return 0.1 + 0.9 / (1 + ((x - 2.0) * (x - 2.0) + (y - 1.0) * (y - 1.0)) / 2.0)
    sizes = []
    def vectorized(x, y):
        assert isinstance(x, np.ndarray) and x.dtype == np.float64 and x.shape == y.shape
        sizes.append(len(x))
        return bump(x, y)
    def bounds(x0, y0, x1, y1):
        return 0.0, 1.0
    rect = (0.3, 0.2, 4.6, 2.5)
    for b in (None, bounds):
        scalar = BUILTIN.query(rect, scale=2000, density=bump, density_max=1.0, density_bounds=b, mode=mode)
        sizes.clear()
        batched = BUILTIN.query(rect, scale=2000, density=vectorized, density_max=1.0, density_bounds=b,
                                mode=mode, vectorized=True)
        assert len(scalar) > 5000 and same(scalar, batched)
        # Each call serves a batch of up to 128 of a tile's reads: measured 117 to 124 on average here.
        assert max(sizes) <= 128 and sum(sizes) > 50 * len(sizes)
        for threads in (None, 2):
            assert np.array_equal(
                BUILTIN.positions(rect, scale=2000, density=vectorized, density_max=1.0, density_bounds=b,
                                  mode=mode, vectorized=True, threads=threads),
                BUILTIN.positions(rect, scale=2000, density=bump, density_max=1.0, density_bounds=b, mode=mode,
                                  threads=threads))


def test_a_vectorized_density_serves_past_the_top_level():
    # Smooth mode at three times the top level, where tiles hand over to their subtiles: the ancestors'
    # points are read a block ahead, in calls of about 40 (measured 41 on average here).
    def bump(x, y):
        return 0.3 + 0.7 / (1 + ((x - 0.3) * (x - 0.3) + (y - 0.3) * (y - 0.3)) / 0.02)
    sizes = []
    def vectorized(x, y):
        sizes.append(len(x))
        return bump(x, y)
    rect, scale = (0.1, 0.15, 0.45, 0.4), 3 * BUILTIN.info["max_points_per_tile"]
    scalar = BUILTIN.query(rect, scale=scale, density=bump, density_max=1.0, mode="smooth")
    batched = BUILTIN.query(rect, scale=scale, density=vectorized, density_max=1.0, mode="smooth",
                            vectorized=True)
    assert len(scalar) > 5000 and same(scalar, batched)
    assert max(sizes) <= 128 and sum(sizes) > 25 * len(sizes)


def test_a_vectorized_density_may_return_one_value_for_all():
    r = BUILTIN.query((0, 0, 2, 2), scale=400, density=lambda x, y: 0.5, density_max=0.5, vectorized=True)
    assert same(r, BUILTIN.query((0, 0, 2, 2), scale=400, density=0.5))


def test_a_vectorized_densitys_bad_values_and_shapes_are_errors():
    with pytest.raises(ValueError, match=r"density callable returned nan at \(1\.\d+, .*finite and >= 0"):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=lambda x, y: np.where(x > 1, np.nan, 1.0),
                      density_max=1, vectorized=True)
    with pytest.raises(ValueError, match=r"returned shape \(\d+, 2\) for \d+ positions"):
        BUILTIN.positions((0, 0, 2, 2), scale=100, density=lambda x, y: np.stack([x, y], axis=1), density_max=1,
                          vectorized=True)
    with pytest.raises(ValueError, match=r"returned shape \(3\) for \d+ positions"):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=lambda x, y: np.ones(3), density_max=1, vectorized=True)
    # A wrong type is a TypeError. Neither None nor complex values are read as numbers (NaN, or the real part,
    # with a mere warning).
    with pytest.raises(TypeError, match=r"returned str for \d+ positions from \(.*\): a vectorized density must "
                                        "return an array of real numbers"):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=lambda x, y: "dense", density_max=1, vectorized=True)
    with pytest.raises(TypeError, match="returned NoneType for"):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=lambda x, y: None, density_max=1, vectorized=True)
    with pytest.raises(TypeError, match="returned ndarray of dtype complex128 for"):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=lambda x, y: x * 0 + 0.5 + 1j, density_max=1,
                      vectorized=True)
    class Boom(Exception):
        pass
    def f(x, y):
        raise Boom("no density here")
    with pytest.raises(Boom, match="no density here"):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=f, density_max=1, vectorized=True, mode="smooth")
    with pytest.raises(ValueError, match="vectorized is for a callable density only"):
        BUILTIN.query((0, 0, 1, 1), scale=10, density=0.5, vectorized=True)
    with pytest.raises(TypeError, match="vectorized"):
        BUILTIN.query((0, 0, 1, 1), scale=10, density=lambda x, y: 1.0, density_max=1.0, vectorized="yes")
    with pytest.raises(ValueError, match="vectorized is for callable classes only"):
        BUILTIN.query((0, 0, 1, 1), scale=10, classes=[0.5], vectorized=True)
    with pytest.raises(ValueError, match="vectorized is for callable classes only"):
        BUILTIN.positions((0, 0, 1, 1), scale=10, classes=[0.5], vectorized=True)
    with pytest.raises(ValueError, match=r"returned shape \(3\) for \d+ positions"):
        BUILTIN.query((0, 0, 2, 2), scale=100, classes=[lambda x, y: np.ones(3), 1.0], density_max=1,
                      vectorized=True)
    assert len(BUILTIN.query((0, 0, 1, 1), scale=100)) > 0  # still usable afterwards


def test_a_callable_density_may_query_itself():
    # A query inside the density of another (on the same thread) leaves the outer one's points alone.
    inner = []
    def f(x, y):
        if not inner:
            inner.append(BUILTIN.query((5, 5, 7, 7), scale=900))
        return 0.5
    a = BUILTIN.query((0, 0, 2, 2), scale=800, density=f, density_max=0.5)
    assert same(a, BUILTIN.query((0, 0, 2, 2), scale=800, density=0.5))
    assert same(inner[0], BUILTIN.query((5, 5, 7, 7), scale=900))


def test_zero_density_and_an_all_white_image_give_no_points():
    assert len(BUILTIN.query((0, 0, 1, 1), scale=100, density=0.0)) == 0
    assert len(BUILTIN.query((0, 0, 1, 1), scale=100, density=np.zeros((4, 4)))) == 0


def test_refusals_name_the_python_parameter():
    with pytest.raises(ValueError, match=r"scale= [0-9.]+ or less, or tile_size= [0-9.]+ or less"):
        BUILTIN.query((0, 0, 1, 1), scale=1e9)
    with pytest.raises(ValueError, match="larger tile_size= or a smaller region"):
        BUILTIN.query((0, 0, 1e4, 1e4), scale=1)


def test_load_save_and_bake(tmp_path, tiny_tileset):
    info = tiny_tileset.info
    assert info["level_points"] == [32, 128] and info["recipe"].startswith("seed 1")
    path = tmp_path / "tiny.kdmt"
    tiny_tileset.save(path)
    loaded = kdm.Tileset.load(path)
    assert loaded.info == info
    kw = dict(scale=100, mode="smooth")
    assert same(loaded.query((0, 0, 3, 3), **kw), tiny_tileset.query((0, 0, 3, 3), **kw))
    assert kdm.bake(TINY_RECIPE, threads=1).info == info  # any thread count, the same set
    damaged = bytearray(path.read_bytes())
    damaged[20] ^= 1 << 4  # the payload size's high bytes: a damaged header, the file is whole
    (tmp_path / "damaged.kdmt").write_bytes(damaged)
    for load in (lambda: kdm.Tileset.load(tmp_path / "damaged.kdmt"), lambda: kdm.Tileset.from_bytes(damaged)):
        with pytest.raises((OSError, ValueError), match="header checksum mismatch"):
            load()
    with pytest.raises(ValueError, match="recipe_text gives no key"):  # not minutes of the defaults
        kdm.bake("# a comment only\n\n")
    with pytest.raises(ValueError, match="this is a kdm tile-set file"):  # a set's bytes read as text
        kdm.bake(path.read_bytes().decode("latin-1"))
    with pytest.raises(ValueError, match="recipe line 2: '=' is not used: write 'levels 2'"):
        kdm.bake("colours 1\nlevels = 2\n")
    with pytest.raises(ValueError, match="density too high|points per tile"):
        loaded.query((0, 0, 1, 1), scale=129)


def test_a_set_from_bytes_pickles_and_copies(tiny_tileset):
    import copy
    import pickle
    data = tiny_tileset.to_bytes()
    again = kdm.Tileset.from_bytes(data)
    assert again.info == tiny_tileset.info and again.to_bytes() == data
    assert kdm.Tileset.from_bytes(memoryview(data)).info == tiny_tileset.info
    assert kdm.Tileset.from_bytes(np.frombuffer(data, np.uint8)).info == tiny_tileset.info  # any buffer
    kw = dict(scale=100, mode="smooth")
    for twin in (pickle.loads(pickle.dumps(tiny_tileset)), copy.deepcopy(tiny_tileset)):
        assert same(twin.query((0, 0, 3, 3), **kw), tiny_tileset.query((0, 0, 3, 3), **kw))
    assert pickle.loads(pickle.dumps(BUILTIN)) is BUILTIN  # the built-in set as itself, not 14 MB
    with pytest.raises(ValueError, match="truncated"):
        kdm.Tileset.from_bytes(data[:-1])
    with pytest.raises(ValueError, match="bad magic"):
        kdm.Tileset.from_bytes(b"not a tile set at all, but long enough to hold a header")
    with pytest.raises(TypeError, match="data must be bytes"):
        kdm.Tileset.from_bytes("a str")


def test_the_shipped_file_loads_as_the_builtin_set(tmp_path):
    from conftest import SOURCE_DIR
    path = SOURCE_DIR / "tilesets" / "default.kdmt"
    shipped = kdm.Tileset.load(path)
    assert shipped.info == BUILTIN.info
    # Its bytes are the file's, kept from the load: encoding 14 MB at zstd's level 19 again took 20 s for
    # every to_bytes(), save() and pickle. Saving writes them; a pickle carries them.
    data = path.read_bytes()
    assert shipped.to_bytes() == data and kdm.Tileset.from_bytes(data).to_bytes() == data
    shipped.save(tmp_path / "again.kdmt")
    assert (tmp_path / "again.kdmt").read_bytes() == data
    import pickle
    assert pickle.loads(pickle.dumps(shipped)).to_bytes() == data


def test_result_index_past_either_end_is_an_index_error_and_iteration_ends():
    r = kdm.Tileset.builtin().query((0, 0, 1, 1), scale=100)
    m = len(r)
    assert m > 10
    for i in (m, m + 5, -m - 1, 10**20):  # as numpy's: not an empty result, on which iteration never ends
        with pytest.raises(IndexError, match="out of range"):
            r[i]
        with pytest.raises(IndexError):
            r.rank[i]
    assert r[-m].rank[0] == r.rank[0] and r[m - 1].rank[0] == r.rank[-1] and r[np.int64(-2)].rank[0] == r.rank[-2]
    items = list(r)  # one-point results, in order
    assert len(items) == m and all(isinstance(p, kdm.QueryResult) and len(p) == 1 for p in items)
    assert np.array_equal(np.concatenate([p.xy for p in items]), r.xy)
    assert list(r[:0]) == []
    # Not an array: numpy and the measures refuse it at once instead of walking one-point results.
    for convert in (np.asarray, kdm.analyze):
        with pytest.raises(TypeError, match=r"\.xy"):
            convert(r)


def test_results_index_key_and_pickle_their_own_points():
    tiles = kdm.Tileset.builtin()
    # Past the top level and left of the origin too: keys hold the depth, and a negative tile's low bits.
    r = tiles.query((-1, -1, 0.5, 0.5), scale=200000, tile_size=0.5, mode="smooth", density="radial:8")
    assert r.depth.max() >= 1 and r.tile.min() < 0
    assert len(set(r.keys.tolist())) == len(r)  # unique: a dict key per point
    key = (r.tile[:, 0].astype(np.uint64) & np.uint64(2**21 - 1)) | \
        (r.tile[:, 1].astype(np.uint64) & np.uint64(2**21 - 1)) << np.uint64(21) | \
        r.rank.astype(np.uint64) << np.uint64(42) | r.depth.astype(np.uint64) << np.uint64(61)
    assert np.array_equal(r.keys, key)
    left = r.xy[:, 0] < 0
    part = r[left]
    for name in ("points", "xy", "tile", "rank", "level", "depth", "keys"):
        assert np.array_equal(getattr(part, name), getattr(r, name)[left]), name
    np.testing.assert_array_equal(tiles.thresholds(part), tiles.thresholds(r)[left])
    assert len(r[3]) == 1 and r[3].rank[0] == r.rank[3] and r[-1].rank[0] == r.rank[-1]
    assert np.array_equal(r[10:20].xy, r.xy[10:20]) and np.array_equal(r[[5, 2]].rank, r.rank[[5, 2]])
    part.xy[0, 0] = 1e9  # a copy: the query's result is untouched
    assert r.xy[left][0, 0] != 1e9
    c = tiles.query((0, 0, 3, 3), scale=900, classes=[0.2, 0.5])
    assert np.array_equal(c[c.classes == 1].classes, np.ones(int(np.sum(c.classes == 1)), np.uint8))
    # A pickle holds the points alone: not the rest of a reused `out` buffer.
    big = tiles.query((0, 0, 30, 30), scale=2000)
    small = tiles.query((0, 0, 0.2, 0.2), scale=2000, out=big)
    again = pickle.loads(pickle.dumps(small))
    assert big.points.nbytes > 10**6 and len(pickle.dumps(small)) < 100 * len(small) + 1000  # 40 B a point
    for name in ("points", "xy", "tile", "rank", "level", "depth"):
        assert np.array_equal(getattr(again, name), getattr(small, name)), name
    back = pickle.loads(pickle.dumps(c))
    assert np.array_equal(back.classes, c.classes) and np.array_equal(back.xy, c.xy)
    assert len(pickle.loads(pickle.dumps(tiles.query((0, 0, 0, 0), scale=1)))) == 0


def test_out_refills_an_earlier_results_arrays():
    tiles = kdm.Tileset.builtin()
    big = tiles.query((0, 0, 4, 4), scale=400)
    small = tiles.query((0, 0, 2, 2), scale=400, out=big)
    fresh = tiles.query((0, 0, 2, 2), scale=400)
    for name in ("xy", "tile", "rank", "level"):
        np.testing.assert_array_equal(getattr(small, name), getattr(fresh, name))
    assert np.shares_memory(small.xy, big.xy) and np.shares_memory(small.level, big.level)  # refilled
    larger = tiles.query((0, 0, 12, 12), scale=400, out=small)  # too small to hold it: new memory
    assert len(larger) > 2 * len(big) + 16384 and not np.shares_memory(larger.xy, big.xy)
    whole = tiles.query((0, 0, 12, 12), scale=400)
    for name in ("xy", "tile", "rank", "level"):
        np.testing.assert_array_equal(getattr(larger, name), getattr(whole, name))
    # Queries far larger than a chunk, fresh and refilling: every point's level is found.
    dense = tiles.query((0, 0, 8, 8), scale=3000, mode="smooth")
    again = tiles.query((0, 0, 8, 8), scale=3000, mode="smooth", out=dense)
    assert len(dense) > 150_000 and np.shares_memory(again.xy, dense.xy)
    levels = np.searchsorted(tiles.info["level_points"], 3000) + 1
    assert np.array_equal(np.bincount(again.level, minlength=levels) > 0, np.ones(levels, bool))
    with pytest.raises(TypeError):
        tiles.query((0, 0, 2, 2), scale=400, out=big.xy)
    # Storage that is not whole and forward (reversed, strided) is not written through: new memory.
    records, levels = big._storage
    for view in (slice(None, None, -1), slice(None, None, 2)):
        odd = kdm.QueryResult(records[:0], None, None, None, None, storage=(records[view], levels[view]))
        got = tiles.query((0, 0, 4, 4), scale=400, out=odd)
        assert not np.shares_memory(got.xy, records)
        again_fresh = tiles.query((0, 0, 4, 4), scale=400)
        for name in ("xy", "tile", "rank", "level"):
            np.testing.assert_array_equal(getattr(got, name), getattr(again_fresh, name))


@pytest.fixture(scope="module")
def handover_tileset():
    # Three levels (32 ... 512 points per tile) handing over to 4 x 4 subtiles: a few seconds to bake.
    return kdm.bake("colours 2\nlevels 3\nbase_points 32\nsweeps 10\nkeyframes 4\nglide_sweeps 4\n"
                    "handover_zone 1\n", threads=0)


def test_smooth_queries_descend_past_the_top_level(handover_tileset):
    info = handover_tileset.info
    assert info["subtiles_per_side"] == 4 and info["max_points_per_tile"] == 512
    scale = 512 * 16 * 40  # points per tile: past 512 * 16**2, depth-3 sub-points appear
    r = handover_tileset.query((0, 0, 0.1, 0.1), scale=scale, mode="smooth")
    assert abs(len(r) / (scale * 0.01) - 1) < 0.05
    depth = r.depth  # an attribute, as tile, rank and level are: the id needs it
    assert np.array_equal(depth, r.points["depth"])
    assert depth.max() == 3 and (depth == 0).any()
    ids = set(zip(r.tile[:, 0].tolist(), r.tile[:, 1].tolist(), r.rank.tolist(), depth.tolist()))
    assert len(ids) == len(r)
    assert r.level.max() < info["levels"]
    with pytest.raises(ValueError, match="scale"):
        handover_tileset.query((0, 0, 0.1, 0.1), scale=scale, mode="stable")


@pytest.mark.parametrize("mode", ["stable", "smooth"])
def test_classes_in_one_query(cli, tmp_path, mode):
    # The same bits and classes as `kdm query --class`; the union is the one-class query at the sum, and
    # in stable mode class 0 is the one-class query at its own density.
    rect = (0.0, 0.0, 3.0, 2.0)
    r = BUILTIN.query(rect, scale=150, classes=[1.0, 2.0, "ramp:4"], mode=mode)
    assert r.classes.dtype == np.uint8 and len(r.classes) == len(r) > 1000
    assert set(np.unique(r.classes)) == {0, 1, 2}
    out = tmp_path / "c.csv"
    cli("query", "--rect", "0,0,3,2", "--scale", 150, "--mode", mode, "--class", "const:1", "--class",
        "const:2", "--class", "ramp:4", "-o", out)
    rows = np.loadtxt(out, delimiter=",", skiprows=1)
    assert np.array_equal(rows[:, :2], r.xy) and np.array_equal(rows[:, 6], r.classes)
    constants = BUILTIN.query(rect, scale=150, classes=[1.0, 2.0, 4.0], mode=mode)
    assert same(constants, BUILTIN.query(rect, scale=150, density=7.0, mode=mode))
    if mode == "stable":
        zero = constants.classes == 0
        alone = BUILTIN.query(rect, scale=150, density=1.0)
        assert same((constants.xy[zero], constants.tile[zero], constants.rank[zero]),
                    (alone.xy, alone.tile, alone.rank))


def test_classes_refuse_bad_input():
    rect = (0.0, 0.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="1 to 8"):
        BUILTIN.query(rect, scale=10, classes=[])
    with pytest.raises(ValueError, match="1 to 8"):
        BUILTIN.query(rect, scale=10, classes=[1.0] * 9)
    with pytest.raises(ValueError, match="not both"):
        BUILTIN.query(rect, scale=10, density=1.0, classes=[1.0])
    with pytest.raises(ValueError, match=r"classes\[1\] is a callable: density_max"):
        BUILTIN.query(rect, scale=10, classes=[1.0, lambda x, y: 1.0])
    with pytest.raises(ValueError, match=r"classes\[1\]"):
        BUILTIN.query(rect, scale=10, classes=[1.0, -2.0])
    with pytest.raises(ValueError, match="scale="):
        BUILTIN.query(rect, scale=1e9, classes=[1.0, 1.0])
    # Images are stretched over one rectangle: of one shape at any resolutions, as kdm query --class.
    with pytest.raises(ValueError, match=r"one shape .*classes\[0\] is 32x32, classes\[2\] is 32x16"):
        BUILTIN.query(rect, scale=100, classes=[np.ones((32, 32)), 0.5, np.ones((16, 32))])
    both = BUILTIN.query(rect, scale=100, classes=[np.ones((32, 32)), 0.5, np.full((16, 16), 0.5)])
    assert set(np.unique(both.classes)) == {0, 1, 2}


@pytest.mark.parametrize("mode", ["stable", "smooth"])
def test_callable_classes(mode):
    # A callable class among a constant and an array: the union is the one-class query at the sum (the
    # same values added in class order), in stable mode class 0 alone the one-class query at its own
    # density; a callable of constant value classes the points as the constant does.
    rect = (0.0, 0.0, 3.0, 2.0)
    def ramp(x, y):
        return 0.5 + 0.5 * x
    image = np.full((4, 6), 0.75)
    # The ramp's bound holds a little past the rect too, where smooth mode also reads (x < 4).
    r = BUILTIN.query(rect, scale=150, classes=[ramp, 1.0, image], density_max=[2.5, None, None], mode=mode)
    assert len(r) > 1000 and set(np.unique(r.classes)) == {0, 1, 2}
    union = BUILTIN.query(rect, scale=150, density=lambda x, y: ramp(x, y) + 1.0 + 0.75, density_max=4.25,
                          mode=mode)
    assert same(r, union)
    if mode == "stable":
        zero = r.classes == 0
        alone = BUILTIN.query(rect, scale=150, density=ramp, density_max=2.5)
        assert same((r.xy[zero], r.tile[zero], r.rank[zero]), (alone.xy, alone.tile, alone.rank))
    constants = BUILTIN.query(rect, scale=150, classes=[1.0, 2.0], mode=mode)
    called = BUILTIN.query(rect, scale=150, classes=[lambda x, y: 1.0, 2.0], density_max=1.0, mode=mode)
    assert same(called, constants) and np.array_equal(called.classes, constants.classes)
    xy, labels = BUILTIN.positions(rect, scale=150, classes=[ramp, 1.0, image], density_max=2.5, mode=mode)
    assert np.array_equal(labels, r.classes) and np.array_equal(xy, r.xy.astype(np.float32))


@pytest.mark.parametrize("mode", ["stable", "smooth"])
def test_image_classes_are_read_by_their_sums(mode):
    # Classes that are all arrays of one shape are read by their running sums, added texel by texel in
    # float32: the union is the one-class query at that sum, in stable mode class 0 the query at its own.
    rect = (0.0, 0.0, 3.0, 2.0)
    v, u = np.mgrid[0:20, 0:30].astype(np.float32) / np.float32(20)
    images = [0.2 + u, 0.3 + v, (1 + np.sin(3 * u) * np.cos(2 * v)).astype(np.float32)]
    images = [np.asarray(i, dtype=np.float32) for i in images]
    r = BUILTIN.query(rect, scale=300, classes=images, mode=mode)
    assert len(r) > 3000 and set(np.unique(r.classes)) == {0, 1, 2}
    total = (images[0] + images[1]) + images[2]
    assert same(r, BUILTIN.query(rect, scale=300, density=total, mode=mode))
    if mode == "stable":
        zero = r.classes == 0
        alone = BUILTIN.query(rect, scale=300, density=images[0])
        assert same((r.xy[zero], r.tile[zero], r.rank[zero]), (alone.xy, alone.tile, alone.rank))
    xy, labels = BUILTIN.positions(rect, scale=300, classes=images, mode=mode, threads=2)
    # Both sorted by the float32 positions: sorted by the float64 ones, two points whose x rounds to one
    # float32 could come in the other order.
    f32 = r.xy.astype(np.float32)
    order = np.lexsort((f32[:, 1], f32[:, 0]))
    order2 = np.lexsort((xy[:, 1], xy[:, 0]))
    assert np.array_equal(xy[order2], f32[order])
    assert np.array_equal(labels[order2], r.classes[order])


@pytest.mark.parametrize("mode", ["stable", "smooth"])
@pytest.mark.parametrize("side", [64, 1024])
def test_image_classes_give_the_same_points_in_chunks(mode, side):
    # Whether images are read by their sums depends on the images (64² arrays are, 1024² are not), never
    # on the region: 16 chunks of a region, a few hundred points each, give the whole region's points.
    rng = np.random.default_rng(5)
    images = [rng.uniform(0.05, 0.3, (side, side)) for _ in range(2)]
    whole_rect = (0.0, 0.0, 16.0, 16.0)
    whole = BUILTIN.query(whole_rect, scale=337, classes=images, mode=mode)
    keys = lambda r: {(int(t[0]), int(t[1]), int(k), float(p[0]), float(p[1]), int(c))
                      for t, k, p, c in zip(r.tile, r.rank, r.xy, r.classes)}
    parts = set()
    for x in range(0, 16, 4):
        for y in range(0, 16, 4):
            part = BUILTIN.query((x, y, x + 4.0, y + 4.0), scale=337, classes=images, mode=mode,
                                 density_rect=whole_rect)
            parts |= keys(part)
    assert len(whole) > 10000 and parts == keys(whole)


@pytest.mark.parametrize("mode", ["stable", "smooth"])
def test_vectorized_classes(mode):
    # Callable classes on arrays: the points and classes of the same functions called point by point, in
    # calls of many positions (measured 115 on average below the top level, 50 at 1.2-2.3 times it),
    # with a constant class that lets the union's bounds emit points unread, classed afterwards.
    def ramp(x, y):
        return 0.5 + 0.5 * x
    def bump(x, y):
        return 0.3 + 0.7 / (1 + ((x - 1.0) * (x - 1.0) + (y - 1.0) * (y - 1.0)) / 0.5)
    cases = [((0.1, 0.2, 2.9, 2.1), 600)]
    if mode == "smooth":
        cases.append(((0.1, 0.15, 0.45, 0.4), 3 * BUILTIN.info["max_points_per_tile"] / 2.5))
    for rect, scale in cases:
        sizes = []
        def counted(f):
            def g(x, y):
                sizes.append(len(x))
                return f(x, y)
            return g
        kwargs = dict(scale=scale, density_max=[2.5, None, 1.0], mode=mode)  # the ramp's, past the rect too
        scalar = BUILTIN.query(rect, classes=[ramp, 0.5, bump], **kwargs)
        batched = BUILTIN.query(rect, classes=[counted(ramp), 0.5, counted(bump)], vectorized=True, **kwargs)
        assert len(scalar) > 3000 and set(np.unique(scalar.classes)) == {0, 1, 2}
        assert same(scalar, batched) and np.array_equal(scalar.classes, batched.classes)
        assert max(sizes) <= 128 and sum(sizes) > 30 * len(sizes)
        xy, labels = BUILTIN.positions(rect, classes=[ramp, 0.5, bump], vectorized=True, **kwargs)
        assert np.array_equal(labels, scalar.classes) and np.array_equal(xy, scalar.xy.astype(np.float32))
        # The functions called from two threads: the same points and classes, in the units' order.
        xy_2, labels_2 = BUILTIN.positions(rect, classes=[ramp, 0.5, bump], vectorized=True, threads=2, **kwargs)
        order, order_2 = np.lexsort(xy.T), np.lexsort(xy_2.T)
        assert np.array_equal(xy[order], xy_2[order_2]) and np.array_equal(labels[order], labels_2[order_2])


def counted_ramp(slope):
    """The density 0.2 + slope * x counting its calls in calls[0], and its bounds over a rectangle."""
    calls = [0]
    def ramp(x, y):
        calls[0] += 1
        return 0.2 + slope * x
    def bounds(x0, y0, x1, y1):
        return 0.2 + slope * x0, 0.2 + slope * x1
    return ramp, bounds, calls


def test_callable_classes_with_bounds():
    # Bounds for the callable classes (None for the others): the same points and classes with fewer calls
    # in stable mode (measured a fifth of them), in both outputs.
    ramp, ramp_bounds, calls = counted_ramp(0.2)
    rect, kwargs = (0.0, 0.0, 3.0, 2.0), dict(scale=600, density_max=[0.8, None])
    plain = BUILTIN.query(rect, classes=[ramp, 0.5], **kwargs)
    without = calls[0]
    calls[0] = 0
    bounded = BUILTIN.query(rect, classes=[ramp, 0.5], density_bounds=[ramp_bounds, None], **kwargs)
    assert len(plain) > 3000 and same(plain, bounded) and np.array_equal(plain.classes, bounded.classes)
    assert calls[0] < without / 3
    xy, labels = BUILTIN.positions(rect, classes=[ramp, 0.5], density_bounds=[ramp_bounds, None], **kwargs)
    assert np.array_equal(labels, plain.classes)
    with pytest.raises(ValueError, match=r"one entry per class \(2\), got 1"):
        BUILTIN.query(rect, classes=[ramp, 0.5], density_bounds=[ramp_bounds], **kwargs)
    with pytest.raises(ValueError, match=r"density_bounds\[1\] is given but classes\[1\] is not a callable"):
        BUILTIN.query(rect, classes=[ramp, 0.5], density_bounds=[ramp_bounds, ramp_bounds], **kwargs)
    with pytest.raises(TypeError, match="sequence of one callable or None per class"):
        BUILTIN.query(rect, classes=[ramp, 0.5], density_bounds=ramp_bounds, **kwargs)
    with pytest.raises(TypeError, match=r"density_bounds\[0\] must be callable or None"):
        BUILTIN.query(rect, classes=[ramp, 0.5], density_bounds=[1.0, None], **kwargs)
    with pytest.raises(ValueError):  # lo > hi
        BUILTIN.query(rect, classes=[ramp, 0.5], density_bounds=[lambda *r: (1.0, 0.0), None], **kwargs)


def test_callable_classes_refuse_bad_input():
    rect = (0.0, 0.0, 1.0, 1.0)
    f = lambda x, y: 0.5  # noqa: E731
    with pytest.raises(ValueError, match=r"one entry per class \(2\), got 3"):
        BUILTIN.query(rect, scale=10, classes=[f, 1.0], density_max=[1.0, None, None])
    with pytest.raises(ValueError, match=r"classes\[1\] is a callable"):
        BUILTIN.query(rect, scale=10, classes=[f, f], density_max=[1.0, None])
    with pytest.raises(ValueError, match="callable classes only"):
        BUILTIN.positions(rect, scale=10, classes=[1.0, 2.0], density_max=1.0)
    with pytest.raises(ValueError, match=r"density_max\[0\] must be > 0"):
        BUILTIN.query(rect, scale=10, classes=[f], density_max=[-1.0])
    with pytest.raises(TypeError, match="density_max must be a number or a sequence"):
        BUILTIN.query(rect, scale=10, classes=[f], density_max="1")
    with pytest.raises(ValueError, match=r"density_max\[1\] is given but classes\[1\] is not a callable"):
        BUILTIN.query(rect, scale=10, classes=[f, 0.2], density_max=[1.0, 0.2])
    with pytest.raises(ValueError, match=r"returned nan at \("):
        BUILTIN.query(rect, scale=100, classes=[1.0, lambda x, y: math.nan], density_max=1.0)
    class Boom(Exception):
        pass
    def boom(x, y):
        raise Boom()
    with pytest.raises(Boom):
        BUILTIN.positions(rect, scale=100, classes=[boom, 1.0], density_max=1.0)


@pytest.mark.parametrize("mode", ["stable", "smooth"])
def test_positions_are_the_querys_points_as_float32(mode):
    rect, origin = (-1.3, 0.4, 2.7, 3.1), (-1.0, 0.0)
    for density in (0.8, "radial:20", lambda x, y: 0.2 + 0.1 * x):
        kwargs = dict(scale=900, mode=mode, origin=origin)
        if callable(density):
            kwargs["density_max"] = 0.5
        full = BUILTIN.query(rect, density=density, **kwargs)
        xy, keys = BUILTIN.positions(rect, density=density, keys=True, **kwargs)
        assert xy.dtype == np.float32 and xy.shape == (len(full), 2) and len(full) > 1000
        # Within the documented 2**-21 * (|position| + tile_size) of the doubles.
        assert np.all(np.abs(xy - full.xy) <= np.ldexp(np.abs(full.xy) + 1.0, -21))
        tile = full.tile.astype(np.uint64) & np.uint64(2**21 - 1)
        expected = tile[:, 0] | tile[:, 1] << np.uint64(21) | full.rank.astype(np.uint64) << np.uint64(42)
        assert keys.dtype == np.uint64 and np.array_equal(keys, expected)
        assert np.array_equal(full.keys, keys)  # a result's keys join with positions'
        # Positions alone are the same numbers.
        assert np.array_equal(BUILTIN.positions(rect, density=density, **kwargs), xy)


@pytest.mark.parametrize("mode", ["stable", "smooth"])
def test_positions_with_classes_are_the_class_querys_points(mode):
    rect, origin = (0.2, 0.1, 3.0, 2.0), (0.0, 0.0)
    classes = [1.0, "ramp:4", 2.0]
    full = BUILTIN.query(rect, scale=150, classes=classes, mode=mode, origin=origin)
    xy, keys, labels = BUILTIN.positions(rect, scale=150, classes=classes, mode=mode, origin=origin, keys=True)
    assert len(full) > 1000 and xy.shape == (len(full), 2) and xy.dtype == np.float32
    assert labels.dtype == np.uint8 and np.array_equal(labels, full.classes)
    # A varying union writes the double rounded to float.
    assert np.array_equal(xy, full.xy.astype(np.float32))
    assert np.array_equal(keys >> np.uint64(42) & np.uint64(2**19 - 1), full.rank.astype(np.uint64))
    # Constant classes: the one-class positions at the sum, bit for bit.
    xy_c, labels_c = BUILTIN.positions(rect, scale=150, classes=[1.0, 2.0], mode=mode)
    assert np.array_equal(xy_c, BUILTIN.positions(rect, scale=150, density=3.0, mode=mode))
    assert set(np.unique(labels_c)) == {0, 1}
    # On threads: the same points and classes (in an order of the units'), the same bits for any count.
    xy_2, labels_2 = BUILTIN.positions(rect, scale=150, classes=classes, mode=mode, origin=origin, threads=2)
    xy_3, labels_3 = BUILTIN.positions(rect, scale=150, classes=classes, mode=mode, origin=origin, threads=3)
    assert np.array_equal(xy_2, xy_3) and np.array_equal(labels_2, labels_3)
    order = np.lexsort((xy[:, 1], xy[:, 0]))
    order_2 = np.lexsort((xy_2[:, 1], xy_2[:, 0]))
    assert np.array_equal(xy[order], xy_2[order_2]) and np.array_equal(labels[order], labels_2[order_2])
    with pytest.raises(ValueError, match=r"threads must be 0 \(the CPUs this process may use\) or 1 to 64"):
        BUILTIN.positions(rect, scale=150, classes=classes, threads=65)
    with pytest.raises(ValueError, match="give either density or classes, not both"):
        BUILTIN.positions(rect, scale=150, classes=classes, density=1.0)
    with pytest.raises(ValueError, match="1 to 8"):
        BUILTIN.positions(rect, scale=150, classes=[])


def test_positions_over_threads_give_the_same_bits_for_any_count():
    rect = (0.0, 0.0, 6.0, 5.0)
    for mode in ("stable", "smooth"):
        one, one_keys = BUILTIN.positions(rect, scale=6000, mode=mode, keys=True, threads=1)
        two, two_keys = BUILTIN.positions(rect, scale=6000, mode=mode, keys=True, threads=2)
        assert len(one) > 100000 and np.array_equal(one, two) and np.array_equal(one_keys, two_keys)
        auto, auto_keys = BUILTIN.positions(rect, scale=6000, mode=mode, keys=True, threads=0)  # the CPUs'
        assert np.array_equal(one, auto) and np.array_equal(one_keys, auto_keys)
        # The same points as one query, in an order of their own.
        plain_xy, plain_keys = BUILTIN.positions(rect, scale=6000, mode=mode, keys=True)
        assert np.array_equal(np.sort(plain_keys), np.sort(one_keys))


def test_query_over_threads_gives_the_same_points():
    rect = (-2.0, -1.0, 4.0, 3.5)
    image = np.random.default_rng(3).random((40, 50))
    for kwargs in (dict(density=image), dict(density="radial:30", mode="smooth"),
                   dict(classes=[0.2, image], mode="smooth"), dict(density=0.9, scale=30000, mode="smooth")):
        kwargs = {"scale": 2500, **kwargs}
        one = BUILTIN.query(rect, **kwargs)
        for threads in (1, 2, 0):
            split = BUILTIN.query(rect, threads=threads, **kwargs)
            assert len(split) == len(one) > 5000
            order = np.argsort(split.keys)  # the same points, with their levels and classes
            back = np.argsort(one.keys)
            assert np.array_equal(split.points[order], one.points[back])
            assert np.array_equal(split.level[order], one.level[back])
            if one.classes is not None:
                assert np.array_equal(split.classes[order], one.classes[back])
            if threads == 1:
                first = split
            else:  # the same bits for any count
                assert np.array_equal(split.points, first.points) and np.array_equal(split.level, first.level)
    # Below a unit's points per tile the split keeps the query's order too.
    small = BUILTIN.query(rect, scale=900, density=image, threads=2)
    assert same(small, BUILTIN.query(rect, scale=900, density=image))
    # A Python function runs one query (the GIL lets one thread call it at a time): the same bits.
    def ramp(x, y):
        return 0.3 + 0.1 * x

    assert same(BUILTIN.query(rect, scale=900, density=ramp, density_max=1, threads=2),
                BUILTIN.query(rect, scale=900, density=ramp, density_max=1))
    with pytest.raises(ValueError, match="threads must be 0 .* or 1 to 64, got 65"):
        BUILTIN.query(rect, scale=900, threads=65)


def test_positions_refuse_bad_arguments():
    with pytest.raises(ValueError, match="threads must be 0 .* or 1 to 64, got -1"):
        BUILTIN.positions((0, 0, 1, 1), scale=10, threads=-1)
    with pytest.raises(TypeError, match="threads must be an int"):
        BUILTIN.positions((0, 0, 1, 1), scale=10, threads=1.5)
    with pytest.raises(TypeError, match="keys must be True or False"):
        BUILTIN.positions((0, 0, 1, 1), scale=10, keys=1)
    xy, keys = BUILTIN.positions((0, 0, 1, 1), scale=40, keys=np.True_)  # numpy's bool is a bool
    assert len(xy) == len(keys) > 0
    with pytest.raises(ValueError, match=r"scale= [0-9.]+ or less"):
        BUILTIN.positions((0, 0, 1, 1), scale=1e9)
    with pytest.raises(ValueError, match=r"scale= [0-9.]+ or less"):
        BUILTIN.positions((0, 0, 1, 1), scale=1e9, threads=2)
    with pytest.raises(ValueError, match="density_max"):
        BUILTIN.positions((0, 0, 1, 1), scale=10, density=lambda x, y: 1.0)
    assert BUILTIN.positions((0, 0, 1, 1), scale=100, density=0.0).shape == (0, 2)


@pytest.mark.parametrize("mode", ["stable", "smooth"])
def test_density_bounds_keep_the_points_and_save_calls(mode):
    ramp, bounds, calls = counted_ramp(0.1)
    rect = (0.0, 0.0, 8.0, 1.0)  # the ramp reaches 1 at x = 8, and a little more where smooth mode reads past it
    plain = BUILTIN.query(rect, scale=600, density=ramp, density_max=1.1, mode=mode)
    everywhere, calls[0] = calls[0], 0
    bounded = BUILTIN.query(rect, scale=600, density=ramp, density_max=1.1, density_bounds=bounds, mode=mode)
    assert len(plain) > 2000 and same(plain, bounded)
    # Stable mode calls the density only between a tile's bounds and its cells' (measured: 0.02 of the
    # calls), smooth mode only below the upper bound (0.46).
    assert calls[0] < (0.3 if mode == "stable" else 0.7) * everywhere
    xy = BUILTIN.positions(rect, scale=600, density=ramp, density_max=1.1, density_bounds=bounds, mode=mode)
    assert np.array_equal(xy, BUILTIN.positions(rect, scale=600, density=ramp, density_max=1.1, mode=mode))


def test_density_bounds_refuse_bad_use_and_pass_errors_on():
    with pytest.raises(ValueError, match="density_bounds is for a callable density only"):
        BUILTIN.query((0, 0, 1, 1), scale=10, density=0.5, density_bounds=lambda *r: (0, 1))
    with pytest.raises(TypeError, match="density_bounds must be callable"):
        BUILTIN.query((0, 0, 1, 1), scale=10, density=lambda x, y: 1.0, density_max=1.0, density_bounds=3)
    with pytest.raises(TypeError, match="density_bounds with classes must be a sequence"):
        BUILTIN.query((0, 0, 1, 1), scale=10, classes=[0.5], density_bounds=lambda *r: (0, 1))
    def broken(x0, y0, x1, y1):
        raise KeyError("no bounds here")
    with pytest.raises(KeyError, match="no bounds here"):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=lambda x, y: 1.0, density_max=1.0, density_bounds=broken)
    with pytest.raises(ValueError, match=r"\(lo, hi\)"):
        BUILTIN.query((0, 0, 2, 2), scale=100, density=lambda x, y: 1.0, density_max=1.0,
                      density_bounds=lambda *r: (0.0, 1.0, 2.0))


def test_glide_together_moves_the_same_points_and_keeps_them_apart():
    # Independent texels a little under a spacing wide (as RuntimeQualityTest's): gliding together keeps
    # the points (ids; only the region's sides may differ) and moves them, and far fewer pairs close up
    # than when each point glides by its own density (measured 0.2-0.4% against 2.5-3%).
    from scipy.spatial import cKDTree
    image = np.random.default_rng(3).uniform(0.1, 1.0, (200, 200))
    args = dict(scale=25000, density=image, tile_size=0.25, mode="smooth")
    own = BUILTIN.query((0, 0, 1, 1), **args)
    together = BUILTIN.query((0, 0, 1, 1), glide_together=True, **args)

    def ids(r):
        return {(int(t[0]), int(t[1]), int(k)) for t, k in zip(r.tile, r.rank)}
    assert len(ids(own) ^ ids(together)) < 0.02 * len(own)
    where = {key: xy for key, xy in zip(zip(own.tile[:, 0], own.tile[:, 1], own.rank), own.xy)}
    moved = [not np.array_equal(where[key], xy)
             for key, xy in zip(zip(together.tile[:, 0], together.tile[:, 1], together.rank), together.xy)
             if key in where]
    assert np.mean(moved) > 0.1

    def close_share(r):
        d, _ = cKDTree(r.xy).query(r.xy, 2)
        return np.mean(d[:, 1] < 0.25 * math.sqrt(2 / (math.sqrt(3) * 25000)))  # a quarter of d_hex at 1
    assert close_share(together) < close_share(own) / 3
    xy = BUILTIN.positions((0, 0, 1, 1), glide_together=True, **args)
    assert np.allclose(xy, together.xy, atol=1e-5)
    stable = dict(args, mode="stable")  # ignored in stable mode
    assert np.array_equal(BUILTIN.query((0, 0, 1, 1), glide_together=True, **stable).xy,
                          BUILTIN.query((0, 0, 1, 1), **stable).xy)
    with pytest.raises(TypeError, match="glide_together"):
        BUILTIN.query((0, 0, 1, 1), glide_together="yes", **args)


def test_a_signal_stops_a_bake_inside_its_call():
    # As for the sampler: the handler runs between the bake's runs, so the call ends with the exception
    # instead of returning the set. This recipe takes about 9 s on one thread; the alarm comes after 0.3 s.
    bake = lambda: kdm.bake("levels 3\ncolours 2\nsweeps 100\n", threads=1)  # noqa: E731
    assert interrupted("bake", bake, 0.3) == ["c_exception"]


def test_an_empty_or_inverted_region_has_no_points():
    # As in C and C++ (query.h: none if x1 <= x0): chunk code that clips regions to a world's bounds needs no
    # special case. Whatever the density, an image stretched over the region included.
    tiles = kdm.Tileset.builtin()
    for rect in [(10, 0, 0, 10), (5, 5, 5, 5), (0, 3, 1, 2)]:
        for density in [1.0, np.ones((4, 4)), "ramp:10", lambda x, y: 0.5]:
            bound = dict(density_max=1.0) if callable(density) else {}
            assert len(tiles.query(rect, scale=100, density=density, **bound)) == 0
            assert tiles.positions(rect, scale=100, density=density, **bound).shape == (0, 2)
        assert len(tiles.query(rect, scale=100, classes=[np.ones((4, 4)), 0.2])) == 0
    # Classes may come as a 1-D array of constant densities.
    assert np.array_equal(tiles.query((0, 0, 4, 4), scale=400, classes=np.array([0.1, 0.2])).classes,
                          tiles.query((0, 0, 4, 4), scale=400, classes=[0.1, 0.2]).classes)


@pytest.mark.parametrize("mode", ["stable", "smooth"])
@pytest.mark.filterwarnings("ignore:class 1 expects")  # its sparse middle class is warned of; not the point here
def test_a_density_map_gives_the_points_of_its_density_and_rect(mode):
    # A map prepared once (converted, checked and mipped once) gives every query the points that passing
    # its array and density_rect each time gives: one density, classes (maps with an array and a constant,
    # as class images are read by their sums) and positions(), in chunks of one region.
    t = kdm.Tileset.builtin()
    rng = np.random.default_rng(5)
    world = (0.0, 0.0, 400.0, 300.0)
    arrays = [rng.random((60, 80)) * c for c in (0.4, 1.0)]
    maps = [kdm.DensityMap(a, world) for a in arrays]
    assert maps[0].kind == "image" and maps[0].rect == world
    for chunk in [(0, 0, 120, 90), (120, 0, 400, 300), (37.5, 12.25, 61, 80)]:
        kw = dict(scale=0.5, tile_size=16, mode=mode)
        a = t.query(chunk, density=arrays[1], density_rect=world, **kw)
        b = t.query(chunk, density=maps[1], **kw)
        assert np.array_equal(a.xy, b.xy) and np.array_equal(a.rank, b.rank)
        a = t.query(chunk, classes=[arrays[0], 0.1, arrays[1]], density_rect=world, **kw)
        b = t.query(chunk, classes=[maps[0], 0.1, maps[1]], **kw)
        assert np.array_equal(a.xy, b.xy) and np.array_equal(a.classes, b.classes)
        # Classes that are all maps keep their running sums with the first (built once, not per query),
        # whichever set it last led: the same points as the arrays read by their sums each time.
        for order in ([0, 1], [1, 0], [0, 1]):
            a = t.query(chunk, classes=[arrays[k] for k in order], density_rect=world, **kw)
            b = t.query(chunk, classes=[maps[k] for k in order], **kw)
            assert np.array_equal(a.xy, b.xy) and np.array_equal(a.classes, b.classes)
        assert np.array_equal(t.positions(chunk, density=arrays[0], density_rect=world, **kw),
                              t.positions(chunk, density=maps[0], **kw))
    # A test map and an image file too; a pickle rebuilds the same map (an array from its own copy).
    for m, given in [(kdm.DensityMap("ramp:8", world), dict(density="ramp:8")),
                     (kdm.DensityMap(str(SPHERE), world, gamma=2), dict(density=str(SPHERE), gamma=2))]:
        b = t.query(world, scale=0.5, tile_size=16, mode=mode, density=m)
        assert np.array_equal(t.query(world, scale=0.5, tile_size=16, mode=mode, density_rect=world, **given).xy,
                              b.xy)
        assert np.array_equal(t.query(world, scale=0.5, tile_size=16, mode=mode,
                                      density=pickle.loads(pickle.dumps(m))).xy, b.xy)
    copy = pickle.loads(pickle.dumps(maps[1]))
    arrays[1][:] = 0  # the map keeps its own values
    assert np.array_equal(t.query(world, scale=0.5, tile_size=16, density=copy).xy,
                          t.query(world, scale=0.5, tile_size=16, density=maps[1]).xy)


def test_a_density_map_refuses_what_it_cannot_stand_for():
    t = kdm.Tileset.builtin()
    m = kdm.DensityMap(np.ones((4, 4)), (0, 0, 10, 10))
    with pytest.raises(ValueError, match="rect is needed"):
        kdm.DensityMap(np.ones((4, 4)))
    with pytest.raises(TypeError, match="density must be a number, a str or a 2-D array"):
        kdm.DensityMap(lambda x, y: 1.0, (0, 0, 1, 1))
    with pytest.raises(ValueError, match="density_rect is the DensityMap's own"):
        t.query((0, 0, 10, 10), scale=1, density=m, density_rect=(0, 0, 10, 10))
    with pytest.raises(ValueError, match="gamma and invert are the DensityMap's own"):
        t.query((0, 0, 10, 10), scale=1, density=m, gamma=2)
    with pytest.raises(ValueError, match="one rect"):
        t.query((0, 0, 10, 10), scale=1, classes=[m, kdm.DensityMap(np.ones((4, 4)), (0, 0, 20, 20))])
    with pytest.raises(ValueError, match="rect is empty or inverted"):
        kdm.DensityMap(np.ones((4, 4)), (0, 0, -1, 1))
    with pytest.raises(ValueError, match="finite and >= 0"):
        kdm.DensityMap(np.full((4, 4), -1.0), (0, 0, 1, 1))
    assert len(t.query((0, 0, 10, 10), scale=20, density=kdm.DensityMap(2.0)).xy) > 100  # a constant: no rect


def test_a_density_map_reads_as_queries_do_and_pickles_what_it_holds(tmp_path):
    # at(): the density a query reads (fading by thresholds needs it), here against the bilinear texel
    # centres of the array; a pickle holds the densities read, not an image's path, so a file changed or
    # gone since gives the same map; rect is read-only, and a constant has none.
    t = kdm.Tileset.builtin()
    a = np.random.default_rng(3).random((30, 40))
    m = kdm.DensityMap(a, (0, 0, 4, 3))
    assert np.allclose(m.at([0.05, 3.95], [2.95, 0.05]), [a[0, 0], a[-1, -1]])
    assert m.at(np.ones((2, 3)), np.ones((2, 3))).shape == (2, 3)
    with pytest.raises(AttributeError):
        m.rect = (0, 0, 1, 1)
    image = tmp_path / "map.png"
    image.write_bytes(SPHERE.read_bytes())
    f = kdm.DensityMap(str(image), (0, 0, 10, 10), gamma=2)
    pickled = pickle.dumps(f)
    image.write_bytes(b"not a picture any more")
    g = pickle.loads(pickled)
    assert np.array_equal(t.query((0, 0, 10, 10), scale=50, density=f).xy,
                          t.query((0, 0, 10, 10), scale=50, density=g).xy)
    assert np.array_equal(f.at([2.5], [7.5]), g.at([2.5], [7.5]))
    c = kdm.DensityMap(0.5, (5, 5, 0, 0))  # a constant's rect is ignored, as documented
    assert c.rect is None and pickle.loads(pickle.dumps(c)).at([1.0], [2.0])[0] == 0.5
    with pytest.raises(ValueError, match="DensityMap's own"):
        t.query((0, 0, 10, 10), scale=1, classes=[f, 0.1], gamma=2)


def test_a_density_map_at_no_position_is_zero_as_in_c():
    # kdm_density_image_at's rule: a NaN or infinite coordinate has density 0 (not the first or the edge
    # texel's, which the clamped bilinear read would give), whatever the map's kind.
    for m in (kdm.DensityMap(np.ones((2, 2)), (0, 0, 1, 1)), kdm.DensityMap(2.0), kdm.DensityMap("ramp:4", (0, 0, 1, 1))):
        assert m.at(0.5, 0.5) > 0
        bad = [np.nan, np.inf, -np.inf, 0.5, 0.5, 0.5]
        assert np.array_equal(m.at(bad, bad[::-1]), [0.0] * 6), m
    assert kdm.DensityMap(np.ones((2, 2)), (0, 0, 1, 1)).at(float("nan"), 0.5) == 0


def test_thresholds_of_positions_keys_are_their_points_thresholds():
    # positions(keys=True) carries keys, not tiles: given a tile of the region, their thresholds are those
    # of the query's records, negative tiles and past the top level too (a key names its tile modulo 2**21).
    t = kdm.Tileset.builtin()
    for rect, scale in [((-7.3, -2.2, -3.1, 1.5), 800.0), ((-3.05, 4.0, -3.0, 4.05), 3.1e6)]:
        kw = dict(scale=scale, tile_size=1, mode="smooth")
        records = t.query(rect, **kw)
        xy, keys = t.positions(rect, keys=True, **kw)
        near = (math.floor(rect[0]), math.floor(rect[1]))
        assert np.array_equal(t.thresholds(keys, near_tile=near), t.thresholds(records))
    with pytest.raises(ValueError, match="keys need near_tile"):
        t.thresholds(keys)
    with pytest.raises(ValueError, match="near_tile is for keys only"):
        t.thresholds(records, near_tile=(0, 0))


def test_a_tile_size_too_small_for_the_density_is_warned_of():
    # As kdm query warns: under the built-in set's coarsest level (32 points per tile) a tile gives part of
    # it, and below one point its count rounds to steps of 1/16 (0.05 per tile: +28% measured).
    with pytest.warns(UserWarning, match=r"at most 20 points per tile, under the tile set's coarsest level "
                                         r"\(32\).*tile_size of at least 1\.26") as said:
        BUILTIN.query((0, 0, 4, 4), scale=20)
    assert said[0].filename == __file__
    with pytest.warns(UserWarning, match=r"at most 0\.05 points per tile; below 1 a tile's expected count rounds "
                                         r"to steps of 1/16") as said:
        xy = BUILTIN.positions((0, 0, 40, 40), scale=0.05)
    assert said[0].filename == __file__ and len(xy) > 0
    with pytest.warns(UserWarning, match="at most 30 points per tile") as said:  # the classes' sum
        BUILTIN.query((0, 0, 4, 4), scale=100, classes=[0.1, 0.2])
    assert said[0].filename == __file__
    with pytest.warns(UserWarning, match="at most 20 points per tile") as said:
        BUILTIN.positions((0, 0, 4, 4), scale=20, density=lambda x, y: 0.5 + 0.5 * x / 4, density_max=1.0)
    assert said[0].filename == __file__
    # A rare class after dense ones (its count what theirs leave: twice its own, as kdm query's test
    # measures), in both query paths; first, it gets its count but the same few places in every tile.
    for call in (BUILTIN.query, BUILTIN.positions):
        with pytest.warns(UserWarning, match=r"class 2 expects at most 1\.02 points per tile.*on its own") as said:
            call((0, 0, 64, 64), scale=1, tile_size=32, classes=[0.02, 0.1, 0.001])
        assert said[0].filename == __file__
        with pytest.warns(UserWarning, match=r"class 0 expects at most 1\.02 points per tile.*tile_size of at "
                                             r"least 179") as said:
            call((0, 0, 64, 64), scale=1, tile_size=32, classes=[0.001, 0.02, 0.1])
        assert said[0].filename == __file__
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        BUILTIN.query((0, 0, 64, 64), scale=1, tile_size=32, classes=[0.04, 0.02, 0.1])  # class 0: 41 a tile
    # A map's peak, not the region's, is what is judged: a sparse corner of a map is no mistake.
    ramp = kdm.DensityMap(np.array([[0.01, 1.0]]), (0, 0, 10, 10))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        BUILTIN.query((0, 0, 1, 1), scale=100, density=ramp)
        BUILTIN.query((0, 0, 0, 0), scale=1)  # an empty region emits nothing to warn of
        BUILTIN.query((0, 0, 2, 2), scale=32)


def test_stable_positions_are_where_a_stable_query_puts_the_points():
    # And where a smooth query's points glide from: a fade weight read there follows the query's rule.
    rect, origin = (0.2, 0.3, 3.2, 2.3), (1.5, -0.5)
    stable = BUILTIN.query(rect, scale=400, tile_size=2.0, origin=origin, mode="stable")
    np.testing.assert_allclose(BUILTIN.stable_positions(stable, tile_size=2.0, origin=origin), stable.xy,
                               rtol=0, atol=1e-12)
    ramp = kdm.DensityMap(np.array([[0.05, 1.0]]), (0, 0, 4, 4))
    smooth = BUILTIN.query(rect, scale=400, tile_size=2.0, origin=origin, density=ramp, mode="smooth")
    home = BUILTIN.stable_positions(smooth, tile_size=2.0, origin=origin)
    assert not np.array_equal(home, smooth.xy)  # they glided
    count = ramp.at(home[:, 0] + origin[0], home[:, 1] + origin[1]) * 400 * 2.0**2
    assert (count > BUILTIN.thresholds(smooth)).all()  # every point present, by its threshold
    with pytest.raises(ValueError, match="tile_size"):
        BUILTIN.stable_positions(stable, tile_size=0)
    with pytest.raises(TypeError, match="QueryResult"):
        BUILTIN.stable_positions(stable.xy)
    with pytest.raises(ValueError, match="origin"):
        BUILTIN.stable_positions(stable, origin=(0, float("nan")))
