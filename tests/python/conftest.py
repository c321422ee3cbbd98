"""Shared fixtures of the Python package's tests: the `kdm` command to compare with, test images, a tiny
recipe. ctest runs them with PYTHONPATH=<build>/python and KDM_CLI=<build>/tools/kdm."""
import os
import signal
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

import kdm

SOURCE_DIR = Path(__file__).resolve().parents[2]
SPHERE = SOURCE_DIR / "examples" / "sphere.png"
# Two levels of 32 and 128 points per tile and a short glide track: bakes in a few seconds
# (tests/generator/bake_test.cpp's small recipe, with keyframes).
TINY_RECIPE = "colours 2\nlevels 2\nbase_points 32\nsweeps 10\nkeyframes 2\nglide_sweeps 2\n"


def interrupted(name, call, after):
    """Runs call() with an alarm after `after` seconds whose handler raises KeyboardInterrupt (as Ctrl-C's
    does), and returns how the extension function `name` ended: ["c_exception"] when the signal stopped it
    inside its call, ["c_return"] when it returned first. The call must raise KeyboardInterrupt."""
    events = []

    def profile(frame, event, arg):
        if event in ("c_return", "c_exception") and getattr(arg, "__name__", "") == name:
            events.append(event)

    def interrupt(signum, frame):
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGALRM, interrupt)
    signal.setitimer(signal.ITIMER_REAL, after)
    sys.setprofile(profile)
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
    finally:
        sys.setprofile(None)
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    return events


@pytest.fixture(scope="session")
def cli():
    """Runs the kdm command line: cli("sample", "--n", "64", ...) returns its stderr."""
    path = os.environ.get("KDM_CLI")
    if not path or not os.access(path, os.X_OK):
        pytest.skip("KDM_CLI does not name the kdm command (ctest sets it)")

    def run(*args):
        done = subprocess.run([path, *map(str, args)], capture_output=True, text=True)
        if done.returncode != 0:
            raise AssertionError(f"kdm {' '.join(map(str, args))} failed: {done.stderr}")
        return done.stderr

    return run


def read_txt(path):
    """The points of a .txt point file (UTK format, '#' comments) as an (n, d) float64 array."""
    rows = [line.split() for line in Path(path).read_text().splitlines() if line and not line.startswith("#")]
    return np.array(rows, dtype=np.float64)


def read_query_csv(path):
    """kdm query's .csv: x, y, tile_x, tile_y, rank, level (and depth) per point."""
    lines = Path(path).read_text().splitlines()
    assert lines[0] == "x,y,tile_x,tile_y,rank,level,depth"
    cols = list(zip(*(line.split(",") for line in lines[1:]))) if len(lines) > 1 else [()] * 7
    xy = np.array([cols[0], cols[1]], dtype=np.float64).T.reshape(-1, 2)
    tile = np.array([cols[2], cols[3]], dtype=np.int64).T.reshape(-1, 2)
    return xy, tile, np.array(cols[4], dtype=np.uint32), np.array(cols[5], dtype=np.uint32)


def write_png(path, grey):
    """An 8-bit greyscale PNG of `grey` (rows of values in [0, 255], row 0 at the top)."""
    grey = np.asarray(grey, dtype=np.uint8)
    raw = b"".join(b"\x00" + row.tobytes() for row in grey)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", grey.shape[1], grey.shape[0], 8, 0, 0, 0, 0)
    body = chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
    Path(path).write_bytes(b"\x89PNG\r\n\x1a\n" + body)


def write_hdr(path, grey):
    """A Radiance .hdr picture of `grey` (rows of values > 0, row 0 at the top) in flat RGBE scanlines: each
    value as an 8-bit mantissa (exact for values of 8 significant bits) and a shared exponent."""
    grey = np.asarray(grey, dtype=np.float64)
    mantissa, exponent = np.frexp(grey)
    rgbe = np.stack([(mantissa * 256).astype(np.uint8)] * 3 + [(exponent + 128).astype(np.uint8)], axis=-1)
    header = f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {grey.shape[0]} +X {grey.shape[1]}\n".encode()
    Path(path).write_bytes(header + rgbe.tobytes())


@pytest.fixture(scope="session")
def gradient_png(tmp_path_factory):
    """A 60 x 40 picture, dark at the top left and light at the bottom right, with some texture: not
    square and not symmetric, so a flipped or transposed reading shows."""
    y, x = np.mgrid[0:40, 0:60]
    grey = np.clip(40 + 2.5 * x + 1.5 * y + 20 * np.sin(x * y / 7.0), 0, 255)
    path = tmp_path_factory.mktemp("images") / "gradient.png"
    write_png(path, grey)
    return path


@pytest.fixture(scope="session")
def tiny_tileset():
    return kdm.bake(TINY_RECIPE, threads=0)
