"""kdm.stipple and kdm.analyze: what `kdm stipple` draws and what `kdm analyze` measures."""
import json
import pickle
import re
import warnings

import numpy as np
import pytest

import kdm
from conftest import SPHERE, interrupted, read_txt, write_hdr, write_png


def test_stipple_writes_what_kdm_stipple_writes(cli, tmp_path):
    cli("stipple", SPHERE, "--points", 6000, "--region", "0.2,0.1,0.8,0.7", "-o", tmp_path / "cli.txt")
    dots = kdm.stipple(str(SPHERE), points=6000, region=(0.2, 0.1, 0.8, 0.7), output=tmp_path / "py.txt")
    assert (tmp_path / "py.txt").read_bytes() == (tmp_path / "cli.txt").read_bytes()
    assert np.array_equal(dots, read_txt(tmp_path / "cli.txt"))
    cli("stipple", SPHERE, "--method", "full", "--points", 1500, "--seed", 4, "-o", tmp_path / "full.txt")
    full = kdm.stipple(SPHERE, method="full", points=1500, seed=4, threads=1)
    assert np.array_equal(full, read_txt(tmp_path / "full.txt"))
    # An SVG for print, as --paper-width sizes it.
    cli("stipple", SPHERE, "--points", 2000, "--paper-width", "7.5in", "-o", tmp_path / "cli.svg")
    kdm.stipple(str(SPHERE), points=2000, paper_width="7.5in", output=tmp_path / "py.svg")
    assert (tmp_path / "py.svg").read_bytes() == (tmp_path / "cli.svg").read_bytes()
    # The picture's 1024 x 1024 pixels within a dot's margin, printed 7.5 in wide.
    svg = (tmp_path / "py.svg").read_text()
    assert 'width="7.5in" height="7.5in" viewBox="-' in svg
    x0, y0, w, h = (float(v) for v in svg.split('viewBox="')[1].split('"')[0].split())
    assert x0 == y0 and 0 < -x0 < 10 and w + 2 * x0 == pytest.approx(1024) and h + 2 * x0 == pytest.approx(1024)
    # A picture sized by its height, as --height sizes it.
    cli("stipple", SPHERE, "--points", 2000, "--height", 300, "--region", "0,0,1,0.5", "-o", tmp_path / "cli.png")
    kdm.stipple(str(SPHERE), points=2000, height=300, region=(0, 0, 1, 0.5), output=tmp_path / "py.png")
    assert (tmp_path / "py.png").read_bytes() == (tmp_path / "cli.png").read_bytes()


def test_stipple_ids_name_the_dots_in_every_region(cli, tmp_path):
    # The ids of kdm stipple's .csv, the same dots; a zoomed region keeps every stable dot by id, in place.
    dots, ids = kdm.stipple(str(SPHERE), points=3000, mode="stable", ids=True)
    assert ids.dtype == np.uint64 and ids.shape == (len(dots),) and len(np.unique(ids)) == len(ids)
    cli("stipple", SPHERE, "--points", 3000, "--mode", "stable", "-o", tmp_path / "s.csv")
    rows = np.loadtxt(tmp_path / "s.csv", delimiter=",", skiprows=1, dtype=np.float64)
    assert np.array_equal(rows[:, :2], dots)
    assert np.array_equal(np.loadtxt(tmp_path / "s.csv", delimiter=",", skiprows=1, usecols=2, dtype=np.uint64), ids)
    zoomed, zoomed_ids = kdm.stipple(str(SPHERE), points=3000, mode="stable", region=(0.25, 0.25, 0.75, 0.75), ids=True)
    where = dict(zip(zoomed_ids.tolist(), 0.25 + 0.5 * zoomed))
    inside = np.all((dots > 0.25) & (dots < 0.75), axis=1)
    assert inside.sum() > 500
    for dot, key in zip(dots[inside], ids[inside].tolist()):
        assert np.allclose(where[key], dot, atol=1e-6)
    dots, classes, inks, ids = kdm.stipple(str(SPHERE), points=2000, colours="cmyk", ids=True)
    assert len(ids) == len(dots) == len(classes)
    assert isinstance(kdm.stipple(str(SPHERE), points=2000), np.ndarray)  # without ids, as before
    with pytest.raises(ValueError, match="ids name the tiles' dots"):
        kdm.stipple(str(SPHERE), points=200, method="full", ids=True)


def test_zoom_regions_are_the_frames_of_kdm_stipple(cli, tmp_path):
    cli("stipple", SPHERE, "--points", 3000, "--region", "0.55,0.3,0.6,0.34", "--frames", 4,
        "-o", tmp_path / "z.txt")
    regions = kdm.zoom_regions((0.55, 0.3, 0.6, 0.34), 4)
    assert regions.shape == (4, 4) and np.allclose(regions[-1], (0.55, 0.3, 0.6, 0.34), rtol=0, atol=1e-15)
    for i, r in enumerate(regions):
        frame = tmp_path / f"z_{i:04d}.txt"
        header = [line for line in frame.read_text().splitlines() if line.startswith("# region")][0]
        assert np.array_equal([float(v) for v in header.split()[2].split(",")], r)  # printed exactly
        assert np.array_equal(kdm.stipple(str(SPHERE), points=3000, region=r), read_txt(frame))
    assert np.all(np.diff(regions[:, 2] - regions[:, 0]) < 0)  # each frame narrower: a zoom
    with pytest.raises(ValueError, match="region must lie in"):
        kdm.zoom_regions((0.5, 0.5, 1.5, 0.9), 10)
    with pytest.raises(ValueError, match="frames"):
        kdm.zoom_regions((0.1, 0.1, 0.2, 0.2), 1)


def test_stipple_fade_draws_what_kdm_stipple_draws(cli, tmp_path):
    # The same SVG as the command line's, about 1/6 of its dots partly grown at fade=0.2 (measured 0.17;
    # tests/cli has the full rule), and the same dots returned as without fade, to float precision.
    cli("stipple", SPHERE, "--points", 4000, "--fade", 0.2, "-o", tmp_path / "cli.svg")
    dots = kdm.stipple(SPHERE, points=4000, fade=0.2, output=tmp_path / "py.svg")
    assert (tmp_path / "py.svg").read_bytes() == (tmp_path / "cli.svg").read_bytes()
    radii = np.array([float(part.split('"')[1]) for part in (tmp_path / "py.svg").read_text().split(" r=")[1:]])
    partial = np.mean(radii < radii.max() * (1 - 1e-5))
    assert 0.1 < partial < 0.25
    plain = kdm.stipple(SPHERE, points=4000)
    assert dots.shape == plain.shape and np.abs(np.sort(dots, axis=0) - np.sort(plain, axis=0)).max() < 1e-5
    with pytest.raises(ValueError, match="fade"):
        kdm.stipple(SPHERE, points=4000, fade=-0.1)
    with pytest.raises(ValueError, match="method='tiles'"):
        kdm.stipple(SPHERE, points=400, fade=0.2, method="full")


def test_stipple_to_png_and_svg(tmp_path, gradient_png):
    dots = kdm.stipple(str(gradient_png), points=3000, output=tmp_path / "s.png", width=300)
    assert dots.shape[1] == 2 and 2000 < len(dots) < 4000  # about the dots asked for
    assert dots.min() >= 0 and dots.max() < 1
    picture = kdm._kdm.load_luminance(str(tmp_path / "s.png"))
    assert picture.shape == (200, 300)  # the image's 3:2 aspect
    assert 0.05 < 1 - picture.mean() < 0.9  # dots drawn, not a blank or black page
    # Dark at the top left of the picture (row 0 at the top): more ink there than at the bottom right.
    assert picture[:100, :150].mean() < picture[100:, 150:].mean()
    kdm.stipple(gradient_png, points=3000, output=str(tmp_path / "s.svg"), width=300, dot_size=1.5)
    svg = (tmp_path / "s.svg").read_text()
    assert svg.startswith("<svg") and svg.count("<circle") == len(dots) and 'r="1.5"' in svg


def test_stipple_an_array_as_the_picture():
    luminance = kdm._kdm.load_luminance(str(SPHERE))
    from_file = kdm.stipple(str(SPHERE), points=4000, gamma=1.3)
    assert np.array_equal(kdm.stipple(luminance, points=4000, gamma=1.3), from_file)
    assert np.array_equal(kdm.stipple(luminance.tolist(), points=4000, gamma=1.3), from_file)
    # Dots land on dark pixels, or with invert on light ones. (The picture's mean luminance is 0.83; under
    # the dots it is 0.32, and 0.93 inverted: deterministic for one seed.)
    def under(dots):
        h, w = luminance.shape
        rows = np.clip(((1 - dots[:, 1]) * h).astype(int), 0, h - 1)
        return luminance[rows, np.clip((dots[:, 0] * w).astype(int), 0, w - 1)].mean()
    assert under(from_file) < 0.5 < 0.85 < under(kdm.stipple(luminance, points=4000, invert=True))


def test_stipple_reads_a_npy_path_as_the_density_and_an_array_as_luminance(cli, tmp_path):
    # A .npy path is the density itself, as kdm stipple reads it (1 dense); an array is a picture's
    # luminance (1 white, no dots) unless invert=True, which makes its values the density: the .npy's dots.
    y, x = np.mgrid[0:90, 0:120]
    density = (x / 119.0) * (0.3 + 0.7 * y / 89.0)  # dense at the right
    np.save(tmp_path / "d.npy", density)
    from_path = kdm.stipple(tmp_path / "d.npy", points=3000)
    cli("stipple", tmp_path / "d.npy", "--points", 3000, "-o", tmp_path / "cli.txt")
    np.testing.assert_array_equal(from_path, read_txt(tmp_path / "cli.txt"))
    np.testing.assert_array_equal(kdm.stipple(density, points=3000, invert=True), from_path)
    # Measured: mean x 0.66 and 0.42 (deterministic; the density alone would give 2/3, its darkness 0.42).
    assert from_path[:, 0].mean() > 0.6 and kdm.stipple(density, points=3000)[:, 0].mean() < 0.45
    for given in (dict(invert=True), dict(gamma=2.0), dict(colours="cmyk")):
        with pytest.raises(ValueError, match="NumPy array of densities"):
            kdm.stipple(tmp_path / "d.npy", points=300, **given)
    said = " ".join(kdm.stipple.__doc__.split())
    assert "A path to a NumPy .npy file is read as ``kdm stipple`` reads one" in said
    assert "An array is a picture instead" in said and "with ``invert=True`` its values are the density" in said


def test_stipple_takes_arrays_as_an_image_file_is_read(tmp_path):
    # uint8 and uint16 luminance, RGB(A) and PIL images: the same dots as the file they came from.
    Image = pytest.importorskip("PIL.Image")
    coffee = SPHERE.parent / "coffee.png"
    rgb = np.asarray(Image.open(coffee))
    assert rgb.dtype == np.uint8 and rgb.shape[2] == 3
    expected = kdm.stipple(str(coffee), points=2000)
    np.testing.assert_array_equal(kdm.stipple(rgb, points=2000), expected)
    np.testing.assert_array_equal(kdm.stipple(Image.open(coffee), points=2000), expected)
    opaque = np.concatenate([rgb, np.full(rgb.shape[:2] + (1,), 255, np.uint8)], axis=2)
    np.testing.assert_array_equal(kdm.stipple(opaque, points=2000), expected)
    # Other PIL modes as their file is read: a palette's colours (not its indices as grey levels), CMYK.
    palette = Image.open(coffee).quantize(16)
    assert palette.mode == "P"
    palette.save(tmp_path / "palette.png")
    for colours in (None, 3):
        a, b = (kdm.stipple(im, points=2000, colours=colours) for im in (palette, str(tmp_path / "palette.png")))
        for x, y in zip(a, b) if colours else [(a, b)]:
            np.testing.assert_array_equal(x, y)
    cmyk = Image.open(coffee).convert("CMYK")
    np.testing.assert_array_equal(kdm.stipple(cmyk, points=2000), kdm.stipple(cmyk.convert("RGB"), points=2000))
    with pytest.raises(ValueError, match="mode 'F' has no set range"):
        kdm.stipple(Image.open(SPHERE).convert("F"), points=200)
    grey = np.asarray(Image.open(SPHERE))
    assert grey.ndim == 2
    np.testing.assert_array_equal(kdm.stipple(grey, points=2000), kdm.stipple(str(SPHERE), points=2000))
    # In colour too, and separate(): the same inks as the file's (with alpha: light on black paper).
    for colours in ("cmyk", "rgb", 4):
        from_file, from_array = kdm.stipple(str(coffee), colours=colours, points=2000), kdm.stipple(
            rgb, colours=colours, points=2000)
        for a, b in zip(from_file, from_array):
            np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(kdm.separate(rgb)[0], kdm.separate(str(coffee))[0])
    translucent = np.concatenate([rgb, np.full(rgb.shape[:2] + (1,), 128, np.uint8)], axis=2)
    Image.fromarray(translucent).save(tmp_path / "translucent.png")
    np.testing.assert_array_equal(kdm.stipple(translucent, colours="rgb", points=2000)[0],
                                  kdm.stipple(str(tmp_path / "translucent.png"), colours="rgb", points=2000)[0])
    np.testing.assert_array_equal(kdm.stipple(grey.astype(np.uint16) * 257, points=2000),
                                  kdm.stipple(grey, points=2000))  # 257 v / 65535 = v / 255, rounded alike


def test_stipple_takes_a_pil_images_transparent_colour_as_its_file_does(tmp_path):
    # Grey and RGB pictures with a transparent colour (a PNG's tRNS; Pillow's info["transparency"]): the
    # pixels of that colour are paper, as the file's are, on white and inverted on black, in colour too.
    Image = pytest.importorskip("PIL.Image")
    import struct
    import zlib

    def png(path, pixels, bits, colour_type, key):
        raw = b"".join(b"\x00" + row.astype(">u2" if bits == 16 else "u1").tobytes() for row in pixels)
        chunk = lambda kind, data: (struct.pack(">I", len(data)) + kind + data
                                    + struct.pack(">I", zlib.crc32(kind + data)))
        size = struct.pack(">IIBBBBB", pixels.shape[1], pixels.shape[0], bits, colour_type, 0, 0, 0)
        key = struct.pack(f">{len(key)}H", *key)  # tRNS: the transparent grey level or RGB, 16 bits each
        path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", size) + chunk(b"tRNS", key)
                         + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
        return path

    grey = np.asarray(Image.open(SPHERE))
    keyed = grey.copy()
    keyed[:, : grey.shape[1] // 2] = 0  # the left half black, the transparent colour: paper, no dots
    rgb = np.asarray(Image.open(SPHERE.parent / "coffee.png")).copy()
    rgb[:, : rgb.shape[1] // 2] = (0, 0, 0)
    files = [png(tmp_path / "grey.png", keyed, 8, 0, (0,)), png(tmp_path / "rgb.png", rgb, 8, 2, (0, 0, 0)),
             png(tmp_path / "grey16.png", keyed.astype(np.uint16) * 257, 16, 0, (0,))]
    for path in files:
        picture = Image.open(path)
        assert "transparency" in picture.info and picture.mode in ("L", "RGB", "I", "I;16"), picture.mode
        dots = kdm.stipple(picture, points=3000)
        np.testing.assert_array_equal(dots, kdm.stipple(str(path), points=3000))
        assert len(dots) > 2000 and (dots[:, 0] < 0.5).mean() < 0.01, path.name  # not the black half's
        np.testing.assert_array_equal(kdm.stipple(picture, points=3000, invert=True),
                                      kdm.stipple(str(path), points=3000, invert=True))
        for a, b in zip(kdm.stipple(picture, points=3000, colours="cmyk"),
                        kdm.stipple(str(path), points=3000, colours="cmyk")):
            np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(kdm.separate(picture)[0], kdm.separate(str(path))[0])
    # Mode "I" is read as 16-bit grey; an 8-bit picture converted to it (drawn near black) is warned of.
    eight = Image.open(SPHERE).convert("I")
    with pytest.warns(UserWarning, match=r"convert\('L'\)") as caught:
        kdm.stipple(eight, points=500)
    assert caught[0].filename == __file__
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        kdm.stipple(Image.fromarray(grey.astype(np.int32) * 257, mode="I"), points=500)


def test_stipple_takes_grey_and_alpha_as_a_file_of_them_is_read(tmp_path):
    # (rows, columns, 2): grey and alpha, composited on white paper as an LA picture file is read; and
    # (rows, columns, 1) is grey alone.
    Image = pytest.importorskip("PIL.Image")
    grey = np.asarray(Image.open(SPHERE))
    alpha = np.tile(np.linspace(0, 255, grey.shape[1]).astype(np.uint8), (grey.shape[0], 1))
    la = np.stack([grey, alpha], axis=2)
    Image.fromarray(la, "LA").save(tmp_path / "la.png")
    from_file = kdm.stipple(str(tmp_path / "la.png"), points=2000)
    np.testing.assert_array_equal(kdm.stipple(la, points=2000), from_file)
    np.testing.assert_array_equal(kdm.stipple(la / 255.0, points=2000), kdm.stipple(la, points=2000))
    assert not np.array_equal(from_file, kdm.stipple(grey, points=2000))  # the alpha counts
    for a, b in zip(kdm.stipple(la, points=2000, colours="cmyk"),
                    kdm.stipple(str(tmp_path / "la.png"), points=2000, colours="cmyk")):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(kdm.stipple(grey[..., None], points=2000), kdm.stipple(grey, points=2000))


def test_stipple_inverts_an_array_with_alpha_as_kdm_stipple_inverts_its_file(cli, tmp_path):
    # Inverted, transparent is black paper: an RGBA or grey-and-alpha array gives the dots `kdm stipple
    # --invert` gives for its file, bit for bit (not its clear parts, laid on white, as bright dots).
    Image = pytest.importorskip("PIL.Image")
    rgb = np.asarray(Image.open(SPHERE.parent / "coffee.png"))
    grey = np.asarray(Image.open(SPHERE))
    ramp = lambda a: np.tile(np.linspace(0, 255, a.shape[1]).astype(np.uint8), (a.shape[0], 1))
    for name, pixels in (("rgba.png", np.dstack([rgb, ramp(rgb)])), ("la.png", np.dstack([grey, ramp(grey)]))):
        Image.fromarray(pixels).save(tmp_path / name)
        cli("stipple", tmp_path / name, "--points", 3000, "--invert", "--gamma", 1.5, "-o", tmp_path / "cli.txt")
        dots = kdm.stipple(pixels, points=3000, invert=True, gamma=1.5)
        np.testing.assert_array_equal(dots, read_txt(tmp_path / "cli.txt"))
        assert not np.array_equal(dots, kdm.stipple(pixels[..., :-1], points=3000, invert=True, gamma=1.5))
    # Black at part opacity has no light to draw, at any opacity.
    black = np.zeros((64, 64, 4), np.uint8)
    black[..., 3] = 64
    assert kdm.stipple(black, points=4000, invert=True).shape == (0, 2)


def test_stipple_writes_the_formats_kdm_stipple_writes_and_names_them(cli, tmp_path):
    import os
    import subprocess
    for ext in ("png", "svg", "txt", "csv"):
        kdm.stipple(str(SPHERE), points=300, output=tmp_path / f"dots.{ext}")
        assert (tmp_path / f"dots.{ext}").stat().st_size > 0
    # Anything else, .npy too (the dots come back as an array), is refused in the command line's words,
    # before any dot is placed.
    for ext in ("npy", "gif"):
        done = subprocess.run([os.environ["KDM_CLI"], "stipple", str(SPHERE), "-o", str(tmp_path / f"x.{ext}")],
                              capture_output=True, text=True)
        said = done.stderr.strip().removeprefix("kdm: error: ")
        assert done.returncode != 0 and said.endswith("(use .png, .svg, .txt or .csv)"), said
        with pytest.raises(ValueError) as info:
            kdm.stipple(str(SPHERE), points=300, output=tmp_path / f"x.{ext}")
        assert str(info.value) == said
    assert not list(tmp_path.glob("x.*"))


def test_stipple_of_a_blank_image_has_no_dots(tmp_path):
    # As kdm stipple: an empty picture, not an error (a blank frame of an animation).
    assert kdm.stipple(np.ones((6, 9))).shape == (0, 2)
    assert kdm.stipple(np.zeros((6, 9)), invert=True, method="full").shape == (0, 2)
    white = tmp_path / "white.png"
    write_png(white, np.full((6, 9), 255))
    dots, classes, inks = kdm.stipple(str(white), colours="cmyk", output=tmp_path / "w.svg")
    assert dots.shape == (0, 2) and classes.shape == (0,) and inks == []
    assert "<circle" not in (tmp_path / "w.svg").read_text()
    kdm.stipple(np.ones((6, 9)), output=tmp_path / "w.png", width=90)
    Image = pytest.importorskip("PIL.Image")
    assert np.asarray(Image.open(tmp_path / "w.png")).min() == 255


@pytest.mark.filterwarnings("ignore:.*coarsest level holds")  # the tiny set's, tested below
def test_stipple_scale_region_mode_and_tileset(tiny_tileset, tmp_path):
    whole = kdm.stipple(str(SPHERE), scale=8000)
    part = kdm.stipple(str(SPHERE), scale=8000, region=(0.25, 0.25, 0.75, 0.75))
    # Zooming 2x into the middle shows 4x its dots at the same dot size (measured: 4.00x; deterministic).
    inside = ((whole >= 0.25) & (whole < 0.75)).all(axis=1).sum()
    assert 3.8 * inside < len(part) < 4.2 * inside
    stable = kdm.stipple(str(SPHERE), points=3000, mode="stable")
    assert not np.array_equal(stable, kdm.stipple(str(SPHERE), points=3000))
    own = kdm.stipple(str(SPHERE), points=3000, tileset=tiny_tileset)
    assert len(own) > 1000 and not np.array_equal(own, kdm.stipple(str(SPHERE), points=3000))
    tiny_tileset.save(tmp_path / "tiny.kdmt")  # a file, as kdm stipple --tileset takes
    np.testing.assert_array_equal(kdm.stipple(str(SPHERE), points=3000, tileset=tmp_path / "tiny.kdmt"), own)
    # scale counts dots at full darkness for both methods: the sphere's mean darkness is 0.17, and the
    # runtime's count is within 0.3% of scale times it (deterministic).
    full = kdm.stipple(str(SPHERE), scale=8000, method="full")
    assert abs(len(full) - len(whole)) < 0.01 * len(whole) and len(full) < 0.2 * 8000
    with pytest.raises(ValueError, match="places no dot"):
        kdm.stipple(str(SPHERE), scale=1e-9, method="full")
    with pytest.raises(ValueError, match="more than the full sampler's 2\\^31"):
        kdm.stipple(str(SPHERE), scale=1e300, method="full")


def test_stipple_warns_where_a_tile_set_serves_light_tones_unevenly(tiny_tileset):
    # As kdm stipple warns: a set of 2 levels (1:4) places a ramp's light tones under its coarsest level;
    # the built-in set (1:1024) serves them and says nothing.
    ramp = np.tile(np.linspace(0, 1, 64), (32, 1))
    with pytest.warns(UserWarning, match=r"coarsest level holds \(32\), and come out clumpy") as said:
        dots = kdm.stipple(ramp, tileset=tiny_tileset)
    assert len(said) == 1 and "a tile set of more levels" in str(said[0].message)
    assert "gamma below 1" in str(said[0].message) and said[0].filename == __file__
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(kdm.stipple(ramp)) > 1000
    assert len(dots) > 1000


def test_analyze_gives_metrics_json(cli, tmp_path):
    points = kdm.sample(4096, seed=2)
    np.savetxt(tmp_path / "p.txt", points, fmt="%.17g")
    cli("analyze", tmp_path / "p.txt", "--tile-size", 0.25, "-o", tmp_path / "out")
    expected = json.loads((tmp_path / "out" / "metrics.json").read_text())
    got = kdm.analyze(points, tile_size=0.25)
    assert set(got) == set(expected)
    for key in set(expected) - {"inputs", "seconds"}:
        assert json.dumps(_lists(got[key]), sort_keys=True) == json.dumps(expected[key], sort_keys=True), key
    assert isinstance(got["spectrum"]["raps"], np.ndarray)
    assert isinstance(got["pair_correlation"]["g"], np.ndarray)
    assert got["inputs"] == ["points"] and got["domain"] == "torus" and got["energy_per_point"] > 0


def test_analyze_gives_the_periodogram_its_spectrum_measures_come_from():
    # P(k) = |Σ exp(-2πi k·x)|² / n at integer k, row ky + ky_max and column kx + kx_max, as computed here;
    # the mean over several sets; none for a 3-D set, which gets no spectrum.
    sets = [kdm.sample(1024, seed=s) for s in (1, 2)]
    one = kdm.analyze(sets[0], periodogram=True)["spectrum"]["periodogram"]
    both = kdm.analyze(sets, periodogram=True)["spectrum"]["periodogram"]
    assert "periodogram" not in kdm.analyze(sets[0])["spectrum"]  # metrics.json's keys unless asked
    ky_max, kx_max = (one.shape[0] - 1) // 2, (one.shape[1] - 1) // 2
    assert one.shape == (2 * ky_max + 1, 2 * kx_max + 1) and kx_max >= 40
    def direct(p, kx, ky):
        return abs(np.exp(-2j * np.pi * (p @ np.array([kx, ky]))).sum()) ** 2 / len(p)
    for kx, ky in ((0, 1), (3, -2), (-17, 5), (30, 20)):
        assert one[ky + ky_max, kx + kx_max] == pytest.approx(direct(sets[0], kx, ky), rel=1e-9, abs=1e-9)
        mean = (direct(sets[0], kx, ky) + direct(sets[1], kx, ky)) / 2
        assert both[ky + ky_max, kx + kx_max] == pytest.approx(mean, rel=1e-9, abs=1e-9)
    assert np.isnan(one[0, 0])  # a corner outside the disc computed
    assert "spectrum" not in kdm.analyze(kdm.sample(300, dim=3, seed=1), periodogram=True)


def test_analyze_classes_and_options_as_the_command_line(cli, tmp_path, gradient_png):
    # Labelled points: each class alone and the closest pair of different classes, classes.json's numbers;
    # and the density test's options, metrics.json's.
    points, labels = kdm.sample(3000, seed=5, classes=[1, 2, 4], threads=1)
    path = tmp_path / "c.csv"
    np.savetxt(path, np.column_stack([points, labels]), fmt=["%.17g", "%.17g", "%d"], delimiter=",",
               header="x,y,class", comments="")
    cli("analyze", path, "--no-energy", "--density", gradient_png, "--min-expected", 40, "--density-bands", 4,
        "--holes-min-density", 0.2, "-o", tmp_path / "out")
    expected = json.loads((tmp_path / "out" / "classes.json").read_text())
    metrics = json.loads((tmp_path / "out" / "metrics.json").read_text())
    got = kdm.analyze(points, classes=labels, energy=False, density=str(gradient_png), min_expected=40,
                      density_bands=4, holes_min_density=0.2)
    assert [c["class"] for c in got["classes"]["classes"]] == [0, 1, 2]
    assert got["classes"]["cross_class_closest"] == expected["cross_class_closest"]
    for mine, theirs in zip(got["classes"]["classes"], expected["classes"]):
        for key in ("nearest_neighbour", "spectrum", "empty_circles"):
            assert json.dumps(_lists(mine["metrics"][key]), sort_keys=True) == json.dumps(
                theirs["metrics"][key], sort_keys=True), key
    for key in ("density", "empty_circles"):
        assert json.dumps(_lists(got[key]), sort_keys=True) == json.dumps(metrics[key], sort_keys=True), key
    unpacked = kdm.analyze(*kdm.sample(3000, seed=5, classes=[1, 2, 4], threads=1), energy=False)
    plain = kdm.analyze(points, classes=labels, energy=False)["classes"]["cross_class_closest"]
    assert unpacked["classes"]["cross_class_closest"] == plain  # sample's tuple, unpacked
    assert plain != got["classes"]["cross_class_closest"]  # with a density: in local spacings
    lone = labels.copy()
    lone[0] = 7  # one point of its class: listed, not analysed
    too_small = kdm.analyze(points, classes=lone, energy=False)["classes"]["too_small"]
    assert too_small.tolist() == [7] and too_small.dtype.kind == "i"  # labels, not measures
    with pytest.raises(ValueError, match="one array of labels per set"):
        kdm.analyze([points, points], classes=[labels])
    with pytest.raises(ValueError, match="must hold one label per point"):
        kdm.analyze(points, classes=labels[:-1])
    # Labels are integers: a float array is a TypeError, whole numbers too (said how to convert them).
    with pytest.raises(TypeError, match=r"classes must be an \(n,\) array of integer labels 0 to 255, got dtype "
                                        r"float64$"):
        kdm.analyze(points, labels + 0.5)
    with pytest.raises(TypeError, match=r"got dtype float64 \(whole numbers as floats: convert them with "
                                        r"\.astype\(int\)\)$"):
        kdm.analyze(points, labels.astype(np.float64))
    with pytest.raises(TypeError, match=r"classes\[1\] must be .* got dtype bool$"):
        kdm.analyze([points, points], [labels, labels > 0])
    with pytest.raises(ValueError, match=r"integer labels 0 to 255, got -1 to 1$"):
        kdm.analyze(points, labels.astype(np.int64) - 1)
    with pytest.raises(ValueError, match=r"integer labels 0 to 255, got shape \(1, \d+\)$"):
        kdm.analyze(points, labels[None])
    with pytest.raises(ValueError, match="density_bands must be <= 1000"):
        kdm.analyze(points, density_bands=1001)


def test_analyze_class_densities_as_the_command_line(cli, tmp_path):
    # Each class against its own density, the whole set against their sum, and the counts against the
    # densities' shares: what kdm analyze --class-density writes to classes.json.
    points, labels = kdm.sample(2000, seed=3, classes=[1, "ramp:20"], threads=1)
    path = tmp_path / "c.csv"
    np.savetxt(path, np.column_stack([points, labels]), fmt=["%.17g", "%.17g", "%d"], delimiter=",",
               header="x,y,class", comments="")
    cli("analyze", path, "--no-energy", "--class-density", "const:1", "--class-density", "ramp:20",
        "-o", tmp_path / "out")
    expected = json.loads((tmp_path / "out" / "classes.json").read_text())
    metrics = json.loads((tmp_path / "out" / "metrics.json").read_text())
    got = kdm.analyze(points, labels, class_densities=[1, "ramp:20"], energy=False)
    assert json.dumps(_lists(got["density"]), sort_keys=True) == json.dumps(metrics["density"], sort_keys=True)
    assert got["classes"]["cross_class_closest"] == expected["cross_class_closest"]
    assert [s["class"] for s in got["classes"]["shares"]] == [0, 1]
    assert json.dumps(got["classes"]["shares"], sort_keys=True) == json.dumps(expected["shares"], sort_keys=True)
    for mine, theirs in zip(got["classes"]["classes"], expected["classes"]):
        for key in ("density", "empty_circles"):
            assert json.dumps(_lists(mine["metrics"][key]), sort_keys=True) == json.dumps(
                theirs["metrics"][key], sort_keys=True), key
    # Seeds 1..6 (the command line's test): class 1's RMS z 0.24-0.42 against its ramp, 4.3-4.4 against
    # one uniform density for every class; the sampler's counts are its shares to the rounding (|z| < 0.1).
    ramp_class = got["classes"]["classes"][1]["metrics"]["density"]["rms_z"]
    uniform = kdm.analyze(points, labels, density=1, energy=False)["classes"]["classes"][1]
    assert ramp_class < 0.7 < 2.5 < uniform["metrics"]["density"]["rms_z"]
    assert all(abs(s["z"]) < 0.5 for s in got["classes"]["shares"])
    assert "shares" not in kdm.analyze(points, labels, energy=False)["classes"]

    # Any form density= takes; callables too. A scale the sampler did not have shows in the shares alone.
    few, few_labels = kdm.sample(1000, seed=1, classes=[1, 3], threads=1)
    for densities in ([1, 3], [lambda x, y: 1.0, lambda x, y: 3.0], [np.ones((2, 2)), "const:3"]):
        shares = kdm.analyze(few, few_labels, class_densities=densities, energy=False)["classes"]["shares"]
        assert [s["count"] for s in shares] == [250, 750] and all(abs(s["z"]) < 0.5 for s in shares), densities
    wrong = kdm.analyze(few, few_labels, class_densities=[1, 1], energy=False)["classes"]
    assert wrong["shares"][0]["z"] < -10  # 250 points where 500 are expected, sd 15.8
    assert wrong["classes"][1]["metrics"]["density"]["rms_z"] < 0.7  # the shape is right

    with pytest.raises(ValueError, match=r"holds 1 density, but the classes run 0 to 1 \(2 classes\)"):
        kdm.analyze(few, few_labels, class_densities=[1])
    with pytest.raises(ValueError, match=r"holds 3 densities, but the classes run 0 to 1 \(2 classes\)"):
        kdm.analyze(few, few_labels, class_densities=[1, 2, 3])
    with pytest.raises(ValueError, match="class_densities needs classes"):
        kdm.analyze(few, class_densities=[1, 3])
    with pytest.raises(ValueError, match="class 0's density is zero everywhere, but the class has 250 points"):
        kdm.analyze(few, few_labels, class_densities=[0, 3])
    with pytest.raises(TypeError, match="class_densities must be a list"):
        kdm.analyze(few, few_labels, class_densities="const:1")
    with pytest.raises(TypeError, match=r"class_densities\[1\] must be"):
        kdm.analyze(few, few_labels, class_densities=[1, None])
    with pytest.raises(ValueError, match=r"class_densities\[1\] callable returned -1 at \(.*\): a density must be "
                                         "finite and >= 0"):
        kdm.analyze(few, few_labels, class_densities=[1, lambda x, y: -1.0], energy=False)


def _lists(value):
    """The dict back with its arrays as lists, NaN as null, as metrics.json holds them."""
    if isinstance(value, dict):
        return {k: _lists(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return [None if np.isnan(v) else int(v) if float(v).is_integer() else float(v) for v in value]
    if isinstance(value, list):
        return [_lists(v) for v in value]
    return value


def test_analyze_options_and_several_sets(gradient_png):
    sets = [kdm.sample(2000, str(gradient_png), seed=s) for s in (1, 2)]
    m = kdm.analyze(sets, box=True, density=str(gradient_png), energy=False, threads=1)
    assert m["sets"] == 2 and m["domain"] == "box" and "energy_per_point" not in m
    assert m["inputs"] == ["points[0]", "points[1]"] and len(m["dmin_per_set"]) == 2
    # The sampler follows its density: the accuracy test's z-scores stay small. (Over seeds 1..10 at
    # n = 2000, one set each, rms z was 0.18 to 0.26 against this density and 2.30 to 2.37 against a
    # uniform one; 1.0 and 1.5 sit between with room on both sides.)
    assert m["density"]["rms_z"] < 1.0
    wrong = kdm.analyze(sets[0], box=True, density=np.ones((2, 2)), energy=False)
    assert wrong["density"]["rms_z"] > 1.5
    assert kdm.analyze(kdm.sample(1000, dim=3), energy=False)["dim"] == 3
    # A density of the other dimension is refused, as kdm analyze --density refuses it (a volume was read
    # as its middle slice).
    with pytest.raises(ValueError, match="density is a 3-D volume, and the points are 2-D"):
        kdm.analyze(sets[0], density=np.ones((2, 3, 4)), energy=False)
    # Blue noise against random points: δmin far apart. (Seeds 1..10 at n = 2000: 0.53 to 0.70 for kdm,
    # 0.008 to 0.026 for uniform random points.)
    rng = np.random.default_rng(0)
    assert kdm.analyze(rng.random((2000, 2)), energy=False)["nearest_neighbour"]["dmin"] < 0.2
    assert kdm.analyze(kdm.sample(2000), energy=False)["nearest_neighbour"]["dmin"] > 0.4


def test_analyze_takes_a_function_as_the_density(gradient_png):
    def ramp(x, y):
        return 0.05 + x

    points = kdm.sample(3000, ramp, seed=2, threads=1)
    # The same function the set was drawn for: small z-scores; a uniform target: large ones. (Seeds 1..6:
    # rms z 0.22 to 0.28 against the ramp, 2.55 against uniform, measured; 1.0 and 1.5 sit between.)
    m = kdm.analyze(points, box=True, density=ramp, threads=2)
    assert m["density"]["rms_z"] < 1.0 and m["energy_per_point"] > 0
    assert kdm.analyze(points, box=True, density=1.0, energy=False)["density"]["rms_z"] > 1.5
    # Its failures are raised as kdm.sample raises them.
    with pytest.raises(ZeroDivisionError):
        kdm.analyze(points, density=lambda x, y: 1 / 0, energy=False)
    with pytest.raises(ValueError, match="density callable returned nan"):
        kdm.analyze(points, density=lambda x, y: float("nan"), energy=False)
    with pytest.raises(TypeError, match=r"density: the density is called as f\(x, y\), with 2 coordinates"):
        kdm.analyze(points, density=lambda x: 1.0, energy=False)
    with pytest.raises(ValueError, match="gamma and invert apply to image files only"):
        kdm.analyze(points, density=ramp, invert=True)
    # The bands and the holes' density floor need a density: without one they would do nothing.
    for option in (dict(holes_min_density=0.5), dict(density_bands=5)):
        with pytest.raises(ValueError, match=f"{next(iter(option))} applies with a density"):
            kdm.analyze(points, energy=False, **option)
    floor = kdm.analyze(points, box=True, density=ramp, holes_min_density=0.5, density_bands=5, energy=False)
    assert len(floor["density"]["bands"]) == 5
    kdm.analyze(points, energy=False, min_expected=50)  # also the uniformity check's windows: taken alone


def test_stipple_never_writes_over_its_image(tmp_path):
    image = tmp_path / "sphere.png"
    image.write_bytes(open(SPHERE, "rb").read())
    with pytest.raises(ValueError, match="is the input image"):
        kdm.stipple(str(image), points=500, output=str(image))
    assert image.read_bytes() == open(SPHERE, "rb").read()


def test_analyze_pools_sets_of_any_size_but_their_spectrum_only_of_one():
    a, b = kdm.sample(1024, seed=3, threads=1), kdm.sample(100, seed=4, threads=1)
    m = kdm.analyze([a, b], energy=False, threads=1)
    assert "100 to 1024 points" in m["spectrum_skipped"] and "spectrum" not in m
    assert m["points_min"] == 100 and m["points_max"] == 1024 and len(m["dmin_per_set"]) == 2
    # The other measures pool the sets: both sets' triangles, as analysing them one by one finds.
    one = [kdm.analyze(s, energy=False, threads=1)["empty_circles"]["triangles"] for s in (a, b)]
    assert m["empty_circles"]["triangles"] == sum(one) == 2 * (1024 + 100)  # a torus: 2n each
    assert "spectrum" in kdm.analyze([a, kdm.sample(1000, seed=5, threads=1)], energy=False, threads=1)


def test_analyze_skips_the_2d_diagnostics_of_3d_points():
    # A density still sets the energy, as kdm analyze's does: a test map and the same function agree,
    # and differ from the uniform density's; an image (2D) is refused.
    p = kdm.sample(1000, dim=3, density="ramp:100", seed=1, threads=1)
    plain = kdm.analyze(p, threads=1)
    with pytest.warns(UserWarning, match="2D only; skipped"):
        given = kdm.analyze(p, density="ramp:100", tile_size=0.5, threads=1)
    assert "tiling" not in given and "density" not in given
    assert given["spectrum_skipped"].startswith("2D only") and "spectrum" not in given
    assert given["empty_circles_skipped"].startswith("2D only")
    with pytest.warns(UserWarning, match="2D only"):
        function = kdm.analyze(p, density=lambda x, y, z: 100.0 ** -x, threads=1)
    assert given["energy_per_point"] == pytest.approx(function["energy_per_point"], rel=1e-6)
    assert given["energy_per_point"] < 0.5 * plain["energy_per_point"]  # measured: 1.6 against 15.9
    with pytest.warns(UserWarning, match="2D only"), pytest.raises(
            ValueError, match="density is a 2-D image, and the points are 3-D: give a 3-D array"):
        kdm.analyze(p, density=np.array([[1.0, 0.01]]), threads=1)


@pytest.mark.parametrize("method", ["tiles", "full"])
def test_each_inks_tone_follows_its_separation(method):
    # 100,000 dots of the coffee picture: each ink's windowed density z-scores against its own channel, RMS
    # at most 0.5. Measured (seeds 1-3, 90,000-110,000 dots): tiles 0.36 / 0.43-0.44 / 0.44-0.45, full
    # 0.27-0.29 / 0.35-0.48 / 0.39-0.48 for black, magenta, yellow; with the inks in order of decreasing
    # coverage black was 0.60 (tiles) and 0.65 (full).
    coffee = SPHERE.parent / "coffee.png"
    channels, inks = kdm.separate(coffee)
    assert channels.shape == (4, 200, 300) and channels.dtype == np.float32
    assert inks == ["black", "magenta", "yellow", "cyan"]  # least coverage first; cyan, under a tenth, last
    dots, classes, names = kdm.stipple(str(coffee), points=100000, colours="cmyk", method=method, seed=1)
    assert names == inks
    for k in range(3):
        mine = dots[classes == k]
        assert len(mine) > 20000
        z = kdm.analyze(mine, box=True, density=channels[k], energy=False, fmax=0.2)["density"]["rms_z"]
        assert z <= 0.5, (method, inks[k], z)
    with pytest.raises(ValueError, match="cmyk, rgb"):
        kdm.separate(coffee, colours="cmy")
    with pytest.raises(OSError):
        kdm.separate(SPHERE.parent / "missing.png")


def test_stipple_in_colour_as_kdm_stipple_does(cli, tmp_path):
    # The same dots and inks as `kdm stipple --colours cmyk`, each ink a class, all of them the dots asked.
    coffee = SPHERE.parent / "coffee.png"
    cli("stipple", coffee, "--colours", "cmyk", "--points", 5000, "-o", tmp_path / "cli.csv")
    dots, classes, inks = kdm.stipple(str(coffee), points=5000, colours="cmyk", output=tmp_path / "py.svg")
    rows = np.loadtxt(tmp_path / "cli.csv", delimiter=",", skiprows=1)
    assert np.array_equal(rows[:, :2], dots) and np.array_equal(rows[:, 2], classes)
    assert classes.dtype == np.uint8 and len(inks) == 4 and set(inks) == {"cyan", "magenta", "yellow", "black"}
    assert '<g id="%s"' % inks[0] in (tmp_path / "py.svg").read_text()
    # Each ink is its name with its colour, the one the command line prints beside the name, and the
    # one its SVG layer draws in; it pickles as itself.
    printed = cli("stipple", coffee, "--colours", 3, "--points", 2000, "-o", tmp_path / "three.svg")
    _, _, three = kdm.stipple(str(coffee), points=2000, colours=3, output=tmp_path / "py3.svg")
    assert [type(ink) for ink in three] == [kdm.Ink] * len(three) and len(three) >= 2
    for k, ink in enumerate(three):
        assert f"{k} {ink} {ink.colour}" in printed and re.fullmatch("#[0-9a-f]{6}", ink.colour)
        layer = (tmp_path / "py3.svg").read_text().split('<g id="%s"' % ink)[1].split("</g>")[0]
        assert f'fill="{ink.colour}"' in layer
    again = pickle.loads(pickle.dumps(three))
    assert again == three and [i.colour for i in again] == [i.colour for i in three]
    _, separated = kdm.separate(str(coffee), colours="cmyk")
    assert {ink: ink.colour for ink in separated}["black"] == "#000000"
    # A grey picture: black holds every dot, but the SVG keeps a layer for each of the scheme's pens.
    _, grey_classes, grey_inks = kdm.stipple(str(SPHERE), points=2000, colours="cmyk", output=tmp_path / "g.svg")
    assert grey_inks == ["black"] and not grey_classes.any()
    assert all('<g id="%s"' % ink in (tmp_path / "g.svg").read_text() for ink in ("cyan", "magenta", "yellow"))
    full = kdm.stipple(str(coffee), points=2000, colours=3, method="full", threads=1)
    assert len(full[0]) == 2000 and set(np.unique(full[1])) <= {0, 1, 2}
    with pytest.raises(ValueError, match="cmyk, rgb"):
        kdm.stipple(str(coffee), colours="cmy")
    with pytest.raises(ValueError, match="invert"):
        kdm.stipple(str(coffee), colours="rgb", invert=True)
    dots, classes, inks = kdm.stipple(np.ones((4, 4)) * 0.5, colours="cmyk", points=200)  # grey: black ink
    assert len(dots) > 150 and set(classes) == {0} and inks == ["black"]


def test_stipple_writes_the_header_kdm_stipple_writes_in_colour(cli, tmp_path):
    # The same SVG as `kdm stipple --colours`, its first comment naming the inks; a blank image's too.
    coffee = str(SPHERE.parent / "coffee.png")
    white = tmp_path / "white.png"
    write_png(white, np.full((6, 9), 255))
    for image, colours, said in ((coffee, "cmyk", "inks cmyk"), (coffee, "3", "inks 3 of 3"),
                                 (coffee, "#ff0000,#000000,#00ff00", "of 3 given"), (str(white), "cmyk", "no ink")):
        cli("stipple", image, "--colours", colours, "--points", 2000, "-o", tmp_path / "cli.svg")
        kdm.stipple(image, colours=colours, points=2000, output=tmp_path / "py.svg")
        svg = (tmp_path / "py.svg").read_text()
        assert svg == (tmp_path / "cli.svg").read_text()
        assert said in svg.splitlines()[1], svg.splitlines()[1]
    cli("stipple", white, "--points", 2000, "-o", tmp_path / "cli.svg")
    kdm.stipple(white, points=2000, output=tmp_path / "py.svg")
    assert (tmp_path / "py.svg").read_text() == (tmp_path / "cli.svg").read_text()


def test_stipple_white_sets_an_hdr_pictures_white_as_kdm_stipple_does(cli, tmp_path):
    # A strip at 100 on a background of 0.5: by default the strip is white and the background 1/200 of it,
    # nearly black; with white=1 the background is half-tone and the strip, brighter, white.
    grey = np.full((16, 32), 0.5)
    grey[:, :2] = 100.0
    hdr = tmp_path / "strip.hdr"
    write_hdr(hdr, grey)
    black = 2000 * 32 / 16  # scale 2000: dots per unit area at full darkness, over a 2 x 1 image
    assert len(kdm.stipple(hdr, scale=2000)) == pytest.approx(black * 30 / 32, abs=0.05 * black)
    half = kdm.stipple(hdr, scale=2000, white=1, output=tmp_path / "py.txt")
    assert len(half) == pytest.approx(black * 0.5 * 30 / 32, abs=0.05 * black)
    assert half[:, 0].min() >= 1.5 / 32  # none on the strip (white up to its last pixel's centre)
    cli("stipple", hdr, "--scale", 2000, "--white", 1, "-o", tmp_path / "cli.txt")
    assert (tmp_path / "py.txt").read_bytes() == (tmp_path / "cli.txt").read_bytes()
    assert np.array_equal(half, read_txt(tmp_path / "cli.txt"))
    # In colour too (the colour loader), and the inks' separation.
    cli("stipple", hdr, "--scale", 2000, "--white", 1, "--colours", "cmyk", "-o", tmp_path / "cli.csv")
    dots, classes, _ = kdm.stipple(hdr, scale=2000, white=1, colours="cmyk")
    rows = np.loadtxt(tmp_path / "cli.csv", delimiter=",", skiprows=1)
    assert np.array_equal(rows[:, :2], dots) and np.array_equal(rows[:, 2], classes)
    assert len(dots) == pytest.approx(black * 0.5 * 30 / 32, abs=0.05 * black)
    channels, inks = kdm.separate(hdr, white=1)
    assert inks == ["black"] and np.allclose(channels[0, :, 2:], 0.5, atol=0.01) and not channels[0, :, :2].any()
    assert np.allclose(kdm.separate(hdr)[0][0, :, 2:], 0.995, atol=0.01)
    # Refused, as kdm stipple --white refuses them.
    for bad in (0, -1, float("nan"), float("inf")):
        with pytest.raises(ValueError, match=r"white must be a finite number > 0 \(the luminance that is white\)"):
            kdm.stipple(hdr, white=bad)
    for bad in ("1", True, [1.0]):
        with pytest.raises(TypeError, match="white must be a number"):
            kdm.stipple(hdr, white=bad)
    for call in (kdm.stipple, kdm.separate):
        with pytest.raises(ValueError, match=r"white sets the luminance that is white in a Radiance \.hdr picture, "
                                             r"and '.*sphere\.png' is none"):
            call(SPHERE, white=1)
        with pytest.raises(ValueError, match="white sets the luminance .* an array or PIL image is none"):
            call(np.full((4, 4, 3), 0.5), white=1)


def test_stipple_takes_pens_as_a_list(tmp_path):
    # A list or tuple of pens is the comma-separated str `kdm stipple --colours` takes, in stipple() and
    # separate(); a pen alone in a list is a pen, '#' or not.
    coffee = str(SPHERE.parent / "coffee.png")
    as_text = kdm.stipple(coffee, points=2000, colours="#ff0000,#000000")
    for pens in (["#ff0000", "#000000"], ("#ff0000", " 000000")):
        for a, b in zip(kdm.stipple(coffee, points=2000, colours=pens), as_text):
            np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(kdm.separate(coffee, colours=["#ff0000", "#000000"])[0],
                                  kdm.separate(coffee, colours="#ff0000,#000000")[0])
    assert kdm.stipple(coffee, points=500, colours=["000000"])[2] == ["ink-0-black"]


def test_stipple_refuses_what_kdm_stipple_refuses_before_placing_dots(tmp_path):
    # A white image in rgb is all light: dots, as the command line gives (no grey "no ink" refusal).
    white = tmp_path / "white.png"
    write_png(white, np.full((8, 8), 255))
    dots, classes, inks = kdm.stipple(str(white), points=500, colours="rgb")
    assert len(dots) > 400 and inks == ["red", "green", "blue"]
    coffee = str(SPHERE.parent / "coffee.png")
    with pytest.raises(ValueError, match="fade grows dots in pictures"):
        kdm.stipple(str(SPHERE), points=500, fade=0.2, output=tmp_path / "x.csv")
    for sized in ({"width": 300}, {"height": 300}, {"dot_size": 2.0}):  # were silently ignored
        with pytest.raises(ValueError, match=f"{next(iter(sized))} sizes pictures"):
            kdm.stipple(str(SPHERE), points=500, output=tmp_path / "x.csv", **sized)
    with pytest.raises(ValueError, match="colours writes each dot's ink as a class"):
        kdm.stipple(coffee, points=500, colours="cmyk", output=tmp_path / "x.txt")
    with pytest.raises(ValueError, match="pixels is too tall .*give height"):
        kdm.stipple(str(SPHERE), points=500, region=(0.499, 0, 0.5, 1), output=tmp_path / "x.png")
    with pytest.raises(ValueError, match="mode applies to method='tiles'"):
        kdm.stipple(str(SPHERE), points=500, method="full", mode="stable")
    with pytest.raises(ValueError, match="tileset applies to method='tiles'"):
        kdm.stipple(str(SPHERE), points=500, method="full", tileset=kdm.Tileset.builtin())
    with pytest.raises(ValueError, match="paper_width must be a number from 0.001 to 1000000 and a unit"):
        kdm.stipple(str(SPHERE), points=500, paper_width="7.5", output=tmp_path / "x.svg")
    with pytest.raises(ValueError, match="paper_width sizes an SVG"):
        kdm.stipple(str(SPHERE), points=500, paper_width="7.5in", output=tmp_path / "x.png")
    with pytest.raises(ValueError, match="paper_width must be a number and a unit"):
        kdm.stipple(str(SPHERE), points=500, paper_width="", output=tmp_path / "x.svg")
    with pytest.raises(ValueError, match="paper_width must be a number from 0.001"):
        kdm.stipple(str(SPHERE), points=500, paper_width="0x10mm", output=tmp_path / "x.svg")
    with pytest.raises(ValueError, match="give width or height, not both"):
        kdm.stipple(str(SPHERE), points=500, width=100, height=100, output=tmp_path / "x.png")
    with pytest.raises(TypeError, match="paper_width must be a str"):
        kdm.stipple(str(SPHERE), points=500, paper_width=7.5, output=tmp_path / "x.svg")
    assert not list(tmp_path.glob("x.*"))


def test_stipple_tiles_seed_picks_another_part_of_the_tiling():
    # One seed gives one set of dots; another seed other dots of the same tone: the image lies elsewhere in
    # the tile set's tiling. (Counts follow the image's ink up to edge tiles: 4,000 dots land within 1% of
    # each other over seeds 1-5, measured; 5% is the bound asserted.)
    one, again, other = (kdm.stipple(str(SPHERE), points=4000, seed=s) for s in (2, 2, 3))
    assert np.array_equal(one, again)
    assert not np.array_equal(one, other)
    assert abs(len(one) - len(other)) < 0.05 * len(one)
    luminance = kdm._kdm.load_luminance(str(SPHERE))
    h, w = luminance.shape
    for dots in (one, other):
        rows = np.clip(((1 - dots[:, 1]) * h).astype(int), 0, h - 1)
        assert luminance[rows, np.clip((dots[:, 0] * w).astype(int), 0, w - 1)].mean() < 0.5


def test_analyze_gives_nan_for_what_cannot_be_measured():
    # Four points have no frequency below f = 0.5 (lowP is NaN, null in metrics.json): a float, NaN, not
    # None, so arithmetic on the result works. A low fmax still measures lowP.
    few = kdm.analyze(np.random.default_rng(1).random((4, 2)), energy=False, threads=1)
    assert isinstance(few["spectrum"]["low_p"], float) and np.isnan(few["spectrum"]["low_p"])
    many = np.random.default_rng(2).random((1000, 2))
    low = kdm.analyze(many, energy=False, fmax=0.3, threads=1)["spectrum"]["low_p"]
    assert low == pytest.approx(kdm.analyze(many, energy=False, threads=1)["spectrum"]["low_p"], rel=1e-9)


def test_analyze_of_points_without_a_triangulation_keeps_the_other_measures():
    # Points on one line (a box) or all at one place have no Delaunay triangulation: the empty circles are
    # skipped, saying why, and the nearest neighbours, spectrum and g(r) are still measured. So for 2 points.
    line = np.c_[np.linspace(0.05, 0.95, 100), np.full(100, 0.5)]
    for points, box in ((line, True), (np.full((100, 2), 0.5), False)):
        result = kdm.analyze(points, box=box, energy=False, threads=1)
        assert "degenerate" in result["empty_circles_skipped"] and "empty_circles" not in result
        assert result["nearest_neighbour"]["count"] == 100 and "spectrum" in result
    two = kdm.analyze(np.array([[0.1, 0.2], [0.6, 0.7]]), energy=False, threads=1)
    assert "fewer than 3 points" in two["empty_circles_skipped"]


def test_analyze_pools_sets_given_as_nested_lists_too():
    rng = np.random.default_rng(8)
    a, b = rng.random((300, 2)), rng.random((300, 2))
    pooled = kdm.analyze([a, b.tolist()], energy=False, threads=1)
    assert pooled["sets"] == 2
    assert pooled["nearest_neighbour"]["davg"] == kdm.analyze([a, b], energy=False, threads=1)["nearest_neighbour"]["davg"]
    assert kdm.analyze(a.tolist(), energy=False, threads=1)["sets"] == 1  # a list of points is one set


def test_analyze_gives_inf_where_metrics_json_has_null_for_infinity():
    # A tile repeated 4 x 4 has no power off the tile lattice: the lattice power ratio is infinite (null in
    # metrics.json), not missing; with no lattice frequency in the spectrum (64 points reach |k| = 5, short
    # of the neighbours of (4, 0)) it is NaN.
    tile = np.random.default_rng(3).random((64, 2))
    tiled = np.concatenate([(tile + [i, j]) / 4 for i in range(4) for j in range(4)])
    tiling = kdm.analyze(tiled, tile_size=0.25, energy=False, threads=1)["tiling"]
    assert tiling["lattice_power_ratio"] == np.inf and tiling["lattice_power_frequencies"] == 24
    small = np.concatenate([(tile[:4] + [i, j]) / 4 for i in range(4) for j in range(4)])
    low = kdm.analyze(small, tile_size=0.25, fmax=0.1, energy=False, threads=1)["tiling"]
    assert np.isnan(low["lattice_power_ratio"])


def test_analyze_names_the_shape_and_the_set_it_cannot_take():
    rng = np.random.default_rng(4)
    with pytest.raises(ValueError, match=r"got shape \(2, 10\) \(transposed\? points.T has shape \(10, 2\)\)"):
        kdm.analyze(rng.random((2, 10)))
    with pytest.raises(ValueError, match=r"got shape \(10, 4\)$"):
        kdm.analyze(rng.random((10, 4)))
    for empty in (np.empty((0, 2)), []):
        with pytest.raises(ValueError, match=r"points\[1\] holds no points"):
            kdm.analyze([rng.random((10, 2)), empty])
    with pytest.raises(ValueError, match=r"points\[0\] holds 1 point"):
        kdm.analyze([rng.random((1, 2)), rng.random((10, 2))])
    points = rng.random((1000, 2))
    with pytest.warns(UserWarning, match="no density window expects min_expected=2000"):
        assert kdm.analyze(points, density=1.0, min_expected=2000, energy=False)["density"]["windows"] == 1


def test_a_signal_stops_a_full_stipple_inside_its_call():
    # The full sampler's stipple stops at its next sweep on Ctrl-C, as kdm.sample does (100,000 dots take
    # seconds; the alarm comes after 0.3 s).
    call = lambda: kdm.stipple(str(SPHERE), points=100_000, method="full", threads=1)  # noqa: E731
    assert interrupted("stipple", call, 0.3) == ["c_exception"]


def test_a_signal_stops_an_analysis_between_its_measures():
    # 150,000 points take seconds to measure; the alarm after 0.3 s stops the call at its next measure.
    points = np.random.default_rng(3).random((150_000, 2))
    call = lambda: kdm.analyze(points, energy=False, threads=1)  # noqa: E731
    assert interrupted("analyze", call, 0.3) == ["c_exception"]


def test_anisotropy_by_ring_finds_a_lattice_and_not_the_sampler():
    # A square lattice holds its peak ring's power on four of its some 400 frequencies (about 20 dB); the
    # full sampler's peak ring is isotropic, near 0 dB for one set (its sd there is about 1 dB).
    m = 64
    lattice = (np.stack(np.meshgrid(np.arange(m), np.arange(m)), -1).reshape(-1, 2) + 0.5) / m
    grid = kdm.analyze(lattice, energy=False, threads=1)["spectrum"]
    blue = kdm.analyze(kdm.sample(m * m, seed=3, threads=1), energy=False, threads=1)["spectrum"]
    for s in (grid, blue):
        assert isinstance(s["anisotropy_db_by_ring"], np.ndarray)
        assert len(s["anisotropy_db_by_ring"]) == len(s["raps_f"])
    assert grid["anisotropy_db_by_ring"][np.argmax(grid["raps"])] > 15
    assert abs(blue["anisotropy_db_by_ring"][np.argmax(blue["raps"])]) < 3


def test_stipple_reads_a_picture_past_the_density_limit_at_the_size_its_dots_need(cli, tmp_path):
    # 8,400 x 8,200 pixels, more than the 2^26 a density may have: a stipple averages it down as it reads
    # it (here to 2^24 pixels, about 4,140 x 4,050), so only the decoder holds every pixel.
    grey = np.full((8200, 8400), 255, np.uint8)
    grey[:, :4200] = 0  # the left half black
    big = tmp_path / "big.png"
    write_png(big, grey)
    dots = kdm.stipple(str(big), points=4000, mode="stable")
    # Measured: 3,974-4,005 dots over seeds 1-3; stable mode between levels keeps counts within a few percent.
    assert abs(len(dots) - 4000) < 120
    # Every dot on the black half, but for the kept pixels (1/4,140 wide) the edge shares with the white.
    assert dots[:, 0].max() < 0.5 + 2 / 4140 and dots[:, 0].min() >= 0
    cli("stipple", big, "--points", 4000, "--mode", "stable", "-o", tmp_path / "cli.txt")
    assert np.array_equal(read_txt(tmp_path / "cli.txt"), dots)
    with pytest.raises(OSError, match="more than the limit of 67108864 pixels"):
        kdm.sample(100, density=str(big))


def test_an_image_array_past_the_size_limit_is_refused_before_it_is_converted():
    # 8,193 x 8,193 pixels, past the 2^26 an array may have: refused from its shape, before the float
    # copies a conversion makes (over a gigabyte for this one). A broadcast scalar holds no pixels itself.
    import tracemalloc

    grey = np.broadcast_to(np.uint8(0), (8193, 8193))
    calls = [lambda: kdm.stipple(grey), lambda: kdm.stipple(grey[..., None], colours="cmyk"),
             lambda: kdm.stipple(np.broadcast_to(0.5, (8193, 8193))),
             lambda: kdm.separate(np.broadcast_to(np.uint8(0), (8193, 8193, 3)))]
    for call in calls:
        tracemalloc.start()
        try:
            with pytest.raises(ValueError, match=r"^image array has more than 2\^26 pixels \(the image size limit"):
                call()
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        assert peak < 1 << 20, peak


def test_analyze_measures_a_set_in_the_domain_it_was_drawn_in(cli, tmp_path):
    # kdm.sample(aspect=2)'s set measured with aspect=2 reads as its square sets do (δavg spreads by about
    # 0.003 between seeds at 2,000 points); measured as a unit square it is squeezed. As kdm analyze does.
    wide = kdm.sample(2000, seed=4, aspect=2, threads=1)
    square = kdm.analyze(kdm.sample(2000, seed=4, threads=1), energy=False)
    got = kdm.analyze(wide, aspect=2, energy=False)
    assert got["sides"] == pytest.approx([2 ** 0.5, 2 ** -0.5], rel=1e-9)
    assert "sides" not in square
    assert got["nearest_neighbour"]["davg"] == pytest.approx(square["nearest_neighbour"]["davg"], abs=0.02)
    assert kdm.analyze(wide, energy=False)["nearest_neighbour"]["davg"] < square["nearest_neighbour"]["davg"] - 0.1
    assert json.dumps(_lists(kdm.analyze(wide, aspect=1.0, energy=False)["nearest_neighbour"])) == json.dumps(
        _lists(kdm.analyze(wide, energy=False)["nearest_neighbour"]))
    np.savetxt(tmp_path / "w.txt", wide, fmt="%.17g")
    cli("analyze", tmp_path / "w.txt", "--aspect", 2, "--no-energy", "-o", tmp_path / "out")
    expected = json.loads((tmp_path / "out" / "metrics.json").read_text())
    assert json.dumps(_lists(got["nearest_neighbour"])) == json.dumps(expected["nearest_neighbour"])
    assert json.dumps(_lists(got["spectrum"])) == json.dumps(expected["spectrum"])
    box = kdm.sample(1000, dim=3, seed=4, aspect=(2, 1, 0.5), threads=1)
    assert kdm.analyze(box, aspect=(2, 1, 0.5), energy=False)["sides"] == pytest.approx([2, 1, 0.5])


@pytest.mark.parametrize("aspect, error", [(0, ValueError), (-2, ValueError), (float("nan"), ValueError),
                                           ((2, 1, 1), ValueError), ("2", TypeError), ((1, 2), ValueError)])
def test_analyze_refuses_a_bad_aspect(aspect, error):
    with pytest.raises(error, match="aspect"):
        kdm.analyze(np.random.default_rng(1).random((50, 2)), aspect=aspect, energy=False)


def test_analyze_refuses_tiles_and_classes_in_a_rectangle():
    points = np.random.default_rng(2).random((200, 2))
    with pytest.raises(ValueError, match="square tiles"):
        kdm.analyze(points, aspect=2, tile_size=0.25, energy=False)
    with pytest.raises(ValueError, match="unit square only"):
        kdm.analyze(points, np.arange(200) % 2, aspect=2, energy=False)
