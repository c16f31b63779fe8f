#include "haptic_session.hpp"

#include "hapticgrasp/servo/realtime_access.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "hapticgrasp/contact/carried_contact.hpp"
#include "hapticgrasp/contact/contact_model.hpp"
#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/geometry/model_cache.hpp"
#include "hapticgrasp/grasp/grasp_state.hpp"
#include "hapticgrasp/scene/scene.hpp"
#include "part_loader.hpp"

namespace hg::freecad {

geometry::PartModelPtr loadPart(const std::string& brep, const std::string& name, const std::atomic<bool>* cancelled) {
  geometry::PartModel::LoadOptions options;
  options.parallel = false;  // beside a GUI and possibly a running servo thread
  return loadPartText(brep, name, options, cancelled);
}

PartInfo describe(const geometry::PartModel& part, const geometry::MassSpec& mass,
                  const geometry::PenetrationModel& penetration) {
  const geometry::MassProperties props = part.massProperties(mass);
  PartInfo info;
  info.name = part.name();
  info.faces = part.faces().Extent();
  const double mm3PerM3 = toMillimetres(1.0) * toMillimetres(1.0) * toMillimetres(1.0);
  info.volume_mm3 = props.volume_m3 * mm3PerM3;
  info.mass_kg = props.mass_kg;
  info.centre_mm = toMillimetres(props.centre_m);
  info.primitive = geometry::toString(part.primitive().kind);
  info.warnings = part.warnings();
  const geometry::Aabb box = part.bounds();
  info.boundsMin_mm = toMillimetres(box.min);
  info.boundsMax_mm = toMillimetres(box.max);
  info.backend = std::string(penetration.name());
  info.backendReason = geometry::autoBackendReason(part, penetration.name());
  info.load_s = part.loadTiming().total_s;
  info.check_s = part.loadTiming().check_s;
  return info;
}

namespace {

// Part-to-part contact as the workbench has it: the shell's defaults, and caches sized for them.
contact::ContactModelOptions contactModelOptions() { return {}; }

contact::CarriedContactConfig contactConfig() {
  contact::CarriedContactConfig c;
  c.query.maxPoints = contactModelOptions().maxPoints;  // every shell fits; the caches no larger
  return c;
}

// A part's contact shell; one that fails leaves the part without contact (others pass
// through it), said in its warnings, never without its model.
contact::ContactModelPtr contactShell(const grasp::ScenePart& part, std::vector<std::string>& warnings) {
  try {
    return contact::ContactModel::build(part.model, part.penetration, contactModelOptions());
  } catch (const std::exception& e) {
    warnings.push_back(std::string("no part-to-part contact: its contact shell failed: ") + e.what());
    return nullptr;
  }
}

}  // namespace

BuiltPart buildPart(const PartRequest& request, const std::atomic<bool>* cancelled) {
  const grasp::PartPose pose = toPose(request.placement);
  auto model = loadPart(request.brep, request.name, cancelled);
  BuiltPart built{grasp::makeScenePart(model, request.mass, pose), {}};
  built.info = describe(*model, request.mass, *built.part.penetration);
  built.part.contact = contactShell(built.part, built.info.warnings);
  return built;
}


// --- ModelBuild -------------------------------------------------------------------------

ModelBuild::ModelBuild(std::vector<PartRequest> requests, bool open)
    : requests_(std::move(requests)), closed_(!open) {
  progress_.total = requests_.size();
  worker_ = std::thread([this] { run(); });
}

ModelBuild::~ModelBuild() {
  cancel();
  if (worker_.joinable()) worker_.join();
}

void ModelBuild::add(PartRequest request) {
  std::lock_guard lock(mutex_);
  if (closed_ || cancel_.load(std::memory_order_acquire)) throw std::logic_error("the model build takes no more parts");
  requests_.push_back(std::move(request));
  progress_.total = requests_.size();
  more_.notify_all();
}

void ModelBuild::close() {
  std::lock_guard lock(mutex_);
  closed_ = true;
  more_.notify_all();
}

void ModelBuild::run() noexcept {
  for (std::size_t i = 0;; ++i) {
    PartRequest request;
    {
      std::unique_lock lock(mutex_);
      more_.wait(lock, [&] { return cancel_.load(std::memory_order_acquire) || i < requests_.size() || closed_; });
      if (cancel_.load(std::memory_order_acquire) || i >= requests_.size()) break;
      request = std::move(requests_[i]);  // the worker's now; add() may grow the vector
      progress_.current = request.name;
    }
    Outcome outcome;
    outcome.request = i;
    outcome.name = request.name;
    try {
      outcome.built = buildPart(request, &cancel_);  // a cancel does not wait for the loader
    } catch (const std::exception& e) {
      outcome.error = e.what();
    } catch (...) {
      outcome.error = "unknown error while building the part";
    }
    std::lock_guard lock(mutex_);
    outcomes_.push_back(std::move(outcome));
    progress_.done = i + 1;
    progress_.current.clear();
  }
  std::lock_guard lock(mutex_);
  progress_.current.clear();
  progress_.cancelled = cancel_.load(std::memory_order_acquire) && (progress_.done < progress_.total || !closed_);
  progress_.finished = true;
  done_.notify_all();
}

ModelBuild::Progress ModelBuild::progress() const {
  std::lock_guard lock(mutex_);
  return progress_;
}

void ModelBuild::cancel() noexcept {
  std::lock_guard lock(mutex_);
  cancel_.store(true, std::memory_order_release);
  more_.notify_all();
}

bool ModelBuild::wait(double timeout_s) {
  std::unique_lock lock(mutex_);
  if (timeout_s < 0) {
    done_.wait(lock, [this] { return progress_.finished; });
  } else {
    done_.wait_for(lock, std::chrono::duration<double>(timeout_s), [this] { return progress_.finished; });
  }
  return progress_.finished;
}

std::vector<ModelBuild::Outcome> ModelBuild::outcomes() const {
  std::lock_guard lock(mutex_);
  std::vector<Outcome> out;
  out.reserve(outcomes_.size());
  for (const auto& o : outcomes_) {
    Outcome copy;
    copy.request = o.request;
    copy.name = o.name;
    copy.error = o.error;
    if (o.built) copy.built = o.built;  // shares the (immutable) models
    out.push_back(std::move(copy));
  }
  return out;
}

BuiltPart ModelBuild::take(std::size_t i) {
  std::lock_guard lock(mutex_);
  if (!progress_.finished) throw std::logic_error("the model build is still running");
  if (i >= outcomes_.size() || !outcomes_[i].built)
    throw std::logic_error("no built part at outcome " + std::to_string(i));
  BuiltPart part = std::move(*outcomes_[i].built);
  outcomes_[i].built.reset();
  return part;
}

// --- Session ----------------------------------------------------------------------------

Session::~Session() {
  loadsCancelled_->store(true, std::memory_order_release);  // before build_'s workers are joined
  stop();
}

int Session::addPart(const std::string& name, const std::string& brep, const Placement& placement,
                     const geometry::MassSpec& mass) {
  if (loop_) throw std::logic_error("parts must be added before start()");
  BuiltPart built = buildPart(PartRequest{name, brep, placement, mass});
  parts_.push_back(std::move(built.part));
  infos_.push_back(std::move(built.info));
  return static_cast<int>(parts_.size()) - 1;
}

std::vector<std::pair<std::size_t, int>> Session::addBuilt(ModelBuild& build) {
  if (loop_) throw std::logic_error("parts must be added before start()");
  const ModelBuild::Progress progress = build.progress();
  if (!progress.finished) throw std::logic_error("the model build is still running");
  if (progress.cancelled) throw std::logic_error("the model build was cancelled");
  const auto outcomes = build.outcomes();
  std::vector<std::pair<std::size_t, int>> added;
  for (std::size_t i = 0; i < outcomes.size(); ++i) {
    if (!outcomes[i].built) continue;
    BuiltPart built = build.take(i);
    parts_.push_back(std::move(built.part));
    infos_.push_back(std::move(built.info));
    added.emplace_back(outcomes[i].request, static_cast<int>(parts_.size()) - 1);
  }
  return added;
}

namespace {

// The one part a finished rebuild (a one-part ModelBuild) built; throws std::logic_error.
BuiltPart takeRebuilt(ModelBuild& build) {
  const ModelBuild::Progress progress = build.progress();
  if (!progress.finished || progress.cancelled) throw std::logic_error("the model build did not finish");
  const auto outcomes = build.outcomes();
  if (outcomes.size() != 1) throw std::logic_error("a part is replaced by a build of one part");
  if (!outcomes[0].built) throw std::logic_error("the rebuild of " + outcomes[0].name + " failed: " + outcomes[0].error);
  return build.take(0);
}

}  // namespace

void Session::replacePart(std::size_t index, ModelBuild& build) {
  if (index >= parts_.size()) throw std::out_of_range("no part " + std::to_string(index));
  BuiltPart built = takeRebuilt(build);
  parts_[index] = std::move(built.part);
  infos_[index] = std::move(built.info);
}

void Session::restart(const std::vector<Placement>& placements) {
  if (!loop_ || !device_) throw std::logic_error("restart() needs a started session");
  if (build_) {  // scene mode: the same parts and models, standing where the document has them
    if (placements.size() != sceneRequests_.size())
      throw std::invalid_argument("restart() needs one placement per part (" + std::to_string(sceneRequests_.size()) + ")");
    std::vector<grasp::PartPose> poses;
    poses.reserve(placements.size());
    for (const auto& p : placements) poses.push_back(toPose(p));
    if (loop_->read(*snap_)) {
      timeOffset_s_ += snap_->time_s;
      tickOffset_ += snap_->tick;
    }
    loop_->stop();
    loop_.reset();
    endRecording();
    const grasp::ScenePtr scene = build_->rebase(poses);
    reader_ = servo::SnapshotReader{};
    resetTracker();
    runLoop(scene);
    return;
  }
  if (placements.size() != parts_.size())
    throw std::invalid_argument("restart() needs one placement per part (" + std::to_string(parts_.size()) + ")");
  std::vector<grasp::PartPose> poses;
  poses.reserve(placements.size());
  for (const auto& p : placements) poses.push_back(toPose(p));  // may throw: nothing changed yet
  auto scene = std::make_shared<const grasp::Scene>([&] {
    std::vector<grasp::ScenePart> parts = parts_;
    for (std::size_t i = 0; i < parts.size(); ++i) parts[i].initialPose = poses[i];
    return parts;
  }());
  // The time and ticks of the old loop carry on in the snapshots.
  if (loop_->read(*snap_)) {
    timeOffset_s_ += snap_->time_s;
    tickOffset_ += snap_->tick;
  }
  loop_->stop();
  loop_.reset();
  endRecording();
  for (std::size_t i = 0; i < parts_.size(); ++i) parts_[i].initialPose = poses[i];
  reader_ = servo::SnapshotReader{};
  resetTracker();
  runLoop(scene);
}

void Session::setHandScript(const std::vector<HandKeyMm>& keys, const Placement& frame,
                            const std::array<double, 3>& pivot_mm) {
  if (loop_) throw std::logic_error("the device must be chosen before start()");
  std::vector<grasp::HandKey> k;
  k.reserve(keys.size());
  for (const auto& key : keys) k.push_back(toHandKey(key));
  script_ = std::make_unique<grasp::HandScript>(std::move(k), toPose(frame), toMetres(pivot_mm));
  handHold_s_ = 0;
  hid_.reset();
  arm_.reset();
}

void Session::useHandInput(double hold_s) {
  if (loop_) throw std::logic_error("the device must be chosen before start()");
  if (!(hold_s > 0 && std::isfinite(hold_s))) throw std::invalid_argument("hand hold time must be positive");
  handHold_s_ = hold_s;
  script_.reset();
  hid_.reset();
  arm_.reset();
}

void Session::useSimulatedArm(const std::array<double, 3>& rest_mm, const std::array<double, 3>& grip_axis,
                              double hold_s) {
  if (loop_) throw std::logic_error("the device must be chosen before start()");
  const Vec3 axis(grip_axis[0], grip_axis[1], grip_axis[2]);  // a direction: no unit
  auto arm = std::make_shared<ArmInputDevice>(toMetres(rest_mm), axis, hold_s);  // throws: nothing changed
  arm_ = std::move(arm);
  handHold_s_ = 0;
  script_.reset();
  hid_.reset();
}

Session::ArmRest Session::armRest() const {
  if (!arm_) throw std::logic_error("the simulated arm is not the device: useSimulatedArm() first");
  const device::ArmPose& p = arm_->restPose();
  const Vec3 u = arm_->gripAxis();
  return {toMillimetres(p.index), toMillimetres(p.thumb), toMillimetres(p.wrist), {u.x(), u.y(), u.z()}};
}

void Session::useSpaceMouse(const std::string& path, const std::array<double, 3>& start_mm, double open_mm,
                            double closed_mm) {
  if (loop_) throw std::logic_error("the device must be chosen before start()");
  if (!(std::isfinite(open_mm) && std::isfinite(closed_mm) && open_mm > 0 && closed_mm >= 0 && closed_mm <= open_mm))
    throw std::invalid_argument("SpaceMouse grip: need 0 <= closed_mm <= open_mm, open_mm > 0");
  device::SpaceMouseConfig config;
  config.initialWrist = -config.gripCentre_wrist;  // the grip centre at the device frame's origin
  config.openWidth_m = toMetres(open_mm);
  config.closedWidth_m = toMetres(closed_mm);
  auto opened = openSpaceMouse(path, config, toMetres(start_mm));  // throws: nothing changed
  hid_ = std::move(opened);
  handHold_s_ = 0;
  script_.reset();
  arm_.reset();
}

void Session::useHid(const std::string& layoutFile, const std::string& path, const std::array<double, 3>& origin_mm) {
  if (loop_) throw std::logic_error("the device must be chosen before start()");
  auto opened = openHidLayout(layoutFile, path, toMetres(origin_mm));  // throws: nothing changed
  hid_ = std::move(opened);
  handHold_s_ = 0;
  script_.reset();
  arm_.reset();
}

void Session::setHand(const std::array<double, 3>& index_mm, const std::array<double, 3>& thumb_mm,
                      const std::array<double, 3>& wrist_mm) {
  if (arm_) {
    device::HandTarget target;
    target.index = toMetres(index_mm);
    target.thumb = toMetres(thumb_mm);
    target.wrist = toMetres(wrist_mm);
    arm_->setTarget(target);
    return;
  }
  if (!input_) throw std::logic_error("no hand input device: useHandInput() and start(), or useSimulatedArm(), first");
  grasp::HandSample hand;
  hand.index = toMetres(index_mm);
  hand.thumb = toMetres(thumb_mm);
  hand.wrist = toMetres(wrist_mm);
  input_->setHand(hand);
}

std::string Session::deviceName() const {
  if (handHold_s_ > 0) return HandInputDevice::defaultSpec().name;
  if (script_) return servo::ScriptedHandDevice::defaultSpec().name;
  if (hid_) return hid_->spec().name;
  if (arm_) return arm_->spec().name;
  return "none";
}

bool Session::deviceForceOutput() const {
  if (handHold_s_ > 0) return HandInputDevice::defaultSpec().forceOutput;
  if (script_) return servo::ScriptedHandDevice::defaultSpec().forceOutput;
  if (hid_) return hid_->spec().forceOutput;
  if (arm_) return arm_->spec().forceOutput;
  return false;
}

namespace {

// The two methods' parameters by their papers' names: the two-finger method's force laws
// [MH], and the multi-finger method's springs, friction and distribution weights [RF]:
// k (finger–god-object springs), k_d (the dynamics' spring), mu (μ), gamma1..3 (γ of eq 19).
double* parameterField(grasp::GraspParameters& p, grasp::multi_finger::MultiFingerParams& m, const std::string& name) {
  if (name == "K_c") return &p.K_c;
  if (name == "B_c") return &p.B_c;
  if (name == "K_g") return &p.K_g;
  if (name == "B_g") return &p.B_g;
  if (name == "d_h") return &p.d_h;
  if (name == "K_ox") return &p.K_ox;
  if (name == "K_oe") return &p.K_oe;
  if (name == "k") return &m.stiffness;
  if (name == "k_d") return &m.dynamicsStiffness;
  if (name == "mu") return &m.friction;
  if (name == "gamma1") return &m.distribution.gamma1;
  if (name == "gamma2") return &m.distribution.gamma2;
  if (name == "gamma3") return &m.distribution.gamma3;
  return nullptr;
}

// The multi-finger method's ranges: positive springs, non-negative friction and weights (γ1
// ≤ 0 selects its scale-free default), all finite.
void validateMultiFinger(const grasp::multi_finger::MultiFingerParams& m) {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(what);
  };
  require(std::isfinite(m.stiffness) && m.stiffness > 0, "k must be a positive finite stiffness (N/m)");
  require(std::isfinite(m.dynamicsStiffness) && m.dynamicsStiffness > 0, "k_d must be a positive finite stiffness (N/m)");
  require(std::isfinite(m.friction) && m.friction >= 0, "mu must be a finite friction coefficient >= 0");
  require(std::isfinite(m.distribution.gamma1), "gamma1 must be finite (<= 0: 1/L^2)");
  require(std::isfinite(m.distribution.gamma2) && m.distribution.gamma2 >= 0, "gamma2 must be finite and >= 0");
  require(std::isfinite(m.distribution.gamma3) && m.distribution.gamma3 > 0, "gamma3 must be finite and > 0");
}

}  // namespace

const std::vector<std::string>& Session::parameterNames() {
  static const std::vector<std::string> names{"K_c", "B_c", "K_g", "B_g", "d_h", "K_ox", "K_oe",
                                              "k",   "k_d", "mu",  "gamma1", "gamma2", "gamma3"};
  return names;
}

void Session::setParameters(const std::vector<std::pair<std::string, double>>& values) {
  if (loop_) throw std::logic_error("parameters must be set before start()");
  grasp::GraspParameters p = parameters_;
  grasp::multi_finger::MultiFingerParams m = multiFinger_;
  for (const auto& [name, value] : values) {
    double* field = parameterField(p, m, name);
    if (!field)
      throw std::invalid_argument("unknown grasp parameter " + name +
                                  " (known: K_c, B_c, K_g, B_g, d_h, K_ox, K_oe, k, k_d, mu, gamma1, gamma2, gamma3)");
    *field = value;
  }
  p.validate();
  validateMultiFinger(m);
  parameters_ = p;
  multiFinger_ = m;
}

double Session::parameter(const std::string& name) const {
  grasp::GraspParameters p = parameters_;
  grasp::multi_finger::MultiFingerParams m = multiFinger_;
  const double* field = parameterField(p, m, name);
  if (!field) throw std::invalid_argument("unknown grasp parameter " + name);
  return *field;
}

double Session::scriptDuration() const { return script_ ? script_->duration() : 0.0; }

void Session::start(double rate_hz, bool realtime) {
  if (loop_) throw std::logic_error("a session starts once");
  if (parts_.empty()) throw std::invalid_argument("no parts to grasp");
  servo::ServoConfig config;
  config.rate_hz = rate_hz;
  config.realtime = realtime;
  launch(std::make_shared<const grasp::Scene>(parts_), config);
}

bool Session::hasDevice() const { return handHold_s_ > 0 || script_ || hid_ || arm_; }

// The chosen device and the servo loop over `scene`; both kept for restart().
void Session::launch(const grasp::ScenePtr& scene, const servo::ServoConfig& config) {
  std::shared_ptr<device::Device> device;
  if (handHold_s_ > 0) {
    device = input_ = std::make_shared<HandInputDevice>(handHold_s_);
  } else if (script_) {
    device = scripted_ = std::make_shared<servo::ScriptedHandDevice>(*script_);
  } else if (hid_) {
    device = hid_;
  } else if (arm_) {
    device = arm_;
  } else {
    throw std::invalid_argument("no device: set a hand script or use the hand input first");
  }
  device_ = device;
  config_ = config;
  resetTracker();
  runLoop(scene);
}

void Session::runLoop(const grasp::ScenePtr& scene) {
  scene_ = scene;
  loop_ = std::make_unique<servo::ServoLoop>(device_, makeEngine(scene), config_);
  startRecording(scene);  // the ring goes to the loop before it starts
  loop_->start();
  // Refused real time costs the rate under a busy GUI (measured: 820-857 Hz of 1 kHz under
  // Xvfb): find out why once, here, so the panel and the report view can say how to fix it.
  realtimeAdvice_.clear();
  if (config_.realtime && loop_->scheduler() != "SCHED_FIFO")
    realtimeAdvice_ = servo::realtimeAdvice(servo::probeRealtime(config_.fifoPriority));
}

ServoTiming Session::servoTiming() const {
  ServoTiming t;
  if (!loop_) return t;
  const servo::TimingSummary s = loop_->timing();
  t.target_hz = config_.rate_hz;
  t.achieved_hz = s.achieved_hz;
  t.periodErrP50_us = s.periodError.p50_us;
  t.periodErrP99_us = s.periodError.p99_us;
  t.periodErrMax_us = s.periodError.max_us;
  t.ticks = s.ticks;
  t.scheduler = loop_->scheduler();
  t.memoryLock = loop_->memoryLock();
  t.realtime = t.scheduler == "SCHED_FIFO";
  t.advice = realtimeAdvice_;
  return t;
}

void Session::setMethod(const std::string& method) {
  if (loop_) throw std::logic_error("the method must be chosen before start()");
  if (method != "two-finger" && method != "multi-finger")
    throw std::invalid_argument("unknown grasp method '" + method + "' (two-finger, multi-finger)");
  method_ = method;
}

// The multi-finger method drives every fingertip the device reads, with its parameters (the
// paper's defaults k = k_d = 800 N/m, μ = 1 unless set); the two-finger one takes the force
// parameters.
grasp::multi_finger::MultiFingerSceneParams Session::multiFingerParams() const {
  grasp::multi_finger::MultiFingerSceneParams params;
  params.grasp = multiFinger_;
  params.grasp.gravity = parameters_.gravity;
  return params;
}

void Session::setContact(bool on) {
  if (loop_) throw std::logic_error("part-to-part contact must be chosen before start()");
  contact_ = on;
}

// Contact off still reports the clearance and any interference: the part passes through.
std::unique_ptr<servo::GraspEngine> Session::makeEngine(const grasp::ScenePtr& scene) const {
  contact::CarriedContactConfig contact = contactConfig();
  contact.constrain = contact_;
  if (method_ == "multi-finger")
    return std::make_unique<servo::MultiFingerEngine>(scene, device_->spec().fingertips, multiFingerParams(), contact);
  return std::make_unique<servo::TwoFingerEngine>(scene, parameters_, contact);
}

std::vector<grasp::PartPose> Session::initialPoses() const {
  std::vector<grasp::PartPose> poses;
  if (build_) {
    const grasp::ScenePtr scene = build_->scene();
    for (std::size_t i = 0; i < scene->size(); ++i) poses.push_back(scene->part(i).initialPose);
  } else {
    for (const auto& part : parts_) poses.push_back(part.initialPose);
  }
  return poses;
}

void Session::resetTracker() { tracker_.reset(initialPoses()); }

// --- Scene mode ------------------------------------------------------------------------

namespace {

const char* kStandInReason = "box: its bounding box until its model is built";

}  // namespace

void Session::startScene(const std::vector<SceneRequest>& requests, double rate_hz, bool realtime, int workers) {
  if (loop_) throw std::logic_error("a session starts once");
  if (requests.empty()) throw std::invalid_argument("no parts to grasp");
  if (!hasDevice()) throw std::invalid_argument("no device: set a hand script or use the hand input first");
  std::vector<grasp::PartSource> sources;
  sources.reserve(requests.size());
  for (const SceneRequest& r : requests) {
    grasp::PartSource p;
    p.name = r.name;
    p.key = r.key;
    p.bounds = {toMetres(r.boxMin_mm), toMetres(r.boxMax_mm)};
    p.pose = toPose(r.placement);  // throws for a bad placement: nothing started
    p.mass = r.mass;
    sources.push_back(std::move(p));
  }
  grasp::SceneBuild::Options options;
  options.workers = workers;
  options.contact = true;  // every shell, whether the session couples or not (setContact)
  options.contactOptions = contactModelOptions();
  const int cpu = realtime ? servo::servoCpu() : -1;  // a real-time servo keeps a CPU to itself
  options.avoidCpu = cpu;
  build_ = std::make_unique<grasp::SceneBuild>(std::move(sources), options);
  sceneRequests_ = requests;
  backends_.assign(requests.size(), {"box", kStandInReason});
  describedModel_.assign(build_->progress().models, false);
  exactParts_ = 0;
  parts_.clear();
  infos_.clear();
  servo::ServoConfig config;
  config.rate_hz = rate_hz;
  config.realtime = realtime;
  config.cpu = cpu;
  launch(build_->scene(), config);  // on the scene of stand-ins
}

std::vector<std::size_t> Session::wantedShapes(std::size_t limit) const {
  if (!build_) throw std::logic_error("not a scene session: startScene() first");
  return build_->awaitingShapes(limit);
}

std::size_t Session::modelOfPart(std::size_t part) const {
  if (!build_) throw std::logic_error("not a scene session: startScene() first");
  return build_->modelOf(part);
}

std::size_t Session::firstPartOfModel(std::size_t model) const {
  if (!build_) throw std::logic_error("not a scene session: startScene() first");
  for (std::size_t i = 0; i < sceneRequests_.size(); ++i)
    if (build_->modelOf(i) == model) return i;
  throw std::out_of_range("no model " + std::to_string(model));
}

void Session::provideShape(std::size_t model, std::string brep) {
  if (!build_) throw std::logic_error("not a scene session: startScene() first");
  const std::string name = sceneRequests_.at(firstPartOfModel(model)).name;
  auto text = std::make_shared<const std::string>(std::move(brep));
  auto sources = cacheSources_;
  auto cancelled = loadsCancelled_;
  build_->provide(model, [text, name, model, sources, cancelled] {
    // Seen before (this Start, an earlier one, another FreeCAD session): not checked again.
    geometry::PartModel::LoadOptions options;
    options.parallel = false;  // beside a GUI and the servo thread
    geometry::ModelCache::Outcome outcome;
    auto part =
        geometry::ModelCache::shared().load(*text, kDocumentUnit, name, options, &outcome, cacheBuild(cancelled));
    std::lock_guard lock(sources->mutex);
    sources->byModel[model] = std::string(geometry::toString(outcome.source)) +
                              (outcome.note.empty() ? "" : " (" + outcome.note + ")");
    return part;
  });
}

std::string Session::modelSource(std::size_t model) const {
  std::lock_guard lock(cacheSources_->mutex);
  const auto found = cacheSources_->byModel.find(model);
  return found == cacheSources_->byModel.end() ? std::string() : found->second;
}

PartInfo Session::replaceScenePart(std::size_t part, ModelBuild& build) {
  if (!build_) throw std::logic_error("not a scene session: startScene() first");
  if (part >= sceneRequests_.size()) throw std::out_of_range("no part " + std::to_string(part));
  BuiltPart built = takeRebuilt(build);
  grasp::ScenePart models = built.part;
  models.initialPose = {};  // each scene keeps the part's own pose
  build_->replace(part, std::move(models));
  backends_[part] = {built.info.backend, built.info.backendReason};
  return built.info;
}

SceneStatus Session::sceneStatus() const {
  if (!build_) throw std::logic_error("not a scene session: startScene() first");
  const grasp::SceneBuild::Progress p = build_->progress();
  return {p.parts, p.models, p.built, p.failed, p.exactParts, p.finished};
}

PartInfo Session::modelInfo(std::size_t model, std::string* error) const {
  if (!build_) throw std::logic_error("not a scene session: startScene() first");
  const auto models = build_->models();
  const grasp::SceneBuild::Model& m = models.at(model);
  if (error) *error = m.error;
  if (m.status != grasp::SceneBuild::Model::Status::Built) {
    PartInfo info;
    info.name = m.name;
    info.backend = "box";
    info.backendReason = m.status == grasp::SceneBuild::Model::Status::Failed ? "box: its model failed: " + m.error
                                                                               : kStandInReason;
    return info;
  }
  const geometry::MassSpec mass = m.parts.empty() ? geometry::MassSpec{} : sceneRequests_.at(m.parts.front()).mass;
  return describe(*m.model, mass, *m.penetration);
}

// The parts whose model came in since the last snapshot get their back end's line.
void Session::refreshBackends() {
  const grasp::SceneBuild::Progress p = build_->progress();
  if (p.exactParts == exactParts_ && p.failed == 0) return;
  const auto models = build_->models();
  for (std::size_t m = 0; m < models.size(); ++m) {
    if (describedModel_[m] || models[m].status == grasp::SceneBuild::Model::Status::Waiting ||
        models[m].status == grasp::SceneBuild::Model::Status::Building)
      continue;
    describedModel_[m] = true;
    const PartInfo info = modelInfo(m);
    for (const std::size_t part : models[m].parts) backends_[part] = {info.backend, info.backendReason};
  }
  exactParts_ = p.exactParts;
}

void Session::stop() noexcept {
  if (loop_) loop_->stop();
  endRecording();  // after the loop: nothing more enters the ring, the drop count is final
}

namespace {

// The report in FreeCAD's units: what the panel and the overlay show.
SessionSnapshot::Contact contactView(const contact::ContactReport& r) {
  SessionSnapshot::Contact c;
  c.carried = r.part >= 0;
  c.part = r.part;
  c.otherPart = r.otherPart;
  c.exact = r.clearanceExact;
  c.clearance_mm = toMillimetres(r.clearance_m);
  c.heldFace = r.heldFace;
  c.otherFace = r.otherFace;
  c.heldPoint_mm = toMillimetres(r.heldPoint);
  c.otherPoint_mm = toMillimetres(r.otherPoint);
  c.penetration_mm = toMillimetres(r.penetration_m);
  c.contactForce_N = r.contactForce_N.norm();
  c.active = r.active;
  c.lagging = r.lagging;
  c.saturated = r.saturated;
  c.unmodelled = r.unmodelled;
  c.letThrough = r.letThrough;
  return c;
}

}  // namespace

SessionSnapshot Session::snapshot() {
  SessionSnapshot out;
  out.placements.reserve(parts_.size());
  if (build_) {
    refreshBackends();
    out.backends = backends_;
    out.exactParts = exactParts_;
  } else {
    for (const PartInfo& info : infos_) out.backends.emplace_back(info.backend, info.backendReason);
    out.exactParts = infos_.size();
  }
  if (!loop_ || !loop_->read(*snap_)) {
    for (const grasp::PartPose& pose : initialPoses()) out.placements.push_back(toPlacement(pose));
    out.tick = tickOffset_;
    out.time_s = timeOffset_s_;
    return out;
  }
  const servo::ServoSnapshot& s = *snap_;
  if (build_) build_->setFocus(s.hand.index);  // the build follows the hand
  out.tick = tickOffset_ + s.tick;
  out.time_s = timeOffset_s_ + s.time_s;
  out.state = grasp::toString(s.state);
  out.graspedPart = s.graspedPart;
  out.events = reader_.eventsSinceLastRead(s, &out.eventsLost);
  for (int bit = 0; bit < grasp::kEventCount; ++bit)
    if (out.events & (1u << bit)) out.eventNames.emplace_back(grasp::eventName(static_cast<grasp::GraspEvent>(1u << bit)));
  if (out.events & servo::kWatchdogTrip) out.eventNames.emplace_back("watchdog trip");
  if (out.events & servo::kWatchdogClear) out.eventNames.emplace_back("watchdog clear");
  if (out.events & servo::kGraspReset) out.eventNames.emplace_back("grasp reset");
  out.fault = servo::toString(s.watchdog.fault);
  out.faults = s.watchdog.trips;
  tracker_.update(s);  // a reader at the GUI's rate loses no put-down (64 between two reads)
  for (const grasp::PartPose& pose : tracker_.poses()) out.placements.push_back(toPlacement(pose));
  const auto newtons = [](const Vec3& f) { return std::array<double, 3>{f.x(), f.y(), f.z()}; };
  out.forces_N = {newtons(s.sent.f_index), newtons(s.sent.f_thumb)};
  out.graspForce_N = s.sent.f_grasp;
  out.index_mm = toMillimetres(s.hand.index);
  out.thumb_mm = toMillimetres(s.hand.thumb);
  out.wrist_mm = toMillimetres(s.hand.wrist);
  out.method = s.method;
  for (int k = 0; k < s.fingertips; ++k) {
    out.fingertips_mm.push_back(toMillimetres(s.hand.fingertip(k)));
    out.fingertipForces_N.push_back(newtons(s.sent.fingertipForce(k)));
  }
  out.rate_hz = s.timing.achieved_hz;
  out.jitter_us = s.timing.periodError.p99_us;
  out.contact = contactView(s.contact);
  return out;
}

void Session::setDeviceSilent(bool silent) {
  if (scripted_) scripted_->setSilent(silent);
  else if (input_) input_->setSilent(silent);
  else if (hid_ && loop_) hid_->setSilent(silent);
  else if (arm_ && loop_) arm_->setSilent(silent);
  else throw std::logic_error("no device yet: start() first");
}

void Session::resetGrasp() {
  if (loop_) loop_->send(servo::ServoCommand{servo::ServoCommand::Kind::ResetGrasp, false});
}

// --- Recording -------------------------------------------------------------------------

void Session::recordTo(const std::string& path, const std::string& document) {
  if (loop_) throw std::logic_error("recordTo() must come before start()");
  recordPath_ = path;
  recordDocument_ = document;
  recorded_ = RecordingStatus{};
}

std::string Session::partName(std::size_t i) const {
  if (build_) return sceneRequests_.at(i).name;
  return infos_.at(i).name;
}

// Everything replay needs to rebuild this loop. Scene mode: the parts whose model is not
// built yet are recorded coarse, by their box (no BREP); their own models, published as
// the builds finish, are recorded as model swaps (the recorder follows the scene).
session::SessionDescription Session::describeSession(const grasp::ScenePtr& scene) const {
  session::SessionDescription d;
  d.document = recordDocument_;
  d.software = std::string("hapticgrasp ") + session::softwareVersion();
  d.build = session::softwareBuild();
  d.created_utc = session::utcNow();
  d.method = method_;
  d.fingertips = method_ == "multi-finger" ? device_->spec().fingertips : 2;
  d.rate_hz = config_.rate_hz;
  d.watchdogRamp_s = config_.watchdogRamp_s;
  d.passivityController = config_.passivityController;
  d.device = device_->spec();
  d.twoFinger = parameters_;
  d.multiFinger = multiFingerParams();
  d.contact = true;
  d.contactModel = contactModelOptions();
  d.contactConfig = contactConfig();
  d.contactConfig.constrain = contact_;
  d.scenePublications = scene->publications();  // before describing: a swap meanwhile is recorded again
  d.parts = session::describeParts(*scene);
  for (std::size_t i = 0; i < d.parts.size(); ++i) d.parts[i].name = partName(i);  // stand-ins have no model name
  return d;
}

namespace {

// The k-th file of a session (k from 1): the path given, then "<stem>-k<ext>" beside it.
std::string recordingFile(const std::string& path, std::size_t k) {
  if (k <= 1) return path;
  const std::filesystem::path p(path);
  return (p.parent_path() / (p.stem().string() + "-" + std::to_string(k) + p.extension().string())).string();
}

}  // namespace

// A recorder for the loop just made (before it starts). A file that cannot be written is
// said in the status; the haptic session goes on without recording.
void Session::startRecording(const grasp::ScenePtr& scene) {
  if (recordPath_.empty()) return;
  const std::string path = recordingFile(recordPath_, recorded_.files.size() + 1);
  recorded_.files.push_back(path);
  recorded_.path = path;
  try {
    recorder_ = std::make_unique<session::Recorder>(path, describeSession(scene), scene);
    loop_->record(recorder_->ring());
    recorder_->start();
  } catch (const std::exception& e) {
    recorder_.reset();
    recorded_.error = std::string("cannot record to ") + path + ": " + e.what();
  }
}

// Closes the current file and adds its figures to recorded_.
void Session::endRecording() noexcept {
  if (!recorder_) return;
  recorder_->stop();
  try {
    const session::Recorder::Status st = recorder_->status();
    recorded_.ticks += st.ticks;
    recorded_.dropped += st.dropped;
    recorded_.bytes += st.bytes;
    recorded_.annotations += st.annotations;
    recorded_.duration_s += st.duration_s;
    if (!st.error.empty()) recorded_.error = st.error;
  } catch (...) {  // status() copies strings; out of memory: the figures stay as they were
  }
  recorder_.reset();
}

RecordingStatus Session::recordingStatus() const {
  RecordingStatus out = recorded_;
  if (!recorder_) return out;
  const session::Recorder::Status st = recorder_->status();
  out.recording = st.recording;
  out.ticks += st.ticks;
  out.dropped += st.dropped;
  out.bytes += st.bytes;
  out.annotations += st.annotations;
  out.duration_s += st.duration_s;
  if (!st.error.empty()) out.error = st.error;
  return out;
}

namespace {

constexpr double kNoteReach_m = 0.03;  // a note is about a part this near the grip centre

}  // namespace

// The part a note is about: the grasped one, else the part whose box (where the tracker
// last saw it) is nearest the grip centre, within kNoteReach_m; "" if none. The box, not
// the surface: simple, and enough to name the part.
std::string Session::partUnderHand(const servo::ServoSnapshot& s) const {
  if (!scene_) return {};
  if (s.graspedPart >= 0 && static_cast<std::size_t>(s.graspedPart) < scene_->size()) return partName(s.graspedPart);
  const Vec3 centre = 0.5 * (s.hand.index + s.hand.thumb);
  const auto poses = tracker_.poses();
  std::string nearest;
  double best = kNoteReach_m;
  for (std::size_t i = 0; i < scene_->size() && i < poses.size(); ++i) {
    const geometry::Aabb& box = scene_->part(i).bounds;
    if (box.empty()) continue;
    const Vec3 local = poses[i].toObject(centre);
    const double d = (local - local.cwiseMax(box.min).cwiseMin(box.max)).norm();
    if (d < best) {
      best = d;
      nearest = partName(i);
    }
  }
  return nearest;
}

Session::NoteMark Session::markNote() {
  NoteMark mark;
  if (loop_ && loop_->read(*snap_)) {  // the current loop's time: the recorder's clock
    mark.time_s = snap_->time_s;
    mark.part = partUnderHand(*snap_);
  }
  return mark;
}

void Session::annotate(const std::string& text) { annotate(text, markNote()); }

void Session::annotate(const std::string& text, const NoteMark& mark) {
  if (!recorder_) throw std::logic_error("not recording: recordTo() before start()");
  recorder_->annotate(mark.time_s, text, mark.part);
}

}  // namespace hg::freecad
