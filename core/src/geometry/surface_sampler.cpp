#include "hapticgrasp/geometry/surface_sampler.hpp"

#include <algorithm>

namespace hg::geometry {

SurfaceSampler::SurfaceSampler(const PartModel& part, double relativeDeflection)
    : mesh_(tessellate(part, relativeDeflection * part.characteristicLength())) {
  double total = 0;
  for (const auto& t : mesh_.triangles) {
    total += (mesh_.vertices[t[1]] - mesh_.vertices[t[0]]).cross(mesh_.vertices[t[2]] - mesh_.vertices[t[0]]).norm();
    cumulativeArea_.push_back(total);
  }
}

std::pair<Vec3, Vec3> SurfaceSampler::sample(std::mt19937& rng) const {
  std::uniform_real_distribution<double> unit(0, 1);
  const auto it = std::lower_bound(cumulativeArea_.begin(), cumulativeArea_.end(), unit(rng) * cumulativeArea_.back());
  const auto& t = mesh_.triangles[std::min<std::size_t>(it - cumulativeArea_.begin(), mesh_.triangles.size() - 1)];
  double a = unit(rng), b = unit(rng);
  if (a + b > 1) a = 1 - a, b = 1 - b;  // fold the square onto the triangle
  const Vec3& p0 = mesh_.vertices[t[0]];
  const Vec3 e1 = mesh_.vertices[t[1]] - p0, e2 = mesh_.vertices[t[2]] - p0;
  return {p0 + a * e1 + b * e2, e1.cross(e2).normalized()};
}

std::vector<Vec3> SurfaceSampler::shell(int count, double shell_m, std::mt19937& rng) const {
  std::uniform_real_distribution<double> offset(-shell_m, shell_m);
  std::vector<Vec3> points;
  points.reserve(count);
  for (int i = 0; i < count; ++i) {
    const auto [p, n] = sample(rng);
    points.push_back(p + offset(rng) * n);
  }
  return points;
}

}  // namespace hg::geometry
