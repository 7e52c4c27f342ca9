#!/usr/bin/python3
"""Reads an 8-bit RGB PNG written with unfiltered rows (as `geodex render` writes them) and prints
facts about it as JSON: size, distinct colours, share of non-white pixels, and the mean brightness
of the non-white pixels in each image quadrant (bl = bottom-left, tr = top-right, ...)."""
import json
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, width, height = 8, b"", 0, 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and color == 2, "expected 8-bit RGB"
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = 1 + 3 * width
    rows = []
    for y in range(height):
        row = raw[y * stride:(y + 1) * stride]
        assert row[0] == 0, "expected unfiltered rows"
        rows.append(row[1:])
    return width, height, rows


def main():
    width, height, rows = read_png(sys.argv[1])
    colours, painted = set(), 0
    quad = {k: [0, 0] for k in ("tl", "tr", "bl", "br")}
    for y, row in enumerate(rows):
        for x in range(width):
            rgb = tuple(row[3 * x:3 * x + 3])
            colours.add(rgb)
            if rgb == (255, 255, 255):
                continue
            painted += 1
            key = ("t" if y < height / 2 else "b") + ("l" if x < width / 2 else "r")
            quad[key][0] += sum(rgb)
            quad[key][1] += 1
    print(json.dumps({
        "width": width, "height": height, "colours": len(colours),
        "painted": painted / (width * height),
        "brightness": {k: (v[0] / v[1] if v[1] else None) for k, v in quad.items()},
    }))


main()
