#include "hapticgrasp/grasp/shake_experiment.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "hapticgrasp/grasp/multi_finger/one_dof.hpp"

namespace hg::grasp {
namespace {

using multi_finger::OneDofOutput;
using multi_finger::OneDofParams;

// The wrist: `shakes` periods of A (1 − cos 2π f t) then `rest` seconds still, repeated.
double wristPosition(const ShakeConfig& c, double t) {
  const double shakeTime = c.shakes / c.frequency;
  const double period = shakeTime + c.rest;
  const double phase = std::fmod(t, period);
  if (phase >= shakeTime) return 0;
  // One-sided: starts and ends at rest with zero velocity, peak acceleration A (2π f)².
  return c.amplitude * (1 - std::cos(2 * std::numbers::pi * c.frequency * phase));
}

struct Accumulator {
  double n = 0, s = 0, ss = 0;
  void add(double x) { n += 1; s += x; ss += x * x; }
  double mean() const { return n > 0 ? s / n : 0; }
  double stddev() const { return n > 1 ? std::sqrt(std::max(0.0, ss / n - mean() * mean())) : 0; }
};

template <class Model>
ShakeMethodResult run(const ShakeConfig& c, double target) {
  OneDofParams p;
  p.mass = c.mass;
  p.length = c.width;
  p.kGrasp = c.stiffness;
  p.kDynamics = c.dynamicsStiffness;
  p.dampingRatio = c.dampingRatio;
  Model model(p);
  model.reset(0);
  // The subject starts holding the block still with its target force (eq 2 → gap).
  double aperture = std::max(0.1 * c.width, c.width - 2 * target / c.stiffness);
  const long ticks = std::lround(c.duration / c.dt);
  const long every = std::max(1L, std::lround(1.0 / (c.sampleRate * c.dt)));
  const double weight = c.mass * c.gravity;
  ShakeMethodResult r;
  Accumulator force, distance;
  long slips = 0;
  // The hand's compliance: each finger gives way by its force over handStiffness, through
  // a first-order lag of handTau (the hand's mass and damping). The loop through the
  // springs and dampers closes one tick late: handStiffness is raised, when needed, to
  // twice the springs' stiffness and twice the dampers' coefficient over handTau, which
  // keeps it stable at any stiffness and dt.
  const double damper = 2 * c.dampingRatio * std::sqrt(std::max(c.stiffness, c.dynamicsStiffness) * c.mass);
  const double kHand = c.handStiffness > 0
                           ? std::max({c.handStiffness, 2 * std::max(c.stiffness, c.dynamicsStiffness),
                                       4 * damper / c.handTau})
                           : 0.0;
  const double handGain = c.dt / (c.handTau + c.dt);
  double thumbGive = 0, indexGive = 0;
  for (long i = 0; i <= ticks; ++i) {
    const double t = i * c.dt;
    const double w = wristPosition(c, t);
    const OneDofOutput& o = model.step(w - 0.5 * aperture + thumbGive, w + 0.5 * aperture + indexGive, 0.0, c.dt);
    if (kHand > 0) {
      thumbGive += handGain * (o.thumbForce / kHand - thumbGive);
      indexGive += handGain * (o.indexForce / kHand - indexGive);
    }
    // The subject's grip (section 2.4): close when the felt grasping force is below the
    // target, open when above, first order with time constant subjectTau. 2/k converts a
    // force error into an aperture change (f_g = k (l − gap)/2 when held still).
    aperture += c.dt / c.subjectTau * (2.0 / c.stiffness) * (o.graspForce - target);
    aperture = std::clamp(aperture, 0.1 * c.width, 2.0 * c.width);
    force.add(o.graspForce);
    distance.add(o.distance);
    r.resultant_max_N = std::max(r.resultant_max_N, std::abs(o.resultant));
    r.max_force_N = std::max({r.max_force_N, std::abs(o.thumbForce), std::abs(o.indexForce)});
    if (2 * c.friction * o.graspForce < weight) ++slips;
    if (!std::isfinite(o.graspForce) || !std::isfinite(o.distance) || !std::isfinite(o.resultant) ||
        !std::isfinite(o.partPosition))
      r.finite = false;
    if (i % every == 0) {
      r.series.t.push_back(t);
      r.series.graspForce.push_back(o.graspForce);
      r.series.distance.push_back(o.distance);
      r.series.resultant.push_back(o.resultant);
    }
  }
  r.grasp_force_mean_N = force.mean();
  r.grasp_force_std_N = force.stddev();
  r.distance_mean_m = distance.mean();
  r.distance_std_m = distance.stddev();
  r.slip_fraction = static_cast<double>(slips) / static_cast<double>(ticks + 1);
  return r;
}

nlohmann::json methodJson(const ShakeMethodResult& m) {
  return {{"grasp_force_mean_N", m.grasp_force_mean_N}, {"grasp_force_std_N", m.grasp_force_std_N},
          {"distance_mean_m", m.distance_mean_m},       {"distance_std_m", m.distance_std_m},
          {"resultant_max_N", m.resultant_max_N},       {"max_force_N", m.max_force_N},
          {"slip_fraction", m.slip_fraction},           {"finite", m.finite}};
}

}  // namespace

ShakeResult runShakeExperiment(const ShakeConfig& c) {
  const auto bad = [](double x) { return !(x > 0) || !std::isfinite(x); };
  if (bad(c.dt) || bad(c.duration) || bad(c.mass) || bad(c.width) || bad(c.stiffness) ||
      bad(c.dynamicsStiffness) || bad(c.frequency) || bad(c.subjectTau) || bad(c.friction) || bad(c.sampleRate) || !(c.handStiffness >= 0) || bad(c.handTau) ||
      c.shakes < 1 || !(c.rest >= 0) || !std::isfinite(c.amplitude) || !std::isfinite(c.gravity))
    throw std::invalid_argument("shake experiment: dt, duration, mass, width, stiffness, frequency, "
                                "subject time constant, friction and sample rate must be positive");
  ShakeResult result;
  result.config = c;
  result.target_grasp_force_N = c.gripSafety * c.mass * std::abs(c.gravity) / (2 * c.friction);
  result.conventional = run<multi_finger::ConventionalOneDof>(c, result.target_grasp_force_N);
  result.proposed = run<multi_finger::ProposedOneDof>(c, result.target_grasp_force_N);
  return result;
}

std::string toJson(const ShakeResult& r, int indent) {
  const ShakeConfig& c = r.config;
  const nlohmann::json j = {
      {"methods", {{"conventional", methodJson(r.conventional)}, {"proposed", methodJson(r.proposed)}}},
      {"target_grasp_force_N", r.target_grasp_force_N},
      {"config",
       {{"dt_s", c.dt}, {"duration_s", c.duration}, {"mass_kg", c.mass}, {"width_m", c.width},
        {"height_m", c.height}, {"gravity_mps2", c.gravity}, {"stiffness_Npm", c.stiffness},
        {"dynamics_stiffness_Npm", c.dynamicsStiffness}, {"damping_ratio", c.dampingRatio},
        {"friction", c.friction}, {"grip_safety", c.gripSafety}, {"subject_tau_s", c.subjectTau}, {"hand_stiffness_Npm", c.handStiffness}, {"hand_tau_s", c.handTau},
        {"amplitude_m", c.amplitude}, {"frequency_Hz", c.frequency}, {"shakes", c.shakes}, {"rest_s", c.rest}}}};
  return j.dump(indent);
}

std::string toSvg(const ShakeResult& r) {
  const double W = 900, panelH = 260, left = 70, right = 20, top = 40, gapH = 60;
  const double plotW = W - left - right;
  const double H = top + 2 * panelH + gapH + 50;
  const double tMax = r.config.duration;
  std::ostringstream s;
  char buf[1024];
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s << "<text x=\"" << W / 2 << "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">Shaking the block: conventional vs "
       "proposed (resultant-force paper, Fig. 8)</text>\n";
  struct Panel {
    const char* label;
    const std::vector<double>& conv;
    const std::vector<double>& prop;
    double scale;  // display unit
  };
  const Panel panels[2] = {{"grasping force [N]", r.conventional.series.graspForce, r.proposed.series.graspForce, 1.0},
                           {"finger distance [cm]", r.conventional.series.distance, r.proposed.series.distance, 100.0}};
  for (int k = 0; k < 2; ++k) {
    const Panel& pn = panels[k];
    const double y0 = top + k * (panelH + gapH);
    double lo = 1e300, hi = -1e300;
    for (const auto* v : {&pn.conv, &pn.prop})
      for (double x : *v)
        if (std::isfinite(x)) { lo = std::min(lo, x * pn.scale); hi = std::max(hi, x * pn.scale); }
    if (!(hi > lo)) { lo = (lo < 1e300 ? lo : 0) - 1; hi = lo + 2; }
    const double pad = 0.05 * (hi - lo);
    lo -= pad;
    hi += pad;
    const auto X = [&](double t) { return left + plotW * t / tMax; };
    const auto Y = [&](double v) { return y0 + panelH * (1 - (v - lo) / (hi - lo)); };
    // Shaking periods shaded, as the paper's grey areas.
    const double shakeTime = r.config.shakes / r.config.frequency, period = shakeTime + r.config.rest;
    for (double t0 = 0; t0 < tMax; t0 += period) {
      std::snprintf(buf, sizeof buf, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"#eee\"/>\n",
                    X(t0), y0, X(std::min(tMax, t0 + shakeTime)) - X(t0), panelH);
      s << buf;
    }
    std::snprintf(buf, sizeof buf,
                  "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" stroke=\"black\"/>\n", left,
                  y0, plotW, panelH);
    s << buf;
    for (int i = 0; i <= 4; ++i) {
      const double v = lo + (hi - lo) * i / 4;
      std::snprintf(buf, sizeof buf,
                    "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%.3g</text><line x1=\"%.1f\" x2=\"%.1f\" "
                    "y1=\"%.1f\" y2=\"%.1f\" stroke=\"#ccc\"/>\n",
                    left - 5, Y(v) + 4, v, left, left + plotW, Y(v), Y(v));
      s << buf;
    }
    for (int i = 0; i <= 6; ++i) {
      const double t = tMax * i / 6;
      std::snprintf(buf, sizeof buf, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%.0f</text>\n", X(t),
                    y0 + panelH + 15, t);
      s << buf;
    }
    std::snprintf(buf, sizeof buf, "<text x=\"%.1f\" y=\"%.1f\">%s</text>\n", left, y0 - 6, pn.label);
    s << buf;
    const char* colours[2] = {"#d62728", "#1f77b4"};
    const std::vector<double>* series[2] = {&pn.conv, &pn.prop};
    const std::vector<double>* times[2] = {&r.conventional.series.t, &r.proposed.series.t};
    for (int m = 0; m < 2; ++m) {
      s << "<polyline fill=\"none\" stroke-width=\"1\" stroke=\"" << colours[m] << "\" points=\"";
      for (std::size_t i = 0; i < series[m]->size() && i < times[m]->size(); ++i) {
        const double v = (*series[m])[i] * pn.scale;
        if (!std::isfinite(v)) continue;
        std::snprintf(buf, sizeof buf, "%.1f,%.1f ", X((*times[m])[i]), Y(v));
        s << buf;
      }
      s << "\"/>\n";
    }
  }
  const double yl = top + 2 * panelH + gapH + 25;
  s << "<text x=\"" << left + plotW / 2 << "\" y=\"" << yl - 5 << "\" text-anchor=\"middle\">time [s]</text>\n";
  std::snprintf(buf, sizeof buf,
                "<line x1=\"%.1f\" x2=\"%.1f\" y1=\"%.1f\" y2=\"%.1f\" stroke=\"#d62728\" stroke-width=\"2\"/><text "
                "x=\"%.1f\" y=\"%.1f\">conventional</text><line x1=\"%.1f\" x2=\"%.1f\" y1=\"%.1f\" y2=\"%.1f\" "
                "stroke=\"#1f77b4\" stroke-width=\"2\"/><text x=\"%.1f\" y=\"%.1f\">proposed</text>\n",
                left, left + 30, yl + 10, yl + 10, left + 35, yl + 14, left + 150, left + 180, yl + 10, yl + 10,
                left + 185, yl + 14);
  s << buf << "</svg>\n";
  return s.str();
}

}  // namespace hg::grasp
