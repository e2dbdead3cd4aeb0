#!/usr/bin/env python3
"""Writes the demo scene's textures (scenes/demo/textures/), from nothing but this script.

- tiles.png: terracotta floor tiles, 4 x 4 per texture, each tile its own shade with a little
  grain, in light grout (8-bit sRGB).
- tiles_height.png: the height the bump map reads: tiles at 1 with rounded edges, grout at 0
  (8-bit grey, linear: the scene loads it raw).

Deterministic (a fixed hash, no random state), standard library only, so the PNGs in the repository
are exactly what this script writes (tests/integration/demo_textures_test.py checks):
    python3 scripts/make_demo_textures.py [OUT_DIR]      (default: scenes/demo/textures)
"""
import math
import os
import sys

from texture_util import hash01, write_png

SIZE = 256
TILES = 4
GROUT = 0.045  # of a tile's width


def tile_at(x, y):
    """Tile index, and the distance (in tile widths) to the nearest tile edge."""
    u, v = x * TILES / SIZE, y * TILES / SIZE
    i, j = int(u), int(v)
    fu, fv = u - i, v - j
    return i, j, min(fu, 1 - fu, fv, 1 - fv)


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "scenes", "demo", "textures")
    os.makedirs(out, exist_ok=True)
    colour_rows, height_rows = [], []
    for y in range(SIZE):
        crow, hrow = [], []
        for x in range(SIZE):
            i, j, edge = tile_at(x + 0.5, y + 0.5)
            if edge < GROUT:
                grain = 0.9 + 0.1 * hash01(x // 2, y // 2, 7)
                crow += [int(200 * grain), int(192 * grain), int(178 * grain)]
                hrow.append(0)
                continue
            shade = 0.78 + 0.22 * hash01(i, j)
            grain = 0.93 + 0.07 * hash01(x // 2, y // 2, 3)
            crow += [int(190 * shade * grain), int(96 * shade * grain), int(62 * shade * grain)]
            # A bevel over the first 6% of the tile, then flat.
            bevel = min(1.0, (edge - GROUT) / 0.06)
            hrow.append(int(255 * math.sin(0.5 * math.pi * bevel)))
        colour_rows.append(crow)
        height_rows.append(hrow)
    write_png(os.path.join(out, "tiles.png"), SIZE, SIZE, 3, colour_rows)
    write_png(os.path.join(out, "tiles_height.png"), SIZE, SIZE, 1, height_rows)
    print("wrote", os.path.join(out, "tiles.png"), "and tiles_height.png")


if __name__ == "__main__":
    main()
