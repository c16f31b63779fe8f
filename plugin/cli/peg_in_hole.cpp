#include "peg_in_hole.hpp"

#include <time.h>

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCone.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <gp_Ax2.hxx>
#include <iostream>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "device_commands.hpp"
#include "hapticgrasp/contact/virtual_coupling.hpp"
#include "hapticgrasp/geometry/backends.hpp"

namespace hg::cli {
namespace {

using contact::ContactBody;
using contact::ContactModel;
using contact::ContactModelPtr;
using contact::ContactScene;
using contact::CouplingOutput;
using contact::VirtualCoupling;
using geometry::LengthUnit;
using geometry::PartModel;

constexpr double kPegDiameter_mm = 10, kPegLength_mm = 40, kClearance_mm = 0.1, kChamfer_mm = 0.5;
constexpr double kWall_mm = 0.5, kStrikeSpeed_m_s = 1.0;

ContactModelPtr modelOf(const TopoDS_Shape& shape, const char* name, int points) {
  const auto part = PartModel::fromShape(shape, LengthUnit::Millimetre, name);
  contact::ContactModelOptions options;
  options.maxPoints = points;
  return ContactModel::build(part, geometry::makePenetration(part), options);
}

// Its bottom face at z = 0, axis z.
ContactModelPtr peg() {
  return modelOf(
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), kPegDiameter_mm / 2, kPegLength_mm).Shape(),
      "peg", 600);
}

// 40 x 40 x 20 mm, top face at z = 0, a through hole on z with a 45 deg chamfer.
ContactModelPtr holeBlock() {
  const double r = (kPegDiameter_mm + kClearance_mm) / 2;
  TopoDS_Shape block = BRepPrimAPI_MakeBox(gp_Pnt(-20, -20, -20), 40, 40, 20).Shape();
  block = BRepAlgoAPI_Cut(block, BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -25), gp_Dir(0, 0, 1)), r, 30).Shape())
              .Shape();
  block = BRepAlgoAPI_Cut(block, BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(0, 0, -kChamfer_mm), gp_Dir(0, 0, 1)), r,
                                                      r + 2 * kChamfer_mm, 2 * kChamfer_mm)
                                     .Shape())
              .Shape();
  return modelOf(block, "hole block", 1024);
}

// 60 x 60 mm, top face at z = 0.
ContactModelPtr plate() {
  return modelOf(BRepPrimAPI_MakeBox(gp_Pnt(-30, -30, -kWall_mm), 60, 60, kWall_mm).Shape(), "plate", 1024);
}

grasp::PartPose poseAt(const Vec3& position, double angle = 0, const Vec3& axis = Vec3::UnitX()) {
  grasp::PartPose p;
  p.rotation = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  p.position = position;
  return p;
}

// This thread's CPU time, us: what a tick costs, without the time the scheduler gave other
// processes meanwhile (this machine runs builds beside the benchmarks).
double threadCpu_us() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e6 * t.tv_sec + 1e-3 * t.tv_nsec;
}

// Steps the coupling at `rate_hz` for `seconds` with the hand at hand(t), timing each
// tick into `times_us`; `each` sees every tick's output.
void drive(VirtualCoupling& coupling, const ContactScene& scene, double rate_hz, double seconds,
           const std::function<grasp::PartPose(double)>& hand, std::vector<double>& times_us,
           std::vector<double>& cpu_us, long& queries, long& allocations,
           const std::function<void(const CouplingOutput&)>& each) {
  const double dt = 1 / rate_hz;
  coupling.reset(hand(0));
  const int ticks = static_cast<int>(std::lround(seconds * rate_hz));
  long before = threadAllocations();
  for (int k = 1; k <= ticks; ++k) {
    if (k == 2) before = threadAllocations();  // the first tick may size OCCT's own caches
    const grasp::PartPose h = hand(k * dt);
    const auto start = std::chrono::steady_clock::now();
    const double cpuStart = threadCpu_us();
    const CouplingOutput& out = coupling.step(h, dt, scene, -1);
    cpu_us.push_back(threadCpu_us() - cpuStart);
    times_us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count());
    queries += out.queried;
    each(out);
  }
  allocations += threadAllocations() - before;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

}  // namespace

PegInHoleResult runPegInHole(double rate_hz) {
  if (!(rate_hz > 0)) throw std::invalid_argument("peg-in-hole: the rate must be positive");
  PegInHoleResult r;
  r.rate_hz = rate_hz;
  const ContactModelPtr pegModel = peg();
  r.shell_points = static_cast<int>(pegModel->shell().size());
  std::vector<double> times, cpu;
  times.reserve(static_cast<std::size_t>(3 * rate_hz));
  cpu.reserve(times.capacity());
  long queries = 0, allocations = 0;

  // Insertion: 0.3 mm off the axis (onto the chamfer), tilted 0.1 deg, down at 20 mm/s
  // from 3 mm above the block to 15 mm into it, then held for 0.2 s.
  {
    const ContactScene scene({ContactBody{holeBlock(), grasp::PartPose{}}});
    VirtualCoupling coupling(pegModel);
    auto& in = r.insertion;
    in.clearance_m = kClearance_mm * 1e-3;
    in.min_clearance_m = std::numeric_limits<double>::infinity();
    const auto hand = [](double t) {
      return poseAt(Vec3(3e-4, 0, std::max(3e-3 - 0.02 * t, -15e-3)), 0.1 * std::numbers::pi / 180);
    };
    drive(coupling, scene, rate_hz, 1.1, hand, times, cpu, queries, allocations, [&](const CouplingOutput& out) {
      in.max_penetration_m = std::max(in.max_penetration_m, out.penetration_m);
      in.max_force_N = std::max(in.max_force_N, out.force_N.norm());
      if (out.pose.position.z() < -2e-3 && out.clearance.exact)
        in.min_clearance_m = std::min(in.min_clearance_m, out.clearance.distance_m);
    });
    const grasp::PartPose& end = coupling.output().pose;
    in.depth_m = -end.position.z();
    in.inserted = in.depth_m > 14.5e-3 && std::hypot(end.position.x(), end.position.y()) < in.clearance_m;
  }

  // Strike: flat end first at 1 m/s from 10 mm above the plate, the hand going on to 20 mm
  // beyond its top face (through where the plate is), then held.
  {
    const ContactScene scene({ContactBody{plate(), grasp::PartPose{}}});
    VirtualCoupling coupling(pegModel);
    auto& s = r.strike;
    s.speed_m_s = kStrikeSpeed_m_s;
    s.wall_m = kWall_mm * 1e-3;
    const auto hand = [](double t) { return poseAt(Vec3(0, 0, std::max(10e-3 - kStrikeSpeed_m_s * t, -20e-3))); };
    drive(coupling, scene, rate_hz, 0.1, hand, times, cpu, queries, allocations, [&](const CouplingOutput& out) {
      s.max_penetration_m = std::max(s.max_penetration_m, out.penetration_m);
      s.max_force_N = std::max(s.max_force_N, out.force_N.norm());
      if (out.pose.position.z() < -s.wall_m) s.tunnelled = true;  // its end face past the far side
    });
  }
  r.p50_us = percentile(times, 0.5);
  r.p99_us = percentile(times, 0.99);
  r.max_us = times.empty() ? 0 : *std::max_element(times.begin(), times.end());
  r.allocations = allocations;
  r.cpu_p50_us = percentile(cpu, 0.5);
  r.cpu_p99_us = percentile(cpu, 0.99);
  r.mean_queries = times.empty() ? 0 : static_cast<double>(queries) / times.size();
  return r;
}

nlohmann::json toJson(const PegInHoleResult& r) {
  const auto& i = r.insertion;
  const auto& s = r.strike;
  return {{"insertion",
           {{"inserted", i.inserted},
            {"clearance_m", i.clearance_m},
            {"max_penetration_m", i.max_penetration_m},
            {"max_force_N", i.max_force_N},
            {"depth_m", i.depth_m},
            {"min_clearance_m", i.min_clearance_m}}},
          {"strike",
           {{"speed_m_s", s.speed_m_s},
            {"wall_m", s.wall_m},
            {"tunnelled", s.tunnelled},
            {"max_penetration_m", s.max_penetration_m},
            {"max_force_N", s.max_force_N}}},
          {"compute_us", {{"p50", r.p50_us}, {"p99", r.p99_us}, {"max", r.max_us}}},
          {"cpu_us", {{"p50", r.cpu_p50_us}, {"p99", r.cpu_p99_us}}},
          {"rate_hz", r.rate_hz},
          {"allocations_in_loop", r.allocations},
          {"mean_queries", r.mean_queries},
          {"shell_points", r.shell_points}};
}

int pegInHole(double rate_hz, bool json) {
  const PegInHoleResult r = runPegInHole(rate_hz);
  if (json) {
    std::cout << toJson(r).dump(2) << std::endl;
    return 0;
  }
  const auto& i = r.insertion;
  const auto& s = r.strike;
  std::printf("peg-in-hole: peg %.0f x %.0f mm (%d shell points), hole +%.2f mm, chamfer %.1f mm, at %.0f Hz\n",
              kPegDiameter_mm, kPegLength_mm, r.shell_points, kClearance_mm, kChamfer_mm, r.rate_hz);
  std::printf("  insertion: %s, %.2f mm deep; max penetration %.4f mm; max force %.2f N; min clearance %.4f mm\n",
              i.inserted ? "inserted" : "NOT inserted", 1e3 * i.depth_m, 1e3 * i.max_penetration_m, i.max_force_N,
              1e3 * i.min_clearance_m);
  std::printf("  strike at %.1f m/s on a %.1f mm plate: %s; max penetration %.4f mm; max force %.1f N\n", s.speed_m_s,
              1e3 * s.wall_m, s.tunnelled ? "TUNNELLED" : "held", 1e3 * s.max_penetration_m, s.max_force_N);
  std::printf("  %ld allocations in the loop\n", r.allocations);
  std::printf(
      "  compute per tick: p50 %.1f us, p99 %.1f us, max %.1f us (its CPU time: p50 %.1f us, p99 %.1f us); "
      "%.1f exact queries a tick\n",
      r.p50_us, r.p99_us, r.max_us, r.cpu_p50_us, r.cpu_p99_us, r.mean_queries);
  return i.inserted && !s.tunnelled ? 0 : 1;
}

int benchContact(const ContactBenchOptions& options, bool json) {
  geometry::LengthUnit unit = LengthUnit::Millimetre;
  const auto part = PartModel::fromShape(PartModel::readFile(options.part, unit), unit, options.part);
  const auto penetration = geometry::makePenetration(part);
  contact::ContactModelOptions heldOptions;
  heldOptions.maxPoints = options.points;
  const auto built = std::chrono::steady_clock::now();
  const ContactModelPtr held = ContactModel::build(part, penetration, heldOptions);
  const ContactModelPtr other = ContactModel::build(part, penetration, {});
  const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - built).count();
  const geometry::Aabb b = part->bounds();
  const Vec3 size = b.size();
  // One copy under the carried one's start, one beside it 2 mm away in x.
  const ContactScene scene(
      {ContactBody{other, grasp::PartPose{}}, ContactBody{other, poseAt(Vec3(size.x() + 2e-3, 0, size.z()))}});
  VirtualCoupling coupling(held);
  // Lowered from 1 mm above onto the lower copy and 1 mm into it, slid 4 mm in x (into the
  // side copy) at 20 mm/s, twisted +-0.5 deg about z at 1 Hz.
  const auto hand = [&](double t) {
    const double z = size.z() + 1e-3 - std::min(t / 0.5, 1.0) * 2e-3;
    const double x = std::min(std::max(t - 0.5, 0.0) * 0.02, 4e-3);
    grasp::PartPose p =
        poseAt(Vec3(x, 0, z), 0.5 * std::numbers::pi / 180 * std::sin(2 * std::numbers::pi * t), Vec3::UnitZ());
    p.position += b.centre() - p.rotation * b.centre();  // turned about the part's centre
    return p;
  };
  std::vector<double> times, cpu;
  times.reserve(static_cast<std::size_t>(options.seconds * options.rate_hz) + 1);
  cpu.reserve(times.capacity());
  long queries = 0, allocations = 0;
  double penetration_m = 0, force_N = 0;
  int contacts = 0;
  drive(coupling, scene, options.rate_hz, options.seconds, hand, times, cpu, queries, allocations,
        [&](const CouplingOutput& out) {
          penetration_m = std::max(penetration_m, out.penetration_m);
          force_N = std::max(force_N, out.force_N.norm());
          contacts = std::max(contacts, out.contacts);
        });
  const nlohmann::json result = {{"part", options.part},
                                 {"faces", part->faces().Extent()},
                                 {"shell_points", held->shell().size()},
                                 {"sharp_edge_points", other->sharpEdges().size()},
                                 {"models_built_s", build_s},
                                 {"rate_hz", options.rate_hz},
                                 {"ticks", times.size()},
                                 {"compute_us",
                                  {{"p50", percentile(times, 0.5)},
                                   {"p99", percentile(times, 0.99)},
                                   {"max", times.empty() ? 0.0 : *std::max_element(times.begin(), times.end())}}},
                                 {"cpu_us", {{"p50", percentile(cpu, 0.5)}, {"p99", percentile(cpu, 0.99)}}},
                                 {"mean_queries", times.empty() ? 0.0 : static_cast<double>(queries) / times.size()},
                                 {"max_contacts", contacts},
                                 {"allocations_in_loop", allocations},
                                 {"max_penetration_m", penetration_m},
                                 {"max_force_N", force_N}};
  if (json) {
    std::cout << result.dump(2) << std::endl;
    return 0;
  }
  std::printf("contact bench: %s (%d faces), shell %zu points, its copies' sharp edges %zu points, built in %.2f s\n",
              options.part.c_str(), part->faces().Extent(), held->shell().size(), other->sharpEdges().size(), build_s);
  std::printf(
      "  %zu ticks at %.0f Hz: compute p50 %.1f us, p99 %.1f us, max %.1f us (CPU time p50 %.1f us, p99 %.1f us); "
      "%.1f exact queries a tick\n",
      times.size(), options.rate_hz, result["compute_us"]["p50"].get<double>(),
      result["compute_us"]["p99"].get<double>(), result["compute_us"]["max"].get<double>(),
      result["cpu_us"]["p50"].get<double>(), result["cpu_us"]["p99"].get<double>(),
      result["mean_queries"].get<double>());
  std::printf("  up to %d contacts, max penetration %.4f mm, max force %.1f N\n", contacts, 1e3 * penetration_m,
              force_N);
  return 0;
}

}  // namespace hg::cli
