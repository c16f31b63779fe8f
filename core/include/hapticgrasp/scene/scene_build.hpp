#pragma once
// A scene touchable at once, its models built in the background, nearest the hand first.
//
// The constructor makes the scene of coarse stand-ins (each part's bounding box, from the
// shape, in closed form: makeCoarseScenePart) and returns: the servo may start on it. Worker
// threads then build each distinct shape's model once (parts with the same key share one
// immutable PartModel and penetration back end) and publish it to every part of that shape
// (Scene::publish: the servo picks it up without a lock). The next model a worker takes is
// the one whose nearest part is nearest the focus (setFocus: the hand), so the part under
// the hand is exact first, and the order follows the hand as it moves.
// With contact, each model's contact shell comes once every model whose shape has come is
// built (the exact surfaces are felt first), published after its model.
//
// Workers run at SCHED_BATCH, nice 19: they take what the servo thread and the GUI leave.
// They keep off the servo thread's CPU when it is pinned (avoidCpu) and two others remain
// (backgroundCpus).
// Never touched by the servo thread.
#include <sched.h>

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "hapticgrasp/contact/contact_model.hpp"
#include "hapticgrasp/geometry/backend.hpp"
#include "hapticgrasp/geometry/mass_properties.hpp"
#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/scene/scene.hpp"

namespace hg::grasp {

// The CPUs background work may use, of `allowed`: all but the servo thread's `avoidCpu` when
// at least two others remain, else all of them. With one left it shares that one with
// FreeCAD's drawing (its GUI thread and the software renderer's threads) and whatever else
// runs, and in the background gets next to nothing there: at SCHED_IDLE five 1,030-face
// plates took 66 s, 87 s and twice over 300 s to build in the GUI beside another FreeCAD on
// this 2-CPU machine. On the servo's CPU it takes what the SCHED_FIFO servo leaves (about
// 94% at 2 kHz), and the servo preempts it.
cpu_set_t backgroundCpus(const cpu_set_t& allowed, int avoidCpu) noexcept;

// One part of a scene before its model exists.
struct PartSource {
  std::string name;
  std::string key;          // parts with the same non-empty key share one model; "" shares nothing
  geometry::Aabb bounds;    // object frame, metres: the stand-in until the model is in
  PartPose pose;
  geometry::MassSpec mass;
  // Builds the part's model (on a worker; may throw). Parts sharing a key share the first's.
  // Empty: the shape comes later (SceneBuild::provide), as the caller can export it (the
  // workbench exports BREP text on the GUI thread, a few parts per tick, nearest first).
  std::function<geometry::PartModelPtr()> load;
};

class SceneBuild {
 public:
  struct Options {
    int workers = 1;
    geometry::Backend backend = geometry::Backend::Auto;
    int avoidCpu = -1;  // the servo thread's CPU (ServoConfig::cpu): the workers run on the others
    // Part-to-part contact: each model also gets its contact shell (ScenePart::contact).
    // A shell that fails leaves the part without contact (contactError says why), never
    // without its model.
    bool contact = false;
    contact::ContactModelOptions contactOptions;
  };
  // One distinct model and what became of it.
  struct Model {
    std::string name;                 // its first part's
    std::vector<std::size_t> parts;   // the parts that share it
    enum class Status { Waiting, Building, Built, Failed } status = Status::Waiting;
    std::string error;                // Failed: why (the parts keep their stand-in)
    geometry::PartModelPtr model;     // Built
    geometry::PenetrationModelPtr penetration;
    contact::ContactModelPtr contact;  // with Options::contact
    std::string contactError;          // why it has none, when it should have one
    double build_s = 0;
  };
  struct Progress {
    std::size_t parts = 0, models = 0;
    std::size_t built = 0, failed = 0;  // models
    std::size_t exactParts = 0;         // parts answered by their own model
    bool finished = false;              // every model built or failed, or cancelled
  };

  // Throws std::invalid_argument (a part without a finite box) before any thread starts.
  explicit SceneBuild(std::vector<PartSource> parts, const Options& options);
  explicit SceneBuild(std::vector<PartSource> parts) : SceneBuild(std::move(parts), Options{}) {}
  ~SceneBuild();  // cancels and joins (a model being built is finished first)
  SceneBuild(const SceneBuild&) = delete;
  SceneBuild& operator=(const SceneBuild&) = delete;

  // The scene the servo runs on (the latest rebase()).
  ScenePtr scene() const;
  void setFocus(const Vec3& world_m);
  // The models still waiting for their shape, nearest the focus first (at most `limit`).
  std::vector<std::size_t> awaitingShapes(std::size_t limit) const;
  // Model m's loader (its shape has come); throws std::logic_error if it had one.
  void provide(std::size_t model, std::function<geometry::PartModelPtr()> load);
  // A new scene with the same parts and their current models, standing at `poses` (a
  // servo restarted with the parts where the document has them); later models are
  // published to it too. Throws std::invalid_argument for a wrong count.
  ScenePtr rebase(const std::vector<PartPose>& poses);
  // Part i's shape changed (an edit): it leaves its shared model and gets `models` (built
  // by the caller) in every scene, from the servo's next tick; the build never publishes
  // its old shape's model to it again. Throws what Scene::publish throws.
  void replace(std::size_t part, ScenePart models);
  Progress progress() const;
  std::vector<Model> models() const;
  // The model index of part i.
  std::size_t modelOf(std::size_t part) const { return modelOf_.at(part); }
  bool wait(double timeout_s = -1);
  void cancel() noexcept;

 private:
  void work() noexcept;
  long nextModel();  // under mutex_: the waiting model with a loader nearest the focus, -1 if none
  double distance(std::size_t model) const;  // under mutex_: of its nearest part to the focus
  void buildModel(std::size_t model, const std::function<geometry::PartModelPtr()>& load);
  void buildShell(std::size_t model);
  void publish(std::size_t model, bool first);  // first: the model (counts its parts exact); else its contact shell after it

  std::vector<PartSource> sources_;
  std::vector<std::size_t> modelOf_;
  std::vector<ScenePtr> scenes_;  // every scene made (rebase()); the last is the servo's
  std::vector<std::function<geometry::PartModelPtr()>> loaders_;  // per model; empty: awaiting its shape
  mutable std::mutex mutex_;
  std::condition_variable done_, work_;
  std::vector<Model> models_;
  Vec3 focus_ = Vec3::Zero();
  std::size_t remaining_ = 0, exactParts_ = 0, running_ = 0;
  geometry::Backend backend_;
  bool contact_ = false;
  std::vector<std::size_t> shellsPending_;  // models built whose contact shell is to come
  contact::ContactModelOptions contactOptions_;
  std::atomic<bool> cancel_{false};
  int avoidCpu_ = -1;
  std::vector<std::thread> workers_;
};

}  // namespace hg::grasp
