#!/usr/bin/env python3
"""Writes two interiors lit only through a small opening, where path guiding should pay (Mitsuba 0.6
syntax), from nothing but this script.

- door-ajar/: two rooms side by side, 3 m x 4 m each and 2.5 m high, between them a wall with a door
  opened a few degrees into the far room. A small spherical lamp hangs in the far room; the camera
  is in the near room, which gets its light only through the wedge of the door ajar (Veach's
  "door ajar" situation): most light reaches the near room after bouncing in the far one.
- window-pane/: a closed room, 5 m x 6 m and 2.6 m high, lit by a uniform sky through a window pane
  of `dielectric` glass (IOR 1.5, 2 cm thick) in its left wall. The camera looks away from the window,
  so the sky is never seen directly; next-event estimation cannot see through glass, so the path
  tracer finds the sky only where a sampled direction happens to leave through the pane.

Both: 320 x 240, box filter, `path` with maxDepth 16 (a render overrides it with --integrator),
walls as thin boxes (their normals face out of the box, so both sides of a wall shade correctly).
Deterministic, standard library only, so the files in the repository are exactly what this script
writes (tests/integration/generated_scenes_test.py checks):
    python3 scripts/make_guiding_scenes.py [OUT_DIR]      (default: scenes)
"""
import os
import sys

import scene_xml
from scene_xml import f, vec, write_text

WIDTH, HEIGHT = 320, 240
MAX_DEPTH = 16
WALL = 0.1  # thickness of walls, floors and ceilings

# --- Door ajar ------------------------------------------------------------------------------------
ROOM_Y = 2.5            # both rooms: y in [0, 2.5], z in [-2, 2]
NEAR_X = (-3.0, 0.0)    # the camera's room
FAR_X = (WALL, 3.1)     # the lamp's room; the partition wall is x in [0, 0.1]
DOOR_Z = (0.6, 1.5)     # the door opening in the partition, floor to DOOR_TOP
DOOR_TOP = 2.05
DOOR_THICKNESS = 0.04
DOOR_ANGLE = 7.0        # degrees the door stands open, into the far room, hinged at z = DOOR_Z[1]
LAMP = (2.3, 1.9, -1.3)  # a small sphere near the far room's back corner
LAMP_RADIUS = 0.1
LAMP_RADIANCE = 400.0

# --- Window pane ----------------------------------------------------------------------------------
WIN_ROOM_X = (-2.5, 2.5)
WIN_ROOM_Z = (-3.0, 3.0)
WIN_ROOM_Y = 2.6
WINDOW_Z = (-1.4, 0.4)  # the opening in the left wall (x = -2.5), between WINDOW_Y
WINDOW_Y = (0.9, 2.1)
PANE_THICKNESS = 0.02
SKY = (2.7, 3.0, 3.6)   # the uniform sky's radiance


def header(comment):
    return f"""<?xml version="1.0" encoding="utf-8"?>
<!-- Written by scripts/make_guiding_scenes.py; do not edit. {comment} -->
<scene version="0.6.0">
    <integrator type="path">
        <integer name="maxDepth" value="{MAX_DEPTH}"/>
    </integrator>
"""


def sensor(origin, target, fov, spp):
    return "\n" + scene_xml.sensor(origin, target, fov, spp, WIDTH, HEIGHT)


def diffuse(id_, rgb):
    return f"""
    <bsdf type="diffuse" id="{id_}">
        <rgb name="reflectance" value="{vec(rgb)}"/>
    </bsdf>
"""


def box(comment, lo, hi, material, extra_transform=""):
    """An axis-aligned box from lo to hi (Mitsuba's cube spans [-1, 1]^3), then `extra_transform`."""
    half = [(b - a) / 2 for a, b in zip(lo, hi)]
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    return f"""
    <!-- {comment} -->
    <shape type="cube">
        <transform name="toWorld">
            <scale x="{f(half[0])}" y="{f(half[1])}" z="{f(half[2])}"/>
            <translate x="{f(centre[0])}" y="{f(centre[1])}" z="{f(centre[2])}"/>{extra_transform}
        </transform>
        {material}
    </shape>
"""


def sphere(comment, centre, radius, inner):
    return f"""
    <!-- {comment} -->
    <shape type="sphere">
        <point name="center" x="{f(centre[0])}" y="{f(centre[1])}" z="{f(centre[2])}"/>
        <float name="radius" value="{f(radius)}"/>
        {inner}
    </shape>
"""


def shell(x, y_top, z, material):
    """Floor, ceiling and four walls round the box x * [0, y_top] * z, each WALL thick, outside it."""
    (x0, x1), (z0, z1), t = x, z, WALL
    return "".join([
        box("floor", (x0 - t, -t, z0 - t), (x1 + t, 0, z1 + t), material),
        box("ceiling", (x0 - t, y_top, z0 - t), (x1 + t, y_top + t, z1 + t), material),
        box("back wall (-z)", (x0, 0, z0 - t), (x1, y_top, z0), material),
        box("front wall (+z)", (x0, 0, z1), (x1, y_top, z1 + t), material),
    ])


def door_ajar_scene():
    z0, z1 = -2.0, 2.0
    x0, x1 = NEAR_X[0], FAR_X[1]
    wall = '<ref id="wall"/>'
    shapes = shell((x0, x1), ROOM_Y, (z0, z1), wall)
    shapes += box("left wall (-x)", (x0 - WALL, 0, z0), (x0, ROOM_Y, z1), wall)
    shapes += box("right wall (+x)", (x1, 0, z0), (x1 + WALL, ROOM_Y, z1), wall)
    dz0, dz1 = DOOR_Z
    shapes += box("partition, beside the door", (0, 0, z0), (WALL, ROOM_Y, dz0), wall)
    shapes += box("partition, the other side of the door", (0, 0, dz1), (WALL, ROOM_Y, z1), wall)
    shapes += box("partition, above the door", (0, DOOR_TOP, dz0), (WALL, ROOM_Y, dz1), wall)
    # The door: built closed with its hinge edge at the origin, turned about y (negative angles
    # swing its free edge towards +x, into the far room) and moved to the hinge.
    hinge = (WALL, 0.0, dz1)
    turn = f"""
            <rotate y="1" angle="{f(-DOOR_ANGLE)}"/>
            <translate x="{f(hinge[0])}" z="{f(hinge[2])}"/>"""
    shapes += box(f"the door, {f(DOOR_ANGLE)} degrees open", (0, 0.005, -(dz1 - dz0) + 0.01),
                  (DOOR_THICKNESS, DOOR_TOP - 0.01, 0), '<ref id="door"/>', turn)
    shapes += box("a low cabinet in the near room", (-2.9, 0, -1.9), (-1.7, 0.8, -1.3), '<ref id="wood"/>')
    shapes += box("a table in the near room", (-1.9, 0.7, 0.2), (-0.9, 0.76, 1.4), '<ref id="wood"/>')
    shapes += sphere("a glossy ball on the floor of the near room", (-1.2, 0.3, -0.8), 0.3, """<bsdf type="roughplastic">
            <rgb name="diffuseReflectance" value="0.5, 0.12, 0.1"/>
            <float name="alpha" value="0.15"/>
        </bsdf>""")
    shapes += sphere("the lamp, in the far room", LAMP, LAMP_RADIUS, f"""<emitter type="area">
            <rgb name="radiance" value="{vec((LAMP_RADIANCE, 0.9 * LAMP_RADIANCE, 0.75 * LAMP_RADIANCE))}"/>
        </emitter>""")
    return (header("Two rooms and a door ajar between them: the camera's room is lit only through the "
                   "door, by a small lamp in the other room (most of its light after bounces there).")
            + sensor((-2.8, 1.5, -1.75), (0.0, 0.7, 1.0), 62, 64)
            + diffuse("wall", (0.7, 0.7, 0.68)) + diffuse("wood", (0.45, 0.3, 0.18)) + diffuse("door", (0.6, 0.55, 0.5))
            + shapes + "</scene>\n")


def window_pane_scene():
    (x0, x1), (z0, z1), y1 = WIN_ROOM_X, WIN_ROOM_Z, WIN_ROOM_Y
    wall = '<ref id="wall"/>'
    shapes = shell((x0, x1), y1, (z0, z1), wall)
    shapes += box("right wall (+x)", (x1, 0, z0), (x1 + WALL, y1, z1), wall)
    wz0, wz1 = WINDOW_Z
    wy0, wy1 = WINDOW_Y
    left = (x0 - WALL, x0)
    shapes += box("left wall, behind the window", (left[0], 0, z0), (left[1], y1, wz0), wall)
    shapes += box("left wall, in front of the window", (left[0], 0, wz1), (left[1], y1, z1), wall)
    shapes += box("left wall, below the window", (left[0], 0, wz0), (left[1], wy0, wz1), wall)
    shapes += box("left wall, above the window", (left[0], wy1, wz0), (left[1], y1, wz1), wall)
    mid = x0 - WALL / 2
    glass = """<bsdf type="dielectric">
            <float name="intIOR" value="1.5"/>
            <float name="extIOR" value="1"/>
        </bsdf>"""
    shapes += box("the window pane, in the middle of the wall", (mid - PANE_THICKNESS / 2, wy0, wz0),
                  (mid + PANE_THICKNESS / 2, wy1, wz1), glass)
    shapes += box("a sideboard against the back wall", (-0.6, 0, -3.0), (1.4, 0.9, -2.5), '<ref id="wood"/>')
    shapes += box("a low table", (-1.3, 0.4, -1.2), (0.1, 0.45, 0.0), '<ref id="wood"/>')
    shapes += sphere("a metal ball on the table", (-0.6, 0.65, -0.6), 0.2, """<bsdf type="roughconductor">
            <string name="material" value="Au"/>
            <float name="alpha" value="0.2"/>
        </bsdf>""")
    shapes += f"""
    <!-- the sky: seen only through the pane -->
    <emitter type="constant">
        <rgb name="radiance" value="{vec(SKY)}"/>
    </emitter>
"""
    return (header("A closed room lit by a uniform sky through a window pane of dielectric glass; "
                   "the camera looks away from the window.")
            + sensor((2.2, 1.6, 2.8), (0.3, 0.3, -3.0), 60, 64)
            + diffuse("wall", (0.72, 0.7, 0.66)) + diffuse("wood", (0.42, 0.28, 0.16))
            + shapes + "</scene>\n")


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes")
    for name, text in (("door-ajar", door_ajar_scene()), ("window-pane", window_pane_scene())):
        os.makedirs(os.path.join(out, name), exist_ok=True)
        write_text(os.path.join(out, name, "scene.xml"), text)
        print(os.path.join(out, name, "scene.xml"))


if __name__ == "__main__":
    main()
