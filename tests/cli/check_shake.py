#!/usr/bin/env python3
"""`hapticgrasp experiment shake --json --plot F.svg`: the schema of issue 6, the paper's
finding (the proposed method keeps grasping force and finger distance steadier than the
conventional one), eq 12's distance for the proposed method, and a plot that is SVG."""
import json
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

work = tempfile.TemporaryDirectory(prefix="hg-shake-")  # removed at exit
svg = os.path.join(work.name, "shake.svg")
r = json.loads(subprocess.run([sys.argv[1], "experiment", "shake", "--json", "--plot", svg], check=True,
                              capture_output=True, text=True).stdout)
conv, prop = r["methods"]["conventional"], r["methods"]["proposed"]
for m in (conv, prop):
    for key in ("grasp_force_mean_N", "grasp_force_std_N", "distance_mean_m", "distance_std_m"):
        assert key in m and m[key] == m[key], key  # present and not NaN
assert prop["grasp_force_std_N"] < conv["grasp_force_std_N"], (prop, conv)
assert prop["distance_std_m"] < conv["distance_std_m"], (prop, conv)
# Eq 12: x2 - x1 = l - 2 f_g / k_g, with l = 6 cm, k_g = 800 N/m.
expected = 0.06 - 2 * prop["grasp_force_mean_N"] / 800.0
assert abs(prop["distance_mean_m"] - expected) < 5e-4, (prop["distance_mean_m"], expected)
root = ET.parse(svg).getroot()
assert root.tag.endswith("svg"), root.tag
print("shake: proposed f_g std %.3f N vs conventional %.3f N" % (prop["grasp_force_std_N"], conv["grasp_force_std_N"]))
