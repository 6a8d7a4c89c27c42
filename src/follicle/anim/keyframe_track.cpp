#include "follicle/anim/keyframe_track.hpp"

#include <algorithm>
#include <cmath>

namespace follicle::anim {

Interp parse_interp(const std::string& s) {
  if (s == "step") return Interp::step;
  if (s == "linear") return Interp::linear;
  if (s == "smooth" || s == "catmull-rom") return Interp::smooth;
  fail("unknown interpolation '{}': expected step, linear or smooth", s);
}

std::string to_string(Interp i) {
  switch (i) {
    case Interp::step: return "step";
    case Interp::linear: return "linear";
    case Interp::smooth: return "smooth";
  }
  return "linear";
}

namespace {
bool finite_value(double v) {
  return std::isfinite(v);
}
template <class D>
bool finite_value(const Eigen::MatrixBase<D>& v) {
  return v.allFinite();
}
}  // namespace

template <class T>
KeyframeTrack<T>::KeyframeTrack(std::vector<Key<T>> keys, Interp interp, const std::string& where)
    : m_keys(std::move(keys)), m_interp(interp) {
  for (std::size_t k = 0; k < m_keys.size(); ++k) {
    const std::string at = fmt::format("{}.keys[{}]", where, k);
    if (!std::isfinite(m_keys[k].t)) fail_at(at, "key time is not a finite number");
    if (!finite_value(m_keys[k].value)) fail_at(at, "key value is not finite");
    if (k > 0 && !(m_keys[k].t > m_keys[k - 1].t))
      fail_at(at, "key times must increase strictly: {} follows {}", m_keys[k].t, m_keys[k - 1].t);
  }
}

template <class T>
T KeyframeTrack<T>::zero() const {
  if constexpr (std::is_same_v<T, double>) {
    return 0.0;
  } else {
    return T::Zero();
  }
}

template <class T>
T KeyframeTrack<T>::tangent(std::size_t k) const {
  const std::size_t n = m_keys.size();
  const std::size_t a = k == 0 ? 0 : k - 1;
  const std::size_t b = k + 1 >= n ? n - 1 : k + 1;
  return T((m_keys[b].value - m_keys[a].value) / (m_keys[b].t - m_keys[a].t));
}

template <class T>
T KeyframeTrack<T>::eval(double t, int order) const {
  const std::size_t n = m_keys.size();
  if (n == 0) return zero();
  if (n == 1 || t <= m_keys.front().t) return order == 0 ? m_keys.front().value : zero();
  if (t >= m_keys.back().t) return order == 0 ? m_keys.back().value : zero();
  // Segment k: t in [t_k, t_{k+1}).
  const auto it = std::upper_bound(m_keys.begin(), m_keys.end(), t,
                                   [](double x, const Key<T>& key) { return x < key.t; });
  const std::size_t k = std::size_t(it - m_keys.begin()) - 1;
  const Key<T>& k0 = m_keys[k];
  const Key<T>& k1 = m_keys[k + 1];
  const double h = k1.t - k0.t;
  const double u = (t - k0.t) / h;
  switch (m_interp) {
    case Interp::step: return order == 0 ? k0.value : zero();
    case Interp::linear:
      if (order == 0) return T(k0.value + (k1.value - k0.value) * u);
      if (order == 1) return T((k1.value - k0.value) / h);
      return zero();
    case Interp::smooth: {
      // Cubic Hermite with tangents m0, m1 (per second): basis h00..h11 in u, derivatives by
      // the chain rule du/dt = 1/h.
      const T m0 = tangent(k);
      const T m1 = tangent(k + 1);
      const double u2 = u * u, u3 = u2 * u;
      if (order == 0) {
        const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u;
        const double h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
        return T(k0.value * h00 + m0 * (h10 * h) + k1.value * h01 + m1 * (h11 * h));
      }
      if (order == 1) {
        const double d00 = 6 * u2 - 6 * u, d10 = 3 * u2 - 4 * u + 1;
        const double d01 = -6 * u2 + 6 * u, d11 = 3 * u2 - 2 * u;
        return T(k0.value * (d00 / h) + m0 * d10 + k1.value * (d01 / h) + m1 * d11);
      }
      const double e00 = 12 * u - 6, e10 = 6 * u - 4, e01 = -12 * u + 6, e11 = 6 * u - 2;
      return T(k0.value * (e00 / (h * h)) + m0 * (e10 / h) + k1.value * (e01 / (h * h)) +
               m1 * (e11 / h));
    }
  }
  return zero();
}

template class KeyframeTrack<double>;
template class KeyframeTrack<Vec2>;
template class KeyframeTrack<Vec3>;

}  // namespace follicle::anim
