#pragma once
// Embree-backed spatial queries on a triangle mesh: first-hit ray casts and closest-point
// queries. The Embree headers stay in the .cpp. Queries are const and thread-safe; build once,
// query from many threads.
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::geom {

struct RayHit {
  bool hit = false;
  int face = -1;
  Vec3 bary = Vec3::Zero();  // weights of the face's three corners (sum 1)
  double distance = std::numeric_limits<double>::infinity();  // along the ray, in |dir| units
  Vec3 point = Vec3::Zero();                                  // origin + distance * dir
};

struct ClosestPoint {
  Vec3 point = Vec3::Zero();
  int face = -1;             // -1 when nothing lies within max_distance
  Vec3 bary = Vec3::Zero();  // point = bary[0]*p0 + bary[1]*p1 + bary[2]*p2
  double distance = std::numeric_limits<double>::infinity();
};

/// Closest point to p on triangle (a, b, c), exact in double precision (Ericson, Real-Time
/// Collision Detection, 5.1.5). Returns the barycentric weights; the point is their combination.
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

class MeshQuery {
 public:
  /// Copies the mesh's positions and faces and builds the Embree BVH. Throws follicle::Error for
  /// an empty or invalid mesh.
  explicit MeshQuery(const TriMesh& mesh);
  ~MeshQuery();
  MeshQuery(MeshQuery&&) noexcept;
  MeshQuery& operator=(MeshQuery&&) noexcept;
  MeshQuery(const MeshQuery&) = delete;
  MeshQuery& operator=(const MeshQuery&) = delete;

  /// First hit of the ray origin + t*dir for t in [tmin, tmax]; both faces count.
  RayHit intersect(const Vec3& origin, const Vec3& dir, double tmin = 0.0,
                   double tmax = std::numeric_limits<double>::infinity()) const;
  /// True when anything is hit for t in [tmin, tmax] (shadow-ray test).
  bool occluded(const Vec3& origin, const Vec3& dir, double tmin = 0.0,
                double tmax = std::numeric_limits<double>::infinity()) const;
  /// Closest surface point to p within max_distance (face = -1 when none).
  ClosestPoint closest_point(const Vec3& p,
                             double max_distance = std::numeric_limits<double>::infinity()) const;
  /// Batched closest_point, parallel over queries via core parallel_for. out[i] is for pts[i].
  std::vector<ClosestPoint> closest_points(
      const Context& ctx, std::span<const Vec3> pts,
      double max_distance = std::numeric_limits<double>::infinity()) const;

  const std::vector<Vec3>& positions() const;
  const std::vector<Vec3i>& faces() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace follicle::geom
