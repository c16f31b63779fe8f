#include "hapticgrasp/scene/scene_build.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <stdexcept>
#include <unordered_map>

#include "hapticgrasp/geometry/backends.hpp"

namespace hg::grasp {
namespace {

std::vector<ScenePart> standIns(const std::vector<PartSource>& sources) {
  std::vector<ScenePart> parts;
  parts.reserve(sources.size());
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const PartSource& s = sources[i];
    if (s.bounds.empty() || !s.bounds.min.allFinite() || !s.bounds.max.allFinite())
      throw std::invalid_argument("scene part " + std::to_string(i) + " (" + s.name + ") has no finite box");
    parts.push_back(makeCoarseScenePart(s.bounds, s.mass, s.pose));
  }
  return parts;
}

// Background work yields to the servo and the GUI: SCHED_BATCH (never preempts on waking)
// at nice 19 (1.5% of a CPU against one busy nice-0 thread), and keeps off the servo's CPU
// when it can (backgroundCpus). Not SCHED_IDLE, which yields even to other nice-19 jobs:
// beside a nice-19 fuzzer the GUI test's five plates took 128 s to build at SCHED_IDLE, 83 s
// so (56-70 s alone); the GUI's longest stall 0.20 s and 0.16 s.
void stayInTheBackground(int avoidCpu) noexcept {
  sched_param param{};
  pthread_setschedparam(pthread_self(), SCHED_BATCH, &param);
  setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 19);  // Linux: a thread's own nice
  if (avoidCpu < 0) return;
  cpu_set_t set;
  if (pthread_getaffinity_np(pthread_self(), sizeof set, &set) != 0) return;
  const cpu_set_t use = backgroundCpus(set, avoidCpu);
  if (!CPU_EQUAL(&use, &set)) pthread_setaffinity_np(pthread_self(), sizeof use, &use);
}

}  // namespace

cpu_set_t backgroundCpus(const cpu_set_t& allowed, int avoidCpu) noexcept {
  cpu_set_t others = allowed;
  if (avoidCpu >= 0 && avoidCpu < CPU_SETSIZE) CPU_CLR(avoidCpu, &others);
  return CPU_COUNT(&others) >= 2 ? others : allowed;
}

SceneBuild::SceneBuild(std::vector<PartSource> parts, const Options& options)
    : sources_(std::move(parts)),
      backend_(options.backend),
      contact_(options.contact),
      contactOptions_(options.contactOptions),
      avoidCpu_(options.avoidCpu) {
  scenes_.push_back(std::make_shared<const Scene>(standIns(sources_)));
  std::unordered_map<std::string, std::size_t> byKey;
  modelOf_.resize(sources_.size());
  for (std::size_t i = 0; i < sources_.size(); ++i) {
    const std::string& key = sources_[i].key;
    auto found = key.empty() ? byKey.end() : byKey.find(key);
    if (found == byKey.end()) {
      models_.push_back({});
      models_.back().name = sources_[i].name;
      found = key.empty() ? byKey.end() : byKey.emplace(key, models_.size() - 1).first;
      modelOf_[i] = models_.size() - 1;
    } else {
      modelOf_[i] = found->second;
    }
    models_[modelOf_[i]].parts.push_back(i);
  }
  loaders_.resize(models_.size());
  for (std::size_t m = 0; m < models_.size(); ++m) loaders_[m] = sources_[models_[m].parts.front()].load;
  remaining_ = models_.size();
  const int workers = std::max(1, options.workers);
  for (int w = 0; w < workers && w < static_cast<int>(models_.size()); ++w) workers_.emplace_back([this] { work(); });
}

SceneBuild::~SceneBuild() {
  cancel();
  for (std::thread& t : workers_)
    if (t.joinable()) t.join();
}

ScenePtr SceneBuild::scene() const {
  std::lock_guard lock(mutex_);
  return scenes_.back();
}

void SceneBuild::setFocus(const Vec3& world_m) {
  if (!world_m.allFinite()) return;
  std::lock_guard lock(mutex_);
  focus_ = world_m;
}

double SceneBuild::distance(std::size_t m) const {
  double best = std::numeric_limits<double>::infinity();
  const Scene& scene = *scenes_.back();
  for (const std::size_t part : models_[m].parts) {
    const geometry::Aabb box = scene.part(part).initialPose.absoluteBounds(sources_[part].bounds);
    best = std::min(best, box.squaredDistance(focus_));
  }
  return best;
}

long SceneBuild::nextModel() {
  long best = -1;
  double bestDistance = std::numeric_limits<double>::infinity();
  for (std::size_t m = 0; m < models_.size(); ++m) {
    if (models_[m].status != Model::Status::Waiting || !loaders_[m]) continue;
    const double d = distance(m);
    if (best < 0 || d < bestDistance) {
      bestDistance = d;
      best = static_cast<long>(m);
    }
  }
  return best;
}

std::vector<std::size_t> SceneBuild::awaitingShapes(std::size_t limit) const {
  std::lock_guard lock(mutex_);
  std::vector<std::pair<double, std::size_t>> waiting;
  for (std::size_t m = 0; m < models_.size(); ++m)
    if (models_[m].status == Model::Status::Waiting && !loaders_[m]) waiting.emplace_back(distance(m), m);
  const std::size_t n = std::min(limit, waiting.size());
  std::partial_sort(waiting.begin(), waiting.begin() + static_cast<std::ptrdiff_t>(n), waiting.end());
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < n; ++k) out.push_back(waiting[k].second);
  return out;
}

void SceneBuild::provide(std::size_t model, std::function<geometry::PartModelPtr()> load) {
  std::lock_guard lock(mutex_);
  if (model >= models_.size()) throw std::out_of_range("no model " + std::to_string(model));
  if (loaders_[model]) throw std::logic_error("model " + std::to_string(model) + " has its shape already");
  if (!load) throw std::invalid_argument("no loader for model " + std::to_string(model));
  loaders_[model] = std::move(load);
  work_.notify_one();
}

ScenePtr SceneBuild::rebase(const std::vector<PartPose>& poses) {
  std::lock_guard lock(mutex_);
  const Scene& last = *scenes_.back();
  if (poses.size() != last.size())
    throw std::invalid_argument("rebase needs one pose per part (" + std::to_string(last.size()) + ")");
  std::vector<ScenePart> parts;
  parts.reserve(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    parts.push_back(last.part(i));
    parts.back().initialPose = poses[i];
  }
  scenes_.push_back(std::make_shared<const Scene>(std::move(parts)));
  return scenes_.back();
}

void SceneBuild::work() noexcept {
  stayInTheBackground(avoidCpu_);
  for (;;) {
    long next = -1;
    std::size_t shell = 0;
    std::function<geometry::PartModelPtr()> load;
    {
      std::unique_lock lock(mutex_);
      // Wait for a model with its shape, else a contact shell to build; done when neither
      // is waiting any more.
      work_.wait(lock, [&] {
        if (cancel_.load(std::memory_order_acquire)) return true;
        next = nextModel();
        return next >= 0 || !shellsPending_.empty() || remaining_ == running_;
      });
      if (cancel_.load(std::memory_order_acquire)) break;
      if (next >= 0) {
        models_[static_cast<std::size_t>(next)].status = Model::Status::Building;
        load = loaders_[static_cast<std::size_t>(next)];
      } else if (!shellsPending_.empty()) {
        shell = shellsPending_.front();
        shellsPending_.erase(shellsPending_.begin());
      } else {
        break;
      }
      ++running_;
    }
    if (next >= 0) buildModel(static_cast<std::size_t>(next), load);
    else buildShell(shell);
    done_.notify_all();
    work_.notify_all();  // the others may be done too
  }
  std::lock_guard lock(mutex_);
  done_.notify_all();
}

void SceneBuild::buildModel(std::size_t m, const std::function<geometry::PartModelPtr()>& load) {
  const auto start = std::chrono::steady_clock::now();
  geometry::PartModelPtr model;
  geometry::PenetrationModelPtr penetration;
  std::string error;
  try {
    model = load();
    penetration = geometry::makePenetration(model, backend_);
  } catch (const std::exception& e) {
    error = e.what();
  } catch (...) {
    error = "unknown error while building the model";
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::lock_guard lock(mutex_);
  Model& out = models_[m];
  out.build_s = seconds;
  if (penetration) {
    out.model = std::move(model);
    out.penetration = std::move(penetration);
    try {
      publish(m, true);
      out.status = Model::Status::Built;
    } catch (const std::exception& e) {  // a mass the scene refuses (an empty solid...)
      out.status = Model::Status::Failed;
      out.error = e.what();
    }
  } else {
    out.status = Model::Status::Failed;
    out.error = error;
  }
  --running_;
  // The contact shell once every model with its shape is built: the hand feels each part's
  // exact surface as soon as without contact (a 1,030-face part's shell takes seconds),
  // and a shell that fails costs the part its contact, never its model. The model stays
  // counted in remaining_ until its shell is done.
  if (contact_ && out.status == Model::Status::Built) shellsPending_.push_back(m);
  else --remaining_;
}

void SceneBuild::buildShell(std::size_t m) {
  geometry::PartModelPtr model;
  geometry::PenetrationModelPtr penetration;
  {
    std::lock_guard lock(mutex_);
    model = models_[m].model;
    penetration = models_[m].penetration;
  }
  contact::ContactModelPtr shell;
  std::string why;
  try {
    shell = contact::ContactModel::build(model, penetration, contactOptions_);
  } catch (const std::exception& e) {
    why = e.what();
  } catch (...) {
    why = "unknown error while sampling the contact shell";
  }
  std::lock_guard lock(mutex_);
  Model& built = models_[m];
  built.contact = std::move(shell);
  built.contactError = std::move(why);
  if (built.contact) {
    try {
      publish(m, false);
    } catch (const std::exception& e) {
      built.contact = nullptr;
      built.contactError = e.what();
    }
  }
  --remaining_;
  --running_;
}

// Every part of the model gets it, with the mass of its own spec (a density may differ
// between parts of one shape). Under mutex_.
void SceneBuild::publish(std::size_t m, bool first) {
  const Model& model = models_[m];
  for (const std::size_t part : model.parts) {
    ScenePart p;
    p.model = model.model;
    p.penetration = model.penetration;
    p.contact = model.contact;
    p.mass = model.model->massProperties(sources_[part].mass);
    p.bounds = model.model->bounds();
    for (const ScenePtr& scene : scenes_) scene->publish(part, p);
    if (first) ++exactParts_;
  }
}

void SceneBuild::replace(std::size_t part, ScenePart models) {
  std::lock_guard lock(mutex_);
  if (part >= sources_.size()) throw std::out_of_range("no part " + std::to_string(part));
  const bool wasExact = !scenes_.back()->part(part).coarse;
  for (const ScenePtr& scene : scenes_) scene->publish(part, models);  // validates first: throws, nothing changed
  std::vector<std::size_t>& shared = models_[modelOf_[part]].parts;
  shared.erase(std::remove(shared.begin(), shared.end(), part), shared.end());
  if (!wasExact) ++exactParts_;
}

SceneBuild::Progress SceneBuild::progress() const {
  std::lock_guard lock(mutex_);
  Progress p;
  p.parts = sources_.size();
  p.models = models_.size();
  for (const Model& m : models_) {
    p.built += m.status == Model::Status::Built;
    p.failed += m.status == Model::Status::Failed;
  }
  p.exactParts = exactParts_;
  p.finished = remaining_ == 0 || (cancel_.load(std::memory_order_acquire) && running_ == 0);
  return p;
}

std::vector<SceneBuild::Model> SceneBuild::models() const {
  std::lock_guard lock(mutex_);
  return models_;
}

bool SceneBuild::wait(double timeout_s) {
  std::unique_lock lock(mutex_);
  const auto finished = [this] { return remaining_ == 0 || (cancel_.load(std::memory_order_acquire) && running_ == 0); };
  if (timeout_s < 0) {
    done_.wait(lock, finished);
    return true;
  }
  return done_.wait_for(lock, std::chrono::duration<double>(timeout_s), finished);
}

void SceneBuild::cancel() noexcept {
  std::lock_guard lock(mutex_);
  cancel_.store(true, std::memory_order_release);
  done_.notify_all();
  work_.notify_all();
}

}  // namespace hg::grasp
