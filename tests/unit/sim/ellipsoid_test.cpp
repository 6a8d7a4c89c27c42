#include "follicle/sim/ellipsoid.hpp"

#include <gtest/gtest.h>

#include "follicle/core/error.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/sim/step_report.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using follicle::sim::Ellipsoid;

static Ellipsoid test_ellipsoid() {
  Ellipsoid e;
  e.centre = Vec3(0.01, 0.1, -0.02);
  e.radii = Vec3(0.08, 0.11, 0.1);
  e.rotation = Eigen::AngleAxisd(0.3, Vec3(0.2, 1, 0.1).normalized()).toRotationMatrix();
  return e;
}

TEST(Ellipsoid, InsideAndPolarRoundTrip) {
  const Ellipsoid e = test_ellipsoid();
  EXPECT_TRUE(e.inside(e.centre));
  for (double az : {-3.0, -1.0, 0.0, 0.5, 2.0, 3.1})
    for (double ze : {0.2, 1.0, 1.6, 2.9}) {
      const Vec3 p = e.surface_point(az, ze);
      EXPECT_NEAR(e.value(p), 0.0, 1e-12);
      const Vec2 pol = e.polar(p);
      EXPECT_NEAR(pol.x(), az, 1e-9);
      EXPECT_NEAR(pol.y(), ze, 1e-9);
      EXPECT_FALSE(e.inside(e.centre + 1.01 * (p - e.centre)));
      EXPECT_TRUE(e.inside(e.centre + 0.99 * (p - e.centre)));
    }
}

TEST(Ellipsoid, GradientMatchesFiniteDifferences) {
  const Ellipsoid e = test_ellipsoid();
  const Vec3 p(0.05, 0.13, 0.04);
  const Vec3 g = e.gradient(p);
  for (int i = 0; i < 3; ++i) {
    Vec3 dp = Vec3::Zero();
    dp[i] = 1e-6;
    EXPECT_NEAR((e.value(p + dp) - e.value(p - dp)) / 2e-6, g[i], 1e-4 * g.norm());
  }
}

TEST(Ellipsoid, PushOutAndClosestPoint) {
  const Ellipsoid e = test_ellipsoid();
  Rng rng(3);
  for (int k = 0; k < 200; ++k) {
    const Vec3 p =
        e.centre + Vec3(rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2));
    const Vec3 q = e.push_out(p, 0.001);
    EXPECT_GE(e.value(q), -1e-12);
    const Vec3 c = e.closest_point(p);
    EXPECT_NEAR(e.value(c), 0.0, 1e-9);
    // No surface sample is closer than the closest point.
    for (int j = 0; j < 50; ++j) {
      const Vec3 s = e.surface_point(rng.uniform(-kPi, kPi), std::acos(rng.uniform(-1, 1)));
      EXPECT_LE((c - p).norm(), (s - p).norm() + 1e-9);
    }
  }
}

TEST(Ellipsoid, FitsSnugHullToHeadScan) {
  const auto path = test::source_dir() / "data/meshes/lee_perry_smith/head.obj";
  const auto mesh = geom::load_mesh(path, LengthUnit::mm);
  const Ellipsoid e = sim::fit_head_ellipsoid(mesh.positions);
  // Crown ~185 mm: the hull top lies just above it; the hull is centred on the skull.
  const double top = e.centre.y() + e.radii.y();
  EXPECT_GT(top, 0.183);
  EXPECT_LT(top, 0.205);
  EXPECT_NEAR(e.centre.x(), 0.0, 0.01);
  // Most cranium vertices are inside, and the hull is snug: they lie close to its surface.
  int inside = 0, n = 0;
  double ymax = -1;
  for (const auto& p : mesh.positions) ymax = std::max(ymax, p.y());
  for (const auto& p : mesh.positions)
    if (p.y() > ymax - 0.08) {
      ++n;
      inside += e.value(p) <= 0;
    }
  EXPECT_GT(double(inside) / n, 0.97);
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(e.radii[i], 0.06);
    EXPECT_LT(e.radii[i], 0.13);
  }
}

TEST(Ellipsoid, FitRejectsTooFewVertices) {
  EXPECT_THROW(sim::fit_head_ellipsoid({Vec3(0, 0, 0), Vec3(1, 0, 0)}), Error);
}

TEST(StepReport, MergeIsOrderIndependent) {
  sim::StepReport a, b;
  a.max_speed = 2;
  b.mark_non_finite(7);
  b.max_speed = 1;
  sim::StepReport c;
  c.mark_blow_up(3);
  sim::StepReport x = a, y = c;
  x.merge(b);
  x.merge(c);
  y.merge(b);
  y.merge(a);
  EXPECT_FALSE(x.ok);
  EXPECT_EQ(x.first_bad, 3u);
  EXPECT_EQ(y.first_bad, 3u);
  EXPECT_EQ(x.max_speed, 2.0);
  EXPECT_EQ(y.max_speed, 2.0);
  x.finish("t", 1.0);
  EXPECT_FALSE(x.message.empty());
}
