#pragma once
// The hand frame of eqs 16-18 and what the transition to GRASP preserves (eqs 12-15), and
// the part pose that keeps both fixed in the object frame (eqs 19-22).
#include "hapticgrasp/grasp/grasp_parameters.hpp"
#include "hapticgrasp/grasp/hand_sample.hpp"
#include "hapticgrasp/grasp/part_pose.hpp"
#include "hapticgrasp/math/types.hpp"

namespace hg::grasp {

// Eqs 16-18: columns h1 (thumb -> index), h2 = h1 x (x_i - x_w) normalised, h3 = h1 x h2,
// absolute frame. Degenerate hands keep what is known: fingertips together -> `lastGood`
// unchanged; wrist on the finger line -> the current h1 with lastGood's h2 made
// orthogonal to it. Never divides by ~0.
Mat3 handFrame(const Vec3& index, const Vec3& thumb, const Vec3& wrist, const Mat3& lastGood,
               const GraspParameters& k) noexcept;

// The hand frame at the transition to GRASP, when there is no last good frame yet: a
// degenerate hand falls back on the wrist's own axes (xi_w^a), so it still grasps.
Mat3 firstHandFrame(const HandSample& hand, const GraspParameters& k) noexcept;

// What the transition to GRASP preserves.
struct GraspMemory {
  PartPose object;                     // x_o_bar^a and R(xi_o_bar^a)^T
  Vec3 xi_o = Vec3::Zero();            // xi_o_bar^a, paper RPY (for RotationalSpring::PaperRpy)
  Mat3 h_o = Mat3::Identity();         // [h1_bar^o h2_bar^o h3_bar^o], eqs 12-14
  Vec3 x_m_o = Vec3::Zero();           // x_m_bar^o, eq 15
  double distance = 0;                 // |x_i_bar^a - x_t_bar^a|, Fig. 4's A
};

// Eqs 12-15, with the hand frame `frame` (eqs 16-18 at the transition).
GraspMemory preserveGrasp(const HandSample& hand, const PartPose& object, const Mat3& frame) noexcept;

// Eqs 19-22: the part pose that keeps the preserved frame and midpoint in place.
PartPose graspedPose(const GraspMemory& memory, const Mat3& frame, const Vec3& index, const Vec3& thumb) noexcept;

}  // namespace hg::grasp
