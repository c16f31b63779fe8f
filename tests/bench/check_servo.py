#!/usr/bin/env python3
"""Smoke run of `hapticgrasp bench servo --json`: the real thread at the real rate. Checks
the schema, that the servo thread allocated nothing, and that the scripted hand grasped
and lifted the part; the rates and timings are printed, never asserted."""
import json
import subprocess
import sys

r = json.loads(subprocess.run([sys.argv[1], "bench", "servo", "--rate", "2000", "--seconds", "1", "--json"],
                              check=True, capture_output=True, text=True).stdout)
for key in ("target_hz", "achieved_hz", "scheduler", "period_err_us", "compute_us", "overruns", "allocations_in_loop"):
    assert key in r, key
for key in ("p50", "p99", "max"):
    assert key in r["period_err_us"] and key in r["compute_us"], key
assert r["allocations_in_loop"] == 0, r["allocations_in_loop"]
assert r["grasps"] >= 1 and r["lifts"] >= 1, r
assert r["watchdog_trips"] == 0, r
print(f"servo: {r['achieved_hz']:.0f} Hz, {r['scheduler']}, compute p99 {r['compute_us']['p99']:.2f} us")
