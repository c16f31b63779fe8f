#!/usr/bin/env python3
"""`hapticgrasp doctor` as users run it:

    check_doctor.py <hapticgrasp> <workbench package dir>

- the JSON names every area with a verdict, a reason, and a fix exactly when the verdict
  is a problem; the problems list is those areas;
- the workbench counts as installed and importable only when it is: with a HOME whose
  FreeCAD Mod folder links the built package, FreeCAD's own Python imports the module
  from it; with an empty HOME it is not installed and the fix says how;
- as root, the same command run as an unprivileged user (setpriv, no capabilities, the
  limits a login without the group gets) is refused real time and told to join the group.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

AREAS = {"realtime": "granted", "memory_lock": "granted", "hidraw": "ok", "freecad": "found",
         "addon": "imports", "audio": "available"}


def doctor(exe, home, prefix=()):
    env = dict(os.environ, HOME=home)
    p = subprocess.run(list(prefix) + [exe, "doctor", "--json"], capture_output=True, text=True, env=env, timeout=300)
    if p.returncode != 0:
        raise SystemExit("doctor: exit %d\n%s\n%s" % (p.returncode, p.stdout, p.stderr))
    return json.loads(p.stdout)


def check_shape(d):
    for area, verdict in AREAS.items():
        f = d[area]
        assert isinstance(f[verdict], bool), (area, f)
        assert f["why"], (area, f)
        assert bool(f.get("fix")) == (not f[verdict]), (area, f)   # a fix exactly for a problem
    bad = [a for a, v in AREAS.items() if not d[a][v] and not (a == "addon" and not d["freecad"]["found"])]
    assert len(d["problems"]) == len(bad), (d["problems"], bad)


def main():
    exe, package = sys.argv[1], os.path.realpath(sys.argv[2])
    work = tempfile.mkdtemp(prefix="hg-doctor-")
    os.chmod(work, 0o755)
    try:
        empty = os.path.join(work, "empty")
        os.makedirs(empty)
        d = doctor(exe, empty)
        check_shape(d)
        assert d["realtime"]["granted"] == (d["realtime"]["cap_sys_nice"] or d["realtime"]["rtprio_limit"] < 0
                                            or d["realtime"]["rtprio_limit"] >= d["realtime"]["priority"]), d["realtime"]
        if d["freecad"]["found"]:
            assert d["freecad"]["version"].startswith("0."), d["freecad"]
            if not os.path.exists("/usr/share/freecad/Mod/HapticGrasp"):
                assert not d["addon"]["installed"] and not d["addon"]["imports"], d["addon"]
                assert "Mod" in d["addon"]["fix"], d["addon"]
            linked = os.path.join(work, "linked")
            os.makedirs(os.path.join(linked, ".local/share/FreeCAD/Mod"))
            os.symlink(package, os.path.join(linked, ".local/share/FreeCAD/Mod/HapticGrasp"))
            d = doctor(exe, linked)
            check_shape(d)
            assert d["addon"]["installed"] and d["addon"]["imports"], d["addon"]
            assert os.path.realpath(d["addon"]["module"]).startswith(package + os.sep), (d["addon"], package)
            print("doctor: FreeCAD %s imports %s" % (d["freecad"]["version"], d["addon"]["module"]))
        if os.geteuid() == 0 and shutil.which("setpriv"):
            user = doctor(exe, empty, ("setpriv", "--reuid=65534", "--regid=65534", "--clear-groups",
                                       "--inh-caps=-all", "prlimit", "--rtprio=0", "--"))
            check_shape(user)
            r = user["realtime"]
            assert not r["granted"] and r["rtprio_limit"] == 0 and not r["cap_sys_nice"], r
            assert "usermod -aG hapticgrasp" in r["fix"], r
            assert any(p.startswith("real time: SCHED_FIFO refused") for p in user["problems"]), user["problems"]
            print("doctor as an unprivileged user: %s" % r["why"])
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print("doctor: ok")


if __name__ == "__main__":
    main()
