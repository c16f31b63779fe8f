#pragma once
// Maekawa & Hollerbach's experiment (section 5, Fig. 6) as a library function: a scripted
// hand touches, traces, grasps, lifts, carries, turns and puts down the paper's cylinder
// (0.1 m x 0.4 m, 2 kg), then grasps it again near one end to feel the eccentric load.
// `hapticgrasp experiment grasp-cylinder [--json]` prints it.
#include <string>
#include <vector>

#include "hapticgrasp/grasp/grasp_state.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"

namespace hg::grasp {

struct GraspCylinderTransition {
  double t = 0;  // s
  GraspState from = GraspState::Free, to = GraspState::Free;
  std::uint32_t events = 0;  // GraspEvent bits of that tick
};

struct GraspCylinderResult {
  double rate_hz = 0;
  double mass_kg = 0;
  std::vector<GraspCylinderTransition> transitions;
  double weight_N = 0;              // M |g|
  double force_jump_at_lift_N = 0;  // largest |change of f_w . g/|g|| over a GRASP -> MANIPULATE tick
  double max_force_N = 0;           // largest fingertip or wrist force of the run
  PartPose initialPose, finalPose;  // the cylinder's frame (its centre) before and after
  double leverArm_m = 0;            // scripted offset of the eccentric grasp from the centre
  double eccentric_moment_Nm = 0;   // |m_w| held still after the eccentric lift (eq 30)
  double expected_eccentric_moment_Nm = 0;  // M |g| * lever arm
};

// Runs the scripted experiment at `rate_hz` servo ticks per second (deterministic; about
// 10 ms at 2 kHz). Throws std::invalid_argument for a rate that is not positive.
GraspCylinderResult runGraspCylinder(double rate_hz = 2000.0);

// The result as the CLI's JSON: {"transitions": [{"t","from","to","events"}], "weight_N",
// "force_jump_at_lift_N", "max_force_N", "initial_pose", "final_pose",
// "eccentric_moment_Nm", "expected_eccentric_moment_Nm", "lever_arm_m", "rate_hz",
// "mass_kg"}; a pose is {"position_m", "rpy_rad" (the paper's xi_o^a, eq 21),
// "rotation_vector_rad"}.
std::string toJson(const GraspCylinderResult& result, int indent = 2);

// runGraspCylinder(rate_hz) as JSON text.
std::string runGraspCylinderExperiment(double rate_hz = 2000.0);

}  // namespace hg::grasp
