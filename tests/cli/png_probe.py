#!/usr/bin/python3
"""Reads an 8-bit RGB PNG written with unfiltered rows (as `geodex render` writes them) and prints
facts about it as JSON: size, distinct colours, share of non-white pixels, the mean brightness of
the non-white pixels in each quadrant of the mesh's area (bl = bottom-left, tr = top-right, ...;
the colour bar's strip, the rightmost --bar-width pixels, left out), the number of pure black
pixels there (source markers), and the colours at --pixel X,Y (repeatable).

usage: png_probe.py FILE [--bar-width N] [--pixel X,Y]..."""
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
    args = sys.argv[2:]
    bar, pixels = 0, []
    while args:
        flag, value = args[0], args[1]
        args = args[2:]
        if flag == "--bar-width":
            bar = int(value)
        elif flag == "--pixel":
            pixels.append(tuple(int(v) for v in value.split(",")))
    width, height, rows = read_png(sys.argv[1])
    area = width - bar
    colours, painted, black = set(), 0, 0
    quad = {k: [0, 0] for k in ("tl", "tr", "bl", "br")}
    for y, row in enumerate(rows):
        for x in range(area):
            rgb = tuple(row[3 * x:3 * x + 3])
            colours.add(rgb)
            if rgb == (255, 255, 255):
                continue
            painted += 1
            black += rgb == (0, 0, 0)
            key = ("t" if y < height / 2 else "b") + ("l" if x < area / 2 else "r")
            quad[key][0] += sum(rgb)
            quad[key][1] += 1
    print(json.dumps({
        "width": width, "height": height, "colours": len(colours),
        "painted": painted / (area * height), "black": black,
        "brightness": {k: (v[0] / v[1] if v[1] else None) for k, v in quad.items()},
        "pixels": [list(rows[y][3 * x:3 * x + 3]) for x, y in pixels],
    }))


if __name__ == "__main__":
    main()
