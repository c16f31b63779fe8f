#include "hapticgrasp/contact/contact_reduction.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hg::contact {
namespace {

// The cube-map cell of a unit normal, and the two world axes that span its face.
int groupOf(const Vec3& n, int& axisU, int& axisV) noexcept {
  int axis = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(n[i]) > std::abs(n[axis])) axis = i;
  axisU = (axis + 1) % 3;
  axisV = (axis + 2) % 3;
  const double scale = 1 / std::max(std::abs(n[axis]), 1e-12);
  const auto cell = [](double t) {
    return std::clamp(static_cast<int>((t + 1) * 0.5 * ContactReduction::kCells), 0, ContactReduction::kCells - 1);
  };
  const int face = 2 * axis + (n[axis] < 0 ? 1 : 0);
  return (face * ContactReduction::kCells + cell(n[axisU] * scale)) * ContactReduction::kCells + cell(n[axisV] * scale);
}

}  // namespace

std::size_t ContactReduction::reduce(std::span<const Contact> in, std::span<Contact> out) noexcept {
  ++calls_;
  int usedCount = 0;
  for (std::size_t j = 0; j < in.size(); ++j) {
    const Contact& c = in[j];
    int u = 0, v = 0;
    const int g = groupOf(c.normal, u, v);
    Group& group = groups_[g];
    if (group.stamp != calls_) {
      group.stamp = calls_;
      used_[usedCount++] = g;
      for (int k = 0; k < kKept; ++k) group.index[k] = static_cast<int>(j);
      group.value[0] = c.gap;
      group.value[1] = -c.point[u], group.value[2] = c.point[u];
      group.value[3] = -c.point[v], group.value[4] = c.point[v];
      continue;
    }
    // Deepest (smallest gap), then the extremes: -u, +u, -v, +v (largest of each).
    const double candidate[kKept] = {c.gap, -c.point[u], c.point[u], -c.point[v], c.point[v]};
    if (candidate[0] < group.value[0]) group.value[0] = candidate[0], group.index[0] = static_cast<int>(j);
    for (int k = 1; k < kKept; ++k)
      if (candidate[k] > group.value[k]) group.value[k] = candidate[k], group.index[k] = static_cast<int>(j);
  }
  std::size_t n = 0;
  for (int i = 0; i < usedCount; ++i) {
    const Group& group = groups_[used_[i]];
    for (int k = 0; k < kKept; ++k) {
      const int index = group.index[k];
      if (std::find(group.index, group.index + k, index) != group.index + k) continue;  // kept already
      if (n < out.size()) out[n++] = in[index];
    }
  }
  return n;
}

}  // namespace hg::contact
