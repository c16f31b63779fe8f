#include "part_check.hpp"

#include <BRepBndLib.hxx>
#include <BRepGProp.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <Precision.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_MapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Vertex.hxx>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <future>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "curve_on_face.hpp"
#include "hapticgrasp/geometry/face_crossings.hpp"
#include "hapticgrasp/geometry/shape_validity.hpp"
#include "shape_healing.hpp"
#include "shape_names.hpp"
#include "shape_topology.hpp"
#include "solid_overlaps.hpp"

namespace hg::geometry {
namespace {

// What is wrong with a part's solids, as the checks found it.
struct Findings {
  std::string defect;                          // the first real defect in words, "" if none
  std::set<std::pair<int, int>> crossingSolids;  // pairs of solids whose boundaries cross
  int unmeshed = 0;                            // faces the crossing search could not mesh
  bool searched = false;                       // the crossing search ran
  bool truncated = false;                      // it confirmed only some of its candidates
  bool meshingStopped = false;                 // its meshing stopped at its budget
  bool pairsStopped = false;                   // so did its comparing of boxes
};

std::string facePairName(const TopoDS_Shape& numbering, const FaceCrossing& c) {
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(numbering, TopAbs_FACE, faces);
  return "faces " + std::to_string(faces.FindIndex(c.a)) + " and " + std::to_string(faces.FindIndex(c.b)) + " cross";
}

// BRepCheck's first problem among the solids, each distinct shape checked once wherever it
// is placed (an assembly repeats its bolts and nuts), named where it first stands.
std::optional<ValidityProblem> firstProblemOfEachShape(const TopoDS_Shape& solids) {
  TopTools_MapOfShape seen;
  for (TopExp_Explorer ex(solids, TopAbs_SOLID); ex.More(); ex.Next()) {
    const TopLoc_Location& placed = ex.Current().Location();
    if (!seen.Add(ex.Current().Located(TopLoc_Location()))) continue;
    auto problem = firstValidityProblem(ex.Current().Located(TopLoc_Location()));
    if (!problem) continue;
    problem->shape.Move(placed);
    if (!problem->context.IsNull()) problem->context.Move(placed);
    return problem;
  }
  return std::nullopt;
}

// The crossing search, or nothing if OCCT failed in it. A fault is caught here, in the
// thread that runs the search: caught further up (PartModel::load), it would jump past the
// frames between, and past findDefects' future (found by fuzz_brep).
std::optional<CrossingSearch> searchCrossings(const TopoDS_Shape& solids) {
  try {
    OCC_CATCH_SIGNALS
    return findFaceCrossings(solids);
  } catch (const Standard_Failure&) {
    return std::nullopt;  // what the validity check finds stands
  }
}

// The validity check and the crossing search read the shape and build their own data: with
// `parallel`, they run side by side.
Findings findDefects(const TopoDS_Shape& solids, const PartLoadOptions& options) {
  Findings found;
  std::future<std::optional<CrossingSearch>> crossings;
  if (options.checkSelfIntersection)
    crossings = std::async(options.parallel ? std::launch::async : std::launch::deferred,
                           [&solids] { return searchCrossings(solids); });
  try {
    // A fault in BRepCheck is caught here, not in PartModel::load: jumping there would skip
    // the future below, leaking it and, with `parallel`, leaving the search running on a
    // shape about to be freed (fuzz_brep found such a part: BRepCheck at address 0).
    OCC_CATCH_SIGNALS
    if (const auto problem = firstProblemOfEachShape(solids)) found.defect = describe(*problem, solids);
  } catch (const Standard_Failure& e) {
    found.defect = std::string("BRepCheck failed on the shape (") + e.GetMessageString() + ")";
  }
  if (!crossings.valid()) return found;
  const std::optional<CrossingSearch> result = crossings.get();
  if (!result) return found;
  const CrossingSearch& search = *result;
  found.searched = true;
  found.truncated = search.truncated;
  found.meshingStopped = search.meshingStopped;
  found.pairsStopped = search.pairsStopped;
  found.unmeshed = static_cast<int>(search.unmeshed.size());
  int within = 0;
  const FaceCrossing* first = nullptr;
  for (const FaceCrossing& c : search.crossings) {
    if (c.solidA != c.solidB) {
      found.crossingSolids.insert({std::min(c.solidA, c.solidB), std::max(c.solidA, c.solidB)});
    } else if (within++ == 0) {
      first = &c;
    }
  }
  if (first && found.defect.empty()) {
    found.defect = facePairName(solids, *first);
    if (within > 1) found.defect += ", and " + std::to_string(within - 1) + " more pairs";
  }
  return found;
}

double diagonalOf(const TopoDS_Shape& shape) {
  Bnd_Box box;
  BRepBndLib::Add(shape, box);
  return box.IsVoid() ? 0 : std::sqrt(box.SquareExtent());
}

// A shape ShapeFix returned is usable only as closed solids.
bool closedSolids(const TopoDS_Shape& shape) {
  int count = 0;
  for (TopExp_Explorer ex(shape, TopAbs_SOLID); ex.More(); ex.Next(), ++count) {
    const UnsharedEdges open = edgesNotShared(ex.Current());
    if (open.free > 0 || open.nonManifold > 0) return false;
  }
  return count > 0;
}

// Pairs of distinct vertices of one solid closer than the sum of their tolerances: what
// BOPAlgo reports as vertex/vertex interferences. STEP files from other systems carry large
// tolerances, and these are normal there. Each shape shared by several solids counts once.
int toleranceContacts(const TopoDS_Shape& solids) {
  int count = 0;
  TopTools_MapOfShape seen;
  for (TopExp_Explorer ex(solids, TopAbs_SOLID); ex.More(); ex.Next()) {
    if (!seen.Add(ex.Current().Located(TopLoc_Location()))) continue;
    TopTools_IndexedMapOfShape vertices;
    TopExp::MapShapes(ex.Current(), TopAbs_VERTEX, vertices);
    struct Point {
      gp_Pnt p;
      double tol;
    };
    std::vector<Point> points;
    double largest = 0;
    for (int i = 1; i <= vertices.Extent(); ++i) {
      const TopoDS_Vertex& v = TopoDS::Vertex(vertices(i));
      points.push_back({BRep_Tool::Pnt(v), BRep_Tool::Tolerance(v)});
      largest = std::max(largest, points.back().tol);
    }
    std::sort(points.begin(), points.end(), [](const Point& a, const Point& b) { return a.p.X() < b.p.X(); });
    for (std::size_t i = 0; i < points.size(); ++i)
      for (std::size_t j = i + 1; j < points.size() && points[j].p.X() - points[i].p.X() <= points[i].tol + largest; ++j)
        if (points[i].p.Distance(points[j].p) <= points[i].tol + points[j].tol) ++count;
  }
  return count;
}

std::string millimetres3(double volume, double metresPerUnit) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g mm^3", volume * std::pow(metresPerUnit * 1e3, 3));
  return text;
}

// One line for all the overlaps of a compound's solids.
std::string overlapWarning(const std::vector<SolidOverlap>& overlaps, const TopoDS_Shape& solids, double metresPerUnit) {
  GProp_GProps props;
  BRepGProp::VolumeProperties(solids, props);
  const double total = props.Mass();
  double sum = 0;
  bool allMeasured = true;
  std::string each;
  for (const SolidOverlap& o : overlaps) {
    if (o.volume >= 0) sum += o.volume;
    else allMeasured = false;
    if (!each.empty()) each += ", ";
    each += std::to_string(o.a) + " and " + std::to_string(o.b) +
            (o.volume >= 0 ? " (" + millimetres3(o.volume, metresPerUnit) + ")" : " (not measured)");
  }
  char share[64];
  std::snprintf(share, sizeof share, "%.3g %% of the part's volume", total > 0 ? 100 * sum / total : 0.0);
  const std::string amount = (allMeasured ? "" : "at least ") + millimetres3(sum, metresPerUnit) + ", " + share;
  if (overlaps.size() == 1)
    return "solids " + each.substr(0, each.find(" (")) + " overlap by " + amount +
           ": the mass properties count it twice";
  return std::to_string(overlaps.size()) + " pairs of solids overlap by " + amount +
         " in all: the mass properties count it twice (solids " + each + ")";
}

// What the mesh does with faces whose edges stray from them (tessellation.cpp), in one line.
std::string filledFromEdges(const std::vector<FaceOffItsEdges>& off, double metresPerUnit) {
  const auto worst = std::max_element(off.begin(), off.end(), [](const FaceOffItsEdges& a, const FaceOffItsEdges& b) {
    return a.distance < b.distance;
  });
  char stray[64] = "cannot be followed on";  // OCCT could not compare the curves
  if (std::isfinite(worst->distance))
    std::snprintf(stray, sizeof stray, "lies %.3g mm off", worst->distance * metresPerUnit * 1e3);
  const std::string edge = "edge " + std::to_string(worst->edge) + " " + stray;
  if (off.size() == 1)
    return "face " + std::to_string(worst->face) + " is filled from its edges in the mesh: " + edge + " it";
  std::string faces;
  for (const FaceOffItsEdges& f : off) faces += (faces.empty() ? "" : ", ") + std::to_string(f.face);
  return std::to_string(off.size()) + " faces are filled from their edges in the mesh (faces " + faces + "): " + edge +
         " face " + std::to_string(worst->face);
}

BackendChoice robustBackend(const std::string& defect) {
#ifdef HG_WITH_EMBREE
  return {Backend::Mesh, "mesh 0.01 mm: " + defect + " (not healable); the exact back end would answer wrongly there",
          true};
#else
  return {Backend::Field, "field 1 mm: " + defect + " (not healable); the exact back end would answer wrongly there", true};
#endif
}

}  // namespace

PartCheck checkPart(const TopoDS_Shape& solids, const PartLoadOptions& options, double metresPerUnit) {
  PartCheck out;
  out.solids = solids;
  Findings found = findDefects(solids, options);
  if (found.defect.empty()) {
    const int contacts = toleranceContacts(solids);
    out.choice = {Backend::Exact, "exact: valid B-rep"};
    if (contacts > 0)
      out.choice.reason += " (" + std::to_string(contacts) + " vertex pair" + (contacts > 1 ? "s" : "") +
                           " within their tolerances, normal for STEP)";
  } else {
    // ShapeFix may grow tolerances up to a ten-thousandth of the part's size to close what
    // it repairs: tolerance-level, as the files of other systems are.
    const double diagonal = diagonalOf(solids);
    const std::string notHealable = unhealable(solids);
    const TopoDS_Shape healed = notHealable.empty()
                                    ? healWithShapeFix(solids, Precision::Confusion(), std::max(1e-4 * diagonal, 1e-6))
                                    : solids;
    Findings again;
    const bool usable = !healed.IsSame(solids) && closedSolids(healed) &&
                        (again = findDefects(healed, options)).defect.empty();
    // The choice's reason says what was healed, or what is wrong: not repeated as a warning.
    if (usable) {
      out.choice = {Backend::Exact, "exact: healed by ShapeFix (" + found.defect + ")"};
      out.solids = healed;
      found = again;
    } else {
      out.choice = robustBackend(notHealable.empty() ? found.defect : found.defect + "; " + notHealable);
      if (const auto off = curvedFacesOffTheirEdges(solids, kMaxEdgeStray * diagonal); !off.empty())
        out.warnings.push_back(filledFromEdges(off, metresPerUnit));
    }
  }
  if (found.unmeshed > 0)
    out.warnings.push_back(std::to_string(found.unmeshed) +
                           (found.unmeshed > 1 ? " faces could not be meshed and were" : " face could not be meshed and was") +
                           " not searched for crossings");
  if (found.truncated)
    out.warnings.push_back("the crossing search confirmed only its first candidates: faces may cross elsewhere");
  if (found.meshingStopped)
    out.warnings.push_back("the crossing search's meshing stopped at its budget: faces may cross where it did not reach");
  if (found.pairsStopped)
    out.warnings.push_back("the crossing search compared the boxes of its triangles up to its budget (a face folds on "
                           "itself?): faces may cross where it did not reach");
  if (options.checkSelfIntersection) {
    const std::vector<SolidOverlap> overlaps = findSolidOverlaps(out.solids, found.crossingSolids);
    if (!overlaps.empty()) out.warnings.push_back(overlapWarning(overlaps, out.solids, metresPerUnit));
  }
  return out;
}

}  // namespace hg::geometry
