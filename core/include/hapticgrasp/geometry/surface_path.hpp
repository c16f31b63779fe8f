#pragma once
// A fingertip tracing a part's surface: the coherent path of the benchmarks and the
// agreement tests. It keeps `depth_m` inside and moves `step_m` per tick along the tangent
// plane, so it runs over edges, down fillets and into holes.
#include <random>
#include <vector>

#include "hapticgrasp/geometry/penetration.hpp"
#include "hapticgrasp/geometry/surface_sampler.hpp"

namespace hg::geometry {

// Up to `ticks` points, starting at a random surface point; `model` finds the surface as
// the path goes (it stops early where the model loses it).
std::vector<Vec3> traceSurfacePath(const PenetrationModel& model, const SurfaceSampler& sampler, int ticks,
                                   double step_m, double depth_m, std::mt19937& rng);

}  // namespace hg::geometry
