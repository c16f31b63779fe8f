#pragma once
// The speed/accuracy ladder of the penetration back ends on one part: every back end and
// setting answers the same random points in a shell around the surface and follows the
// same coherent fingertip path, timed per query and checked against the reference.
#include <nlohmann/json.hpp>

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace hg::cli {

struct LadderOptions {
  std::string part = "block";   // sample part name or .brep/.step file
  int randomQueries = 2000;     // points in the shell
  int coherentTicks = 10000;    // ticks of the traced path
  int referenceChecks = 1000;   // path ticks also answered by the reference
  double shell_m = 5e-3;        // random points lie within +/- this of the surface
  double step_m = 5e-5;         // the path advances this much per tick
  double depth_m = 1e-3;        // and stays this deep inside the part
  unsigned seed = 1;
  int repeat = 1;  // time each query this many times (from the same state), keep the fastest
  std::vector<std::string> backends;  // only these (reference is always run: it is the truth)
};

struct Percentiles {
  double p50 = 0, p99 = 0, max = 0;
};

struct RungResult {
  std::string name, setting;
  double build_s = 0;
  std::size_t memoryBytes = 0;
  Percentiles random_us, coherent_us;
  double maxError_m = 0, rmsError_m = 0;
  int signErrors = 0;
  int queries = 0;
  // The exact back end's slower exhaustive search: queries that needed it, and queries it
  // could not settle within its budget (their answer may be off).
  int fallbackQueries = 0;
  int uncertainQueries = 0;
};

struct LadderResult {
  std::string part;
  int faces = 0;
  std::vector<RungResult> rungs;
};

LadderResult runPenetrationLadder(const LadderOptions& options, const std::function<void(const std::string&)>& log);
nlohmann::json toJson(const LadderResult& result);
void printLadder(const LadderResult& result, std::ostream& out);

}  // namespace hg::cli
