#include "hapticgrasp/grasp/grasp_cylinder_experiment.hpp"

#include <BRepPrimAPI_MakeCylinder.hxx>
#include <gp_Ax2.hxx>

#include <algorithm>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>

#include "hapticgrasp/grasp/hand_script.hpp"
#include "hapticgrasp/grasp/two_finger_grasp.hpp"
#include "hapticgrasp/math/rpy.hpp"

namespace hg::grasp {
namespace {

// The paper's cylinder, built here so the experiment needs no resource files: diameter
// 100 mm, length 400 mm, axis z, centred on its frame's origin; 2 kg.
ScenePart paperCylinder() {
  const gp_Ax2 axis(gp_Pnt(0, 0, -200), gp_Dir(0, 0, 1));
  const auto model = geometry::PartModel::fromShape(BRepPrimAPI_MakeCylinder(axis, 50, 400).Shape(),
                                                    geometry::LengthUnit::Millimetre, "cylinder");
  // Lying on its side, axis along absolute y, centre 0.3 m up.
  PartPose pose;
  pose.rotation = Eigen::AngleAxisd(-std::numbers::pi / 2, Vec3::UnitX()).toRotationMatrix();
  pose.position = Vec3(0.4, 0.0, 0.3);
  return makeScenePart(model, geometry::MassSpec::mass(2.0), pose);
}

// Offsets in absolute axes from the cylinder's centre (the script's frame). The hand
// squeezes across the diameter along x, wrist above the fingertips.
constexpr double kPenetration = 0.5e-3;  // fingertip depth while touching, m (< d_h/2, so
                                         // opening by d_h frees both fingertips)
constexpr double kSqueeze = 0.5e-3;      // each fingertip, further in once grasped, m
constexpr double kClearance = 0.02;      // open fingertips' gap to the surface, m
constexpr double kWristHeight = 0.1;     // wrist above the fingertips, m
constexpr double kLiftHeight = 0.05;     // m, five times the lift threshold M g / K_ox
constexpr double kEccentric = 0.15;      // second grasp, from the centre along the axis, m

struct Hand {
  Vec3 index, thumb, wrist;
};
// Fingertips at +/-x (index at +x), `y` along the axis, `z` above the centre.
Hand hand(double indexX, double thumbX, double y, double z) {
  return {{indexX, y, z}, {thumbX, y, z}, {0, y, z + kWristHeight}};
}

HandScript fig6Script(const ScenePart& cylinder) {
  const double r = 0.5 * cylinder.model->bounds().size().x();
  const double open = r + kClearance, in = r - kPenetration, squeezed = in - kSqueeze;
  const double quarter = std::numbers::pi / 2;
  const Vec3 lifted(0, 0, kLiftHeight), carried(0.25, 0.15, 0);
  std::vector<HandKey> keys;
  const auto key = [&](double t, const Hand& h, const Vec3& shift = Vec3::Zero(), double turn = 0) {
    keys.push_back({t, h.index, h.thumb, h.wrist, shift, turn});
  };
  // (a) FREE: the open hand comes down beside the cylinder.
  key(0.0, hand(open, -open, 0, 0.15));
  key(0.5, hand(open, -open, 0, 0));
  // (b) INDEX CONTACT: the index touches, traces over the curved side and along the axis.
  key(0.8, hand(in, -open, 0, 0));
  int step = 0;
  for (double degrees : {15.0, 30.0, 15.0, 0.0}) {
    const double phi = degrees * std::numbers::pi / 180;
    Hand h = hand(in * std::cos(phi), -open, 0, 0);
    h.index.z() = in * std::sin(phi);
    key(1.05 + 0.25 * step++, h);
  }
  key(2.1, hand(in, -open, 0.1, 0));
  key(2.7, hand(in, -open, -0.1, 0));
  key(3.0, hand(in, -open, 0, 0));
  key(3.3, hand(open, -open, 0, 0));  // back to FREE
  // (c) THUMB CONTACT, (d) GRASP when the index comes in too; then a squeeze (Fig. 4 B->C).
  key(3.7, hand(open, -in, 0, 0));
  key(4.1, hand(in, -in, 0, 0));
  key(4.4, hand(squeezed, -squeezed, 0, 0));
  // (e) MANIPULATE: lift, carry and turn a quarter, put down.
  key(5.4, hand(squeezed, -squeezed, 0, 0), lifted);
  key(7.4, hand(squeezed, -squeezed, 0, 0), carried + lifted, quarter);
  key(7.9, hand(squeezed, -squeezed, 0, 0), carried, quarter);
  // (f) FREE: open the hand, the cylinder stays at its new place; move up and over one end.
  key(8.2, hand(open, -open, 0, 0), carried, quarter);
  key(8.6, hand(open, -open, 0, 0.15), carried, quarter);
  key(9.1, hand(open, -open, kEccentric, 0.15), carried, quarter);
  // The eccentric grasp: the wrist feels the moment of the weight about it (eq 30).
  key(9.6, hand(open, -open, kEccentric, 0), carried, quarter);
  key(9.9, hand(in, -open, kEccentric, 0), carried, quarter);
  key(10.2, hand(in, -in, kEccentric, 0), carried, quarter);
  key(11.2, hand(in, -in, kEccentric, 0), carried + lifted, quarter);
  key(11.7, hand(in, -in, kEccentric, 0), carried + lifted, quarter);  // held still: measured
  key(12.2, hand(in, -in, kEccentric, 0), carried, quarter);
  key(12.5, hand(open, -open, kEccentric, 0), carried, quarter);
  key(12.9, hand(open, -open, kEccentric, 0.15), carried, quarter);
  const Vec3 centre = cylinder.initialPose.pointToAbsolute(cylinder.mass.centre_m);
  return HandScript(std::move(keys), PartPose{Mat3::Identity(), centre}, centre);
}
constexpr double kHoldFrom = 11.25, kHoldTo = 11.7;  // s, the eccentric part held still

nlohmann::json toJson(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
nlohmann::json toJson(const PartPose& pose) {
  return {{"position_m", toJson(pose.position)},
          {"rpy_rad", toJson(math::paperRpy(pose.rotation.transpose()))},
          {"rotation_vector_rad", toJson(math::rotationVector(pose.rotation))}};
}

}  // namespace

GraspCylinderResult runGraspCylinder(double rate_hz) {
  if (!(rate_hz > 0) || !std::isfinite(rate_hz)) throw std::invalid_argument("servo rate must be positive");
  const ScenePart cylinder = paperCylinder();
  const HandScript script = fig6Script(cylinder);
  const auto scene = std::make_shared<const Scene>(std::vector<ScenePart>{cylinder});
  TwoFingerGrasp grasp(scene);
  const GraspParameters& k = grasp.parameters();
  const Vec3 down = k.gravity.normalized();

  GraspCylinderResult result;
  result.rate_hz = rate_hz;
  result.mass_kg = cylinder.mass.mass_kg;
  result.weight_N = cylinder.mass.mass_kg * k.gravity.norm();
  result.initialPose = cylinder.initialPose;
  result.leverArm_m = kEccentric;
  result.expected_eccentric_moment_Nm = result.weight_N * kEccentric;

  const double dt = 1.0 / rate_hz;
  const long ticks = std::lround(script.duration() * rate_hz);
  GraspState state = grasp.state();
  double lastVertical = 0, heldMoment = 0;
  int heldTicks = 0;
  for (long n = 0; n <= ticks; ++n) {
    const HandSample s = script.at(n * dt);
    const GraspOutput out = grasp.step(s, n == 0 ? 0.0 : dt);
    const double vertical = out.f_wrist.dot(down);
    if (out.events & kLift)
      result.force_jump_at_lift_N = std::max(result.force_jump_at_lift_N, std::abs(vertical - lastVertical));
    lastVertical = vertical;
    result.max_force_N = std::max({result.max_force_N, out.f_index.norm(), out.f_thumb.norm(), out.f_wrist.norm()});
    if (out.state != state) result.transitions.push_back({s.t, state, out.state, out.events});
    state = out.state;
    if (state == GraspState::Manipulate && s.t >= kHoldFrom && s.t <= kHoldTo) {
      heldMoment += out.m_wrist.norm();
      ++heldTicks;
    }
  }
  result.finalPose = grasp.poses()[0];
  result.eccentric_moment_Nm = heldTicks ? heldMoment / heldTicks : 0;
  return result;
}

std::string toJson(const GraspCylinderResult& r, int indent) {
  nlohmann::json transitions = nlohmann::json::array();
  for (const GraspCylinderTransition& t : r.transitions) {
    nlohmann::json events = nlohmann::json::array();
    for (int bit = 0; bit < kEventCount; ++bit)
      if (t.events & (1u << bit)) events.push_back(eventName(static_cast<GraspEvent>(1u << bit)));
    transitions.push_back({{"t", t.t}, {"from", toString(t.from)}, {"to", toString(t.to)}, {"events", events}});
  }
  const nlohmann::json j = {{"transitions", transitions},
                            {"weight_N", r.weight_N},
                            {"force_jump_at_lift_N", r.force_jump_at_lift_N},
                            {"max_force_N", r.max_force_N},
                            {"initial_pose", toJson(r.initialPose)},
                            {"final_pose", toJson(r.finalPose)},
                            {"eccentric_moment_Nm", r.eccentric_moment_Nm},
                            {"expected_eccentric_moment_Nm", r.expected_eccentric_moment_Nm},
                            {"lever_arm_m", r.leverArm_m},
                            {"rate_hz", r.rate_hz},
                            {"mass_kg", r.mass_kg}};
  return j.dump(indent);
}

std::string runGraspCylinderExperiment(double rate_hz) { return toJson(runGraspCylinder(rate_hz)); }

}  // namespace hg::grasp
