#!/usr/bin/env python3
"""A short soak (the CI run of `hapticgrasp soak`): the real servo thread at 2 kHz over the
sample parts with both methods, a wandering hand and injected faults, recorded, a floor and
part-to-part contact in every other pair of segments. Checks the JSON contract and what the
soak promises: every fault of every kind injected and handled, no NaN or unbounded output,
no servo-thread allocation, the recordings written without a drop, the part kept out of
the floor.
Memory growth is printed, not judged here (a 30 s run has no warm round to grow from; the
60-minute figure is README's).
    check_soak.py HAPTICGRASP [MINUTES]
"""
import json
import subprocess
import sys

cli, minutes = sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "0.5"
run = subprocess.run([cli, "soak", "--minutes", minutes, "--json"], capture_output=True, text=True, timeout=600)
print(run.stdout, run.stderr)
r = json.loads(run.stdout)
for key in ("ticks", "nan_outputs", "allocations", "faults_injected", "faults_handled", "rss_growth_bytes",
            "max_period_err_us"):
    assert key in r, "missing " + key
failures = []
if r["nan_outputs"] != 0 or r["unbounded_outputs"] != 0:
    failures.append("outputs not finite or beyond the spec")
if r["allocations"] != 0:
    failures.append("the servo thread allocated %s times" % r["allocations"])
for kind, f in r["faults"].items():
    if f["injected"] == 0:
        failures.append("no %s fault injected" % kind)
    if f["handled"] != f["injected"]:
        failures.append("%s: %d of %d handled" % (kind, f["handled"], f["injected"]))
if r["segments"] < 4 or r["grasps"] == 0 or r["lifts"] == 0:
    failures.append("the hand did not grasp and lift through every part and method")
contact = r["contact"]
if contact["segments"] < 2:
    failures.append("part-to-part contact in %d segments, fewer than 2" % contact["segments"])
if not 0 <= contact["max_penetration_m"] < 1e-4:
    failures.append("the part went %g m into the floor" % contact["max_penetration_m"])
if r["ticks"] < 0.8 * 2000 * 60 * float(minutes):
    failures.append("ticks %d, fewer than 80%% of the rate" % r["ticks"])
if r["recording"]["bytes"] == 0 or r["recording"]["error"]:
    failures.append("recording: %s" % r["recording"])
if (run.returncode == 0) != r["passed"]:
    failures.append("exit code %d disagrees with passed %s" % (run.returncode, r["passed"]))
print("\n".join(failures) or "soak: every fault handled")
sys.exit(1 if failures else 0)
