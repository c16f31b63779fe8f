#pragma once
// Random points on a part's surface, uniform by area, with the outward normal there: the
// test points of the benchmarks and the agreement tests.
#include <random>
#include <utility>
#include <vector>

#include "hapticgrasp/geometry/tessellation.hpp"

namespace hg::geometry {

class SurfaceSampler {
 public:
  // Samples a tessellation at `relativeDeflection` times the part's size.
  explicit SurfaceSampler(const PartModel& part, double relativeDeflection = 1e-4);
  // A point and the unit outward normal of the triangle it lies on.
  std::pair<Vec3, Vec3> sample(std::mt19937& rng) const;
  // `count` points within +/- shell_m of the surface along the normal.
  std::vector<Vec3> shell(int count, double shell_m, std::mt19937& rng) const;

 private:
  Tessellation mesh_;
  std::vector<double> cumulativeArea_;
};

}  // namespace hg::geometry
