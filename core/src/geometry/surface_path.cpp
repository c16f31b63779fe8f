#include "hapticgrasp/geometry/surface_path.hpp"

namespace hg::geometry {

std::vector<Vec3> traceSurfacePath(const PenetrationModel& model, const SurfaceSampler& sampler, int ticks,
                                   double step_m, double depth_m, std::mt19937& rng) {
  std::normal_distribution<double> gauss;
  auto [start, n] = sampler.sample(rng);
  Vec3 heading = Vec3(gauss(rng), gauss(rng), gauss(rng));
  heading = (heading - heading.dot(n) * n).normalized();
  QueryState state;
  Vec3 x = start - depth_m * n;
  std::vector<Vec3> path;
  path.reserve(ticks);
  for (int i = 0; i < ticks; ++i) {
    const Penetration p = model.query(x + step_m * heading, state);
    if (p.feature == Feature::None) break;
    x = p.foot - depth_m * p.normal;
    const Vec3 along = heading - heading.dot(p.normal) * p.normal;
    if (along.norm() > 1e-6) heading = along.normalized();
    path.push_back(x);
  }
  return path;
}

}  // namespace hg::geometry
