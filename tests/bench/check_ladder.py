#!/usr/bin/env python3
"""Smoke run of `hapticgrasp bench penetration --json`: the schema the issue fixes, and
the accuracy the exact back end promises. Speed is printed by the benchmark, never
asserted here (a busy machine would make such a test flaky)."""
import json
import subprocess
import sys

cli, part = sys.argv[1], sys.argv[2]
out = subprocess.run([cli, "bench", "penetration", "--part", part, "--queries", "60", "--ticks", "400",
                      "--reference-checks", "40", "--json"], check=True, capture_output=True, text=True).stdout
ladder = json.loads(out)
assert ladder["part"] == part and ladder["faces"] > 0, ladder
names = [b["name"] for b in ladder["backends"]]
for required in ("reference", "exact", "mesh", "field"):
    assert required in names, f"{required} missing from {names}"
for b in ladder["backends"]:
    for key in ("setting", "build_s", "memory_bytes", "max_dist_err_m", "rms_dist_err_m", "sign_errors", "queries"):
        assert key in b, f"{key} missing in {b['name']}"
    for kind in ("random", "coherent"):
        assert b[kind]["p50_us"] > 0 and b[kind]["p99_us"] >= b[kind]["p50_us"], b
    assert b["queries"] > 0
exact = next(b for b in ladder["backends"] if b["name"] == "exact")
assert exact["max_dist_err_m"] < 1e-9, exact
assert exact["sign_errors"] == 0, exact
for b in ladder["backends"]:
    if b["name"] == "mesh":
        assert b["sign_errors"] == 0 and b["max_dist_err_m"] < 1e-3, b
print(f"ladder on {part}: {len(names)} rungs, exact max error {exact['max_dist_err_m']:.1e} m")
