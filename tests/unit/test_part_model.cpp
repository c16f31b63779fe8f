// PartModel: every bad input is a GeometryError naming the problem; compounds of solids as one
// part; defects healed or answered by a robust back end; units, mass properties and the
// sample parts.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Writer.hxx>
#include <ShapeFix_ShapeTolerance.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>
#include <gp_Pln.hxx>
#include <gp_Quaternion.hxx>
#include <gp_Trsf.hxx>

#include <Eigen/Eigenvalues>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/geometry/mass_properties.hpp"
#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/geometry/sample_parts.hpp"
#include "file_fixtures.hpp"
#include "temp_dir.hpp"
#include "test_shapes.hpp"

namespace hg::geometry {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
constexpr double kPi = std::numbers::pi;

// ---------------------------------------------------------------------------------------
// Helpers

// Runs `load`, which must throw a GeometryError whose message contains `what`.
template <class Load>
void expectGeometryError(Load&& load, const std::string& what) {
  try {
    load();
    ADD_FAILURE() << "loaded without error; expected a GeometryError naming \"" << what << "\"";
  } catch (const GeometryError& e) {
    EXPECT_THAT(e.what(), HasSubstr(what));
  }
}

std::string brepText(const TopoDS_Shape& shape) {
  std::ostringstream out;
  BRepTools::Write(shape, out);
  return out.str();
}

TopoDS_Shape boxShape(double x, double y, double z) {
  return BRepPrimAPI_MakeBox(gp_Pnt(-x / 2, -y / 2, -z / 2), x, y, z).Shape();
}

TopoDS_Shape cylinderShape(double radius, double length) {
  return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -length / 2), gp::DZ()), radius, length).Shape();
}

TopoDS_Shape transformed(const TopoDS_Shape& shape, const gp_Trsf& trsf) {
  return BRepBuilderAPI_Transform(shape, trsf, true).Shape();
}

TopoDS_Shape scaled(const TopoDS_Shape& shape, double factor) {
  gp_Trsf trsf;
  trsf.SetScale(gp::Origin(), factor);
  return transformed(shape, trsf);
}

// A scratch directory for the files the tests write, removed at exit.
const fs::path& tempDir() { return hg::test::processTempDir("part-model"); }

fs::path writeFile(const std::string& name, const std::string& content) {
  const fs::path path = tempDir() / name;
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

using hg::test::readFile;

fs::path writeStep(const TopoDS_Shape& shape, const std::string& name) {
  const fs::path path = tempDir() / name;
  STEPControl_Writer writer;
  if (writer.Transfer(shape, STEPControl_AsIs) != IFSelect_RetDone || writer.Write(path.c_str()) != IFSelect_RetDone)
    throw std::runtime_error("could not write " + path.string());
  return path;
}

// |a - b| <= tol * scale, elementwise, with a message naming the element.
void expectNearMatrix(const Mat3& a, const Mat3& b, double tol, const char* what) {
  const double scale = std::max(a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff());
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a(r, c), b(r, c), tol * scale) << what << " (" << r << "," << c << ")";
}

void expectNearVec(const Vec3& a, const Vec3& b, double tol, const char* what) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], tol) << what << " [" << i << "]";
}

double smallestEigenvalue(const Mat3& symmetric) {
  return Eigen::SelfAdjointEigenSolver<Mat3>(symmetric).eigenvalues().minCoeff();
}

// Inertia of a uniform box of mass m about its centre, axes along its edges.
Mat3 boxInertia(double m, double a, double b, double c) {
  return Vec3(m / 12 * (b * b + c * c), m / 12 * (a * a + c * c), m / 12 * (a * a + b * b)).asDiagonal();
}

// ---------------------------------------------------------------------------------------
// Bad input: a GeometryError naming the problem, never a crash.

TEST(PartModelBadInput, EmptyBrepText) {
  expectGeometryError([] { PartModel::fromBrepText("", LengthUnit::Millimetre); }, "empty BREP text");
}

TEST(PartModelBadInput, WhitespaceOnlyBrepText) {
  expectGeometryError([] { PartModel::fromBrepText(" \n\t\r\n  ", LengthUnit::Millimetre); }, "empty BREP text");
}

TEST(PartModelBadInput, GarbageBrepText) {
  expectGeometryError([] { PartModel::fromBrepText("this is not a B-rep\n42 17\n", LengthUnit::Millimetre); },
                      "BREP text could not be read");
}

TEST(PartModelBadInput, TruncatedBrepText) {
  const std::string text = brepText(cylinderShape(50, 400));
  for (const std::size_t length : {text.size() / 2, text.size() / 4, text.size() * 3 / 4, text.size() - 20}) {
    SCOPED_TRACE("truncated to " + std::to_string(length) + " of " + std::to_string(text.size()) + " characters");
    expectGeometryError([&] { PartModel::fromBrepText(text.substr(0, length), LengthUnit::Millimetre); },
                        "BREP text could not be read");
  }
}

// A section count no text of its length could hold: refused before OCCT sizes its tables
// by it and spins through entries that are not there (11 s on the 1 KiB cylinder).
TEST(PartModelBadInput, AbsurdSectionCountInBrepText) {
  std::string text = brepText(cylinderShape(50, 400));
  const std::size_t curves = text.find("\nCurves ");
  ASSERT_NE(curves, std::string::npos);
  text.replace(curves + 8, text.find('\n', curves + 1) - curves - 8, "2000000000");
  expectGeometryError([&] { PartModel::fromBrepText(text, LengthUnit::Millimetre); },
                      "its Curves section claims 2000000000 entries in a text of");
}

// NaN parameters send OCCT's reader round its curve trimming for minutes, and an infinite
// plane axis its projection of an edge onto the plane for good; OCCT never writes them, so a
// text holding one is refused before it is read.
TEST(PartModelBadInput, NotFiniteNumberInBrepText) {
  const std::string text = brepText(cylinderShape(50, 400));
  const std::size_t surfaces = text.find("\nSurfaces ");
  ASSERT_NE(surfaces, std::string::npos);
  // The last two are infinite to OCCT's strtod.
  for (const char* word : {"nan", "-nan", "inf", "-Infinity", "0.5547e2915", "-0x1p2000"}) {
    SCOPED_TRACE(word);
    std::string broken = text;
    const std::size_t entry = broken.find('\n', surfaces + 1) + 1;  // "2 0 0 -200 ...": type, then numbers
    broken.replace(entry + 2, broken.find(' ', entry + 2) - entry - 2, word);
    expectGeometryError([&] { PartModel::fromBrepText(broken, LengthUnit::Millimetre); },
                        std::string("it holds a number that is not finite (") + word + ")");
  }
}

// A number too small for a double is zero to OCCT's reader, as to the check: the part loads.
TEST(PartModelBadInput, NumberBelowDoubleIsZero) {
  const std::string text = brepText(cylinderShape(50, 400));
  const std::size_t surfaces = text.find("\nSurfaces ");
  ASSERT_NE(surfaces, std::string::npos);
  std::string tiny = text;
  const std::size_t entry = tiny.find('\n', surfaces + 1) + 1;  // "2 0 0 -200 ...": type, then the origin's x
  ASSERT_EQ(tiny.substr(entry, 4), "2 0 ");
  tiny.replace(entry + 2, 1, "1e-400");
  EXPECT_NEAR(PartModel::fromBrepText(tiny, LengthUnit::Millimetre)->massProperties(MassSpec::density(1)).volume_m3,
              M_PI * 0.05 * 0.05 * 0.4, 1e-9);
}

// A word where the reader expects a number fails the stream, after which every read does
// nothing and OCCT's reader spins through its counts: the edge's "1  5 0 -10 10" (curve 5
// on [-10, 10]) as "1 (5 0 -10 10" never returned (fuzz_brep; the input is in its corpus).
TEST(PartModelBadInput, WordForANumberInBrepText) {
  std::string text = readFile(fs::path(HG_TEST_DATA_DIR) / "../corpus/parts/trimmed_surfaces.brep");
  const std::size_t edgeCurve = text.find("\n1  5 0 -10 10\n");
  ASSERT_NE(edgeCurve, std::string::npos);
  text.replace(edgeCurve + 3, 1, "(");
  const auto start = std::chrono::steady_clock::now();
  expectGeometryError([&] { PartModel::fromBrepText(text, LengthUnit::Millimetre); },
                      "BREP text could not be read: truncated, or not BREP");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
}

// A cylinder whose bottom circle has an empty parameter range on the side face (a flipped
// byte, found by fuzz_brep): ShapeFix's classifier reduced a parameter of 1e100 by one period
// at a time, forever. The part is now given to a robust back end unhealed, saying why.
TEST(PartModelBadInput, EmptyPcurveRangeIsNotHealed) {
  const fs::path path = fs::path(HG_TEST_DATA_DIR) / "../fuzz/corpus/brep/timeout_empty_pcurve_range.brep";
  const PartModelPtr part = PartModel::fromFile(path, LengthUnit::Millimetre);
  EXPECT_NE(part->backendChoice().backend, Backend::Exact);
  EXPECT_THAT(part->backendChoice().reason,
              HasSubstr("edge 3 has an empty parameter range on face 1 (not healable)"));
}

// A torus whose seam runs on [0, 6.1e15] (a digit lost, found by fuzz_brep): every OCCT
// algorithm that brings a parameter into the period one period at a time (ShapeFix's
// classifier, then the bounding box) never ended. The loader refuses it first.
TEST(PartModelBadInput, ACurveThatRunsRoundAFaceIsRefused) {
  const fs::path path = fs::path(HG_TEST_DATA_DIR) / "../fuzz/corpus/brep/timeout_pcurve_beyond_periods.brep";
  expectGeometryError([&] { PartModel::fromFile(path, LengthUnit::Millimetre); },
                      "the part's geometry is damaged: edge 2 runs more than 1000 times round on face 1");
  // And a sphere's seam far off its latitudes: BRepMesh never finished the face.
  expectGeometryError([] {
    PartModel::fromFile(fs::path(HG_TEST_DATA_DIR) / "../fuzz/corpus/brep/timeout_sphere_seam_runs_off.brep",
                        LengthUnit::Millimetre);
  }, "the part's geometry is damaged: edge 2 runs 1000 times its size off on face 1");
}

TEST(PartModelBadInput, MissingFile) {
  expectGeometryError([] { PartModel::fromFile(tempDir() / "no_such_part.brep", LengthUnit::Millimetre); },
                      "no such file");
}

TEST(PartModelBadInput, Directory) {
  expectGeometryError([] { PartModel::fromFile(tempDir(), LengthUnit::Millimetre); }, "no such file");
}

TEST(PartModelBadInput, EmptyFile) {
  expectGeometryError([] { PartModel::fromFile(writeFile("empty.brep", ""), LengthUnit::Millimetre); }, "empty file");
  expectGeometryError([] { PartModel::fromFile(writeFile("empty.step", ""), LengthUnit::Millimetre); }, "empty file");
}

TEST(PartModelBadInput, UnknownExtension) {
  const fs::path path = writeFile("cylinder.stl", brepText(cylinderShape(50, 400)));
  expectGeometryError([&] { PartModel::fromFile(path, LengthUnit::Millimetre); }, "unknown part file type '.stl'");
  const fs::path none = writeFile("cylinder", brepText(cylinderShape(50, 400)));
  expectGeometryError([&] { PartModel::fromFile(none, LengthUnit::Millimetre); }, "unknown part file type");
}

TEST(PartModelBadInput, UpperCaseExtensionIsAccepted) {
  const fs::path path = writeFile("cylinder.BREP", brepText(cylinderShape(50, 400)));
  EXPECT_NEAR(PartModel::fromFile(path, LengthUnit::Millimetre)->massProperties(MassSpec::density(1)).volume_m3,
              kPi * 0.05 * 0.05 * 0.4, 1e-12);
}

TEST(PartModelBadInput, GarbageBrepFile) {
  const fs::path path = writeFile("garbage.brep", "CASCADE Topology V1, (c) Matra-Datavision\nLocations 3\nbroken");
  expectGeometryError([&] { PartModel::fromFile(path, LengthUnit::Millimetre); }, "could not be read: its location 1 is not as OCCT writes it");
}

TEST(PartModelBadInput, TruncatedBrepFile) {
  const std::string text = brepText(cylinderShape(50, 400));
  const fs::path path = writeFile("truncated.brep", text.substr(0, text.size() / 2));
  expectGeometryError([&] { PartModel::fromFile(path, LengthUnit::Millimetre); }, "could not be read");
}

TEST(PartModelBadInput, GarbageStepFile) {
  const fs::path path = writeFile("garbage.step", "this is not STEP\nat all\n");
  expectGeometryError([&] { PartModel::fromFile(path, LengthUnit::Millimetre); }, "STEP file could not be read");
}

TEST(PartModelBadInput, TruncatedStepFile) {
  const std::string text = readFile(writeStep(cylinderShape(50, 400), "whole.step"));
  ASSERT_GT(text.size(), 1000u);
  const fs::path path = writeFile("truncated.step", text.substr(0, text.size() / 2));
  expectGeometryError([&] { PartModel::fromFile(path, LengthUnit::Millimetre); }, "STEP file could not be read");
}

TEST(PartModelBadInput, NullShape) {
  expectGeometryError([] { PartModel::fromShape(TopoDS_Shape(), LengthUnit::Millimetre); }, "empty shape");
}

TEST(PartModelBadInput, OnlyAFace) {
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(gp_Pln(gp::XOY()), -10, 10, -10, 10).Face();
  expectGeometryError([&] { PartModel::fromShape(face, LengthUnit::Millimetre); },
                      "not a solid: the shape is a face");
  // The same as BREP text.
  expectGeometryError([&] { PartModel::fromBrepText(brepText(face), LengthUnit::Millimetre); }, "not a solid");
}

TEST(PartModelBadInput, OnlyAWireOrAnEdge) {
  const TopoDS_Edge edge = BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(10, 0, 0)).Edge();
  expectGeometryError([&] { PartModel::fromShape(edge, LengthUnit::Millimetre); }, "not a solid: the shape is an edge");
  const TopoDS_Wire wire = BRepBuilderAPI_MakeWire(edge).Wire();
  expectGeometryError([&] { PartModel::fromShape(wire, LengthUnit::Millimetre); }, "not a solid: the shape is a wire");
  expectGeometryError([&] { PartModel::fromShape(BRepBuilderAPI_MakeVertex(gp::Origin()).Vertex(), LengthUnit::Millimetre); },
                      "not a solid");
}

TEST(PartModelBadInput, OpenShell) {
  // A box's shell without its top face.
  const TopoDS_Shape box = boxShape(10, 20, 30);
  TopoDS_Shell shell;
  BRep_Builder builder;
  builder.MakeShell(shell);
  int faces = 0;
  for (TopExp_Explorer ex(box, TopAbs_FACE); ex.More(); ex.Next(), ++faces)
    if (faces != 5) builder.Add(shell, ex.Current());
  ASSERT_EQ(faces, 6);
  expectGeometryError([&] { PartModel::fromShape(shell, LengthUnit::Millimetre); }, "open shell with 4 free edges");
  // As a "solid" made of it.
  TopoDS_Solid solid;
  builder.MakeSolid(solid);
  builder.Add(solid, shell);
  expectGeometryError([&] { PartModel::fromShape(solid, LengthUnit::Millimetre); }, "not a closed solid: 4 free edges");
}

TEST(PartModelBadInput, ClosedShellIsMadeASolid) {
  TopoDS_Shell shell;
  for (TopExp_Explorer ex(boxShape(10, 20, 30), TopAbs_SHELL); ex.More(); ex.Next()) shell = TopoDS::Shell(ex.Current());
  const PartModelPtr part = PartModel::fromShape(shell, LengthUnit::Millimetre);
  EXPECT_NEAR(part->massProperties(MassSpec::density(1)).volume_m3, 6000e-9, 1e-15);
  ASSERT_EQ(part->warnings().size(), 1u);
  EXPECT_THAT(part->warnings()[0], HasSubstr("closed shell"));
}

TEST(PartModelBadInput, OpenShellOfLooseFacesIsSewnOrRefused) {
  // A box's six faces, not sewn (as a STEP file may hold them): sewn into a solid.
  const TopoDS_Shape box = boxShape(10, 20, 30);
  std::vector<TopoDS_Shape> faces;
  for (TopExp_Explorer ex(box, TopAbs_FACE); ex.More(); ex.Next())
    faces.push_back(BRepBuilderAPI_Copy(ex.Current()).Shape());  // each with its own edges
  TopoDS_Compound loose;
  BRep_Builder builder;
  builder.MakeCompound(loose);
  for (const TopoDS_Shape& f : faces) builder.Add(loose, f);
  const PartModelPtr part = PartModel::fromShape(loose, LengthUnit::Millimetre);
  EXPECT_NEAR(part->massProperties(MassSpec::density(1)).volume_m3, 6000e-9, 1e-12);
  ASSERT_EQ(part->warnings().size(), 1u);
  EXPECT_THAT(part->warnings()[0], HasSubstr("sewn into a closed solid"));
  EXPECT_EQ(part->backendChoice().backend, Backend::Exact);
  // One face moved off by 1 um leaves a gap sewing closes (within 1e-4 of the size)...
  gp_Trsf nudge;
  nudge.SetTranslation(gp_Vec(0, 0, 1e-3));
  TopoDS_Compound gap;
  builder.MakeCompound(gap);
  for (std::size_t i = 0; i < faces.size(); ++i) builder.Add(gap, i == 5 ? transformed(faces[i], nudge) : faces[i]);
  EXPECT_THAT(PartModel::fromShape(gap, LengthUnit::Millimetre)->warnings()[0], HasSubstr("sewn"));
  // ... but not a missing face: refused with one line.
  TopoDS_Compound open;
  builder.MakeCompound(open);
  for (std::size_t i = 0; i < 5; ++i) builder.Add(open, faces[i]);
  expectGeometryError([&] { PartModel::fromShape(open, LengthUnit::Millimetre); }, "does not close it");
}

// ---------------------------------------------------------------------------------------
// Compounds: one rigid part, however many solids. Touching is fine; overlapping volumes are
// measured, since the mass properties count them twice.

// The warning about overlapping solids, or "" when there is none.
std::string overlapWarning(const PartModel& part) {
  for (const std::string& w : part.warnings())
    if (w.find("overlap") != std::string::npos) return w;
  return {};
}

// The volume in mm^3 a warning names ("... overlap by 125 mm^3, ..."), or -1.
double overlapVolume_mm3(const std::string& warning) {
  const std::size_t at = warning.find("overlap by ");
  if (at == std::string::npos) return -1;
  return std::stod(warning.substr(at + 11));
}

TEST(PartModelCompounds, TouchingBoxesLoadWithoutAnOverlap) {
  const TopoDS_Shape a = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 10, 10, 10).Shape();
  const TopoDS_Shape b = BRepPrimAPI_MakeBox(gp_Pnt(10, 0, 0), 10, 10, 10).Shape();   // a face against a's
  const TopoDS_Shape c = BRepPrimAPI_MakeBox(gp_Pnt(2, 2, 10), 5, 5, 5).Shape();      // on a's top
  const TopoDS_Shape d = BRepPrimAPI_MakeBox(gp_Pnt(20, 10, 0), 5, 5, 5).Shape();     // along b's edge
  const PartModelPtr part = PartModel::fromShape(test::compoundOf({a, b, c, d}), LengthUnit::Millimetre, "touching");
  EXPECT_TRUE(part->warnings().empty()) << part->warnings()[0];
  EXPECT_EQ(part->backendChoice().backend, Backend::Exact);
  EXPECT_EQ(part->backendChoice().reason, "exact: valid B-rep");
  EXPECT_NEAR(part->massProperties(MassSpec::density(1)).volume_m3, (2000 + 125 + 125) * 1e-9, 1e-15);
}

TEST(PartModelCompounds, OverlappingBoxesLoadWithTheirOverlap) {
  const TopoDS_Shape a = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 10, 10, 10).Shape();
  const TopoDS_Shape b = BRepPrimAPI_MakeBox(gp_Pnt(5, 5, 5), 10, 10, 10).Shape();
  const PartModelPtr part = PartModel::fromShape(test::compoundOf({a, b}), LengthUnit::Millimetre);
  const std::string warning = overlapWarning(*part);
  EXPECT_THAT(warning, HasSubstr("solids 1 and 2 overlap by 125 mm^3"));
  EXPECT_THAT(warning, HasSubstr("6.25 % of the part's volume"));  // 125 of 2000
  EXPECT_THAT(warning, HasSubstr("count it twice"));
  EXPECT_EQ(part->backendChoice().backend, Backend::Exact);  // each solid is valid
  // The mass properties are those of the solids as given: the overlap counted twice.
  EXPECT_NEAR(part->massProperties(MassSpec::density(1)).volume_m3, 2000e-9, 1e-15);
}

TEST(PartModelCompounds, ABoxInsideABoxOverlapsByAllOfIt) {
  // Boundaries apart: only a containment test finds it.
  const TopoDS_Shape outer = boxShape(20, 20, 20);
  const TopoDS_Shape inner = boxShape(2, 2, 2);
  for (const TopoDS_Shape& shape : {test::compoundOf({outer, inner}), test::compoundOf({inner, outer}),
                                    test::compoundOf({outer.Reversed(), inner})}) {  // turned before the test
    const PartModelPtr part = PartModel::fromShape(shape, LengthUnit::Millimetre);
    EXPECT_NEAR(overlapVolume_mm3(overlapWarning(*part)), 8, 1e-9) << overlapWarning(*part);
  }
}

TEST(PartModelCompounds, FacesCrossingInAClosedLoopBetweenSolids) {
  const PartModelPtr part = PartModel::fromShape(test::sphereThroughSlab(), LengthUnit::Millimetre);
  // The sphere (r = 5) below the slab's top (z = 3): all of it but a cap of height 2.
  const double r = 5, h = 2;
  const double expected = 4 * kPi * r * r * r / 3 - kPi * h * h * (3 * r - h) / 3;
  EXPECT_NEAR(overlapVolume_mm3(overlapWarning(*part)), expected, 1e-3 * expected) << overlapWarning(*part);
}

TEST(PartModelCompounds, ABoltInItsNutTouchesAndAFatOneOverlaps) {
  const PartModelPtr fits = PartModel::fromShape(test::boltInNut(4), LengthUnit::Millimetre, "fits");
  EXPECT_TRUE(fits->warnings().empty()) << fits->warnings()[0];
  const PartModelPtr fat = PartModel::fromShape(test::boltInNut(4.5), LengthUnit::Millimetre, "fat");
  const double expected = kPi * (4.5 * 4.5 - 4 * 4) * 6;  // the ring the nut and the bolt share
  EXPECT_NEAR(overlapVolume_mm3(overlapWarning(*fat)), expected, 1e-3 * expected) << overlapWarning(*fat);
}

// The public AS1 assembly (Open CASCADE sample, STEPcode's copy): 18 solids, bolts touching
// plates, nuts and brackets, read as one compound.
TEST(PartModelCompounds, TheAs1AssemblyLoadsAsOnePart) {
  const PartModelPtr part = PartModel::fromFile(fs::path(HG_TEST_DATA_DIR) / "as1-oc-214.stp", LengthUnit::Millimetre);
  TopTools_IndexedMapOfShape solids;
  TopExp::MapShapes(part->shape(), TopAbs_SOLID, solids);
  EXPECT_EQ(solids.Extent(), 18);
  EXPECT_EQ(part->faces().Extent(), 160);
  EXPECT_TRUE(part->warnings().empty()) << part->warnings()[0];
  EXPECT_EQ(part->backendChoice().backend, Backend::Exact);
  EXPECT_THAT(part->backendChoice().reason, HasSubstr("exact: valid B-rep"));
  // The sum of the solids' volumes, as FreeCAD's Shape.Volume gives it.
  EXPECT_NEAR(part->massProperties(MassSpec::density(1)).volume_m3, 764520e-9, 1e-6 * 764520e-9);
  const PartLoadTiming& t = part->loadTiming();
  std::printf("AS1: load %.3f s (read %.3f s, checks %.3f s)\n", t.total_s, t.read_s, t.check_s);
}

TEST(PartModelCompounds, CrossingSearchCanBeSkipped) {
  PartModel::LoadOptions options;
  options.checkSelfIntersection = false;
  const TopoDS_Shape a = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 10, 10, 10).Shape();
  const TopoDS_Shape b = BRepPrimAPI_MakeBox(gp_Pnt(5, 5, 5), 10, 10, 10).Shape();
  const PartModelPtr part = PartModel::fromShape(test::compoundOf({a, b}), LengthUnit::Millimetre, "boxes", options);
  EXPECT_TRUE(part->warnings().empty());
  // The other checks still run.
  const TopoDS_Edge edge = BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(10, 0, 0)).Edge();
  expectGeometryError([&] { PartModel::fromShape(edge, LengthUnit::Millimetre, "edge", options); }, "not a solid");
}

// ---------------------------------------------------------------------------------------
// Defects of one solid: tolerance-level findings are not defects; a real one is healed, or
// answered by a back end that does not depend on it, and said in one line.

TEST(PartModelDefects, AHelicalThreadOfBSplineFacesLoadsAsExact) {
  // Three B-spline faces wound around each other: the pave-filler check this replaced took
  // minutes on it, and its per-face self-intersection step could call such faces defective.
  const PartModelPtr part = PartModel::fromShape(test::helicalThread(), LengthUnit::Millimetre, "thread");
  EXPECT_EQ(part->faces().Extent(), 5);
  EXPECT_EQ(part->backendChoice().reason, "exact: valid B-rep");
  EXPECT_TRUE(part->warnings().empty());
  std::printf("thread: load %.3f s (checks %.3f s)\n", part->loadTiming().total_s, part->loadTiming().check_s);
}

TEST(PartModelDefects, VerticesWithinTheirTolerancesLoadAsExact) {
  // A 0.5 mm thin plate whose vertices carry 0.3 mm tolerances, as STEP files from other
  // systems do: each vertex's sphere overlaps its neighbour's across the thickness.
  TopoDS_Shape plate = BRepBuilderAPI_Copy(boxShape(10, 10, 0.5)).Shape();
  ShapeFix_ShapeTolerance().SetTolerance(plate, 0.3, TopAbs_VERTEX);
  const PartModelPtr part = PartModel::fromShape(plate, LengthUnit::Millimetre, "loose");
  EXPECT_EQ(part->backendChoice().backend, Backend::Exact);
  EXPECT_THAT(part->backendChoice().reason, HasSubstr("exact: valid B-rep (4 vertex pairs within their tolerances"));
  EXPECT_TRUE(part->warnings().empty());
}

TEST(PartModelDefects, FacesCrossingWithinOneSolidGoToTheMesh) {
  const PartModelPtr mild = PartModel::fromShape(test::twistedPrism(kPi / 3), LengthUnit::Millimetre);
  EXPECT_EQ(mild->faces().Extent(), 10);
  EXPECT_EQ(mild->backendChoice().backend, Backend::Exact);
  const PartModelPtr crossed = PartModel::fromShape(test::twistedPrism(kPi * 5 / 6), LengthUnit::Millimetre);
  EXPECT_EQ(crossed->backendChoice().backend, Backend::Mesh);
  EXPECT_THAT(crossed->backendChoice().reason, testing::MatchesRegex("mesh 0.01 mm: faces [0-9]+ and [0-9]+ cross.*"
                                                                     "\\(not healable\\); the exact back end would "
                                                                     "answer wrongly there"));
  EXPECT_TRUE(crossed->backendChoice().surfaceMayCross);
  EXPECT_FALSE(mild->backendChoice().surfaceMayCross);
  EXPECT_EQ(makePenetration(crossed)->name(), "mesh");
}

TEST(PartModelDefects, ASelfIntersectingWireIsAnsweredByTheMesh) {
  const PartModelPtr part = PartModel::fromShape(test::loopPrism(), LengthUnit::Millimetre, "loop");
  const BackendChoice& choice = part->backendChoice();
  EXPECT_EQ(choice.backend, Backend::Mesh);
  EXPECT_THAT(choice.reason, testing::MatchesRegex("mesh 0.01 mm: self-intersecting wire in face [0-9]+ \\(not "
                                                   "healable\\); the exact back end would answer wrongly there"));
  EXPECT_TRUE(choice.surfaceMayCross);
  EXPECT_EQ(choice.reason.find('\n'), std::string::npos);  // one line
}

TEST(PartModelDefects, AFaceTurnedInsideOutIsHealed) {
  // A box shell with one face reversed: BRepCheck objects to the shell's orientation;
  // ShapeFix turns the face back.
  TopoDS_Shell shell;
  BRep_Builder builder;
  builder.MakeShell(shell);
  int k = 0;
  for (TopExp_Explorer ex(boxShape(10, 20, 30), TopAbs_FACE); ex.More(); ex.Next(), ++k)
    builder.Add(shell, k == 2 ? ex.Current().Reversed() : ex.Current());
  TopoDS_Solid solid;
  builder.MakeSolid(solid);
  builder.Add(solid, shell);
  const PartModelPtr part = PartModel::fromShape(solid, LengthUnit::Millimetre, "turned");
  EXPECT_EQ(part->backendChoice().backend, Backend::Exact);
  EXPECT_THAT(part->backendChoice().reason, HasSubstr("exact: healed by ShapeFix ("));
  EXPECT_NEAR(part->massProperties(MassSpec::density(1)).volume_m3, 6000e-9, 1e-12);
}

TEST(PartModelDefects, ZeroVolumeSolidIsRefused) {
  // A closed shell of two squares on one boundary: every edge has two faces, no volume.
  const TopoDS_Wire square =
      BRepBuilderAPI_MakePolygon(gp_Pnt(0, 0, 0), gp_Pnt(10, 0, 0), gp_Pnt(10, 10, 0), gp_Pnt(0, 10, 0), true).Wire();
  const TopoDS_Face a = BRepBuilderAPI_MakeFace(gp_Pln(gp::XOY()), square).Face();
  const TopoDS_Face b = BRepBuilderAPI_MakeFace(gp_Pln(gp::XOY()), square).Face();
  TopoDS_Shell shell;
  BRep_Builder builder;
  builder.MakeShell(shell);
  builder.Add(shell, a);
  builder.Add(shell, b.Reversed());
  TopoDS_Solid solid;
  builder.MakeSolid(solid);
  builder.Add(solid, shell);
  expectGeometryError([&] { PartModel::fromShape(solid, LengthUnit::Millimetre); }, "solid has no volume");
  // One face twice is an open shell.
  TopoDS_Shell twice;
  builder.MakeShell(twice);
  builder.Add(twice, a);
  builder.Add(twice, a.Reversed());
  expectGeometryError([&] { PartModel::fromShape(twice, LengthUnit::Millimetre); }, "open shell");
}

TEST(PartModelDefects, FaceUsedThreeTimesIsNotAClosedSolid) {
  // A box with its top face doubled: three faces on each top edge.
  const TopoDS_Shape box = boxShape(10, 10, 10);
  TopoDS_Shell shell;
  BRep_Builder builder;
  builder.MakeShell(shell);
  TopoDS_Face last;
  for (TopExp_Explorer ex(box, TopAbs_FACE); ex.More(); ex.Next()) {
    builder.Add(shell, ex.Current());
    last = TopoDS::Face(ex.Current());
  }
  TopoDS_Face copy = TopoDS::Face(last.EmptyCopied());
  for (TopExp_Explorer ex(last, TopAbs_WIRE); ex.More(); ex.Next()) builder.Add(copy, ex.Current());
  builder.Add(shell, copy.Reversed());
  TopoDS_Solid solid;
  builder.MakeSolid(solid);
  builder.Add(solid, shell);
  expectGeometryError([&] { PartModel::fromShape(solid, LengthUnit::Millimetre); },
                      "not a closed solid: 4 edges bound more than two faces");
}

TEST(PartModelBadInput, InsideOutSolidIsReversedWithAWarning) {
  const TopoDS_Shape box = boxShape(100, 60, 30).Reversed();
  const PartModelPtr part = PartModel::fromShape(box, LengthUnit::Millimetre, "reversed box");
  ASSERT_EQ(part->warnings().size(), 1u);
  EXPECT_THAT(part->warnings()[0], HasSubstr("inside out"));
  const MassProperties m = part->massProperties(MassSpec::density(1000));
  EXPECT_NEAR(m.volume_m3, 0.1 * 0.06 * 0.03, 1e-15);
  expectNearMatrix(m.inertia_kgm2, boxInertia(m.mass_kg, 0.1, 0.06, 0.03), 1e-12, "inertia");
  EXPECT_TRUE(hg::test::boxPart()->warnings().empty());
}

// The signed volume enclosed by a mesh: positive when its triangles face outwards.
double signedMeshVolume(const Tessellation& mesh) {
  double v = 0;
  for (const auto& t : mesh.triangles) v += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]])) / 6;
  return v;
}

TEST(PartModelBadInput, InsideOutSolidTessellatesOutwards) {
  for (const bool reversed : {false, true}) {
    SCOPED_TRACE(reversed ? "reversed" : "as built");
    const TopoDS_Shape box = boxShape(100, 60, 30);
    const PartModelPtr part = PartModel::fromShape(reversed ? box.Reversed() : box, LengthUnit::Millimetre);
    const Tessellation mesh = tessellate(*part, 1e-4);
    EXPECT_NEAR(signedMeshVolume(mesh), 0.1 * 0.06 * 0.03, 1e-12);
  }
}

TEST(PartModelBadInput, InsideOutSolidInACompound) {
  const TopoDS_Shape a = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 10, 10, 10).Shape();
  const TopoDS_Shape b = BRepPrimAPI_MakeBox(gp_Pnt(20, 0, 0), 10, 10, 10).Shape().Reversed();
  const PartModelPtr part = PartModel::fromShape(test::compoundOf({a, b}), LengthUnit::Millimetre);
  ASSERT_EQ(part->warnings().size(), 1u);
  EXPECT_THAT(part->warnings()[0], HasSubstr("1 of 2 solids were inside out"));
  const MassProperties m = part->massProperties(MassSpec::density(1));
  EXPECT_NEAR(m.volume_m3, 2000e-9, 1e-15);
  expectNearVec(m.centre_m, Vec3(0.015, 0.005, 0.005), 1e-15, "centre");
}

// ---------------------------------------------------------------------------------------
// Units

void expectSameBounds(const Aabb& a, const Aabb& b, double relTol) {
  const double tol = relTol * std::max(a.diagonal(), b.diagonal());
  expectNearVec(a.min, b.min, tol, "bounds min");
  expectNearVec(a.max, b.max, tol, "bounds max");
}

void expectSameMass(const MassProperties& a, const MassProperties& b, double relTol) {
  EXPECT_NEAR(a.volume_m3, b.volume_m3, relTol * b.volume_m3);
  EXPECT_NEAR(a.mass_kg, b.mass_kg, relTol * b.mass_kg);
  expectNearVec(a.centre_m, b.centre_m, relTol * std::cbrt(b.volume_m3), "centre");
  expectNearMatrix(a.inertia_kgm2, b.inertia_kgm2, relTol, "inertia");
}

TEST(PartModelUnits, MillimetreAndMetreBrepTextAgree) {
  // Off-centre, so that the centre and bounds are not all zero.
  gp_Trsf move;
  move.SetTranslation(gp_Vec(30, -20, 10));
  const TopoDS_Shape mm = transformed(cylinderShape(50, 400), move);
  const TopoDS_Shape m = scaled(mm, 0.001);
  const PartModelPtr inMm = PartModel::fromBrepText(brepText(mm), LengthUnit::Millimetre, "mm");
  const PartModelPtr inM = PartModel::fromBrepText(brepText(m), LengthUnit::Metre, "m");
  EXPECT_EQ(inMm->metresPerUnit(), 1e-3);
  EXPECT_EQ(inM->metresPerUnit(), 1.0);
  expectSameBounds(inMm->bounds(), inM->bounds(), 1e-12);
  expectNearVec(inM->bounds().min, Vec3(-0.02, -0.07, -0.19), 1e-9, "bounds min");
  expectNearVec(inM->bounds().max, Vec3(0.08, 0.03, 0.21), 1e-9, "bounds max");
  for (const MassSpec spec : {MassSpec::mass(2.0), MassSpec::density(7850)})
    expectSameMass(inMm->massProperties(spec), inM->massProperties(spec), 1e-12);
  EXPECT_NEAR(inM->massProperties(MassSpec::density(1)).volume_m3, kPi * 0.05 * 0.05 * 0.4, 1e-15);
  expectNearVec(inMm->massProperties(MassSpec::mass(2)).centre_m, Vec3(0.03, -0.02, 0.01), 1e-12, "centre");
  // The primitive is in metres too.
  EXPECT_EQ(inMm->primitive().kind, Primitive::Kind::Cylinder);
  EXPECT_EQ(inM->primitive().kind, Primitive::Kind::Cylinder);
  EXPECT_NEAR(inMm->primitive().radius, 0.05, 1e-12);
  EXPECT_NEAR(inM->primitive().radius, 0.05, 1e-12);
}

TEST(PartModelUnits, StepRoundTrip) {
  const TopoDS_Shape cylinder = cylinderShape(50, 400);
  const PartModelPtr original = PartModel::fromShape(cylinder, LengthUnit::Millimetre);
  const PartModelPtr fromStep = PartModel::fromFile(writeStep(cylinder, "cylinder.step"), LengthUnit::Millimetre);
  const double v0 = original->massProperties(MassSpec::density(1)).volume_m3;
  EXPECT_NEAR(fromStep->massProperties(MassSpec::density(1)).volume_m3, v0, 1e-9 * v0);
  EXPECT_NEAR(v0, kPi * 0.05 * 0.05 * 0.4, 1e-15);
  expectSameBounds(original->bounds(), fromStep->bounds(), 1e-9);
  EXPECT_EQ(fromStep->name(), "cylinder");
}

TEST(PartModelUnits, StepFileInMetresIsReadInItsUnit) {
  // A STEP file says its unit: written in metres, read back in the same metres, whatever
  // unit the caller passes.
  const TopoDS_Shape box = boxShape(100, 60, 30);
  Interface_Static::SetCVal("write.step.unit", "M");
  const fs::path path = writeStep(box, "box_in_m.step");
  Interface_Static::SetCVal("write.step.unit", "MM");
  ASSERT_THAT(readFile(path), HasSubstr(".METRE."));
  for (const LengthUnit unit : {LengthUnit::Millimetre, LengthUnit::Metre}) {
    const PartModelPtr part = PartModel::fromFile(path, unit);
    EXPECT_NEAR(part->massProperties(MassSpec::density(1)).volume_m3, 0.1 * 0.06 * 0.03, 1e-12);
    expectNearVec(part->bounds().max, Vec3(0.05, 0.03, 0.015), 1e-9, "bounds max");
  }
}

TEST(PartModelUnits, TinyAndHugeParts) {
  struct Case {
    const char* what;
    double size;  // in `unit`
    LengthUnit unit;
    double size_m;
  };
  for (const Case& c : {Case{"1 mm cube in mm", 1, LengthUnit::Millimetre, 1e-3},
                        Case{"1 mm cube in m", 1e-3, LengthUnit::Metre, 1e-3},
                        Case{"10 m cube in mm", 1e4, LengthUnit::Millimetre, 10},
                        Case{"10 m cube in m", 10, LengthUnit::Metre, 10}}) {
    SCOPED_TRACE(c.what);
    const PartModelPtr box = PartModel::fromShape(boxShape(c.size, c.size / 2, c.size / 4), c.unit);
    EXPECT_NEAR(box->massProperties(MassSpec::density(1)).volume_m3, std::pow(c.size_m, 3) / 8, 1e-12 * std::pow(c.size_m, 3));
    EXPECT_NEAR(box->bounds().diagonal(), c.size_m * std::sqrt(1 + 0.25 + 0.0625), 1e-9 * c.size_m);
    EXPECT_EQ(box->primitive().kind, Primitive::Kind::Box);
    const PartModelPtr cylinder = PartModel::fromShape(cylinderShape(c.size / 2, c.size), c.unit);
    const double r = c.size_m / 2;
    EXPECT_NEAR(cylinder->massProperties(MassSpec::density(1)).volume_m3, kPi * r * r * c.size_m,
                1e-12 * std::pow(c.size_m, 3));
  }
}

TEST(PartModelUnits, ParseLengthUnit) {
  EXPECT_EQ(parseLengthUnit("mm"), LengthUnit::Millimetre);
  EXPECT_EQ(parseLengthUnit("m"), LengthUnit::Metre);
  expectGeometryError([] { parseLengthUnit("inch"); }, "inch");
}

// ---------------------------------------------------------------------------------------
// Mass properties

TEST(PartModelMass, BoxClosedForm) {
  const double a = 0.1, b = 0.06, c = 0.03, rho = 2700;
  const MassProperties m = hg::test::boxPart(100, 60, 30)->massProperties(MassSpec::density(rho));
  EXPECT_NEAR(m.volume_m3, a * b * c, 1e-15);
  EXPECT_NEAR(m.mass_kg, rho * a * b * c, 1e-12);
  expectNearVec(m.centre_m, Vec3::Zero(), 1e-15, "centre");
  expectNearMatrix(m.inertia_kgm2, boxInertia(m.mass_kg, a, b, c), 1e-12, "inertia");
}

TEST(PartModelMass, CylinderClosedForm) {
  const double r = 0.05, h = 0.4;
  const MassProperties m = hg::test::cylinderPart(100, 400)->massProperties(MassSpec::mass(2.0));
  EXPECT_NEAR(m.volume_m3, kPi * r * r * h, 1e-15);
  EXPECT_DOUBLE_EQ(m.mass_kg, 2.0);
  expectNearVec(m.centre_m, Vec3::Zero(), 1e-15, "centre");
  const Mat3 expected = Vec3(2.0 / 12 * (3 * r * r + h * h), 2.0 / 12 * (3 * r * r + h * h), 2.0 / 2 * r * r).asDiagonal();
  expectNearMatrix(m.inertia_kgm2, expected, 1e-12, "inertia");
}

TEST(PartModelMass, MovedBoxInertiaIsRotatedAboutItsCentre) {
  const double a = 0.1, b = 0.06, c = 0.03, rho = 1000;
  gp_Trsf trsf;
  const gp_Quaternion q(gp_Vec(1, 2, 3).Normalized(), 0.7);
  trsf.SetRotation(q);
  trsf.SetTranslationPart(gp_Vec(120, -40, 75));  // mm
  const PartModelPtr part = PartModel::fromShape(transformed(boxShape(100, 60, 30), trsf), LengthUnit::Millimetre);
  const MassProperties m = part->massProperties(MassSpec::density(rho));
  EXPECT_NEAR(m.volume_m3, a * b * c, 1e-15);
  expectNearVec(m.centre_m, Vec3(0.12, -0.04, 0.075), 1e-14, "centre");
  Mat3 R;
  const gp_Mat qm = q.GetMatrix();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R(i, j) = qm(i + 1, j + 1);
  const Mat3 expected = R * boxInertia(rho * a * b * c, a, b, c) * R.transpose();
  expectNearMatrix(m.inertia_kgm2, expected, 1e-12, "inertia");
  EXPECT_GT(std::abs(expected(0, 1)), 1e-3 * expected.maxCoeff());  // a real test of the products of inertia
  EXPECT_LT((m.inertia_kgm2 - m.inertia_kgm2.transpose()).norm(), 1e-15);
  // Still recognised as a box, in metres, in its own axes.
  const Primitive& box = part->primitive();
  ASSERT_EQ(box.kind, Primitive::Kind::Box);
  expectNearVec(box.centre, Vec3(0.12, -0.04, 0.075), 1e-12, "box centre");
  EXPECT_NEAR(box.halfExtents.prod(), a * b * c / 8, 1e-15);
  EXPECT_NEAR(box.axes.determinant(), 1.0, 1e-12);
  // The box's axes are the rotated x, y, z, in some order and sense.
  for (int k = 0; k < 3; ++k) EXPECT_NEAR((R.transpose() * box.axes.col(k)).cwiseAbs().maxCoeff(), 1.0, 1e-12);
}

TEST(PartModelMass, MassAndDensityAgree) {
  const PartModelPtr part = hg::test::drilledBlockPart();
  const MassProperties byDensity = part->massProperties(MassSpec::density(2700));
  const MassProperties byMass = part->massProperties(MassSpec::mass(byDensity.mass_kg));
  expectSameMass(byMass, byDensity, 1e-12);
  // Inertia scales with the mass, the rest does not move.
  const MassProperties doubled = part->massProperties(MassSpec::mass(2 * byDensity.mass_kg));
  EXPECT_DOUBLE_EQ(doubled.volume_m3, byDensity.volume_m3);
  expectNearVec(doubled.centre_m, byDensity.centre_m, 1e-15, "centre");
  expectNearMatrix(doubled.inertia_kgm2, 2 * byDensity.inertia_kgm2, 1e-12, "inertia");
  // A hole makes it lighter than its box, and the inertia is positive definite.
  EXPECT_LT(byDensity.volume_m3, 0.1 * 0.06 * 0.03);
  EXPECT_GT(smallestEigenvalue(byDensity.inertia_kgm2), 0);
}

TEST(PartModelMass, NonPositiveMassOrDensityThrows) {
  const PartModelPtr part = hg::test::boxPart();
  for (const double value : {0.0, -1.0, -0.0, std::numeric_limits<double>::quiet_NaN()}) {
    SCOPED_TRACE(value);
    expectGeometryError([&] { part->massProperties(MassSpec::mass(value)); }, "must be positive");
    expectGeometryError([&] { part->massProperties(MassSpec::density(value)); }, "must be positive");
  }
}

// ---------------------------------------------------------------------------------------
// Shapes from the other tests' builders and the sample parts

TEST(PartModelShapes, TestShapesLoad) {
  EXPECT_EQ(hg::test::spherePart(40)->primitive().kind, Primitive::Kind::Sphere);
  EXPECT_EQ(hg::test::boxPart()->primitive().kind, Primitive::Kind::Box);
  EXPECT_EQ(hg::test::cylinderPart()->primitive().kind, Primitive::Kind::Cylinder);
  EXPECT_EQ(hg::test::drilledBlockPart()->primitive().kind, Primitive::Kind::None);
  const PartModelPtr loft = hg::test::loftPart();
  EXPECT_EQ(loft->faces().Extent(), 3);
  EXPECT_GT(loft->massProperties(MassSpec::density(1)).volume_m3, 0);
}

TEST(PartModelShapes, SamplePartsLoad) {
  const std::vector<SamplePart> parts = sampleParts();
  ASSERT_EQ(parts.size(), 4u);
  for (const SamplePart& sample : parts) {
    SCOPED_TRACE(sample.name);
    const PartModelPtr part = PartModel::fromFile(sample.file, sample.unit);  // the plate once: it is the slow one
    EXPECT_EQ(part->name(), sample.name);
    EXPECT_TRUE(part->warnings().empty());
    EXPECT_EQ(part->backendChoice().backend, Backend::Exact);
    EXPECT_EQ(part->backendChoice().reason, "exact: valid B-rep");
    const PartLoadTiming& t = part->loadTiming();
    EXPECT_GT(t.total_s, 0);
    EXPECT_LE(t.read_s + t.check_s, t.total_s);
    std::printf("%s: %d faces, load %.3f s (read %.3f s, checks %.3f s)\n", sample.name.c_str(), part->faces().Extent(),
                t.total_s, t.read_s, t.check_s);
    EXPECT_GT(part->faces().Extent(), 0);
    EXPECT_FALSE(part->bounds().empty());
    const MassProperties m = part->massProperties(sample.mass);
    EXPECT_GT(m.volume_m3, 0);
    EXPECT_GT(m.mass_kg, 0);
    EXPECT_TRUE(part->bounds().contains(m.centre_m));
    EXPECT_GT(smallestEigenvalue(m.inertia_kgm2), 0);
    if (sample.name == "cylinder") {
      EXPECT_EQ(part->faces().Extent(), 3);
      EXPECT_NEAR(m.volume_m3, kPi * 0.05 * 0.05 * 0.4, 1e-15);
      EXPECT_DOUBLE_EQ(m.mass_kg, 2.0);
    } else if (sample.name == "block") {
      EXPECT_EQ(part->faces().Extent(), 58);
    } else if (sample.name == "loft") {
      EXPECT_EQ(part->faces().Extent(), 3);
    } else if (sample.name == "plate") {
      EXPECT_EQ(part->faces().Extent(), 1030);
      EXPECT_NEAR(m.volume_m3, (200 * 200 * 5 - 1024 * kPi * 1.5 * 1.5 * 5) * 1e-9, 1e-15);
      expectNearVec(m.centre_m, Vec3(0, 0, 0.0025), 1e-12, "centre");
    } else {
      ADD_FAILURE() << "unknown sample part";
    }
  }
}

}  // namespace
}  // namespace hg::geometry
