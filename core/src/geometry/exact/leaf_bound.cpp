#include "leaf_bound.hpp"

#include <Eigen/Eigenvalues>

namespace hg::geometry::exact {

LeafBound LeafBound::around(const std::vector<Vec3>& points, const Vec3& axis, bool axisIsNormal, double margin) {
  LeafBound b;
  for (const Vec3& p : points) b.box.extend(p);
  b.box = b.box.inflated(margin);
  if (points.empty() || !(axis.norm() > 0)) return b;
  const Vec3 a = axis.normalized();
  // The spread of the points across `a`: its main direction is the next axis.
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Mat3 scatter = Mat3::Zero();
  for (const Vec3& p : points) {
    const Vec3 q = (p - mean) - a * a.dot(p - mean);
    scatter += q * q.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(scatter);
  Vec3 across = eig.eigenvectors().col(2);  // largest spread
  across = (across - a * a.dot(across));
  if (!(across.norm() > 1e-12)) across = a.unitOrthogonal();
  across.normalize();
  const Vec3 third = a.cross(across);
  if (axisIsNormal) b.axes << across, third, a;
  else b.axes << a, across, third;
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (const Vec3& p : points) {
    const Vec3 l = b.axes.transpose() * p;
    lo = lo.cwiseMin(l);
    hi = hi.cwiseMax(l);
  }
  b.centre = b.axes * (0.5 * (lo + hi));
  b.half = 0.5 * (hi - lo) + Vec3::Constant(margin);
  return b;
}

}  // namespace hg::geometry::exact
