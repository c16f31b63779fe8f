// A recording reduced for the report: the bins keep every peak (the largest force of the
// session is the largest of the bins), their number stays bounded however long the
// session, the carried part's manipulation is found with how far it went.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "hapticgrasp/servo/servo_bench.hpp"
#include "hapticgrasp/session/session_series.hpp"
#include "session/stepped_session.hpp"

namespace hg::session {
namespace {

namespace fs = std::filesystem;

const std::string& recorded() {
  static const std::string file = [] {
    const fs::path dir = test::tempDir("series");
    servo::ServoBenchOptions o;
    o.device = "scripted";
    o.seconds = 2.5;  // one grasp, lift, put-down cycle (2 s) and the start of the next
    o.realtime = false;
    o.recordPath = (dir / "series.mcap").string();
    servo::runServoBench(o);
    return o.recordPath;
  }();
  return file;
}

TEST(SessionSeries, BinsKeepThePeaksAndStayBounded) {
  const SessionSeries s = readSessionSeries(recorded(), 64);
  EXPECT_GT(s.ticks, 4000u);
  EXPECT_LE(s.time_s.size(), 64u);
  EXPECT_GE(s.time_s.size(), 16u);
  EXPECT_TRUE(std::is_sorted(s.time_s.begin(), s.time_s.end()));
  double peak = 0;
  for (std::size_t b = 0; b < s.time_s.size(); ++b) {
    peak = std::max(peak, s.wristForce_N[b]);
    for (double f : s.fingertip_N[b]) peak = std::max(peak, f);
  }
  EXPECT_GT(s.maxForce_N, 1.0);
  EXPECT_EQ(peak, s.maxForce_N);
  // More bins, finer: the same peak, more of them.
  const SessionSeries fine = readSessionSeries(recorded(), 2000);
  EXPECT_GT(fine.time_s.size(), s.time_s.size());
  EXPECT_LT(fine.binWidth_s, s.binWidth_s);
}

TEST(SessionSeries, FindsTheManipulationAndTheEvents) {
  const SessionSeries s = readSessionSeries(recorded());
  ASSERT_GE(s.manipulations.size(), 1u);
  const Manipulation& m = s.manipulations.front();
  EXPECT_EQ(m.part, "cylinder");
  EXPECT_LT(m.start_s, m.end_s);
  // The script lifts 5 cm, then lowers the part to where it was: it travelled, and landed near its start.
  const double travel = *std::max_element(s.travel_m.begin(), s.travel_m.end());
  EXPECT_GT(travel, 0.03);
  EXPECT_LT(m.distance_m, 0.01);
  EXPECT_GT(m.maxForce_N, 1.0);
  const auto has = [&](const std::string& what) {
    return std::any_of(s.events.begin(), s.events.end(), [&](const SessionEvent& e) { return e.text.find(what) != std::string::npos; });
  };
  EXPECT_TRUE(has("grasp"));
  EXPECT_TRUE(has("lift"));
  const auto j = nlohmann::json::parse(toJson(s));
  EXPECT_EQ(j["manipulations"][0]["part"], "cylinder");
  EXPECT_EQ(j["fingertip_N"].size(), 5u);
  EXPECT_EQ(j["time_s"].size(), s.time_s.size());
}

}  // namespace
}  // namespace hg::session
