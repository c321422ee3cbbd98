"""kdm.BlueNoise as a SciPy QMC engine, with SciPy and without it."""
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import kdm


def test_a_qmc_engine_of_scipy():
    qmc = pytest.importorskip("scipy.stats.qmc")
    engine = kdm.BlueNoise(d=2, seed=7)
    assert isinstance(engine, qmc.QMCEngine) and engine.d == 2
    first = engine.random(512)
    assert first.shape == (512, 2) and first.min() >= 0 and first.max() < 1
    second = engine.random(512)
    assert engine.num_generated == 1024 and not np.array_equal(first, second)
    engine.reset()
    assert engine.num_generated == 0
    assert np.array_equal(engine.random(512), first) and np.array_equal(engine.random(512), second)
    # fast_forward(n) skips one set of n (its seed: its points are never computed); of 0, nothing.
    engine.reset().fast_forward(512)
    assert engine.num_generated == 512 and np.array_equal(engine.random(512), second)
    assert np.array_equal(engine.reset().fast_forward(0).random(512), first)
    ints = engine.integers(10, n=256)
    assert ints.shape == (256, 2) and ints.dtype == np.int64 and 0 <= ints.min() and ints.max() < 10
    # SciPy's tools take it: the discrepancy of blue noise is far below that of random points.
    # (At 512 points, 20 seeds of each: kdm's centred L2 discrepancy spans 1.8e-5..1.0e-4, uniform random
    # points' 2.8e-4..1.6e-3; 2e-4 lies between.)
    assert qmc.discrepancy(first) < 2e-4


def test_each_draw_is_a_whole_blue_noise_set():
    engine = kdm.BlueNoise(d=2, seed=3)
    p = engine.random(1024)
    # Nearest-neighbour distances of blue noise: no close pairs. Over engine seeds 0..19 at n = 1024 the
    # smallest distance was 0.60 to 0.72 of the hexagonal spacing (random points: 0.04); 0.4 leaves margin.
    d_hex = np.sqrt(2 / (np.sqrt(3) * len(p)))
    diff = np.abs(p[:, None, :] - p[None, :, :])
    diff = np.minimum(diff, 1 - diff)  # torus
    dist = np.sqrt((diff ** 2).sum(-1)) + np.eye(len(p))
    assert dist.min() > 0.4 * d_hex


def test_seeds_as_scipy_takes_them():
    pytest.importorskip("scipy")
    a = kdm.BlueNoise(d=2, seed=np.random.default_rng(5)).random(300)
    b = kdm.BlueNoise(d=2, seed=5).random(300)
    assert np.array_equal(a, b)  # an int seeds default_rng(int)
    drawn = int(np.random.default_rng(5).integers(0, 2**63, dtype=np.int64))
    assert np.array_equal(b, kdm.sample(300, seed=drawn))  # each draw is kdm.sample with a drawn seed
    rng = np.random.default_rng(9)
    engine = kdm.BlueNoise(2, seed=rng)
    first = engine.random(200)
    engine.reset()  # a Generator is replayed from the copy taken at construction
    assert np.array_equal(engine.random(200), first)
    assert kdm.BlueNoise(2).random(10).shape == (10, 2)  # None: fresh entropy
    fresh = kdm.BlueNoise(2)
    first = fresh.random(100)
    assert np.array_equal(fresh.reset().random(100), first)  # kept, so reset() replays it too
    assert not np.array_equal(kdm.BlueNoise(2).random(100), first)  # fresh for each engine
    assert kdm.BlueNoise(3, seed=1).random(100).shape == (100, 3)
    assert kdm.BlueNoise(2, seed=1).random(0).shape == (0, 2)
    with pytest.raises(TypeError, match="seed must be None, an int, a numpy.random.Generator"):
        kdm.BlueNoise(2, seed="seven")
    # A SeedSequence (the docstring's way to seed workers) or a BitGenerator seeds default_rng, as numpy's
    # own default_rng takes them.
    children = np.random.SeedSequence(3).spawn(2)
    from_child = kdm.BlueNoise(2, seed=children[0]).random(100)
    assert np.array_equal(from_child, kdm.BlueNoise(2, seed=np.random.default_rng(children[0])).random(100))
    assert not np.array_equal(from_child, kdm.BlueNoise(2, seed=children[1]).random(100))
    assert np.array_equal(kdm.BlueNoise(2, rng=np.random.PCG64(4)).random(100),
                          kdm.BlueNoise(2, seed=np.random.default_rng(4)).random(100))
    with pytest.raises(ValueError, match="seed must be a non-negative int, got -1"):
        kdm.BlueNoise(2, seed=-1)
    # SciPy 1.15 names it rng: the same engine by either name, not both at once.
    assert np.array_equal(kdm.BlueNoise(2, rng=5).random(300), b)
    assert np.array_equal(kdm.BlueNoise(2, rng=np.random.default_rng(5)).random(300), b)
    with pytest.raises(TypeError, match="seed or rng, not both"):
        kdm.BlueNoise(2, seed=5, rng=5)


def test_engine_options():
    e = kdm.BlueNoise(2, seed=1, density="ramp:10", temperature=0.2, threads=1)
    p = e.random(2000)
    # The ramp R^-x puts sqrt(10) = 3.16 times more points left of x = 0.5 than right of it (3.12 to 3.34
    # over engine seeds 0..19 at n = 2000; a uniform density gives 1).
    assert (p[:, 0] < 0.5).sum() > 2.5 * (p[:, 0] >= 0.5).sum()
    with pytest.raises(ValueError):
        kdm.BlueNoise(4)
    with pytest.raises(ValueError):
        kdm.BlueNoise(2, density=0.0)
    with pytest.raises(TypeError):
        kdm.BlueNoise(2.0)
    with pytest.raises(ValueError, match="image and array densities are 2-D; use d=2"):
        kdm.BlueNoise(3, density=np.ones((4, 4)))
    e.threads = 10**9  # set after __init__: checked at the draw
    with pytest.raises(ValueError, match="threads must be"):
        e.random(10)
    # A density set after __init__ is checked when set and drawn from: uniform now, so about as many
    # points on each side of x = 0.5 (the ramp above gives three times more on the left).
    e.threads = 1
    e.density = None
    p = e.random(2000)
    assert abs((p[:, 0] < 0.5).mean() - 0.5) < 0.05
    with pytest.raises(ValueError):
        e.density = 0.0
    with pytest.raises(ValueError, match="'const:0' is zero everywhere"):  # when set, not at the draw
        e.density = "const:0"
    e3 = kdm.BlueNoise(3, seed=1)
    with pytest.raises(ValueError, match="image and array densities are 2-D; use d=2"):
        e3.density = np.ones((4, 4))
    # Checked at construction, not at the first draw, as kdm.sample checks them.
    with pytest.raises(ValueError, match="temperature must be at most 1000"):
        kdm.BlueNoise(2, temperature=2000)
    with pytest.raises(ValueError, match="aspect must be > 0"):
        kdm.BlueNoise(3, aspect=0.0)
    # An array density is copied: the caller's later changes neither reach the draws nor seem to.
    ramp = np.tile(np.linspace(1.0, 10.0, 8), (8, 1))
    e = kdm.BlueNoise(2, seed=3, density=ramp, threads=1)
    before = e.random(500)
    ramp[:] = 1.0
    assert not np.array_equal(e.density, ramp) and not e.density.flags.writeable
    assert np.array_equal(e.reset().random(500), before)


def test_an_engine_pickles_and_copies():
    import copy
    import pickle
    for density in (None, 2.0, "ramp:4", np.tile(np.linspace(1.0, 4.0, 6), (5, 1))):
        e = kdm.BlueNoise(2, seed=7, density=density, threads=1)
        e.random(50)  # the copy continues from here
        for twin in (pickle.loads(pickle.dumps(e)), copy.deepcopy(e)):
            if isinstance(density, np.ndarray):
                assert not twin.density.flags.writeable
            assert np.array_equal(twin.random(300), e.random(300)), density
            e.reset(), twin.reset()
            assert np.array_equal(twin.random(300), e.random(300)), density


def test_a_shallow_copy_is_an_engine_of_its_own():
    import copy
    for seed in (7, np.random.default_rng(7), np.random.RandomState(7)):
        e = kdm.BlueNoise(2, seed=seed, threads=1)
        e.random(50)
        twin = copy.copy(e)
        assert twin.rng is not e.rng
        # The same state: the twin draws what the engine draws next, and each draw advances only its own.
        first = twin.random(200)
        assert np.array_equal(first, e.random(200))
        assert np.array_equal(twin.random(200), e.random(200))
        assert np.array_equal(twin.reset().random(200), e.reset().random(200))


def test_the_density_and_aspect_forms_of_kdm_sample_for_d():
    # A volume needs d=3, named as the engine names it.
    with pytest.raises(ValueError, match=r"a 3-D array of shape \(4, 4, 4\) is a volume .*: use d=3$"):
        kdm.BlueNoise(d=2, density=np.ones((4, 4, 4)))
    volume = np.ones((4, 5, 6))
    volume[:2] = 3.0
    engine = kdm.BlueNoise(d=3, seed=2, density=volume, threads=1)
    drawn = int(np.random.default_rng(2).integers(0, 2**63, dtype=np.int64))
    assert np.array_equal(engine.random(300), kdm.sample(300, volume, dim=3, seed=drawn, threads=1))
    # Three sides with d=3, as kdm.sample(dim=3) takes them: its points, in [0, 1)^3 as kdm.sample's.
    for density in (None, lambda x, y, z: 1.0 + z):
        engine = kdm.BlueNoise(d=3, seed=2, aspect=(1, 2, 3), density=density, threads=1)
        assert engine.aspect == (1.0, 2.0, 3.0)
        points = engine.random(400)
        assert np.array_equal(points, kdm.sample(400, density, dim=3, seed=drawn, aspect=(1, 2, 3), threads=1))
        assert points.min() >= 0 and points.max() < 1
        assert not np.array_equal(points, kdm.BlueNoise(d=3, seed=2, density=density, threads=1).random(400))
    with pytest.raises(ValueError, match=r"aspect=\(x, y, z\) sets a 3-D domain's sides: use d=3"):
        kdm.BlueNoise(d=2, aspect=(1, 2, 3))
    with pytest.raises(ValueError, match=r"aspect\[1\] must be > 0"):
        kdm.BlueNoise(d=3, aspect=(1, 0, 3))
    with pytest.raises(TypeError, match="aspect must be a number or a sequence of three sides"):
        kdm.BlueNoise(d=3, aspect="1:2:3")
    engine = kdm.BlueNoise(d=3, seed=2)
    engine.aspect = (1, 2)  # set after __init__: checked at the draw
    with pytest.raises(ValueError, match="got 2 values"):
        engine.random(10)


def test_aspect_spaces_points_evenly_in_the_unit_square():
    # A 10 x 40 array of ones is a uniform density 4 times wider than tall: by default the points are spaced
    # evenly in that shape and squeezed into [0, 1)^2 (anisotropic there, as kdm.sample's are); aspect=1
    # spaces them evenly in the unit square. (Seed 1, 4,096 points: 2.7 dB against 0.03 dB.)
    density = np.ones((10, 40))
    def anisotropy(engine):
        m = kdm.analyze(engine.random(4096), box=True, energy=False, threads=1)
        return abs(m["spectrum"]["anisotropy_db"])
    assert anisotropy(kdm.BlueNoise(density=density, seed=1, threads=1)) > 1.5
    assert anisotropy(kdm.BlueNoise(density=density, seed=1, threads=1, aspect=1)) < 0.5
    with pytest.raises(ValueError, match="aspect"):
        kdm.BlueNoise(aspect=0)


def test_without_scipy():
    # A fresh interpreter where importing scipy fails: kdm still imports and BlueNoise still works.
    code = textwrap.dedent("""
        import sys, importlib.abc
        class NoScipy(importlib.abc.MetaPathFinder):
            def find_spec(self, name, path, target=None):
                if name == "scipy" or name.startswith("scipy."):
                    raise ImportError("scipy is blocked")
        sys.meta_path.insert(0, NoScipy())
        import numpy as np, kdm
        e = kdm.BlueNoise(d=2, seed=7)
        first = e.random(256)
        assert type(e).__mro__[1].__module__ == "kdm._engine", type(e).__mro__
        assert e.num_generated == 256 and first.shape == (256, 2)
        e.reset()
        assert np.array_equal(e.random(256), first) and e.num_generated == 256
        assert e.integers(5, n=16).max() < 5
        assert e.integers(5, u_bounds=6, n=8, endpoint=True).min() >= 5
        for bad in ((5, 2), (5, 5), (True, None), (0, [3, 4, 5])):  # SciPy refuses each as well
            try:
                e.integers(bad[0], u_bounds=bad[1], n=3)
            except ValueError:
                pass
            else:
                raise AssertionError(f"integers{bad} drew")
        assert "scipy" not in sys.modules
        print("ok", kdm.__version__)
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"ok {kdm.__version__}"


def test_a_refused_draw_uses_no_seed_and_workers_follow_scipy():
    # The draw after a refused one is the draw a fresh engine makes first: the refused one used no seed.
    engine = kdm.BlueNoise(d=2, seed=1, threads=1)
    with pytest.raises(ValueError, match="computational grid"):
        engine.random(2**31)
    assert np.array_equal(engine.random(10), kdm.BlueNoise(d=2, seed=1, threads=1).random(10))
    # workers as SciPy's engines take it (-1: every core), the same points whatever the count.
    for bad in (0, -2, "x", 2.5, True):
        with pytest.raises(ValueError, match="Invalid number of workers"):
            engine.random(8, workers=bad)
    one, two, every = (kdm.BlueNoise(d=2, seed=3).random(64, workers=w) for w in (1, 2, -1))
    assert np.array_equal(one, two) and np.array_equal(one, every)
    # An attribute set to nonsense is refused by name at the next draw, which then uses no seed either.
    engine.temperature = "hot"
    with pytest.raises(TypeError, match="temperature must be a number"):
        engine.random(5)
