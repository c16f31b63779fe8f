#include "hapticgrasp/geometry/part_model.hpp"

#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_MakeSolid.hxx>
#include <BRepGProp.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shell.hxx>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iterator>
#include <streambuf>
#include <string_view>
#include <utility>
#include <vector>

#include "hapticgrasp/geometry/occt_faults.hpp"
#include "brep_text_check.hpp"
#include "curve_on_face.hpp"
#include "part_check.hpp"
#include "primitive_recognition.hpp"
#include "shape_healing.hpp"
#include "shape_names.hpp"
#include "shape_topology.hpp"
#include "step_references.hpp"

namespace hg::geometry {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

double diagonalOf(const TopoDS_Shape& shape) {
  Bnd_Box box;
  BRepBndLib::Add(shape, box);
  return box.IsVoid() ? 0 : std::sqrt(box.SquareExtent());
}

TopoDS_Compound compoundOf(const std::vector<TopoDS_Shape>& shapes) {
  TopoDS_Compound compound;
  BRep_Builder builder;
  builder.MakeCompound(compound);
  for (const TopoDS_Shape& s : shapes) builder.Add(compound, s);
  return compound;
}

std::string millimetres(double length, double metresPerUnit) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2g mm", length * metresPerUnit * 1e3);
  return text;
}

// Sewing closes gaps up to a ten-thousandth of the part's size (0.01 mm in 100 mm), or ten
// times the largest tolerance the shape carries: what STEP files of other systems leave
// between faces written one by one.
double sewingTolerance(const TopoDS_Shape& shape) {
  return std::max(1e-4 * diagonalOf(shape), 10 * BRep_Tool::MaxTolerance(shape, TopAbs_VERTEX));
}

// The solids sewing makes of `shape`'s faces, or a GeometryError naming what stays open.
std::vector<TopoDS_Shape> sewn(const TopoDS_Shape& shape, const std::string& what, double metresPerUnit,
                               std::vector<std::string>& warnings) {
  const double tolerance = sewingTolerance(shape);
  int open = 0;
  const TopoDS_Shape solids = sewIntoSolids(shape, tolerance, open);
  std::vector<TopoDS_Shape> out;
  for (TopExp_Explorer ex(solids, TopAbs_SOLID); ex.More(); ex.Next()) out.push_back(ex.Current());
  if (out.empty() || open != 0) throw GeometryError(what + " (sewing within " + millimetres(tolerance, metresPerUnit) +
                                                    " does not close it)");
  warnings.push_back(std::string("the faces were sewn into ") + (out.size() == 1 ? "a closed solid" : "closed solids") +
                     " within " + millimetres(tolerance, metresPerUnit));
  return out;
}

std::string notSolid(const TopoDS_Shape& shape) {
  return std::string("not a solid: the shape is ") + (shape.ShapeType() == TopAbs_EDGE ? "an " : "a ") +
         shapeTypeName(shape.ShapeType()) + " without any closed shell";
}

// One solid, or a compound of solids, each closed: every edge bounds two of its faces. A
// closed shell outside any solid is made one; open shells, loose faces and solids with
// holes are sewn, and refused if sewing does not close them.
TopoDS_Shape closedSolidsOf(const TopoDS_Shape& shape, double metresPerUnit, std::vector<std::string>& warnings) {
  const TopAbs_ShapeEnum type = shape.ShapeType();
  if (type == TopAbs_FACE || type == TopAbs_WIRE || type == TopAbs_EDGE || type == TopAbs_VERTEX)
    throw GeometryError(notSolid(shape));
  std::vector<TopoDS_Shape> solids;
  for (TopExp_Explorer ex(shape, TopAbs_SOLID); ex.More(); ex.Next()) {
    const UnsharedEdges open = edgesNotShared(ex.Current());
    if (open.nonManifold > 0)
      throw GeometryError("not a closed solid: " + std::to_string(open.nonManifold) +
                          " edges bound more than two faces");
    if (open.free == 0) {
      solids.push_back(ex.Current());
      continue;
    }
    const std::string what = "not a closed solid: " + std::to_string(open.free) + " free edges";
    for (const TopoDS_Shape& s : sewn(ex.Current(), what, metresPerUnit, warnings)) solids.push_back(s);
  }
  if (solids.empty()) {
    int closed = 0;
    std::vector<TopoDS_Shape> open;
    int freeEdges = 0;
    for (TopExp_Explorer ex(shape, TopAbs_SHELL, TopAbs_SOLID); ex.More(); ex.Next()) {
      const UnsharedEdges unshared = edgesNotShared(ex.Current());
      if (unshared.free == 0 && unshared.nonManifold == 0) {
        solids.push_back(BRepBuilderAPI_MakeSolid(TopoDS::Shell(ex.Current())).Solid());
        ++closed;
      } else {
        open.push_back(ex.Current());
        freeEdges += unshared.free;
      }
    }
    for (TopExp_Explorer ex(shape, TopAbs_FACE, TopAbs_SHELL); ex.More(); ex.Next()) open.push_back(ex.Current());
    if (closed > 0) warnings.push_back(closed == 1 ? "a closed shell was made into a solid"
                                                   : std::to_string(closed) + " closed shells were made into solids");
    if (!open.empty()) {
      const std::string what = freeEdges > 0 ? "not a solid: open shell with " + std::to_string(freeEdges) + " free edges"
                                             : "not a solid: faces without a closed shell";
      for (const TopoDS_Shape& s : sewn(compoundOf(open), what, metresPerUnit, warnings)) solids.push_back(s);
    }
  }
  if (solids.empty()) throw GeometryError(notSolid(shape));
  return solids.size() == 1 ? solids.front() : compoundOf(solids);
}

std::string lowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

std::string readText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (!in && !in.eof()) throw GeometryError("could not read " + path.string());
  return text;
}

TopoDS_Shape readStep(const std::filesystem::path& path) {
  // Before OCCT reads it: references in a circle or nested too deep overflow its reader's
  // stack (step_references.hpp).
  if (const std::string problem = stepReferenceProblem(readText(path)); !problem.empty())
    throw GeometryError("STEP file could not be read: " + problem + ": " + path.string());
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
  checkBrepText(text, what);
  BrepTextBuffer buffer(std::move(text));
  std::istream in(&buffer);
  // badbit: rethrow what the buffer throws. failbit: a word that is not the number the
  // reader expects ("1 (5 0") leaves the stream failed, every later read then does nothing,
  // and the reader spins through its counts forever (found by fuzz_brep); a complete text
  // never fails a read.
  in.exceptions(std::ios::badbit | std::ios::failbit);
  TopoDS_Shape shape;
  BRep_Builder builder;
  try {
    OCC_CATCH_SIGNALS  // a fault in the reader becomes a Standard_Failure (occt_faults.hpp)
    BRepTools::Read(shape, in, builder);
  } catch (const EndOfBrepText&) {
    throw GeometryError(what + " could not be read: truncated, or not BREP");
  } catch (const std::ios_base::failure&) {
    throw GeometryError(what + " could not be read: truncated, or not BREP");
  } catch (const Standard_Failure& e) {
    throw GeometryError(what + " could not be read: " + e.GetMessageString());
  }
  if (shape.IsNull()) throw GeometryError(what + " could not be read: truncated, or not BREP");
  return shape;
}

Vec3 toVec(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

bool contains(const Bnd_Box& outer, const Bnd_Box& inner) {
  const gp_Pnt a = inner.CornerMin(), b = inner.CornerMax(), lo = outer.CornerMin(), hi = outer.CornerMax();
  return a.X() >= lo.X() && a.Y() >= lo.Y() && a.Z() >= lo.Z() && b.X() <= hi.X() && b.Y() <= hi.Y() && b.Z() <= hi.Z();
}

// The volume, centre and inertia of a compound whose solids repeat (the same shape placed
// several times, as assemblies are): each distinct shape integrated once and moved.
struct Volume {
  double volume = 0;  // shape units^3
  gp_XYZ centre;
  Mat3 inertia = Mat3::Zero();  // about the centre, unit density
};

Volume integrate(const TopoDS_Shape& shape) {
  GProp_GProps props;
  BRepGProp::VolumeProperties(shape, props);
  Volume v;
  v.volume = props.Mass();
  v.centre = props.CentreOfMass().XYZ();
  const gp_Mat I = props.MatrixOfInertia();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) v.inertia(r, c) = I(r + 1, c + 1);
  return v;
}

// The solids with their faces oriented outwards, and their volume properties. Each distinct
// shape is integrated once and moved where it is placed (assemblies repeat bolts and nuts).
// An inside-out solid integrates to a negative volume and inertia: it is reversed, with a
// warning, and its properties change sign.
struct OutwardSolids {
  TopoDS_Shape shape;
  Volume volume;
};

OutwardSolids outwardSolids(const TopoDS_Shape& solids, std::vector<std::string>& warnings) {
  std::vector<std::pair<TopoDS_Shape, Volume>> distinct;  // unlocated solid, its volume
  std::vector<Volume> pieces;
  std::vector<TopoDS_Shape> oriented;
  int reversed = 0;
  for (TopExp_Explorer ex(solids, TopAbs_SOLID); ex.More(); ex.Next()) {
    TopoDS_Shape solid = ex.Current();
    const gp_Trsf trsf = solid.Location().Transformation();
    Volume piece;
    if (std::abs(trsf.ScaleFactor() - 1) > 1e-12 || trsf.IsNegative()) {
      piece = integrate(solid);
    } else {
      const TopoDS_Shape base = solid.Located(TopLoc_Location());
      auto it = std::find_if(distinct.begin(), distinct.end(), [&](const auto& d) { return d.first.IsEqual(base); });
      if (it == distinct.end()) it = distinct.insert(distinct.end(), {base, integrate(base)});
      piece = it->second;
      trsf.Transforms(piece.centre);
      Mat3 R;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) R(r, c) = trsf.Value(r + 1, c + 1);
      piece.inertia = R * piece.inertia * R.transpose();
    }
    if (piece.volume < 0) {
      solid.Reverse();
      piece.volume = -piece.volume;
      piece.inertia = -piece.inertia;
      ++reversed;
    }
    oriented.push_back(solid);
    pieces.push_back(piece);
  }
  OutwardSolids out;
  out.shape = reversed == 0 ? solids : oriented.size() == 1 ? oriented.front() : compoundOf(oriented);
  if (reversed > 0)
    warnings.push_back(oriented.size() == 1 ? "the solid was inside out and has been reversed"
                                            : std::to_string(reversed) + " of " + std::to_string(oriented.size()) +
                                                  " solids were inside out and have been reversed");
  if (pieces.size() == 1) {
    out.volume = pieces.front();
    return out;
  }
  Volume& total = out.volume;
  for (const Volume& p : pieces) {
    total.volume += p.volume;
    total.centre += p.centre * p.volume;
  }
  if (total.volume != 0) total.centre /= total.volume;
  // Parallel axes: each piece's inertia moved to the common centre.
  for (const Volume& p : pieces) {
    const Vec3 d = toVec(p.centre - total.centre);
    total.inertia += p.inertia + p.volume * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
  }
  return out;
}

// The tight bounds of a shape: BRepBndLib::AddOptimal, which is slow on curved faces (0.06 s
// of the 58-face block's fillets), only for the faces whose quick box reaches beyond what
// the others have bounded already. The result is the same box.
Bnd_Box tightBounds(const TopoDS_Shape& shape) {
  Bnd_Box box;
  std::vector<TopoDS_Shape> curved;
  for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) {
    const TopoDS_Face& face = TopoDS::Face(ex.Current());
    if (BRepAdaptor_Surface(face, false).GetType() == GeomAbs_Plane) BRepBndLib::AddOptimal(face, box, false, false);
    else curved.push_back(face);
  }
  for (const TopoDS_Shape& face : curved) {
    Bnd_Box quick;
    BRepBndLib::Add(face, quick, false);
    if (!box.IsVoid() && !quick.IsVoid() && contains(box, quick)) continue;
    BRepBndLib::AddOptimal(face, box, false, false);
  }
  return box;
}

}  // namespace

PartModelPtr PartModel::fromBrepText(std::string_view text, LengthUnit unit, std::string name,
                                     const LoadOptions& options) {
  const Clock::time_point start = Clock::now();
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos) throw GeometryError("empty BREP text");
  const TopoDS_Shape shape = readBrep(std::string(text), "BREP text");
  return load(shape, unit, std::move(name), options, secondsSince(start), start);
}

TopoDS_Shape PartModel::readFile(const std::filesystem::path& path, LengthUnit& unit) {
  if (!std::filesystem::is_regular_file(path)) throw GeometryError("no such file: " + path.string());
  if (std::filesystem::file_size(path) == 0) throw GeometryError("empty file: " + path.string());
  const std::string ext = lowerExtension(path);
  const FaultStack overflowReachesTheHandler;  // outlives the catch below
  try {
    OCC_CATCH_SIGNALS  // a fault in the STEP reader becomes a Standard_Failure (occt_faults.hpp)
    if (ext == ".step" || ext == ".stp") {
      unit = LengthUnit::Millimetre;  // OCCT's STEP reader converts every file to mm
      return readStep(path);
    }
    if (ext == ".brep" || ext == ".brp") {
      return readBrep(readText(path), "BREP file " + path.string());
    }
  } catch (const Standard_Failure& e) {
    throw GeometryError("could not read " + path.string() + ": " + e.GetMessageString());
  }
  throw GeometryError("unknown part file type '" + ext + "' (use .brep or .step): " + path.string());
}

PartModelPtr PartModel::fromFile(const std::filesystem::path& path, LengthUnit unit, const LoadOptions& options) {
  const Clock::time_point start = Clock::now();
  const TopoDS_Shape shape = readFile(path, unit);
  return load(shape, unit, path.stem().string(), options, secondsSince(start), start);
}

PartModelPtr PartModel::fromShape(const TopoDS_Shape& input, LengthUnit unit, std::string name,
                                  const LoadOptions& options) {
  return load(input, unit, std::move(name), options, 0.0, Clock::now());
}

PartModelPtr PartModel::load(const TopoDS_Shape& input, LengthUnit unit, std::string name, const LoadOptions& options,
                             double read_s, std::chrono::steady_clock::time_point start) {
  if (input.IsNull()) throw GeometryError("empty shape");
  std::shared_ptr<PartModel> part(new PartModel);
  part->name_ = std::move(name);
  part->metresPerUnit_ = metresPer(unit);
  const double s = part->metresPerUnit_;
  try {
    OCC_CATCH_SIGNALS  // damaged geometry can fault the checks and integrals too
    const Clock::time_point checkStart = Clock::now();
    // Before any OCCT algorithm meets it: one that would not end (curve_on_face.hpp).
    if (const std::string damage = damagedGeometry(input); !damage.empty())
      throw GeometryError("the part's geometry is damaged: " + damage);
    OutwardSolids outward = outwardSolids(closedSolidsOf(input, s, part->warnings_), part->warnings_);
    PartCheck check = checkPart(outward.shape, options, s);
    if (!check.solids.IsSame(outward.shape)) outward = outwardSolids(check.solids, part->warnings_);  // healed
    part->warnings_.insert(part->warnings_.end(), check.warnings.begin(), check.warnings.end());
    part->backendChoice_ = std::move(check.choice);
    part->timing_.check_s = secondsSince(checkStart);

    const TopoDS_Shape& solids = outward.shape;
    const Volume& v = outward.volume;
    const Bnd_Box box = tightBounds(solids);
    const double diagonal = std::sqrt(box.SquareExtent());
    if (!(v.volume > 1e-12 * diagonal * diagonal * diagonal)) throw GeometryError("solid has no volume");

    part->setShape(solids);
    double x0, y0, z0, x1, y1, z1;
    box.Get(x0, y0, z0, x1, y1, z1);
    part->bounds_ = {Vec3(x0, y0, z0) * s, Vec3(x1, y1, z1) * s};
    part->volume_m3_ = v.volume * s * s * s;
    part->centre_m_ = toVec(v.centre) * s;
    part->unitDensityInertia_ = v.inertia * std::pow(s, 5);  // about the centre of mass, density 1
    part->primitive_ = recognisePrimitive(solids, s, part->volume_m3_);
  } catch (const Standard_Failure& e) {
    throw GeometryError(std::string("OpenCASCADE failed on the shape: ") + e.GetMessageString());
  }
  part->timing_.read_s = read_s;
  part->timing_.total_s = secondsSince(start);
  return part;
}

// The checked shape and its topology maps (a penetration's featureIndex refers to these).
void PartModel::setShape(const TopoDS_Shape& solids) {
  shape_ = solids;
  TopExp::MapShapes(solids, TopAbs_FACE, faces_);
  TopExp::MapShapes(solids, TopAbs_EDGE, edges_);
  TopExp::MapShapes(solids, TopAbs_VERTEX, vertices_);
}

PartModel::Record PartModel::record() const {
  return {metresPerUnit_, bounds_, volume_m3_, centre_m_, unitDensityInertia_, warnings_, backendChoice_};
}

PartModelPtr PartModel::restore(const TopoDS_Shape& shape, const Record& r, std::string name,
                                 const PartLoadTiming* timing) {
  const Clock::time_point start = Clock::now();
  if (shape.IsNull()) throw GeometryError("empty shape");
  std::shared_ptr<PartModel> part(new PartModel);
  part->name_ = std::move(name);
  part->metresPerUnit_ = r.metresPerUnit;
  try {
    part->setShape(shape);
    part->primitive_ = recognisePrimitive(shape, r.metresPerUnit, r.volume_m3);
  } catch (const Standard_Failure& e) {
    throw GeometryError(std::string("OpenCASCADE failed on the shape: ") + e.GetMessageString());
  }
  part->bounds_ = r.bounds;
  part->volume_m3_ = r.volume_m3;
  part->centre_m_ = r.centre_m;
  part->unitDensityInertia_ = r.unitDensityInertia;
  part->warnings_ = r.warnings;
  part->backendChoice_ = r.choice;
  if (timing) part->timing_ = *timing;
  part->timing_.total_s += secondsSince(start);
  return part;
}

MassProperties PartModel::massProperties(const MassSpec& spec) const {
  if (!(spec.value > 0)) throw GeometryError("mass and density must be positive");
  const double density = spec.kind == MassSpec::Kind::Density ? spec.value : spec.value / volume_m3_;
  return {volume_m3_, density * volume_m3_, centre_m_, density * unitDensityInertia_};
}

}  // namespace hg::geometry
