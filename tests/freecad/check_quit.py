#!/usr/bin/env python3
"""FreeCAD closed while haptics run (issue 14): FreeCAD exits by itself with status 0, the
session stops first (the servo joined) and its recording is complete, not cut short.
    check_quit.py FREECAD ADDON_DIR HAPTICGRASP SOURCE_DIR
"""
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile

freecad, addon, cli, source = sys.argv[1:5]
home = tempfile.mkdtemp(prefix="hg-quit-")
os.makedirs(os.path.join(home, ".local/share/FreeCAD/Mod"))
os.symlink(addon, os.path.join(home, ".local/share/FreeCAD/Mod/HapticGrasp"))
env = dict(os.environ, HOME=home, QTWEBENGINE_DISABLE_SANDBOX="1", HG_RESOURCES_DIR=os.path.join(source, "resources"))
script = os.path.join(source, "tests/freecad/quit_while_running.py")
run = subprocess.run(["timeout", "120", "xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", freecad, script],
                     env=env, capture_output=True, text=True)
out = run.stdout + run.stderr
print("\n".join(line for line in out.splitlines() if "HapticGrasp" in line or "QUIT-TEST" in line))
failures = []
if run.returncode != 0:
    failures.append("FreeCAD exited with %d (124: it did not exit)" % run.returncode)
if "QUIT-TEST running True" not in out:
    failures.append("haptics were not running when FreeCAD was closed")
recordings = glob.glob(os.path.join(home, ".local/share/HapticGrasp/reviews/*.mcap"))
if len(recordings) != 1:
    failures.append("recordings: %s" % recordings)
else:
    info = json.loads(subprocess.run([cli, "recording", "info", recordings[0], "--json"], capture_output=True,
                                     text=True).stdout)
    print("recording: complete %s, %.3f s" % (info["complete"], info["duration_s"]))
    if not info["complete"]:
        failures.append("the recording was cut short at exit")
print("\n".join(failures) or "quit while running: clean")
shutil.rmtree(home, ignore_errors=True)  # FreeCAD's settings and the recording
sys.exit(1 if failures else 0)
