#include <gtest/gtest.h>

#include <cmath>

#include "follicle/skin/wrinkle_shape_bando2002.hpp"

using namespace follicle;
using namespace follicle::skin;

TEST(WrinkleShape, IntegratesToZero) {  // (2.2)
  for (double w : {0.002, 0.005, 0.012}) {
    const double d = 0.004;
    double sum = 0;
    const int n = 400000;
    const double L = 60 * w, h = L / n;
    for (int i = 0; i < n; ++i) {
      const double a = i * h, b = a + h;
      sum += h / 6 *
             (wrinkle_shape(a, d, w) + 4 * wrinkle_shape(0.5 * (a + b), d, w) +
              wrinkle_shape(b, d, w));
    }
    EXPECT_NEAR(sum / (d * w), 0.0, 1e-9);
  }
}

TEST(WrinkleShape, FurrowZeroCrossingAndBulgePeak) {
  const double d = 0.005, w = 0.003;
  EXPECT_DOUBLE_EQ(wrinkle_shape(0, d, w), -d);
  EXPECT_NEAR(wrinkle_shape(w, d, w), 0.0, 1e-18);
  // Peak at l = 2w: numerically the maximum over a fine sampling, height d e^-2.
  double best = -1, lbest = 0;
  for (int i = 0; i <= 100000; ++i) {
    const double l = 10 * w * i / 100000.0;
    if (wrinkle_shape(l, d, w) > best) {
      best = wrinkle_shape(l, d, w);
      lbest = l;
    }
  }
  EXPECT_NEAR(lbest, 2 * w, 1e-3 * w);
  EXPECT_NEAR(best, d * std::exp(-2.0), 1e-12);
}

TEST(AmplitudeModulation, ContinuousWithContinuousSlopeAtZero) {
  for (double r : {0.05, 0.3, 0.5, 1.0}) {
    const double h = 1e-7;
    const double left = amplitude_modulation(-h, r), right = amplitude_modulation(h, r);
    EXPECT_NEAR(left, r, 1e-6);
    EXPECT_NEAR(right, r, 1e-6);
    const double sl = (amplitude_modulation(0.0, r) - amplitude_modulation(-h, r)) / h;
    const double sr = (amplitude_modulation(h, r) - amplitude_modulation(0.0, r)) / h;
    EXPECT_NEAR(sl, 1 - r, 1e-5) << r;
    EXPECT_NEAR(sr, 1 - r, 1e-5) << r;
  }
  EXPECT_DOUBLE_EQ(amplitude_modulation(1.0, 0.3), 1.0);  // full shrinkage: maximum height
}

TEST(AmplitudeModulation, RZeroLimitWithoutDivision) {
  EXPECT_EQ(amplitude_modulation(-0.5, 0.0), 0.0);
  EXPECT_EQ(amplitude_modulation(-1e-300, 0.0), 0.0);
  EXPECT_EQ(amplitude_modulation(0.0, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(amplitude_modulation(0.4, 0.0), 0.4);
  // Tiny r approaches the limit.
  EXPECT_LT(amplitude_modulation(-0.1, 1e-6), 1e-12);
  EXPECT_TRUE(std::isfinite(amplitude_modulation(-0.1, 1e-300)));
}

TEST(TriangleShrinkage, MatchesGeometry) {  // (2.3)
  // Equal scaling t of both edges: s = 1 - t exactly for any direction in the sector.
  EXPECT_NEAR(triangle_shrinkage(0.3, 0.7, 0.8, 0.8), 0.2, 1e-15);
  EXPECT_NEAR(triangle_shrinkage(1.0, 0.0, 0.5, 2.0), 0.5, 1e-15);  // along edge 2 only t2 matters
  EXPECT_NEAR(triangle_shrinkage(0.5, 0.5, 1.0, 1.0), 0.0, 1e-15);
  // Direct construction: e2 = (1,0), e3 = (0,1), d = (1,1)/2 hits the edge at (0.5,0.5);
  // scaled edges (t2, t3) -> the line x/t2 + y/t3 = 1 meets the diagonal at x = y = 1/(1/t2 +
  // 1/t3).
  const double t2 = 0.6, t3 = 1.3;
  const double xL = 0.5, xLp = 1.0 / (1.0 / t2 + 1.0 / t3);
  EXPECT_NEAR(triangle_shrinkage(0.5, 0.5, t2, t3), 1 - xLp / xL, 1e-14);
}

TEST(Bezier, ProjectionDistanceOnStraightCurve) {
  CubicBezier2 c{{Vec2(0, 0), Vec2(1, 0), Vec2(2, 0), Vec2(3, 0)}};
  BezierDistance bd(c);
  const auto p = bd.project(Vec2(1.3, 0.25));
  EXPECT_NEAR(p.distance, 0.25, 1e-12);
  EXPECT_NEAR(p.point.x(), 1.3, 1e-9);
  EXPECT_NEAR(std::abs(p.tangent.x()), 1.0, 1e-12);
}
