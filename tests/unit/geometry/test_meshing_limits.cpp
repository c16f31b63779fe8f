// The limits put on BRepMesh (core/src/geometry/meshing_limits.hpp): faces that would need
// an unbounded grid of nodes are left out, real parts' faces are not.
#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepPrimAPI_MakeCone.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Poly_Triangulation.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Ax3.hxx>
#include <gp_Cone.hxx>

#include <algorithm>
#include <filesystem>
#include <string>

#include "file_fixtures.hpp"
#include "geometry/meshing_limits.hpp"
#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/geometry/part_model.hpp"
#include "test_shapes.hpp"

namespace hg::geometry {
namespace {

namespace fs = std::filesystem;

// The finest deflection a session meshes at by default, 0.01 mm, in a part's millimetres.
const MeshingParameters kFine{0.01, 0.5};

int triangles(const TopoDS_Face& face) {
  TopLoc_Location location;
  const Handle(Poly_Triangulation) mesh = BRep_Tool::Triangulation(face, location);
  return mesh.IsNull() ? 0 : mesh->NbTriangles();
}

// A cone 0.001 mm wide and a metre long: BRepMesh would lay a V step of the order of its
// radius along all of it.
TopoDS_Face needleCone() {
  const gp_Cone cone(gp_Ax3(), 1e-6, 0.001);
  return BRepBuilderAPI_MakeFace(cone, 0, 2 * M_PI, 0, 1000).Face();
}

TopoDS_Shape sampleShape(const std::string& name) {
  return test::readShape(fs::path(HG_RESOURCES_DIR) / "parts" / (name + ".brep"));
}

TEST(MeshingLimits, ANeedleConeIsBeyondTheLimitAndLeftWithoutTriangles) {
  const TopoDS_Face needle = needleCone();
  const TopoDS_Shape sound = BRepPrimAPI_MakeCone(20, 5, 30).Shape();
  TopoDS_Compound both;
  BRep_Builder builder;
  builder.MakeCompound(both);
  builder.Add(both, needle);
  builder.Add(both, sound);
  const SurfaceGrids grids = surfaceGrids(both, kFine);
  ASSERT_EQ(grids.beyondTheLimit.size(), 1u);
  EXPECT_TRUE(grids.beyondTheLimit.front().IsSame(needle));
  EXPECT_GT(grids.largest, 0);

  const MeshedFaces meshed = meshWithin(both, kFine, Handle(Message_ProgressIndicator)());
  ASSERT_EQ(meshed.beyondTheLimit.size(), 1u);
  EXPECT_TRUE(meshed.beyondTheLimit.front().IsSame(needle));
  EXPECT_EQ(triangles(needle), 0);
  for (TopExp_Explorer ex(sound, TopAbs_FACE); ex.More(); ex.Next()) EXPECT_GT(triangles(TopoDS::Face(ex.Current())), 0);
}

// Each analytic surface gets a grid, and a real one stays far below the limit.
TEST(MeshingLimits, RealAnalyticFacesStayFarBelowTheLimit) {
  const TopoDS_Shape shapes[] = {BRepPrimAPI_MakeCylinder(50, 400).Shape(), BRepPrimAPI_MakeCone(50, 0, 200).Shape(),
                                 BRepPrimAPI_MakeSphere(100).Shape(), BRepPrimAPI_MakeTorus(100, 5).Shape()};
  for (const TopoDS_Shape& shape : shapes) {
    const SurfaceGrids grids = surfaceGrids(shape, kFine);
    EXPECT_TRUE(grids.beyondTheLimit.empty());
    EXPECT_GT(grids.largest, 1);
    EXPECT_LT(grids.largest, kMaxSurfaceGridNodes / 20);
  }
}

TEST(MeshingLimits, TheSamplePartsStayFarBelowTheLimit) {
  for (const char* name : {"block", "cylinder", "loft", "plate"}) {
    const SurfaceGrids grids = surfaceGrids(sampleShape(name), kFine);
    EXPECT_TRUE(grids.beyondTheLimit.empty()) << name;
    EXPECT_LT(grids.largest, kMaxSurfaceGridNodes / 20) << name;
  }
}

// The curved face of a damaged cone from fuzz_brep, as ShapeFix healed it: once BRepMesh
// has healed its wire, its edge points all lie at U = 0. The crossing search's BRepMesh took
// more than 8 GB on it in a minute, laying points 1e-8 apart along its seam.
TEST(MeshingLimits, AConeWhoseEdgePointsSpanNoWidthIsBeyondTheLimit) {
  const TopoDS_Shape cone = test::readShape(fs::path(HG_TEST_DATA_DIR) / "cone_seam_without_width.brep");
  const MeshingParameters asTheCrossingSearch{0.752665, 1.0};
  EXPECT_EQ(surfaceGrids(cone, asTheCrossingSearch).beyondTheLimit.size(), 1u);
  const MeshedFaces meshed = meshWithin(cone, asTheCrossingSearch, Handle(Message_ProgressIndicator)());
  ASSERT_EQ(meshed.beyondTheLimit.size(), 1u);
  EXPECT_EQ(triangles(meshed.beyondTheLimit.front()), 0);
}

// The damaged cone itself loads, on the mesh back end, which refuses it in one line: its
// plane face, filled from its edges, gives no triangles.
TEST(MeshingLimits, TheDamagedConeFromFuzzingLoadsAndItsBackEndAnswers) {
  const std::string text = test::readFile(fs::path(HG_TEST_DATA_DIR) / "../fuzz/corpus/brep/mesh_cone_seam_unbounded.brep");
  ASSERT_FALSE(text.empty());
  PartLoadOptions options;
  options.parallel = false;
  const PartModelPtr part = PartModel::fromBrepText(text, LengthUnit::Millimetre, "cone", options);
  EXPECT_EQ(part->backendChoice().backend, Backend::Mesh);
  try {
    EXPECT_NE(makePenetration(part), nullptr);
  } catch (const GeometryError& e) {
    EXPECT_STREQ(e.what(), "tessellation left face 2 without triangles");
  }
}

}  // namespace
}  // namespace hg::geometry
