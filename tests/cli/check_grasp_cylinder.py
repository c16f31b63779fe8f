#!/usr/bin/env python3
"""`hapticgrasp experiment grasp-cylinder --json`: the paper's claims hold in the output —
the Fig. 6 state sequence, a continuous vertical wrist force at lift, and the moment of
an eccentric grasp equal to M g times the lever arm."""
import json
import subprocess
import sys

r = json.loads(subprocess.run([sys.argv[1], "experiment", "grasp-cylinder", "--json"], check=True,
                              capture_output=True, text=True).stdout)
for key in ("transitions", "weight_N", "force_jump_at_lift_N", "max_force_N", "initial_pose", "final_pose",
            "eccentric_moment_Nm", "expected_eccentric_moment_Nm"):
    assert key in r, key
states = [(t["from"], t["to"]) for t in r["transitions"]]
expected = [("FREE", "INDEX CONTACT"), ("INDEX CONTACT", "FREE"), ("FREE", "THUMB CONTACT"),
            ("THUMB CONTACT", "GRASP"), ("GRASP", "MANIPULATE"), ("MANIPULATE", "FREE")]
assert states[:6] == expected, states
assert abs(r["weight_N"] - 2.0 * 9.80665) < 1e-9, r["weight_N"]
assert r["force_jump_at_lift_N"] < 0.01 * r["weight_N"], r["force_jump_at_lift_N"]
assert abs(r["eccentric_moment_Nm"] - r["expected_eccentric_moment_Nm"]) < 0.01 * r["expected_eccentric_moment_Nm"]
moved = [a - b for a, b in zip(r["final_pose"]["position_m"], r["initial_pose"]["position_m"])]
assert max(abs(m) for m in moved) > 0.05, moved  # put down somewhere new
print("grasp-cylinder:", len(states), "transitions; jump at lift", r["force_jump_at_lift_N"], "N")
