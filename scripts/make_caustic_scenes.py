#!/usr/bin/env python3
"""Writes two caustic test scenes (Mitsuba 0.6 syntax), from nothing but this script.

- pool/: a swimming-pool basin (4 m x 5 m, 1.4 m deep, open at the top) tiled in light blue and
  white with grey grout, filled to just below its rim with water: a one-sided dielectric sheet
  (IOR 1.33 under 1.0, normals up) whose waves are a sum of five sines. The only light is a small
  square area light 4 m above the pool, off-centre and out of the camera's view, so the floor and the
  walls under the water are lit only through the waves and seen only through them (light, specular,
  diffuse, specular, eye: the caustic net on the floor). Written: scene.xml, meshes/water.ply
  (128 x 128 quads as 32,768 triangles with per-vertex normals, binary PLY: as OBJ text it would be
  over 2 MB), textures/tiles.png (8-bit sRGB).
- glass-caustic/: a glass sphere (IOR 1.5) on a light-grey floor, a point light low to its side that
  the sphere focuses into a bright caustic on the floor, and an upright mirror behind; the camera
  looks into the mirror over a low wall that hides the floor around the sphere, so the caustic is
  seen only in the mirror (light, specular, specular, diffuse, specular, eye). Written: scene.xml.

Both: 320 x 180, box filter, `path` with maxDepth 12 (a render overrides it with --integrator).
Deterministic (a fixed hash, no random state), standard library only, so the files in the repository
are exactly what this script writes (tests/integration/caustic_scenes_test.py checks):
    python3 scripts/make_caustic_scenes.py [OUT_DIR]      (default: scenes)
"""
import math
import os
import struct
import sys

import scene_xml
from scene_xml import f, vec, write_text
from texture_util import hash01, write_png

# --- The pool -------------------------------------------------------------------------------------
POOL_HALF_X = 2.0     # the basin's inside: x in [-2, 2], z in [-2.5, 2.5], floor at -1.4, rim at 0
POOL_HALF_Z = 2.5
POOL_DEPTH = 1.4
WATER_LEVEL = -0.06   # the waves' mean height, just below the rim; they stay under it
GRID = 128            # quads along each side of the water sheet
SHEET_OVERLAP = 0.004  # the sheet reaches this far into the walls: no gap at its edges
# (amplitude m, wavelength m, direction degrees from +x towards +z, phase): long swells and shorter
# ripples whose curvatures focus light at about the depth of the floor.
WAVES = [
    (0.0100, 2.20, 20.0, 0.3),
    (0.0095, 0.62, 75.0, 1.7),
    (0.0070, 0.37, 15.0, 4.1),
    (0.0054, 0.31, 135.0, 2.6),
    (0.0042, 0.28, -105.0, 5.3),
]
POOL_LIGHT = (1.2, 4.0, 1.0)  # centre of the square light, facing down
POOL_LIGHT_HALF = 0.1         # 20 cm x 20 cm
POOL_LIGHT_RADIANCE = 1200.0
TILE_PX = 256                 # the tile texture: 4 x 4 tiles of 25 cm, one metre per repeat
TILES = 4
GROUT = 0.04                  # of a tile's width

# --- The glass sphere and the mirror --------------------------------------------------------------
SPHERE_RADIUS = 0.5
GLASS_LIGHT = (-2.4, 2.6, 2.2)
GLASS_LIGHT_INTENSITY = 40.0


def pool_tiles(path):
    """Light blue and white tiles in a checker, each its own shade with a little grain, in grey grout."""
    rows = []
    for y in range(TILE_PX):
        row = []
        for x in range(TILE_PX):
            u, v = (x + 0.5) * TILES / TILE_PX, (y + 0.5) * TILES / TILE_PX
            i, j = int(u), int(v)
            fu, fv = u - i, v - j
            if min(fu, 1 - fu, fv, 1 - fv) < GROUT:
                grain = 0.9 + 0.1 * hash01(x // 2, y // 2, 11)
                row += [int(120 * grain), int(128 * grain), int(132 * grain)]
                continue
            shade = 0.9 + 0.1 * hash01(i, j, 5)
            grain = 0.95 + 0.05 * hash01(x // 2, y // 2, 13)
            base = (222, 239, 246) if (i + j) % 2 else (168, 214, 236)
            row += [int(c * shade * grain) for c in base]
        rows.append(row)
    write_png(path, TILE_PX, TILE_PX, 3, rows)


def water_height(x, z):
    """Height of the water at (x, z), and its gradient."""
    h, dx, dz = WATER_LEVEL, 0.0, 0.0
    for amp, wavelength, angle, phase in WAVES:
        k = 2 * math.pi / wavelength
        cx, cz = math.cos(math.radians(angle)), math.sin(math.radians(angle))
        arg = k * (cx * x + cz * z) + phase
        h += amp * math.sin(arg)
        slope = amp * k * math.cos(arg)
        dx += slope * cx
        dz += slope * cz
    return h, dx, dz


def water_ply(path):
    """The water sheet over the basin, (GRID + 1)^2 vertices with normals up out of the water."""
    n = GRID + 1
    x0, x1 = -POOL_HALF_X - SHEET_OVERLAP, POOL_HALF_X + SHEET_OVERLAP
    z0, z1 = -POOL_HALF_Z - SHEET_OVERLAP, POOL_HALF_Z + SHEET_OVERLAP
    verts = []
    for j in range(n):
        z = z0 + (z1 - z0) * j / GRID
        for i in range(n):
            x = x0 + (x1 - x0) * i / GRID
            h, dx, dz = water_height(x, z)
            inv = 1.0 / math.sqrt(dx * dx + 1.0 + dz * dz)
            verts.append(struct.pack("<6f", x, h, z, -dx * inv, inv, -dz * inv))
    faces = []
    for j in range(GRID):
        for i in range(GRID):
            a, b = j * n + i, j * n + i + 1      # (x, z), (x + dx, z)
            c, d = a + n, b + n                   # (x, z + dz), (x + dx, z + dz)
            # Counter-clockwise seen from above (+y): x then z is clockwise, so a, c, b.
            faces.append(struct.pack("<B3i", 3, a, c, b))
            faces.append(struct.pack("<B3i", 3, b, c, d))
    header = ("ply\nformat binary_little_endian 1.0\n"
              "comment water surface written by scripts/make_caustic_scenes.py\n"
              f"element vertex {len(verts)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              "property float nx\nproperty float ny\nproperty float nz\n"
              f"element face {len(faces)}\n"
              "property list uchar int vertex_indices\nend_header\n")
    with open(path, "wb") as f:
        f.write(header.encode("ascii") + b"".join(verts) + b"".join(faces))


def sensor(origin, target, fov, spp):
    return scene_xml.sensor(origin, target, fov, spp, 320, 180)


def tile_bitmap(uscale, vscale):
    return f"""<texture type="bitmap" name="reflectance">
                <string name="filename" value="textures/tiles.png"/>
                <float name="uscale" value="{f(uscale)}"/>
                <float name="vscale" value="{f(vscale)}"/>
            </texture>"""


def pool_scene():
    hx, hz, d = POOL_HALF_X, POOL_HALF_Z, POOL_DEPTH
    hy, cy = d / 2, -d / 2  # the walls' half-height and centre
    walls = [  # (comment, transform lines, uscale, vscale): every tiled face looks into the basin
        ("floor", f'<scale x="{f(hx)}" y="{f(hz)}" z="1"/>\n            <rotate x="1" angle="-90"/>\n'
                  f'            <translate y="{f(-d)}"/>', 2 * hx, 2 * hz),
        ("far wall (-z), facing +z", f'<scale x="{f(hx)}" y="{f(hy)}" z="1"/>\n'
                                     f'            <translate y="{f(cy)}" z="{f(-hz)}"/>', 2 * hx, d),
        ("near wall (+z), facing -z", f'<scale x="{f(hx)}" y="{f(hy)}" z="1"/>\n'
                                      f'            <rotate y="1" angle="180"/>\n'
                                      f'            <translate y="{f(cy)}" z="{f(hz)}"/>', 2 * hx, d),
        ("left wall (-x), facing +x", f'<scale x="{f(hz)}" y="{f(hy)}" z="1"/>\n'
                                      f'            <rotate y="1" angle="90"/>\n'
                                      f'            <translate x="{f(-hx)}" y="{f(cy)}"/>', 2 * hz, d),
        ("right wall (+x), facing -x", f'<scale x="{f(hz)}" y="{f(hy)}" z="1"/>\n'
                                       f'            <rotate y="1" angle="-90"/>\n'
                                       f'            <translate x="{f(hx)}" y="{f(cy)}"/>', 2 * hz, d),
    ]
    shapes = ""
    for comment, transform, us, vs in walls:
        shapes += f"""
    <!-- {comment} -->
    <shape type="rectangle">
        <transform name="toWorld">
            {transform}
        </transform>
        <bsdf type="diffuse">
            {tile_bitmap(us, vs)}
        </bsdf>
    </shape>
"""
    lx, ly, lz = POOL_LIGHT
    waves = ",\n     ".join(f"{f(a * 1000)} mm high, {f(w)} m long, towards {f(ang)} deg from +x"
                           for a, w, ang, _ in WAVES)
    return f"""<?xml version="1.0" encoding="utf-8"?>
<!-- Written by scripts/make_caustic_scenes.py; do not edit. A swimming-pool basin ({f(2 * hx)} m x
     {f(2 * hz)} m, {f(d)} m deep, open at the top), tiled, with water just under the rim: a one-sided
     dielectric sheet (normals up, out of the water) {f(-WATER_LEVEL)} m under the rim on average,
     whose waves are a sum of sines:
     {waves}.
     The only light is a small square area light {f(ly)} m above the rim, off-centre and out of
     view: the floor is lit only through the waves and seen only through them, so its caustic net
     takes specular-diffuse-specular paths (a photon mapper or bdpt with many samples). -->
<scene version="0.6.0">
    <integrator type="path">
        <integer name="maxDepth" value="12"/>
    </integrator>

{sensor((0.3, 3.4, 3.2), (-0.2, -1.4, -0.5), 40, 64)}{shapes}
    <!-- The water: IOR 1.33 inside (below the sheet), air above. -->
    <shape type="ply">
        <string name="filename" value="meshes/water.ply"/>
        <bsdf type="dielectric">
            <float name="intIOR" value="1.33"/>
            <float name="extIOR" value="1.0"/>
        </bsdf>
    </shape>

    <!-- The light: {f(2 * POOL_LIGHT_HALF)} m square, facing down. -->
    <shape type="rectangle">
        <transform name="toWorld">
            <scale value="{f(POOL_LIGHT_HALF)}"/>
            <rotate x="1" angle="90"/>
            <translate x="{f(lx)}" y="{f(ly)}" z="{f(lz)}"/>
        </transform>
        <emitter type="area">
            <rgb name="radiance" value="{f(POOL_LIGHT_RADIANCE)}"/>
        </emitter>
    </shape>
</scene>
"""


def glass_scene():
    r = SPHERE_RADIUS
    return f"""<?xml version="1.0" encoding="utf-8"?>
<!-- Written by scripts/make_caustic_scenes.py; do not edit. A glass sphere (IOR 1.5) on a light-grey
     floor, lit by a point light low to its side that the sphere focuses into a bright caustic on
     the floor, and an upright mirror behind. The camera looks into the mirror over a low wall that
     hides the floor around the sphere: the caustic is seen only in the mirror (light, specular,
     specular, diffuse, specular, eye: a photon mapper's path, not a path tracer's). -->
<scene version="0.6.0">
    <integrator type="path">
        <integer name="maxDepth" value="12"/>
    </integrator>

{sensor((1.6, 1.8, 4.6), (0.35, 0.7, -2.0), 45, 64)}
    <bsdf type="diffuse" id="floor">
        <rgb name="reflectance" value="0.6"/>
    </bsdf>
    <bsdf type="diffuse" id="wall">
        <rgb name="reflectance" value="0.55, 0.5, 0.45"/>
    </bsdf>

    <!-- The floor, 12 m square. -->
    <shape type="rectangle">
        <transform name="toWorld">
            <scale value="6"/>
            <rotate x="1" angle="-90"/>
        </transform>
        <ref id="floor"/>
    </shape>

    <!-- Walls round the floor (no ceiling), each facing in: behind the mirror, behind the camera,
         left and right. -->
    <shape type="rectangle">
        <transform name="toWorld">
            <scale x="6" y="2" z="1"/>
            <translate y="2" z="-2.1"/>
        </transform>
        <ref id="wall"/>
    </shape>
    <shape type="rectangle">
        <transform name="toWorld">
            <scale x="6" y="2" z="1"/>
            <rotate y="1" angle="180"/>
            <translate y="2" z="6"/>
        </transform>
        <bsdf type="diffuse">
            <rgb name="reflectance" value="0.25, 0.35, 0.55"/>
        </bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="toWorld">
            <scale x="4.05" y="2" z="1"/>
            <rotate y="1" angle="90"/>
            <translate x="-6" y="2" z="1.95"/>
        </transform>
        <ref id="wall"/>
    </shape>
    <shape type="rectangle">
        <transform name="toWorld">
            <scale x="4.05" y="2" z="1"/>
            <rotate y="1" angle="-90"/>
            <translate x="6" y="2" z="1.95"/>
        </transform>
        <ref id="wall"/>
    </shape>

    <!-- The mirror: 5 m x 1.8 m, standing on the floor just in front of the back wall, facing +z. -->
    <shape type="rectangle">
        <transform name="toWorld">
            <scale x="2.5" y="0.9" z="1"/>
            <translate y="0.9" z="-2"/>
        </transform>
        <bsdf type="conductor">
            <string name="material" value="none"/>
        </bsdf>
    </shape>

    <!-- The low wall between the camera and the sphere: it hides the floor round the sphere. -->
    <shape type="cube">
        <transform name="toWorld">
            <scale x="2.5" y="0.39" z="0.05"/>
            <translate y="0.39" z="0.7"/>
        </transform>
        <bsdf type="diffuse">
            <rgb name="reflectance" value="0.5, 0.3, 0.22"/>
        </bsdf>
    </shape>

    <!-- The glass sphere, resting on the floor. -->
    <shape type="sphere">
        <point name="center" x="0" y="{f(r)}" z="0"/>
        <float name="radius" value="{f(r)}"/>
        <bsdf type="dielectric">
            <float name="intIOR" value="1.5"/>
            <float name="extIOR" value="1.0"/>
        </bsdf>
    </shape>

    <emitter type="point">
        <point name="position" x="{f(GLASS_LIGHT[0])}" y="{f(GLASS_LIGHT[1])}" z="{f(GLASS_LIGHT[2])}"/>
        <rgb name="intensity" value="{f(GLASS_LIGHT_INTENSITY)}"/>
    </emitter>
</scene>
"""


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "scenes")
    pool = os.path.join(out, "pool")
    glass = os.path.join(out, "glass-caustic")
    for d in (os.path.join(pool, "meshes"), os.path.join(pool, "textures"), glass):
        os.makedirs(d, exist_ok=True)
    pool_tiles(os.path.join(pool, "textures", "tiles.png"))
    water_ply(os.path.join(pool, "meshes", "water.ply"))
    write_text(os.path.join(pool, "scene.xml"), pool_scene())
    write_text(os.path.join(glass, "scene.xml"), glass_scene())
    print("wrote", pool, "(scene.xml, meshes/water.ply, textures/tiles.png) and", glass, "(scene.xml)")


if __name__ == "__main__":
    main()
