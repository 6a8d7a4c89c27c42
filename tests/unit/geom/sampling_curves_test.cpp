// Surface sampling, Poisson-disc, Bézier and Catmull-Rom curves, mesh distance.
#include <gtest/gtest.h>

#include "follicle/core/context.hpp"
#include "follicle/core/error.hpp"
#include "follicle/geom/curves.hpp"
#include "follicle/geom/mesh_distance.hpp"
#include "follicle/geom/sampling.hpp"

using namespace follicle;
using namespace follicle::geom;

namespace {
TriMesh make_grid(int n, double size = 1.0) {
  TriMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.positions.emplace_back(size * i / n, size * j / n, 0);
  auto id = [&](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.faces.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  return m;
}
}  // namespace

TEST(Sampling, UniformByAreaOnTwoTriangles) {
  // Triangle 0 has area 0.5, triangle 1 area 1.5 (3x): expect 25% / 75% of the samples.
  TriMesh m;
  m.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0),
                 Vec3(5, 0, 0), Vec3(8, 0, 0), Vec3(5, 1, 0)};
  m.faces = {Vec3i(0, 1, 2), Vec3i(3, 4, 5)};
  Context ctx(2);
  const std::size_t n = 40000;
  const auto s = sample_uniform(ctx, m, n, 77);
  std::size_t c0 = 0, sub = 0;
  for (const auto& x : s) {
    ASSERT_NEAR(x.bary.sum(), 1.0, 1e-12);
    ASSERT_GE(x.bary.minCoeff(), 0.0);
    if (x.face == 0) {
      ++c0;
      if (x.point.x() + x.point.y() < 0.5) ++sub;  // sub-triangle holding 1/4 of the area
    }
  }
  // Chi-square with 1 degree of freedom, 99.9% quantile 10.83.
  const double e0 = 0.25 * n, e1 = 0.75 * n;
  const double chi2 = (double(c0) - e0) * (double(c0) - e0) / e0 +
                      (double(n - c0) - e1) * (double(n - c0) - e1) / e1;
  EXPECT_LT(chi2, 10.83);
  // Inside a face the density is uniform too: a quarter of triangle 0 lies below x + y = 0.5.
  const double es = 0.25 * double(c0),
               chi2s = (double(sub) - es) * (double(sub) - es) / es +
                       (double(c0 - sub) - 3 * es) * (double(c0 - sub) - 3 * es) / (3 * es);
  EXPECT_LT(chi2s, 10.83);
  // Thread-count independent.
  Context one(1);
  const auto s1 = sample_uniform(one, m, 1000, 77);
  for (std::size_t i = 0; i < s1.size(); ++i) EXPECT_EQ(s1[i].point, s[i].point);
}

TEST(Sampling, PoissonDiscRespectsMinimumDistanceAndCoversSurface) {
  const TriMesh m = make_grid(8, 1.0);
  Context ctx(2);
  PoissonDiscParams p;
  p.min_distance = 0.05;
  const auto s = sample_poisson_disc(ctx, m, p, 3);
  ASSERT_GT(s.size(), 100u);
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::size_t j = i + 1; j < s.size(); ++j)
      ASSERT_GE((s[i].point - s[j].point).norm(), p.min_distance) << i << " " << j;
  // Maximality: random points on the plane are within 2r of some sample (no big holes).
  const auto probes = sample_uniform(ctx, m, 500, 99);
  for (const auto& q : probes) {
    double best = 1e9;
    for (const auto& x : s) best = std::min(best, (x.point - q.point).norm());
    EXPECT_LT(best, 2 * p.min_distance);
  }
  // The count estimate is in the right range.
  const double r = poisson_disc_distance_for_count(1.0, s.size());
  EXPECT_NEAR(r, p.min_distance, 0.3 * p.min_distance);
  p.max_points = 10;
  EXPECT_EQ(sample_poisson_disc(ctx, m, p, 3).size(), 10u);
  p.min_distance = -1;
  EXPECT_THROW(sample_poisson_disc(ctx, m, p, 3), Error);
}

TEST(Bezier, EndpointsDerivativeAndLength) {
  const Bezier3 b{{Vec3(0, 0, 0), Vec3(1, 2, 0), Vec3(3, 2, 1), Vec3(4, 0, 1)}};
  EXPECT_EQ(b.eval(0), b.p[0]);
  EXPECT_EQ(b.eval(1), b.p[3]);
  EXPECT_NEAR((b.derivative(0) - 3 * (b.p[1] - b.p[0])).norm(), 0, 1e-12);
  EXPECT_NEAR((b.derivative(1) - 3 * (b.p[3] - b.p[2])).norm(), 0, 1e-12);
  for (double t : {0.1, 0.37, 0.8}) {
    const double h = 1e-6;
    const Vec3 fd = (b.eval(t + h) - b.eval(t - h)) / (2 * h);
    EXPECT_NEAR((fd - b.derivative(t)).norm(), 0, 1e-7);
    const Vec3 fd2 = (b.derivative(t + h) - b.derivative(t - h)) / (2 * h);
    EXPECT_NEAR((fd2 - b.second_derivative(t)).norm(), 0, 1e-6);
  }
  // Straight Bézier with evenly spaced controls: length = |p3 - p0|, t = s / L.
  const Bezier2 line{{Vec2(0, 0), Vec2(1, 1), Vec2(2, 2), Vec2(3, 3)}};
  EXPECT_NEAR(line.arc_length(), 3 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(line.parameter_at_length(std::sqrt(2.0)), 1.0 / 3, 1e-10);
  // Length against a fine polyline.
  const auto pts = b.sample(20001);
  double poly = 0;
  for (std::size_t i = 1; i < pts.size(); ++i) poly += (pts[i] - pts[i - 1]).norm();
  EXPECT_NEAR(b.arc_length(), poly, 1e-7);
  EXPECT_NEAR(b.arc_length(0, 0.4) + b.arc_length(0.4, 1), b.arc_length(), 1e-10);
  const auto even = b.sample_by_length(5);
  for (std::size_t i = 1; i < even.size(); ++i)
    EXPECT_NEAR(b.arc_length(b.closest_parameter(even[i - 1]), b.closest_parameter(even[i])),
                b.arc_length() / 4, 1e-6);
  // Split halves meet and reproduce the curve.
  const auto halves = b.split(0.3);
  EXPECT_NEAR((halves[0].eval(1) - b.eval(0.3)).norm(), 0, 1e-12);
  EXPECT_NEAR((halves[1].eval(0.5) - b.eval(0.65)).norm(), 0, 1e-12);
}

TEST(Bezier, ClosestParameterMatchesDenseSearch) {
  const Bezier2 b{{Vec2(0, 0), Vec2(2, 3), Vec2(-1, 3), Vec2(1, 0)}};  // a loop-like arch
  const Bezier3 b3{{Vec3(0, 0, 0), Vec3(1, 2, 0), Vec3(3, -2, 1), Vec3(4, 0, 1)}};
  for (int i = 0; i < 50; ++i) {
    const Vec2 q(-1 + 0.07 * i, 2.5 - 0.05 * i);
    double d;
    const double t = b.closest_parameter(q, &d);
    double best = 1e9;
    for (int k = 0; k <= 100000; ++k) best = std::min(best, (b.eval(k / 1e5) - q).norm());
    EXPECT_NEAR(d, best, 1e-8);
    EXPECT_NEAR((b.eval(t) - q).norm(), d, 1e-12);
    const Vec3 q3(0.1 * i, 0.5, 0.3);
    double d3;
    b3.closest_parameter(q3, &d3);
    double best3 = 1e9;
    for (int k = 0; k <= 100000; ++k) best3 = std::min(best3, (b3.eval(k / 1e5) - q3).norm());
    EXPECT_NEAR(d3, best3, 1e-8);
  }
  // A point on the curve has distance 0 at its own parameter.
  double d;
  EXPECT_NEAR(b3.closest_parameter(b3.eval(0.62), &d), 0.62, 1e-7);
  EXPECT_NEAR(d, 0, 1e-10);
}

TEST(CatmullRom, InterpolatesAndDerivativesAgree) {
  std::vector<Vec3> pts = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1.1, 1, 0), Vec3(3, 1, 0.5),
                           Vec3(3, 3, 1)};
  for (double alpha : {0.0, 0.5, 1.0})
    for (bool closed : {false, true}) {
      const CatmullRom3 c(pts, alpha, closed);
      EXPECT_EQ(c.num_segments(), closed ? 5u : 4u);
      for (std::size_t i = 0; i < pts.size(); ++i)
        EXPECT_NEAR((c.eval(double(i)) - pts[i]).norm(), 0, 1e-12) << alpha << closed << i;
      if (closed) {
        EXPECT_NEAR((c.eval(5.0) - pts[0]).norm(), 0, 1e-12);
      }
      // Derivative by finite differences, and C1 continuity at interior knots.
      for (double s : {0.3, 1.5, 2.75, 3.2}) {
        const double h = 1e-6;
        EXPECT_NEAR(((c.eval(s + h) - c.eval(s - h)) / (2 * h) - c.derivative(s)).norm(), 0, 1e-6);
      }
      for (std::size_t k = 1; k + 1 < c.num_segments(); ++k) {
        // Non-uniform splines are C1 in knot time t (tangent = d/du / dt_i), so G1 in s; the
        // uniform one is C1 in s.
        const Vec3 left = c.segment(k - 1).derivative(1.0), right = c.segment(k).derivative(0.0);
        EXPECT_NEAR((left.normalized() - right.normalized()).norm(), 0, 1e-9)
            << alpha << " knot " << k;
        if (alpha == 0.0) {
          EXPECT_NEAR((left - right).norm(), 0, 1e-12);
        }
      }
    }
  // Uniform Catmull-Rom tangent at an interior knot is (p[i+1] - p[i-1]) / 2.
  const CatmullRom3 u(pts, 0.0, false);
  EXPECT_NEAR((u.derivative(2.0) - 0.5 * (pts[3] - pts[1])).norm(), 0, 1e-12);
  // Collinear evenly spaced points: uniform spline is the straight line at constant speed.
  const CatmullRom2 line({Vec2(0, 0), Vec2(1, 0), Vec2(2, 0), Vec2(3, 0)}, 0.0);
  EXPECT_NEAR((line.eval(1.25) - Vec2(1.25, 0)).norm(), 0, 1e-12);
  EXPECT_EQ(line.sample(4).size(), 13u);
  EXPECT_THROW(CatmullRom2({Vec2(0, 0)}), Error);
  EXPECT_THROW(CatmullRom2({Vec2(0, 0), Vec2(1, 0)}, 2.0), Error);
}

TEST(CatmullRom, CentripetalHasNoCuspWhereUniformOvershoots) {
  // Classic cusp case: a short middle segment between far-apart neighbours.
  std::vector<Vec2> pts = {Vec2(0, 0), Vec2(1, 1), Vec2(1.1, 1), Vec2(2.1, 0)};
  const CatmullRom2 cen(pts, 0.5), uni(pts, 0.0);
  double max_y_cen = 0, max_y_uni = 0;
  for (int k = 0; k <= 200; ++k) {
    max_y_cen = std::max(max_y_cen, cen.eval(1.0 + k / 200.0).y());
    max_y_uni = std::max(max_y_uni, uni.eval(1.0 + k / 200.0).y());
  }
  EXPECT_GT(max_y_uni, max_y_cen);  // uniform overshoots (loops) on the short segment
  EXPECT_LT(max_y_cen, 1.05);
}

TEST(MeshDistance, SelfIsZeroTranslatedPlaneIsTranslation) {
  Context ctx(2);
  const TriMesh a = make_grid(10, 1.0);
  MeshDistanceParams p;
  p.samples = 5000;
  const auto self = mesh_distance(ctx, a, a, p);
  EXPECT_LT(self.two_sided.max, 1e-12);
  EXPECT_LT(self.two_sided.mean, 1e-12);
  TriMesh b = a;
  Affine3 t = Affine3::Identity();
  t.translate(Vec3(0, 0, 0.02));
  b.transform(t);
  const auto r = mesh_distance(ctx, a, b, p);
  for (const DistanceStats* s : {&r.a_to_b, &r.b_to_a, &r.two_sided}) {
    EXPECT_NEAR(s->mean, 0.02, 1e-12);
    EXPECT_NEAR(s->rms, 0.02, 1e-12);
    EXPECT_NEAR(s->p95, 0.02, 1e-12);
    EXPECT_NEAR(s->max, 0.02, 1e-12);
  }
  EXPECT_EQ(r.two_sided.count, 2 * p.samples);
  const auto vd = vertex_distances(ctx, a, b);
  ASSERT_EQ(vd.size(), a.num_vertices());
  for (double d : vd) EXPECT_NEAR(d, 0.02, 1e-12);
  // In-plane shift of a larger plane: interior distance 0, the overhang gives the Hausdorff.
  TriMesh c = a;
  Affine3 s = Affine3::Identity();
  s.translate(Vec3(0.1, 0, 0));
  c.transform(s);
  const auto rc = mesh_distance(ctx, a, c, p);
  EXPECT_NEAR(rc.two_sided.max, 0.1, 1e-12);
  EXPECT_NEAR(rc.a_to_b.mean, 0.1 * 0.1 / 2, 2e-3);  // 10% strip, mean offset 0.05
}

TEST(MeshDistance, StatsOfKnownList) {
  std::vector<double> d;
  for (int i = 1; i <= 100; ++i) d.push_back(i);
  const auto s = distance_stats(d);
  EXPECT_DOUBLE_EQ(s.mean, 50.5);
  EXPECT_DOUBLE_EQ(s.max, 100);
  EXPECT_DOUBLE_EQ(s.p95, 95);
  EXPECT_NEAR(s.rms, std::sqrt(338350.0 / 100), 1e-12);
}
