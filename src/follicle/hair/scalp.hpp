#pragma once
// The real head surface as seen by the hair module: closest point + outward normal. Roots are
// placed on it (Anjyo 1992 step [α]: pores given on the hull, then moved to the scalp) and the
// cantilever can optionally avoid it. Backed by geom::MeshQuery (Embree) in the scene; a brute
// force version is here for small meshes and tests.
#include <functional>
#include <memory>

#include "follicle/core/types.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::geom {
class MeshQuery;
}

namespace follicle::hair {

struct SurfaceHit {
  Vec3 point = Vec3::Zero();    // closest point on the surface [m]
  Vec3 normal = Vec3::UnitY();  // outward unit normal (of the face holding `point`)
};

/// Closest point on a surface to a query point. Must be thread-safe (called from parallel loops).
using ClosestPointFn = std::function<SurfaceHit(const Vec3&)>;

/// O(faces) per query; fine for tests and a few thousand roots. The mesh must outlive the result.
ClosestPointFn brute_force_closest_point(const geom::TriMesh& mesh);

/// Embree-backed query (geom::MeshQuery); the query must outlive the result.
ClosestPointFn mesh_query_closest_point(const geom::MeshQuery& query);

/// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection §5.1.5).
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace follicle::hair
