#!/usr/bin/env python3
"""Smoke run of `hapticgrasp bench scene`: the public AS1 assembly 56 times (1,008 parts)
on the real servo thread. Checks the JSON's schema and what must hold whatever the
machine's load: every part modelled from 5 distinct shapes, none failed, the target part
touched through its own model, every model built, no allocation in the loop. Then two
copies built apart (10 models), each model loaded as the workbench loads it, in the loader process:
every one built there. Never speed."""
import json
import subprocess
import sys

cli, step = sys.argv[1], sys.argv[2]
out = subprocess.run([cli, "bench", "scene", "--part", step, "--copies", "56", "--seconds", "1", "--json"],
                     capture_output=True, text=True, timeout=300)
if out.returncode != 0:
    sys.exit("bench scene failed: %s" % out.stderr)
r = json.loads(out.stdout)
keys = {"parts", "unique_models", "failed_models", "read_s", "start_s", "first_touch_s", "all_built_s",
        "memory_bytes", "compute_us", "period_err_us", "achieved_hz", "allocations_in_loop", "scheduler", "target",
        "load", "loader_processes"}
missing = keys - set(r)
assert not missing, "missing keys %s" % missing
assert set(r["compute_us"]) == {"p50", "p99", "max"}, r["compute_us"]
assert r["parts"] == 1008, r["parts"]
assert r["unique_models"] == 5, r["unique_models"]
assert r["failed_models"] == 0, r
assert r["first_touch_s"] > 0, "the target part was never touched through its own model: %s" % r
assert r["all_built_s"] > 0, r
assert r["start_s"] < r["first_touch_s"], r
assert r["allocations_in_loop"] == 0, r
assert (r["load"], r["loader_processes"]) == ("shape", 0), r
print("bench scene: %d parts, %d models, start %.3f s, first touch %.3f s, all built %.3f s, compute p99 %.2f us"
      % (r["parts"], r["unique_models"], r["start_s"], r["first_touch_s"], r["all_built_s"], r["compute_us"]["p99"]))

out = subprocess.run([cli, "bench", "scene", "--part", step, "--copies", "2", "--no-sharing", "--load", "loader",
                      "--seconds", "1", "--json"], capture_output=True, text=True, timeout=300)
if out.returncode != 0:
    sys.exit("bench scene --load loader failed: %s" % out.stderr)
r = json.loads(out.stdout)
assert r["load"] == "loader", r
assert (r["parts"], r["unique_models"], r["failed_models"]) == (36, 10, 0), r   # 5 shapes a copy
assert r["loader_processes"] == 1, r   # one worker: one helper, part after part
assert r["first_touch_s"] > 0 and r["all_built_s"] > 0, r
assert r["allocations_in_loop"] == 0, r
print("bench scene --load loader: %d models in the loader process (%d processes), all built %.3f s"
      % (r["unique_models"], r["loader_processes"], r["all_built_s"]))
