#include "hapticgrasp/scene/broad_phase.hpp"

#include <algorithm>
#include <numeric>

namespace hg::grasp {
namespace {

geometry::Aabb merged(const geometry::Aabb& a, const geometry::Aabb& b) noexcept {
  return {a.min.cwiseMin(b.min), a.max.cwiseMax(b.max)};
}

// A balanced tree of n leaves is at most ceil(log2 n) + 1 deep: 64 levels hold any scene.
constexpr int kMaxDepth = 64;

// Whether two boxes share a point (an empty box overlaps nothing).
bool overlap(const geometry::Aabb& a, const geometry::Aabb& b) noexcept {
  return !a.empty() && !b.empty() && (a.min.array() <= b.max.array()).all() && (b.min.array() <= a.max.array()).all();
}

}  // namespace

BroadPhase::BroadPhase(std::span<const geometry::Aabb> boxes) {
  leafOf_.assign(boxes.size(), -1);
  if (boxes.empty()) return;
  nodes_.reserve(2 * boxes.size() - 1);
  std::vector<int> items(boxes.size());
  std::iota(items.begin(), items.end(), 0);
  build(items, boxes, -1);
}

int BroadPhase::build(std::span<int> items, std::span<const geometry::Aabb> boxes, int parent) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.push_back({});
  nodes_[index].parent = parent;
  if (items.size() == 1) {
    nodes_[index].item = items[0];
    nodes_[index].box = boxes[static_cast<std::size_t>(items[0])];
    leafOf_[static_cast<std::size_t>(items[0])] = index;
    return index;
  }
  // Split at the median of the centres along their widest spread. Empty boxes (infinite
  // centres) sort to one end and hold nothing wherever they go.
  geometry::Aabb centres;
  for (const int i : items) {
    const geometry::Aabb& b = boxes[static_cast<std::size_t>(i)];
    if (!b.empty()) centres.extend(b.centre());
  }
  int axis = 0;
  if (!centres.empty()) centres.size().maxCoeff(&axis);
  const auto centre = [&](int i) {
    const geometry::Aabb& b = boxes[static_cast<std::size_t>(i)];
    return b.empty() ? 0.0 : b.centre()[axis];
  };
  const std::size_t half = items.size() / 2;
  std::nth_element(items.begin(), items.begin() + static_cast<std::ptrdiff_t>(half), items.end(),
                   [&](int a, int b) { return centre(a) < centre(b); });
  const int left = build(items.first(half), boxes, index);
  const int right = build(items.subspan(half), boxes, index);
  Node& node = nodes_[index];
  node.left = left;
  node.right = right;
  node.box = merged(nodes_[left].box, nodes_[right].box);
  return index;
}

void BroadPhase::update(std::size_t item, const geometry::Aabb& box) noexcept {
  if (item >= leafOf_.size()) return;
  int n = leafOf_[item];
  nodes_[n].box = box;
  for (n = nodes_[n].parent; n >= 0; n = nodes_[n].parent)
    nodes_[n].box = merged(nodes_[nodes_[n].left].box, nodes_[nodes_[n].right].box);
}

template <class Enters>
std::size_t BroadPhase::collect(Enters enters, std::span<int> out) const noexcept {
  if (nodes_.empty()) return 0;
  std::size_t found = 0;
  int stack[kMaxDepth];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (!enters(node.box)) continue;
    if (node.item >= 0) {
      if (found < out.size()) out[found] = node.item;
      ++found;
    } else {
      stack[top++] = node.left;
      stack[top++] = node.right;
    }
  }
  return found;
}

std::size_t BroadPhase::query(const Vec3& x, std::span<int> out) const noexcept {
  return collect([&](const geometry::Aabb& b) { return b.contains(x); }, out);
}

std::size_t BroadPhase::overlapping(const geometry::Aabb& box, std::span<int> out) const noexcept {
  if (box.empty()) return 0;
  return collect([&](const geometry::Aabb& b) { return overlap(b, box); }, out);
}

}  // namespace hg::grasp
