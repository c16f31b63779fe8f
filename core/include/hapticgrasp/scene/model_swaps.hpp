#pragma once
// Follows a scene's model swaps (Scene::publish) on the servo thread, so that a grasp
// method refits the boxes of the parts whose models changed (their bounds may differ from
// the stand-in's) without a lock, and within a budget per tick: a background build
// publishing thousands of parts at once costs the servo a few microseconds per tick for a
// few ticks, never one long tick. When the scene's log has wrapped past what was followed,
// every part is refitted, the same budget per tick.
#include <algorithm>
#include <cstdint>

#include "hapticgrasp/scene/scene.hpp"

namespace hg::grasp {

class ModelSwaps {
 public:
  static constexpr std::uint64_t kBudget = 256;  // refits per tick

  ModelSwaps() = default;
  explicit ModelSwaps(const Scene& scene) noexcept : published_(scene.publications()) {}

  // Calls refit(part) for parts swapped since the last call, at most kBudget of them.
  template <class Refit>
  void follow(const Scene& scene, Refit&& refit) noexcept {
    std::uint64_t budget = kBudget;
    if (sweep_ < scene.size()) {  // a sweep over every part is under way
      const std::uint64_t end = std::min<std::uint64_t>(scene.size(), sweep_ + budget);
      for (; sweep_ < end; ++sweep_) refit(static_cast<int>(sweep_));
      return;
    }
    const std::uint64_t now = scene.publications();
    for (; published_ < now && budget > 0; ++published_, --budget) {
      const int part = scene.publishedPart(published_);
      if (part < 0) {  // the log wrapped past us: sweep every part, from the next tick
        published_ = now;
        sweep_ = 0;
        return;
      }
      refit(part);
    }
  }

 private:
  std::uint64_t published_ = 0;
  std::uint64_t sweep_ = UINT64_MAX;  // next part of a sweep; past the end: none
};

}  // namespace hg::grasp
