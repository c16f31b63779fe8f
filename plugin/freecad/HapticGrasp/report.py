# -*- coding: utf-8 -*-
"""The report of a recorded design-review session: one self-contained HTML page.

    python3 -m freecad.hapticgrasp.report SESSION.mcap -o REPORT.html
                                   (what `hapticgrasp report` runs, the addon folder on PYTHONPATH)
    python3 report.py SESSION.mcap -o REPORT.html      (from the build tree's package folder)

The recording is read by the core's reader through the _hapticgrasp module
(read_session_series: one streaming pass, series reduced to bins that keep each bin's
largest value, every event exact); the plots are drawn by matplotlib (Agg, no display) and
embedded as PNG, so the page needs nothing beside itself.
"""
import argparse
import base64
import datetime
import html
import io
import json
import os
import sys


def _module():
    try:
        from . import _hapticgrasp   # imported as freecad.hapticgrasp.report
    except ImportError:   # run as a script: Python put this file's folder first on sys.path
        import _hapticgrasp
    return _hapticgrasp


def read(path):
    return json.loads(_module().read_session_series(path))


def _png(fig):
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=90, bbox_inches="tight")
    return base64.b64encode(buffer.getvalue()).decode("ascii")


def _mark_events(ax, s):
    for e in s["events"]:
        if e["fault"] or e["from"] != e["to"]:
            ax.axvline(e["time_s"], color="red" if e["fault"] else "0.8", lw=0.6, zorder=0)


def plots(s):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t = s["time_s"]
    names = ["index", "thumb", "middle", "ring", "little"]
    figures = []

    fig, ax = plt.subplots(figsize=(10, 3))
    for k, series in enumerate(s["fingertip_N"]):
        if k < 2 or any(series):
            ax.plot(t, series, lw=0.8, label=names[k])
    ax.plot(t, s["grasp_N"], lw=0.8, color="k", label="grasping force")
    _mark_events(ax, s)
    ax.set(xlabel="time [s]", ylabel="force [N]", title="Fingertip and grasping forces (largest per %.0f ms)"
           % (1000 * s["bin_width_s"]))
    ax.legend(loc="upper right", fontsize=8)
    figures.append(("Fingertip and grasping forces", _png(fig)))

    fig, ax = plt.subplots(figsize=(10, 3))
    ax.plot(t, s["wrist_force_N"], lw=0.8, label="wrist force [N]")
    ax.plot(t, s["wrist_moment_Nm"], lw=0.8, label="wrist moment [N m]")
    ax.plot(t, s["requested_N"], lw=0.6, ls=":", color="0.4", label="largest force asked, before saturation [N]")
    _mark_events(ax, s)
    ax.set(xlabel="time [s]", title="Wrist force and moment")
    ax.legend(loc="upper right", fontsize=8)
    figures.append(("Wrist force and moment", _png(fig)))

    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(10, 4), sharex=True)
    ax.plot(t, [1000 * v for v in s["travel_m"]], lw=0.8)
    ax.set(ylabel="travel [mm]", title="Part motion: how far the carried part is from where it was picked up")
    ax2.step(t, s["state"], where="post", lw=0.8)
    ax2.set_yticks(range(len(s["state_names"])))
    ax2.set_yticklabels(s["state_names"], fontsize=7)
    ax2.set(xlabel="time [s]", title="Grasp state")
    figures.append(("Part motion and grasp state", _png(fig)))

    fig, ax = plt.subplots(figsize=(10, 3))
    ax.plot(t, s["compute_us"], lw=0.8, label="compute [us]")
    ax.plot(t, s["period_error_us"], lw=0.8, label="period error [us]")
    ax.set_yscale("symlog", linthresh=10)
    ax.set(xlabel="time [s]", title="Servo timing (largest per bin)")
    ax.legend(loc="upper right", fontsize=8)
    figures.append(("Servo timing", _png(fig)))
    plt.close("all")
    return figures


def _table(headers, rows):
    out = ["<table><tr>" + "".join("<th>%s</th>" % html.escape(h) for h in headers) + "</tr>"]
    for row in rows:
        out.append("<tr>" + "".join("<td>%s</td>" % html.escape(str(c)) for c in row) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


def page(path, s):
    info = s["info"]
    summary = [
        ("Recording", os.path.basename(path)),
        ("Document", info["document"] or "(command line)"),
        ("Recorded", "%s by %s" % (info["created_utc"], info["software"])),
        ("Method", "%s, device '%s', %.0f Hz" % (info["method"], info["device"], info["rate_hz"])),
        ("Duration", "%.2f s, %d ticks%s" % (info["duration_s"], s["ticks"],
                                             "" if info["complete"] else " (cut short: readable to %.2f s)"
                                             % info["last_good_s"])),
        ("Parts", ", ".join(info["parts"])),
        ("Largest force sent", "%.2f N (%d ticks saturated)" % (s["max_force_N"], s["saturated_ticks"])),
        ("Servo compute", "p99 %.1f us, max %.1f us" % (s["compute_p99_us"], s["compute_max_us"])),
        ("Watchdog faults", str(s["faults"])),
        ("Records dropped", "unknown" if info["dropped_records"] is None else str(info["dropped_records"])),
    ]
    timeline = [("%.3f" % e["time_s"], e["text"] or "", "%s -> %s" % (e["from"], e["to"]) if e["from"] != e["to"] else "")
                for e in s["events"]]
    timeline += [("%.3f" % a["time_s"], "note: " + a["text"], a["part"]) for a in info["annotations"]]
    timeline.sort(key=lambda row: float(row[0]))
    carried = [(m["part"], "%.2f - %.2f" % (m["start_s"], m["end_s"]),
                "(%.1f, %.1f, %.1f)" % tuple(1000 * v for v in m["from_m"]),
                "(%.1f, %.1f, %.1f)" % tuple(1000 * v for v in m["to_m"]),
                "%.1f" % (1000 * m["distance_m"]), "%.1f" % m["angle_deg"], "%.2f" % m["max_force_N"])
               for m in s["manipulations"]]
    warnings = "".join("<p class=warn>%s</p>" % html.escape(w) for w in info["warnings"])
    figures = "".join("<h3>%s</h3><img alt='%s' src='data:image/png;base64,%s'>" % (html.escape(title), html.escape(title), png)
                      for title, png in plots(s))
    return """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>HapticGrasp session report: %(name)s</title>
<style>body{font-family:sans-serif;margin:2em;max-width:1000px}table{border-collapse:collapse;margin:1em 0}
td,th{border:1px solid #ccc;padding:2px 8px;text-align:left;font-size:13px}.warn{color:#a00}img{max-width:100%%}</style>
</head><body>
<h1>Design-review session</h1>
%(warnings)s
<h2>Summary</h2>%(summary)s
<h2>Manipulations</h2>%(carried)s
<h2>Timeline: states, events and annotations</h2>%(timeline)s
<h2>Plots</h2>%(figures)s
<p><small>Made %(now)s by hapticgrasp report.</small></p>
</body></html>
""" % {"name": html.escape(os.path.basename(path)), "warnings": warnings,
       "summary": _table(["", ""], summary),
       "carried": _table(["part", "time [s]", "from [mm]", "to [mm]", "moved [mm]", "turned [deg]", "largest force [N]"],
                         carried) if carried else "<p>No part was carried.</p>",
       "timeline": _table(["time [s]", "what", "state / part"], timeline),
       "figures": figures, "now": datetime.datetime.now().strftime("%Y-%m-%d %H:%M")}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recording")
    parser.add_argument("-o", "--output", required=True)
    args = parser.parse_args(argv)
    try:
        text = page(args.recording, read(args.recording))
    except (RuntimeError, ValueError, OSError) as e:
        print("hapticgrasp report: %s" % e, file=sys.stderr)
        return 2
    with open(args.output, "w", encoding="utf-8") as out:
        out.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
