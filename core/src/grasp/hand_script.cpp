#include "hapticgrasp/grasp/hand_script.hpp"

#include <algorithm>
#include <stdexcept>

namespace hg::grasp {

HandScript::HandScript(std::vector<HandKey> keys, const PartPose& frame, const Vec3& pivot, const Vec3& up,
                       const Mat3& wristRotation)
    : keys_(std::move(keys)), frame_(frame), pivot_(pivot), up_(up.normalized()), wristRotation_(wristRotation) {
  if (keys_.empty()) throw std::invalid_argument("a hand script needs at least one key");
  for (std::size_t i = 1; i < keys_.size(); ++i)
    if (!(keys_[i].t > keys_[i - 1].t)) throw std::invalid_argument("hand script keys must be in time order");
}

HandSample HandScript::at(double t) const noexcept {
  const auto after = std::upper_bound(keys_.begin(), keys_.end(), t,
                                      [](double time, const HandKey& key) { return time < key.t; });
  const HandKey& a = after == keys_.begin() ? keys_.front() : *(after - 1);
  const HandKey& b = after == keys_.end() ? keys_.back() : *after;
  const double u = b.t > a.t ? std::clamp((t - a.t) / (b.t - a.t), 0.0, 1.0) : 0.0;
  // Explicit return types: an Eigen expression returned by a lambda would outlive the
  // temporaries it refers to.
  const auto mix = [u](const Vec3& p, const Vec3& q) -> Vec3 { return (1 - u) * p + u * q; };

  const Mat3 turn = Eigen::AngleAxisd((1 - u) * a.turn + u * b.turn, up_).toRotationMatrix();
  const Vec3 shift = mix(a.shift, b.shift);
  const auto place = [&](const Vec3& local) -> Vec3 {
    return pivot_ + turn * (frame_.pointToAbsolute(local) - pivot_) + shift;
  };
  HandSample s;
  s.t = t;
  s.index = place(mix(a.index, b.index));
  s.thumb = place(mix(a.thumb, b.thumb));
  s.wrist = place(mix(a.wrist, b.wrist));
  for (std::size_t k = 0; k < a.extra.size(); ++k) s.extra[k] = place(mix(a.extra[k], b.extra[k]));
  s.wristRotation = turn * frame_.rotation * wristRotation_;
  return s;
}

}  // namespace hg::grasp
