#include "hapticgrasp/grasp/multi_finger/god_object.hpp"

#include <algorithm>
#include <cmath>

namespace hg::grasp::multi_finger {

using geometry::Feature;
using geometry::Penetration;

void GodObject::reset() noexcept {
  state_.reset();
  release();
}

void GodObject::release() noexcept {
  contact_ = GodObjectContact{};
  u_ = v_ = 0;
}

const GodObjectContact& GodObject::update(const Vec3& x) noexcept {
  if (!x.allFinite()) return contact_;
  Penetration pen;
  bool held = false;
  // The face the finger entered through: held while x is behind its tangent plane.
  if (contact_.inContact && contact_.feature == Feature::Face) {
    double u = u_, v = v_;
    if (model_->againstFeature(x, Feature::Face, contact_.featureIndex, u, v, pen) &&
        pen.normal.allFinite() && (x - pen.foot).dot(pen.normal) < 0) {
      u_ = u;
      v_ = v;
      held = true;
    }
  }
  if (!held) {
    // Not (or no longer) behind a held face: the closest feature, with tracking at edges.
    pen = model_->track(x, state_, params_.hysteresis_m);
    if (!pen.inside || !pen.normal.allFinite() || pen.normal.squaredNorm() < 0.25) {
      const Vec3 last = contact_.proxy;
      release();
      contact_.proxy = pen.inside ? last : x;
      return contact_;
    }
    if (!contact_.inContact || contact_.feature != pen.feature || contact_.featureIndex != pen.featureIndex) {
      u_ = state_.tu;  // the tracked feature's parameters warm-start the held face
      v_ = state_.tv;
    }
  }

  const Vec3 n = pen.normal.normalized();
  const Vec3 foot = pen.foot;
  const double k = params_.stiffness > 0 ? params_.stiffness : 0.0;
  const double depth = std::max(0.0, (foot - x).dot(n));
  // Stick: last tick's proxy, kept on the tangent plane at the foot.
  Vec3 proxy = foot;
  bool sliding = false;
  if (contact_.inContact) {
    const Vec3 stuck = contact_.proxy - (contact_.proxy - foot).dot(n) * n;
    const Vec3 offset = stuck - foot;  // tangential
    const double tangential = k * offset.norm();
    const double limit = std::max(0.0, params_.friction) * k * depth;
    if (tangential <= limit) {
      proxy = stuck;
    } else {
      proxy = foot + offset * (limit / tangential);  // the friction cone's edge
      sliding = true;
    }
  }
  contact_.inContact = true;
  contact_.proxy = proxy;
  contact_.normal = n;
  contact_.force = k * (proxy - x);
  contact_.normalForce = contact_.force.dot(n);
  contact_.tangentialForce = (contact_.force - contact_.normalForce * n).norm();
  contact_.depth = depth;
  contact_.sliding = sliding;
  contact_.feature = pen.feature;
  contact_.featureIndex = pen.featureIndex;
  return contact_;
}

}  // namespace hg::grasp::multi_finger
