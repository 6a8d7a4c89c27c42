#include "follicle/hair/scalp.hpp"

#include <limits>

#include "follicle/geom/spatial_embree.hpp"

namespace follicle::hair {

Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

ClosestPointFn brute_force_closest_point(const geom::TriMesh& mesh) {
  const geom::TriMesh* m = &mesh;
  return [m](const Vec3& p) {
    SurfaceHit best;
    double bd = std::numeric_limits<double>::infinity();
    for (const auto& f : m->faces) {
      const Vec3& a = m->positions[std::size_t(f[0])];
      const Vec3& b = m->positions[std::size_t(f[1])];
      const Vec3& c = m->positions[std::size_t(f[2])];
      const Vec3 x = closest_point_on_triangle(p, a, b, c);
      const double d = (x - p).squaredNorm();
      if (d < bd) {
        bd = d;
        best.point = x;
        const Vec3 n = (b - a).cross(c - a);
        best.normal = n.norm() > 0 ? Vec3(n.normalized()) : Vec3::UnitY();
      }
    }
    return best;
  };
}

ClosestPointFn mesh_query_closest_point(const geom::MeshQuery& query) {
  const geom::MeshQuery* q = &query;
  return [q](const Vec3& p) {
    SurfaceHit h;
    const geom::ClosestPoint c = q->closest_point(p);
    if (c.face < 0) {
      h.point = p;
      return h;
    }
    h.point = c.point;
    const Vec3i f = q->faces()[std::size_t(c.face)];
    const auto& P = q->positions();
    const Vec3 n = (P[std::size_t(f[1])] - P[std::size_t(f[0])])
                       .cross(P[std::size_t(f[2])] - P[std::size_t(f[0])]);
    if (n.norm() > 0) h.normal = n.normalized();
    return h;
  };
}

}  // namespace follicle::hair
