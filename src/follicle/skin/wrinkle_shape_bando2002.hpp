#pragma once
// Closed-form pieces of Bando et al. 2002 large-scale wrinkles (thesis ch. 2, §2.5):
// the wrinkle shape function S(l) (2.1), the amplitude modulation function M(s) (2.4), the
// shrinkage of one triangle along a texture-space direction (2.3) and cubic Bezier furrows.
#include <array>
#include <cmath>
#include <vector>

#include "follicle/core/types.hpp"

namespace follicle::skin {

/// (2.1) S(l) = d (l/w - 1) exp(-l/w); l >= 0 is the perpendicular distance from the furrow.
/// S(0) = -d (furrow bottom), S(w) = 0, bulge peak S(2w) = d e^-2, and (2.2) int_0^inf S = 0.
inline double wrinkle_shape(double l, double depth, double width) {
  const double x = std::abs(l) / width;
  return depth * (x - 1.0) * std::exp(-x);  // (2.1)
}

/// (2.4) M(s) = (1-r) s + r for s >= 0, r exp((1/r - 1) s) for s < 0. C1 at s = 0 for r in (0,1].
/// r = 0 is the limit M = 0 for s < 0 (evaluated without dividing by r).
inline double amplitude_modulation(double s, double r) {
  if (s >= 0) return (1.0 - r) * s + r;      // (2.4) upper branch
  if (r <= 0) return 0.0;                    // limit r -> 0+: r exp((1/r-1)s) -> 0 for s < 0
  return r * std::exp((1.0 / r - 1.0) * s);  // (2.4) lower branch
}

/// (2.3) Shrinkage of a triangle v1 v2 v3 measured from v1 along texture direction d_p, with
/// d_p = a e2 + b e3 (a, b >= 0; e2 = uv2 - uv1, e3 = uv3 - uv1). When the edges v1v2 and v1v3
/// are scaled by t2 and t3 (3D length ratios), the ray along d_p meets the scaled edge v2'v3'
/// at L' = 1/(a/t2 + b/t3) versus L = 1/(a + b), so s = 1 - L'/L = 1 - (a+b)/(a/t2 + b/t3).
inline double triangle_shrinkage(double a, double b, double t2, double t3) {
  const double denom = a / t2 + b / t3;
  return 1.0 - (a + b) / denom;  // (2.3) s = 1 - L'/L
}

/// A cubic Bezier curve in texture space.
struct CubicBezier2 {
  std::array<Vec2, 4> p;
  Vec2 eval(double t) const {
    const double u = 1 - t;
    return u * u * u * p[0] + 3 * u * u * t * p[1] + 3 * u * t * t * p[2] + t * t * t * p[3];
  }
  Vec2 tangent(double t) const {
    const double u = 1 - t;
    return 3 * u * u * (p[1] - p[0]) + 6 * u * t * (p[2] - p[1]) + 3 * t * t * (p[3] - p[2]);
  }
};

/// Closest point on a Bezier curve sampled as a polyline (then refined by Newton on the curve).
struct CurveProjection {
  double t = 0;         // curve parameter of the closest point
  double distance = 0;  // texture-space distance
  Vec2 point = Vec2::Zero();
  Vec2 tangent = Vec2::UnitX();  // unit
};

class BezierDistance {
 public:
  explicit BezierDistance(const CubicBezier2& c, int samples = 128);
  CurveProjection project(const Vec2& q) const;
  /// Axis-aligned bounds of the sampled curve.
  Eigen::AlignedBox2d bounds() const { return m_box; }
  const CubicBezier2& curve() const { return m_c; }
  double length() const { return m_length; }

 private:
  CubicBezier2 m_c;
  std::vector<Vec2> m_pts;
  std::vector<double> m_ts;
  Eigen::AlignedBox2d m_box;
  double m_length = 0;
};

}  // namespace follicle::skin
