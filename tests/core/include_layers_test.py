#!/usr/bin/env python3
"""Each folder of common/ includes only its own headers and those of the folders below it.

The layers, bottom first: core; image and guiding (core only); accel; render (the interfaces, the
scene and its light selection); sequence (the pass sequencer and the render driver) and scene (the
loader's description); the plugins (bsdf, light, medium, shape, texture), denoise and tools. A new include that points upwards fails here with its file and
line, before it turns into a cycle.
"""
import re
import sys
from pathlib import Path

ALLOWED = {
    "core": set(),
    "image": {"core"},
    "guiding": {"core"},
    "accel": {"core"},
    "render": {"core", "image", "guiding", "accel"},
    "sequence": {"core", "image", "guiding", "accel", "render"},
    "scene": {"core", "image", "guiding", "accel", "render"},
    "denoise": {"core", "image", "render"},
    "tools": {"core", "accel"},
}
PLUGIN_DEPS = {"core", "image", "guiding", "accel", "render", "scene"}
for plugin in ("bsdf", "light", "medium", "shape", "texture"):
    ALLOWED[plugin] = PLUGIN_DEPS

INCLUDE = re.compile(r'^\s*#\s*include\s+"tessera/([a-z_]+)/')


def violations(common: Path):
    found = []
    for top in ("include/tessera", "src"):
        root = common / top
        for path in sorted(root.rglob("*")):
            if path.suffix not in (".h", ".cpp", ".inc") or not path.is_file():
                continue
            folder = path.relative_to(root).parts[0]
            if folder not in ALLOWED:
                found.append(f"{path}: folder '{folder}' has no layer in this test")
                continue
            for number, line in enumerate(path.read_text().splitlines(), 1):
                m = INCLUDE.match(line)
                if m and m.group(1) != folder and m.group(1) not in ALLOWED[folder]:
                    found.append(f"{path}:{number}: {folder}/ includes {m.group(1)}/, a layer above it")
    return found


def main():
    common = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2] / "common"
    found = violations(common)
    for v in found:
        print(v)
    print(f"{len(found)} include(s) against the layering of {common}")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
