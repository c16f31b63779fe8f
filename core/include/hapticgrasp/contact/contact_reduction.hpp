#pragma once
// The few contacts that decide a rigid part's motion, out of the many the point shell
// finds. A block on a floor touches it at a hundred points that all say the same: for a
// rigid part, those at the contact patch's extremes and the deepest one carry every
// constraint the others do (the others lie inside their hull, at the same gap). The
// constraint solver's work grows with its rows and their redundancy (Gauss-Seidel slows on
// near-identical rows), so contacts are grouped by normal (a cube map of 6 x 4 x 4 cells,
// ~22 deg each) and each group keeps its deepest contact and its extremes along the two
// axes of its cube face. A peg's side in its hole keeps a few rows a 22 deg sector, a
// block in a corner ten. Preallocated, no allocation.
#include <array>
#include <span>

#include "hapticgrasp/contact/contact_query.hpp"

namespace hg::contact {

class ContactReduction {
 public:
  static constexpr int kCells = 4;  // per cube-face axis
  static constexpr int kGroups = 6 * kCells * kCells;
  static constexpr int kKept = 5;  // per group: deepest, then -u, +u, -v, +v

  // Writes the kept contacts to `out` (at most out.size()); returns how many.
  std::size_t reduce(std::span<const Contact> in, std::span<Contact> out) noexcept;

 private:
  struct Group {
    int index[kKept];
    double value[kKept];
    int stamp = -1;
  };
  std::array<Group, kGroups> groups_;
  std::array<int, kGroups> used_{};
  int calls_ = 0;
};

}  // namespace hg::contact
