#!/usr/bin/env python3
"""The Debian package as a user gets it: built by CPack, judged by lintian, and run from its
own files with the source and build trees out of sight.

    check_package.py BUILD_DIR SOURCE_DIR WORK_DIR

1. `cpack` makes the .deb from the build (what `make package` does).
2. Its control data: the name, the libraries dpkg-shlibdeps found in the binaries, Python 3.11
   pinned for the compiled module, postinst, the limits.d file as a conffile.
3. Its files: the command, the workbench in FreeCAD's system Mod folder, the compiled module in
   dist-packages (not /usr/share), the data, the udev rule (uaccess, never world-writable);
   no Python caches, nothing writable by others.
4. lintian: no error.
5. Unpacked with dpkg-deb -x into a temporary root and run there, inside a mount namespace whose
   tmpfs hides the source and build trees (root only; otherwise said and run without): the
   command finds its sample parts, arm model and layouts under <root>/usr/share/hapticgrasp,
   prints the rule it installs, records a session and reports it (the report runs the
   installed workbench's Python over the installed compiled module); FreeCAD (freecadcmd) loads
   the installed workbench from a Mod folder and its grasp tests pass; the real GUI under Xvfb
   lists and activates it (its conventions tests).
Exits 0 when all hold, 1 with what failed.
"""
import glob
import json
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import time

BUILD, SOURCE, WORK = (os.path.realpath(p) for p in sys.argv[1:4])
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)
    return ok


def run(cmd, timeout=300, env=None, hide=False):
    """Runs cmd; with hide, in a mount namespace where tmpfs covers the source and build trees."""
    if hide and HIDE:
        mounts = " && ".join('mount -t tmpfs hg-hidden "%s"' % d for d in HIDE)
        cmd = ["unshare", "--mount", "--propagation", "private", "sh", "-c", mounts + ' && exec "$@"', "sh"] + cmd
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env)


def hidden_trees():
    """The folders to hide (the build may lie inside the source tree), if this user can."""
    trees = [SOURCE] + ([] if BUILD.startswith(SOURCE + os.sep) else [BUILD])
    probe = subprocess.run(["unshare", "--mount", "--propagation", "private", "sh", "-c",
                            'mount -t tmpfs hg-hidden "%s" && test ! -e "%s/CMakeLists.txt"' % (SOURCE, SOURCE)],
                           capture_output=True, text=True)
    if probe.returncode != 0:
        print("note: cannot hide the source and build trees here (%s); running beside them"
              % probe.stderr.strip())
        return []
    return trees


def build_deb():
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    start = time.monotonic()
    r = run(["cpack", "--config", os.path.join(BUILD, "CPackConfig.cmake"), "-B", WORK], timeout=600)
    print("cpack: %.1f s" % (time.monotonic() - start))
    if not check(r.returncode == 0, "cpack builds the package"):
        print(r.stdout[-3000:], r.stderr[-3000:])
        sys.exit(1)
    debs = glob.glob(os.path.join(WORK, "hapticgrasp_*.deb"))
    check(len(debs) == 1, "one .deb: %s" % debs)
    print("package: %s, %.2f MB" % (os.path.basename(debs[0]), os.path.getsize(debs[0]) / 1e6))
    return debs[0]


def check_control(deb):
    field = lambda name: run(["dpkg-deb", "-f", deb, name]).stdout.strip()
    depends = field("Depends")
    print("Depends:", depends)
    check(field("Package") == "hapticgrasp", "package name hapticgrasp")
    for lib in ("libocct-foundation", "libembree", "libprotobuf", "libhidapi-hidraw", "liborocos-kdl",
                "libzstd", "libc6", "libstdc++6"):
        check(lib in depends, "Depends computed from the binaries names %s" % lib)
    for dep in ("python3 (<< 3.12)", "python3-matplotlib", "adduser"):
        check(dep in depends, "Depends has %s" % dep)
    check("freecad" in field("Recommends"), "Recommends FreeCAD")
    control = os.path.join(WORK, "control")
    run(["dpkg-deb", "-e", deb, control])
    postinst = os.path.join(control, "postinst")
    check(os.path.exists(postinst) and os.stat(postinst).st_mode & stat.S_IXUSR, "postinst is executable")
    check("addgroup --quiet --system hapticgrasp" in open(postinst).read(), "postinst makes the group hapticgrasp")
    check(open(os.path.join(control, "conffiles")).read().split() == ["/etc/security/limits.d/95-hapticgrasp.conf"],
          "the limits.d file is a conffile")


def check_contents(deb):
    listing = run(["dpkg-deb", "-c", deb]).stdout.splitlines()
    paths = {line.split()[-1].lstrip(".") for line in listing}
    modes = {line.split()[-1].lstrip("."): line.split()[0] for line in listing}
    mod = "/usr/share/freecad/Mod/HapticGrasp/"
    for path in ("/usr/bin/hapticgrasp", "/usr/lib/hapticgrasp/hapticgrasp-loader", mod + "package.xml", mod + "freecad/hapticgrasp/init_gui.py",
                 mod + "freecad/hapticgrasp/report.py", mod + "freecad/hapticgrasp/resources/icons/HapticGraspWorkbench.svg",
                 "/usr/share/hapticgrasp/parts/parts.json", "/usr/share/hapticgrasp/arms/master_arm.urdf",
                 "/usr/lib/udev/rules.d/70-hapticgrasp.rules", "/etc/security/limits.d/95-hapticgrasp.conf",
                 "/usr/share/doc/hapticgrasp/copyright", "/usr/share/doc/hapticgrasp/changelog.gz"):
        check(path in paths, "installs " + path)
    modules = [p for p in paths if "/_hapticgrasp" in p]
    check(len(modules) == 1 and modules[0].startswith("/usr/lib/python3/dist-packages/freecad/hapticgrasp/_hapticgrasp.cpython-311"),
          "the compiled module in dist-packages only: %s" % modules)
    check(not any("__pycache__" in p or p.endswith(".pyc") for p in paths), "no Python caches")
    check(not any(m[0] == "-" and m[8] == "w" for m in modes.values()), "no file writable by others")
    return paths


def check_lintian(deb):
    if not check(shutil.which("lintian") is not None, "lintian is installed (packaging/install-deps)"):
        return
    r = run(["lintian", "--no-tag-display-limit", deb], timeout=300)
    tags = [line for line in r.stdout.splitlines() if line[:2] in ("E:", "W:", "I:")]
    for line in tags:
        print("  lintian " + line)
    check(not any(line.startswith("E:") for line in tags), "lintian reports no error (%d warnings)"
          % sum(line.startswith("W:") for line in tags))


def check_cli(root):
    cli = os.path.join(root, "usr/bin/hapticgrasp")
    r = run([cli, "parts", "info", "cylinder"], hide=True)
    check(r.returncode == 0 and "faces 3" in r.stdout, "the installed command finds its sample parts: "
          + (r.stdout + r.stderr).strip().splitlines()[0] if (r.stdout + r.stderr).strip() else "(no output)")
    r = run([cli, "devices", "--udev-rule"], hide=True)
    installed = open(os.path.join(root, "usr/lib/udev/rules.d/70-hapticgrasp.rules")).read()
    rules = [line for line in installed.splitlines() if line and not line.startswith("#")]
    check(r.returncode == 0 and r.stdout == installed and rules and
          all('TAG+="uaccess"' in line and "MODE" not in line and "GROUP" not in line for line in rules),
          "the installed rule is the one the command prints from its tables, uaccess only")
    check("HID layout" in installed, "the rule grants the installed HID layouts' devices")
    out = tempfile.mkdtemp(prefix="hg-pkg-out-")  # outside the hidden trees
    mcap = os.path.join(out, "arm.mcap")
    r = run([cli, "record", "--device", "arm", "--part", "block", "--seconds", "1", "-o", mcap, "--json"], hide=True)
    ok = r.returncode == 0
    if ok:
        rec = json.loads(r.stdout)
        print("record:", json.dumps({k: rec.get(k) for k in ("device", "achieved_hz")}))
    check(ok and os.path.getsize(mcap) > 0, "the installed command drives the simulated arm (its URDF) and records "
          + ("" if ok else r.stderr.strip()[-300:]))
    html = os.path.join(out, "arm.html")
    r = run([cli, "report", mcap, "-o", html], hide=True, timeout=120)
    check(r.returncode == 0 and "<html" in open(html).read(1000) if os.path.exists(html) else False,
          "report runs the installed workbench's Python over the installed module " + r.stderr.strip()[-300:])
    shutil.rmtree(out, ignore_errors=True)


def freecad_env(root, home):
    """A throw-away HOME whose FreeCAD Mod folder links to the unpacked workbench, and whose
    user site-packages holds a .pth naming the unpacked dist-packages: the stand-in for the
    system's dist-packages, which Python always has on sys.path (FreeCAD's GUI clears
    PYTHONPATH, but processes site as every Python does)."""
    os.makedirs(os.path.join(home, ".local/share/FreeCAD/Mod"))
    os.symlink(os.path.join(root, "usr/share/freecad/Mod/HapticGrasp"), os.path.join(home, ".local/share/FreeCAD/Mod/HapticGrasp"))
    site = os.path.join(home, ".local/lib/python%d.%d/site-packages" % sys.version_info[:2])
    os.makedirs(site)
    with open(os.path.join(site, "hapticgrasp-package.pth"), "w") as f:
        f.write(os.path.join(root, "usr/lib/python3/dist-packages") + "\n")
    env = dict(os.environ, HOME=home, QTWEBENGINE_DISABLE_SANDBOX="1",
               HG_RESOURCES_DIR=os.path.join(root, "usr/share/hapticgrasp"))
    for name in ("HG_TEST_DATA_DIR", "PYTHONPATH", "PYTHONNOUSERSITE"):
        env.pop(name, None)
    return env


def check_workbench(root):
    if not check(shutil.which("freecadcmd") is not None, "FreeCAD is installed"):
        return
    home = tempfile.mkdtemp(prefix="hg-pkg-home-")
    env = freecad_env(root, home)
    probe = os.path.join(home, "probe.py")
    with open(probe, "w") as f:
        f.write("import os\nfrom freecad.hapticgrasp import _hapticgrasp, session\n"
                "print('MODULE', _hapticgrasp.__file__)\nprint('PACKAGE', session.__file__)\n"
                "loader = _hapticgrasp.loader()\n"
                "print('LOADER', loader['program'] if loader['isolated'] else 'none: ' + loader['why'])\nos._exit(0)\n")
    r = run(["timeout", "120", "freecadcmd", probe], env=env, hide=True)
    lines = dict(line.split(" ", 1) for line in r.stdout.splitlines() if line.startswith(("MODULE ", "PACKAGE ", "LOADER ")))
    check(lines.get("MODULE", "").startswith(os.path.join(root, "usr/lib/python3/dist-packages/freecad/hapticgrasp/")),
          "FreeCAD imports the compiled module from the package's dist-packages: %s" % lines.get("MODULE"))
    check(os.path.realpath(lines.get("PACKAGE", "")).startswith(os.path.join(root, "usr/share/freecad/Mod/HapticGrasp/")),
          "and the workbench's Python from its Mod folder: %s" % lines.get("PACKAGE"))
    check(lines.get("LOADER", "") == os.path.join(root, "usr/lib/hapticgrasp/hapticgrasp-loader"),
          "and loads parts in the package's loader process: %s" % lines.get("LOADER"))
    tests = "freecad.hapticgrasp.TestHapticGrasp.HapticGraspDocument"
    r = run(["timeout", "300", "freecadcmd", "-t", tests], env=env, hide=True, timeout=320)
    summary = [line for line in (r.stdout + r.stderr).splitlines() if line.startswith(("Ran ", "OK", "FAILED"))]
    check(r.returncode == 0, "the installed workbench's grasp tests pass in freecadcmd: %s" % " ".join(summary))
    if r.returncode != 0:
        print((r.stdout + r.stderr)[-4000:])
    if shutil.which("xvfb-run") and shutil.which("freecad"):
        tests = "freecad.hapticgrasp.TestHapticGraspGui.WorkbenchConventions"
        r = run(["timeout", "300", "xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", "freecad", "-t", tests],
                env=env, hide=True, timeout=320)
        summary = [line for line in (r.stdout + r.stderr).splitlines() if line.startswith(("Ran ", "OK", "FAILED"))]
        check(r.returncode == 0, "the real GUI lists and activates the installed workbench: %s" % " ".join(summary))
        if r.returncode != 0:
            print((r.stdout + r.stderr)[-4000:])
    shutil.rmtree(home, ignore_errors=True)


HIDE = hidden_trees()
deb = build_deb()
check_control(deb)
check_contents(deb)
check_lintian(deb)
root = tempfile.mkdtemp(prefix="hg-pkg-root-")
try:
    run(["dpkg-deb", "-x", deb, root])
    check_cli(root)
    check_workbench(root)
finally:
    shutil.rmtree(root, ignore_errors=True)
print("%d failed" % len(failures) if failures else "package: all checks passed")
sys.exit(1 if failures else 0)
