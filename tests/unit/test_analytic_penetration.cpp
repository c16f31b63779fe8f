// The analytic back end: primitive recognition, closed-form answers against hand-computed
// values and OpenCASCADE's own distances, B-rep feature indices, single-feature queries
// for contact tracking; and the sample parts of resources/parts.
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRepClass3d_SolidClassifier.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <ShapeUpgrade_ShapeDivideClosedEdges.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <gp_Trsf.hxx>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "alloc_counter.hpp"
#include "hapticgrasp/geometry/backends.hpp"

namespace hg::geometry {
namespace {

const std::filesystem::path kParts = std::filesystem::path(HG_RESOURCES_DIR) / "parts";

// Reaches the protected single-feature query, as PenetrationModel::track does.
struct FeatureAccess : PenetrationModel {
  static bool call(const PenetrationModel& model, const Vec3& x, Feature feature, int index, double& u, double& v,
                   Penetration& out) {
    return (model.*(&FeatureAccess::queryFeature))(x, feature, index, u, v, out);
  }
};

PartModelPtr mm(const TopoDS_Shape& shape, const char* name = "part") {
  return PartModel::fromShape(shape, LengthUnit::Millimetre, name);
}

// The paper's cylinder: diameter 100 mm, length 400 mm, axis z, centred at the origin.
TopoDS_Shape paperCylinder() {
  return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -200), gp::DZ()), 50, 400).Shape();
}
TopoDS_Shape box100x60x30() { return BRepPrimAPI_MakeBox(gp_Pnt(-50, -30, -15), 100, 60, 30).Shape(); }
TopoDS_Shape sphere25() { return BRepPrimAPI_MakeSphere(gp_Pnt(10, 20, 30), 25).Shape(); }

gp_Pnt toMm(const Vec3& p_m) { return gp_Pnt(p_m.x() * 1e3, p_m.y() * 1e3, p_m.z() * 1e3); }

// Distance in mm from a point (m) to a shape.
double mmDistance(const TopoDS_Shape& shape, const Vec3& p_m) {
  BRepExtrema_DistShapeShape dist(BRepBuilderAPI_MakeVertex(toMm(p_m)).Vertex(), shape);
  EXPECT_TRUE(dist.IsDone());
  return dist.Value();
}

// The B-rep feature an answer names contains its foot.
void expectFootOnFeature(const PartModel& part, const Penetration& p) {
  const TopTools_IndexedMapOfShape& map = p.feature == Feature::Face   ? part.faces()
                                          : p.feature == Feature::Edge ? part.edges()
                                                                       : part.vertices();
  ASSERT_NE(p.feature, Feature::None);
  ASSERT_GE(p.featureIndex, 1);
  ASSERT_LE(p.featureIndex, map.Extent());
  EXPECT_LT(mmDistance(map(p.featureIndex), p.foot), 1e-6)
      << toString(p.feature) << " " << p.featureIndex << " foot " << p.foot.transpose();
}

// What holds for every answer: vector = x - foot = -depth * normal, unit normal.
void expectConsistent(const Vec3& x, const Penetration& p) {
  const double scale = 1e-12 * (1 + x.norm());
  EXPECT_NEAR((p.vector - (x - p.foot)).norm(), 0, scale);
  EXPECT_NEAR(p.normal.norm(), 1, 1e-12);
  EXPECT_NEAR((p.vector + p.depth * p.normal).norm(), 0, scale);
  EXPECT_EQ(p.inside, p.depth > 0);
}

void expectVec(const Vec3& actual, const Vec3& expected, double tol = 1e-14) {
  EXPECT_NEAR((actual - expected).norm(), 0, tol) << actual.transpose() << " vs " << expected.transpose();
}

// The index of the part's face closest to a point (mm distance ~0).
int faceContaining(const PartModel& part, const Vec3& p_m) {
  for (int i = 1; i <= part.faces().Extent(); ++i)
    if (mmDistance(part.faces()(i), p_m) < 1e-6) return i;
  return 0;
}

// ----------------------------------------------------------------------- recognition

TEST(PrimitiveRecognition, CylinderBoxSphere) {
  const PartModelPtr cylinder = mm(paperCylinder());
  const Primitive& c = cylinder->primitive();
  ASSERT_EQ(c.kind, Primitive::Kind::Cylinder);
  EXPECT_NEAR(c.radius, 0.05, 1e-15);
  EXPECT_NEAR(c.halfLength, 0.2, 1e-15);
  expectVec(c.centre, Vec3::Zero());
  EXPECT_NEAR(std::abs(c.axes.col(2).z()), 1, 1e-15);
  EXPECT_NEAR(c.axes.determinant(), 1, 1e-12);

  const PartModelPtr box = mm(box100x60x30());
  const Primitive& b = box->primitive();
  ASSERT_EQ(b.kind, Primitive::Kind::Box);
  expectVec(b.centre, Vec3::Zero());
  // The half extents along the box's own axes, whichever order it found them in.
  const Vec3 world = (b.axes * b.halfExtents.asDiagonal()).cwiseAbs().rowwise().sum();
  expectVec(world, Vec3(0.05, 0.03, 0.015));

  const PartModelPtr sphere = mm(sphere25());
  const Primitive& s = sphere->primitive();
  ASSERT_EQ(s.kind, Primitive::Kind::Sphere);
  EXPECT_NEAR(s.radius, 0.025, 1e-15);
  expectVec(s.centre, Vec3(0.01, 0.02, 0.03));
}

TEST(PrimitiveRecognition, NotPrimitives) {
  // A cylinder with a hole along its axis: one more cylindrical face.
  const TopoDS_Shape hole = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -250), gp::DZ()), 20, 500).Shape();
  BRepAlgoAPI_Cut tube(paperCylinder(), hole);
  ASSERT_TRUE(tube.IsDone());
  const PartModelPtr tubePart = mm(tube.Shape(), "tube");
  EXPECT_EQ(tubePart->primitive().kind, Primitive::Kind::None);
  EXPECT_THROW(makeAnalyticPenetration(tubePart), GeometryError);

  for (const char* name : {"block.brep", "loft.brep"}) {
    const PartModelPtr part = PartModel::fromFile(kParts / name, LengthUnit::Millimetre);
    EXPECT_EQ(part->primitive().kind, Primitive::Kind::None) << name;
    EXPECT_THROW(makeAnalyticPenetration(part), GeometryError) << name;
  }
}

// ----------------------------------------------------------------------- the model

TEST(AnalyticPenetration, Description) {
  const PenetrationModelPtr model = makeAnalyticPenetration(mm(paperCylinder()));
  EXPECT_EQ(model->name(), "analytic");
  EXPECT_EQ(model->setting(), "cylinder r 50 mm, length 400 mm");
  EXPECT_TRUE(model->realTimeSafe());
  EXPECT_GT(model->memoryBytes(), 0u);
  EXPECT_EQ(makeAnalyticPenetration(mm(box100x60x30()))->setting().rfind("box ", 0), 0u);
  EXPECT_EQ(makeAnalyticPenetration(mm(sphere25()))->setting(), "sphere r 25 mm");
  QueryState state;
  const Vec3 x = Vec3::Zero();
  static_assert(noexcept(model->query(x, state)));
}

TEST(AnalyticPenetration, CylinderHandComputed) {
  const PartModelPtr part = mm(paperCylinder());
  const PenetrationModelPtr model = makeAnalyticPenetration(part);
  QueryState state;
  const int side = faceContaining(*part, Vec3(0.05, 0, 0));
  const int top = faceContaining(*part, Vec3(0, 0, 0.2));
  const int bottom = faceContaining(*part, Vec3(0, 0, -0.2));
  ASSERT_TRUE(side && top && bottom);
  ASSERT_TRUE(side != top && top != bottom && side != bottom);

  {  // the centre, on the axis: any side point 50 mm away
    const Vec3 x = Vec3::Zero();
    const Penetration p = model->query(x, state);
    EXPECT_TRUE(p.inside);
    EXPECT_NEAR(p.depth, 0.05, 1e-15);
    EXPECT_NEAR(p.foot.head<2>().norm(), 0.05, 1e-15);
    EXPECT_NEAR(p.foot.z(), 0, 1e-15);
    expectVec(p.normal, Vec3(p.foot.x(), p.foot.y(), 0) / 0.05);
    EXPECT_EQ(p.feature, Feature::Face);
    EXPECT_EQ(p.featureIndex, side);
    EXPECT_EQ(state.feature, Feature::Face);
    EXPECT_EQ(state.index, side);
    expectConsistent(x, p);
    expectFootOnFeature(*part, p);
  }
  {  // on the axis near the top: the cap
    const Vec3 x(0, 0, 0.19);
    const Penetration p = model->query(x, state);
    EXPECT_NEAR(p.depth, 0.01, 1e-15);
    expectVec(p.foot, Vec3(0, 0, 0.2));
    expectVec(p.normal, Vec3::UnitZ());
    EXPECT_EQ(p.featureIndex, top);
    expectConsistent(x, p);
  }
  {  // in the cap region, off the axis
    const Vec3 x(0.01, 0, 0.195);
    const Penetration p = model->query(x, state);
    EXPECT_TRUE(p.inside);
    EXPECT_NEAR(p.depth, 0.005, 1e-15);
    expectVec(p.foot, Vec3(0.01, 0, 0.2));
    expectVec(p.vector, Vec3(0, 0, -0.005));
    expectVec(p.normal, Vec3::UnitZ());
    EXPECT_EQ(p.feature, Feature::Face);
    EXPECT_EQ(p.featureIndex, top);
    expectConsistent(x, p);
    expectFootOnFeature(*part, p);
  }
  {  // inside near the side
    const Vec3 x(0, -0.045, -0.1);
    const Penetration p = model->query(x, state);
    EXPECT_NEAR(p.depth, 0.005, 1e-15);
    expectVec(p.foot, Vec3(0, -0.05, -0.1));
    expectVec(p.normal, -Vec3::UnitY());
    EXPECT_EQ(p.featureIndex, side);
    expectFootOnFeature(*part, p);
  }
  {  // outside near the top rim: 3-4-5 from the rim
    const Vec3 x(0.053, 0, 0.204);
    const Penetration p = model->query(x, state);
    EXPECT_FALSE(p.inside);
    EXPECT_NEAR(p.depth, -0.005, 1e-15);
    expectVec(p.foot, Vec3(0.05, 0, 0.2));
    expectVec(p.normal, Vec3(0.6, 0, 0.8));
    EXPECT_EQ(p.feature, Feature::Edge);
    expectConsistent(x, p);
    expectFootOnFeature(*part, p);
  }
  {  // outside near the bottom rim, at 45 degrees about the axis
    const double c = std::sqrt(0.5);
    const Vec3 x(0.06 * c, 0.06 * c, -0.21);
    const Penetration p = model->query(x, state);
    EXPECT_NEAR(p.depth, -std::sqrt(2.0) * 0.01, 1e-15);
    expectVec(p.foot, Vec3(0.05 * c, 0.05 * c, -0.2));
    EXPECT_EQ(p.feature, Feature::Edge);
    expectFootOnFeature(*part, p);
  }
  {  // outside the side
    const Vec3 x(0, 0.06, 0.1);
    const Penetration p = model->query(x, state);
    EXPECT_NEAR(p.depth, -0.01, 1e-15);
    expectVec(p.foot, Vec3(0, 0.05, 0.1));
    expectVec(p.normal, Vec3::UnitY());
    EXPECT_EQ(p.featureIndex, side);
    expectFootOnFeature(*part, p);
  }
  {  // below the bottom cap
    const Vec3 x(0.01, 0.01, -0.25);
    const Penetration p = model->query(x, state);
    EXPECT_NEAR(p.depth, -0.05, 1e-15);
    expectVec(p.foot, Vec3(0.01, 0.01, -0.2));
    expectVec(p.normal, -Vec3::UnitZ());
    EXPECT_EQ(p.featureIndex, bottom);
    expectFootOnFeature(*part, p);
  }
}

TEST(AnalyticPenetration, BoxHandComputed) {
  const PartModelPtr part = mm(box100x60x30());
  const PenetrationModelPtr model = makeAnalyticPenetration(part);
  QueryState state;
  {  // the corner region: 3-4-12 from the corner (50, 30, 15) mm
    const Vec3 x(0.053, 0.034, 0.027);
    const Penetration p = model->query(x, state);
    EXPECT_NEAR(p.depth, -0.013, 1e-15);
    expectVec(p.foot, Vec3(0.05, 0.03, 0.015));
    expectVec(p.normal, Vec3(3, 4, 12) / 13);
    EXPECT_EQ(p.feature, Feature::Vertex);
    expectConsistent(x, p);
    expectFootOnFeature(*part, p);
  }
  {  // the edge region of the vertical edge at x, y > 0
    const Vec3 x(0.053, 0.034, 0.001);
    const Penetration p = model->query(x, state);
    EXPECT_NEAR(p.depth, -0.005, 1e-15);
    expectVec(p.foot, Vec3(0.05, 0.03, 0.001));
    expectVec(p.normal, Vec3(0.6, 0.8, 0));
    EXPECT_EQ(p.feature, Feature::Edge);
    expectConsistent(x, p);
    expectFootOnFeature(*part, p);
  }
  {  // facing +x
    const Vec3 x(0.06, 0.01, -0.005);
    const Penetration p = model->query(x, state);
    EXPECT_NEAR(p.depth, -0.01, 1e-15);
    expectVec(p.foot, Vec3(0.05, 0.01, -0.005));
    expectVec(p.normal, Vec3::UnitX());
    EXPECT_EQ(p.feature, Feature::Face);
    expectFootOnFeature(*part, p);
  }
  {  // inside, nearest the +x face
    const Vec3 x(0.045, 0, 0);
    const Penetration p = model->query(x, state);
    EXPECT_TRUE(p.inside);
    EXPECT_NEAR(p.depth, 0.005, 1e-15);
    expectVec(p.foot, Vec3(0.05, 0, 0));
    expectVec(p.normal, Vec3::UnitX());
    expectFootOnFeature(*part, p);
  }
  {  // the centre: nearest the -z/+z faces, 15 mm
    const Penetration p = model->query(Vec3::Zero(), state);
    EXPECT_NEAR(p.depth, 0.015, 1e-15);
    EXPECT_NEAR(std::abs(p.foot.z()), 0.015, 1e-15);
    expectFootOnFeature(*part, p);
  }
}

TEST(AnalyticPenetration, SphereHandComputed) {
  const PartModelPtr part = mm(sphere25());
  const PenetrationModelPtr model = makeAnalyticPenetration(part);
  QueryState state;
  const Vec3 c(0.01, 0.02, 0.03);
  {
    const Penetration p = model->query(c, state);
    EXPECT_TRUE(p.inside);
    EXPECT_NEAR(p.depth, 0.025, 1e-15);
    EXPECT_NEAR((p.foot - c).norm(), 0.025, 1e-15);
    expectConsistent(c, p);
    expectFootOnFeature(*part, p);
  }
  {
    const Vec3 x = c + Vec3(0.03, 0, 0.04);
    const Penetration p = model->query(x, state);
    EXPECT_NEAR(p.depth, -0.025, 1e-15);
    expectVec(p.foot, c + Vec3(0.015, 0, 0.02));
    expectVec(p.normal, Vec3(0.6, 0, 0.8));
    EXPECT_EQ(p.feature, Feature::Face);
    expectConsistent(x, p);
    expectFootOnFeature(*part, p);
  }
}

// Random points around moved and rotated primitives against OCCT's distance to the
// shell and its classifier: the same depth, and the foot on the feature named.
void compareWithOcct(const TopoDS_Shape& shape, Primitive::Kind kind, int points) {
  const PartModelPtr part = mm(shape);
  ASSERT_EQ(part->primitive().kind, kind);
  const PenetrationModelPtr model = makeAnalyticPenetration(part);
  TopExp_Explorer shellEx(part->shape(), TopAbs_SHELL);
  const TopoDS_Shape shell = shellEx.Current();
  const Aabb box = part->bounds().inflated(0.2 * part->characteristicLength());
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> unit(0, 1);
  QueryState state;
  int inside = 0, faces = 0, edges = 0, vertices = 0;
  for (int i = 0; i < points; ++i) {
    const Vec3 x = box.min + box.size().cwiseProduct(Vec3(unit(rng), unit(rng), unit(rng)));
    const Penetration p = model->query(x, state);
    expectConsistent(x, p);
    EXPECT_NEAR(std::abs(p.depth) * 1e3, mmDistance(shell, x), 1e-6) << x.transpose();
    BRepClass3d_SolidClassifier classifier(part->shape(), toMm(x), 1e-7);
    EXPECT_EQ(classifier.State() == TopAbs_IN, p.inside) << x.transpose();
    expectFootOnFeature(*part, p);
    inside += p.inside;
    faces += p.feature == Feature::Face;
    edges += p.feature == Feature::Edge;
    vertices += p.feature == Feature::Vertex;
  }
  EXPECT_GT(inside, 0);
  EXPECT_GT(faces, 0);
  if (kind != Primitive::Kind::Sphere) {
    EXPECT_GT(edges, 0);
  }
  if (kind == Primitive::Kind::Box) {
    EXPECT_GT(vertices, 0);
  }
}

TopoDS_Shape moved(const TopoDS_Shape& shape) {
  gp_Trsf rotation, translation;
  rotation.SetRotation(gp_Ax1(gp::Origin(), gp_Dir(1, 2, 3)), 0.7);
  translation.SetTranslation(gp_Vec(5, -7, 11));
  return BRepBuilderAPI_Transform(shape, translation * rotation, /*copy=*/true).Shape();
}

TEST(AnalyticPenetration, MatchesOcctCylinder) {
  compareWithOcct(moved(BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(1, 2, 3), gp_Dir(0, 1, 1)), 12, 30).Shape()),
                  Primitive::Kind::Cylinder, 300);
}
TEST(AnalyticPenetration, MatchesOcctBox) {
  compareWithOcct(moved(BRepPrimAPI_MakeBox(gp_Pnt(-3, 4, 1), 20, 35, 8).Shape()), Primitive::Kind::Box, 300);
}
TEST(AnalyticPenetration, MatchesOcctSphere) {
  compareWithOcct(moved(sphere25()), Primitive::Kind::Sphere, 100);
}

// A CAD export may split a closed rim into several edges: each answer names the piece
// that holds its foot, and a single-feature query refuses a foot on another piece.
TEST(AnalyticPenetration, SplitRims) {
  ShapeUpgrade_ShapeDivideClosedEdges divide(paperCylinder());
  divide.SetNbSplitPoints(2);
  ASSERT_TRUE(divide.Perform());
  const PartModelPtr part = mm(divide.Result(), "split");
  ASSERT_EQ(part->primitive().kind, Primitive::Kind::Cylinder);
  ASSERT_GT(part->edges().Extent(), 3);
  const PenetrationModelPtr model = makeAnalyticPenetration(part);
  QueryState state;
  int pieces[2] = {0, 0};
  for (int i = 0; i < 36; ++i) {
    const double a = 2 * std::numbers::pi * (i + 0.5) / 36;
    for (double z : {0.204, -0.204}) {
      const Vec3 x(0.053 * std::cos(a), 0.053 * std::sin(a), z);
      const Penetration p = model->query(x, state);
      ASSERT_EQ(p.feature, Feature::Edge);
      EXPECT_NEAR(p.depth, -0.005, 1e-15);
      expectFootOnFeature(*part, p);
      // Against every edge: exactly the one named holds the foot.
      int holding = 0;
      for (int e = 1; e <= part->edges().Extent(); ++e) {
        double u = 0, v = 0;
        Penetration q;
        if (FeatureAccess::call(*model, x, Feature::Edge, e, u, v, q) && (q.foot - p.foot).norm() < 1e-15) {
          ++holding;
          EXPECT_EQ(e, p.featureIndex);
        }
      }
      EXPECT_EQ(holding, 1);
      pieces[z < 0] |= 1 << (p.featureIndex % 16);
    }
  }
  EXPECT_GT(__builtin_popcount(pieces[0]), 1);
  EXPECT_GT(__builtin_popcount(pieces[1]), 1);
  compareWithOcct(divide.Result(), Primitive::Kind::Cylinder, 200);
}

TEST(AnalyticPenetration, QueryAllocatesNothing) {
  const PenetrationModelPtr cylinder = makeAnalyticPenetration(mm(paperCylinder()));
  const PenetrationModelPtr box = makeAnalyticPenetration(mm(box100x60x30()));
  const PenetrationModelPtr sphere = makeAnalyticPenetration(mm(sphere25()));
  QueryState state;
  double sum = 0;
  const long before = hg::test::allocations();
  for (int i = 0; i < 1000; ++i) {
    const Vec3 x(0.07 * std::sin(i * 0.1), 0.07 * std::cos(i * 0.13), 0.25 * std::sin(i * 0.07));
    sum += cylinder->query(x, state).depth + box->query(x, state).depth + sphere->query(x, state).depth;
    sum += cylinder->track(x, state, 1e-3).depth + box->track(x, state, 1e-3).depth;
  }
  EXPECT_EQ(hg::test::allocations() - before, 0);
  EXPECT_TRUE(std::isfinite(sum));
}

// ----------------------------------------------------------------------- single features

TEST(AnalyticPenetration, QueryFeatureCylinder) {
  const PartModelPtr part = mm(paperCylinder());
  const PenetrationModelPtr model = makeAnalyticPenetration(part);
  const int side = faceContaining(*part, Vec3(0.05, 0, 0));
  const int top = faceContaining(*part, Vec3(0, 0, 0.2));
  QueryState state;
  const int topRim = model->query(Vec3(0.053, 0, 0.204), state).featureIndex;
  double u = 0, v = 0;
  Penetration p;

  // The cap region, against the side: radial projection.
  ASSERT_TRUE(FeatureAccess::call(*model, Vec3(0.01, 0, 0.195), Feature::Face, side, u, v, p));
  EXPECT_NEAR(p.depth, 0.04, 1e-15);
  expectVec(p.foot, Vec3(0.05, 0, 0.195));
  expectVec(p.normal, Vec3::UnitX());
  EXPECT_EQ(p.featureIndex, side);
  // ...and against the top cap.
  ASSERT_TRUE(FeatureAccess::call(*model, Vec3(0.01, 0, 0.195), Feature::Face, top, u, v, p));
  EXPECT_NEAR(p.depth, 0.005, 1e-15);
  expectVec(p.foot, Vec3(0.01, 0, 0.2));
  // Beyond the caps the side does not apply; beyond the rim the cap does not.
  EXPECT_FALSE(FeatureAccess::call(*model, Vec3(0.01, 0, 0.25), Feature::Face, side, u, v, p));
  EXPECT_FALSE(FeatureAccess::call(*model, Vec3(0.06, 0, 0.1), Feature::Face, top, u, v, p));
  // Against the top cap from below the part: a negative depth, the cap's plane.
  ASSERT_TRUE(FeatureAccess::call(*model, Vec3(0.01, 0, -0.25), Feature::Face, top, u, v, p));
  EXPECT_NEAR(p.depth, 0.45, 1e-15);

  // The rim from inside: the closest point of the circle, the normal from x to it.
  ASSERT_TRUE(FeatureAccess::call(*model, Vec3(0.04, 0, 0.19), Feature::Edge, topRim, u, v, p));
  EXPECT_NEAR(p.depth, std::sqrt(2.0) * 0.01, 1e-15);
  expectVec(p.foot, Vec3(0.05, 0, 0.2));
  expectVec(p.normal, Vec3(1, 0, 1) / std::sqrt(2.0));
  expectConsistent(Vec3(0.04, 0, 0.19), p);
  // ...and from outside.
  ASSERT_TRUE(FeatureAccess::call(*model, Vec3(0, 0.06, 0.21), Feature::Edge, topRim, u, v, p));
  EXPECT_NEAR(p.depth, -std::sqrt(2.0) * 0.01, 1e-15);
  expectVec(p.foot, Vec3(0, 0.05, 0.2));
  expectFootOnFeature(*part, p);

  // Nothing to measure against.
  EXPECT_FALSE(FeatureAccess::call(*model, Vec3::Zero(), Feature::None, 1, u, v, p));
  EXPECT_FALSE(FeatureAccess::call(*model, Vec3::Zero(), Feature::Face, 0, u, v, p));
  EXPECT_FALSE(FeatureAccess::call(*model, Vec3::Zero(), Feature::Face, 4, u, v, p));
  EXPECT_FALSE(FeatureAccess::call(*model, Vec3::Zero(), Feature::Edge, 99, u, v, p));
}

TEST(AnalyticPenetration, QueryFeatureBox) {
  const PartModelPtr part = mm(box100x60x30());
  const PenetrationModelPtr model = makeAnalyticPenetration(part);
  QueryState state;
  // The edge along x at y = 30, z = 15 mm, and the +x face.
  const Penetration edge = model->query(Vec3(0, 0.034, 0.018), state);
  ASSERT_EQ(edge.feature, Feature::Edge);
  const Penetration face = model->query(Vec3(0.06, 0, 0), state);
  ASSERT_EQ(face.feature, Feature::Face);
  const Penetration corner = model->query(Vec3(0.06, 0.04, 0.02), state);
  ASSERT_EQ(corner.feature, Feature::Vertex);
  double u = 0, v = 0;
  Penetration p;

  ASSERT_TRUE(FeatureAccess::call(*model, Vec3(0.02, 0.025, 0.01), Feature::Edge, edge.featureIndex, u, v, p));
  expectVec(p.foot, Vec3(0.02, 0.03, 0.015));
  EXPECT_NEAR(p.depth, std::hypot(0.005, 0.005), 1e-15);
  expectVec(p.normal, Vec3(0, 1, 1) / std::sqrt(2.0));
  EXPECT_FALSE(FeatureAccess::call(*model, Vec3(0.055, 0.025, 0.01), Feature::Edge, edge.featureIndex, u, v, p));

  ASSERT_TRUE(FeatureAccess::call(*model, Vec3(0.01, 0.02, 0.01), Feature::Face, face.featureIndex, u, v, p));
  EXPECT_NEAR(p.depth, 0.04, 1e-15);
  expectVec(p.foot, Vec3(0.05, 0.02, 0.01));
  expectVec(p.normal, Vec3::UnitX());
  EXPECT_FALSE(FeatureAccess::call(*model, Vec3(0.01, 0.035, 0.01), Feature::Face, face.featureIndex, u, v, p));

  ASSERT_TRUE(FeatureAccess::call(*model, Vec3(0.04, 0.02, 0.01), Feature::Vertex, corner.featureIndex, u, v, p));
  expectVec(p.foot, Vec3(0.05, 0.03, 0.015));
  EXPECT_NEAR(p.depth, Vec3(0.01, 0.01, 0.005).norm(), 1e-15);
  expectConsistent(Vec3(0.04, 0.02, 0.01), p);
}

// Contact tracking on the cylinder's rim bisector: the held cap wins until the side is
// closer by more than the hysteresis.
TEST(AnalyticPenetration, TrackHoldsTheFeatureEnteredThrough) {
  const PartModelPtr part = mm(paperCylinder());
  const PenetrationModelPtr model = makeAnalyticPenetration(part);
  const int side = faceContaining(*part, Vec3(0.05, 0, 0));
  const int top = faceContaining(*part, Vec3(0, 0, 0.2));
  QueryState state;
  Penetration p = model->track(Vec3(0.045, 0, 0.21), state, 0.002);  // above the cap, outside
  EXPECT_FALSE(p.inside);
  EXPECT_EQ(state.tracked, Feature::None);
  p = model->track(Vec3(0.045, 0, 0.198), state, 0.002);  // in through the cap
  EXPECT_EQ(p.featureIndex, top);
  EXPECT_EQ(state.trackedIndex, top);
  p = model->track(Vec3(0.048, 0, 0.195), state, 0.002);  // side 2 mm, cap 5 mm: 3 mm > 2 mm, the side
  EXPECT_EQ(p.featureIndex, side);
  state.reset();
  model->track(Vec3(0.045, 0, 0.198), state, 0.002);
  p = model->track(Vec3(0.047, 0, 0.195), state, 0.003);  // side 3 mm, cap 5 mm, hysteresis 3 mm
  EXPECT_TRUE(p.inside);
  EXPECT_EQ(p.featureIndex, top);
  EXPECT_NEAR(p.depth, 0.005, 1e-15);
  expectVec(p.foot, Vec3(0.047, 0, 0.2));
  p = model->track(Vec3(0.049, 0, 0.19), state, 0.003);  // side 1 mm, cap 10 mm: the side
  EXPECT_EQ(p.featureIndex, side);
  EXPECT_NEAR(p.depth, 0.001, 1e-15);
}

// ----------------------------------------------------------------------- sample parts

TEST(SampleParts, LoadWithTheFaceCountsListed) {
  std::ifstream in(kParts / "parts.json");
  ASSERT_TRUE(in) << kParts / "parts.json";
  const nlohmann::json list = nlohmann::json::parse(in);
  ASSERT_EQ(list.size(), 4u);
  for (const nlohmann::json& entry : list) {
    const std::string name = entry.at("name");
    SCOPED_TRACE(name);
    EXPECT_EQ(entry.at("unit"), "mm");
    EXPECT_NE(entry.contains("mass_kg"), entry.contains("density_kg_m3"));
    const PartModelPtr part =
        PartModel::fromFile(kParts / entry.at("file").get<std::string>(), LengthUnit::Millimetre);
    EXPECT_EQ(part->faces().Extent(), entry.at("faces").get<int>());
    EXPECT_TRUE(part->warnings().empty());
    if (name == "cylinder") {
      EXPECT_EQ(part->primitive().kind, Primitive::Kind::Cylinder);
      EXPECT_EQ(entry.at("mass_kg").get<double>(), 2.0);
    } else {
      EXPECT_EQ(part->primitive().kind, Primitive::Kind::None);
    }
    if (name == "block") {
      EXPECT_GE(part->faces().Extent(), 50);
    }
    if (name == "plate") {
      EXPECT_GT(part->faces().Extent(), 1000);
    }
    if (name == "loft") {
      int bspline = 0, planes = 0;
      for (int i = 1; i <= part->faces().Extent(); ++i) {
        const GeomAbs_SurfaceType type = BRepAdaptor_Surface(TopoDS::Face(part->faces()(i))).GetType();
        bspline += type == GeomAbs_BSplineSurface;
        planes += type == GeomAbs_Plane;
      }
      EXPECT_EQ(bspline, 1);
      EXPECT_EQ(planes, 2);
    }
  }
}

TEST(SampleParts, CylinderMassPropertiesClosedForm) {
  const PartModelPtr part = PartModel::fromFile(kParts / "cylinder.brep", LengthUnit::Millimetre);
  const MassProperties mp = part->massProperties(MassSpec::mass(2.0));
  const double m = 2.0, r = 0.05, h = 0.4;
  EXPECT_NEAR(mp.mass_kg, m, 1e-12);
  EXPECT_NEAR(mp.volume_m3, std::numbers::pi * r * r * h, 1e-12 * std::numbers::pi * r * r * h);
  EXPECT_NEAR(mp.centre_m.norm(), 0, 1e-12);
  const double izz = m * r * r / 2, ixx = m * (3 * r * r + h * h) / 12;
  EXPECT_NEAR(mp.inertia_kgm2(2, 2), izz, 1e-9 * izz);
  EXPECT_NEAR(mp.inertia_kgm2(0, 0), ixx, 1e-9 * ixx);
  EXPECT_NEAR(mp.inertia_kgm2(1, 1), ixx, 1e-9 * ixx);
  for (int r0 = 0; r0 < 3; ++r0)
    for (int c0 = 0; c0 < 3; ++c0)
      if (r0 != c0) {
        EXPECT_NEAR(mp.inertia_kgm2(r0, c0), 0, 1e-12 * ixx);
      }
}

}  // namespace
}  // namespace hg::geometry
