#!/usr/bin/python3
"""An independent reader of kdm tile sets (.kdmt, format versions 2 to 7).

Written from docs/tileset-format.md alone, not from the C++ sources: the test
runtime.independent_python_reader compares its --summary with the C++ runtime's decoding of the shipped
set, which shows the document is complete and exact. Needs the standard library and python3-zstandard
(Debian; scripts/deps installs it).

  tileset_reader.py FILE --summary     canonical summary: counts, texts, per-tile checksums
  tileset_reader.py FILE --points TILE one line "x y key level" per point of tile TILE, x and y as
                                       unit-square doubles (repr)

Every check the document asks of a reader is made; a failure exits with status 1 and one line
"tileset_reader.py: error: FILE: problem" on stderr.
"""
import argparse
import array
import bisect
import math
import struct
import sys
import zlib

try:
    import zstandard
except ImportError:  # the reader is useless without it: say what to install
    zstandard = None

FORMAT_VERSION = 7
OLDEST_FORMAT_VERSION = 2
MAX_KEYFRAMES = 256
GLIDE_UNITS_PER_SPACING = 32.0
MAGIC = b"KDMTILES"
FIXED_HEADER_BYTES = 64
HEADER_CRC_OFFSET = 60
MAX_HEADER_BYTES = 1 << 20  # kMaxTilesetHeaderBytes
MAX_BODY_BYTES = 512 << 20  # kMaxTilesetPayloadBytes, applies to the decompressed body
MAX_COLOURS = 16
MAX_LEVELS = 16


class TilesetError(Exception):
    """The file is not a valid tile set; the message names the first problem (doc §3 order)."""


class Tile:
    def __init__(self, level_end, xs, ys, keys, glide, handover=None, appearing=None):
        self.level_end = level_end  # list of L ints
        self.xs = xs  # array('H'), x of each point in 1/65536 of the tile side
        self.ys = ys
        self.keys = keys  # array('H'), emission key of each point
        self.glide = glide  # array('b'), gliding offsets (x, y pairs, Tileset.glide_unit), empty without keyframes
        self.thresholds = None  # each point's emission threshold, once Tileset.offsets_at_keyframe needs them
        self.handover = handover if handover is not None else array.array("H")  # doc §7, the hand-over
        self.appearing = appearing if appearing is not None else array.array(_uint32_typecode())

    def levels_of_points(self):
        """The level of every point: point i is in level k iff level_end[k-1] <= i < level_end[k]."""
        out, start = [], 0
        for k, end in enumerate(self.level_end):
            out.extend([k] * (end - start))
            start = end
        return out


class Tileset:
    def __init__(self):
        self.version = 0
        self.colours = 0
        self.levels = 0
        self.level_nominal = []
        self.keyframe_nominal = []
        self.handover_zone = 0
        self.handover_level = 0
        self.handover_slack = 0
        self.tiles = []
        self.recipe = b""
        self.generator_version = b""

    def threshold(self, level, key):
        """Doc §7: the float32 emission threshold, returned as the float32 value (widened to a double)."""
        lo = 0 if level == 0 else self.level_nominal[level - 1]
        hi = self.level_nominal[level]
        value = lo + (key + 0.5) * (1.0 / 65536.0) * (hi - lo)  # IEEE double, this order
        return struct.unpack("<f", struct.pack("<f", value))[0]

    def coarsest_level_thresholds(self):
        """Doc §7: every tile's level-0 thresholds as queries compare them, spread over the tiles."""
        pooled = []  # (threshold, tie, tile, rank): tie counts the tile's earlier ranks of equal threshold
        for t, tile in enumerate(self.tiles):
            for i in range(tile.level_end[0]):
                value = self.threshold(0, tile.keys[i])
                tie = pooled[-1][1] + 1 if i > 0 and pooled[-1][0] == value else 0
                pooled.append((value, tie, t, i))
        pooled.sort(key=lambda p: (p[0], p[1], p[2]))
        out = [[0.0] * tile.level_end[0] for tile in self.tiles]
        step = self.level_nominal[0] / len(pooled)  # IEEE double
        for i, (_, _, t, rank) in enumerate(pooled):
            out[t][rank] = struct.unpack("<f", struct.pack("<f", (i + 0.5) * step))[0]
        return out

    def emits(self, level, key, expected):
        """Doc §7: emitted iff the tile's expected point count exceeds the threshold."""
        return expected > self.threshold(level, key)

    def glide_unit(self, g):
        """Doc §7: keyframe g's glide offset unit in tile sides."""
        return 1.0 / (GLIDE_UNITS_PER_SPACING * math.sqrt(self.keyframe_nominal[g]))

    def offsets_at_keyframe(self, tile, g):
        """Doc §7: the points with a position at keyframe g, those emitted at the next keyframe's count
        (every point at the last keyframe)."""
        if g + 1 == len(self.keyframe_nominal):
            return len(tile.xs)
        # Thresholds never decrease along a tile (keys are sorted within a level, _validate, and each level's
        # thresholds lie above the last's): the points emitted are a prefix.
        if tile.thresholds is None:
            tile.thresholds = [self.threshold(k, q) for k, q in zip(tile.levels_of_points(), tile.keys)]
        return bisect.bisect_left(tile.thresholds, self.keyframe_nominal[g + 1])


def _u32(data, offset):
    return struct.unpack_from("<I", data, offset)[0]


def _u64(data, offset):
    return struct.unpack_from("<Q", data, offset)[0]


def _crc32(data):
    return zlib.crc32(data) & 0xFFFFFFFF


class _Body:
    """Doc §5: the decompressed body, read field by field in the byte order its first byte announces."""

    def __init__(self, body):
        self.body = body
        if len(body) < 1:
            raise TilesetError("body is empty: no endianness flag")
        flag = body[0]
        if flag not in (0, 1):
            raise TilesetError(f"body endianness flag is {flag}, not 1 (little-endian) or 0 (big-endian)")
        self.order = "<" if flag == 1 else ">"
        self.swap = (flag == 1) != (sys.byteorder == "little")  # array() reads native order
        self.pos = 1

    def remaining(self):
        return len(self.body) - self.pos

    def _take(self, size, what):
        if size > self.remaining():
            raise TilesetError(f"body ends inside {what}")
        chunk = self.body[self.pos : self.pos + size]
        self.pos += size
        return chunk

    def u32(self, what):
        return struct.unpack(self.order + "I", self._take(4, what))[0]

    def array(self, typecode, what):
        """A size tag (u64 element count) then that many raw elements."""
        n = struct.unpack(self.order + "Q", self._take(8, what + " size tag"))[0]
        size = array.array(typecode).itemsize
        if n > self.remaining() // size:
            raise TilesetError(f"{what} claims {n} elements, more than {self.remaining()} body bytes hold")
        values = array.array(typecode)
        values.frombytes(self._take(n * size, what))
        if self.swap:
            values.byteswap()
        return values


def _uint32_typecode():
    for code in ("I", "L"):
        if array.array(code).itemsize == 4:
            return code
    raise RuntimeError("no 4-byte unsigned array type on this platform")


U32 = _uint32_typecode()


def decode(data):
    """Decodes and validates a whole .kdmt file given as bytes; returns a Tileset or raises TilesetError."""
    size = len(data)
    # Doc §1 and §3, in order.
    if size < 8 or data[:8] != MAGIC:
        if size < 8 and MAGIC.startswith(data):
            raise TilesetError("truncated: file ends inside the magic number")
        raise TilesetError("bad magic: file does not start with KDMTILES")
    if size < 12:
        raise TilesetError("truncated: file ends inside the header")
    version = _u32(data, 8)
    if not OLDEST_FORMAT_VERSION <= version <= FORMAT_VERSION:
        raise TilesetError(
            f"unsupported format version {version} (this reader reads {OLDEST_FORMAT_VERSION} to {FORMAT_VERSION})"
        )
    if size < FIXED_HEADER_BYTES:
        raise TilesetError("truncated: file ends inside the header")
    header_size = _u32(data, 12)
    if not FIXED_HEADER_BYTES <= header_size <= MAX_HEADER_BYTES:
        raise TilesetError(f"header size {header_size} is outside {FIXED_HEADER_BYTES}..{MAX_HEADER_BYTES}")
    if size < header_size:
        if FIXED_HEADER_BYTES + _u32(data, 48) + _u32(data, 52) != header_size:
            raise TilesetError(f"header size {header_size} disagrees with its texts' sizes: a damaged header")
        raise TilesetError(f"truncated: file ends inside the {header_size}-byte header")
    # Doc §2: the CRC of the whole header with its own field read as zero.
    header = bytearray(data[:header_size])
    header[HEADER_CRC_OFFSET : HEADER_CRC_OFFSET + 4] = b"\0\0\0\0"
    stored, computed = _u32(data, HEADER_CRC_OFFSET), _crc32(header)
    if stored != computed:
        raise TilesetError(f"header CRC-32 mismatch: stored {stored:08x}, computed {computed:08x}")
    payload_size, body_size = _u64(data, 16), _u64(data, 24)
    payload_crc, tile_count = _u32(data, 32), _u32(data, 36)
    colours, levels = _u32(data, 40), _u32(data, 44)
    recipe_size, version_size = _u32(data, 48), _u32(data, 52)
    if FIXED_HEADER_BYTES + recipe_size + version_size != header_size:
        raise TilesetError(
            f"header text sizes {recipe_size} + {version_size} + 64 differ from the header size {header_size}"
        )
    if header_size + payload_size > size:
        raise TilesetError(f"truncated: file ends inside the {payload_size}-byte payload")
    if header_size + payload_size < size:
        raise TilesetError(f"trailing bytes: {size - header_size - payload_size} bytes follow the payload")
    if body_size > MAX_BODY_BYTES:
        raise TilesetError(f"too large: body of {body_size} bytes exceeds the cap of {MAX_BODY_BYTES}")
    if not 1 <= colours <= MAX_COLOURS:
        raise TilesetError(f"colour count {colours} is outside 1..{MAX_COLOURS}")
    if not 1 <= levels <= MAX_LEVELS:
        raise TilesetError(f"level count {levels} is outside 1..{MAX_LEVELS}")
    if tile_count != colours**4:
        raise TilesetError(f"header tile count {tile_count} is not colours^4 = {colours ** 4}")
    payload = data[header_size:]
    computed = _crc32(payload)
    if computed != payload_crc:
        raise TilesetError(f"payload CRC-32 mismatch: stored {payload_crc:08x}, computed {computed:08x}")

    # Doc §4: exactly one zstd frame that states its content size, which must be the body size.
    if zstandard is None:
        raise TilesetError("cannot decompress: module zstandard missing (apt-get install python3-zstandard)")
    try:
        frame_size = zstandard.get_frame_parameters(payload).content_size
    except zstandard.ZstdError as e:
        raise TilesetError(f"payload is not a zstd frame: {e}") from None
    if frame_size == zstandard.CONTENTSIZE_UNKNOWN:
        raise TilesetError("payload zstd frame does not state its content size")
    if frame_size != body_size:
        raise TilesetError(f"payload zstd frame holds {frame_size} bytes, the header says {body_size}")
    try:
        body = zstandard.ZstdDecompressor().decompress(
            payload, max_output_size=body_size, allow_extra_data=False
        )
    except zstandard.ZstdError as e:
        raise TilesetError(f"payload does not decompress: {e}") from None
    if len(body) != body_size:
        raise TilesetError(f"payload decompresses to {len(body)} bytes, the header says {body_size}")

    # Doc §5.
    reader = _Body(body)
    ts = Tileset()
    ts.version = version
    ts.colours = reader.u32("colours")
    ts.levels = reader.u32("levels")
    body_tiles = reader.u32("tile count")
    if ts.colours != colours or ts.levels != levels:
        raise TilesetError(
            f"body says {ts.colours} colours and {ts.levels} levels, the header {colours} and {levels}"
        )
    if body_tiles != tile_count:
        raise TilesetError(f"body says {body_tiles} tiles, the header {tile_count}")
    ts.level_nominal = list(reader.array(U32, "level_nominal"))
    gliding, handing_over = version >= 3, version >= 5
    if gliding:
        ts.keyframe_nominal = list(reader.array(U32, "keyframe_nominal"))
    if handing_over:
        ts.handover_zone = reader.u32("handover_zone")
    if version >= 6:
        ts.handover_level = reader.u32("handover_level")
    if version >= 7:
        ts.handover_slack = reader.u32("handover_slack")
    if body_tiles > reader.remaining() // (48 if handing_over else 32 if gliding else 24):
        raise TilesetError(f"tile count {body_tiles} exceeds what {reader.remaining()} body bytes can hold")
    for t in range(body_tiles):
        level_end = list(reader.array(U32, f"tile {t} level_end"))
        xy = reader.array("H", f"tile {t} xy")
        if len(xy) % 2:
            raise TilesetError(f"tile {t} has an odd number of coordinates ({len(xy)})")
        keys = reader.array("H", f"tile {t} keys")
        glide = reader.array("H" if version == 3 else "B", f"tile {t} glide") if gliding else array.array("b")
        handover = reader.array("H", f"tile {t} handover") if handing_over else None
        appearing = reader.array(U32, f"tile {t} appearing") if handing_over else None
        ts.tiles.append(Tile(level_end, xy[0::2], xy[1::2], keys, glide, handover, appearing))
    if reader.remaining():
        raise TilesetError(f"body has {reader.remaining()} bytes after the last tile")

    _validate(ts)
    for tile in ts.tiles:
        if version == 3:
            tile.glide = _glide_from_format3(ts, tile, _glide_sums(ts, tile, tile.glide, 0xFFFF))
        elif version >= 4:
            sums = _glide_sums(ts, tile, tile.glide, 0xFF)
            tile.glide = array.array("b", [v - 256 if v >= 128 else v for v in sums])
    ts.recipe = bytes(data[FIXED_HEADER_BYTES : FIXED_HEADER_BYTES + recipe_size])
    ts.generator_version = bytes(data[FIXED_HEADER_BYTES + recipe_size : header_size])
    return ts


def _validate(ts):
    """Doc §6: the structural invariants."""
    if len(ts.level_nominal) != ts.levels:
        raise TilesetError(f"level_nominal has {len(ts.level_nominal)} entries for {ts.levels} levels")
    previous = 0
    for k, n in enumerate(ts.level_nominal):
        if n <= previous:
            raise TilesetError(f"level_nominal is not strictly increasing and positive at level {k} ({n})")
        previous = n
    if len(ts.tiles) != ts.colours**4:
        raise TilesetError(f"expected {ts.colours ** 4} tiles, found {len(ts.tiles)}")
    for t, tile in enumerate(ts.tiles):
        if len(tile.level_end) != ts.levels:
            raise TilesetError(f"tile {t} has {len(tile.level_end)} level_end entries for {ts.levels} levels")
        for k in range(1, ts.levels):
            if tile.level_end[k] < tile.level_end[k - 1]:
                raise TilesetError(f"tile {t} has a decreasing level_end at level {k}")
        if tile.level_end[-1] != len(tile.xs):
            raise TilesetError(f"tile {t}'s level_end ends at {tile.level_end[-1]}, not at its point count")
        if len(tile.keys) != len(tile.xs):
            raise TilesetError(f"tile {t} has {len(tile.keys)} keys for {len(tile.xs)} points")
        start = 0
        for k, end in enumerate(tile.level_end):
            keys = tile.keys[start:end]
            if any(a > b for a, b in zip(keys, keys[1:])):
                raise TilesetError(f"tile {t} has unsorted keys in level {k}")
            start = end
    if all(len(tile.xs) == 0 for tile in ts.tiles):
        raise TilesetError("its tiles hold no points")
    for k, nominal in enumerate(ts.level_nominal):
        for t, tile in enumerate(ts.tiles):
            if tile.level_end[k] > 4 * nominal + 64:
                raise TilesetError(f"tile {t} holds {tile.level_end[k]} points in levels 0..{k}, more than 4 "
                                   f"times their nominal {nominal} (+64)")
    if len(ts.keyframe_nominal) > MAX_KEYFRAMES:
        raise TilesetError(f"{len(ts.keyframe_nominal)} keyframes, more than {MAX_KEYFRAMES}")
    previous = 0
    for n in ts.keyframe_nominal:
        if n <= previous:
            raise TilesetError("keyframe counts are not strictly increasing")
        previous = n
    if ts.keyframe_nominal and ts.keyframe_nominal[-1] != ts.level_nominal[-1]:
        raise TilesetError("the last keyframe is not the top level's count")
    for t, tile in enumerate(ts.tiles):
        needed = 2 * sum(ts.offsets_at_keyframe(tile, g) for g in range(len(ts.keyframe_nominal)))
        if len(tile.glide) != needed:
            raise TilesetError(f"tile {t} has {len(tile.glide)} glide offsets, its keyframes need {needed}")
    _validate_handover(ts)


def _mix64(z):
    """Doc §7: SplitMix64's finaliser."""
    mask = (1 << 64) - 1
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & mask
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & mask
    return z ^ (z >> 31)


def subvertex_colour(ts, m, sw, se, ne, nw, i, j):
    """Doc §7, the hand-over: the colour of sub-vertex (i, j) of the tile with corners (sw, se, ne, nw)."""
    z, C, mask = ts.handover_zone, ts.colours, (1 << 64) - 1
    near_x, near_y = i <= z or i >= m - z, j <= z or j >= m - z
    di, dj = (i if 2 * i <= m else i - m), (j if 2 * j <= m else j - m)
    east, north = 2 * i > m, 2 * j > m
    if near_x and near_y:
        kind, key, a, b = 0, (ne if east else nw) if north else (se if east else sw), di, dj
    elif near_y:
        kind, key, a, b = 1, (nw * C + ne) if north else (sw * C + se), i, dj
    elif near_x:
        kind, key, a, b = 2, (se * C + ne) if east else (sw * C + nw), di, j
    else:
        kind, key, a, b = 3, ((sw * C + se) * C + ne) * C + nw, i, j
    h = _mix64(0x53554254494C45 ^ kind)
    h = _mix64(h ^ key)
    h = _mix64(h ^ ((a + 0x8000) & mask))
    return _mix64(h ^ ((b + 0x8000) & mask)) % C


def handover_keyframe(ts):
    """Doc §7: h, S keyframes past the first above N_j (j the hand-over level, S its slack; at least 1)."""
    return max(1, bisect.bisect_right(ts.keyframe_nominal, ts.level_nominal[ts.handover_level])) + ts.handover_slack


def _validate_handover(ts):
    """Doc §6, invariant 9."""
    if ts.handover_zone == 0:
        if ts.handover_level:
            raise TilesetError("a hand-over level in a set without a hand-over")
        if ts.handover_slack:
            raise TilesetError("a hand-over slack in a set without a hand-over")
        for t, tile in enumerate(ts.tiles):
            if len(tile.handover) or len(tile.appearing):
                raise TilesetError(f"tile {t} has hand-over tables in a set without a hand-over")
        return
    C, z, level = ts.colours, ts.handover_zone, ts.handover_level
    if len(ts.keyframe_nominal) < 2:
        raise TilesetError("a hand-over needs a glide track of at least two keyframes")
    if level + 1 >= ts.levels:
        raise TilesetError(f"the hand-over level {level} is not below the top level")
    m = round(math.sqrt(ts.level_nominal[-1] / ts.level_nominal[level]))
    if m * m * ts.level_nominal[level] != ts.level_nominal[-1] or not 2 <= m <= 256:
        raise TilesetError("a hand-over needs N_top / N_j to be the square of an integer m in 2..256")
    if 2 * z + 1 >= m:
        raise TilesetError(f"the hand-over zone {z} is too wide")
    if ts.handover_slack > 16:
        raise TilesetError(f"the hand-over slack {ts.handover_slack} is above 16")
    h = handover_keyframe(ts)
    if h + 1 >= len(ts.keyframe_nominal):
        raise TilesetError("the hand-over keyframe is the top one")
    present = []
    for tile in ts.tiles:
        ts.offsets_at_keyframe(tile, 0)  # fills tile.thresholds
        present.append(bisect.bisect_left(tile.thresholds, ts.keyframe_nominal[h]))
    for t, tile in enumerate(ts.tiles):
        sw, se, ne, nw = t // C**3, t // C**2 % C, t // C % C, t % C
        colour = {}
        for j in range(m + 1):
            for i in range(m + 1):
                colour[i, j] = subvertex_colour(ts, m, sw, se, ne, nw, i, j)
        first, types = [0], []
        for j in range(m * m):
            i, k = j % m, j // m
            types.append(((colour[i, k] * C + colour[i + 1, k]) * C + colour[i + 1, k + 1]) * C + colour[i, k + 1])
            first.append(first[-1] + present[types[-1]])
        if len(tile.handover) != len(tile.xs):
            raise TilesetError(f"tile {t} has {len(tile.handover)} hand-over targets for {len(tile.xs)} points")
        taken = bytearray(first[-1])

        def take(j, q):
            if q >= present[types[j]]:
                raise TilesetError(f"tile {t} names rank {q} of subtile {j}, which has {present[types[j]]} at keyframe {h}")
            if taken[first[j] + q]:
                raise TilesetError(f"tile {t} takes a sub-point twice")
            taken[first[j] + q] = 1

        for x, y, v in zip(tile.xs, tile.ys, tile.handover):
            i, k = ((x * m) >> 16) + v % 25 % 5 - 2, ((y * m) >> 16) + v % 25 // 5 - 2
            if not (0 <= i < m and 0 <= k < m):
                raise TilesetError(f"tile {t} sends a point to a subtile outside it")
            take(k * m + i, v // 25)
        for w in tile.appearing:
            if w >> 16 >= m * m:
                raise TilesetError(f"tile {t} has an appearing sub-point outside its subtiles")
            take(w >> 16, w & 0xFFFF)
        if len(tile.handover) + len(tile.appearing) != first[-1]:
            raise TilesetError(f"tile {t} leaves some of its subtiles' points out of the hand-over")


def _round_half_away(v):
    """C's round(): the nearest integer, halves away from zero (the subtraction below is exact)."""
    whole = math.floor(abs(v))
    if abs(v) - whole >= 0.5:
        whole += 1
    return whole if v >= 0 else -whole


def _glide_sums(ts, tile, stored, mask):
    """Doc §7: an offset with one at the keyframe before is stored as the difference (mod 2^8, format 3:
    mod 2^16); returns the offsets as unsigned values."""
    values = list(stored)
    at, before = 0, 0
    for g in range(len(ts.keyframe_nominal)):
        n = 2 * ts.offsets_at_keyframe(tile, g)
        for i in range(min(before, n)):
            values[at + i] = (values[at + i] + values[at - before + i]) & mask
        at, before = at + n, n
    return values


def _glide_from_format3(ts, tile, offsets):
    """Doc §7: format 3's 16-bit offsets (in 1/65536 tile sides) into 8-bit units of glide_unit, rounded
    half away from zero and clamped to +-127."""
    out = array.array("b", bytes(len(offsets)))
    at = 0
    for g in range(len(ts.keyframe_nominal)):
        n = 2 * ts.offsets_at_keyframe(tile, g)
        units = 1.0 / (65536.0 * ts.glide_unit(g))
        for i in range(at, at + n):
            v = offsets[i] - 65536 if offsets[i] >= 32768 else offsets[i]
            out[i] = max(-127, min(127, _round_half_away(v * units)))
        at += n
    return out


def load(path):
    with open(path, "rb") as f:
        return decode(f.read())


def _escaped(text):
    """Printable ASCII as is; other bytes and the backslash as \\xNN (one line whatever the bytes)."""
    return "".join(chr(b) if 0x20 <= b < 0x7F and b != 0x5C else f"\\x{b:02x}" for b in text)


def _le_bytes(values):
    """The little-endian bytes of an array, whatever the host's byte order."""
    if sys.byteorder != "little":
        values = array.array(values.typecode, values)
        values.byteswap()
    return values.tobytes()


def summary(ts):
    """The canonical summary; tests/runtime/tileset_summary.cpp prints the same from the C++ decoder."""
    lines = [
        f"format_version {ts.version}",
        f"colours {ts.colours}",
        f"levels {ts.levels}",
        f"tiles {len(ts.tiles)}",
        "level_nominal " + " ".join(str(n) for n in ts.level_nominal),
        "keyframe_nominal" + "".join(f" {n}" for n in ts.keyframe_nominal),
    ] + ([f"handover_zone {ts.handover_zone}"] if ts.handover_zone else []) + (
        [f"handover_level {ts.handover_level}"] if ts.handover_level else []
    ) + ([f"handover_slack {ts.handover_slack}"] if ts.handover_slack else []) + [
        f"recipe_bytes {len(ts.recipe)}",
        f"recipe_crc32 {_crc32(ts.recipe):08x}",
        f"generator_version {_escaped(ts.generator_version)}",
    ]
    coarsest = ts.coarsest_level_thresholds()
    for t, tile in enumerate(ts.tiles):
        # (x, y, key) as three little-endian u16 per point; each point's float32 threshold as its bits.
        triples = array.array("H", bytes(6 * len(tile.xs)))
        triples[0::3], triples[1::3], triples[2::3] = tile.xs, tile.ys, tile.keys
        levels = tile.levels_of_points()
        thresholds = array.array("f", coarsest[t] + [ts.threshold(k, q) for k, q in zip(levels, tile.keys)
                                                     if k > 0])
        lines.append(
            f"tile {t} points {len(tile.xs)} level_end {' '.join(str(e) for e in tile.level_end)}"
            f" points_crc32 {_crc32(_le_bytes(triples)):08x}"
            f" thresholds_crc32 {_crc32(_le_bytes(thresholds)):08x}"
            f" glide_crc32 {_crc32(_le_bytes(tile.glide)):08x}"
            + (
                f" handover_crc32 {_crc32(_le_bytes(tile.handover)):08x}"
                f" appearing_crc32 {_crc32(_le_bytes(tile.appearing)):08x}"
                if ts.handover_zone
                else ""
            )
        )
    return "".join(line + "\n" for line in lines)


def point_lines(ts, t):
    """Doc §7: one "x y key level" line per point, x and y at their grid cell's centre in the unit square."""
    tile = ts.tiles[t]
    return "".join(
        f"{(x + 0.5) / 65536.0!r} {(y + 0.5) / 65536.0!r} {q} {k}\n"
        for x, y, q, k in zip(tile.xs, tile.ys, tile.keys, tile.levels_of_points())
    )


def main(argv=None):
    parser = argparse.ArgumentParser(description="Reads and checks a kdm tile set (.kdmt, format versions 2 to 7).")
    parser.add_argument("file")
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--summary", action="store_true", help="print the canonical summary")
    mode.add_argument("--points", type=int, metavar="TILE", help="print a tile's points as 'x y key level'")
    args = parser.parse_args(argv)
    try:
        ts = load(args.file)
        if args.summary:
            sys.stdout.write(summary(ts))
        else:
            if not 0 <= args.points < len(ts.tiles):
                raise TilesetError(f"tile {args.points} does not exist (the set has {len(ts.tiles)} tiles)")
            sys.stdout.write(point_lines(ts, args.points))
    except (TilesetError, OSError) as e:
        print(f"tileset_reader.py: error: {args.file}: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
