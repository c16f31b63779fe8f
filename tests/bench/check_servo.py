#!/usr/bin/env python3
"""Smoke run of `hapticgrasp bench servo --part block --seconds 2 --json [extra options]`: the
real thread at the real rate, the simulated master arm (the default device) or the scripted
hand, with the two-finger method (default) or the multi-finger one (`--method multi-finger
--fingers N`), grasping and lifting the machined block (with `--contact`, standing on a floor
it is put back onto). Checks the schema, the options echoed back, that the servo thread
allocated nothing, that the hand grasped and lifted the part, and with contact that the
part met the floor and stayed out of it; the rates and timings are printed, never asserted."""
import json
import subprocess
import sys

extra = sys.argv[2:]
r = json.loads(subprocess.run([sys.argv[1], "bench", "servo", "--part", "block", "--seconds", "2", "--json"] + extra,
                              check=True, capture_output=True, text=True).stdout)
option = lambda name, default: extra[extra.index(name) + 1] if name in extra else default
for key in ("part", "device", "backend", "target_hz", "achieved_hz", "scheduler", "period_err_us", "compute_us",
            "overruns", "allocations_in_loop", "grasps", "lifts", "watchdog_trips", "method", "fingers"):
    assert key in r, key
for key in ("p50", "p99", "max"):
    assert key in r["period_err_us"] and key in r["compute_us"], key
assert r["part"] == "block" and r["device"] == option("--device", "arm"), r
assert r["method"] == option("--method", "two-finger") and r["fingers"] == int(option("--fingers", "2")), r
assert r["allocations_in_loop"] == 0, r["allocations_in_loop"]
assert r["grasps"] >= 1 and r["lifts"] >= 1, r
assert r["watchdog_trips"] == 0, r
if "--contact" in extra:  # the multi-finger put-down presses the block onto the floor
    assert r["contact_polls"] > 0, r
    assert 0 <= r["contact_max_penetration_m"] < 1e-4, r
else:
    assert r["contact_polls"] == 0, r
print(f"servo: {r['part']} ({r['backend']}), {r['device']}, {r['method']} x{r['fingers']}: {r['achieved_hz']:.0f} Hz, {r['scheduler']}, "
      f"compute p50 {r['compute_us']['p50']:.2f} us, p99 {r['compute_us']['p99']:.2f} us, "
      f"max {r['compute_us']['max']:.2f} us, overruns {r['overruns']}")
