#pragma once
// `hapticgrasp experiment peg-in-hole`: part-to-part contact from the exact B-rep (issue
// 15). A scripted hand carries a steel peg (10 mm, 40 mm long) into a block's hole 0.1 mm
// wider than the peg, its rim chamfered 0.5 mm, starting 0.3 mm off the axis and tilted
// 0.1 deg; then strikes a 0.5 mm plate with the peg at 1 m/s and pushes on through the
// plate's place by 20 mm. The peg is held through the 6-DOF virtual coupling
// (contact/virtual_coupling.hpp) at the servo rate; each tick's compute is timed.
// `hapticgrasp bench contact` times the same machinery on a real ~500-face part.
#include <nlohmann/json.hpp>
#include <string>

namespace hg::cli {

struct PegInHoleResult {
  struct Insertion {
    bool inserted = false;
    double clearance_m = 0;        // the fit's diametral clearance
    double depth_m = 0;            // how deep the peg's end went below the block's top face
    double max_penetration_m = 0;  // deepest interpenetration of any tick
    double max_force_N = 0;        // largest coupling force on the hand
    double min_clearance_m = 0;    // smallest clearance seen once inside (< 0: interference)
  } insertion;
  struct Strike {
    double speed_m_s = 0;
    double wall_m = 0;
    bool tunnelled = false;  // any point of the peg got past the plate's far side
    double max_penetration_m = 0;
    double max_force_N = 0;
  } strike;
  double p50_us = 0, p99_us = 0, max_us = 0;  // compute per tick, both phases (wall clock)
  double cpu_p50_us = 0, cpu_p99_us = 0;      // the same ticks' CPU time (without preemption)
  double rate_hz = 0;
  double mean_queries = 0;  // exact point queries per tick
  int shell_points = 0;     // the peg's shell
  long allocations = 0;     // heap allocations in the ticks (after the first of each phase)
};

PegInHoleResult runPegInHole(double rate_hz = 2000);
// {"insertion": {"inserted", "clearance_m", "max_penetration_m", "max_force_N", "depth_m",
//  "min_clearance_m"}, "strike": {"speed_m_s", "wall_m", "tunnelled", "max_penetration_m",
//  "max_force_N"}, "compute_us": {"p50", "p99", "max"}, "cpu_us": {"p50", "p99"}, "rate_hz", "allocations_in_loop",
//  "mean_queries", "shell_points"}
nlohmann::json toJson(const PegInHoleResult& result);
int pegInHole(double rate_hz, bool json);

// `hapticgrasp bench contact --part FILE`: the part carried among two copies of itself (one
// under it, one beside it): pressed onto the one, slid into the other, turned against both.
struct ContactBenchOptions {
  std::string part;
  double rate_hz = 2000;
  double seconds = 3;
  int points = 1024;  // the carried part's shell
};
int benchContact(const ContactBenchOptions& options, bool json);

}  // namespace hg::cli
