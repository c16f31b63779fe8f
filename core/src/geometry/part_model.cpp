#include "hapticgrasp/geometry/part_model.hpp"

#include <BOPAlgo_ArgumentAnalyzer.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_MakeSolid.hxx>
#include <BRepCheck.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepCheck_ListOfStatus.hxx>
#include <BRepCheck_Result.hxx>
#include <BRepGProp.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>

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

// The first thing BRepCheck_Analyzer objects to, in words.
std::string firstCheckProblem(const BRepCheck_Analyzer& analyzer, const TopoDS_Shape& shape) {
  for (TopAbs_ShapeEnum type : {TopAbs_VERTEX, TopAbs_EDGE, TopAbs_WIRE, TopAbs_FACE, TopAbs_SHELL, TopAbs_SOLID}) {
    int n = 0;
    for (TopExp_Explorer ex(shape, type); ex.More(); ex.Next(), ++n) {
      const Handle(BRepCheck_Result)& result = analyzer.Result(ex.Current());
      if (result.IsNull()) continue;
      for (const BRepCheck_Status status : result->Status()) {
        if (status == BRepCheck_NoError) continue;
        std::ostringstream out;
        BRepCheck::Print(status, out);
        std::string text = out.str();
        text.erase(std::remove(text.begin(), text.end(), '\n'), text.end());
        return std::string(shapeTypeName(type)) + " " + std::to_string(n + 1) + ": " + text;
      }
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
    throw GeometryError(std::string("not a solid: the shape is a ") + shapeTypeName(shape.ShapeType()) +
                        " without any closed shell");
  if (count == 1) {
    TopExp_Explorer ex(solids, TopAbs_SOLID);
    return ex.Current();
  }
  return solids;
}

void validate(const TopoDS_Shape& solids) {
  const int free = countFreeEdges(solids);
  if (free > 0) throw GeometryError("not a closed solid: " + std::to_string(free) + " free edges");
  BRepCheck_Analyzer analyzer(solids);
  if (!analyzer.IsValid()) throw GeometryError("invalid B-rep: " + firstCheckProblem(analyzer, solids));
  BOPAlgo_ArgumentAnalyzer self;
  self.SetShape1(solids);
  self.ArgumentTypeMode() = false;
  self.SelfInterMode() = true;
  self.SmallEdgeMode() = false;
  self.Perform();
  if (self.HasFaulty()) throw GeometryError("self-intersecting shape: faces or solids intersect each other");
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

TopoDS_Shape readBrep(std::istream& in, const std::string& what) {
  TopoDS_Shape shape;
  BRep_Builder builder;
  BRepTools::Read(shape, in, builder);
  if (shape.IsNull()) throw GeometryError(what + " could not be read: not BREP, or truncated");
  return shape;
}

Vec3 toVec(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

}  // namespace

PartModelPtr PartModel::fromBrepText(std::string_view text, LengthUnit unit, std::string name) {
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos) throw GeometryError("empty BREP text");
  std::istringstream in{std::string(text)};
  TopoDS_Shape shape;
  try {
    shape = readBrep(in, "BREP text");
  } catch (const Standard_Failure& e) {
    throw GeometryError(std::string("BREP text could not be read: ") + e.GetMessageString());
  }
  return fromShape(shape, unit, std::move(name));
}

PartModelPtr PartModel::fromFile(const std::filesystem::path& path, LengthUnit unit) {
  if (!std::filesystem::is_regular_file(path)) throw GeometryError("no such file: " + path.string());
  if (std::filesystem::file_size(path) == 0) throw GeometryError("empty file: " + path.string());
  const std::string ext = lowerExtension(path);
  TopoDS_Shape shape;
  try {
    if (ext == ".step" || ext == ".stp") {
      shape = readStep(path);
      unit = LengthUnit::Millimetre;  // OCCT's STEP reader converts every file to mm
    } else if (ext == ".brep" || ext == ".brp") {
      std::ifstream in(path);
      shape = readBrep(in, "BREP file " + path.string());
    } else {
      throw GeometryError("unknown part file type '" + ext + "' (use .brep or .step): " + path.string());
    }
  } catch (const Standard_Failure& e) {
    throw GeometryError("could not read " + path.string() + ": " + e.GetMessageString());
  }
  return fromShape(shape, unit, path.stem().string());
}

PartModelPtr PartModel::fromShape(const TopoDS_Shape& input, LengthUnit unit, std::string name) {
  if (input.IsNull()) throw GeometryError("empty shape");
  std::shared_ptr<PartModel> part(new PartModel);
  part->name_ = std::move(name);
  part->metresPerUnit_ = metresPer(unit);
  const double s = part->metresPerUnit_;
  try {
    TopoDS_Shape solids = solidsOf(input, part->warnings_);
    validate(solids);
    GProp_GProps props;
    BRepGProp::VolumeProperties(solids, props);
    if (props.Mass() < 0) {  // faces oriented inwards: the solid is inside out
      solids.Reverse();
      part->warnings_.push_back("the solid was inside out and has been reversed");
      props = GProp_GProps();
      BRepGProp::VolumeProperties(solids, props);
    }
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
