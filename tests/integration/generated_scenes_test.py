#!/usr/bin/env python3
"""Scenes the repository generates are exactly what their script writes:
    generated_scenes_test.py SCRIPT SCENE...   (scripts/SCRIPT, writing scenes/SCENE/...)"""
import filecmp
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT, SCENES = sys.argv[1], tuple(sys.argv[2:])


def files_under(top):
    return sorted(os.path.relpath(os.path.join(d, n), top) for d, _, names in os.walk(top) for n in names)


with tempfile.TemporaryDirectory() as out:
    subprocess.run([sys.executable, os.path.join(ROOT, "scripts", SCRIPT), out], check=True,
                   stdout=subprocess.DEVNULL)
    names, bad, extra = [], [], []
    for scene in SCENES:
        made, committed = os.path.join(out, scene), os.path.join(ROOT, "scenes", scene)
        written = files_under(made)
        names += [os.path.join(scene, n) for n in written]
        bad += [os.path.join(scene, n) for n in written
                if not os.path.isfile(os.path.join(committed, n))
                or not filecmp.cmp(os.path.join(made, n), os.path.join(committed, n), shallow=False)]
        if os.path.isdir(committed):
            extra += [os.path.join(scene, n) for n in sorted(set(files_under(committed)) - set(written))]
    unexpected = sorted(set(os.listdir(out)) - set(SCENES))
if bad or extra or unexpected or not names:
    sys.exit(f"scenes {', '.join(SCENES)} differ from {SCRIPT}'s output: {bad}; not made by it: "
             f"{extra}; the script also wrote: {unexpected}")
print(f"{SCRIPT}:", ", ".join(names), "as the script makes them")
