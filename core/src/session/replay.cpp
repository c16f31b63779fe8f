#include "hapticgrasp/session/replay.hpp"

#include <BinTools.hxx>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "hapticgrasp/geometry/backend.hpp"
#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/session/mcap_reader.hpp"
#include "hapticgrasp/session/model_swap_message.hpp"
#include "hapticgrasp/session/recorder.hpp"
#include "hapticgrasp/session/recording.hpp"
#include "hapticgrasp/session/tick_message.hpp"

namespace hg::session {
namespace {

// Plays the recorded samples back: read() gives the tick's sample exactly when the
// original device gave one, so the watchdog sees the same silences and NaNs.
class RecordedDevice final : public device::Device {
 public:
  explicit RecordedDevice(device::DeviceSpec spec) : spec_(std::move(spec)) {}
  const device::DeviceSpec& spec() const noexcept override { return spec_; }
  bool read(device::DeviceSample& sample) noexcept override {
    if (!next_ || !next_->freshSample) return false;
    sample = next_->sample;
    return true;
  }
  void write(const device::DeviceCommand& command) noexcept override { written_ = command; }
  const servo::TickRecord* next_ = nullptr;
  device::DeviceCommand written_;

 private:
  device::DeviceSpec spec_;
};

double forceDiff(const device::DeviceCommand& a, const device::DeviceCommand& b) {
  double d = std::max({(a.f_index - b.f_index).norm(), (a.f_thumb - b.f_thumb).norm(), (a.f_wrist - b.f_wrist).norm(),
                       (a.m_wrist - b.m_wrist).norm(), std::abs(a.f_grasp - b.f_grasp)});
  for (int k = 0; k < grasp::HandSample::kMaxFingertips - 2; ++k) d = std::max(d, (a.f_extra[k] - b.f_extra[k]).norm());
  return std::isnan(d) ? std::numeric_limits<double>::infinity() : d;
}

grasp::ScenePart rebuildPart(const RecordedPart& p, const SessionDescription& d) {
  const geometry::MassSpec mass = geometry::MassSpec::mass(p.mass.mass_kg);
  grasp::ScenePart part;
  if (p.coarse || p.brep.empty()) {
    part = grasp::makeCoarseScenePart(p.bounds, mass, p.initialPose);
  } else {
    TopoDS_Shape shape;
    std::istringstream in(p.brep, std::ios::binary);
    try {
      BinTools::Read(shape, in);
    } catch (const Standard_Failure& e) {
      const std::string why = e.GetMessageString();
      throw SessionError("part '" + p.name + "': its attached BREP does not read: " +
                         (why.empty() ? std::string(e.DynamicType()->Name()) : why));
    }
    const auto model = geometry::PartModel::fromShape(shape, p.unit, p.name);
    const geometry::Backend backend = p.backend == "box" ? geometry::Backend::Auto : geometry::parseBackend(p.backend);
    part = grasp::makeScenePart(model, mass, p.initialPose, backend);
    if (d.contact) part.contact = contact::ContactModel::build(part.model, part.penetration, d.contactModel);
  }
  part.mass = p.mass;  // as recorded, to the bit
  return part;
}

// One recorded tick through the loop's stages, with the commands the GUI had sent, and
// what came out compared with what was recorded.
void stepOne(servo::ServoLoop& loop, RecordedDevice& device, const servo::TickRecord& r, servo::ServoSnapshot& out,
             ReplayCheck& check) {
  if (r.commands & servo::kCommandReset) loop.send({servo::ServoCommand::Kind::ResetGrasp, false});
  if (r.commands & servo::kCommandPassivityOn) loop.send({servo::ServoCommand::Kind::SetPassivityController, true});
  if (r.commands & servo::kCommandPassivityOff) loop.send({servo::ServoCommand::Kind::SetPassivityController, false});
  device.next_ = &r;
  loop.step(r.time_s, r.dt_s);
  loop.read(out);
  ++check.ticks;
  bool mismatch = false;
  if (out.state != r.state) {
    ++check.stateMismatches;
    mismatch = true;
  }
  if (out.events != r.events) {
    ++check.eventMismatches;
    mismatch = true;
  }
  const double force = std::max(forceDiff(out.sent, r.sent), forceDiff(out.raw, r.raw));
  check.maxForceDiff_N = std::max(check.maxForceDiff_N, force);
  double pose = out.movingCount == r.movingCount ? 0.0 : std::numeric_limits<double>::infinity();
  for (int k = 0; k < std::min({out.movingCount, r.movingCount, servo::TickRecord::kMaxMoving}); ++k) {
    if (out.moving[k].part != r.movingPart[k]) pose = std::numeric_limits<double>::infinity();
    pose = std::max(pose, (out.moving[k].pose.position - r.movingPose[k].position).norm());
  }
  check.maxPoseDiff_m = std::max(check.maxPoseDiff_m, pose);
  mismatch |= force != 0 || pose != 0;
  if (mismatch && check.firstMismatchTick == 0) check.firstMismatchTick = r.tick;
}

}  // namespace

grasp::ScenePtr rebuildScene(const SessionDescription& d) {
  std::vector<grasp::ScenePart> parts;
  parts.reserve(d.parts.size());
  for (const RecordedPart& p : d.parts) parts.push_back(rebuildPart(p, d));
  return std::make_shared<const grasp::Scene>(std::move(parts));
}

std::unique_ptr<servo::GraspEngine> rebuildEngine(const SessionDescription& d, grasp::ScenePtr scene) {
  std::optional<contact::CarriedContactConfig> contact;
  if (d.contact) contact = d.contactConfig;
  if (d.method == "two-finger") return std::make_unique<servo::TwoFingerEngine>(std::move(scene), d.twoFinger, contact);
  if (d.method == "multi-finger")
    return std::make_unique<servo::MultiFingerEngine>(std::move(scene), d.fingertips, d.multiFinger, contact);
  throw SessionError("recording: unknown grasp method '" + d.method + "'");
}

// The description and the parts' BREPs come first in a recording (before any chunk): the
// scene is built at the first tick message, then each tick is stepped as it streams by.
ReplayCheck replay(const std::string& path,
                   const std::function<void(const servo::TickRecord&, const servo::ServoSnapshot&)>& onTick) {
  McapReader reader(path);
  ReplayCheck check;
  std::optional<SessionDescription> description;
  std::shared_ptr<RecordedDevice> device;
  std::unique_ptr<servo::ServoLoop> loop;
  std::uint16_t tickChannel = 0, modelChannel = 0;
  servo::TickRecord record;
  servo::ServoSnapshot snapshot;
  grasp::ScenePtr scene;
  // Models published during the session, each applied before the first tick that saw it.
  struct Pending {
    std::uint64_t publication;
    int part;
    grasp::ScenePart models;
  };
  std::vector<Pending> pending;

  const auto setUp = [&] {
    description = readDescription(reader);
    if (description->build != softwareBuild())
      check.warnings.push_back("recorded by " + description->software + " (" + description->build +
                               "), replayed by " + softwareBuild() + ": results may differ in the last bits");
    device = std::make_shared<RecordedDevice>(description->device);
    servo::ServoConfig config;
    config.rate_hz = description->rate_hz;
    config.realtime = false;
    config.watchdogRamp_s = description->watchdogRamp_s;
    config.passivityController = description->passivityController;
    // The description is the file's: a value the loop, the engine or a part's model refuses
    // (a watchdog ramp of 5 s, found by fuzz_recording) is a recording that does not replay.
    try {
      scene = rebuildScene(*description);
      loop = std::make_unique<servo::ServoLoop>(device, rebuildEngine(*description, scene), config);
    } catch (const std::invalid_argument& e) {
      throw SessionError(std::string("recording: its session cannot be rebuilt: ") + e.what());
    } catch (const geometry::GeometryError& e) {
      throw SessionError(std::string("recording: its session cannot be rebuilt: ") + e.what());
    }
    for (const auto& [id, channel] : reader.channels()) {
      if (channel.topic == kTickTopic) tickChannel = id;
      if (channel.topic == kModelTopic) modelChannel = id;
    }
  };
  const auto publishSeen = [&](const servo::TickRecord& r) {
    auto seen = std::stable_partition(pending.begin(), pending.end(),
                                      [&](const Pending& p) { return p.publication < r.scenePublications; });
    for (auto it = pending.begin(); it != seen; ++it) scene->publish(static_cast<std::size_t>(it->part), std::move(it->models));
    pending.erase(pending.begin(), seen);
  };

  const McapSummary summary = reader.scan(
      [&](const McapMessageView& m) {
        if (!loop) setUp();
        if (m.channel == modelChannel && modelChannel != 0) {
          ModelSwap swap = decodeModelSwap(m.data);
          if (swap.part < 0 || static_cast<std::size_t>(swap.part) >= scene->size())
            throw SessionError("model swap for part " + std::to_string(swap.part) + " of " +
                               std::to_string(scene->size()));
          pending.push_back({swap.publication, swap.part, rebuildPart(swap.model, *description)});
          return;
        }
        if (m.channel != tickChannel) return;
        if (!decodeTick(m.data, record)) {
          check.warnings.push_back("tick at " + std::to_string(m.logTime_ns) + " ns does not decode; replay stops");
          return;
        }
        publishSeen(record);
        stepOne(*loop, *device, record, snapshot, check);
        if (onTick) onTick(record, snapshot);
      },
      /*attachmentData=*/true);
  check.complete = summary.complete;
  for (const std::string& w : summary.warnings) check.warnings.push_back(w);
  if (!loop) throw SessionError(path + ": no ticks recorded");
  return check;
}

std::string toJson(const ReplayCheck& c, int indent) {
  // JSON has no infinity: a structural mismatch (a part moving in one run and not the
  // other) is written as null.
  const auto finite = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  return nlohmann::json{{"ticks", c.ticks},
                        {"state_mismatches", c.stateMismatches},
                        {"event_mismatches", c.eventMismatches},
                        {"max_force_diff_N", finite(c.maxForceDiff_N)},
                        {"max_pose_diff_m", finite(c.maxPoseDiff_m)},
                        {"first_mismatch_tick", c.firstMismatchTick},
                        {"complete", c.complete},
                        {"warnings", c.warnings}}
      // Warnings quote the file (its software string...): not always UTF-8 (fuzz_recording).
      .dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace hg::session
