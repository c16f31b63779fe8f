#include "hapticgrasp/session/session_series.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "hapticgrasp/servo/servo_loop.hpp"
#include "hapticgrasp/servo/timing_stats.hpp"
#include "hapticgrasp/session/mcap_reader.hpp"
#include "hapticgrasp/session/recorder.hpp"
#include "hapticgrasp/session/tick_message.hpp"

namespace hg::session {
namespace {

constexpr double kFirstBin_s = 0.005;  // doubled whenever the bins outgrow maxBins

// The bins: fixed width, merged pairwise (keeping each pair's largest value) when there
// are too many, so one pass needs no duration known in advance.
class Bins {
 public:
  Bins(SessionSeries& s, std::size_t maxBins) : s_(s), max_(std::max<std::size_t>(maxBins, 16)) { s_.binWidth_s = kFirstBin_s; }

  void add(double t, const servo::TickRecord& r, double travel) {
    const auto bin = static_cast<std::size_t>(std::max(0.0, t) / s_.binWidth_s);
    while (s_.time_s.size() <= bin) {
      if (s_.time_s.size() == max_) {
        halve();
        add(t, r, travel);
        return;
      }
      push(static_cast<double>(s_.time_s.size()) * s_.binWidth_s);
    }
    const std::size_t b = std::min(bin, s_.time_s.size() - 1);
    for (int k = 0; k < 5; ++k) keepMax(s_.fingertip_N[b][static_cast<std::size_t>(k)], r.sent.fingertipForce(k).norm());
    keepMax(s_.grasp_N[b], r.sent.f_grasp);
    keepMax(s_.wristForce_N[b], r.sent.f_wrist.norm());
    keepMax(s_.wristMoment_Nm[b], r.sent.m_wrist.norm());
    double requested = std::max(r.raw.f_wrist.norm(), r.raw.f_grasp);
    for (int k = 0; k < 5; ++k) requested = std::max(requested, r.raw.fingertipForce(k).norm());
    keepMax(s_.requested_N[b], requested);
    keepMax(s_.travel_m[b], travel);
    keepMax(s_.compute_us[b], r.compute_us);
    keepMax(s_.periodError_us[b], r.periodError_us);
    s_.state[b] = static_cast<int>(r.state);
  }

 private:
  static void keepMax(double& into, double v) {
    if (std::isfinite(v)) into = std::max(into, v);
  }
  void push(double t) {
    s_.time_s.push_back(t);
    s_.fingertip_N.push_back({});
    for (auto* v : series()) v->push_back(0);
    s_.state.push_back(s_.state.empty() ? 0 : s_.state.back());
  }
  std::array<std::vector<double>*, 7> series() {
    return {&s_.grasp_N, &s_.wristForce_N, &s_.wristMoment_Nm, &s_.requested_N, &s_.travel_m, &s_.compute_us,
            &s_.periodError_us};
  }
  void halve() {
    const std::size_t n = s_.time_s.size() / 2;
    for (std::size_t i = 0; i < n; ++i) {
      s_.time_s[i] = s_.time_s[2 * i];
      for (std::size_t k = 0; k < 5; ++k) s_.fingertip_N[i][k] = std::max(s_.fingertip_N[2 * i][k], s_.fingertip_N[2 * i + 1][k]);
      for (auto* v : series()) (*v)[i] = std::max((*v)[2 * i], (*v)[2 * i + 1]);
      s_.state[i] = s_.state[2 * i + 1];
    }
    s_.time_s.resize(n);
    s_.fingertip_N.resize(n);
    for (auto* v : series()) v->resize(n);
    s_.state.resize(n);
    s_.binWidth_s *= 2;
  }

  SessionSeries& s_;
  std::size_t max_;
};

double sentMax(const servo::TickRecord& r) {
  double f = r.sent.f_wrist.norm();
  for (int k = 0; k < 5; ++k) f = std::max(f, r.sent.fingertipForce(k).norm());
  return std::isfinite(f) ? f : 0.0;
}

// The parts carried: a part entering the moving set starts a manipulation from where it
// stood; leaving it ends one where it was last seen.
class Manipulations {
 public:
  Manipulations(SessionSeries& s, const SessionDescription& d) : s_(s), d_(d) {
    for (const RecordedPart& p : d.parts) poses_.push_back(p.initialPose);
  }
  double update(double t, const servo::TickRecord& r) {
    if ((r.commands & servo::kCommandReset) || (r.events & servo::kWatchdogTrip)) {
      finishAll(t);
      for (std::size_t i = 0; i < poses_.size(); ++i) poses_[i] = d_.parts[i].initialPose;
    }
    const int n = std::min(r.movingCount, servo::TickRecord::kMaxMoving);
    for (auto it = open_.begin(); it != open_.end();) {
      const bool still = std::find(r.movingPart, r.movingPart + n, it->first) != r.movingPart + n;
      if (still) {
        ++it;
        continue;
      }
      finish(it->second, t);
      it = open_.erase(it);
    }
    double travel = 0;
    for (int k = 0; k < n; ++k) {
      const int part = r.movingPart[k];
      if (part < 0 || static_cast<std::size_t>(part) >= poses_.size()) continue;
      auto [it, fresh] = open_.try_emplace(part);
      if (fresh) it->second = {d_.parts[static_cast<std::size_t>(part)].name, t, t, poses_[static_cast<std::size_t>(part)],
                               poses_[static_cast<std::size_t>(part)], 0, 0, 0};
      poses_[static_cast<std::size_t>(part)] = r.movingPose[k];
      it->second.to = r.movingPose[k];
      it->second.maxForce_N = std::max(it->second.maxForce_N, sentMax(r));
      travel = std::max(travel, (r.movingPose[k].position - it->second.from.position).norm());
    }
    return travel;
  }
  void finishAll(double t) {
    for (auto& [part, m] : open_) finish(m, t);
    open_.clear();
  }

 private:
  void finish(Manipulation& m, double t) {
    m.end_s = t;
    m.distance_m = (m.to.position - m.from.position).norm();
    m.angle_rad = Eigen::AngleAxisd(m.to.rotation * m.from.rotation.transpose()).angle();
    s_.manipulations.push_back(m);
  }
  SessionSeries& s_;
  const SessionDescription& d_;
  std::vector<grasp::PartPose> poses_;
  std::map<int, Manipulation> open_;
};

}  // namespace

SessionSeries readSessionSeries(const std::string& path, std::size_t maxBins) {
  SessionSeries s;
  s.info = readRecordingInfo(path);
  McapReader reader(path);
  std::uint16_t tickChannel = 0;
  for (const auto& [id, channel] : reader.channels())
    if (channel.topic == kTickTopic) tickChannel = id;
  Bins bins(s, maxBins);
  Manipulations carried(s, s.info.description);
  servo::DurationHistogram compute;
  servo::TickRecord r;
  double t = 0;
  reader.scan(
      [&](const McapMessageView& m) {
        if (tickChannel == 0) {
          const auto c = reader.channels().find(m.channel);
          if (c != reader.channels().end() && c->second.topic == kTickTopic) tickChannel = m.channel;
        }
        if (m.channel != tickChannel || !decodeTick(m.data, r)) return;
        t = m.logTime_ns > s.info.firstTime_ns ? 1e-9 * static_cast<double>(m.logTime_ns - s.info.firstTime_ns) : 0.0;
        ++s.ticks;
        s.saturatedTicks += r.saturated;
        s.faults += (r.events & servo::kWatchdogTrip) != 0;
        s.maxForce_N = std::max(s.maxForce_N, sentMax(r));
        compute.add(1e-6 * r.compute_us);
        if (r.events != 0 || r.state != r.stateBefore)
          s.events.push_back({t, servo::eventsText(r.events), r.stateBefore, r.state, r.events});
        bins.add(t, r, carried.update(t, r));
      },
      /*attachmentData=*/false);
  carried.finishAll(t);
  const servo::DurationSummary c = compute.summary();
  s.computeMax_us = c.max_us;
  s.computeP99_us = c.p99_us;
  return s;
}

std::string toJson(const SessionSeries& s) {
  using nlohmann::json;
  json fingertips = json::array();
  for (std::size_t k = 0; k < 5; ++k) {
    json f = json::array();
    for (const auto& bin : s.fingertip_N) f.push_back(bin[k]);
    fingertips.push_back(std::move(f));
  }
  json states = json::array();
  for (int k = 0; k <= static_cast<int>(grasp::GraspState::Manipulate); ++k)
    states.push_back(grasp::toString(static_cast<grasp::GraspState>(k)));
  json events = json::array();
  for (const SessionEvent& e : s.events)
    events.push_back({{"time_s", e.time_s}, {"text", e.text}, {"from", grasp::toString(e.from)},
                      {"to", grasp::toString(e.to)}, {"fault", (e.events & servo::kWatchdogTrip) != 0}});
  const auto vec = [](const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); };
  json carried = json::array();
  for (const Manipulation& m : s.manipulations)
    carried.push_back({{"part", m.part}, {"start_s", m.start_s}, {"end_s", m.end_s}, {"from_m", vec(m.from.position)},
                       {"to_m", vec(m.to.position)}, {"distance_m", m.distance_m},
                       {"angle_deg", m.angle_rad * 180 / 3.14159265358979323846}, {"max_force_N", m.maxForce_N}});
  return json{{"info", json::parse(toJson(s.info))}, {"bin_width_s", s.binWidth_s}, {"time_s", s.time_s},
              {"fingertip_N", fingertips}, {"grasp_N", s.grasp_N}, {"wrist_force_N", s.wristForce_N},
              {"wrist_moment_Nm", s.wristMoment_Nm}, {"requested_N", s.requested_N}, {"travel_m", s.travel_m},
              {"compute_us", s.compute_us}, {"period_error_us", s.periodError_us}, {"state", s.state},
              {"state_names", states}, {"events", events}, {"manipulations", carried}, {"ticks", s.ticks},
              {"saturated_ticks", s.saturatedTicks}, {"faults", s.faults}, {"max_force_N", s.maxForce_N},
              {"compute_p99_us", s.computeP99_us}, {"compute_max_us", s.computeMax_us}}
      .dump(-1, ' ', false, json::error_handler_t::replace);  // names from the file: maybe not UTF-8
}

}  // namespace hg::session
