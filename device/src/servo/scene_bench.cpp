#include "hapticgrasp/servo/scene_bench.hpp"

#include <BRepBndLib.hxx>
#include <BRepTools.hxx>
#include <Bnd_Box.hxx>
#include <IntCurvesFace_ShapeIntersector.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <gp_Lin.hxx>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <string>

#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/geometry/loader_process.hpp"
#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/geometry/sample_parts.hpp"
#include "hapticgrasp/geometry/units.hpp"
#include "hapticgrasp/grasp/hand_script.hpp"
#include "hapticgrasp/install_layout.hpp"
#include "hapticgrasp/scene/scene_build.hpp"
#include "hapticgrasp/servo/grasp_engine.hpp"
#include "hapticgrasp/servo/scripted_hand_device.hpp"

namespace hg::servo {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Anonymous resident memory (the heap: models, scene), not the libraries the real-time
// thread's mlockall makes resident.
long residentBytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("RssAnon:", 0) == 0) return 1024 * std::stol(line.substr(8));
  return 0;
}

// One solid of the file: its shape without location, where it stands, its box.
struct Solid {
  TopoDS_Shape shape;   // unlocated
  grasp::PartPose pose; // metres
  geometry::Aabb box;   // object frame, metres
  std::string key;      // the TShape: instances of one product share it
};

grasp::PartPose poseOf(const TopLoc_Location& location, double metresPerUnit) {
  const gp_Trsf t = location.Transformation();
  grasp::PartPose pose;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) pose.rotation(r, c) = t.Value(r + 1, c + 1);
  pose.position = metresPerUnit * Vec3(t.TranslationPart().X(), t.TranslationPart().Y(), t.TranslationPart().Z());
  return pose;
}

std::vector<Solid> solidsOf(const TopoDS_Shape& shape, double metresPerUnit) {
  std::vector<Solid> solids;
  for (TopExp_Explorer e(shape, TopAbs_SOLID); e.More(); e.Next()) {
    Solid s;
    s.shape = e.Current().Located(TopLoc_Location());
    s.pose = poseOf(e.Current().Location(), metresPerUnit);
    Bnd_Box box;
    BRepBndLib::Add(s.shape, box, false);  // straight from the shape: control points, no meshing
    if (box.IsVoid()) continue;
    double x0, y0, z0, x1, y1, z1;
    box.Get(x0, y0, z0, x1, y1, z1);
    s.box = {metresPerUnit * Vec3(x0, y0, z0), metresPerUnit * Vec3(x1, y1, z1)};
    char key[32];
    std::snprintf(key, sizeof key, "%p", static_cast<const void*>(s.shape.TShape().get()));
    s.key = key;
    solids.push_back(std::move(s));
  }
  if (solids.empty()) throw geometry::GeometryError("no solid in the file");
  return solids;
}

// The top of the solid above its box centre (object frame, metres): where the finger comes
// down. A ray straight down through the centre, or through points around it.
Vec3 topPoint(const Solid& s, double metresPerUnit) {
  IntCurvesFace_ShapeIntersector hit;
  hit.Load(s.shape, 1e-7);
  const Vec3 c = s.box.centre() / metresPerUnit, size = s.box.size() / metresPerUnit;
  for (const double f : {0.0, 0.15, -0.15, 0.3, -0.3}) {
    for (const double g : {0.0, 0.15, -0.15, 0.3, -0.3}) {
      const gp_Pnt from(c.x() + f * size.x(), c.y() + g * size.y(), c.z() + size.z());
      hit.Perform(gp_Lin(from, gp_Dir(0, 0, -1)), 0, 1e9);
      if (!hit.IsDone() || hit.NbPnt() == 0) continue;
      int first = 1;
      for (int i = 2; i <= hit.NbPnt(); ++i)
        if (hit.WParameter(i) < hit.WParameter(first)) first = i;
      const gp_Pnt p = hit.Pnt(first);
      return metresPerUnit * Vec3(p.X(), p.Y(), p.Z());
    }
  }
  return metresPerUnit * Vec3(c.x(), c.y(), c.z() + 0.5 * size.z());
}

// The index fingertip comes down onto `top` (world) from 30 mm above and presses 1 mm in;
// the thumb and wrist stay well above everything it could touch.
grasp::HandScript touchScript(const Vec3& top) {
  std::vector<grasp::HandKey> keys;
  const auto key = [&](double t, double above) {
    grasp::HandKey k;
    k.t = t;
    k.index = top + Vec3(0, 0, above);
    k.thumb = top + Vec3(0, 0, above + 0.3);
    k.wrist = top + Vec3(0, 0, above + 0.4);
    keys.push_back(k);
  };
  key(0.0, 0.03);
  key(0.3, 0.03);
  key(0.6, -0.001);
  key(3600.0, -0.001);
  return grasp::HandScript(std::move(keys));
}

// A model's load, the way `how` asks (SceneBenchOptions::load); on a worker.
geometry::PartModelPtr loadSolid(const TopoDS_Shape& solid, geometry::LengthUnit unit, const std::string& name,
                                 const std::string& how, geometry::LoaderProcess* loader) {
  geometry::PartModel::LoadOptions options;
  options.parallel = false;  // the worker keeps to its one thread
  if (how == "shape") return geometry::PartModel::fromShape(solid, unit, name, options);
  std::ostringstream text;  // as FreeCAD's exportBrepToString writes it
  BRepTools::Write(solid, text);
  if (loader) return loader->load(text.str(), unit, name, options);
  return geometry::PartModel::fromBrepText(text.str(), unit, name, options);
}

}  // namespace

SceneBenchResult runSceneBench(const SceneBenchOptions& o) {
  if (o.copies < 1 || o.copies > 100000) throw std::invalid_argument("--copies must be in [1, 100000]");
  if (o.load != "shape" && o.load != "text" && o.load != "loader")
    throw std::invalid_argument("--load must be shape, text or loader");
  if (!(o.seconds > 0 && o.seconds <= 3600)) throw std::invalid_argument("--seconds must be in (0, 3600]");
  SceneBenchResult r;
  const long rss0 = residentBytes();
  Clock::time_point t0 = Clock::now();
  const geometry::SamplePart sample = geometry::findPart(o.part);
  geometry::LengthUnit unit = sample.unit;
  const TopoDS_Shape shape = geometry::PartModel::readFile(sample.file, unit);
  const double metresPerUnit = geometry::metresPer(unit);
  const std::vector<Solid> solids = solidsOf(shape, metresPerUnit);
  r.read_s = since(t0);

  // --- The call: Start.
  t0 = Clock::now();
  geometry::Aabb assembly;
  for (const Solid& s : solids) {
    const geometry::Aabb w = s.pose.absoluteBounds(s.box);
    assembly.extend(w.min);
    assembly.extend(w.max);
  }
  const double pitch = 1.2 * assembly.size().x() + 0.01;
  std::shared_ptr<geometry::LoaderProcess> loader;
  if (o.load == "loader")
    loader = std::make_shared<geometry::LoaderProcess>(geometry::LoaderProcess::Options{{loaderProgram().string()}});
  std::vector<grasp::PartSource> sources;
  sources.reserve(solids.size() * static_cast<std::size_t>(o.copies));
  std::size_t target = 0;
  for (std::size_t i = 1; i < solids.size(); ++i)
    if (solids[i].box.size().prod() > solids[target].box.size().prod()) target = i;
  for (int c = 0; c < o.copies; ++c) {
    for (std::size_t i = 0; i < solids.size(); ++i) {
      grasp::PartSource p;
      p.name = "solid " + std::to_string(i + 1) + " copy " + std::to_string(c + 1);
      p.key = o.share ? solids[i].key : solids[i].key + " copy " + std::to_string(c);
      p.bounds = solids[i].box;
      p.pose = solids[i].pose;
      p.pose.position.x() += c * pitch;
      p.mass = geometry::MassSpec::density(7850);
      const TopoDS_Shape solid = solids[i].shape;
      const std::string name = p.name;
      p.load = [solid, unit, name, how = o.load, loader] { return loadSolid(solid, unit, name, how, loader.get()); };
      sources.push_back(std::move(p));
    }
  }
  const Vec3 top = solids[target].pose.pointToAbsolute(topPoint(solids[target], metresPerUnit));
  grasp::SceneBuild::Options buildOptions;
  buildOptions.workers = o.workers;
  const int cpu = o.realtime && o.pin ? servoCpu() : -1;  // a real-time servo keeps a CPU to itself
  buildOptions.avoidCpu = cpu;
  grasp::SceneBuild build(std::move(sources), buildOptions);
  build.setFocus(top);
  auto device = std::make_shared<ScriptedHandDevice>(touchScript(top));
  ServoConfig config;
  config.rate_hz = o.rate_hz;
  config.realtime = o.realtime;
  config.allocationCounter = o.allocationCounter;
  config.cpu = cpu;
  ServoLoop loop(device, std::make_unique<TwoFingerEngine>(build.scene()), config);
  loop.start();
  r.start_s = since(t0);
  r.parts = build.scene()->size();
  r.target = "solid " + std::to_string(target + 1) + " copy 1";

  // --- Watch: the hand's point steers the build; the first force from the target's model.
  ServoSnapshot snap;
  const grasp::Scene& scene = *build.scene();
  while (since(t0) < 3600) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    const bool exact = !scene.part(target).coarse;  // published before the snapshot below was read
    if (!loop.read(snap)) continue;
    build.setFocus(snap.hand.index);
    if (r.first_touch_s < 0 && exact && snap.sent.f_index.norm() > 0) r.first_touch_s = since(t0);
    const grasp::SceneBuild::Progress p = build.progress();
    if (r.all_built_s < 0 && p.finished) r.all_built_s = since(t0);
    if (r.all_built_s >= 0 && r.first_touch_s >= 0 && snap.time_s >= o.seconds) break;
    if (p.finished && snap.time_s >= o.seconds + 5) break;  // the target never touched: say so (-1)
  }
  loop.stop();
  const TimingSummary t = loop.timing();
  r.compute = t.compute;
  r.periodError = t.periodError;
  r.achieved_hz = t.achieved_hz;
  if (loop.read(snap)) r.allocations_in_loop = snap.allocations;
  r.scheduler = loop.scheduler() + ", " + loop.affinity();
  const grasp::SceneBuild::Progress p = build.progress();
  r.uniqueModels = p.models;
  r.failedModels = p.failed;
  r.memory_bytes = residentBytes() - rss0;
  r.load = o.load;
  r.loaderProcesses = loader ? loader->started() : 0;
  return r;
}

std::string toJson(const SceneBenchResult& r, int indent) {
  const auto summary = [](const DurationSummary& d) {
    return nlohmann::json{{"p50", d.p50_us}, {"p99", d.p99_us}, {"max", d.max_us}};
  };
  nlohmann::json j{{"parts", r.parts},
                   {"unique_models", r.uniqueModels},
                   {"failed_models", r.failedModels},
                   {"read_s", r.read_s},
                   {"start_s", r.start_s},
                   {"first_touch_s", r.first_touch_s},
                   {"all_built_s", r.all_built_s},
                   {"memory_bytes", r.memory_bytes},
                   {"compute_us", summary(r.compute)},
                   {"period_err_us", summary(r.periodError)},
                   {"achieved_hz", r.achieved_hz},
                   {"allocations_in_loop", r.allocations_in_loop},
                   {"scheduler", r.scheduler},
                   {"target", r.target},
                   {"load", r.load},
                   {"loader_processes", r.loaderProcesses}};
  return j.dump(indent);
}

}  // namespace hg::servo
