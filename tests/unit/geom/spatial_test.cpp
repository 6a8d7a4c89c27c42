// Embree queries and the neighbour grid against brute force.
#include <gtest/gtest.h>

#include <algorithm>

#include "follicle/core/context.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/geom/grid.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/geom/spatial_embree.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::geom;

namespace {
// Random triangle soup inside the unit cube plus a closed-ish structure.
TriMesh random_soup(uint64_t seed, int n) {
  Rng rng(seed);
  TriMesh m;
  for (int f = 0; f < n; ++f) {
    const Vec3 c(rng.uniform(), rng.uniform(), rng.uniform());
    for (int k = 0; k < 3; ++k)
      m.positions.push_back(c +
                            0.1 * Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)));
    m.faces.emplace_back(3 * f, 3 * f + 1, 3 * f + 2);
  }
  return m;
}

double brute_closest(const TriMesh& m, const Vec3& p) {
  double best = 1e300;
  for (const Vec3i& f : m.faces) {
    const Vec3& a = m.positions[std::size_t(f[0])];
    const Vec3& b = m.positions[std::size_t(f[1])];
    const Vec3& c = m.positions[std::size_t(f[2])];
    const Vec3 w = closest_point_on_triangle(p, a, b, c);
    best = std::min(best, (w[0] * a + w[1] * b + w[2] * c - p).norm());
  }
  return best;
}
}  // namespace

TEST(ClosestPointOnTriangle, RegionsAgainstDenseSampling) {
  Rng rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 a(rng.normal(), rng.normal(), rng.normal()),
        b(rng.normal(), rng.normal(), rng.normal()), c(rng.normal(), rng.normal(), rng.normal()),
        p(2 * rng.normal(), 2 * rng.normal(), 2 * rng.normal());
    const Vec3 w = closest_point_on_triangle(p, a, b, c);
    EXPECT_NEAR(w.sum(), 1.0, 1e-12);
    EXPECT_GE(w.minCoeff(), -1e-12);
    const double d = (w[0] * a + w[1] * b + w[2] * c - p).norm();
    // No point of a dense barycentric lattice is closer.
    const int N = 40;
    for (int i = 0; i <= N; ++i)
      for (int j = 0; i + j <= N; ++j) {
        const Vec3 q = (double(N - i - j) * a + double(i) * b + double(j) * c) / N;
        ASSERT_GE((q - p).norm(), d - 1e-12);
      }
  }
}

TEST(MeshQuery, ClosestPointMatchesBruteForce) {
  const TriMesh m = random_soup(3, 300);
  const MeshQuery q(m);
  Rng rng(11);
  std::vector<Vec3> pts;
  for (int i = 0; i < 400; ++i)
    pts.emplace_back(rng.uniform(-0.3, 1.3), rng.uniform(-0.3, 1.3), rng.uniform(-0.3, 1.3));
  Context ctx(2);
  const auto batch = q.closest_points(ctx, pts);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const ClosestPoint cp = q.closest_point(pts[i]);
    EXPECT_NEAR(cp.distance, brute_closest(m, pts[i]), 1e-12) << i;
    EXPECT_EQ(batch[i].face, cp.face);
    EXPECT_EQ(batch[i].distance, cp.distance);
    // Barycentrics reproduce the point, the point is at the reported distance.
    const Vec3i& f = m.faces[std::size_t(cp.face)];
    const Vec3 x = cp.bary[0] * m.positions[std::size_t(f[0])] +
                   cp.bary[1] * m.positions[std::size_t(f[1])] +
                   cp.bary[2] * m.positions[std::size_t(f[2])];
    EXPECT_NEAR((x - cp.point).norm(), 0, 1e-12);
    EXPECT_NEAR((cp.point - pts[i]).norm(), cp.distance, 1e-12);
  }
  // A cut-off radius smaller than the true distance finds nothing.
  const Vec3 far(5, 5, 5);
  EXPECT_EQ(q.closest_point(far, 1.0).face, -1);
  EXPECT_GE(q.closest_point(far).face, 0);
}

TEST(MeshQuery, RayHitsMatchBruteForceOnPlane) {
  TriMesh quad;
  quad.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  quad.faces = {Vec3i(0, 1, 2), Vec3i(0, 2, 3)};
  const MeshQuery q(quad);
  const RayHit h = q.intersect(Vec3(0.7, 0.2, 2), Vec3(0, 0, -1));
  ASSERT_TRUE(h.hit);
  EXPECT_EQ(h.face, 0);
  EXPECT_NEAR(h.distance, 2.0, 1e-6);
  EXPECT_NEAR((h.point - Vec3(0.7, 0.2, 0)).norm(), 0, 1e-6);
  EXPECT_NEAR(h.bary.sum(), 1.0, 1e-12);
  EXPECT_FALSE(q.intersect(Vec3(1.5, 0.2, 2), Vec3(0, 0, -1)).hit);
  EXPECT_FALSE(q.intersect(Vec3(0.5, 0.5, 2), Vec3(0, 0, -1), 0, 1.5).hit);  // tmax
  EXPECT_TRUE(q.occluded(Vec3(0.5, 0.5, -1), Vec3(0, 0, 1)));
  EXPECT_FALSE(q.occluded(Vec3(0.5, 0.5, 1), Vec3(0, 0, 1)));
  // Random rays against the soup: the hit distance equals the brute-force minimum.
  const TriMesh soup = random_soup(5, 200);
  const MeshQuery qs(soup);
  Rng rng(9);
  for (int i = 0; i < 200; ++i) {
    const Vec3 o(rng.uniform(-1, 2), rng.uniform(-1, 2), -1);
    const Vec3 d = (Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - o).normalized();
    double best = std::numeric_limits<double>::infinity();
    for (const Vec3i& f : soup.faces) {  // Moeller-Trumbore
      const Vec3 a = soup.positions[std::size_t(f[0])], e1 = soup.positions[std::size_t(f[1])] - a,
                 e2 = soup.positions[std::size_t(f[2])] - a;
      const Vec3 pv = d.cross(e2);
      const double det = e1.dot(pv);
      if (std::abs(det) < 1e-14) continue;
      const Vec3 tv = o - a;
      const double u = tv.dot(pv) / det;
      const Vec3 qv = tv.cross(e1);
      const double v = d.dot(qv) / det, t = e2.dot(qv) / det;
      if (u >= 0 && v >= 0 && u + v <= 1 && t > 0) best = std::min(best, t);
    }
    const RayHit rh = qs.intersect(o, d);
    ASSERT_EQ(rh.hit, std::isfinite(best)) << i;
    if (rh.hit) {
      EXPECT_NEAR(rh.distance, best, 1e-5);
    }
  }
}

TEST(MeshQuery, EmptyMeshIsAnError) {
  EXPECT_THROW(MeshQuery(TriMesh{}), Error);
}

TEST(NeighbourGrid, QueryAndPairsMatchBruteForce) {
  Rng rng(21);
  std::vector<Vec3f> pts;
  for (int i = 0; i < 3000; ++i)
    pts.emplace_back(float(rng.uniform()), float(rng.uniform(0, 0.5)), float(rng.uniform()));
  pts.push_back(pts[5]);  // duplicate point
  const float r = 0.06f;
  auto within = [&](const Vec3f& a, const Vec3f& b, float rr) {
    const float dx = b.x() - a.x(), dy = b.y() - a.y(), dz = b.z() - a.z();
    return dx * dx + dy * dy + dz * dz <= rr * rr;
  };
  for (int threads : {1, 2}) {
    Context ctx(threads);
    NeighbourGrid g;
    g.build(ctx, pts, r);
    for (int t = 0; t < 100; ++t) {
      const Vec3f p(float(rng.uniform(-0.1, 1.1)), float(rng.uniform(-0.1, 0.6)),
                    float(rng.uniform(-0.1, 1.1)));
      for (float rr : {0.5f * r, r, 3.0f * r}) {
        std::vector<uint32_t> expect;
        for (uint32_t i = 0; i < pts.size(); ++i)
          if (within(pts[i], p, rr)) expect.push_back(i);
        EXPECT_EQ(g.query(p, rr), expect);
      }
    }
    const auto pairs = g.all_pairs(ctx, r);
    std::vector<std::pair<uint32_t, uint32_t>> expect;
    for (uint32_t i = 0; i < pts.size(); ++i)
      for (uint32_t j = i + 1; j < pts.size(); ++j)
        if (within(pts[j], pts[i], r)) expect.emplace_back(i, j);
    EXPECT_EQ(pairs, expect) << threads << " threads";
    const NeighbourList nl = g.neighbour_lists(ctx, r);
    ASSERT_EQ(nl.size(), pts.size());
    EXPECT_EQ(nl.index.size(), 2 * expect.size());
  }
}

TEST(NeighbourGrid, DeterministicAcrossThreadCountsAndHugeSparseDomains) {
  Rng rng(5);
  std::vector<Vec3> pts;
  for (int i = 0; i < 2000; ++i) pts.emplace_back(rng.uniform(), rng.uniform(), rng.uniform());
  pts.emplace_back(1e6, 1e6, 1e6);  // far outlier forces a coarser grid, results stay exact
  Context c1(1), c2(2);
  NeighbourGrid g1, g2;
  g1.build(c1, pts, 0.05);
  g2.build(c2, pts, 0.05);
  const auto a = g1.neighbour_lists(c1, 0.05f), b = g2.neighbour_lists(c2, 0.05f);
  EXPECT_EQ(a.offsets, b.offsets);
  EXPECT_EQ(a.index, b.index);
  std::size_t brute = 0;
  for (std::size_t i = 0; i < pts.size(); ++i)
    for (std::size_t j = 0; j < pts.size(); ++j) {
      const Vec3f d = (pts[i].cast<float>() - pts[j].cast<float>());
      if (i != j && d.x() * d.x() + d.y() * d.y() + d.z() * d.z() <= 0.05f * 0.05f) ++brute;
    }
  EXPECT_EQ(a.index.size(), brute);
  std::vector<Vec3> bad = {Vec3(0, 0, 0), Vec3(std::nan(""), 0, 0)};
  NeighbourGrid g3;
  EXPECT_THROW(g3.build(c1, bad, 0.1), Error);
  EXPECT_THROW(g3.build(c1, pts, 0.0), Error);
  NeighbourGrid empty;
  empty.build(c1, std::vector<Vec3f>{}, 0.1f);
  EXPECT_TRUE(empty.query(Vec3f(0, 0, 0), 1.0f).empty());
}

TEST(MeshQuery, DefaultHeadClosestPointSpotCheck) {
  const auto path = test::source_dir() / "data/meshes/lee_perry_smith/head.obj";
  ASSERT_TRUE(std::filesystem::exists(path));
  const TriMesh head = load_mesh(path, LengthUnit::mm);
  const MeshQuery q(head);
  Rng rng(2);
  const auto box = head.bounds();
  for (int i = 0; i < 20; ++i) {
    const Vec3 p =
        box.min() + Vec3(rng.uniform(), rng.uniform(), rng.uniform()).cwiseProduct(box.sizes());
    EXPECT_NEAR(q.closest_point(p).distance, brute_closest(head, p), 1e-12);
  }
  // Vertices lie on the surface.
  for (std::size_t v = 0; v < head.num_vertices(); v += 997)
    EXPECT_NEAR(q.closest_point(head.positions[v]).distance, 0, 1e-12);
}
