#!/usr/bin/env python3
"""Writes the seed corpora of the query, image, recipe and point-file fuzzers (tests/fuzz/corpus/<name>/) and
the inputs that made a fuzzer fail (tests/fuzz/crashes/<name>/, see the README there). Run from
anywhere; the files are committed, this script says how they were made. The JPEG seed (image/tiny.jpg, 8x8,
by stb_image_write's stbi_write_jpg) and the tile-set seeds are not made here."""

import os
import struct
import zlib

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")


def write(folder, name, data, root=HERE):
    os.makedirs(os.path.join(root, folder), exist_ok=True)
    with open(os.path.join(root, folder, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


# ---- PNG: colour type 0 grey, 2 RGB, 3 palette, 4 grey+alpha, 6 RGBA; 8 or 16 bits.

def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def png(w, h, depth, colour, samples, extra=b"", interlace=0):
    """samples: rows of sample values (already per channel). Adam7 when interlace=1 (passes built here)."""
    channels = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[colour]

    def row_bytes(row):
        if depth == 16:
            return b"".join(struct.pack(">H", v) for v in row)
        if depth == 8:
            return bytes(row)
        per = 8 // depth  # packed low-depth samples, most significant first
        out = bytearray()
        for i in range(0, len(row), per):
            byte = 0
            for k, v in enumerate(row[i:i + per]):
                byte |= v << (8 - depth * (k + 1))
            out.append(byte)
        return bytes(out)

    raw = b""
    if interlace:
        passes = [(0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2)]
        for x0, y0, dx, dy in passes:
            for y in range(y0, h, dy):
                cols = list(range(x0, w, dx))
                if not cols:
                    continue
                row = [s for x in cols for s in samples[y][x * channels:(x + 1) * channels]]
                raw += b"\x00" + row_bytes(row)
    else:
        for r in samples:
            raw += b"\x01" + row_bytes(r)  # filter "sub" on every row: the unfilter path runs too
    ihdr = struct.pack(">IIBBBBB", w, h, depth, colour, 0, 0, interlace)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + extra + chunk(b"IDAT", zlib.compress(raw, 9)) +
            chunk(b"IEND", b""))


def images():
    write("image", "grey8.png", png(4, 4, 8, 0, [[16 * (x + 4 * y) for x in range(4)] for y in range(4)]))
    write("image", "grey16.png", png(3, 3, 16, 0, [[7000 * (x + 3 * y) for x in range(3)] for y in range(3)]))
    write("image", "grey1.png", png(8, 2, 1, 0, [[x & 1 for x in range(8)], [1 - (x & 1) for x in range(8)]]))
    write("image", "rgb8.png", png(3, 2, 8, 2, [[255, 0, 0, 0, 255, 0, 0, 0, 255], [9, 99, 199, 0, 0, 0, 255, 255, 255]]))
    write("image", "rgba16.png", png(2, 2, 16, 6, [[65535, 0, 0, 65535, 0, 65535, 0, 30000],
                                                    [0, 0, 65535, 0, 1000, 2000, 3000, 65535]]))
    write("image", "grey_alpha8.png", png(2, 2, 8, 4, [[0, 255, 128, 128], [255, 0, 64, 200]]))
    palette = chunk(b"PLTE", bytes([0, 0, 0, 255, 255, 255, 128, 64, 32])) + chunk(b"tRNS", bytes([255, 0]))
    write("image", "palette_trns.png", png(4, 2, 2, 3, [[0, 1, 2, 1], [2, 1, 0, 0]], extra=palette))
    write("image", "grey8_trns.png", png(2, 2, 8, 0, [[0, 50], [100, 150]], extra=chunk(b"tRNS", b"\x00\x32")))
    write("image", "interlaced.png", png(9, 9, 8, 0, [[(x * 28 + y * 3) % 256 for x in range(9)] for y in range(9)],
                                         interlace=1))
    # Other formats stb_image reads (kdm accepts whatever it reads): PGM, PPM, BMP, TGA.
    write("image", "grey.pgm", b"P5 3 2 255\n" + bytes([0, 60, 120, 180, 240, 255]))
    write("image", "deep.pgm", b"P5 2 1 65535\n" + struct.pack(">HH", 1000, 60000))
    write("image", "rgb.ppm", b"P6\n2 1\n255\n" + bytes([255, 0, 0, 0, 0, 255]))
    bmp_pixels = bytes([0, 0, 255, 0, 255, 0, 0, 0]) + bytes([255, 0, 0, 255, 255, 255, 0, 0])  # rows padded to 4
    bmp = (b"BM" + struct.pack("<IHHI", 14 + 40 + len(bmp_pixels), 0, 0, 54) +
           struct.pack("<IiiHHIIiiII", 40, 2, 2, 1, 24, 0, len(bmp_pixels), 2835, 2835, 0, 0) + bmp_pixels)
    write("image", "rgb.bmp", bmp)
    tga = struct.pack("<BBBHHBHHHHBB", 0, 0, 3, 0, 0, 0, 0, 0, 2, 2, 8, 0) + bytes([0, 85, 170, 255])
    write("image", "grey.tga", tga)
    # Radiance: flat RGBE pixels (narrow), and run-length scanlines (8 wide: one run and one dump per channel).
    header = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n"
    write("image", "flat.hdr", header + b"-Y 2 +X 2\n" + bytes([128, 128, 128, 129, 64, 0, 0, 120] * 2))
    scanline = b"\x02\x02\x00\x08" + (bytes([132, 200]) + bytes([4, 1, 2, 3, 4])) * 3 + bytes([136, 130])
    write("image", "rle.hdr", header + b"-Y 2 +X 8\n" + scanline * 2)
    # tiny.jpg with an EXIF segment after its SOI: big-endian TIFF, one entry, Orientation 6.
    with open(os.path.join(HERE, "image", "tiny.jpg"), "rb") as f:
        jpeg = f.read()
    tiff = b"MM\x00\x2a" + struct.pack(">IH", 8, 1) + struct.pack(">HHIHH", 0x0112, 3, 1, 6, 0) + b"\0\0\0\0"
    exif = b"Exif\0\0" + tiff
    write("image", "exif_orientation.jpg", jpeg[:2] + b"\xff\xe1" + struct.pack(">H", len(exif) + 2) + exif + jpeg[2:])


# ---- Query: byte 0 = density kind (0 constant, 1 image, 2 callback) + (capacity - 1) << 2; bytes 1-2 =
# raw-double selector bits; then x0 y0 x1 y1 origin_x origin_y tile_size scale value callback_max, the
# image's x0 y0 x1 y1 (one byte each unless raw), the split byte, 16 texels (bytes unless bit 14 is set).
# Byte values: coordinates int8/8, tile_size b/64, scale 2^((b-128)/8), value int8/16, callback_max b/16.

def query(kind, capacity, raw=0, values=None, split=128, texels=None, smooth=False):
    fields = values or [0, 0, 16, 16, 0, 0, 64, 160, 16, 16, 0, 0, 16, 16]
    out = bytes([kind + ((capacity - 1) << 2) + (32 if smooth else 0), raw & 0xFF, raw >> 8])
    for i, v in enumerate(fields):
        out += struct.pack("<d", v) if (raw >> i) & 1 else bytes([v])
    out += bytes([split])
    if (raw >> 14) & 1:
        out += b"".join(struct.pack("<f", t) for t in texels)
    else:
        out += bytes(texels or [(7 * i) % 64 for i in range(16)])
    return out


def queries():
    write("query", "constant", query(0, 8))
    write("query", "image", query(1, 3))
    write("query", "callback", query(2, 1))
    write("query", "smooth_image", query(1, 6, smooth=True))
    write("query", "smooth_callback", query(2, 2, smooth=True))
    # 10^8 points per unit area on tiles of side 1: three thousand times the top level, two depths down.
    write("query", "smooth_past_top", query(0, 8, raw=1 << 7, values=[0, 0, 1, 1, 0, 0, 64, 1e8, 16, 16,
                                                                      0, 0, 16, 16], smooth=True))
    write("query", "smooth_past_top_callback", query(2, 3, raw=1 << 7, values=[8, 8, 9, 9, 0, 0, 64, 3e8, 16,
                                                                               16, 0, 0, 16, 16], smooth=True))
    write("query", "nan_region", query(0, 4, raw=1 << 2, values=[0, 0, float("nan"), 16, 0, 0, 64, 160, 16, 16,
                                                                  0, 0, 16, 16]))
    write("query", "huge_scale", query(0, 8, raw=1 << 7, values=[0, 0, 16, 16, 0, 0, 64, 1e12, 16, 16,
                                                                  0, 0, 16, 16]))
    write("query", "far_origin", query(1, 5, raw=(1 << 4) | (1 << 5), values=[248, 240, 24, 8, 1e9, -1e9, 32, 176,
                                                                              16, 16, 0, 0, 16, 16]))
    write("query", "raw_texels", query(1, 2, raw=1 << 14, texels=[0.5, 1e-30, 3.0, 0.0] * 4))


def recipes():
    write("recipe", "default.recipe", "# The default tile set\nseed 1\ncolours 2\nlevels 6\nbase_points 32\n"
          "temperature 0.5\nsweeps 100\nband 0.35\nerosion 1.5\n")
    write("recipe", "small.recipe", "seed 3\nlevels 2\nbase_points 32\nsweeps 10\n")
    write("recipe", "edges.recipe", "  colours\t16 # the format's cap\r\nlevels 1\nbase_points 65536\n"
          "temperature 0\nband 0.49\nerosion 0\nseed 9007199254740992\n")
    write("recipe", "bad.recipe", "levels three\n")
    write("recipe", "handover.recipe", "levels 3\nbase_points 16\nsweeps 10\nerosion 1\nedge_gap 0.5\nkeyframes 2\n"
          "glide_sweeps 5\nhandover_zone 1\n")


def point_files():
    write("point_file", "two_sets.txt", "# kdm sample\n0.1 0.2\n0.3 0.4\n#\n0.5 0.6\n\n0.7,0.8\r\n")
    write("point_file", "header.csv", "x,y,z\n0.25,0.5,0.75\n1e-3,0x1p-2,.5\n")
    write("point_file", "bad.txt", "0.1 0.2\n0.3\n")
    write("point_file", "classes.csv", "x,y,class\n0.1,0.2,0\n0.3,0.4,2\n")
    write("point_file", "query.csv", "x,y,tile_x,tile_y,rank,level,class\n0.5,0.25,0,0,3,0,1\n")
    write("point_file", "named_columns.csv", "id, Y ,X,label\n7,0.5,0.25,1\np2,0.75,0.125,0\n")
    # np.save(f, np.array([[0.25, 0.5], [0.75, 0.125]])): version 1.0, its header padded to 64 bytes.
    header = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2), }"
    header += " " * (64 - 10 - len(header) - 1) + "\n"
    write("point_file", "two_points.npy", b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) +
          header.encode() + struct.pack("<4d", 0.25, 0.5, 0.75, 0.125))


def crashes():
    root = os.path.join(os.path.dirname(HERE), "crashes")
    # A DHT table of 16 x 255 codes: stb writes past its 257-entry Huffman arrays (already in stbi_info).
    write("image", "jpeg_huffman_overflow.jpg", b"\xff\xd8\xff\xc4\x00\x13\x00" + b"\xff" * 16 + b"\xff\xd9", root)
    # A frame and a scan but no DHT: stb decodes with Huffman tables it never initialised (fuzzer-found,
    # minimised; faults when the heap holds 0xFF bytes, e.g. ASAN_OPTIONS=malloc_fill_byte=255).
    write("image", "jpeg_no_huffman_tables.jpg",
          bytes.fromhex("ffd8ffc000110800080408030122020011010311" "01ffda000c03"), root)
    ihdr = chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 0, 0, 0, 0))
    # An IDAT claiming 2^31 - 16 bytes in a 44-byte file: stb reallocs 2 GiB before reading it.
    write("image", "png_chunk_past_end.png",
          b"\x89PNG\r\n\x1a\n" + ihdr + struct.pack(">I", 0x7FFFFFF0) + b"IDAT\x78\x9c\x63", root)
    # An empty first IDAT: memcpy(NULL, p, 0) in stbi__getn (harmless; suppressed in tests/fuzz/ubsan.supp).
    write("image", "png_empty_idat.png", b"\x89PNG\r\n\x1a\n" + ihdr + chunk(b"IDAT", b"") +
          chunk(b"IDAT", zlib.compress(b"\0" * 6)) + chunk(b"IEND", b""), root)
    # A width past INT_MAX: signed overflow in stbi__pnm_getinteger.
    write("image", "pnm_header_overflow.pgm", b"P5 99999999999 1 255\n\0", root)
    # 64x64 pixels announced, 10 given: stb returns the other 4086 uninitialised.
    write("image", "pnm_pixels_cut_short.pgm", b"P5 64 64 255\n" + b"\x80" * 10, root)
    # A 2-bit palette PNG whose PLTE holds 3 entries and whose pixels use index 3 (fuzzer-found): stb reads
    # the entry from its uninitialised stack, so the picture differed from one decode to the next.
    write("image", "png_index_past_palette.png", bytes.fromhex(
        "89504e470d0a1a0a0000000d494844520000000400000002020300000002c695f000000009504c5445800000ffffff8040"
        "2059e4f73c0000000274524e51ff00e5b7304a0000000c4944415478da6394647e000000e500ac242342fa000030004945"
        "4e44ae426082"), root)
    # A 4-bit BMP cut short whose pixel offset is 0, inside its header (fuzzer-found): stb counts a negative
    # palette, reads none, and draws every pixel from its uninitialised stack.
    write("image", "bmp_pixels_inside_header.bmp",
          bytes.fromhex("424d4600002f003d003600000000280000002b00000011000000010004"), root)
    # A run-length scanline with a run of length 0 (fuzzer-found): stb 2.27 reads on in place forever.
    write("image", "hdr_run_of_length_zero.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 8\n" +
          bytes([2, 2, 0, 8, 4, 180, 0, 240, 0, 0]), root)
    # query_points never returns (runtime/src/query.cpp): x in [0, 5e-324) with tiles of side 255/64 covers
    # no tile column (x1 / tile_size underflows to 0, so ceil = floor), the tile count is 0 x 2.5e14 = 0
    # and passes kMaxQueryTiles, and the loop walks 2.5e14 empty rows without examining a candidate.
    write("query", "zero_columns_many_rows",
          query(0, 1, raw=(1 << 2) | (1 << 3), values=[0, 0, 5e-324, 1e15, 0, 0, 255, 160, 16, 16, 0, 0, 16, 16]),
          root)
    # Not a runtime bug but the fuzzer's: the same sliver 1e15 tall, compact, with scale 16 and the origin at
    # 0. The query answers it with no points, as it covers no tile column, before it judges the origin's
    # distance; the fuzzer expected the refusal whatever the region held.
    write("query", "compact_sliver_far_from_origin", bytes.fromhex(
        "000c000000010000000000000000003426f56b0c430000ff" "a01010000010108000070e151c232a31383f060d141b2229"), root)
    # Not a runtime bug but the fuzzer's: a region 1.8e-322 wide splits into a half 2e-323 wide, too narrow
    # for its distance from the world origin (kTooFarFromOrigin), which the split check took for a failure.
    write("query", "split_half_too_narrow_for_its_distance",
          bytes.fromhex("040c00000025000000000000" "00ffffffffffff100010101080000e0a1c143c1b2229"), root)
    # ParallelQuery never returned (runtime/src/parallel_query.cpp): a region from y = -6 to 3e-322 on tiles of
    # side 2.95 leaves a last row of units 3e-322 high, which the query refuses as too narrow for its
    # distance from the origin (kTooFarFromOrigin); the worker waited for a last call that never came.
    write("query", "parallel_unit_too_narrow_for_its_distance", bytes.fromhex(
        "040c0000d04b6202f0550000404000000000000000b89fbd" "5df2ffffbf4000000000ffffffffffffffff00ff0f1000"), root)
    # ParallelQuery refused an accepted query (runtime/src/parallel_query.cpp): a region from x = -1.7e-154
    # to 3.7e-4 on tiles of side 3.36 cut into half-tile cells starts a column of cells past the region
    # (cells are counted from the tile's side) and has a column -1.7e-154 to 0, too narrow for its
    # distance from the origin; merging only the first column kept the sliver.
    write("query", "parallel_sliver_after_an_empty_column", bytes.fromhex(
        "25270000000010100002a0100002a0102dc310002525401c23383f060d141b101020000000d7d7d7d7d701005617a520d0"
        "ffffffffffffffffffffffffffffffffffd8d7d710002525230d3f401c3414061b101022ffffffff29"), root)


if __name__ == "__main__":
    crashes()
    images()
    queries()
    recipes()
    point_files()
