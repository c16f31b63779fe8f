#!/usr/bin/env python3
"""The session verbs end to end, as a user runs them:

    check_session.py <hapticgrasp> <work dir>

record (the real servo thread, scripted hand) -> recording info (complete; the parts, the
topics) -> replay --check (bit-identical, exit 0) -> report (one self-contained HTML page
with its plots and the manipulation) -> the reference reader (@mcap/core, when installed)
reads the recorder's file with CRCs checked and counts what `recording info` counts ->
a copy cut short still informs (exit 0, complete false) -> bench servo --record adds its
"recording" figures. Prints the figures it reads.
"""
import json
import os
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
MCAP_TESTS = os.path.join(os.path.dirname(HERE), "mcap")


def run(*args, check=True):
    p = subprocess.run(list(args), capture_output=True, text=True)
    if check and p.returncode != 0:
        raise SystemExit(f"{' '.join(args)}: exit {p.returncode}\n{p.stdout}\n{p.stderr}")
    return p


def expect(condition, what):
    if not condition:
        raise SystemExit("FAILED: " + what)
    print("ok:", what)


def main():
    cli, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    mcap = os.path.join(work, "session.mcap")
    if os.path.exists(mcap):
        os.remove(mcap)

    rec = json.loads(run(cli, "record", "--device", "scripted", "--part", "block", "--seconds", "3",
                         "-o", mcap, "--json").stdout)["recording"]
    print("record:", json.dumps(rec))
    expect(rec["dropped_records"] == 0 and rec["error"] == "", "nothing dropped, no error")

    info = json.loads(run(cli, "recording", "info", mcap, "--json").stdout)
    print("info:", json.dumps({k: info[k] for k in ("complete", "duration_s", "messages", "bytes", "topics")}))
    expect(info["complete"], "the recording is complete")
    expect(info["parts"] == ["block"], "the part is named")
    expect(info["topics"]["/hapticgrasp/tick"] == rec["ticks"], "every tick is in the file")
    expect(info["dropped_records"] == 0, "the file says nothing was dropped")
    for topic in ("/tf", "/scene/parts", "/scene/hand", "/hapticgrasp/events"):
        expect(topic in info["topics"], "the file has " + topic)
    expect(2.5 < info["duration_s"] < 3.6, "about three seconds long")

    replay = run(cli, "replay", mcap, "--check", "--json")
    check = json.loads(replay.stdout)
    print("replay:", json.dumps(check))
    expect(replay.returncode == 0 and check["ticks"] == rec["ticks"], "replay re-ran every tick")
    expect(check["state_mismatches"] == 0 and check["max_force_diff_N"] == 0 and check["max_pose_diff_m"] == 0,
           "replay is bit-identical")

    html = os.path.join(work, "report.html")
    began = time.monotonic()
    run(cli, "report", mcap, "-o", html)
    print("report: %.2f s, %d bytes" % (time.monotonic() - began, os.path.getsize(html)))
    page = open(html, encoding="utf-8").read()
    expect(page.count("data:image/png;base64,") >= 4, "the report embeds its plots")
    expect("Manipulations" in page and "<td>block</td>" in page, "the report lists the block's manipulation")
    expect("src='http" not in page and 'src="http' not in page, "the report is self-contained")

    cut = os.path.join(work, "cut.mcap")
    with open(mcap, "rb") as f:
        data = f.read()
    with open(cut, "wb") as f:
        f.write(data[: len(data) * 2 // 3])
    short = json.loads(run(cli, "recording", "info", cut, "--json").stdout)
    print("cut short:", json.dumps({k: short[k] for k in ("complete", "duration_s", "last_good_s", "warnings")}))
    expect(not short["complete"] and 0 < short["last_good_s"] < info["duration_s"], "a cut file says how much it kept")
    bad = run(cli, "replay", os.path.join(work, "missing.mcap"), check=False)
    expect(bad.returncode == 2 and "hapticgrasp:" in bad.stderr, "a missing file gets one clear line")

    node = shutil.which("node")
    if node and os.path.isdir(os.path.join(MCAP_TESTS, "node_modules", "@mcap", "core")):
        ref = run(node, os.path.join(MCAP_TESTS, "validate.mjs"), mcap)
        got = json.loads(ref.stdout.splitlines()[0])
        print("reference reader:", json.dumps(got))
        expect(got["messages"] == info["messages"] and got["topics"] == info["topics"],
               "@mcap/core reads the recording, CRCs checked, with the same counts")
    else:
        print("reference reader: not installed here (packaging/install-deps installs it)")

    bench = json.loads(run(cli, "bench", "servo", "--device", "scripted", "--seconds", "1",
                           "--record", os.path.join(work, "bench.mcap"), "--json").stdout)
    expect("recording" in bench and bench["recording"]["messages"] > 1000, "bench servo --record reports its recording")
    print("bench servo --record:", json.dumps(bench["recording"]), "compute p99 %.2f us" % bench["compute_us"]["p99"])


if __name__ == "__main__":
    main()
