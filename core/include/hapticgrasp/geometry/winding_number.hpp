#pragma once
// The generalised winding number of a triangle mesh (Jacobson, Kavan & Sorkine-Hornung
// 2013): the solid angles its triangles subtend at a point, summed and divided by 4 pi. On
// a closed mesh that does not cross itself it is 1 inside and 0 outside; where the surface
// crosses itself it counts how often the point is enclosed (2 where two lobes overlap, -1
// in a lobe turned inside out). A part encloses x iff w(x) > 1/2: unlike a nearest face's
// normal or a ray's parity, this does not depend on the surface being sound.
//
// Summing every triangle costs a query the whole mesh. The hierarchical approximation of
// Barill, Dickson, Schmidt, Levin & Jacobson 2018 ("Fast winding numbers for soups and
// clouds") groups the triangles in a tree of clusters; a cluster seen from farther than
// beta times its radius contributes the Taylor expansion, to second order, of its dipole
// field about its area-weighted centre; a nearer one is opened, down to the exact solid
// angles of its triangles (Van Oosterom & Strackee 1983). Near the surface, where the
// answer jumps from 0 to 1, the nearby triangles are therefore always exact.
#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <vector>

#include "hapticgrasp/math/types.hpp"

namespace hg::geometry {

// The signed solid angle (steradians) the triangle abc subtends at the origin: positive
// when the origin lies behind it, on the side its normal (b - a) x (c - a) points away
// from (as the inside of a closed mesh whose triangles face outwards does). Van Oosterom &
// Strackee's closed form; 0 when the origin lies in the triangle's plane.
double solidAngle(const Vec3& a, const Vec3& b, const Vec3& c) noexcept;

class WindingNumber {
 public:
  // Barill et al.'s accuracy parameter beta: a cluster is expanded only when the point lies
  // farther from its centre than beta times its radius. Their default; the order of the
  // expansion (2) is theirs too.
  static constexpr double kBeta = 2.0;

  // Any triangles: closed or not, crossing or not, slivers included (they subtend nothing).
  // Throws GeometryError for an index out of range.
  WindingNumber(const std::vector<Vec3>& vertices, const std::vector<Eigen::Vector3i>& triangles);

  // The hierarchical approximation at x: real-time safe (no heap, no lock, no throw) and
  // bounded (it visits each cluster and triangle at most once).
  double at(const Vec3& x) const noexcept;
  // Whether the mesh encloses x at all: at(x) > 1/2.
  bool encloses(const Vec3& x) const noexcept { return at(x) > 0.5; }
  // Every triangle's exact solid angle: the truth the approximation is held to (tests).
  double exact(const Vec3& x) const noexcept;

  std::size_t triangleCount() const noexcept { return triangles_.size(); }
  std::size_t clusterCount() const noexcept { return clusters_.size(); }
  std::size_t memoryBytes() const noexcept;

 private:
  struct Triangle {
    Vec3 corner[3];
  };
  // A node of the tree. Its moments are integrals over its triangles of the unit normal n
  // times powers of d = p - centre, the offset of the surface point p from the centre:
  // dipole = integral of n (the area-weighted normal sum), first_ij = integral of n_i d_j,
  // second[i]_jk = integral of n_i d_j d_k.
  struct Cluster {
    Vec3 centre = Vec3::Zero();  // area-weighted centroid
    double radius = 0;           // farthest triangle corner from the centre
    Vec3 dipole = Vec3::Zero();
    Mat3 first = Mat3::Zero();
    std::array<Mat3, 3> second{Mat3::Zero(), Mat3::Zero(), Mat3::Zero()};
    int begin = 0, end = 0;  // its triangles, [begin, end) of triangles_
    int right = 0;           // the second child (the first is the next cluster); 0 for a leaf
  };
  // Leaves hold at most this many triangles: below it, a cluster's expansion costs about
  // what its triangles' exact solid angles do.
  static constexpr int kLeafSize = 8;
  // The traversal's stack, on the caller's stack: a median split keeps the depth near
  // log2(triangles / kLeafSize), far below this for any mesh that fits in memory.
  static constexpr int kMaxDepth = 64;

  int build(std::vector<int>& order, const std::vector<Vec3>& centroids, int begin, int end, int depth);
  void computeMoments(Cluster& cluster) const;
  double farField(const Cluster& cluster, const Vec3& x) const noexcept;

  std::vector<Triangle> triangles_;  // in the tree's order: each cluster's are contiguous
  std::vector<Cluster> clusters_;    // depth first: clusters_[0] is the root
};

}  // namespace hg::geometry
