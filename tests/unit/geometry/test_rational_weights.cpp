// Weights of rational curves and surfaces: real parts' lie close together, a damaged
// loft's (fuzz_brep) 1.8e17 times apart, and each kind of carrier is found.
#include <gtest/gtest.h>

#include <BRepBuilderAPI_Copy.hxx>
#include <BRepBuilderAPI_NurbsConvert.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRep_Tool.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <STEPControl_Reader.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>

#include <filesystem>
#include <string>

#include "geometry/curve_on_face.hpp"
#include "geometry/rational_weights.hpp"
#include "test_shapes.hpp"

namespace hg::geometry {
namespace {

namespace fs = std::filesystem;
const fs::path kData = HG_TEST_DATA_DIR;

// A 50 x 400 mm cylinder as NURBS: its circles and its side are rational.
TopoDS_Shape nurbsCylinder() {
  return BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeCylinder(50, 400).Shape(), true).Shape();
}

TEST(RationalWeights, APartWithoutWeightsSpreadsNone) {
  const WeightSpread widest = widestWeights(BRepPrimAPI_MakeCylinder(50, 400).Shape());
  EXPECT_EQ(widest.spread, 1);
  EXPECT_EQ(widest.where, "");
}

TEST(RationalWeights, ACircleAsNurbsIsRationalAndFine) {
  const TopoDS_Shape cylinder = nurbsCylinder();
  const WeightSpread widest = widestWeights(cylinder);
  EXPECT_GT(widest.spread, 1.1);  // the circle's 1/cos weights
  EXPECT_LT(widest.spread, 3);
  EXPECT_EQ(weightsTooFarApart(cylinder), "");
  EXPECT_EQ(damagedGeometry(cylinder), "");
}

// The same cylinder with one weight of its side, then of an edge's 3D curve, made heavy.
TEST(RationalWeights, WeightsFarApartAreNamed) {
  const TopoDS_Shape cylinder = nurbsCylinder();
  TopTools_IndexedMapOfShape faces, edges;
  TopExp::MapShapes(cylinder, TopAbs_FACE, faces);
  TopExp::MapShapes(cylinder, TopAbs_EDGE, edges);
  TopLoc_Location location;
  const auto side = Handle(Geom_BSplineSurface)::DownCast(BRep_Tool::Surface(TopoDS::Face(faces(1)), location));
  ASSERT_FALSE(side.IsNull());
  const double weight = side->Weight(1, 1);
  side->SetWeight(1, 1, weight * 0.4e8);  // within the limit: the side's weights were 2 apart
  EXPECT_EQ(weightsTooFarApart(cylinder), "");
  side->SetWeight(1, 1, weight * 1e9);
  EXPECT_EQ(widestWeights(cylinder).where, "face 1's surface");
  EXPECT_EQ(damagedGeometry(cylinder), "face 1's surface has weights 2e+09 times apart");
  side->SetWeight(1, 1, weight);

  double first = 0, last = 0;
  for (int i = 1; i <= edges.Extent(); ++i) {
    const auto curve = Handle(Geom_BSplineCurve)::DownCast(BRep_Tool::Curve(TopoDS::Edge(edges(i)), first, last));
    if (curve.IsNull() || !curve->IsRational()) continue;
    curve->SetWeight(2, curve->Weight(2) * 1e12);
    EXPECT_EQ(widestWeights(cylinder).where, "edge " + std::to_string(i) + "'s curve");
    EXPECT_NE(weightsTooFarApart(cylinder), "");
    return;
  }
  FAIL() << "no rational 3D curve in the NURBS cylinder";
}

// A loft whose weights were 1 and, by a mutation, 1.8e17, with a pole 88 km off: BRepMesh's
// Delaunay triangulation for the crossing search took 6 GB in 12 s.
TEST(RationalWeights, TheFuzzedLoftIsRefused) {
  const TopoDS_Shape loft = test::readShape(kData / "../fuzz/corpus/brep/oom_rational_weights_far_apart.brep");
  EXPECT_EQ(damagedGeometry(loft), "face 1's surface has weights 1.8e+17 times apart");
}

// Real parts: the corpus, its external STEP files and the sample parts. The assembly from
// elsewhere has the widest (3, in 280 of its curves and surfaces).
TEST(RationalWeights, RealPartsLieAtMostThreeTimesApart) {
  double widest = 1;
  for (const fs::path& folder : {kData / "../corpus/parts", fs::path(HG_RESOURCES_DIR) / "parts"})
    for (const fs::directory_entry& file : fs::directory_iterator(folder))
      if (file.path().extension() == ".brep") {
        const WeightSpread w = widestWeights(test::readShape(file.path()));
        EXPECT_LE(w.spread, 3) << file.path() << ": " << w.where;
        widest = std::max(widest, w.spread);
      }
  for (const fs::directory_entry& file : fs::directory_iterator(kData / "../corpus/external")) {
    STEPControl_Reader reader;
    ASSERT_EQ(reader.ReadFile(file.path().c_str()), IFSelect_RetDone) << file.path();
    reader.TransferRoots();
    const WeightSpread w = widestWeights(reader.OneShape());
    EXPECT_LE(w.spread, 3 + 1e-9) << file.path() << ": " << w.where;
    widest = std::max(widest, w.spread);
  }
  EXPECT_GT(widest, 2.9);  // the assembly's 3 was found
}

}  // namespace
}  // namespace hg::geometry
