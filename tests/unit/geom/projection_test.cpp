#include "follicle/geom/projection.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace follicle;
using namespace follicle::geom;

TEST(Projection, PlanarIsAffine) {
  PlanarProjection p;
  p.origin = Vec3(1, 2, 3);
  p.u_axis = Vec3(0, 0, 2);
  p.v_axis = Vec3(1, 0, 0);
  p.scale = 0.5;
  const auto uv = project_planar({Vec3(1, 2, 3), Vec3(2, 5, 4)}, p);
  EXPECT_NEAR(uv[0].norm(), 0, 1e-15);
  EXPECT_NEAR(uv[1].x(), 2.0, 1e-15);
  EXPECT_NEAR(uv[1].y(), 2.0, 1e-15);
  p.v_axis = p.u_axis;
  EXPECT_THROW(project_planar({Vec3::Zero()}, p), Error);
}

TEST(Projection, CylindricalAnglesAndSeamWrap) {
  CylindricalProjection c;  // axis y, u = 0.5 at +z, seam at -z
  std::vector<Vec3> ring;
  const int n = 16;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * kPi * i / n;
    ring.emplace_back(std::sin(a), 0, std::cos(a));
    ring.emplace_back(std::sin(a), 1, std::cos(a));
  }
  const auto uv = project_cylindrical(ring, c);
  EXPECT_NEAR(uv[0].x(), 0.5, 1e-12);
  for (const auto& t : uv) {
    EXPECT_GE(t.x(), 0.0);
    EXPECT_LT(t.x(), 1.0);
  }
  EXPECT_NEAR(uv[1].y(), 1.0, 1e-12);
  // A closed band of quads around the axis: after wrap every triangle is continuous in u.
  TriMesh m;
  m.positions = ring;
  for (int i = 0; i < n; ++i) {
    const int a = 2 * i, b = 2 * ((i + 1) % n);
    m.faces.emplace_back(a, b, b + 1);
    m.faces.emplace_back(a, b + 1, a + 1);
  }
  assign_uvs(m, uv, true);
  m.check("band");
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    double lo = 10, hi = -10;
    for (int k = 0; k < 3; ++k) {
      lo = std::min(lo, m.uvs[std::size_t(m.uv_faces[f][k])].x());
      hi = std::max(hi, m.uvs[std::size_t(m.uv_faces[f][k])].x());
    }
    EXPECT_LT(hi - lo, 0.5);
  }
  EXPECT_GT(m.uvs.size(), uv.size());  // seam copies were added
  EXPECT_NEAR(wrapped_uv_delta(Vec2(0.98, 0), Vec2(0.02, 0)).x(), -0.04, 1e-12);
}
