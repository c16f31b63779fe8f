#include "hapticgrasp/geometry/winding_number.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>

#include "hapticgrasp/geometry/aabb.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"

namespace hg::geometry {

// Van Oosterom & Strackee 1983: tan(omega / 2) = a.(b x c) / (|a||b||c| + (a.b)|c| +
// (b.c)|a| + (c.a)|b|). atan2 keeps the quadrant, so omega runs over (-2 pi, 2 pi]; and it
// answers 0 rather than NaN when a corner is the origin.
double solidAngle(const Vec3& a, const Vec3& b, const Vec3& c) noexcept {
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  return 2 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
}

WindingNumber::WindingNumber(const std::vector<Vec3>& vertices, const std::vector<Eigen::Vector3i>& triangles) {
  const int count = static_cast<int>(triangles.size());
  if (triangles.size() > static_cast<std::size_t>(count))
    throw GeometryError("winding number: too many triangles");
  std::vector<Vec3> centroids(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k)
      if (triangles[t][k] < 0 || static_cast<std::size_t>(triangles[t][k]) >= vertices.size())
        throw GeometryError("winding number: triangle " + std::to_string(t) + " names no vertex");
    centroids[t] = (vertices[triangles[t][0]] + vertices[triangles[t][1]] + vertices[triangles[t][2]]) / 3;
  }
  if (count == 0) return;  // no surface: w = 0 everywhere

  std::vector<int> order(triangles.size());
  std::iota(order.begin(), order.end(), 0);
  build(order, centroids, 0, count, 0);
  clusters_.shrink_to_fit();  // held for the part's lifetime

  triangles_.reserve(triangles.size());
  for (const int t : order)
    triangles_.push_back({{vertices[triangles[t][0]], vertices[triangles[t][1]], vertices[triangles[t][2]]}});
  for (Cluster& cluster : clusters_) computeMoments(cluster);
}

// Halves the triangles at the median of their centroids along the widest axis of those
// centroids: a balanced tree, so the depth (and the traversal's stack) is logarithmic
// whatever the mesh. (Embree's BVH would do for the tree, but its nodes are hidden from
// its queries and so cannot carry the moments; its surface-area heuristic serves rays.)
int WindingNumber::build(std::vector<int>& order, const std::vector<Vec3>& centroids, int begin, int end, int depth) {
  if (depth >= kMaxDepth) throw GeometryError("winding number: the tree is too deep");  // unreachable: median split
  const int index = static_cast<int>(clusters_.size());
  clusters_.emplace_back();
  clusters_[index].begin = begin;
  clusters_[index].end = end;
  if (end - begin <= kLeafSize) return index;

  Aabb box;
  for (int i = begin; i < end; ++i) box.extend(centroids[order[i]]);
  int axis = 0;
  box.size().maxCoeff(&axis);
  const int middle = begin + (end - begin) / 2;
  std::nth_element(order.begin() + begin, order.begin() + middle, order.begin() + end,
                   [&](int a, int b) { return centroids[a][axis] < centroids[b][axis]; });
  build(order, centroids, begin, middle, depth + 1);  // the first child is the next cluster
  const int right = build(order, centroids, middle, end, depth + 1);
  clusters_[index].right = right;
  return index;
}

// A flat triangle's normal is constant, so each moment is its area vector A = n area times
// a moment of the triangle's area about the cluster's centre: with o the offset of the
// triangle's centroid, integral of d is o area, and integral of d d^T is
// (o o^T + (1/12) sum over corners of e e^T) area, e a corner's offset from the centroid
// (the covariance of a uniform triangle).
void WindingNumber::computeMoments(Cluster& cluster) const {
  double area = 0;
  Vec3 weighted = Vec3::Zero(), mean = Vec3::Zero();
  for (int t = cluster.begin; t < cluster.end; ++t) {
    const Vec3* p = triangles_[t].corner;
    const Vec3 centroid = (p[0] + p[1] + p[2]) / 3;
    const double a = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    area += a;
    weighted += a * centroid;
    mean += centroid;
  }
  // Slivers only: no area to weigh by, and no moment either; any centre will do.
  cluster.centre = area > 0 ? Vec3(weighted / area) : Vec3(mean / (cluster.end - cluster.begin));
  for (int t = cluster.begin; t < cluster.end; ++t) {
    const Vec3* p = triangles_[t].corner;
    const Vec3 areaVector = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]);
    const Vec3 centroid = (p[0] + p[1] + p[2]) / 3;
    const Vec3 o = centroid - cluster.centre;
    Mat3 spread = o * o.transpose();
    for (int k = 0; k < 3; ++k) {
      const Vec3 e = p[k] - centroid;
      spread += e * e.transpose() / 12;
      cluster.radius = std::max(cluster.radius, (p[k] - cluster.centre).norm());
    }
    cluster.dipole += areaVector;
    cluster.first += areaVector * o.transpose();
    for (int i = 0; i < 3; ++i) cluster.second[i] += areaVector[i] * spread;
  }
}

// The solid angle of a far cluster: integral over its surface of n . g(p - x), where
// g(r) = r / |r|^3 (whose flux through a closed surface around x is 4 pi), expanded about
// r = centre - x to second order in d = p - centre:
//   g_i(r + d) ~ g_i + d_j dg_i/dr_j + 1/2 d_j d_k d2g_i/dr_j dr_k,
//   dg_i/dr_j = delta_ij / |r|^3 - 3 r_i r_j / |r|^5,
//   d2g_i/dr_j dr_k = -3 (delta_ij r_k + delta_ik r_j + delta_jk r_i) / |r|^5 + 15 r_i r_j r_k / |r|^7,
// each term contracted with its moment (Barill et al. 2018, section 3.2).
double WindingNumber::farField(const Cluster& c, const Vec3& x) const noexcept {
  const Vec3 r = c.centre - x;
  const double r2 = r.squaredNorm(), length = std::sqrt(r2);
  const double inv3 = 1 / (r2 * length), inv5 = inv3 / r2, inv7 = inv5 / r2;
  const double zeroth = r.dot(c.dipole) * inv3;
  const double first = c.first.trace() * inv3 - 3 * r.dot(c.first * r) * inv5;
  double contracted = 0, traced = 0, cubic = 0;  // sum_i (S_i r)_i, sum_i r_i tr S_i, sum_i r_i r.S_i r
  for (int i = 0; i < 3; ++i) {
    const Vec3 sr = c.second[i] * r;
    contracted += sr[i];
    traced += r[i] * c.second[i].trace();
    cubic += r[i] * r.dot(sr);
  }
  const double second = 0.5 * (-3 * (2 * contracted + traced) * inv5 + 15 * cubic * inv7);
  return zeroth + first + second;
}

double WindingNumber::at(const Vec3& x) const noexcept {
  if (clusters_.empty()) return 0;
  const double farSquared = kBeta * kBeta;
  int stack[kMaxDepth + 1];  // a cluster at depth d leaves at most d + 1 entries
  int size = 0;
  stack[size++] = 0;
  double omega = 0;
  while (size > 0) {
    const int index = stack[--size];
    const Cluster& c = clusters_[index];
    if ((c.centre - x).squaredNorm() > farSquared * c.radius * c.radius) {
      omega += farField(c, x);
    } else if (c.right == 0) {
      for (int t = c.begin; t < c.end; ++t) {
        const Vec3* p = triangles_[t].corner;
        omega += solidAngle(p[0] - x, p[1] - x, p[2] - x);
      }
    } else {
      stack[size++] = c.right;
      stack[size++] = index + 1;
    }
  }
  return omega / (4 * std::numbers::pi);
}

double WindingNumber::exact(const Vec3& x) const noexcept {
  double omega = 0;
  for (const Triangle& t : triangles_) omega += solidAngle(t.corner[0] - x, t.corner[1] - x, t.corner[2] - x);
  return omega / (4 * std::numbers::pi);
}

std::size_t WindingNumber::memoryBytes() const noexcept {
  return triangles_.capacity() * sizeof(Triangle) + clusters_.capacity() * sizeof(Cluster);
}

}  // namespace hg::geometry
