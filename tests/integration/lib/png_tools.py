#!/usr/bin/env python3
"""PNG helpers of the integration tests (standard library only: zlib + PNG filter decoding).

    png_tools.py stats FILE     -> "W H DISTINCT_COLOURS" (colours sampled every 4th pixel/row)
    png_tools.py diff A B       -> "MEAN_ABS FRACTION_OVER_32" over RGB (same size required)
"""
import struct
import sys
import zlib


def read_png(path):
    """(width, height, bytes per pixel, list of rows as bytearray) of an 8-bit PNG."""
    d = open(path, "rb").read()
    if d[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG")
    pos, idat, hdr = 8, b"", None
    while pos < len(d):
        n, t = struct.unpack(">I4s", d[pos:pos + 8])
        body = d[pos + 8:pos + 8 + n]
        if t == b"IHDR":
            hdr = struct.unpack(">IIBBBBB", body)
        if t == b"IDAT":
            idat += body
        pos += 12 + n
    w, h, depth, ctype = hdr[:4]
    if depth != 8:
        raise ValueError(f"{path}: {depth}-bit PNG, expected 8")
    bpp = {0: 1, 2: 3, 4: 2, 6: 4}[ctype]
    raw, stride = zlib.decompress(idat), w * bpp
    prev, rows, i = bytearray(stride), [], 0
    for _ in range(h):
        f, line = raw[i], bytearray(raw[i + 1:i + 1 + stride])
        i += 1 + stride
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b, c = prev[x], (prev[x - bpp] if x >= bpp else 0)
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return w, h, bpp, rows


def stats(path):
    w, h, bpp, rows = read_png(path)
    colours = set()
    for y in range(0, h, 4):
        for x in range(0, w * bpp, bpp * 4):
            colours.add(bytes(rows[y][x:x + bpp]))
    return w, h, len(colours)


def diff(a, b):
    wa, ha, pa, ra = read_png(a)
    wb, hb, pb, rb = read_png(b)
    if (wa, ha) != (wb, hb):
        raise ValueError(f"sizes differ: {a} {wa}x{ha}, {b} {wb}x{hb}")
    total, over, n = 0, 0, 0
    for y in range(ha):
        for x in range(wa):
            d = max(abs(ra[y][x * pa + k] - rb[y][x * pb + k]) for k in range(3))
            total += d
            over += d > 32
            n += 1
    return total / n, over / n


if __name__ == "__main__":
    if sys.argv[1] == "stats":
        print(*stats(sys.argv[2]))
    elif sys.argv[1] == "diff":
        m, f = diff(sys.argv[2], sys.argv[3])
        print(f"{m:.3f} {f:.5f}")
    else:
        sys.exit(__doc__)
