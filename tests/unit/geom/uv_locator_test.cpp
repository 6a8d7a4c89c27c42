// UvLocator (point location in texture space), uv_jacobian, uv_islands and fit_cubic_bezier:
// analytic cases on a flat grid whose UVs are an affine image of its positions.
#include "follicle/geom/uv_locator.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/geom/curves.hpp"

using namespace follicle;
using namespace follicle::geom;

namespace {

// n x n quads in the z = 0 plane over [0, 2] x [0, 1] m, two triangles each; uv = (x/2, y),
// optionally split into two UV islands at x = 1 (the right half's UVs shifted by +2 in u).
TriMesh grid(int n, bool split) {
  TriMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.positions.emplace_back(2.0 * i / n, double(j) / n, 0.0);
  auto id = [&](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.faces.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  // UV vertices: one per position, plus a second copy for the right half when split.
  const int nv = int(m.positions.size());
  for (const auto& p : m.positions) m.uvs.emplace_back(p.x() / 2, p.y());
  if (split)
    for (const auto& p : m.positions) m.uvs.emplace_back(p.x() / 2 + 2.0, p.y());
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    Vec3i t = m.faces[f];
    const bool right = (f / 2) % std::size_t(n) >= std::size_t(n / 2);
    if (split && right) t += Vec3i::Constant(nv);
    m.uv_faces.push_back(t);
  }
  return m;
}

}  // namespace

TEST(UvLocator, FindsTheFaceAndWeightsOfAnyPoint) {
  const TriMesh m = grid(8, false);
  const UvLocator loc(m);
  for (const Vec2& q : {Vec2(0.13, 0.71), Vec2(0.5, 0.5), Vec2(0.999, 0.001), Vec2(0, 0)}) {
    const UvHit h = loc.locate(q);
    ASSERT_GE(h.face, 0) << q.transpose();
    EXPECT_NEAR(h.bary.sum(), 1.0, 1e-12);
    EXPECT_GE(h.bary.minCoeff(), 0.0);
    // The weights reproduce the point in texture space and on the surface (x = 2u, y = v).
    const Vec3i& t = m.uv_faces[std::size_t(h.face)];
    const Vec2 back = h.bary[0] * m.uvs[std::size_t(t[0])] + h.bary[1] * m.uvs[std::size_t(t[1])] +
                      h.bary[2] * m.uvs[std::size_t(t[2])];
    EXPECT_LT((back - q).norm(), 1e-12);
    const Vec3i& f = m.faces[std::size_t(h.face)];
    const Vec3 p = h.bary[0] * m.positions[std::size_t(f[0])] +
                   h.bary[1] * m.positions[std::size_t(f[1])] +
                   h.bary[2] * m.positions[std::size_t(f[2])];
    EXPECT_LT((p - Vec3(2 * q.x(), q.y(), 0)).norm(), 1e-12);
  }
  EXPECT_EQ(loc.locate(Vec2(1.2, 0.5)).face, -1);
  EXPECT_EQ(loc.locate(Vec2(-0.01, 0.5)).face, -1);
  EXPECT_EQ(loc.locate(Vec2(std::nan(""), 0.5)).face, -1);
  // Just outside the border: found with a tolerance, not without.
  EXPECT_EQ(loc.locate(Vec2(1.0 + 1e-9, 0.5)).face, -1);
  EXPECT_GE(loc.locate(Vec2(1.0 + 1e-9, 0.5), 1e-6).face, 0);
}

TEST(UvLocator, RefusesAMeshWithoutUvs) {
  TriMesh m = grid(2, false);
  m.uvs.clear();
  m.uv_faces.clear();
  EXPECT_THROW(UvLocator{m}, Error);
}

TEST(UvLocator, JacobianAndIslands) {
  const TriMesh m = grid(4, true);
  // uv = (x/2, y): dP/du = (2, 0, 0), dP/dv = (0, 1, 0) on every face.
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const auto j = uv_jacobian(m, f);
    EXPECT_LT((j.col(0) - Vec3(2, 0, 0)).norm(), 1e-12);
    EXPECT_LT((j.col(1) - Vec3(0, 1, 0)).norm(), 1e-12);
  }
  const auto isl = uv_islands(m);
  ASSERT_EQ(isl.size(), m.faces.size());
  EXPECT_EQ(isl.front(), 0);
  int left = 0, right = 0;
  for (std::size_t f = 0; f < isl.size(); ++f) ((f / 2) % 4 >= 2 ? right : left) += isl[f];
  EXPECT_EQ(left, 0);                     // every left face on island 0
  EXPECT_EQ(right, int(isl.size()) / 2);  // every right face on island 1
  // The right island is found at its shifted texture position.
  const UvLocator loc(m);
  const UvHit h = loc.locate(Vec2(2.8, 0.4));
  ASSERT_GE(h.face, 0);
  EXPECT_EQ(isl[std::size_t(h.face)], 1);
}

TEST(FitCubicBezier, ReproducesLinesAndCubicsAndRefusesBadInput) {
  // Points on a straight line: the fitted curve lies on it.
  std::vector<Vec2> line;
  for (int i = 0; i <= 8; ++i) line.emplace_back(0.1 + 0.05 * i, 0.2 - 0.02 * i);
  const Bezier2 l = fit_cubic_bezier<2>(line);
  for (double t = 0; t <= 1; t += 0.05) {
    const Vec2 p = l.eval(t);
    EXPECT_NEAR((p.y() - 0.2) * 0.05 + (p.x() - 0.1) * 0.02, 0.0, 1e-12);
  }
  // Samples of a cubic at uniform arc length: the fit passes within 0.2% of its size.
  Bezier3 c;
  c.p = {Vec3(0, 0, 0), Vec3(0.3, 0.4, 0.1), Vec3(0.7, 0.4, -0.1), Vec3(1, 0, 0)};
  const auto pts = c.sample_by_length(9);
  const Bezier3 f = fit_cubic_bezier<3>(pts);
  EXPECT_LT((f.p[0] - c.p[0]).norm(), 1e-15);
  EXPECT_LT((f.p[3] - c.p[3]).norm(), 1e-15);
  for (const Vec3& q : c.sample(41)) {
    double d = 0;
    f.closest_parameter(q, &d);
    EXPECT_LT(d, 2e-3) << q.transpose();
  }
  // Two points: the segment.
  const Bezier2 s = fit_cubic_bezier<2>({Vec2(0, 0), Vec2(3, 0)});
  EXPECT_LT((s.eval(0.5) - Vec2(1.5, 0)).norm(), 1e-12);
  // All points in one place: a point curve, not NaN.
  const Bezier2 z = fit_cubic_bezier<2>({Vec2(1, 1), Vec2(1, 1), Vec2(1, 1)});
  EXPECT_TRUE(z.eval(0.3).allFinite());
  EXPECT_THROW(fit_cubic_bezier<2>({Vec2(0, 0)}), Error);
  EXPECT_THROW(fit_cubic_bezier<2>({Vec2(0, 0), Vec2(std::nan(""), 0)}), Error);
}
