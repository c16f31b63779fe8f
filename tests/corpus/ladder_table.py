#!/usr/bin/env python3
"""The README's corpus table: for every part of corpus.json, what `hapticgrasp parts info`
says (its back end and why, its load time) and what the speed/accuracy ladder measures for
that back end (`bench penetration --part FILE --backends B --json`, default counts: 2000
random points, 10,000 path ticks, 1000 of them checked against the reference).

    python3 tests/corpus/ladder_table.py build/plugin/cli/hapticgrasp > table.md
"""
import json
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def short_types(counts):
    names = {"Plane": "plane", "Cylinder": "cyl", "Cone": "cone", "Sphere": "sphere", "Toroid": "torus",
             "Torus": "torus", "SurfaceOfRevolution": "revolution", "SurfaceOfExtrusion": "extrusion",
             "OffsetSurface": "offset", "BSplineSurface": "B-spline", "BezierSurface": "Bezier",
             "RectangularTrimmedSurface": "trimmed"}
    return ", ".join("%s %d" % (names.get(k, k), v) for k, v in sorted(counts.items(), key=lambda kv: -kv[1]))


def main():
    cli = sys.argv[1]
    parts = json.load(open(os.path.join(HERE, "corpus.json")))
    print("| part | faces | surfaces | load s | back end (why) | build s | max err m | sign err "
          "| coherent p50 / p99 µs | random p50 µs | vs ref | fallback |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for p in parts:
        path = os.path.join(HERE, p["file"])
        info = subprocess.run([cli, "parts", "info", path], capture_output=True, text=True).stdout
        reason = re.search(r"back end: (.*)", info).group(1)
        load = float(re.search(r"load ([0-9.]+) s", info).group(1))
        backend = reason.split(":")[0].split()[0]
        rung = {"analytic": "analytic", "mesh": "mesh", "field": "field"}.get(backend, "exact")
        out = subprocess.run([cli, "bench", "penetration", "--part", path, "--backends", rung, "--json"],
                             capture_output=True, text=True).stdout
        result = json.loads(out)
        rungs = result["backends"]
        ref = rungs[0]
        # mesh and field run at two settings: the finer one is what the part gets
        r = [b for b in rungs if b["name"] == rung][-1]
        ratio = ref["random"]["p50_us"] / max(r["random"]["p50_us"], 1e-9)
        fallback = 100.0 * r.get("fallback_queries", 0) / max(1, r["queries"])
        print("| %s | %d | %s | %.3f | %s | %.3f | %.1e | %d | %.2f / %.2f | %.2f | %.0f× | %.2f%% |" % (
            p["name"], p["faces"], short_types(p["surfaces"]), load, reason.replace("|", "/"), r["build_s"],
            r["max_dist_err_m"], r["sign_errors"], r["coherent"]["p50_us"], r["coherent"]["p99_us"],
            r["random"]["p50_us"], ratio, fallback))
        sys.stdout.flush()


if __name__ == "__main__":
    main()
