#pragma once
// Cubic Bézier curves and Catmull-Rom splines in 2-D and 3-D (instantiated for D = 2, 3).
// Catmull-Rom segments are converted to Bézier form, so both share eval/derivative/arc length.
#include <array>
#include <cstddef>
#include <vector>

#include "follicle/core/types.hpp"

namespace follicle::geom {

template <int D>
struct CubicBezier {
  using V = Eigen::Matrix<double, D, 1>;
  std::array<V, 4> p;  // control points; the curve runs from p[0] (t=0) to p[3] (t=1)

  V eval(double t) const;
  V derivative(double t) const;         // dB/dt
  V second_derivative(double t) const;  // d2B/dt2
  /// Parameter t in [0, 1] of the curve point closest to q (global: dense sampling, then
  /// Newton refinement, endpoints included). Writes the distance when `distance` is given.
  double closest_parameter(const V& q, double* distance = nullptr) const;
  /// Arc length between t0 and t1 (adaptive 5-point Gauss-Legendre, relative error ~1e-10).
  double arc_length(double t0 = 0.0, double t1 = 1.0) const;
  /// Parameter at arc length s from t = 0 (clamped to [0, 1]).
  double parameter_at_length(double s) const;
  /// n >= 2 points at uniform t (n == 1 gives p[0]).
  std::vector<V> sample(std::size_t n) const;
  /// n >= 2 points at uniform arc length.
  std::vector<V> sample_by_length(std::size_t n) const;
  /// de Casteljau split at t.
  std::array<CubicBezier, 2> split(double t) const;
};

using Bezier2 = CubicBezier<2>;
using Bezier3 = CubicBezier<3>;

/// The cubic Bézier through the first and last of `points` that is closest to the others in the
/// least-squares sense, at chord-length parameters (Schneider, "An algorithm for automatically
/// fitting digitized curves", Graphics Gems 1990: the two inner control points from the 2x2
/// normal equations). Two points give the straight segment; near-collinear or degenerate inner
/// systems fall back to the chord's thirds. Throws follicle::Error for fewer than 2 points or
/// non-finite ones.
template <int D>
CubicBezier<D> fit_cubic_bezier(const std::vector<Eigen::Matrix<double, D, 1>>& points);

/// Catmull-Rom spline through points. alpha = 0: uniform, 0.5: centripetal (no cusps or
/// self-intersections within a segment, Yuksel et al. 2011), 1: chordal. The curve interpolates
/// every point; parameter s runs over [0, num_segments()], segment i spans [i, i+1].
/// Open splines extrapolate phantom end points (p[-1] = 2 p[0] - p[1]); closed ones wrap.
template <int D>
class CatmullRom {
 public:
  using V = Eigen::Matrix<double, D, 1>;
  /// Throws follicle::Error with fewer than 2 points (3 when closed) or alpha outside [0, 1].
  CatmullRom(std::vector<V> points, double alpha = 0.5, bool closed = false);

  std::size_t num_segments() const { return m_closed ? m_pts.size() : m_pts.size() - 1; }
  bool closed() const { return m_closed; }
  const std::vector<V>& points() const { return m_pts; }
  /// Segment i as a cubic Bézier in the local parameter u in [0, 1].
  CubicBezier<D> segment(std::size_t i) const;
  V eval(double s) const;
  V derivative(double s) const;  // d/ds
  /// `per_segment` points per segment (the last point of the curve is included for open curves).
  std::vector<V> sample(std::size_t per_segment) const;

 private:
  std::size_t locate(double s, double& u) const;
  std::vector<V> m_pts;
  std::vector<CubicBezier<D>> m_segments;
  double m_alpha;
  bool m_closed;
};

using CatmullRom2 = CatmullRom<2>;
using CatmullRom3 = CatmullRom<3>;

extern template struct CubicBezier<2>;
extern template struct CubicBezier<3>;
extern template class CatmullRom<2>;
extern template class CatmullRom<3>;

}  // namespace follicle::geom
