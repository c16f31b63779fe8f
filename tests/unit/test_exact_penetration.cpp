// The exact back end against OCCT's reference: the same distance to 1e-9 m, the same
// sign, on planes, cylinders, fillets, holes and B-spline lofts; special points; tiny and
// huge parts; warm starts; no allocation.
#include <gtest/gtest.h>

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRep_Tool.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>

#include "alloc_counter.hpp"
#include "hapticgrasp/geometry/backends.hpp"
#include "test_shapes.hpp"

namespace hg::geometry {
namespace {

struct Agreement {
  double maxError = 0;
  int signErrors = 0;
  int count = 0;
};

Agreement compare(const PartModelPtr& part, const std::vector<Vec3>& points, bool warm) {
  const auto reference = makeReferencePenetration(part);
  const auto exact = makeExactPenetration(part);
  Agreement a;
  QueryState sr, se;
  for (const Vec3& x : points) {
    if (!warm) se.reset();
    const Penetration r = reference->query(x, sr), e = exact->query(x, se);
    EXPECT_NE(e.feature, Feature::None) << x.transpose();
    a.maxError = std::max(a.maxError, std::abs(r.depth - e.depth));
    // A sign decided on the surface itself is no error.
    if (r.inside != e.inside && std::abs(r.depth) > 1e-9) ++a.signErrors;
    ++a.count;
  }
  return a;
}

void expectAgreement(const PartModelPtr& part, int count, double shell_m) {
  const Agreement a = compare(part, test::shellPoints(*part, count, shell_m), false);
  EXPECT_LT(a.maxError, 1e-9) << part->name();
  EXPECT_EQ(a.signErrors, 0) << part->name();
}

TEST(ExactPenetration, AgreesWithReferenceOnBox) { expectAgreement(test::boxPart(), 2000, 5e-3); }
TEST(ExactPenetration, AgreesWithReferenceOnCylinder) { expectAgreement(test::cylinderPart(), 2000, 5e-3); }
TEST(ExactPenetration, AgreesWithReferenceOnSphere) { expectAgreement(test::spherePart(), 1000, 5e-3); }
TEST(ExactPenetration, AgreesWithReferenceOnFilletedDrilledBlock) { expectAgreement(test::drilledBlockPart(), 3000, 5e-3); }
TEST(ExactPenetration, AgreesWithReferenceOnLoft) { expectAgreement(test::loftPart(), 1000, 5e-3); }

// Every kind of surface and curve OCCT has, each checked to be in the part it is meant for.
TEST(ExactPenetration, AgreesOnASurfaceOfRevolution) {
  const auto part = test::revolvedSplinePart();
  ASSERT_GT(test::surfaceTypes(*part)[GeomAbs_SurfaceOfRevolution], 0);
  expectAgreement(part, 1500, 5e-3);
}

TEST(ExactPenetration, AgreesOnASurfaceOfExtrusion) {
  const auto part = test::extrudedSplinePart();
  ASSERT_GT(test::surfaceTypes(*part)[GeomAbs_SurfaceOfExtrusion], 0);
  ASSERT_GT(test::curveTypes(*part)[GeomAbs_BSplineCurve], 0);
  expectAgreement(part, 1500, 5e-3);
}

TEST(ExactPenetration, AgreesOnAConeWithItsApex) {
  const auto part = test::conePart();
  ASSERT_GT(test::surfaceTypes(*part)[GeomAbs_Cone], 0);
  expectAgreement(part, 1500, 8e-3);
  // Beyond the apex along the axis, the apex (a vertex) is the foot.
  const auto exact = makeExactPenetration(part);
  QueryState s;
  const Penetration p = exact->query(Vec3(0, 0, 0.023), s);
  EXPECT_FALSE(p.inside);
  EXPECT_NEAR(p.depth, -0.003, 1e-12);
}

TEST(ExactPenetration, AgreesOnRingAndAppleTori) {
  for (const auto& [major, minor] : {std::pair{30.0, 8.0}, {5.0, 8.0}}) {
    const auto part = test::torusPart(major, minor);
    ASSERT_GT(test::surfaceTypes(*part)[GeomAbs_Torus], 0);
    expectAgreement(part, 1500, 5e-3);
  }
}

TEST(ExactPenetration, AgreesOnBezierSurfacesAndCurves) {
  const auto part = test::bezierPart();
  ASSERT_GT(test::surfaceTypes(*part)[GeomAbs_BezierSurface], 0);
  ASSERT_GT(test::curveTypes(*part)[GeomAbs_BezierCurve], 0);
  expectAgreement(part, 1500, 5e-3);
}

TEST(ExactPenetration, AgreesOnARectangularTrimmedSurface) {
  const auto part = test::trimmedSurfacePart();
  bool trimmed = false;
  for (int i = 1; i <= part->faces().Extent(); ++i)
    trimmed |= BRep_Tool::Surface(TopoDS::Face(part->faces()(i)))->IsKind(STANDARD_TYPE(Geom_RectangularTrimmedSurface));
  ASSERT_TRUE(trimmed);
  expectAgreement(part, 1500, 5e-3);
}

TEST(ExactPenetration, AgreesOnOffsetSurfaces) {
  const auto part = test::thickLoftPart();
  ASSERT_GT(test::surfaceTypes(*part)[GeomAbs_OffsetSurface], 0);
  expectAgreement(part, 1000, 5e-3);
}

TEST(ExactPenetration, AgreesOnOffsetAndBezierCurves) {
  const auto part = test::offsetCurvePart();
  ASSERT_GT(test::curveTypes(*part)[GeomAbs_OffsetCurve], 0);
  expectAgreement(part, 1500, 4e-3);
}

TEST(ExactPenetration, AgreesOnEllipseHyperbolaAndParabolaEdges) {
  const auto part = test::conicSectionsPart();
  auto curves = test::curveTypes(*part);
  ASSERT_GT(curves[GeomAbs_Ellipse], 0);
  ASSERT_GT(curves[GeomAbs_Hyperbola], 0);
  ASSERT_GT(curves[GeomAbs_Parabola], 0);
  expectAgreement(part, 2000, 5e-3);
}

// One part of two solids that touch face to face: inside either is inside, also right at
// the face they share, where each solid's own face says "outside" of the other.
TEST(ExactPenetration, SolidsThatTouchAreOnePart) {
  const auto part = test::touchingBoxesPart();
  expectAgreement(part, 1500, 5e-3);
  const auto exact = makeExactPenetration(part);
  QueryState s;
  for (const double x : {0.0399, 0.0401}) {
    const Penetration p = exact->query(Vec3(x, 0.015, 0.01), s);
    EXPECT_TRUE(p.inside) << x;
    EXPECT_NEAR(p.depth, 1e-4, 1e-12) << x;
  }
}

// Inside a thin tube, points near its centre line lie near the focal points of its wall:
// the exhaustive search answers there and is counted. So near the line that the wall is
// nearly as close all round, it cannot prove its answer within a servo tick's budget, and
// says so; its answers still agree with the reference.
TEST(ExactPenetration, FocalPointsAreSearchedExhaustivelyAndCounted) {
  const auto part = test::sweptTubePart();
  const auto reference = makeReferencePenetration(part);
  const auto exact = makeExactPenetration(part);
  int fallbacks = 0, uncertain = 0, count = 0;
  for (const Vec3& x : test::shellPoints(*part, 600, 2.5e-3, 5)) {
    QueryState se, sr;
    const Penetration e = exact->query(x, se), r = reference->query(x, sr);
    fallbacks += e.fallbacks > 0;
    uncertain += !e.certain;
    EXPECT_NEAR(e.depth, r.depth, 1e-9) << x.transpose();
    ++count;
  }
  std::printf("focal points: %d of %d queries searched exhaustively, %d left uncertain\n", fallbacks, count, uncertain);
  EXPECT_GT(fallbacks, 0);
  EXPECT_LT(fallbacks, count / 2);
  EXPECT_GT(uncertain, 0);
  EXPECT_LE(uncertain, fallbacks);
}

TEST(ExactPenetration, WarmStartedPathAgreesWithReference) {
  // A fingertip moving 0.05 mm per tick around the loft, 1 mm inside, crossing the seam.
  const auto part = test::loftPart();
  std::vector<Vec3> path;
  for (int i = 0; i < 2000; ++i) {
    const double a = 2 * M_PI * i / 2000.0 * 1.2;
    path.emplace_back(0.025 * std::cos(a), 0.018 * std::sin(a), 0.05 + 0.01 * std::sin(3 * a));
  }
  const Agreement a = compare(part, path, true);
  EXPECT_LT(a.maxError, 1e-9);
  EXPECT_EQ(a.signErrors, 0);
}

TEST(ExactPenetration, SpecialPointsOfTheCylinder) {
  const auto exact = makeExactPenetration(test::cylinderPart());
  QueryState s;
  // On the axis, every side point is equally close: depth is the radius.
  Penetration p = exact->query(Vec3(0, 0, 0.05), s);
  EXPECT_TRUE(p.inside);
  EXPECT_NEAR(p.depth, 0.05, 1e-12);
  EXPECT_EQ(p.feature, Feature::Face);
  // Outside beyond the rim: the rim circle (an edge) is the closest feature.
  s.reset();
  p = exact->query(Vec3(0.06, 0, 0.21), s);
  EXPECT_FALSE(p.inside);
  EXPECT_EQ(p.feature, Feature::Edge);
  EXPECT_NEAR(p.depth, -std::hypot(0.01, 0.01), 1e-12);
  // On the surface: zero depth.
  s.reset();
  p = exact->query(Vec3(0.05, 0, 0.1), s);
  EXPECT_NEAR(p.depth, 0, 1e-12);
  // Inside near the cap: the cap is closer than the side.
  s.reset();
  p = exact->query(Vec3(0.0, 0.0, 0.199), s);
  EXPECT_TRUE(p.inside);
  EXPECT_NEAR(p.depth, 0.001, 1e-12);
  EXPECT_NEAR(p.normal.z(), 1.0, 1e-12);
}

// A point 1e-18 m on the wrong side of a cone's seam plane: its angle, a hair below 0,
// rounded to 2 pi exactly when wrapped, and the face was lost (the rim edge answered,
// 0.28 mm "inside"). Found by a peg entering a chamfered hole along the seam's plane.
TEST(ExactPenetration, APointAHairOffASeamFindsItsFace) {
  const double r = 5.05;
  TopoDS_Shape block = BRepPrimAPI_MakeBox(gp_Pnt(-20, -20, -20), 40, 40, 20).Shape();
  block = BRepAlgoAPI_Cut(block, BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -25), gp_Dir(0, 0, 1)), r, 30).Shape()).Shape();
  block = BRepAlgoAPI_Cut(block, BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(0, 0, -0.5), gp_Dir(0, 0, 1)), r, r + 1, 1).Shape()).Shape();
  const auto exact = geometry::makeExactPenetration(test::part(block, "chamfered hole"));
  for (const double y : {-1.2246449339040861e-18, 0.0, 1e-18, -1e-15}) {
    geometry::QueryState state;
    const geometry::Penetration q = exact->query(Vec3(5.3e-3, y, -1.3e-4), state);
    EXPECT_FALSE(q.inside) << y;
    EXPECT_EQ(q.feature, geometry::Feature::Face) << y;
    EXPECT_NEAR(q.depth, -0.12e-3 / std::sqrt(2.0), 1e-9) << y;  // 0.12 mm across from the 45 deg chamfer
  }
}

TEST(ExactPenetration, CornerOfTheBoxIsAVertexFoot) {
  const auto exact = makeExactPenetration(test::boxPart());
  QueryState s;
  const Penetration p = exact->query(Vec3(0.051, 0.031, 0.016), s);
  EXPECT_FALSE(p.inside);
  EXPECT_EQ(p.feature, Feature::Vertex);
  EXPECT_NEAR(p.depth, -std::sqrt(3.0) * 1e-3, 1e-12);
  EXPECT_NEAR(p.foot.x(), 0.05, 1e-12);
}

TEST(ExactPenetration, TinyAndHugePartsScale) {
  for (const double diameter_mm : {1.0, 10000.0}) {
    const auto part = test::cylinderPart(diameter_mm, diameter_mm * 4);
    const double r = diameter_mm * 1e-3 / 2;
    const auto exact = makeExactPenetration(part);
    QueryState s;
    const Penetration p = exact->query(Vec3(0.9 * r, 0, 0), s);
    EXPECT_TRUE(p.inside) << diameter_mm;
    EXPECT_NEAR(p.depth, 0.1 * r, 1e-12 * r) << diameter_mm;
    const Agreement a = compare(part, test::shellPoints(*part, 300, 0.05 * r), false);
    EXPECT_LT(a.maxError, 1e-9 * std::max(1.0, r)) << diameter_mm;
    EXPECT_EQ(a.signErrors, 0) << diameter_mm;
  }
}

TEST(ExactPenetration, NanGivesNoContact) {
  const auto exact = makeExactPenetration(test::boxPart());
  QueryState s;
  const Penetration p = exact->query(Vec3(NAN, 0, 0), s);
  EXPECT_FALSE(p.inside);
  EXPECT_EQ(p.feature, Feature::None);
}

TEST(ExactPenetration, QueriesDoNotAllocate) {
  for (const auto& part : {test::drilledBlockPart(), test::loftPart()}) {
    const auto exact = makeExactPenetration(part);
    const auto points = test::shellPoints(*part, 500, 5e-3);
    QueryState s;
    exact->query(points[0], s);
    const long before = test::allocations();
    double sum = 0;
    for (const Vec3& x : points) sum += exact->query(x, s).depth;
    EXPECT_EQ(test::allocations() - before, 0) << part->name();
    EXPECT_TRUE(std::isfinite(sum));
  }
}

TEST(ExactPenetration, AllocationCounterSeesAllocations) {
  const long before = test::allocations();
  auto* p = new std::vector<int>(100);
  EXPECT_GT(test::allocations() - before, 0);
  delete p;
}

// A god object holds the face its fingertip entered: the point measured against that face
// alone, over all its patches (found through the part's BVH, nearest first), is OCCT's
// distance to the face whatever face is closer, or nothing where the face's closest point
// is on its boundary; and it allocates nothing.
TEST(ContactTracking, AHeldFreeformFaceAnswersAsOcctsDistanceToIt) {
  const auto part = test::loftPart();
  const auto exact = makeExactPenetration(part);
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(part->shape(), TopAbs_FACE, faces);
  const auto points = test::shellPoints(*part, 200, 6e-3);
  int compared = 0;
  for (int k = 1; k <= faces.Extent(); ++k) {
    const TopoDS_Face& face = TopoDS::Face(faces(k));
    if (BRepAdaptor_Surface(face).GetType() != GeomAbs_BSplineSurface) continue;
    for (const Vec3& x : points) {
      QueryState s;
      if (!exact->query(x, s).inside) continue;
      double u = 0, v = 0;
      Penetration held;
      const bool found = exact->againstFeature(x, Feature::Face, k, u, v, held);
      const Vec3 xu = x / part->metresPerUnit();
      BRepExtrema_DistShapeShape distance(BRepBuilderAPI_MakeVertex(gp_Pnt(xu.x(), xu.y(), xu.z())).Vertex(), face);
      ASSERT_TRUE(distance.IsDone());
      // A foot inside the face, or none: OCCT's closest point is then on its boundary.
      EXPECT_EQ(found, distance.SupportTypeShape2(1) == BRepExtrema_IsInFace) << "face " << k << " at " << x.transpose();
      if (found) EXPECT_NEAR(held.depth, distance.Value() * part->metresPerUnit(), 1e-9) << "face " << k << " at " << x.transpose();
      compared += found;
    }
    const long before = test::allocations();
    double u = 0, v = 0;
    Penetration held;
    for (const Vec3& x : points) exact->againstFeature(x, Feature::Face, k, u, v, held);
    EXPECT_EQ(test::allocations() - before, 0);
  }
  EXPECT_GT(compared, 80);
}

TEST(ContactTracking, HoldsTheEnteredFaceAcrossTheCylinderRimBisector) {
  // A fingertip enters through the cap near the rim, then moves outwards and down so
  // that the side becomes the closest face: the force direction must not flip at once.
  const auto exact = makeExactPenetration(test::cylinderPart());
  QueryState tracked, raw;
  const double h = 2e-3;
  int flipsTracked = 0, flipsRaw = 0;
  Vec3 lastTracked = Vec3::Zero(), lastRaw = Vec3::Zero();
  for (int i = 0; i <= 100; ++i) {
    // Along the bisector of the rim, 3 mm inside, wobbling 0.2 mm across it.
    const double wobble = 2e-4 * ((i % 2) ? 1 : -1);
    const Vec3 x(0.047 + wobble, 0, 0.197 - wobble);
    const Penetration t = exact->track(x, tracked, h), r = exact->query(x, raw);
    ASSERT_TRUE(t.inside);
    if (i > 0 && t.normal.dot(lastTracked) < 0.5) ++flipsTracked;
    if (i > 0 && r.normal.dot(lastRaw) < 0.5) ++flipsRaw;
    lastTracked = t.normal;
    lastRaw = r.normal;
  }
  EXPECT_GT(flipsRaw, 50);   // the raw minimum flips between cap and side every tick
  EXPECT_EQ(flipsTracked, 0);
  // Far past the bisector the side is closer by more than the hysteresis: contact moves.
  const Penetration moved = exact->track(Vec3(0.047, 0, 0.19), tracked, h);
  EXPECT_NEAR(moved.normal.x(), 1.0, 1e-9);
}

}  // namespace
}  // namespace hg::geometry

namespace hg::geometry {
namespace {

TEST(Backends, AutoPicksAnalyticForPrimitivesAndExactOtherwise) {
  EXPECT_EQ(makePenetration(test::cylinderPart())->name(), "analytic");
  EXPECT_EQ(makePenetration(test::drilledBlockPart())->name(), "exact");
  EXPECT_EQ(makePenetration(test::loftPart(), Backend::Auto)->name(), "exact");
  EXPECT_EQ(parseBackend("mesh"), Backend::Mesh);
  EXPECT_THROW(parseBackend("voxels"), GeometryError);
}

}  // namespace
}  // namespace hg::geometry
