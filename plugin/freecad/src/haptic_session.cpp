#include "haptic_session.hpp"

#include <cmath>
#include <stdexcept>

#include "hapticgrasp/grasp/grasp_state.hpp"
#include "hapticgrasp/grasp/scene.hpp"

namespace hg::freecad {

geometry::PartModelPtr loadPart(const std::string& brep, const std::string& name) {
  geometry::PartModel::LoadOptions options;
  options.parallel = false;  // beside a GUI and possibly a running servo thread
  return geometry::PartModel::fromBrepText(brep, kDocumentUnit, name, options);
}

PartInfo describe(const geometry::PartModel& part, const geometry::MassSpec& mass) {
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
  return info;
}

Session::~Session() { stop(); }

int Session::addPart(const std::string& name, const std::string& brep, const Placement& placement,
                     const geometry::MassSpec& mass) {
  if (loop_) throw std::logic_error("parts must be added before start()");
  const grasp::PartPose pose = toPose(placement);
  auto model = loadPart(brep, name);
  parts_.push_back(grasp::makeScenePart(model, mass, pose));
  infos_.push_back(describe(*model, mass));
  return static_cast<int>(parts_.size()) - 1;
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
}

void Session::useHandInput(double hold_s) {
  if (loop_) throw std::logic_error("the device must be chosen before start()");
  if (!(hold_s > 0 && std::isfinite(hold_s))) throw std::invalid_argument("hand hold time must be positive");
  handHold_s_ = hold_s;
  script_.reset();
  hid_.reset();
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
}

void Session::useHid(const std::string& layoutFile, const std::string& path, const std::array<double, 3>& origin_mm) {
  if (loop_) throw std::logic_error("the device must be chosen before start()");
  auto opened = openHidLayout(layoutFile, path, toMetres(origin_mm));  // throws: nothing changed
  hid_ = std::move(opened);
  handHold_s_ = 0;
  script_.reset();
}

void Session::setHand(const std::array<double, 3>& index_mm, const std::array<double, 3>& thumb_mm,
                      const std::array<double, 3>& wrist_mm) {
  if (!input_) throw std::logic_error("no hand input device: useHandInput() and start() first");
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
  return "none";
}

bool Session::deviceForceOutput() const {
  if (handHold_s_ > 0) return HandInputDevice::defaultSpec().forceOutput;
  if (script_) return servo::ScriptedHandDevice::defaultSpec().forceOutput;
  if (hid_) return hid_->spec().forceOutput;
  return false;
}

namespace {

double* parameterField(grasp::GraspParameters& p, const std::string& name) {
  if (name == "K_c") return &p.K_c;
  if (name == "B_c") return &p.B_c;
  if (name == "K_g") return &p.K_g;
  if (name == "B_g") return &p.B_g;
  if (name == "d_h") return &p.d_h;
  if (name == "K_ox") return &p.K_ox;
  if (name == "K_oe") return &p.K_oe;
  return nullptr;
}

}  // namespace

const std::vector<std::string>& Session::parameterNames() {
  static const std::vector<std::string> names{"K_c", "B_c", "K_g", "B_g", "d_h", "K_ox", "K_oe"};
  return names;
}

void Session::setParameters(const std::vector<std::pair<std::string, double>>& values) {
  if (loop_) throw std::logic_error("parameters must be set before start()");
  grasp::GraspParameters p = parameters_;
  for (const auto& [name, value] : values) {
    double* field = parameterField(p, name);
    if (!field)
      throw std::invalid_argument("unknown grasp parameter " + name + " (known: K_c, B_c, K_g, B_g, d_h, K_ox, K_oe)");
    *field = value;
  }
  p.validate();
  parameters_ = p;
}

double Session::parameter(const std::string& name) const {
  grasp::GraspParameters p = parameters_;
  const double* field = parameterField(p, name);
  if (!field) throw std::invalid_argument("unknown grasp parameter " + name);
  return *field;
}

double Session::scriptDuration() const { return script_ ? script_->duration() : 0.0; }

void Session::start(double rate_hz, bool realtime) {
  if (loop_) throw std::logic_error("a session starts once");
  if (parts_.empty()) throw std::invalid_argument("no parts to grasp");
  std::shared_ptr<device::Device> device;
  if (handHold_s_ > 0) {
    device = input_ = std::make_shared<HandInputDevice>(handHold_s_);
  } else if (script_) {
    device = scripted_ = std::make_shared<servo::ScriptedHandDevice>(*script_);
  } else if (hid_) {
    device = hid_;
  } else {
    throw std::invalid_argument("no device: set a hand script or use the hand input first");
  }
  auto scene = std::make_shared<const grasp::Scene>(parts_);
  servo::ServoConfig config;
  config.rate_hz = rate_hz;
  config.realtime = realtime;
  loop_ = std::make_unique<servo::ServoLoop>(device, scene, parameters_, config);
  loop_->start();
}

void Session::stop() noexcept {
  if (loop_) loop_->stop();
}

SessionSnapshot Session::snapshot() {
  SessionSnapshot out;
  out.placements.reserve(parts_.size());
  if (!loop_ || !loop_->read(*snap_)) {
    for (const auto& part : parts_) out.placements.push_back(toPlacement(part.initialPose));
    return out;
  }
  const servo::ServoSnapshot& s = *snap_;
  out.tick = s.tick;
  out.time_s = s.time_s;
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
  for (int i = 0; i < s.partCount; ++i) out.placements.push_back(toPlacement(s.poses[i]));
  const auto newtons = [](const Vec3& f) { return std::array<double, 3>{f.x(), f.y(), f.z()}; };
  out.forces_N = {newtons(s.sent.f_index), newtons(s.sent.f_thumb)};
  out.graspForce_N = s.sent.f_grasp;
  out.index_mm = toMillimetres(s.hand.index);
  out.thumb_mm = toMillimetres(s.hand.thumb);
  out.wrist_mm = toMillimetres(s.hand.wrist);
  out.rate_hz = s.timing.achieved_hz;
  out.jitter_us = s.timing.periodError.p99_us;
  return out;
}

void Session::setDeviceSilent(bool silent) {
  if (scripted_) scripted_->setSilent(silent);
  else if (input_) input_->setSilent(silent);
  else if (hid_ && loop_) hid_->setSilent(silent);
  else throw std::logic_error("no device yet: start() first");
}

void Session::resetGrasp() {
  if (loop_) loop_->send(servo::ServoCommand{servo::ServoCommand::Kind::ResetGrasp, false});
}

}  // namespace hg::freecad
