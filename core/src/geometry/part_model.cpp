#include "hapticgrasp/geometry/part_model.hpp"

#include <BOPAlgo_CheckerSI.hxx>
#include <BOPDS_DS.hxx>
#include <BOPTools_AlgoTools.hxx>
#include <BOPTools_Parallel.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_MakeSolid.hxx>
#include <BRepCheck.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepCheck_ListOfStatus.hxx>
#include <BRepCheck_Result.hxx>
#include <BRepClass3d_SolidClassifier.hxx>
#include <BRepGProp.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <GeomAPI_ProjectPointOnCurve.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IntTools_Context.hxx>
#include <IntTools_Curve.hxx>
#include <IntTools_FaceFace.hxx>
#include <NCollection_Vector.hxx>
#include <Precision.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Pln.hxx>
#include <gp_Torus.hxx>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <exception>
#include <fstream>
#include <iterator>
#include <sstream>
#include <streambuf>
#include <type_traits>
#include <utility>
#include <vector>

#include "primitive_recognition.hpp"

namespace hg::geometry {
namespace {

const char* shapeTypeName(TopAbs_ShapeEnum type) {
  switch (type) {
    case TopAbs_COMPOUND: return "compound";
    case TopAbs_COMPSOLID: return "compsolid";
    case TopAbs_SOLID: return "solid";
    case TopAbs_SHELL: return "shell";
    case TopAbs_FACE: return "face";
    case TopAbs_WIRE: return "wire";
    case TopAbs_EDGE: return "edge";
    case TopAbs_VERTEX: return "vertex";
    default: return "shape";
  }
}

// Edges bounded by one face only (seams and degenerated edges excepted): the holes of an
// open shell.
int countFreeEdges(const TopoDS_Shape& shape) {
  TopTools_IndexedDataMapOfShapeListOfShape edgeFaces;
  TopExp::MapShapesAndUniqueAncestors(shape, TopAbs_EDGE, TopAbs_FACE, edgeFaces);
  int free = 0;
  for (int i = 1; i <= edgeFaces.Extent(); ++i) {
    const TopoDS_Edge& e = TopoDS::Edge(edgeFaces.FindKey(i));
    const TopTools_ListOfShape& faces = edgeFaces(i);
    if (BRep_Tool::Degenerated(e) || faces.Extent() != 1) continue;
    if (!BRep_Tool::IsClosed(e, TopoDS::Face(faces.First()))) ++free;
  }
  return free;
}

std::string statusText(BRepCheck_Status status) {
  std::ostringstream out;
  BRepCheck::Print(status, out);
  std::string text = out.str();
  text.erase(std::remove(text.begin(), text.end(), '\n'), text.end());
  return text;
}

// The first thing BRepCheck_Analyzer objects to, in words: a problem of a sub-shape on its
// own ("edge 3: BRepCheck_InvalidCurveOnSurface"), or in the context of a shape that holds
// it ("edge 3 in shell 1: BRepCheck_BadOrientation").
std::string firstCheckProblem(const BRepCheck_Analyzer& analyzer, const TopoDS_Shape& shape) {
  const TopAbs_ShapeEnum types[] = {TopAbs_VERTEX, TopAbs_EDGE, TopAbs_WIRE, TopAbs_FACE, TopAbs_SHELL, TopAbs_SOLID};
  std::vector<TopTools_IndexedMapOfShape> maps(std::size(types));
  for (std::size_t t = 0; t < std::size(types); ++t) TopExp::MapShapes(shape, types[t], maps[t]);
  auto name = [&](const TopoDS_Shape& s) {
    for (std::size_t t = 0; t < std::size(types); ++t)
      if (types[t] == s.ShapeType()) return std::string(shapeTypeName(s.ShapeType())) + " " + std::to_string(maps[t].FindIndex(s));
    return std::string(shapeTypeName(s.ShapeType()));
  };
  for (std::size_t t = 0; t < std::size(types); ++t) {
    for (int i = 1; i <= maps[t].Extent(); ++i) {
      const Handle(BRepCheck_Result)& result = analyzer.Result(maps[t](i));
      if (result.IsNull()) continue;
      for (const BRepCheck_Status status : result->Status())
        if (status != BRepCheck_NoError) return name(maps[t](i)) + ": " + statusText(status);
      for (result->InitContextIterator(); result->MoreShapeInContext(); result->NextShapeInContext())
        for (const BRepCheck_Status status : result->StatusOnShape())
          if (status != BRepCheck_NoError)
            return name(maps[t](i)) + " in " + name(result->ContextualShape()) + ": " + statusText(status);
    }
  }
  return "unspecified problem";
}

// One solid, or a compound of solids; a closed shell is accepted and made a solid.
TopoDS_Shape solidsOf(const TopoDS_Shape& shape, std::vector<std::string>& warnings) {
  TopoDS_Compound solids;
  BRep_Builder builder;
  builder.MakeCompound(solids);
  int count = 0;
  for (TopExp_Explorer ex(shape, TopAbs_SOLID); ex.More(); ex.Next(), ++count) builder.Add(solids, ex.Current());
  if (count == 0) {
    for (TopExp_Explorer ex(shape, TopAbs_SHELL, TopAbs_SOLID); ex.More(); ex.Next()) {
      const TopoDS_Shell& shell = TopoDS::Shell(ex.Current());
      const int free = countFreeEdges(shell);
      if (free > 0)
        throw GeometryError("not a solid: open shell with " + std::to_string(free) + " free edges");
      builder.Add(solids, BRepBuilderAPI_MakeSolid(shell).Solid());
      warnings.push_back("a closed shell was made into a solid");
      ++count;
    }
  }
  if (count == 0)
    throw GeometryError(std::string("not a solid: the shape is ") +
                        (shape.ShapeType() == TopAbs_EDGE ? "an " : "a ") + shapeTypeName(shape.ShapeType()) +
                        " without any closed shell");
  if (count == 1) {
    TopExp_Explorer ex(solids, TopAbs_SOLID);
    return ex.Current();
  }
  return solids;
}

// A sub-shape in words, numbered 1..N in TopExp::MapShapes order as PartModel numbers them.
std::string subShapeName(const TopoDS_Shape& whole, const TopoDS_Shape& sub) {
  TopTools_IndexedMapOfShape map;
  TopExp::MapShapes(whole, sub.ShapeType(), map);
  return std::string(shapeTypeName(sub.ShapeType())) + " " + std::to_string(map.FindIndex(sub));
}

// The self-intersection check. BOPAlgo_CheckerSI at its full level (what
// BOPAlgo_ArgumentAnalyzer runs) intersects every pair of faces whose boxes overlap,
// adjacent ones included, and matches each section against the existing edges through the
// whole pave filler: 13 s for the 1030-face plate, whose top and bottom faces meet 1024 hole
// walls each. This check finds the same defects in four steps, 0.3-0.5 s for the plate:
//  1. BOPAlgo_CheckerSI up to edge/face interferences (fast): an edge that crosses or
//     touches a face or another edge, a vertex on an edge or a face. Where two faces cross,
//     their section ends on an edge of one of them, which crosses the other: found here.
//  2. What remains are sections that never reach an edge: a closed loop inside two faces,
//     or a loop that leaves a shared edge and comes back to it. Pairs of faces whose boxes
//     overlap (sweep and prune) are intersected with IntTools_FaceFace, and each section is
//     sampled: a sample inside both faces, away from the edges and vertices they share, is
//     a self-intersection. Two planar faces meet in a line, which must end on an edge
//     (step 1): for them only coincidence is tested. Coincident faces (same surface,
//     overlapping) are reported as BOPAlgo_CheckerSI does.
//  3. Faces that intersect themselves (non-analytic ones), as BOPAlgo_CheckerSI does.
//  4. A solid of a compound inside another one, their boundaries apart.
// Steps 2 and 3 run on OCCT's thread pool, one IntTools_Context per thread. A sampled
// section can miss a crossing shorter than 1/32 of the section's length in the faces'
// boxes; a face/face intersection that failed is, as in the pave filler, not a finding.
class SelfIntersectionCheck {
 public:
  SelfIntersectionCheck(const TopoDS_Shape& shape, bool parallel) : shape_(shape), parallel_(parallel) {
    Bnd_Box box;
    BRepBndLib::Add(shape, box);
    relTol_ = 1e-6 * std::sqrt(box.SquareExtent());
  }

  // An empty string, or what intersects what.
  std::string run() {
    if (std::string found = boundaryInterferences(); !found.empty()) return found;
    prepareFaces();
    if (std::string found = faceTasks(); !found.empty()) return found;
    return nestedSolids();
  }

 private:
  struct Face {
    TopoDS_Face face;
    Bnd_Box box;
    GeomAbs_SurfaceType type = GeomAbs_OtherSurface;
    double tolerance = 0;       // largest tolerance of the face, its edges and vertices
    std::vector<int> edges;     // indices into edges_, sorted
    std::vector<int> vertices;  // indices into vertices_, sorted
  };

  // One pair of faces (i < j), or one face against itself (i == j), for BOPTools_Parallel.
  struct Task {
    const SelfIntersectionCheck* check = nullptr;
    int i = 0, j = 0;
    Handle(IntTools_Context) context;
    std::string found;
    void SetContext(const Handle(IntTools_Context)& c) { context = c; }
    void Perform() {
      try {
        found = i == j ? check->selfIntersection(i, context) : check->facePair(i, j, context);
      } catch (const Standard_Failure&) {
        found.clear();  // as the pave filler: a failed intersection is no finding
      }
    }
  };

  std::string boundaryInterferences() const {
    BOPAlgo_CheckerSI checker;
    TopTools_ListOfShape arguments;
    arguments.Append(shape_);
    checker.SetArguments(arguments);
    checker.SetNonDestructive(true);
    checker.SetRunParallel(parallel_);
    checker.SetLevelOfCheck(4);  // BOPDS interference types 0-4: VV, VE, EE, VF, EF
    checker.Perform();
    if (checker.HasErrors()) throw GeometryError("self-intersection check failed on the shape");
    BOPDS_DS& ds = *checker.PDS();
    std::string found;
    // Counted as BOPAlgo_CheckerSI::PostTreat counts them.
    auto scan = [&](auto& interferences) {
      for (int k = 0; found.empty() && k < interferences.Length(); ++k) {
        const auto& interference = interferences(k);
        if constexpr (std::is_same_v<std::decay_t<decltype(interference)>, BOPDS_InterfEF>) {
          if (interference.CommonPart().Type() == TopAbs_SHAPE) continue;
        }
        int n1, n2;
        interference.Indices(n1, n2);
        if (ds.IsNewShape(n1) || ds.IsNewShape(n2)) continue;
        found = subShapeName(shape_, ds.Shape(n1)) + " and " + subShapeName(shape_, ds.Shape(n2)) + " intersect";
      }
    };
    scan(ds.InterfVV());
    scan(ds.InterfVE());
    scan(ds.InterfEE());
    scan(ds.InterfVF());
    scan(ds.InterfEF());
    return found;
  }

  void prepareFaces() {
    TopTools_IndexedMapOfShape faceMap;
    TopExp::MapShapes(shape_, TopAbs_FACE, faceMap);
    TopExp::MapShapes(shape_, TopAbs_EDGE, edges_);
    TopExp::MapShapes(shape_, TopAbs_VERTEX, vertices_);
    faces_.resize(faceMap.Extent());
    for (int i = 0; i < faceMap.Extent(); ++i) {
      Face& f = faces_[i];
      f.face = TopoDS::Face(faceMap(i + 1));
      BRepBndLib::Add(f.face, f.box, false);
      f.box.Enlarge(relTol_);
      f.type = BRepAdaptor_Surface(f.face, false).GetType();
      f.tolerance = BRep_Tool::Tolerance(f.face);
      for (TopExp_Explorer ex(f.face, TopAbs_EDGE); ex.More(); ex.Next()) {
        f.edges.push_back(edges_.FindIndex(ex.Current()));
        f.tolerance = std::max(f.tolerance, BRep_Tool::Tolerance(TopoDS::Edge(ex.Current())));
      }
      for (TopExp_Explorer ex(f.face, TopAbs_VERTEX); ex.More(); ex.Next()) {
        f.vertices.push_back(vertices_.FindIndex(ex.Current()));
        f.tolerance = std::max(f.tolerance, BRep_Tool::Tolerance(TopoDS::Vertex(ex.Current())));
      }
      for (std::vector<int>* v : {&f.edges, &f.vertices}) {
        std::sort(v->begin(), v->end());
        v->erase(std::unique(v->begin(), v->end()), v->end());
      }
    }
  }

  // Steps 2 and 3; the first finding in face order, whatever the threads' timing.
  std::string faceTasks() const {
    NCollection_Vector<Task> tasks;
    auto add = [&](int i, int j) {
      Task& task = tasks.Appended();
      task.check = this;
      task.i = i;
      task.j = j;
    };
    const int n = static_cast<int>(faces_.size());
    for (int i = 0; i < n; ++i) {
      const GeomAbs_SurfaceType type = faces_[i].type;
      if (type == GeomAbs_Plane || type == GeomAbs_Cylinder || type == GeomAbs_Cone || type == GeomAbs_Sphere) continue;
      if (type == GeomAbs_Torus) {
        const gp_Torus torus = BRepAdaptor_Surface(faces_[i].face, false).Torus();
        if (torus.MajorRadius() > torus.MinorRadius() + Precision::Confusion()) continue;
      }
      add(i, i);
    }
    // Sweep and prune along x.
    std::vector<int> order(n);
    std::vector<double> xmin(n), xmax(n);
    for (int i = 0; i < n; ++i) {
      order[i] = i;
      double y0, z0, y1, z1;
      faces_[i].box.Get(xmin[i], y0, z0, xmax[i], y1, z1);
    }
    std::sort(order.begin(), order.end(), [&](int a, int b) { return xmin[a] < xmin[b]; });
    std::vector<std::pair<int, int>> pairs;
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n && xmin[order[b]] <= xmax[order[a]]; ++b) {
        const int i = order[a], j = order[b];
        if (!faces_[i].box.IsOut(faces_[j].box)) pairs.emplace_back(std::min(i, j), std::max(i, j));
      }
    std::sort(pairs.begin(), pairs.end());
    for (const auto& [i, j] : pairs) add(i, j);

    Handle(IntTools_Context) context = new IntTools_Context;
    BOPTools_Parallel::Perform(parallel_, tasks, context);
    for (const Task& task : tasks)
      if (!task.found.empty()) return task.found;
    return {};
  }

  static std::string facesName(int i, int j) { return "faces " + std::to_string(i + 1) + " and " + std::to_string(j + 1); }

  // As BOPAlgo_CheckerSI::CheckFaceSelfIntersection.
  std::string selfIntersection(int i, const Handle(IntTools_Context)& context) const {
    IntTools_FaceFace ff;
    ff.SetContext(context);
    ff.Perform(faces_[i].face, faces_[i].face);
    if (ff.IsDone() && (ff.Lines().Length() > 0 || ff.Points().Length() > 0))
      return "face " + std::to_string(i + 1) + " intersects itself";
    return {};
  }

  std::string facePair(int i, int j, const Handle(IntTools_Context)& context) const {
    const Face& a = faces_[i];
    const Face& b = faces_[j];
    const double faceTol = std::max(a.tolerance, b.tolerance);
    if (a.type == GeomAbs_Plane && b.type == GeomAbs_Plane) {
      const gp_Pln pa = BRepAdaptor_Surface(a.face, false).Plane();
      const gp_Pln pb = BRepAdaptor_Surface(b.face, false).Plane();
      const double tol = std::max(relTol_, 4 * faceTol);
      if (!pa.Axis().IsParallel(pb.Axis(), Precision::Angular()) || pa.Distance(pb.Location()) > tol) return {};
      if (BOPTools_AlgoTools::AreFacesSameDomain(a.face, b.face, context)) return facesName(i, j) + " overlap";
      return {};
    }
    IntTools_FaceFace ff;
    ff.SetContext(context);
    ff.Perform(a.face, b.face);
    if (!ff.IsDone()) return {};
    if (ff.TangentFaces()) {
      if (BOPTools_AlgoTools::AreFacesSameDomain(a.face, b.face, context)) return facesName(i, j) + " overlap";
      return {};
    }
    if (ff.Lines().IsEmpty()) return {};
    std::vector<int> sharedEdges, sharedVertices;
    std::set_intersection(a.edges.begin(), a.edges.end(), b.edges.begin(), b.edges.end(),
                          std::back_inserter(sharedEdges));
    std::set_intersection(a.vertices.begin(), a.vertices.end(), b.vertices.begin(), b.vertices.end(),
                          std::back_inserter(sharedVertices));
    for (const IntTools_Curve& section : ff.Lines()) {
      const Handle(Geom_Curve)& curve = section.Curve();
      double t0, t1;
      if (curve.IsNull() || !parameterRange(section, a.box, b.box, t0, t1)) continue;
      // On a shared edge or vertex: within their tolerance, the section's, and a margin.
      const double onTol = std::max({relTol_, 4 * faceTol, 4 * section.Tolerance()});
      // In a face: the section lies on both surfaces to its tolerance.
      const double inTol = std::max(section.Tolerance(), faceTol) + Precision::Confusion();
      constexpr int kSamples = 32;
      for (int k = 0; k < kSamples; ++k) {
        const gp_Pnt p = curve->Value(t0 + (k + 0.5) / kSamples * (t1 - t0));
        if (onShared(p, sharedEdges, sharedVertices, onTol, context)) continue;
        if (context->IsValidPointForFace(p, a.face, inTol) && context->IsValidPointForFace(p, b.face, inTol))
          return facesName(i, j) + " intersect";
      }
    }
    return {};
  }

  // The part of a section worth sampling: its bounds, or for an unbounded one the span
  // near both faces' boxes.
  static bool parameterRange(const IntTools_Curve& section, const Bnd_Box& a, const Bnd_Box& b, double& t0,
                             double& t1) {
    const Handle(Geom_Curve)& curve = section.Curve();
    gp_Pnt p0, p1;
    if (!section.Bounds(t0, t1, p0, p1)) {
      t0 = curve->FirstParameter();
      t1 = curve->LastParameter();
    }
    if (!Precision::IsInfinite(t0) && !Precision::IsInfinite(t1)) return t1 > t0;
    if (a.IsOut(b)) return false;
    double ax0, ay0, az0, ax1, ay1, az1, bx0, by0, bz0, bx1, by1, bz1;
    a.Get(ax0, ay0, az0, ax1, ay1, az1);
    b.Get(bx0, by0, bz0, bx1, by1, bz1);
    const gp_Pnt lo(std::max(ax0, bx0), std::max(ay0, by0), std::max(az0, bz0));
    const gp_Pnt hi(std::min(ax1, bx1), std::min(ay1, by1), std::min(az1, bz1));
    GeomAPI_ProjectPointOnCurve projection(gp_Pnt((lo.XYZ() + hi.XYZ()) / 2), curve);
    if (projection.NbPoints() == 0) return false;
    const double centre = projection.LowerDistanceParameter();
    // Lines are parametrised by length; the other open conics (parabola, hyperbola) nearly
    // so near their apex.
    const double half = lo.Distance(hi);
    t0 = std::max(curve->FirstParameter(), centre - half);
    t1 = std::min(curve->LastParameter(), centre + half);
    return t1 > t0;
  }

  bool onShared(const gp_Pnt& p, const std::vector<int>& edges, const std::vector<int>& vertices, double tol,
                const Handle(IntTools_Context)& context) const {
    for (int v : vertices) {
      const TopoDS_Vertex& vertex = TopoDS::Vertex(vertices_(v));
      if (p.Distance(BRep_Tool::Pnt(vertex)) <= tol + BRep_Tool::Tolerance(vertex)) return true;
    }
    for (int e : edges) {
      const TopoDS_Edge& edge = TopoDS::Edge(edges_(e));
      if (BRep_Tool::Degenerated(edge)) continue;
      GeomAPI_ProjectPointOnCurve& projection = context->ProjPC(edge);
      projection.Perform(p);
      if (projection.NbPoints() > 0 && projection.LowerDistance() <= tol + BRep_Tool::Tolerance(edge)) return true;
    }
    return false;
  }

  // Solids of a compound whose boundaries do not meet (steps 1-2 found nothing) overlap
  // only if one holds the other: then every vertex of the inner one is inside the outer.
  std::string nestedSolids() const {
    TopTools_IndexedMapOfShape solids;
    TopExp::MapShapes(shape_, TopAbs_SOLID, solids);
    if (solids.Extent() < 2) return {};
    std::vector<Bnd_Box> boxes(solids.Extent());
    for (int i = 1; i <= solids.Extent(); ++i) BRepBndLib::Add(solids(i), boxes[i - 1]);
    for (int i = 1; i <= solids.Extent(); ++i)
      for (int j = 1; j <= solids.Extent(); ++j) {
        if (i == j || boxes[i - 1].IsOut(boxes[j - 1])) continue;
        BRepClass3d_SolidClassifier classifier(solids(j));
        for (TopExp_Explorer ex(solids(i), TopAbs_VERTEX); ex.More(); ex.Next()) {
          const TopoDS_Vertex& v = TopoDS::Vertex(ex.Current());
          classifier.Perform(BRep_Tool::Pnt(v), BRep_Tool::Tolerance(v));
          if (classifier.State() == TopAbs_ON) continue;
          if (classifier.State() == TopAbs_IN)
            return "solid " + std::to_string(i) + " is inside solid " + std::to_string(j);
          break;
        }
      }
    return {};
  }

  const TopoDS_Shape& shape_;
  const bool parallel_;
  double relTol_ = Precision::Confusion();
  TopTools_IndexedMapOfShape edges_, vertices_;
  std::vector<Face> faces_;
};

void checkClosedAndValid(const TopoDS_Shape& solids, const PartLoadOptions& options) {
  const int free = countFreeEdges(solids);
  if (free > 0) throw GeometryError("not a closed solid: " + std::to_string(free) + " free edges");
  BRepCheck_Analyzer analyzer(solids, true, options.parallel);
  if (!analyzer.IsValid()) throw GeometryError("invalid B-rep: " + firstCheckProblem(analyzer, solids));
}

// After outwardSolids: the containment test needs solids that face outwards.
void checkSelfIntersection(const TopoDS_Shape& solids, const PartLoadOptions& options) {
  if (!options.checkSelfIntersection) return;
  const std::string found = SelfIntersectionCheck(solids, options.parallel).run();
  if (!found.empty()) throw GeometryError("self-intersecting shape: " + found);
}

// Each solid with its faces oriented outwards: an inside-out solid (negative volume) is
// reversed, with a warning.
TopoDS_Shape outwardSolids(const TopoDS_Shape& solids, std::vector<std::string>& warnings) {
  TopoDS_Compound out;
  BRep_Builder builder;
  builder.MakeCompound(out);
  int count = 0, reversed = 0;
  TopoDS_Shape last;
  for (TopExp_Explorer ex(solids, TopAbs_SOLID); ex.More(); ex.Next(), ++count) {
    last = ex.Current();
    GProp_GProps props;
    BRepGProp::VolumeProperties(last, props);
    if (props.Mass() < 0) {
      last.Reverse();
      ++reversed;
    }
    builder.Add(out, last);
  }
  if (reversed == 0) return solids;
  warnings.push_back(count == 1 ? "the solid was inside out and has been reversed"
                                : std::to_string(reversed) + " of " + std::to_string(count) +
                                      " solids were inside out and have been reversed");
  return count == 1 ? last : TopoDS_Shape(out);
}

std::string lowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

TopoDS_Shape readStep(const std::filesystem::path& path) {
  STEPControl_Reader reader;
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone)
    throw GeometryError("STEP file could not be read: " + path.string());
  if (reader.TransferRoots() == 0) throw GeometryError("STEP file holds no shape: " + path.string());
  TopoDS_Shape shape = reader.OneShape();
  if (shape.IsNull()) throw GeometryError("STEP file holds no shape: " + path.string());
  return shape;
}

// OCCT 7.6's BREP reader does not stop at the end of its input: on a truncated text it
// loops forever on the failed stream (BRepTools_ShapeSet::ReadGeometry), or returns part of
// a shape. A complete text never reads past its last line, so this buffer throws when
// asked for more, and the stream passes the exception on.
class EndOfBrepText : public std::exception {
 public:
  const char* what() const noexcept override { return "unexpected end of text"; }
};

class BrepTextBuffer : public std::streambuf {
 public:
  explicit BrepTextBuffer(std::string text) : text_(std::move(text)) {
    text_ += '\n';  // a complete text without a final newline would end inside its last number
    setg(text_.data(), text_.data(), text_.data() + text_.size());
  }

 protected:
  int_type underflow() override { throw EndOfBrepText(); }

 private:
  std::string text_;
};

TopoDS_Shape readBrep(std::string text, const std::string& what) {
  BrepTextBuffer buffer(std::move(text));
  std::istream in(&buffer);
  in.exceptions(std::ios::badbit);  // rethrow what the buffer throws
  TopoDS_Shape shape;
  BRep_Builder builder;
  try {
    BRepTools::Read(shape, in, builder);
  } catch (const EndOfBrepText&) {
    throw GeometryError(what + " could not be read: truncated, or not BREP");
  } catch (const Standard_Failure& e) {
    throw GeometryError(what + " could not be read: " + e.GetMessageString());
  }
  if (shape.IsNull()) throw GeometryError(what + " could not be read: truncated, or not BREP");
  return shape;
}

Vec3 toVec(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

}  // namespace

PartModelPtr PartModel::fromBrepText(std::string_view text, LengthUnit unit, std::string name,
                                     const LoadOptions& options) {
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos) throw GeometryError("empty BREP text");
  const TopoDS_Shape shape = readBrep(std::string(text), "BREP text");
  return fromShape(shape, unit, std::move(name), options);
}

PartModelPtr PartModel::fromFile(const std::filesystem::path& path, LengthUnit unit, const LoadOptions& options) {
  if (!std::filesystem::is_regular_file(path)) throw GeometryError("no such file: " + path.string());
  if (std::filesystem::file_size(path) == 0) throw GeometryError("empty file: " + path.string());
  const std::string ext = lowerExtension(path);
  TopoDS_Shape shape;
  try {
    if (ext == ".step" || ext == ".stp") {
      shape = readStep(path);
      unit = LengthUnit::Millimetre;  // OCCT's STEP reader converts every file to mm
    } else if (ext == ".brep" || ext == ".brp") {
      std::ifstream in(path, std::ios::binary);
      std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      if (!in && !in.eof()) throw GeometryError("could not read " + path.string());
      shape = readBrep(std::move(text), "BREP file " + path.string());
    } else {
      throw GeometryError("unknown part file type '" + ext + "' (use .brep or .step): " + path.string());
    }
  } catch (const Standard_Failure& e) {
    throw GeometryError("could not read " + path.string() + ": " + e.GetMessageString());
  }
  return fromShape(shape, unit, path.stem().string(), options);
}

PartModelPtr PartModel::fromShape(const TopoDS_Shape& input, LengthUnit unit, std::string name,
                                  const LoadOptions& options) {
  if (input.IsNull()) throw GeometryError("empty shape");
  std::shared_ptr<PartModel> part(new PartModel);
  part->name_ = std::move(name);
  part->metresPerUnit_ = metresPer(unit);
  const double s = part->metresPerUnit_;
  try {
    TopoDS_Shape solids = solidsOf(input, part->warnings_);
    checkClosedAndValid(solids, options);
    solids = outwardSolids(solids, part->warnings_);
    checkSelfIntersection(solids, options);
    GProp_GProps props;
    BRepGProp::VolumeProperties(solids, props);
    const double volume = props.Mass();
    Bnd_Box box;
    BRepBndLib::AddOptimal(solids, box, false, false);
    const double diagonal = std::sqrt(box.SquareExtent());
    if (!(volume > 1e-12 * diagonal * diagonal * diagonal)) throw GeometryError("solid has no volume");

    part->shape_ = solids;
    TopExp::MapShapes(solids, TopAbs_FACE, part->faces_);
    TopExp::MapShapes(solids, TopAbs_EDGE, part->edges_);
    TopExp::MapShapes(solids, TopAbs_VERTEX, part->vertices_);
    double x0, y0, z0, x1, y1, z1;
    box.Get(x0, y0, z0, x1, y1, z1);
    part->bounds_ = {Vec3(x0, y0, z0) * s, Vec3(x1, y1, z1) * s};
    part->volume_m3_ = volume * s * s * s;
    part->centre_m_ = toVec(props.CentreOfMass().XYZ()) * s;
    const gp_Mat I = props.MatrixOfInertia();  // about the centre of mass, density 1
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) part->unitDensityInertia_(r, c) = I(r + 1, c + 1) * std::pow(s, 5);
    part->primitive_ = recognisePrimitive(solids, s, part->volume_m3_);
  } catch (const Standard_Failure& e) {
    throw GeometryError(std::string("OpenCASCADE failed on the shape: ") + e.GetMessageString());
  }
  return part;
}

MassProperties PartModel::massProperties(const MassSpec& spec) const {
  if (!(spec.value > 0)) throw GeometryError("mass and density must be positive");
  const double density = spec.kind == MassSpec::Kind::Density ? spec.value : spec.value / volume_m3_;
  return {volume_m3_, density * volume_m3_, centre_m_, density * unitDensityInertia_};
}

}  // namespace hg::geometry
