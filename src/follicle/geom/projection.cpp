#include "follicle/geom/projection.hpp"

#include <cmath>

#include "follicle/core/error.hpp"

namespace follicle::geom {

void PlanarProjection::validate() const {
  validate_params(*this, "planar_projection");
  if (u_axis.norm() < 1e-12 || v_axis.norm() < 1e-12 || u_axis.cross(v_axis).norm() < 1e-9)
    fail_at("planar_projection", "u_axis and v_axis must be non-zero and not parallel");
}

void CylindricalProjection::validate() const {
  validate_params(*this, "cylindrical_projection");
  if (axis.norm() < 1e-12 || zero_dir.cross(axis).norm() < 1e-9)
    fail_at("cylindrical_projection", "axis must be non-zero and zero_dir not parallel to it");
}

std::vector<Vec2> project_planar(const std::vector<Vec3>& positions, const PlanarProjection& p) {
  p.validate();
  const Vec3 u = p.u_axis.normalized(), v = p.v_axis.normalized();
  std::vector<Vec2> out(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const Vec3 d = positions[i] - p.origin;
    out[i] = Vec2(d.dot(u), d.dot(v)) / p.scale;
  }
  return out;
}

std::vector<Vec2> project_cylindrical(const std::vector<Vec3>& positions,
                                      const CylindricalProjection& p) {
  p.validate();
  const Vec3 a = p.axis.normalized();
  const Vec3 z = (p.zero_dir - p.zero_dir.dot(a) * a).normalized();
  const Vec3 x = a.cross(z);  // counter-clockwise about a: z -> x
  std::vector<Vec2> out(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const Vec3 d = positions[i] - p.origin;
    const double ang = std::atan2(d.dot(x), d.dot(z));  // (-pi, pi], 0 at zero_dir
    double u = 0.5 + ang / (2 * kPi);
    if (u >= 1.0) u -= 1.0;
    out[i] = Vec2(u, d.dot(a) / p.height_scale);
  }
  return out;
}

Vec2 wrapped_uv_delta(const Vec2& a, const Vec2& b) {
  double du = a.x() - b.x();
  du -= std::floor(du + 0.5);
  return Vec2(du, a.y() - b.y());
}

void assign_uvs(TriMesh& mesh, const std::vector<Vec2>& vertex_uv, bool wrap_u) {
  if (vertex_uv.size() != mesh.positions.size())
    fail("assign_uvs: {} UVs for {} vertices", vertex_uv.size(), mesh.positions.size());
  mesh.uvs = vertex_uv;
  mesh.uv_faces = mesh.faces;
  if (!wrap_u) return;
  std::vector<int> shifted(vertex_uv.size(), -1);  // vertex -> index of its u+1 copy
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    double lo = 1e300, hi = -1e300;
    for (int k = 0; k < 3; ++k) {
      const double u = vertex_uv[std::size_t(mesh.faces[f][k])].x();
      lo = std::min(lo, u);
      hi = std::max(hi, u);
    }
    if (hi - lo <= 0.5) continue;
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.faces[f][k];
      if (vertex_uv[std::size_t(v)].x() < 0.5) {
        if (shifted[std::size_t(v)] < 0) {
          shifted[std::size_t(v)] = int(mesh.uvs.size());
          mesh.uvs.push_back(vertex_uv[std::size_t(v)] + Vec2(1.0, 0.0));
        }
        mesh.uv_faces[f][k] = shifted[std::size_t(v)];
      }
    }
  }
}

PlanarProjection fit_planar_projection(const std::vector<Vec3>& positions, const Vec3& view_dir,
                                       const Vec3& up) {
  if (positions.empty()) fail("fit_planar_projection: no vertices");
  const Vec3 n = view_dir.normalized();
  Vec3 v = (up - up.dot(n) * n);
  if (v.norm() < 1e-12) fail("fit_planar_projection: up is parallel to view_dir");
  v.normalize();
  const Vec3 u = v.cross(n);  // right-handed: u x v = n (seen from n, u right, v up)
  PlanarProjection p;
  p.u_axis = u;
  p.v_axis = v;
  Eigen::AlignedBox2d box;
  for (const auto& x : positions) box.extend(Vec2(x.dot(u), x.dot(v)));
  const double s = std::max(box.sizes().x(), box.sizes().y());
  p.scale = s > 0 ? s : 1.0;
  p.origin = box.min().x() * u + box.min().y() * v;
  return p;
}

}  // namespace follicle::geom
