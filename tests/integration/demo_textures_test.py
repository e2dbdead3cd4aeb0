#!/usr/bin/env python3
"""The demo scene's textures in the repository are exactly what scripts/make_demo_textures.py writes."""
import filecmp
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
committed = os.path.join(ROOT, "scenes", "demo", "textures")
with tempfile.TemporaryDirectory() as out:
    subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "make_demo_textures.py"), out], check=True,
                   stdout=subprocess.DEVNULL)
    names = sorted(os.listdir(out))
    bad = [n for n in names if not filecmp.cmp(os.path.join(out, n), os.path.join(committed, n), shallow=False)]
    extra = sorted(set(os.listdir(committed)) - set(names))
if bad or extra or not names:
    sys.exit(f"scenes/demo/textures differs from the script's output: {bad}; not made by it: {extra}")
print("demo textures:", ", ".join(names), "as the script makes them")
