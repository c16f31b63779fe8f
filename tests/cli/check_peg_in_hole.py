#!/usr/bin/env python3
"""`hapticgrasp experiment peg-in-hole --json`: the schema of issue 15 and what must hold
whatever the machine's load: the peg enters its hole with 0.1 mm diametral clearance, the
strike at 1 m/s does not pass the 0.5 mm plate, and penetration in contact stays within
0.05 mm. Compute time is printed, never judged (a benchmark, not a timed test)."""
import json
import subprocess
import sys

out = subprocess.run([sys.argv[1], "experiment", "peg-in-hole", "--json"], capture_output=True, text=True, timeout=120)
if out.returncode != 0:
    sys.exit("experiment peg-in-hole failed: %s" % out.stderr)
r = json.loads(out.stdout)
for key in ("insertion", "strike", "compute_us", "rate_hz"):
    assert key in r, key
i, s, c = r["insertion"], r["strike"], r["compute_us"]
assert {"inserted", "clearance_m", "max_penetration_m", "max_force_N"} <= set(i), i
assert {"speed_m_s", "wall_m", "tunnelled", "max_penetration_m"} <= set(s), s
assert {"p50", "p99"} <= set(c), c
assert i["inserted"] is True, i
assert abs(i["clearance_m"] - 1e-4) < 1e-12, i
assert 0 <= i["max_penetration_m"] <= 5e-5, i
assert 0 < i["max_force_N"] < 100, i
assert s["speed_m_s"] >= 1.0 and abs(s["wall_m"] - 5e-4) < 1e-12, s
assert s["tunnelled"] is False, s
assert 0 <= s["max_penetration_m"] <= 5e-5, s
assert r["rate_hz"] >= 2000, r
assert 0 < c["p50"] <= c["p99"], c
print("peg-in-hole: inserted, strike held; penetration %.1f / %.1f um; compute p50 %.1f us, p99 %.1f us at %.0f Hz"
      % (1e6 * i["max_penetration_m"], 1e6 * s["max_penetration_m"], c["p50"], c["p99"], r["rate_hz"]))
