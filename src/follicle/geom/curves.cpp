#include "follicle/geom/curves.hpp"

#include <algorithm>
#include <cmath>

#include "follicle/core/error.hpp"

namespace follicle::geom {

template <int D>
auto CubicBezier<D>::eval(double t) const -> V {
  const double s = 1 - t;
  return s * s * s * p[0] + 3 * s * s * t * p[1] + 3 * s * t * t * p[2] + t * t * t * p[3];
}

template <int D>
auto CubicBezier<D>::derivative(double t) const -> V {
  const double s = 1 - t;
  return 3 * s * s * (p[1] - p[0]) + 6 * s * t * (p[2] - p[1]) + 3 * t * t * (p[3] - p[2]);
}

template <int D>
auto CubicBezier<D>::second_derivative(double t) const -> V {
  return 6 * (1 - t) * (p[2] - 2 * p[1] + p[0]) + 6 * t * (p[3] - 2 * p[2] + p[1]);
}

template <int D>
double CubicBezier<D>::closest_parameter(const V& q, double* distance) const {
  // A cubic's squared distance has at most 5 critical points; 32 samples bracket them well on
  // any reasonable curve, Newton on f(t) = B'(t).(B(t) - q) polishes the best few.
  constexpr int kSamples = 32;
  double best_t = 0, best_d = (eval(0) - q).squaredNorm();
  for (int i = 0; i <= kSamples; ++i) {
    double t = double(i) / kSamples;
    for (int it = 0; it < 8; ++it) {
      const V b = eval(t) - q;
      const V d1 = derivative(t);
      const double f = d1.dot(b);
      const double df = second_derivative(t).dot(b) + d1.squaredNorm();
      if (!(std::abs(df) > 1e-300)) break;
      const double tn = std::clamp(t - f / df, 0.0, 1.0);
      if (std::abs(tn - t) < 1e-14) {
        t = tn;
        break;
      }
      t = tn;
    }
    const double d = (eval(t) - q).squaredNorm();
    if (d < best_d) {
      best_d = d;
      best_t = t;
    }
  }
  const double d1 = (eval(1) - q).squaredNorm();
  if (d1 < best_d) {
    best_d = d1;
    best_t = 1;
  }
  if (distance) *distance = std::sqrt(best_d);
  return best_t;
}

namespace {
template <class F>
double gauss5(const F& f, double a, double b) {
  static constexpr double x[5] = {0.0, 0.5384693101056831, -0.5384693101056831, 0.9061798459386640,
                                  -0.9061798459386640};
  static constexpr double w[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665,
                                  0.2369268850561891, 0.2369268850561891};
  const double c = 0.5 * (a + b), h = 0.5 * (b - a);
  double s = 0;
  for (int i = 0; i < 5; ++i) s += w[i] * f(c + h * x[i]);
  return s * h;
}
template <class F>
double adaptive(const F& f, double a, double b, double whole, int depth) {
  const double m = 0.5 * (a + b);
  const double l = gauss5(f, a, m), r = gauss5(f, m, b);
  if (depth <= 0 || std::abs(l + r - whole) <= 1e-12 * std::max(1e-300, std::abs(l + r)))
    return l + r;
  return adaptive(f, a, m, l, depth - 1) + adaptive(f, m, b, r, depth - 1);
}
}  // namespace

template <int D>
double CubicBezier<D>::arc_length(double t0, double t1) const {
  if (t1 < t0) return -arc_length(t1, t0);
  auto speed = [&](double t) { return derivative(t).norm(); };
  return adaptive(speed, t0, t1, gauss5(speed, t0, t1), 20);
}

template <int D>
double CubicBezier<D>::parameter_at_length(double s) const {
  const double total = arc_length();
  if (s <= 0) return 0;
  if (s >= total) return 1;
  // Newton on L(t) - s with bisection safeguard (L is monotone).
  double lo = 0, hi = 1, t = s / total;
  for (int it = 0; it < 50; ++it) {
    const double f = arc_length(0, t) - s;
    if (std::abs(f) < 1e-12 * std::max(1.0, total)) break;
    if (f > 0)
      hi = t;
    else
      lo = t;
    const double sp = derivative(t).norm();
    double tn = sp > 0 ? t - f / sp : 0.5 * (lo + hi);
    if (!(tn > lo && tn < hi)) tn = 0.5 * (lo + hi);
    t = tn;
  }
  return t;
}

template <int D>
auto CubicBezier<D>::sample(std::size_t n) const -> std::vector<V> {
  std::vector<V> out;
  if (n == 0) return out;
  if (n == 1) return {p[0]};
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) out.push_back(eval(double(i) / double(n - 1)));
  return out;
}

template <int D>
auto CubicBezier<D>::sample_by_length(std::size_t n) const -> std::vector<V> {
  std::vector<V> out;
  if (n == 0) return out;
  if (n == 1) return {p[0]};
  const double total = arc_length();
  for (std::size_t i = 0; i < n; ++i)
    out.push_back(eval(parameter_at_length(total * double(i) / double(n - 1))));
  return out;
}

template <int D>
auto CubicBezier<D>::split(double t) const -> std::array<CubicBezier, 2> {
  const V a = p[0] + t * (p[1] - p[0]), b = p[1] + t * (p[2] - p[1]), c = p[2] + t * (p[3] - p[2]);
  const V ab = a + t * (b - a), bc = b + t * (c - b);
  const V m = ab + t * (bc - ab);
  return {CubicBezier{{p[0], a, ab, m}}, CubicBezier{{m, bc, c, p[3]}}};
}

template <int D>
CatmullRom<D>::CatmullRom(std::vector<V> points, double alpha, bool closed)
    : m_pts(std::move(points)), m_alpha(alpha), m_closed(closed) {
  if (!(alpha >= 0 && alpha <= 1)) fail("CatmullRom: alpha {} must be in [0, 1]", alpha);
  if (m_pts.size() < (closed ? 3u : 2u))
    fail("CatmullRom: {} points, need at least {}", m_pts.size(), closed ? 3 : 2);
  for (const V& q : m_pts)
    if (!q.allFinite()) fail("CatmullRom: control point is not finite");
  const std::size_t n = m_pts.size();
  auto P = [&](std::ptrdiff_t i) -> V {
    if (m_closed)
      return m_pts[std::size_t((i % std::ptrdiff_t(n) + std::ptrdiff_t(n)) % std::ptrdiff_t(n))];
    if (i < 0) return 2 * m_pts[0] - m_pts[1];
    if (i >= std::ptrdiff_t(n)) return 2 * m_pts[n - 1] - m_pts[n - 2];
    return m_pts[std::size_t(i)];
  };
  // Knot spacing |p_{i+1} - p_i|^alpha; a tiny floor keeps coincident points finite.
  auto dt = [&](const V& a, const V& b) {
    const double d = std::pow((b - a).norm(), m_alpha);
    return d > 1e-12 ? d : 1e-12;
  };
  for (std::size_t i = 0; i < num_segments(); ++i) {
    const auto ii = std::ptrdiff_t(i);
    const V p0 = P(ii - 1), p1 = P(ii), p2 = P(ii + 1), p3 = P(ii + 2);
    const double d0 = dt(p0, p1), d1 = dt(p1, p2), d2 = dt(p2, p3);
    // Hermite tangents of the non-uniform Catmull-Rom segment, scaled to u in [0, 1]
    // (equivalent to the Barry-Goldman pyramid); uniform alpha = 0 gives (p2 - p0) / 2.
    const V m1 = d1 * ((p1 - p0) / d0 - (p2 - p0) / (d0 + d1) + (p2 - p1) / d1);
    const V m2 = d1 * ((p2 - p1) / d1 - (p3 - p1) / (d1 + d2) + (p3 - p2) / d2);
    m_segments.push_back(CubicBezier<D>{{p1, p1 + m1 / 3.0, p2 - m2 / 3.0, p2}});
  }
}

template <int D>
CubicBezier<D> CatmullRom<D>::segment(std::size_t i) const {
  return m_segments.at(i);
}

template <int D>
std::size_t CatmullRom<D>::locate(double s, double& u) const {
  const double ns = double(num_segments());
  s = std::clamp(s, 0.0, ns);
  std::size_t i = std::size_t(std::floor(s));
  if (i >= num_segments()) i = num_segments() - 1;
  u = s - double(i);
  return i;
}

template <int D>
auto CatmullRom<D>::eval(double s) const -> V {
  double u;
  const std::size_t i = locate(s, u);
  return m_segments[i].eval(u);
}

template <int D>
auto CatmullRom<D>::derivative(double s) const -> V {
  double u;
  const std::size_t i = locate(s, u);
  return m_segments[i].derivative(u);  // du/ds = 1
}

template <int D>
auto CatmullRom<D>::sample(std::size_t per_segment) const -> std::vector<V> {
  std::vector<V> out;
  if (per_segment == 0) return out;
  for (std::size_t i = 0; i < num_segments(); ++i)
    for (std::size_t k = 0; k < per_segment; ++k)
      out.push_back(m_segments[i].eval(double(k) / double(per_segment)));
  if (!m_closed) out.push_back(m_pts.back());
  return out;
}

template <int D>
CubicBezier<D> fit_cubic_bezier(const std::vector<Eigen::Matrix<double, D, 1>>& points) {
  using V = Eigen::Matrix<double, D, 1>;
  const std::size_t n = points.size();
  if (n < 2) fail("fit_cubic_bezier: {} point(s), need at least 2", n);
  for (const V& q : points)
    if (!q.allFinite()) fail("fit_cubic_bezier: a point is not finite");
  CubicBezier<D> c;
  c.p[0] = points.front();
  c.p[3] = points.back();
  const V chord = c.p[3] - c.p[0];
  c.p[1] = c.p[0] + chord / 3.0;
  c.p[2] = c.p[0] + 2.0 * chord / 3.0;
  if (n == 2) return c;
  // Chord-length parameters t_i in [0, 1].
  std::vector<double> t(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) t[i] = t[i - 1] + (points[i] - points[i - 1]).norm();
  const double total = t.back();
  if (!(total > 0)) return c;  // every point the same: a point curve
  for (double& x : t) x /= total;
  // Minimize sum |B(t_i) - q_i|^2 over the free p1, p2 (D independent 2x2 systems sharing one
  // matrix): B = b0 p0 + b1 p1 + b2 p2 + b3 p3. Then Schneider's reparameterization: each t_i
  // moves to the parameter of the fitted curve's point closest to q_i, and the fit is redone;
  // points sampled from a cubic are reproduced once the parameters have converged.
  auto solve = [&](CubicBezier<D>& cur) {
    Eigen::Matrix2d a = Eigen::Matrix2d::Zero();
    Eigen::Matrix<double, 2, D> rhs = Eigen::Matrix<double, 2, D>::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      const double u = t[i], s = 1 - u;
      const double b0 = s * s * s, b1 = 3 * s * s * u, b2 = 3 * s * u * u, b3 = u * u * u;
      a(0, 0) += b1 * b1;
      a(0, 1) += b1 * b2;
      a(1, 1) += b2 * b2;
      const V r = points[i] - b0 * cur.p[0] - b3 * cur.p[3];
      rhs.row(0) += b1 * r.transpose();
      rhs.row(1) += b2 * r.transpose();
    }
    a(1, 0) = a(0, 1);
    if (!(std::abs(a.determinant()) > 1e-12 * a.squaredNorm())) return false;
    const Eigen::Matrix<double, 2, D> x = a.inverse() * rhs;
    cur.p[1] = x.row(0).transpose();
    cur.p[2] = x.row(1).transpose();
    return cur.p[1].allFinite() && cur.p[2].allFinite();
  };
  CubicBezier<D> cur = c;
  if (!solve(cur)) return c;  // all points at the ends
  constexpr int kReparameterizations = 20;
  for (int it = 0; it < kReparameterizations; ++it) {
    double moved = 0;
    for (std::size_t i = 1; i + 1 < n; ++i) {
      const double nt = cur.closest_parameter(points[i]);
      moved = std::max(moved, std::abs(nt - t[i]));
      t[i] = nt;
    }
    CubicBezier<D> next = cur;
    if (!solve(next)) break;
    cur = next;
    if (moved < 1e-12) break;
  }
  return cur;
}

template CubicBezier<2> fit_cubic_bezier<2>(const std::vector<Vec2>&);
template CubicBezier<3> fit_cubic_bezier<3>(const std::vector<Vec3>&);

template struct CubicBezier<2>;
template struct CubicBezier<3>;
template class CatmullRom<2>;
template class CatmullRom<3>;

}  // namespace follicle::geom
