# Measures every corpus part with FreeCAD and writes the manifest and the README's tables:
#   freecadcmd tests/corpus/survey.py
# -> tests/corpus/corpus.json, and the blocks between the "generated" markers in README.md.
# Nothing here is typed by hand except the external files' origin and licence lines below and
# each part's `expect` (made parts: in make_corpus.py).
import collections
import json
import os
import sys
import time
import traceback

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
os.environ["MAKE_CORPUS_IMPORT_ONLY"] = "1"
import brep_types  # noqa: E402
import make_corpus  # noqa: E402
import Part  # noqa: E402

MADE = "made here: make_corpus.py"
MADE_LICENCE = "made here for HapticGrasp: the project's own"
NIST_ORIGIN = ("NIST MBE PMI Validation and Conformance Testing project (https://go.usa.gov/mGVm), "
               "geometry-only STEP file as stored in the public repository tsun7170/STEPswiftcode, "
               "path swiftP21read/TestCases/NIST_CTC_STEP_PMI/%s, commit 1da6b4088bfc834b4fb9b70c1a6e90a7bacf25ac")
NIST_LICENCE = "public domain (a work of the US Government, not subject to copyright in the United States)"

# The files from outside. `what` says why each is here.
EXTERNAL = [
    dict(name="as1_oc_214", file="external/as1-oc-214.stp", expect="exact",
         what="AS1, a STEP AP214 assembly (Open CASCADE sample model, 2008): 18 solids in one "
              "compound (plate, two L-brackets, rod, 6 bolts, 8 nuts), touching; read as one shape",
         origin="Open CASCADE sample model as distributed in the STEPcode repository "
                "(data/ap214e3/as1-oc-214.stp); copied from /work/shared/data",
         licence="STEPcode: 3-clause BSD, Copyright (c) 2009-2019 STEPcode AUTHORS"),
]
NIST = [
    ("nist_ctc_01", "nist_ctc_01_asme1_rd.stp",
     "NIST combined test case 1: a machined plate part from a commercial CAD system (139-face solid) plus "
     "78 loose wireframe edges (construction geometry) in the same compound (AP203, geometry only)"),
    ("nist_ftc_06", "nist_ftc_06_asme1_rd.stp",
     "NIST fully-toleranced test case 6: a machined part in INCH units (read as mm: 144-face solid with "
     "planes, cylinders, cones, spheres, tori, ellipse and B-spline edges) plus 73 loose wireframe edges "
     "(construction geometry) in the same compound (AP203, geometry only)"),
    ("nist_ctc_04", "nist_ctc_04_asme1_rd.stp",
     "NIST combined test case 4: a large machined part (517-face solid: planes, cylinders, cones with "
     "apex, spheres, tori, B-spline edges) plus one open one-face shell of supplemental geometry that the "
     "STEP file carries (AP203, geometry only)"),
]
for name, fname, what in NIST:
    EXTERNAL.append(dict(name=name, file="external/" + fname, expect="exact", what=what,
                         origin=NIST_ORIGIN % fname, licence=NIST_LICENCE))

SURFACE_TYPES = ["Plane", "Cylinder", "Cone", "Sphere", "Torus", "SurfaceOfRevolution", "SurfaceOfExtrusion",
                 "OffsetSurface", "BSplineSurface", "BezierSurface", "RectangularTrimmedSurface"]
CURVE_TYPES = ["Line", "Circle", "Ellipse", "Hyperbola", "Parabola", "BSplineCurve", "BezierCurve", "OffsetCurve"]
ADAPTOR_NAMES = {"Toroid": "Torus", "LineSegment": "Line"}


def load(path):
    shape = Part.Shape()
    shape.read(path)
    return shape


def bop_check(shape):
    """'ok', or the first problem FreeCAD's check(True) reports (BRepCheck first, then the
    Boolean argument analyser), with every distinct problem."""
    try:
        shape.check(True)
        return "ok", []
    except Exception as ex:  # FreeCAD raises Part.OCCError / ValueError with the list
        lines = [ln.strip() for ln in str(ex).splitlines()]
        problems = [ln for ln in lines if ln and ln != "No error" and not ln.startswith("BOP check found")]
        unique = list(dict.fromkeys(problems))
        return (unique[0] if unique else str(ex).strip()), unique


def adaptor_types(shape):
    """What FreeCAD (BRepAdaptor, the GeomAbs type) reports per face and per edge."""
    surfaces = collections.Counter()
    for f in shape.Faces:
        name = f.Surface.__class__.__name__
        surfaces[ADAPTOR_NAMES.get(name, name)] += 1
    curves = collections.Counter()
    for e in shape.Edges:
        if e.Degenerated:
            continue
        try:
            name = e.Curve.__class__.__name__
        except Exception:
            name = "Other"
        curves[ADAPTOR_NAMES.get(name, name)] += 1
    return dict(sorted(surfaces.items())), dict(sorted(curves.items()))


def overlap_volume(shape):
    """Summed pairwise common volume of a compound's solids (0 for touching solids)."""
    solids = shape.Solids
    total = 0.0
    for i in range(len(solids)):
        for j in range(i + 1, len(solids)):
            if not solids[i].BoundBox.intersect(solids[j].BoundBox):
                continue
            total += solids[i].common(solids[j]).Volume
    return total


def survey(spec):
    path = os.path.join(HERE, spec["file"])
    t0 = time.time()
    shape = load(path)
    load_s = time.time() - t0
    text = shape.exportBrepToString()
    stored = brep_types.analyse(text)
    surfaces, curves = adaptor_types(shape)
    t0 = time.time()
    bop, problems = bop_check(shape)
    check_s = time.time() - t0
    entry = dict(
        name=spec["name"], file=spec["file"], unit="mm", origin=spec["origin"], licence=spec["licence"],
        what=spec["what"], bytes=os.path.getsize(path),
        shape_type=shape.ShapeType, faces=len(shape.Faces), edges=len(shape.Edges), vertices=len(shape.Vertexes),
        solids=len(shape.Solids), shells_closed=bool(shape.Shells) and all(s.isClosed() for s in shape.Shells),
        volume_mm3=round(sum(s.Volume for s in shape.Solids), 3),
        surfaces=surfaces, curves=curves,
        stored_surfaces=stored["surfaces"], stored_curves=stored["curves"],
        seam_edges=stored["seam_edges"], degenerated_edges=stored["degenerated_edges"],
        freecad_valid=shape.isValid(), bop_check=bop, bop_problems=problems,
        max_vertex_tolerance_mm=max(v.Tolerance for v in shape.Vertexes),
        max_edge_tolerance_mm=max(e.Tolerance for e in shape.Edges),
        expect=spec["expect"],
        freecad_load_s=round(load_s, 3), bop_check_s=round(check_s, 2),
    )
    free_shells = len(shape.Shells) - sum(len(s.Shells) for s in shape.Solids)
    in_shells = {e.hashCode() for sh in shape.Shells for e in sh.Edges}
    loose_edges = sum(1 for e in shape.Edges if e.hashCode() not in in_shells)
    if loose_edges:
        entry["loose_edges"] = loose_edges  # edges in no shell (e.g. STEP wireframe construction geometry)
    if free_shells:
        entry["free_shells"] = free_shells  # shells outside any solid (e.g. STEP supplemental geometry)
    if len(shape.Solids) > 1 or (shape.Solids and (free_shells or loose_edges)):
        # check(True) on a compound reports touching solids (or a free face or loose edge touching a
        # solid) as self-interference: check each solid alone too
        entry["bop_check_per_solid"] = next((p for p in (bop_check(s)[0] for s in shape.Solids) if p != "ok"), "ok")
    if len(shape.Solids) > 1:
        entry["overlap_mm3"] = round(overlap_volume(shape), 3)
    if "overlap_mm3" in spec:
        entry["overlap_expected_mm3"] = round(spec["overlap_mm3"], 3)
    return entry


def base_type(stored_name):
    """'RectangularTrimmedSurface(Cylinder)' -> ['RectangularTrimmedSurface', 'Cylinder']."""
    return stored_name.replace(")", "").split("(")


def coverage(entries):
    """Per type: faces/edges and parts where the stored class or the GeomAbs type is that type."""
    rows = []
    for kind, types, stored_key, adaptor_key in (("surface", SURFACE_TYPES, "stored_surfaces", "surfaces"),
                                                 ("curve", CURVE_TYPES, "stored_curves", "curves")):
        for t in types:
            stored_n = adaptor_n = 0
            parts = []
            for e in entries:
                s = sum(n for k, n in e[stored_key].items() if t in base_type(k))
                a = e[adaptor_key].get(t, 0)
                stored_n += s
                adaptor_n += a
                if s or a:
                    parts.append(e["name"])
            rows.append((kind, t, stored_n, adaptor_n, parts))
    for t, key in (("seam edges", "seam_edges"), ("degenerated edges", "degenerated_edges")):
        parts = [e["name"] for e in entries if e[key]]
        rows.append(("edge", t, sum(e[key] for e in entries), None, parts))
    return rows


def coverage_markdown(rows):
    out = ["| kind | type | stored in the BREP (each TShape once; a trimmed or offset basis counts) "
           "| GeomAbs type as FreeCAD reports it (each occurrence) | parts |",
           "|---|---|---|---|---|"]
    for kind, t, s, a, parts in rows:
        shown = ", ".join(parts[:6]) + (" and %d more" % (len(parts) - 6) if len(parts) > 6 else "")
        out.append("| %s | %s | %d | %s | %s |" % (kind, t, s, "-" if a is None else a, shown or "**none**"))
    return "\n".join(out)


def short_types(counter):
    return ", ".join("%s %d" % (k, n) for k, n in counter.items())


def parts_markdown(entries):
    out = ["| part | what it is, why it is here | faces | surfaces (stored class) | edge curves (stored class) "
           "| seams / degenerated | valid / BOP check | expect | origin | licence |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for e in entries:
        origin = "make_corpus.py" if e["origin"] == MADE else e["origin"].split(",")[0]
        out.append("| `%s` | %s | %d | %s | %s | %d / %d | %s / %s | %s | %s | %s |" % (
            e["file"], e["what"], e["faces"], short_types(e["stored_surfaces"]), short_types(e["stored_curves"]),
            e["seam_edges"], e["degenerated_edges"], e["freecad_valid"], e["bop_check"], e["expect"]
            + (" (%.3f mm3)" % e["overlap_mm3"] if e["expect"] == "warn-overlap" else ""),
            origin, e["licence"]))
    return "\n".join(out)


def replace_block(text, tag, body):
    begin, end = "<!-- generated:%s -->" % tag, "<!-- end:%s -->" % tag
    a, b = text.index(begin) + len(begin), text.index(end)
    return text[:a] + "\n" + body + "\n" + text[b:]


def main():
    specs = []
    for name, spec in make_corpus.PARTS.items():
        specs.append(dict(name=name, file="parts/%s.brep" % name, origin=MADE, licence=MADE_LICENCE, **{
            k: v for k, v in spec.items() if k != "make"}))
    specs += [s for s in EXTERNAL if os.path.exists(os.path.join(HERE, s["file"]))]
    entries, failed = [], []
    for spec in specs:
        try:
            e = survey(spec)
            entries.append(e)
            print("%-28s %5d faces  valid %-5s  bop %-40.40s  %.1f s" % (
                e["name"], e["faces"], e["freecad_valid"], e["bop_check"], e["bop_check_s"]), flush=True)
        except Exception:
            traceback.print_exc()
            failed.append(spec["name"])
    with open(os.path.join(HERE, "corpus.json"), "w") as f:
        json.dump(entries, f, indent=1)
        f.write("\n")
    readme = os.path.join(HERE, "README.md")
    with open(readme) as f:
        text = f.read()
    text = replace_block(text, "parts", parts_markdown(entries))
    text = replace_block(text, "coverage", coverage_markdown(coverage(entries)))
    with open(readme, "w") as f:
        f.write(text)
    if failed:
        print("survey: failed:", ", ".join(failed))
        sys.exit(1)
    print("survey: %d parts, corpus.json and README.md written" % len(entries))


main()
