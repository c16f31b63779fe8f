#include "hapticgrasp/geometry/shape_validity.hpp"

#include <BRepCheck.hxx>
#include <BRepCheck_Edge.hxx>
#include <BRepCheck_Face.hxx>
#include <BRepCheck_ListOfStatus.hxx>
#include <BRepCheck_Result.hxx>
#include <BRepCheck_Shell.hxx>
#include <BRepCheck_Solid.hxx>
#include <BRepCheck_Vertex.hxx>
#include <BRepCheck_Wire.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <BndLib_Add2dCurve.hxx>
#include <Bnd_Box2d.hxx>
#include <Geom2dAdaptor_Curve.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_Curve.hxx>
#include <NCollection_IndexedDataMap.hxx>
#include <Precision.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_DataMapOfShapeShape.hxx>
#include <TopTools_MapOfShape.hxx>
#include <TopTools_ShapeMapHasher.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>

#include <algorithm>
#include <memory>
#include <sstream>
#include <vector>

#include "shape_names.hpp"

namespace hg::geometry {
namespace {

// Faces with more wires than this have theirs classified through boxes (below); the others
// by BRepCheck_Face itself, which is as fast for them.
constexpr int kManyWires = 16;

using ResultMap = NCollection_IndexedDataMap<TopoDS_Shape, Handle(BRepCheck_Result), TopTools_ShapeMapHasher>;

// One wire of a face with many wires: is it a hole, which box holds it, a point on it.
struct Loop {
  TopoDS_Wire wire;
  bool hole = false;         // oriented as a hole: the infinite point is inside it
  Bnd_Box2d box;             // its pcurves
  bool hasPoint = false;
  gp_Pnt2d point;            // on it, where BRepCheck_Face samples it
  std::unique_ptr<BRepTopAdaptor_FClass2d> classifier;  // a face bounded by this wire alone
  int holds = 0;             // other wires inside it
};

// The point of a wire BRepCheck_Face tests against the other wires: the middle of its
// first edge that is neither too short in parameter nor in space.
bool wirePoint(const TopoDS_Wire& wire, const TopoDS_Face& face, gp_Pnt2d& point) {
  for (TopExp_Explorer ex(wire, TopAbs_EDGE); ex.More(); ex.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(ex.Current());
    double first, last;
    const Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(edge, face, first, last);
    if (pcurve.IsNull()) continue;
    double t;
    if (!Precision::IsNegativeInfinite(first) && !Precision::IsPositiveInfinite(last)) {
      t = (first + last) / 2;
      if (std::abs(t - first) < Precision::PConfusion()) continue;
      double first3d, last3d;
      const Handle(Geom_Curve) curve = BRep_Tool::Curve(edge, first3d, last3d);
      if (curve.IsNull()) continue;
      if (curve->Value(first).Distance(curve->Value((first3d + last3d) / 2)) < Precision::Confusion()) continue;
    } else if (Precision::IsNegativeInfinite(first) && Precision::IsPositiveInfinite(last)) {
      t = 0;
    } else {
      t = Precision::IsNegativeInfinite(first) ? last - 1 : first + 1;
    }
    point = pcurve->Value(t);
    return true;
  }
  return false;
}

Bnd_Box2d wireBox(const TopoDS_Wire& wire, const TopoDS_Face& face) {
  Bnd_Box2d box;
  for (TopExp_Explorer ex(wire, TopAbs_EDGE); ex.More(); ex.Next()) {
    double first, last;
    const Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(TopoDS::Edge(ex.Current()), face, first, last);
    if (pcurve.IsNull()) continue;
    const Geom2dAdaptor_Curve adaptor(pcurve);
    BndLib_Add2dCurve::Add(adaptor, std::max(first, adaptor.FirstParameter()), std::min(last, adaptor.LastParameter()),
                           0., box);
  }
  return box;
}

// BRepCheck_Face::OrientationOfWires for a face with many wires. The face is valid when one
// wire holds all the others, none of the others holds any, the holding one is not oriented
// as a hole and all the others are; a single wire must not be a hole (unless the face is
// infinite). "Holds" is BRepCheck_Face's test: the other wire's point classified against
// a face bounded by this wire alone. A point outside this wire's box cannot be inside it,
// so only the wires whose points fall in the box are classified: for a plate with 1024
// holes, 1024 classifications against its outline instead of a million.
// Returns nothing when the face is the exception this does not reproduce (an outline
// oriented as a hole made of two edges, which BRepCheck_Face accepts when thin).
std::optional<BRepCheck_Status> orientationOfManyWires(const TopoDS_Face& face, BRepCheck_Face& result) {
  const BRepCheck_Status crossing = result.IntersectWires();  // box-filtered already
  if (crossing != BRepCheck_NoError) return crossing;
  const TopoDS_Face forward = TopoDS::Face(face.Oriented(TopAbs_FORWARD));
  std::vector<Loop> loops;
  BRep_Builder builder;
  for (TopExp_Explorer ex(forward, TopAbs_WIRE); ex.More(); ex.Next()) {
    Loop& loop = loops.emplace_back();
    loop.wire = TopoDS::Wire(ex.Current());
    TopoDS_Face alone = TopoDS::Face(forward.EmptyCopied());
    alone.Orientation(TopAbs_FORWARD);
    builder.Add(alone, loop.wire);
    loop.classifier = std::make_unique<BRepTopAdaptor_FClass2d>(alone, Precision::PConfusion());
    loop.hole = loop.classifier->PerformInfinitePoint() != TopAbs_OUT;
    loop.box = wireBox(loop.wire, forward);
    loop.hasPoint = wirePoint(loop.wire, forward, loop.point);
  }
  const int n = static_cast<int>(loops.size());
  for (Loop& outer : loops) {
    for (const Loop& inner : loops) {
      if (&inner == &outer || !inner.hasPoint || outer.box.IsOut(inner.point)) continue;
      const TopAbs_State state = outer.classifier->Perform(inner.point, false);
      if (outer.hole ? state == TopAbs_OUT : state == TopAbs_IN) ++outer.holds;
    }
  }
  const Loop* outline = nullptr;
  for (const Loop& loop : loops) {
    if (loop.holds == 0) continue;
    if (outline) return BRepCheck_InvalidImbricationOfWires;  // two wires hold others
    outline = &loop;
  }
  if (outline && outline->holds != n - 1) return BRepCheck_InvalidImbricationOfWires;
  if (!outline && n == 1 && !face.Infinite()) outline = &loops[0];
  if (!outline) return face.Infinite() || n == 0 ? BRepCheck_NoError : BRepCheck_InvalidImbricationOfWires;
  if (outline->hole) {
    int edges = 0;
    for (TopExp_Explorer ex(outline->wire, TopAbs_EDGE); ex.More(); ex.Next()) ++edges;
    if (edges == 2) return std::nullopt;
    return BRepCheck_BadOrientationOfSubshape;
  }
  for (const Loop& loop : loops)
    if (&loop != outline && !loop.hole) return BRepCheck_BadOrientationOfSubshape;
  return BRepCheck_NoError;
}

bool hasStatusOn(const Handle(BRepCheck_Result)& result, const TopoDS_Shape& context,
                 std::initializer_list<BRepCheck_Status> which) {
  if (!result->IsStatusOnShape(context)) return false;
  for (const BRepCheck_Status status : result->StatusOnShape(context)) {
    if (which.size() == 0 ? status != BRepCheck_NoError
                          : std::find(which.begin(), which.end(), status) != which.end())
      return true;
  }
  return false;
}

// BRepCheck_Analyzer's work, in its order, on one thread.
class Analysis {
 public:
  explicit Analysis(const TopoDS_Shape& shape) { put(shape); }

  void run() {
    for (int i = 1; i <= results_.Extent(); ++i) {
      const TopoDS_Shape& shape = results_.FindKey(i);
      const Handle(BRepCheck_Result)& result = results_(i);
      if (result.IsNull()) continue;
      switch (shape.ShapeType()) {
        case TopAbs_EDGE: checkEdge(TopoDS::Edge(shape), result); break;
        case TopAbs_FACE: checkFace(TopoDS::Face(shape), result); break;
        case TopAbs_SOLID: inContext(shape, TopAbs_SHELL, result); break;
        default: break;
      }
    }
  }

  std::optional<ValidityProblem> firstProblem() const {
    for (const TopAbs_ShapeEnum type : {TopAbs_VERTEX, TopAbs_EDGE, TopAbs_WIRE, TopAbs_FACE, TopAbs_SHELL, TopAbs_SOLID})
      for (int i = 1; i <= results_.Extent(); ++i) {
        const TopoDS_Shape& shape = results_.FindKey(i);
        const Handle(BRepCheck_Result)& result = results_(i);
        if (shape.ShapeType() != type || result.IsNull()) continue;
        for (const BRepCheck_Status status : result->Status())
          if (status != BRepCheck_NoError) return ValidityProblem{shape, TopoDS_Shape(), status};
        for (result->InitContextIterator(); result->MoreShapeInContext(); result->NextShapeInContext())
          for (const BRepCheck_Status status : result->StatusOnShape())
            if (status != BRepCheck_NoError) return ValidityProblem{shape, original(result->ContextualShape()), status};
      }
    return std::nullopt;
  }

 private:
  void put(const TopoDS_Shape& shape) {
    if (results_.Contains(shape)) return;
    Handle(BRepCheck_Result) result;
    switch (shape.ShapeType()) {
      case TopAbs_VERTEX: result = new BRepCheck_Vertex(TopoDS::Vertex(shape)); break;
      case TopAbs_EDGE: result = new BRepCheck_Edge(TopoDS::Edge(shape)); break;
      case TopAbs_WIRE: result = new BRepCheck_Wire(TopoDS::Wire(shape)); break;
      case TopAbs_FACE: result = new BRepCheck_Face(TopoDS::Face(shape)); break;
      case TopAbs_SHELL: result = new BRepCheck_Shell(TopoDS::Shell(shape)); break;
      case TopAbs_SOLID: result = new BRepCheck_Solid(TopoDS::Solid(shape)); break;
      default: break;
    }
    results_.Add(shape, result);
    for (TopoDS_Iterator it(shape); it.More(); it.Next()) put(it.Value());
  }

  // Each sub-shape of `type` (once) checked in the context of `shape`; true if none failed.
  bool inContext(const TopoDS_Shape& shape, TopAbs_ShapeEnum type, const Handle(BRepCheck_Result)& result) {
    TopTools_MapOfShape done;
    bool ok = true;
    for (TopExp_Explorer ex(shape, type); ex.More(); ex.Next()) {
      if (!done.Add(ex.Current())) continue;
      const Handle(BRepCheck_Result)& sub = results_.FindFromKey(ex.Current());
      try {
        sub->InContext(shape);
      } catch (const Standard_Failure&) {
        result->SetFailStatus(shape);
        sub->SetFailStatus(ex.Current());
        sub->SetFailStatus(shape);
        ok = false;
      }
    }
    return ok;
  }

  void checkEdge(const TopoDS_Edge& edge, const Handle(BRepCheck_Result)& result) {
    try {
      const Handle(BRepCheck_Edge) edgeResult = Handle(BRepCheck_Edge)::DownCast(result);
      const BRepCheck_Status status = edgeResult->CheckPolygonOnTriangulation(edge);
      if (status != BRepCheck_NoError) edgeResult->SetStatus(status);
    } catch (const Standard_Failure&) {
      result->SetFailStatus(edge);
    }
    inContext(edge, TopAbs_VERTEX, result);
  }

  // The contexts a face's vertices, edges and wires are checked in: the face itself, or for
  // a face with many wires one copy of it per wire, bounded by that wire alone. BRepCheck
  // looks each sub-shape up among all those of its context, and searches the whole face for
  // seams once per wire: quadratic in the wires. A copy shares the face's surface, location
  // and orientation, so each check on it is the check on the face.
  std::vector<TopoDS_Face> contextsOf(const TopoDS_Face& face, int wires) {
    if (wires <= kManyWires) return {face};
    std::vector<TopoDS_Face> contexts;
    BRep_Builder builder;
    for (TopoDS_Iterator it(face); it.More(); it.Next()) {
      TopoDS_Face alone = TopoDS::Face(face.EmptyCopied());
      builder.Add(alone, it.Value());
      substitutes_.Bind(alone, face);
      contexts.push_back(alone);
    }
    return contexts;
  }

  // As the analyzer: the wires' orientation is judged only when every edge has a good
  // curve on the face and every wire is fine on it.
  void checkFace(const TopoDS_Face& face, const Handle(BRepCheck_Result)& result) {
    int wires = 0;
    for (TopExp_Explorer ex(face, TopAbs_WIRE); ex.More(); ex.Next()) ++wires;
    bool edgesFit = true, wiresFit = true;
    for (const TopoDS_Face& context : contextsOf(face, wires)) {
      inContext(context, TopAbs_VERTEX, result);
      inContext(context, TopAbs_EDGE, result);
      for (TopExp_Explorer ex(context, TopAbs_EDGE); edgesFit && ex.More(); ex.Next())
        if (hasStatusOn(results_.FindFromKey(ex.Current()), context,
                        {BRepCheck_NoCurveOnSurface, BRepCheck_InvalidCurveOnSurface, BRepCheck_InvalidRange,
                         BRepCheck_InvalidCurveOnClosedSurface}))
          edgesFit = false;
      inContext(context, TopAbs_WIRE, result);
      for (TopExp_Explorer ex(context, TopAbs_WIRE); wiresFit && ex.More(); ex.Next())
        if (hasStatusOn(results_.FindFromKey(ex.Current()), context, {})) wiresFit = false;
    }
    const Handle(BRepCheck_Face) faceResult = Handle(BRepCheck_Face)::DownCast(result);
    try {
      if (!edgesFit || !wiresFit) {
        faceResult->SetUnorientable();
        return;
      }
      if (wires > kManyWires) {
        if (const auto status = orientationOfManyWires(face, *faceResult)) {
          if (*status != BRepCheck_NoError) faceResult->SetStatus(*status);
          return;
        }
      }
      faceResult->OrientationOfWires(true);
    } catch (const Standard_Failure&) {
      result->SetFailStatus(face);
    }
  }

  // The face a context stands for.
  TopoDS_Shape original(const TopoDS_Shape& context) const {
    const TopoDS_Shape* face = substitutes_.Seek(context);
    return face ? *face : context;
  }

  ResultMap results_;
  TopTools_DataMapOfShapeShape substitutes_;  // a face's copy with one wire -> the face
};

std::string statusName(BRepCheck_Status status) {
  std::ostringstream out;
  BRepCheck::Print(status, out);
  std::string text = out.str();
  text.erase(std::remove(text.begin(), text.end(), '\n'), text.end());
  return text;
}

}  // namespace

std::optional<ValidityProblem> firstValidityProblem(const TopoDS_Shape& shape) {
  Analysis analysis(shape);
  analysis.run();
  return analysis.firstProblem();
}

std::string describe(const ValidityProblem& problem, const TopoDS_Shape& numbering) {
  TopoDS_Shape context = problem.context;
  if (context.IsNull() && problem.shape.ShapeType() == TopAbs_WIRE) {
    // BRepCheck records a wire's own faults on the wire: name the face it bounds.
    for (TopExp_Explorer f(numbering, TopAbs_FACE); f.More() && context.IsNull(); f.Next())
      for (TopoDS_Iterator w(f.Current()); w.More(); w.Next())
        if (w.Value().IsSame(problem.shape)) {
          context = f.Current();
          break;
        }
  }
  if (problem.status == BRepCheck_SelfIntersectingWire && !context.IsNull())
    return "self-intersecting wire in " + subShapeName(numbering, context);
  const std::string where = subShapeName(numbering, problem.shape);
  if (context.IsNull()) return where + ": " + statusName(problem.status);
  return where + " in " + subShapeName(numbering, context) + ": " + statusName(problem.status);
}

}  // namespace hg::geometry
