#include "penetration_ladder.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/geometry/sample_parts.hpp"
#include "hapticgrasp/geometry/surface_path.hpp"
#include "hapticgrasp/geometry/surface_sampler.hpp"
#include "hapticgrasp/geometry/tessellation.hpp"
#include "hapticgrasp/geometry/winding_number.hpp"

namespace hg::cli {
namespace {

using namespace hg::geometry;
using Clock = std::chrono::steady_clock;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

Percentiles percentiles(std::vector<double> v) {
  if (v.empty()) return {};
  std::sort(v.begin(), v.end());
  return {v[v.size() / 2], v[static_cast<std::size_t>(0.99 * (v.size() - 1))], v.back()};
}

struct Answers {
  std::vector<Penetration> random, coherent;
};

// Times each query on its own. steady_clock costs ~20 ns a call here: it is in the figures.
// With repeat > 1 each query runs that many times from the same starting state and the
// fastest counts: on a shared machine that removes preemption, not algorithmic cost.
template <class Query>
std::vector<double> timeQueries(const std::vector<Vec3>& points, int repeat, QueryState& state, Query&& query,
                                std::vector<Penetration>& answers) {
  std::vector<double> us;
  us.reserve(points.size());
  answers.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const QueryState start = state;
    double best = INFINITY;
    for (int r = 0; r < repeat; ++r) {
      state = start;
      const auto t0 = Clock::now();
      answers[i] = query(points[i], state);
      best = std::min(best, 1e6 * seconds(Clock::now() - t0));
    }
    us.push_back(best);
  }
  return us;
}

struct Rung {
  std::string label;
  std::function<PenetrationModelPtr()> make;
  double signTolerance_m;  // a sign disagreement closer to the surface than this is no error
};

std::vector<Rung> rungsFor(const PartModelPtr& part) {
  std::vector<Rung> rungs{{"reference", [part] { return makeReferencePenetration(part); }, 1e-9},
                          {"exact", [part] { return makeExactPenetration(part); }, 1e-9}};
  if (part->primitive().kind != Primitive::Kind::None)
    rungs.push_back({"analytic", [part] { return makeAnalyticPenetration(part); }, 1e-9});
  for (const double deflection : {1e-4, 1e-5})
    rungs.push_back({"mesh", [part, deflection] { return makeMeshPenetration(part, deflection); }, 2 * deflection});
  // The sign a part whose faces cross gets: what the winding number costs over pseudo-normals.
  rungs.push_back({"mesh", [part] { return makeMeshPenetration(part, 1e-5, MeshSign::WindingNumber); }, 2e-5});
  for (const double voxel : {1e-3, 5e-4})
    rungs.push_back({"field", [part, voxel] { return makeFieldPenetration(part, voxel); }, 2 * voxel});
  return rungs;
}

void measureErrors(const Answers& truth, const Answers& answers, std::size_t checkEvery, double signTolerance,
                   RungResult& r) {
  double sum2 = 0;
  int n = 0;
  auto check = [&](const Penetration& t, const Penetration& a) {
    if (t.feature == Feature::None) return;
    const double e = std::abs(t.depth - a.depth);
    r.maxError_m = std::max(r.maxError_m, e);
    sum2 += e * e;
    ++n;
    if (t.inside != a.inside && std::abs(t.depth) > signTolerance) ++r.signErrors;
  };
  for (std::size_t i = 0; i < truth.random.size(); ++i) check(truth.random[i], answers.random[i]);
  for (std::size_t i = 0; i < truth.coherent.size(); ++i)
    check(truth.coherent[i], answers.coherent[i * checkEvery]);
  r.rmsError_m = n ? std::sqrt(sum2 / n) : 0;
}

// Where a part's faces cross, the reference's ray parity calls a point enclosed twice
// outside: inside is what the part encloses at all, its winding number above 1/2, summed
// exactly over every triangle of a 0.01 mm mesh. The reference keeps its distances.
void signByWindingNumber(const PartModel& part, const std::vector<Vec3>& random, const std::vector<Vec3>& checked,
                         Answers& truth) {
  const Tessellation mesh = tessellate(part, 1e-5);
  const WindingNumber winding(mesh.vertices, mesh.triangles);
  auto resign = [&](const std::vector<Vec3>& points, std::vector<Penetration>& answers) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      Penetration& t = answers[i];
      t.inside = winding.exact(points[i]) > 0.5;
      t.depth = t.inside ? t.distance() : -t.distance();
    }
  };
  resign(random, truth.random);
  resign(checked, truth.coherent);
}

}  // namespace

LadderResult runPenetrationLadder(const LadderOptions& o, const std::function<void(const std::string&)>& log) {
  const SamplePart sample = findPart(o.part);
  const PartModelPtr part = PartModel::fromFile(sample.file, sample.unit);
  LadderResult result{sample.name, part->faces().Extent(), {}};
  std::mt19937 rng(o.seed);
  const SurfaceSampler sampler(*part);
  const std::vector<Vec3> random = sampler.shell(o.randomQueries, o.shell_m, rng);
  const std::vector<Vec3> path =
      traceSurfacePath(*makeExactPenetration(part), sampler, o.coherentTicks, o.step_m, o.depth_m, rng);
  const std::size_t checkEvery = std::max<std::size_t>(1, path.size() / std::max(1, o.referenceChecks));
  std::vector<Vec3> checked;
  for (std::size_t i = 0; i < path.size(); i += checkEvery) checked.push_back(path[i]);

  Answers truth;
  for (const Rung& rung : rungsFor(part)) {
    if (rung.label != "reference" && !o.backends.empty() &&
        std::find(o.backends.begin(), o.backends.end(), rung.label) == o.backends.end())
      continue;
    log("  " + rung.label + " ...");
    RungResult r;
    const auto t0 = Clock::now();
    PenetrationModelPtr model;
    try {
      model = rung.make();
    } catch (const GeometryError& e) {
      log("  " + rung.label + " skipped: " + e.what());
      continue;
    }
    r.build_s = seconds(Clock::now() - t0);
    r.name = std::string(model->name());
    r.setting = model->setting();
    r.memoryBytes = model->memoryBytes();
    Answers answers;
    const bool isReference = truth.random.empty();
    const int repeat = isReference ? 1 : o.repeat;
    QueryState cold;
    r.random_us = percentiles(timeQueries(random, repeat, cold, [&](const Vec3& x, QueryState& s) {
      s.reset();
      return model->query(x, s);
    }, answers.random));
    // The reference follows only the checked ticks (it is slow); the others the whole path.
    QueryState warm;
    r.coherent_us = percentiles(timeQueries(isReference ? checked : path, repeat, warm,
                                            [&](const Vec3& x, QueryState& s) { return model->query(x, s); },
                                            answers.coherent));
    r.queries = static_cast<int>(answers.random.size() + answers.coherent.size());
    for (const auto* list : {&answers.random, &answers.coherent})
      for (const Penetration& p : *list) {
        r.fallbackQueries += p.fallbacks > 0;
        r.uncertainQueries += !p.certain;
      }
    if (isReference) {
      truth = answers;
      if (part->backendChoice().surfaceMayCross) {
        log("  sign truth: the winding number of a 0.01 mm mesh (the part's faces cross)");
        signByWindingNumber(*part, random, checked, truth);
      }
    }
    measureErrors(truth, answers, isReference ? 1 : checkEvery, rung.signTolerance_m, r);
    result.rungs.push_back(r);
  }
  return result;
}

nlohmann::json toJson(const LadderResult& result) {
  nlohmann::json backends = nlohmann::json::array();
  for (const RungResult& r : result.rungs)
    backends.push_back({{"name", r.name},
                        {"setting", r.setting},
                        {"build_s", r.build_s},
                        {"memory_bytes", r.memoryBytes},
                        {"random", {{"p50_us", r.random_us.p50}, {"p99_us", r.random_us.p99}}},
                        {"coherent", {{"p50_us", r.coherent_us.p50}, {"p99_us", r.coherent_us.p99}}},
                        {"max_dist_err_m", r.maxError_m},
                        {"rms_dist_err_m", r.rmsError_m},
                        {"sign_errors", r.signErrors},
                        {"queries", r.queries},
                        {"fallback_queries", r.fallbackQueries},
                        {"uncertain_queries", r.uncertainQueries}});
  return {{"part", result.part}, {"faces", result.faces}, {"backends", backends}};
}

void printLadder(const LadderResult& result, std::ostream& out) {
  char line[256];
  out << "part " << result.part << ": " << result.faces << " faces\n";
  std::snprintf(line, sizeof line, "%-10s %-38s %9s %10s %20s %20s %10s %10s %6s %9s %9s\n", "back end", "setting",
                "build s", "memory KiB", "random p50/p99 us", "coherent p50/p99 us", "max err m", "rms err m", "sign",
                "vs ref", "fallback");
  out << line;
  const double reference = result.rungs.empty() ? 0 : result.rungs.front().random_us.p50;
  for (const RungResult& r : result.rungs) {
    char random[32], coherent[32];
    std::snprintf(random, sizeof random, "%.2f / %.2f", r.random_us.p50, r.random_us.p99);
    std::snprintf(coherent, sizeof coherent, "%.2f / %.2f", r.coherent_us.p50, r.coherent_us.p99);
    char fallback[32];
    std::snprintf(fallback, sizeof fallback, "%.2f%%", 100.0 * r.fallbackQueries / std::max(1, r.queries));
    std::snprintf(line, sizeof line, "%-10s %-38s %9.3f %10.0f %20s %20s %10.1e %10.1e %6d %8.0fx %9s\n", r.name.c_str(),
                  r.setting.c_str(), r.build_s, r.memoryBytes / 1024.0, random, coherent, r.maxError_m, r.rmsError_m,
                  r.signErrors, reference / std::max(r.random_us.p50, 1e-9), fallback);
    out << line;
  }
}

}  // namespace hg::cli
