#!/usr/bin/env python3
"""`hapticgrasp parts info` (or another verb) on broken copies of a file: a result or one
clear error line.

Makes the copies (make_hostile.py, seeded) of SOURCE in WORK_DIR, and for a recording also
copies whose attached parts are broken (hostile_recording.py), and runs the command on each. Every run must end by itself within 10 s (issue 14's budget), not by a signal, with
exit code 0, or 1 or 2 and exactly one line on stderr that starts with "hapticgrasp: " and
names the file; its peak resident memory must stay under the bound. Prints one line per
copy.

Usage: check_hostile.py HAPTICGRASP WORK_DIR SOURCE [MAX_RSS_MIB [VERB...]]   (VERB: parts info)
"""
import os
import pathlib
import signal
import subprocess
import sys
import tempfile
import threading
import time

import hostile_recording
import make_hostile

BUDGET_S = 10  # the requirement: a verdict within 10 s of asking
GRACE_S = 20   # past the budget, this script ends the run itself (and fails it)


def run(command):
    """Exit status, stderr text, seconds and peak RSS (MiB, with the command's children)."""
    with tempfile.TemporaryFile() as err:
        start = time.monotonic()
        proc = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=err)
        killer = threading.Timer(BUDGET_S + GRACE_S, proc.kill)
        killer.start()
        _, status, usage = os.wait4(proc.pid, 0)
        killer.cancel()
        proc.returncode = 0  # reaped by wait4: keep Popen from waiting again
        seconds = time.monotonic() - start
        err.seek(0)
        return status, err.read().decode(errors="replace"), seconds, usage.ru_maxrss / 1024


def verdict(status, stderr, seconds, rss_mib, max_rss_mib, file_name):
    """What is wrong with a run, or None."""
    if os.WIFSIGNALED(status):
        return f"killed by {signal.Signals(os.WTERMSIG(status)).name}"
    if seconds > BUDGET_S:
        return f"took {seconds:.1f} s (budget {BUDGET_S} s)"
    if rss_mib > max_rss_mib:
        return f"peak RSS {rss_mib:.0f} MiB (bound {max_rss_mib} MiB)"
    code = os.WEXITSTATUS(status)
    lines = stderr.splitlines()
    if code == 0:
        return None
    if code not in (1, 2):
        return f"exit code {code}"
    if len(lines) != 1 or not lines[0].startswith("hapticgrasp: "):
        return f"exit code {code} without exactly one 'hapticgrasp: ' line: {stderr!r:.300}"
    if file_name not in lines[0]:
        return f"the error does not name the file: {lines[0]!r:.300}"
    return None


def main(hapticgrasp, work_dir, source, max_rss_mib=1024, *verb):
    source, work_dir = pathlib.Path(source), pathlib.Path(work_dir)
    copies = make_hostile.make_copies(work_dir, [source])
    if source.suffix == ".mcap":
        copies += hostile_recording.make_copies(work_dir, source)
    failures = 0
    for copy in copies:
        status, stderr, seconds, rss = run([hapticgrasp, *(verb or ("parts", "info")), str(copy)])
        wrong = verdict(status, stderr, seconds, rss, int(max_rss_mib), copy.name)
        failures += wrong is not None
        outcome = "result" if os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0 else stderr.strip()[:160]
        print(f"{'FAIL' if wrong else 'ok  '} {copy.name}: {seconds:.2f} s, {rss:.0f} MiB: {wrong or outcome}")
    print(f"{len(copies) - failures} passed, {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    sys.exit(main(*sys.argv[1:]))
