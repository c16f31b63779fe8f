#pragma once
// A servo session stepped without a thread (deterministic), for the recorder, replay and
// review tests: the bench's scripted hand read at the time step() is given, 2 kHz.
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "hapticgrasp/servo/scripted_hand_device.hpp"
#include "hapticgrasp/servo/servo_bench.hpp"
#include "hapticgrasp/servo/servo_loop.hpp"
#include "hapticgrasp/session/recorder.hpp"
#include "hapticgrasp/session/session_description.hpp"
#include "temp_dir.hpp"

namespace hg::session::test {

// A folder for this test process's files, removed when it exits (temp_dir.hpp).
inline std::filesystem::path tempDir(const std::string& what) { return hg::test::processTempDir(what); }

inline SessionDescription describeBench(const grasp::Scene& scene, const device::DeviceSpec& spec, double rate_hz) {
  SessionDescription d;
  d.software = "hapticgrasp test";
  d.build = softwareBuild();
  d.rate_hz = rate_hz;
  d.device = spec;
  d.scenePublications = scene.publications();
  d.parts = describeParts(scene);
  return d;
}

// The bench's scripted hand at the time step() is given (no thread, deterministic).
class ClockedHand final : public device::Device {
 public:
  const device::DeviceSpec& spec() const noexcept override { return spec_; }
  bool read(device::DeviceSample& s) noexcept override {
    s.hand = script_.at(now_s);
    return true;
  }
  void write(const device::DeviceCommand&) noexcept override {}
  double now_s = 0;

 private:
  grasp::HandScript script_ = servo::benchScript();
  device::DeviceSpec spec_ = servo::ScriptedHandDevice::defaultSpec();
};

// The loop stepped at 2 kHz on the clocked hand over `scene` (the bench's cylinder by default).
struct SteppedLoop {
  explicit SteppedLoop(grasp::ScenePtr s = servo::benchScene()) : scene(std::move(s)) {}
  std::shared_ptr<ClockedHand> device = std::make_shared<ClockedHand>();
  grasp::ScenePtr scene;
  servo::ServoLoop loop{device, scene, {}, [] {
                          servo::ServoConfig c;
                          c.realtime = false;
                          return c;
                        }()};
  SessionDescription description() const { return describeBench(*scene, device->spec(), 2000); }
  // Ticks [from, to); every `pauseEvery` ticks the writer gets a few milliseconds.
  void run(int from, int to, int pauseEvery = 0) {
    for (int k = from; k < to; ++k) {
      device->now_s = k * 0.0005;
      loop.step(k * 0.0005, k ? 0.0005 : 0.0);
      if (pauseEvery && k % pauseEvery == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
};

// What the workbench does: the servo starts on a stand-in box and the part's own model is
// published while it runs. Here the stand-in is the cylinder's box grown 5 mm on every side
// and the cylinder comes in at 0.05 s, before the fingers close (20 mm clear): a replay
// that missed the swap would feel the box 5 mm early and differ. Then the bench script's
// grasp, lift and put-down, 3 s in all, recorded into `file`.
inline void recordSwappedSession(const std::string& file) {
  const grasp::ScenePart cylinder = servo::benchScene()->part(0);
  geometry::Aabb grown = cylinder.bounds;
  grown.min -= Vec3::Constant(0.005);
  grown.max += Vec3::Constant(0.005);
  std::vector<grasp::ScenePart> coarse;
  coarse.push_back(grasp::makeCoarseScenePart(grown, geometry::MassSpec::mass(cylinder.mass.mass_kg), cylinder.initialPose));
  const auto scene = std::make_shared<const grasp::Scene>(std::move(coarse));
  SteppedLoop session(scene);
  Recorder recorder(file, session.description(), scene);
  session.loop.record(recorder.ring());
  recorder.start();
  session.run(0, 100);
  scene->publish(0, cylinder);
  session.run(100, 6000);
  recorder.stop();
}

}  // namespace hg::session::test
