#!/usr/bin/env python3
"""Runs the CLI on every corpus file and writes baseline.md (plain Python, no FreeCAD):
    python3 tests/corpus/baseline.py [build/plugin/cli/hapticgrasp]
For each file: `parts info` (outcome, time) and `bench penetration --backends exact` against
the reference (max error, sign errors); where exact is wrong, the same with the mesh back end.
Each command under `timeout 120`. Raw outputs go to baseline.json beside it."""
import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
CLI = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "plugin", "cli", "hapticgrasp")
TIMEOUT = 120
BENCH = ["bench", "penetration", "--queries", "1000", "--ticks", "3000", "--reference-checks", "300", "--json"]
WRONG_M = 1e-6   # an exact answer further than 1 um from the reference counts as wrong


def run(args):
    t0 = time.time()
    p = subprocess.run(["timeout", str(TIMEOUT), CLI] + args, capture_output=True, text=True)
    return dict(cmd=" ".join(["timeout", str(TIMEOUT), "hapticgrasp"] + args), rc=p.returncode,
                seconds=round(time.time() - t0, 2), stdout=p.stdout[-4000:], stderr=p.stderr[-4000:])


def outcome(r):
    if r["rc"] == 124:
        return "timeout"
    if r["rc"] != 0:
        last = (r["stderr"].strip().splitlines() or ["exit %d" % r["rc"]])[-1]
        return "fails (rc %d): %s" % (r["rc"], last[:160])
    return "ok"


def bench(path, backends):
    r = run(BENCH + ["--part", path, "--backends", backends])
    r["outcome"] = outcome(r)
    if r["outcome"] == "ok":
        try:
            r["result"] = json.loads(r["stdout"][r["stdout"].index("{"):])
        except ValueError:
            r["outcome"] = "no JSON in the output"
    return r


def rung(r, name):
    for b in r.get("result", {}).get("backends", []):
        if b["name"] == name:
            return b
    return None


def main():
    if os.environ.get("BASELINE_MARKDOWN_ONLY"):   # rewrite baseline.md from baseline.json, run nothing
        with open(os.path.join(HERE, "baseline.json")) as f:
            write_markdown(json.load(f))
        return
    with open(os.path.join(HERE, "corpus.json")) as f:
        corpus = json.load(f)
    only = [n for n in os.environ.get("BASELINE_ONLY", "").split(",") if n]
    results = []
    out_json = os.path.join(HERE, "baseline.json")
    old = {}
    if only and os.path.exists(out_json):
        with open(out_json) as f:
            old = {r["name"]: r for r in json.load(f)}
    for part in corpus:
        if only and part["name"] not in only:
            results.append(old.get(part["name"], dict(name=part["name"], skipped=True)))
            continue
        path = os.path.join(HERE, part["file"])
        info = run(["parts", "info", path])
        info["outcome"] = outcome(info)
        exact = bench(path, "exact")
        entry = dict(name=part["name"], file=part["file"], faces=part["faces"], expect=part["expect"],
                     info=info, exact=exact)
        e = rung(exact, "exact")
        if e is None or e["max_dist_err_m"] > WRONG_M or e["sign_errors"] > 0:
            entry["mesh"] = bench(path, "mesh")
        results.append(entry)
        print("%-28s info %-8s %6.2fs  exact %s" % (part["name"], info["outcome"][:8], info["seconds"],
                                                   exact["outcome"] if e is None else
                                                   "max %.3g m, %d sign" % (e["max_dist_err_m"], e["sign_errors"])),
              flush=True)
    with open(out_json, "w") as f:
        json.dump(results, f, indent=1)
        f.write("\n")
    write_markdown(results)


def fmt_err(b):
    if b is None:
        return "-", "-"
    return "%.3g" % (b["max_dist_err_m"] * 1e3), str(b["sign_errors"])


def summary(results):
    done = [r for r in results if not r.get("skipped")]
    timeouts = [r["name"] for r in done if "timeout" in (r["info"]["outcome"], r["exact"]["outcome"])]
    fails = [r for r in done if r["info"]["outcome"] != "ok" and r["info"]["outcome"] != "timeout"]
    wrong, right = [], []
    for r in done:
        e = rung(r["exact"], "exact")
        if e is None:
            continue
        (wrong if e["max_dist_err_m"] > WRONG_M or e["sign_errors"] > 0 else right).append((r, e))
    out = ["", "## Summary", "",
           "%d files: %d answered by the exact back end within 1 um of the reference with no sign errors, "
           "%d answered with larger errors or sign errors, %d not loaded, %d timeouts%s." % (
               len(done), len(right), len(wrong), len(fails), len(timeouts),
               (" (" + ", ".join(timeouts) + ")") if timeouts else ""), ""]
    if fails:
        out.append("Not loaded (`parts info` and the bench both refuse the file):")
        out.append("")
        out += ["- `%s` (expect %s): %s" % (r["name"], r["expect"], r["info"]["outcome"]) for r in fails]
        out.append("")
    if wrong:
        out.append("Exact back end off the reference (max error mm, sign errors; expect):")
        out.append("")
        out += ["- `%s`: %.3g mm, %d sign errors (expect %s)" % (r["name"], e["max_dist_err_m"] * 1e3,
                                                              e["sign_errors"], r["expect"]) for r, e in wrong]
        # the finest mesh rung is off by more than 0.1 mm too: the reference may be the one that is wrong
        suspect = []
        for r, e in wrong:
            rows = [b for b in r.get("mesh", {}).get("result", {}).get("backends", []) if b["name"] == "mesh"]
            if rows and min(b["max_dist_err_m"] for b in rows) > 1e-4:
                suspect.append("`%s` (%.3g mm)" % (r["name"], min(b["max_dist_err_m"] for b in rows) * 1e3))
        if suspect:
            out += ["", "Where even the finest mesh rung is more than 0.1 mm off the reference, the reference "
                    "itself is suspect (not decided here): " + ", ".join(suspect) + "."]
    return out


def write_markdown(results):
    lines = ["# Baseline: the CLI on the corpus", "",
             "Measured when the corpus was made (branch `corpus`, Release build, 2 shared cores).",
             "Regenerate: `python3 tests/corpus/baseline.py` (raw outputs: `baseline.json`).", "",
             "Commands, each under `timeout %d`:" % TIMEOUT, "",
             "    hapticgrasp parts info FILE",
             "    hapticgrasp bench penetration --part FILE --queries 1000 --ticks 3000 --reference-checks 300 "
             "--backends exact --json",
             "    (and --backends mesh where exact is off by more than 1 um or has sign errors)", "",
             "Errors are against the `reference` rung (BRepExtrema + solid classifier), in mm; the bench "
             "reports metres.", "",
             "| part | faces | expect | parts info | info s | bench | bench s | exact max err mm | exact sign errors "
             "| mesh (deflection) max err mm / sign errors |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        if r.get("skipped"):
            continue
        e = rung(r["exact"], "exact")
        err, sign = fmt_err(e)
        mesh = "-"
        if "mesh" in r:
            rows = [b for b in r["mesh"].get("result", {}).get("backends", []) if b["name"] == "mesh"]
            mesh = "; ".join("%s: %s / %d" % (b["setting"], "%.3g" % (b["max_dist_err_m"] * 1e3), b["sign_errors"])
                             for b in rows) or r["mesh"]["outcome"]
        lines.append("| %s | %d | %s | %s | %.2f | %s | %.1f | %s | %s | %s |" % (
            r["name"], r["faces"], r["expect"], r["info"]["outcome"].replace("|", "/"), r["info"]["seconds"],
            r["exact"]["outcome"].replace("|", "/"), r["exact"]["seconds"], err, sign, mesh))
    lines += summary(results)
    with open(os.path.join(HERE, "baseline.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


main()
