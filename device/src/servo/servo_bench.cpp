#include "hapticgrasp/servo/servo_bench.hpp"

#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <gp_Ax2.hxx>

#include <algorithm>
#include <chrono>
#include <functional>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "hapticgrasp/contact/contact_model.hpp"
#include "hapticgrasp/device/simulated_operator.hpp"
#include "hapticgrasp/geometry/sample_parts.hpp"
#include "hapticgrasp/grasp/grasp_state.hpp"
#include "hapticgrasp/grasp/hand_script.hpp"
#include "hapticgrasp/grasp/multi_finger/multi_finger_grasp.hpp"
#include "hapticgrasp/servo/scripted_hand_device.hpp"
#include "hapticgrasp/session/recorder.hpp"
#include "servo/advancing_device.hpp"

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

namespace {

// Where the fingertips meet a part grasped across its y sides (part frame): through the
// point `centre` (x centre of the bounds, y centre, mid-height), the surface first met
// coming in from outside is at centre + plus * y and centre - minus * y. On a tall part the
// fingertips go no lower than 25 mm below its top.
struct GraspGeometry {
  Vec3 centre = Vec3::Zero();
  double plus = 0, minus = 0;
};

GraspGeometry graspGeometry(const geometry::PartModel& model, const geometry::PenetrationModel& penetration) {
  const geometry::Aabb b = model.bounds();
  GraspGeometry g;
  g.centre = b.centre();
  g.centre.z() = std::min(g.centre.z(), b.max.z() - 0.025);
  const auto surface = [&](double sign) {
    const double outside = (sign > 0 ? b.max.y() - g.centre.y() : g.centre.y() - b.min.y()) + 0.01;
    for (double s = outside; s > 0; s -= 0.1e-3) {
      geometry::QueryState q;
      if (penetration.query(g.centre + sign * s * Vec3::UnitY(), q).depth > 0) return s;
    }
    throw std::invalid_argument("bench servo: part '" + model.name() + "' has no material across y at its centre");
  };
  g.plus = surface(+1);
  g.minus = surface(-1);
  return g;
}

// The operator lags the path by 0.1-0.2 s and the thumb closes less than the index, so the
// closed targets lie deep inside, the thumb's deepest (the contact forces are a few newtons at most: the
// operator squeezes until the grasp); the hand opens to about 10 cm at most.
constexpr double kArmClearance = 0.015; // open fingertips this far outside the surface
constexpr double kArmSqueezeIndex = 0.015;  // closed targets this far inside
constexpr double kArmSqueezeThumb = 0.04;
constexpr double kArmFingerFirmness = 10;
constexpr double kArmDrop = 0.04;       // the open hand comes down this far onto the part
constexpr double kArmReach_s = 0.25;    // from the arm's rest pose to above the part
constexpr double kArmCycleEnd_s = 1.95; // then a cycle of 1.7 s, repeated
constexpr double kArmPeriod_s = kArmCycleEnd_s - kArmReach_s;

double armPhase(double t) { return t < kArmCycleEnd_s ? t : kArmReach_s + std::fmod(t - kArmReach_s, kArmPeriod_s); }

struct BenchSetup {
  std::shared_ptr<device::Device> device;
  std::shared_ptr<device::SimulatedMasterArm> arm;  // device "arm" only
  grasp::ScenePtr scene;
  std::function<double()> phase;  // script time within the cycle, read from the bench's thread
  double resetFrom = 0, resetTo = 0, rearmBelow = 0;  // the ResetGrasp window
};

BenchSetup armSetup(const geometry::PartModelPtr& model, const geometry::MassSpec& mass, geometry::Backend backend) {
  // Where the arm's hand rests: the part goes below it.
  const device::ArmPose rest = device::SimulatedMasterArm().pose();
  const Vec3 m0 = 0.5 * (rest.index + rest.thumb);
  Vec3 u = rest.index - rest.thumb;
  u.z() = 0;
  u = u.norm() > 1e-6 ? Vec3(u.normalized()) : Vec3(Vec3::UnitY());
  const Vec3 wristOffset = rest.wrist - m0;

  grasp::ScenePart part = grasp::makeScenePart(model, mass, {}, backend);
  const GraspGeometry g = graspGeometry(*model, *part.penetration);
  // Part y along the grip axis u (index side +y), part x horizontal.
  grasp::PartPose pose;
  pose.rotation = Eigen::AngleAxisd(std::atan2(u.y(), u.x()) - std::numbers::pi / 2, Vec3::UnitZ()).toRotationMatrix();
  const Vec3 G = m0 - Vec3(0, 0, kArmDrop);  // the grasp centre, absolute
  pose.position = G - pose.rotation * g.centre;
  part.initialPose = pose;
  auto scene = std::make_shared<const grasp::Scene>(std::vector<grasp::ScenePart>{part});

  const grasp::GraspParameters k;
  const double sag = part.mass.mass_kg * k.gravity.norm() / k.K_ox;
  // At rest the thumb tip sits higher than the index tip and the operator never quite
  // levels the hand: aim the thumb that much lower than the index (the tips end up close
  // to level, around the grasp height).
  const double tilt = std::clamp(rest.thumb.z() - rest.index.z(), -0.02, 0.02);
  const auto hand = [&](double index, double thumb, const Vec3& centre) {
    device::HandTarget h;
    h.index = centre + index * u + Vec3(0, 0, 0.5 * tilt);
    h.thumb = centre - thumb * u - Vec3(0, 0, 0.5 * tilt);
    h.wrist = 0.5 * (h.index + h.thumb) + wristOffset;
    return h;
  };
  const double openP = g.plus + kArmClearance, openM = g.minus + kArmClearance;
  // The thumb aims past the centre: against the index's contact force it closes the least.
  const double inP = std::max(0.003, g.plus - kArmSqueezeIndex), inM = g.minus - kArmSqueezeThumb;
  const Vec3 above = G + Vec3(0, 0, kArmDrop), lifted = G + Vec3(0, 0, 0.05), down = G + Vec3(0, 0, sag);
  std::vector<device::HandKeyframe> keys = {
      {0.00, {rest.index, rest.thumb, rest.wrist}},
      {kArmReach_s, hand(openP, openM, above)},  // open, above the part
      {0.50, hand(openP, openM, G)},             // down, fingertips outside its sides
      {0.75, hand(inP, inM, G)},                 // close: both fingertips in, grasp
      {0.95, hand(inP, inM, G)},
      {1.20, hand(inP, inM, lifted)},            // lift 5 cm
      {1.32, hand(inP, inM, lifted)},            // hold
      {1.55, hand(inP, inM, down)},              // put down where it was
      {1.70, hand(openP, openM, down)},          // open: release
      {1.85, hand(openP, openM, above)},         // up and away
      {kArmCycleEnd_s, hand(openP, openM, above)},
  };
  device::HandPath path = device::keyframePath(std::move(keys));
  device::HandPath cyclic = [path](double t) { return path(armPhase(t)); };
  // A firmer grip than the default operator's: its fingers cannot out-squeeze the grasp's
  // grip force (K_g, B_g) and the grasp would release at once.
  device::OperatorGains gains;
  for (int j = device::kIndexFlexion; j <= device::kThumbFlexion; ++j) {
    gains.stiffness[j] *= kArmFingerFirmness;
    gains.damping[j] *= kArmFingerFirmness;
  }
  auto arm = std::make_shared<device::SimulatedMasterArm>(device::SimulatedArmOptions{}, std::move(cyclic), gains);
  auto adapter = std::make_shared<AdvancingArmDevice>(arm);
  BenchSetup setup;
  setup.device = adapter;
  setup.arm = arm;
  setup.scene = std::move(scene);
  setup.phase = [adapter] { return armPhase(adapter->simTime()); };
  setup.resetFrom = 1.87;
  setup.resetTo = 1.94;
  setup.rearmBelow = 1.8;
  return setup;
}

// The multi-finger hand's cycle, with benchScript()'s timing: the thumb (fingertip 1)
// against the part's -y side, the others side by side along x against its +y side.
std::vector<grasp::HandKey> multiFingerKeys(const GraspGeometry& g, const grasp::ScenePart& part, int fingers) {
  const grasp::multi_finger::MultiFingerParams k;
  const double weight = part.mass.mass_kg * k.gravity.norm();
  const double in = -1.5 * weight / (2 * k.friction * k.stiffness);  // the squeeze carries 1.5 times the weight
  const double sag = weight / k.dynamicsStiffness;
  const auto key = [&](double t, double depth, double z) {
    grasp::HandKey h;
    h.t = t;
    h.wrist = Vec3(0, 0, kWristHeight);
    h.shift = Vec3(0, 0, z);
    for (int f = 0, side = 0; f < fingers; ++f) {
      if (f == 1) {
        h.fingertip(1) = Vec3(0, -g.minus - depth, 0);
        continue;
      }
      const double x = 0.015 * (side++ - 0.5 * (fingers - (fingers > 1 ? 2 : 1)));
      h.fingertip(f) = Vec3(x, g.plus + depth, 0);
    }
    return h;
  };
  return {key(0.0, kClearance, 0), key(0.1, kClearance, 0), key(0.5, in, 0), key(0.6, in, 0),
          key(1.0, in, kLift), key(1.2, in, kLift), key(1.5, in, sag), key(1.7, kClearance, sag),
          key(1.8, kClearance, 0), key(kCycle_s, kClearance, 0)};
}

BenchSetup scriptedSetup(const geometry::PartModelPtr& model, const geometry::MassSpec& mass, geometry::Backend backend,
                         bool paperCylinder, int multiFingers) {
  grasp::HandScript script = benchScript();
  grasp::ScenePtr scene;
  if (paperCylinder) {
    scene = benchScene();
  } else {
    grasp::ScenePart part = grasp::makeScenePart(model, mass, {}, backend);
    const GraspGeometry g = graspGeometry(*model, *part.penetration);
    const Vec3 G(0.4, 0.0, 0.3);
    part.initialPose.position = G - g.centre;
    scene = std::make_shared<const grasp::Scene>(std::vector<grasp::ScenePart>{part});
    // benchScript()'s keys, across y and sized for this part.
    const grasp::GraspParameters k;
    const double sag = part.mass.mass_kg * k.gravity.norm() / k.K_ox;
    std::vector<grasp::HandKey> keys;
    if (multiFingers > 0) keys = multiFingerKeys(g, part, multiFingers);
    const auto key = [&](double t, double index, double thumb, double z) {
      keys.push_back({t, {0, g.plus + index, 0}, {0, -g.minus - thumb, 0}, {0, 0, kWristHeight}, Vec3(0, 0, z), 0});
    };
    const double open = kClearance, in = -kPenetration, squeezed = in - kSqueeze;
    if (multiFingers == 0) {
      key(0.0, open, open, 0);
      key(0.1, open, open, 0);
      key(0.3, in, open, 0);
      key(0.5, in, in, 0);
      key(0.6, squeezed, squeezed, 0);
      key(1.0, squeezed, squeezed, kLift);
      key(1.2, squeezed, squeezed, kLift);
      key(1.5, squeezed, squeezed, sag);
      key(1.7, open, open, sag);
      key(1.8, open, open, 0);
      key(kCycle_s, open, open, 0);
    }
    script = grasp::HandScript(std::move(keys), grasp::PartPose{Mat3::Identity(), G});
  }
  device::DeviceSpec spec = ScriptedHandDevice::defaultSpec();
  spec.maxForce_N = 40;
  spec.maxTorque_Nm = 5;
  spec.fingertips = std::max(2, multiFingers);
  auto device = std::make_shared<ScriptedHandDevice>(std::move(script), spec, /*loop=*/true);
  BenchSetup setup;
  setup.device = device;
  setup.scene = std::move(scene);
  setup.phase = [device] { return device->scriptTime(); };
  setup.resetFrom = 1.85;
  setup.resetTo = 1.98;
  setup.rearmBelow = 1.8;
  return setup;
}

// The bench's part with its contact shell, standing on a 5 mm floor plate 20 mm wider all
// round (the scene as the workbench builds it with part-to-part contact on): the scripted
// put-down brings the part back to where it stood, onto the floor.
grasp::ScenePtr withFloor(const grasp::Scene& scene) {
  constexpr double kMm = 1e-3, kMargin = 20 * kMm, kThickness = 5 * kMm;
  grasp::ScenePart part = scene.part(0);
  part.contact = contact::ContactModel::build(part.model, part.penetration);
  const geometry::Aabb box = part.model->bounds();
  const Vec3 lo = box.min + part.initialPose.position, hi = box.max + part.initialPose.position;
  const Vec3 corner = (Vec3(lo.x() - kMargin, lo.y() - kMargin, lo.z() - kThickness)) / kMm;
  const Vec3 size = (Vec3(hi.x() - lo.x() + 2 * kMargin, hi.y() - lo.y() + 2 * kMargin, kThickness)) / kMm;
  const auto plate = geometry::PartModel::fromShape(
      BRepPrimAPI_MakeBox(gp_Pnt(corner.x(), corner.y(), corner.z()), size.x(), size.y(), size.z()).Shape(),
      geometry::LengthUnit::Millimetre, "floor");
  grasp::ScenePart floor = grasp::makeScenePart(plate, geometry::MassSpec::mass(1.0), grasp::PartPose{});
  floor.contact = contact::ContactModel::build(floor.model, floor.penetration);
  return std::make_shared<const grasp::Scene>(std::vector<grasp::ScenePart>{std::move(part), std::move(floor)});
}

// The session as a recording describes it: what replay needs to rebuild the same loop.
session::SessionDescription describe(const ServoBenchOptions& o, const BenchSetup& setup, int fingers) {
  session::SessionDescription d;
  d.software = std::string("hapticgrasp ") + session::softwareVersion();
  d.build = session::softwareBuild();
  d.created_utc = session::utcNow();
  d.method = o.method;
  d.fingertips = fingers;
  d.rate_hz = o.rate_hz;
  d.device = setup.device->spec();
  d.scenePublications = setup.scene->publications();  // before describing: a swap meanwhile is recorded again
  d.parts = session::describeParts(*setup.scene);
  d.contact = o.contact;  // the shells with the default ContactModelOptions, as withFloor builds them
  return d;
}

}  // namespace

OfflineArmBenchResult simulateArmBench(const std::string& part, double seconds, double rate_hz, double maxStep_s) {
  if (!(seconds > 0 && seconds <= 3600)) throw std::invalid_argument("bench seconds must be in (0, 3600]");
  if (!(rate_hz >= 50 && rate_hz <= 10000)) throw std::invalid_argument("bench rate must be in [50, 10000] Hz");
  if (!(maxStep_s > 0)) throw std::invalid_argument("bench sub-step must be > 0");
  const geometry::SamplePart sample = geometry::findPart(part);
  const geometry::PartModelPtr model = geometry::PartModel::fromFile(sample.file, sample.unit);
  const BenchSetup setup = armSetup(model, sample.mass, geometry::Backend::Auto);
  device::SimulatedMasterArm& arm = *setup.arm;
  TwoFingerEngine engine(setup.scene);
  const double dt = 1.0 / rate_hz;
  const int substeps = std::max(1, static_cast<int>(std::ceil(dt / maxStep_s)));
  const int ticks = static_cast<int>(std::llround(seconds * rate_hz));
  OfflineArmBenchResult r;
  device::DeviceSample s;
  bool armed = true, first = true;
  double graspDistance = 0;
  for (int k = 0; k < ticks; ++k) {
    // As the servo loop with AdvancingArmDevice does: advance, read, step the grasp, write.
    for (int i = 0; i < substeps; ++i) arm.advance(dt / substeps);
    arm.read(s);
    const EngineStep g = engine.step(s.hand, first ? 0.0 : dt);
    first = false;
    device::DeviceCommand c = g.command;
    c.f_grasp = std::clamp(std::isfinite(c.f_grasp) ? c.f_grasp : 0.0, 0.0, arm.spec().maxForce_N);
    arm.write(c);
    const double distance = (s.hand.index - s.hand.thumb).norm();
    if (g.events & grasp::kGrasp) {
      ++r.grasps;
      graspDistance = distance;
    }
    if (g.events & grasp::kLift) ++r.lifts;
    if (g.events & grasp::kRelease) ++r.releases;
    const double t = armPhase(arm.time());
    if (engine.state() == grasp::GraspState::Manipulate && t < 1.55)  // carried, before the hand opens
      r.maxCarriedOpening_m = std::max(r.maxCarriedOpening_m, distance - graspDistance);
    if (t > setup.resetFrom && t < setup.resetTo && armed) {  // the bench's ResetGrasp
      engine.reset();
      armed = false;
    }
    if (t < setup.rearmBelow) armed = true;
  }
  return r;
}

ServoBenchResult runServoBench(double rate_hz, double seconds, bool realtime, AllocationCounter allocationCounter) {
  ServoBenchOptions o;
  o.rate_hz = rate_hz;
  o.seconds = seconds;
  o.realtime = realtime;
  o.part = "cylinder";
  o.device = "scripted";
  o.allocationCounter = allocationCounter;
  return runServoBench(o);
}

ServoBenchResult runServoBench(const ServoBenchOptions& options) {
  const double rate_hz = options.rate_hz, seconds = options.seconds;
  if (!(seconds > 0 && seconds <= 3600)) throw std::invalid_argument("bench seconds must be in (0, 3600]");
  if (options.device != "arm" && options.device != "scripted")
    throw std::invalid_argument("bench device must be 'arm' or 'scripted', not '" + options.device + "'");
  const bool multiFinger = options.method == "multi-finger";
  if (!multiFinger && options.method != "two-finger")
    throw std::invalid_argument("bench method must be 'two-finger' or 'multi-finger', not '" + options.method + "'");
  const int fingers = multiFinger ? options.fingers : 2;
  if (fingers < 1 || fingers > grasp::HandSample::kMaxFingertips)
    throw std::invalid_argument("bench fingers must be 1 to 5");
  ServoConfig config;
  config.rate_hz = rate_hz;
  config.realtime = options.realtime;
  config.allocationCounter = options.allocationCounter;
  config.validate();

  const geometry::Backend backend = geometry::parseBackend(options.backend);
  const geometry::SamplePart sample = geometry::findPart(options.part);
  const bool paperCylinder = !multiFinger && !options.contact && options.device == "scripted" &&
                             options.part == "cylinder" && backend == geometry::Backend::Auto;
  const geometry::PartModelPtr model =
      paperCylinder ? geometry::PartModelPtr{} : geometry::PartModel::fromFile(sample.file, sample.unit);
  BenchSetup setup = options.device == "arm" ? armSetup(model, sample.mass, backend)
                                             : scriptedSetup(model, sample.mass, backend, paperCylinder,
                                                             multiFinger ? fingers : 0);
  if (options.wrapDevice) setup.device = options.wrapDevice(setup.device);
  std::optional<contact::CarriedContactConfig> contact;
  if (options.contact) {
    setup.scene = withFloor(*setup.scene);
    contact.emplace();
  }
  std::unique_ptr<GraspEngine> engine;
  if (multiFinger)
    engine = std::make_unique<MultiFingerEngine>(setup.scene, fingers, grasp::multi_finger::MultiFingerSceneParams{},
                                                 contact);
  else
    engine = std::make_unique<TwoFingerEngine>(setup.scene, grasp::GraspParameters{}, contact);
  ServoLoop loop(setup.device, std::move(engine), config);
  std::unique_ptr<session::Recorder> recorder;
  if (!options.recordPath.empty()) {
    recorder = std::make_unique<session::Recorder>(options.recordPath, describe(options, setup, fingers), setup.scene);
    loop.record(recorder->ring());
    recorder->start();
  }
  loop.start();
  const auto start = std::chrono::steady_clock::now();
  const auto end = start + std::chrono::duration<double>(seconds);
  ServoSnapshot snapshot;
  bool armed = true;
  std::uint64_t contactPolls = 0;
  double contactPenetration_m = 0;
  while (std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (options.poll) options.poll(*setup.scene, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    // Once per cycle, with the hand open and away, a ResetGrasp puts the part back exactly
    // (the GUI's path into the loop, exercised here too).
    const double t = setup.phase();
    if (t > setup.resetFrom && t < setup.resetTo && armed) {
      loop.send({ServoCommand::Kind::ResetGrasp, false});
      armed = false;
    }
    if (t < setup.rearmBelow) armed = true;
    if (options.contact) {
      loop.read(snapshot);
      if (snapshot.contact.active) {
        ++contactPolls;
        contactPenetration_m = std::max(contactPenetration_m, snapshot.contact.penetration_m);
      }
    }
  }
  loop.stop();
  loop.read(snapshot);

  ServoBenchResult r;
  r.contact_polls = contactPolls;
  r.contact_max_penetration_m = contactPenetration_m;
  if (recorder) {
    recorder->stop();
    const session::Recorder::Status st = recorder->status();
    r.recording = {true, st.path, st.dropped, st.bytes, st.messages, st.ticks, st.error};
  }
  const TimingSummary timing = loop.timing();
  r.part = sample.name;
  r.device = options.device;
  r.backend = std::string(setup.scene->part(0).penetration->name());
  r.method = options.method;
  r.fingers = fingers;
  r.target_hz = rate_hz;
  r.achieved_hz = timing.achieved_hz;
  r.seconds = seconds;
  r.scheduler = loop.scheduler();
  r.memory_lock = loop.memoryLock();
  r.period_err = timing.periodError;
  r.compute = timing.compute;
  r.deviceIo = timing.deviceIo;
  r.ticks = timing.ticks;
  r.overruns = timing.overruns;
  r.allocations_in_loop = options.allocationCounter ? snapshot.allocations : -1;
  r.grasps = snapshot.eventTotals[4];  // grasp::kGrasp
  r.lifts = snapshot.eventTotals[5];   // grasp::kLift
  r.watchdog_trips = snapshot.watchdog.trips;
  r.watchdog_clears = snapshot.eventTotals[17];  // kWatchdogClear
  return r;
}

std::string toJson(const ServoBenchResult& r, int indent) {
  const auto summary = [](const DurationSummary& d) {
    return nlohmann::json{{"p50", d.p50_us}, {"p99", d.p99_us}, {"max", d.max_us}};
  };
  const nlohmann::json j = {{"part", r.part},
                            {"device", r.device},
                            {"backend", r.backend},
                            {"target_hz", r.target_hz},
                            {"achieved_hz", r.achieved_hz},
                            {"seconds", r.seconds},
                            {"scheduler", r.scheduler},
                            {"memory_lock", r.memory_lock},
                            {"period_err_us", summary(r.period_err)},
                            {"compute_us", summary(r.compute)},
                            {"device_us", summary(r.deviceIo)},
                            {"ticks", r.ticks},
                            {"overruns", r.overruns},
                            {"allocations_in_loop", r.allocations_in_loop},
                            {"grasps", r.grasps},
                            {"lifts", r.lifts},
                            {"watchdog_trips", r.watchdog_trips},
                            {"method", r.method},
                            {"fingers", r.fingers},
                            {"contact_polls", r.contact_polls},
                            {"contact_max_penetration_m", r.contact_max_penetration_m}};
  nlohmann::json out = j;
  if (r.recording.enabled)
    out["recording"] = {{"path", r.recording.path},         {"dropped_records", r.recording.droppedRecords},
                        {"bytes", r.recording.bytes},       {"messages", r.recording.messages},
                        {"ticks", r.recording.ticks},       {"error", r.recording.error}};
  return out.dump(indent);
}

}  // namespace hg::servo
