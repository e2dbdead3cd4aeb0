#!/usr/bin/env python3
"""`tessera render --denoise` and `tessera denoise` as a user runs them: a small scene rendered with
--denoise writes OUT.exr (denoised, with the AOV layers) and OUT.noisy.exr (raw); `tessera denoise
OUT.noisy.exr -o AGAIN.exr` gives a file identical byte for byte to OUT.exr, for 1 and 2 threads and
also in preview mode; the raw image equals a render without --denoise; an EXR without the layers is
refused naming the file and the missing layers."""
import argparse
import filecmp
import os
import subprocess
import sys
import tempfile

SCENE = """<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="45"/>
    <transform name="to_world"><lookat origin="0,1,4" target="0,0.5,0" up="0,1,0"/></transform>
    <sampler type="sobol"><integer name="sample_count" value="8"/></sampler>
    <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="32"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0" y="0.6" z="0"/><float name="radius" value="0.6"/>
    <bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.2,0.4,0.7"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="1" y="2" z="1"/><float name="radius" value="0.3"/>
    <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape>
</scene>
"""


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def run(cmd, expect=0):
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    if r.returncode != expect:
        fail("%s exited %d (expected %d): %s%s" % (" ".join(cmd), r.returncode, expect, r.stdout, r.stderr))
    return r.stdout + r.stderr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True, help="the tessera binary")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        scene = os.path.join(tmp, "scene.xml")
        with open(scene, "w") as f:
            f.write(SCENE)
        p = lambda name: os.path.join(tmp, name)
        for mode in ("full", "preview"):
            run([args.cli, "render", scene, "--denoise", "--denoise-mode", mode, "-o", p(mode + ".exr"), "-q"])
            if not os.path.exists(p(mode + ".noisy.exr")):
                fail("--denoise wrote no %s.noisy.exr" % mode)
            for threads in ("1", "2"):
                again = p("again_%s_%s.exr" % (mode, threads))
                run([args.cli, "denoise", p(mode + ".noisy.exr"), "-o", again, "--mode", mode, "--threads", threads])
                if not filecmp.cmp(again, p(mode + ".exr"), shallow=False):
                    fail("tessera denoise of %s.noisy.exr (%s threads) differs from render --denoise" % (mode, threads))
        # The raw image is the plain render's (the PFMs hold only the image).
        run([args.cli, "render", scene, "--denoise", "-o", p("d.pfm"), "-q"])
        run([args.cli, "render", scene, "-o", p("plain.pfm"), "-q"])
        if not filecmp.cmp(p("d.noisy.pfm"), p("plain.pfm"), shallow=False):
            fail("the raw image of a --denoise render differs from a render without it")
        if filecmp.cmp(p("d.pfm"), p("plain.pfm"), shallow=False):
            fail("the denoised image equals the raw one")

        run([args.cli, "render", scene, "--aovs", "albedo,depth", "-o", p("partial.exr"), "-q"])
        out = run([args.cli, "denoise", p("partial.exr"), "-o", p("x.exr")], expect=1)
        if p("partial.exr") not in out or "missing: normal, variance, half_a, half_b" not in out:
            fail("the error for missing layers does not name the file and layers: " + out)
    print("ok: render --denoise and tessera denoise agree bit for bit; missing layers are named")


if __name__ == "__main__":
    main()
