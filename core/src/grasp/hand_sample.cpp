#include "hapticgrasp/grasp/hand_sample.hpp"

namespace hg::grasp {

HandSample between(const HandSample& a, const HandSample& b, double f) noexcept {
  const auto mix = [f](const Vec3& p, const Vec3& q) -> Vec3 { return p + f * (q - p); };
  HandSample h;
  h.t = a.t + f * (b.t - a.t);
  h.index = mix(a.index, b.index);
  h.thumb = mix(a.thumb, b.thumb);
  h.wrist = mix(a.wrist, b.wrist);
  for (int k = 0; k < HandSample::kMaxFingertips - 2; ++k) h.extra[k] = mix(a.extra[k], b.extra[k]);
  const Quat qa(a.wristRotation), qb(b.wristRotation);
  h.wristRotation = qa.slerp(f, qb).toRotationMatrix();
  return h;
}

}  // namespace hg::grasp
