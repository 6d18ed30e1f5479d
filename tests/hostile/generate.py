#!/usr/bin/env python3
"""Regenerates the hostile-input corpus in this directory (standard library only).

Run from anywhere: `python3 tests/hostile/generate.py`. Every file is small (< 64 KiB) and
deterministic; README.md lists each one with its expected outcome and is checked by
crates/ibl-io/tests/hostile.rs, which also checks that every file here is listed.
"""

import math
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def write(name, data):
    assert len(data) < 64 * 1024, name
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data)


# ---------------------------------------------------------------- Radiance HDR

def hdr_header(res, extra=b""):
    return b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n" + extra + b"\n" + res + b"\n"


def rle_scanline(width, value=(128, 64, 32, 129)):
    """A valid new-style RLE scanline of `width` identical pixels."""
    out = bytes([2, 2, width >> 8, width & 0xFF])
    for comp in value:
        left = width
        while left:
            n = min(left, 127)
            out += bytes([128 + n, comp])
            left -= n
    return out


def hdr_files():
    w, h = 64, 16
    valid = hdr_header(b"-Y %d +X %d" % (h, w)) + rle_scanline(w) * h
    write("truncated.hdr", valid[: len(valid) - 40])
    write("truncated_header.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n")
    write("no_resolution.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
    write("wrong_magic.hdr", b"RADIANCE but not really\n\n-Y 1 +X 1\n\x00\x00\x00\x00")
    write("zero_width.hdr", hdr_header(b"-Y 16 +X 0"))
    write("huge_2p31.hdr", hdr_header(b"-Y 2147483648 +X 2147483648") + rle_scanline(64))
    write("huge_exact_limit.hdr", hdr_header(b"-Y 65536 +X 65536") + rle_scanline(64))
    # Within the limits (64 M pixels) but 200 bytes cannot hold 8192 scanlines.
    write("too_big_for_file.hdr", hdr_header(b"-Y 8192 +X 8192") + rle_scanline(8192)[:200])
    write("bad_resolution.hdr", hdr_header(b"-Y abc +X 5") + b"\x00" * 40)
    write("huge_header_line.hdr", b"#?RADIANCE\n" + b"A" * 60000)
    write("xyze.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n\x80\x80\x80\x81")
    write("bad_exposure.hdr", hdr_header(b"-Y 1 +X 1", b"EXPOSURE=0\n") + b"\x80\x80\x80\x81")
    # Run length 127 at position 60 of a 64-pixel scanline.
    bad_run = bytes([2, 2, 0, w]) + bytes([128 + 60, 7, 128 + 127, 7])
    write("rle_run_overflow.hdr", hdr_header(b"-Y 1 +X %d" % w) + bad_run + b"\x00" * 64)
    # Literal of 100 bytes in a 64-pixel scanline.
    bad_lit = bytes([2, 2, 0, w, 100]) + bytes(range(100))
    write("rle_literal_overflow.hdr", hdr_header(b"-Y 1 +X %d" % w) + bad_lit + b"\x00" * 64)
    # Scanline header claims 65 pixels in a 64-pixel image.
    write("rle_bad_scanline_header.hdr",
          hdr_header(b"-Y 2 +X %d" % w) + bytes([2, 2, 0, w + 1]) + rle_scanline(w)[4:] * 2)
    write("rle_zero_literal.hdr", hdr_header(b"-Y 1 +X %d" % w) + bytes([2, 2, 0, w, 0]) + b"\x01" * 300)
    # Old-style RLE: one pixel then a run of 200 in an 8-pixel (flat-width) scanline... widths
    # below 8 are never new-style RLE, so use width 4.
    old = bytes([128, 0, 0, 129]) + bytes([1, 1, 1, 200])
    write("old_rle_overflow.hdr", hdr_header(b"-Y 1 +X 4") + old)
    write("old_rle_run_first.hdr", hdr_header(b"-Y 1 +X 4") + bytes([1, 1, 1, 3]) * 2)
    # A PNG signature in a .hdr file.
    write("png_named.hdr", png_bytes(4, 4))


# ---------------------------------------------------------------- PFM

def pfm_files():
    write("truncated.pfm", b"PF\n16 16\n-1.0\n" + b"\x00" * 1000)
    write("wrong_magic.pfm", b"P6\n2 2\n255\n" + b"\x00" * 12)
    write("zero_dims.pfm", b"PF\n0 0\n-1.0\n")
    write("huge_2p31.pfm", b"PF\n2147483648 2147483648\n-1.0\n" + b"\x00" * 64)
    write("too_big_for_file.pfm", b"PF\n4000 4000\n-1.0\n" + b"\x00" * 64)
    write("bad_scale.pfm", b"PF\n1 1\n0\n" + b"\x00" * 12)
    write("truncated_header.pfm", b"PF\n16")
    # 2 x 2 RGB, little-endian: NaN, +Inf, -Inf and one negative among 12 values.
    vals = [math.nan, 1.0, 2.0, math.inf, 0.5, 0.25, -math.inf, 3.0, 4.0, -1.0, 5.0, 6.0]
    write("nan_inf.pfm", b"PF\n2 2\n-1.0\n" + struct.pack("<12f", *vals))
    # Grey, big-endian: NaN and -2.
    write("nan_grey_be.pfm", b"Pf\n3 1\n1.0\n" + struct.pack(">3f", math.nan, -2.0, 1.0))


# ---------------------------------------------------------------- OpenEXR

def attr(name, ty, value):
    return name + b"\0" + ty + b"\0" + struct.pack("<i", len(value)) + value


def chlist(names, pixel_type):
    out = b""
    for n in sorted(names):
        out += n + b"\0" + struct.pack("<iBBBBii", pixel_type, 0, 0, 0, 0, 1, 1)
    return out + b"\0"


def exr_header(w, h, compression=0, channels=(b"B", b"G", b"R"), pixel_type=2, window=None):
    window = window or (0, 0, w - 1, h - 1)
    box = struct.pack("<iiii", *window)
    return (
        b"\x76\x2f\x31\x01" + bytes([2, 0, 0, 0])
        + attr(b"channels", b"chlist", chlist(channels, pixel_type))
        + attr(b"compression", b"compression", bytes([compression]))
        + attr(b"dataWindow", b"box2i", box)
        + attr(b"displayWindow", b"box2i", box)
        + attr(b"lineOrder", b"lineOrder", b"\0")
        + attr(b"pixelAspectRatio", b"float", struct.pack("<f", 1.0))
        + attr(b"screenWindowCenter", b"v2f", struct.pack("<ff", 0, 0))
        + attr(b"screenWindowWidth", b"float", struct.pack("<f", 1.0))
        + b"\0"
    )


def exr_float_uncompressed(w, h, pixel):
    """A valid single-part NONE-compressed float RGB file; pixel(x, y) -> (r, g, b)."""
    head = exr_header(w, h)
    chunks = []
    for y in range(h):
        row = [pixel(x, y) for x in range(w)]
        data = b"".join(struct.pack("<%df" % w, *[p[c] for p in row]) for c in (2, 1, 0))
        chunks.append(struct.pack("<ii", y, len(data)) + data)
    offset = len(head) + 8 * h
    table = b""
    for c in chunks:
        table += struct.pack("<Q", offset)
        offset += len(c)
    return head + table + b"".join(chunks)


def exr_files():
    valid = exr_float_uncompressed(16, 8, lambda x, y: (x / 16, y / 8, 0.5))
    write("truncated.exr", valid[: len(valid) - 100])
    write("truncated_header.exr", valid[:60])
    write("text.exr", b"This is a text file that merely has an .exr extension.\n")
    write("zero_dims.exr", exr_header(1, 1, window=(0, 0, -1, -1)) + b"\0" * 64)
    big = 2**31 - 1
    write("huge_2p31.exr", exr_header(1, 1, window=(0, 0, big, big)) + b"\0" * 64)
    write("too_big_for_file.exr", exr_header(1, 1, compression=3, window=(0, 0, 29999, 7999)) + b"\0" * 256)
    write("htj2k.exr", exr_header(4, 4, compression=10) + b"\0" * 64)
    write("unknown_compression.exr", exr_header(4, 4, compression=42) + b"\0" * 64)
    write("subsampled.exr", exr_header(4, 4).replace(struct.pack("<ii", 1, 1), struct.pack("<ii", 2, 2), 1) + b"\0" * 256)
    write("no_rgb_channels.exr", exr_header(4, 4, channels=(b"Z",)) + b"\0" * 256)
    # Offsets pointing far beyond the end of the file.
    head = exr_header(4, 2)
    write("bad_offsets.exr", head + struct.pack("<QQ", 1 << 40, 1 << 41) + b"\0" * 128)
    # ZIPS (code 2) chunks whose payload is not zlib data.
    head = exr_header(4, 2, compression=2)
    body = [struct.pack("<ii", y, 20) + b"\xde\xad\xbe\xef" * 5 for y in (0, 1)]
    table = struct.pack("<QQ", len(head) + 16, len(head) + 16 + 28)
    write("corrupt_zip.exr", head + table + body[0] + body[1])
    # Huge attribute size.
    h = exr_header(4, 4)
    write("huge_attribute.exr", h[:8] + b"comments\0string\0" + struct.pack("<i", 2**31 - 1) + b"x" * 32)
    # Float pixels with NaN, +Inf, -Inf and negatives: must load, with counts.
    special = {(0, 0): (math.nan, 1.0, 1.0), (1, 0): (math.inf, -math.inf, 0.5), (2, 1): (-0.25, 1.0, -4.0)}
    write("nan_inf.exr", exr_float_uncompressed(4, 2, lambda x, y: special.get((x, y), (0.1, 0.2, 0.3))))


# ---------------------------------------------------------------- PNG / JPEG

def png_chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def png_bytes(w, h, ihdr_w=None, ihdr_h=None):
    raw = b"".join(b"\0" + bytes((x * 40) % 256 for x in range(3 * w)) for _ in range(h))
    ihdr_w = w if ihdr_w is None else ihdr_w
    ihdr_h = h if ihdr_h is None else ihdr_h
    ihdr = struct.pack(">IIBBBBB", ihdr_w, ihdr_h, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", ihdr)
            + png_chunk(b"IDAT", zlib.compress(raw)) + png_chunk(b"IEND", b""))


def ldr_files():
    valid = png_bytes(32, 32)
    write("truncated.png", valid[: len(valid) // 2])
    write("huge_2p31.png", png_bytes(4, 4, ihdr_w=2**31 - 1, ihdr_h=2**31 - 1))
    write("zero_dims.png", png_bytes(4, 4, ihdr_w=0, ihdr_h=4))
    write("text.png", b"not a png\n")
    write("truncated.jpg", b"\xff\xd8\xff\xe0\x00\x10JFIF\x00\x01\x01\x00\x00\x01\x00\x01\x00\x00\xff\xdb")
    write("empty.hdr", b"")
    write("empty.exr", b"")
    write("empty.pfm", b"")
    write("empty.png", b"")
    write("empty.jpg", b"")


if __name__ == "__main__":
    hdr_files()
    pfm_files()
    exr_files()
    ldr_files()
