#!/usr/bin/env python3
"""Smoke run of `hapticgrasp bench contact`: a ~500-face part carried onto and into two
copies of itself. Checks the JSON's schema and what must hold whatever the load: contact
was made, penetration stayed within 0.05 mm. Prints the compute figures; never judges speed."""
import json
import subprocess
import sys

cli, part = sys.argv[1], sys.argv[2]
out = subprocess.run([cli, "bench", "contact", "--part", part, "--seconds", "2", "--json"],
                     capture_output=True, text=True, timeout=300)
if out.returncode != 0:
    sys.exit("bench contact failed: %s" % out.stderr)
r = json.loads(out.stdout)
keys = {"part", "faces", "shell_points", "rate_hz", "ticks", "compute_us", "mean_queries", "max_contacts",
        "max_penetration_m", "max_force_N"}
assert keys <= set(r), "missing keys %s" % (keys - set(r))
assert set(r["compute_us"]) == {"p50", "p99", "max"}, r["compute_us"]
assert r["max_contacts"] > 0, r
assert r["max_penetration_m"] <= 5e-5, r
print("bench contact: %d faces, %d shell points; compute p50 %.1f us, p99 %.1f us; %.1f queries a tick"
      % (r["faces"], r["shell_points"], r["compute_us"]["p50"], r["compute_us"]["p99"], r["mean_queries"]))
