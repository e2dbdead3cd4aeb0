#!/usr/bin/env python3
"""CI smoke run of bench/convergence.sh (docs/performance.md): cornell-box at its reference's
256x256, spp 1 and 4, every strategy with and without path guiding, into a temporary folder.
Expected: the script exits 0; the CSV has the header and exactly the rows bsdf/nee/mis (each plain,
then +guiding) x 1/4 spp in that order, with finite positive
relMSE and times, a mean ratio within [0.5, 2] and a noise estimate that is infinite at 1 spp (no
variance from one sample) and finite at 4 (a guided image holds the 3 samples after training); the
SVG parses as XML with two panels' polylines per series. Missing scene/reference files: exit 77 (skip) locally, failure under CI=true."""
import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

SCENE = "cornell-box"


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True, help="the tessera binary")
    ap.add_argument("--source", required=True, help="the project root (bench/convergence.sh)")
    ap.add_argument("--shared", required=True, help="../shared")
    args = ap.parse_args()

    needed = [os.path.join(args.shared, "scenes", SCENE, "scene.xml"),
              os.path.join(args.shared, "references", SCENE, "reference.exr"),
              os.path.join(args.shared, "references", SCENE, "README.md")]
    missing = [p for p in needed if not os.path.exists(p)]
    if missing:
        if os.environ.get("CI") == "true":
            fail("required file missing: " + ", ".join(missing))
        print("skip: file missing: " + ", ".join(missing))
        sys.exit(77)

    with tempfile.TemporaryDirectory() as out:
        env = dict(os.environ, TESSERA=args.cli, CONV_SCENES=SCENE, CONV_SPP="1,4", CONV_OUT=out,
                   CONV_STRATEGIES="bsdf,nee,mis", CONV_GUIDING="off,on", CONV_THREADS="2")
        r = subprocess.run(["bash", os.path.join(args.source, "bench", "convergence.sh"), "unused", "0"],
                           env=env, capture_output=True, text=True, timeout=300)
        print(r.stdout)
        print(r.stderr, file=sys.stderr)
        if r.returncode != 0:
            fail("convergence.sh exited %d" % r.returncode)

        with open(os.path.join(out, SCENE + ".csv"), newline="") as f:
            rows = list(csv.reader(f))
        header = ["strategy", "spp", "seconds", "relmse", "relmse_trim", "mse", "mean_ratio", "noise_estimate"]
        if rows[0] != header:
            fail("CSV header %r" % rows[0])
        got = [(row[0], int(row[1])) for row in rows[1:]]
        want = [(s + g, n) for s in ("bsdf", "nee", "mis") for g in ("", "+guiding") for n in (1, 4)]
        if got != want:
            fail("CSV rows %r, expected %r" % (got, want))
        for row in rows[1:]:
            v = dict(zip(header, row))
            seconds, relmse, trim, ratio, noise = (float(v[k]) for k in
                                                   ("seconds", "relmse", "relmse_trim", "mean_ratio", "noise_estimate"))
            if not (seconds > 0 and math.isfinite(seconds)):
                fail("seconds %r in %r" % (seconds, row))
            if not (relmse > 0 and math.isfinite(relmse) and 0 < trim <= relmse):
                fail("relmse %r / trimmed %r in %r" % (relmse, trim, row))
            if not 0.5 <= ratio <= 2.0:
                fail("mean ratio %r in %r" % (ratio, row))
            if (int(v["spp"]) == 1) != math.isinf(noise):
                fail("noise estimate %r in %r" % (noise, row))

        root = ET.parse(os.path.join(out, SCENE + ".svg")).getroot()
        if root.tag != "{http://www.w3.org/2000/svg}svg":
            fail("SVG root is %r" % root.tag)
        lines = root.findall(".//{http://www.w3.org/2000/svg}polyline")
        if len(lines) != 12:
            fail("%d polylines in the SVG, expected 12" % len(lines))
        for line in lines:
            if len(line.get("points", "").split()) != 2:
                fail("a polyline without its two points: %r" % line.get("points"))
        txt = open(os.path.join(out, SCENE + ".txt")).read()
        if txt.count("time_to_target") != 12:
            fail("expected 12 time_to_target lines in the output (2 targets x 6 series)")
    print("ok")


if __name__ == "__main__":
    main()
