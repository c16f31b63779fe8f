#include "hapticgrasp/servo/servo_bench.hpp"

#include <BRepPrimAPI_MakeCylinder.hxx>
#include <gp_Ax2.hxx>

#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "hapticgrasp/grasp/hand_script.hpp"
#include "hapticgrasp/servo/scripted_hand_device.hpp"

namespace hg::servo {
namespace {

constexpr double kCycle_s = 2.0;
constexpr double kRadius = 0.05;        // the paper's cylinder: 0.1 m x 0.4 m, 2 kg
constexpr double kMass = 2.0;
constexpr double kPenetration = 0.5e-3; // fingertip depth while touching (< d_h/2)
constexpr double kSqueeze = 0.5e-3;
constexpr double kClearance = 0.02;
constexpr double kWristHeight = 0.1;
constexpr double kLift = 0.05;

grasp::PartPose cylinderPose() {
  grasp::PartPose pose;
  pose.rotation = Eigen::AngleAxisd(-std::numbers::pi / 2, Vec3::UnitX()).toRotationMatrix();  // axis along y
  pose.position = Vec3(0.4, 0.0, 0.3);
  return pose;
}

}  // namespace

grasp::ScenePtr benchScene() {
  const gp_Ax2 axis(gp_Pnt(0, 0, -200), gp_Dir(0, 0, 1));
  const auto model = geometry::PartModel::fromShape(BRepPrimAPI_MakeCylinder(axis, 1000 * kRadius, 400).Shape(),
                                                    geometry::LengthUnit::Millimetre, "cylinder");
  return std::make_shared<const grasp::Scene>(
      std::vector<grasp::ScenePart>{grasp::makeScenePart(model, geometry::MassSpec::mass(kMass), cylinderPose())});
}

grasp::HandScript benchScript() {
  const double open = kRadius + kClearance, in = kRadius - kPenetration, squeezed = in - kSqueeze;
  // The springs carry the weight after M g / K_ox; lowering the hand to that height puts
  // the part back where it was (default grasp parameters).
  const grasp::GraspParameters k;
  const double sag = kMass * k.gravity.norm() / k.K_ox;
  std::vector<grasp::HandKey> keys;
  const auto key = [&](double t, double index, double thumb, double z) {
    keys.push_back({t, {index, 0, 0}, {-thumb, 0, 0}, {0, 0, kWristHeight}, Vec3(0, 0, z), 0});
  };
  key(0.0, open, open, 0);
  key(0.1, open, open, 0);
  key(0.3, in, open, 0);               // index contact
  key(0.5, in, in, 0);                 // thumb contact: grasp
  key(0.6, squeezed, squeezed, 0);
  key(1.0, squeezed, squeezed, kLift); // lift: manipulate
  key(1.2, squeezed, squeezed, kLift);
  key(1.5, squeezed, squeezed, sag);   // put down where it was
  key(1.7, open, open, sag);           // release
  key(1.8, open, open, 0);
  key(kCycle_s, open, open, 0);
  return grasp::HandScript(std::move(keys), grasp::PartPose{Mat3::Identity(), cylinderPose().position});
}

ServoBenchResult runServoBench(double rate_hz, double seconds, bool realtime, AllocationCounter allocationCounter) {
  if (!(seconds > 0 && seconds <= 3600)) throw std::invalid_argument("bench seconds must be in (0, 3600]");
  ServoConfig config;
  config.rate_hz = rate_hz;
  config.realtime = realtime;
  config.allocationCounter = allocationCounter;
  config.validate();

  device::DeviceSpec spec = ScriptedHandDevice::defaultSpec();
  spec.maxForce_N = 40;
  spec.maxTorque_Nm = 5;
  auto device = std::make_shared<ScriptedHandDevice>(benchScript(), spec, /*loop=*/true);
  ServoLoop loop(device, benchScene(), {}, config);
  loop.start();
  const auto start = std::chrono::steady_clock::now();
  const auto end = start + std::chrono::duration<double>(seconds);
  ServoSnapshot snapshot;
  bool armed = true;
  while (std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    // Once per cycle, with the hand open and away, a ResetGrasp puts the part back exactly
    // (the GUI's path into the loop, exercised here too).
    const double t = device->scriptTime();
    if (t > 1.85 && t < 1.98 && armed) {
      loop.send({ServoCommand::Kind::ResetGrasp, false});
      armed = false;
    }
    if (t < 1.8) armed = true;
  }
  loop.stop();
  loop.read(snapshot);

  ServoBenchResult r;
  const TimingSummary timing = loop.timing();
  r.target_hz = rate_hz;
  r.achieved_hz = timing.achieved_hz;
  r.seconds = seconds;
  r.scheduler = loop.scheduler();
  r.memory_lock = loop.memoryLock();
  r.period_err = timing.periodError;
  r.compute = timing.compute;
  r.ticks = timing.ticks;
  r.overruns = timing.overruns;
  r.allocations_in_loop = allocationCounter ? snapshot.allocations : -1;
  r.grasps = snapshot.eventTotals[4];  // grasp::kGrasp
  r.lifts = snapshot.eventTotals[5];   // grasp::kLift
  r.watchdog_trips = snapshot.watchdog.trips;
  return r;
}

std::string toJson(const ServoBenchResult& r, int indent) {
  const auto summary = [](const DurationSummary& d) {
    return nlohmann::json{{"p50", d.p50_us}, {"p99", d.p99_us}, {"max", d.max_us}};
  };
  const nlohmann::json j = {{"target_hz", r.target_hz},
                            {"achieved_hz", r.achieved_hz},
                            {"seconds", r.seconds},
                            {"scheduler", r.scheduler},
                            {"memory_lock", r.memory_lock},
                            {"period_err_us", summary(r.period_err)},
                            {"compute_us", summary(r.compute)},
                            {"ticks", r.ticks},
                            {"overruns", r.overruns},
                            {"allocations_in_loop", r.allocations_in_loop},
                            {"grasps", r.grasps},
                            {"lifts", r.lifts},
                            {"watchdog_trips", r.watchdog_trips}};
  return j.dump(indent);
}

}  // namespace hg::servo
