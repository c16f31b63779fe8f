#include "solid_overlaps.hpp"

#include <BRepAlgoAPI_Common.hxx>
#include <BRepBndLib.hxx>
#include <BRepClass3d_SolidClassifier.hxx>
#include <BRepGProp.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Vertex.hxx>

#include <optional>

namespace hg::geometry {
namespace {

// Where a point of `inner` lies with respect to `outer`, from the first of its vertices
// (then its centre of mass, when inside it) that is not on `outer`'s boundary; nothing when
// every one is (coincident solids decide nothing here).
std::optional<TopAbs_State> pointOfInside(const TopoDS_Shape& inner, const TopoDS_Shape& outer) {
  BRepClass3d_SolidClassifier classifier(outer);
  for (TopExp_Explorer ex(inner, TopAbs_VERTEX); ex.More(); ex.Next()) {
    const TopoDS_Vertex& v = TopoDS::Vertex(ex.Current());
    classifier.Perform(BRep_Tool::Pnt(v), BRep_Tool::Tolerance(v));
    if (classifier.State() != TopAbs_ON) return classifier.State();
  }
  GProp_GProps props;
  BRepGProp::VolumeProperties(inner, props);
  BRepClass3d_SolidClassifier self(inner, props.CentreOfMass(), 1e-7);
  if (self.State() != TopAbs_IN) return std::nullopt;
  classifier.Perform(props.CentreOfMass(), 1e-7);
  if (classifier.State() != TopAbs_ON) return classifier.State();
  return std::nullopt;
}

bool inside(const Bnd_Box& inner, const Bnd_Box& outer) {
  double a[6], b[6];
  inner.Get(a[0], a[1], a[2], a[3], a[4], a[5]);
  outer.Get(b[0], b[1], b[2], b[3], b[4], b[5]);
  return a[0] >= b[0] && a[1] >= b[1] && a[2] >= b[2] && a[3] <= b[3] && a[4] <= b[4] && a[5] <= b[5];
}

double commonVolume(const TopoDS_Shape& a, const TopoDS_Shape& b) {
  try {
    BRepAlgoAPI_Common common(a, b);
    if (common.HasErrors()) return -1;
    GProp_GProps props;
    BRepGProp::VolumeProperties(common.Shape(), props);
    return props.Mass();
  } catch (const Standard_Failure&) {
    return -1;
  }
}

}  // namespace

std::vector<SolidOverlap> findSolidOverlaps(const TopoDS_Shape& shape, const std::set<std::pair<int, int>>& crossing,
                                            int maxMeasured) {
  TopTools_IndexedMapOfShape solids;
  TopExp::MapShapes(shape, TopAbs_SOLID, solids);
  std::vector<SolidOverlap> out;
  if (solids.Extent() < 2) return out;
  std::vector<Bnd_Box> boxes(solids.Extent());
  for (int i = 1; i <= solids.Extent(); ++i) {
    BRepBndLib::Add(solids(i), boxes[i - 1]);
    boxes[i - 1].Enlarge(BRep_Tool::MaxTolerance(solids(i), TopAbs_VERTEX));
  }
  for (int i = 1; i <= solids.Extent(); ++i)
    for (int j = i + 1; j <= solids.Extent(); ++j) {
      if (boxes[i - 1].IsOut(boxes[j - 1])) continue;
      bool overlaps = crossing.count({i, j}) > 0;
      try {
        if (!overlaps && inside(boxes[i - 1], boxes[j - 1])) overlaps = pointOfInside(solids(i), solids(j)) == TopAbs_IN;
        if (!overlaps && inside(boxes[j - 1], boxes[i - 1])) overlaps = pointOfInside(solids(j), solids(i)) == TopAbs_IN;
      } catch (const Standard_Failure&) {
        // A classification that failed finds nothing; crossing pairs are already known.
      }
      if (overlaps) out.push_back({i, j, -1});
    }
  for (std::size_t k = 0; k < out.size() && static_cast<int>(k) < maxMeasured; ++k)
    out[k].volume = commonVolume(solids(out[k].a), solids(out[k].b));
  return out;
}

}  // namespace hg::geometry
