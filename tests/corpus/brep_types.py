"""The geometry a BREP file really stores: the Geom class of each face's surface and each
edge's 3D curve, seam and degenerated edges.

FreeCAD's `face.Surface` and `edge.Curve` go through BRepAdaptor (the GeomAbs type): a face on
a Geom_RectangularTrimmedSurface reads as its basis surface there. What the C++ core gets from
BRep_Tool::Surface is the stored class, so the corpus counts both. This module reads the text
BREP format ("CASCADE Topology V1", as FreeCAD's exportBrep writes it). Plain Python.
"""
import collections

CURVE3D = {1: "Line", 2: "Circle", 3: "Ellipse", 4: "Parabola", 5: "Hyperbola", 6: "BezierCurve",
           7: "BSplineCurve", 8: "TrimmedCurve", 9: "OffsetCurve"}
SURFACE = {1: "Plane", 2: "Cylinder", 3: "Cone", 4: "Sphere", 5: "Torus", 6: "SurfaceOfExtrusion",
           7: "SurfaceOfRevolution", 8: "BezierSurface", 9: "BSplineSurface", 10: "RectangularTrimmedSurface",
           11: "OffsetSurface"}


class _Tokens:
    def __init__(self, text):
        self.t = text.split()
        self.i = 0

    def next(self):
        self.i += 1
        return self.t[self.i - 1]

    def skip(self, n):
        self.i += n

    def int(self):
        return int(self.next())


def _curve(tok, dim):
    """Reads one curve record (3D: dim 3, 2D: dim 2); returns its name, basis in brackets."""
    kind = tok.int()
    name = CURVE3D[kind]
    if kind == 1:
        tok.skip(2 * dim)
    elif kind in (2, 4):
        tok.skip(dim + (3 if dim == 3 else 0) + 2 * dim + 1)  # centre, [normal], X and Y axes, radius
    elif kind in (3, 5):
        tok.skip(dim + (3 if dim == 3 else 0) + 2 * dim + 2)
    elif kind == 6:
        rational, degree = tok.int(), tok.int()
        tok.skip((degree + 1) * (dim + rational))
    elif kind == 7:
        rational, _periodic, _degree, poles, knots = (tok.int() for _ in range(5))
        tok.skip(poles * (dim + rational) + 2 * knots)
    elif kind == 8:
        tok.skip(2)
        name = "TrimmedCurve(%s)" % _curve(tok, dim)
    elif kind == 9:
        tok.skip(1 + (3 if dim == 3 else 0))
        name = "OffsetCurve(%s)" % _curve(tok, dim)
    return name


def _surface(tok):
    kind = tok.int()
    name = SURFACE[kind]
    if kind in (1, 2, 3, 4, 5):
        tok.skip(12 + {1: 0, 2: 1, 3: 2, 4: 1, 5: 2}[kind])
    elif kind == 6:
        tok.skip(3)
        name = "SurfaceOfExtrusion(%s)" % _curve(tok, 3)
    elif kind == 7:
        tok.skip(6)
        name = "SurfaceOfRevolution(%s)" % _curve(tok, 3)
    elif kind == 8:
        ur, vr, ud, vd = (tok.int() for _ in range(4))
        tok.skip((ud + 1) * (vd + 1) * (3 + (1 if ur or vr else 0)))
    elif kind == 9:
        ur, vr, _up, _vp, _ud, _vd, nu, nv, nuk, nvk = (tok.int() for _ in range(10))
        tok.skip(nu * nv * (3 + (1 if ur or vr else 0)) + 2 * nuk + 2 * nvk)
    elif kind == 10:
        tok.skip(4)
        name = "RectangularTrimmedSurface(%s)" % _surface(tok)
    elif kind == 11:
        tok.skip(1)
        name = "OffsetSurface(%s)" % _surface(tok)
    return name


def _section(lines, start, title):
    """Index of the line that opens section `title` (e.g. 'Curves 12'), from `start`."""
    for i in range(start, len(lines)):
        if lines[i].startswith(title + " "):
            return i
    raise ValueError("no %s section" % title)


def _read_records(lines, title, reader, start=0):
    head = _section(lines, start, title)
    count = int(lines[head].split()[1])
    end = head + 1
    # The records run to the next section's title line.
    while end < len(lines) and not lines[end][:1].isalpha():
        end += 1
    tok = _Tokens("\n".join(lines[head + 1:end]))
    records = [reader(tok) for _ in range(count)]
    if tok.i != len(tok.t):
        raise ValueError("%s: read %d of %d tokens" % (title, tok.i, len(tok.t)))
    return records, end


def analyse(text):
    """Counts in a BREP text: stored surface class per face, stored 3D curve class per edge,
    seam edges (a pcurve pair on a closed surface), degenerated edges. Each TShape counts once."""
    lines = text.splitlines()
    curves, _ = _read_records(lines, "Curves", lambda t: _curve(t, 3))
    surfaces, after = _read_records(lines, "Surfaces", _surface)
    shapes = _section(lines, after, "TShapes")
    face_surfaces = collections.Counter()
    edge_curves = collections.Counter()
    seams = degenerated = 0
    i = shapes + 1
    while i < len(lines):
        code = lines[i].strip()
        if code == "Fa":
            face_surfaces[surfaces[int(lines[i + 1].split()[2]) - 1]] += 1
            i += 2
        elif code == "Ed":
            if int(lines[i + 1].split()[3]):
                degenerated += 1
            i += 2
            curve3d = None
            seam = False
            while lines[i].strip() != "0":
                rep = lines[i].split()
                if rep[0] == "1":
                    curve3d = curves[int(rep[1]) - 1]
                elif rep[0] == "3":
                    seam = True
                i += 1
            if curve3d:
                edge_curves[curve3d] += 1
            seams += seam
        else:
            i += 1
    return {"surfaces": dict(sorted(face_surfaces.items())), "curves": dict(sorted(edge_curves.items())),
            "seam_edges": seams, "degenerated_edges": degenerated}


if __name__ == "__main__":
    import json
    import sys
    for path in sys.argv[1:]:
        with open(path) as f:
            print(path, json.dumps(analyse(f.read())))
