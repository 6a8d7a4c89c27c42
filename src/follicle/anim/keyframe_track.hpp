#pragma once
// Keyframe tracks: a value (double, Vec2, Vec3) given at increasing key times, interpolated
// piecewise (step, linear or smooth = Catmull-Rom cubic Hermite with non-uniform key spacing) and
// clamped outside the key range (the first/last value is held, derivatives are zero there).
//
// Catmull-Rom tangents for non-uniform times: m_k = (p_{k+1} - p_{k-1}) / (t_{k+1} - t_{k-1});
// at the ends the one-sided difference. With these tangents the smooth track reproduces linear
// data exactly and is C^1 inside the key range.
#include <string>
#include <vector>

#include "follicle/core/error.hpp"
#include "follicle/core/types.hpp"

namespace follicle::anim {

enum class Interp { step, linear, smooth };

/// "step", "linear", "smooth" (alias "catmull-rom"); throws follicle::Error otherwise.
Interp parse_interp(const std::string& s);
std::string to_string(Interp i);

template <class T>
struct Key {
  double t = 0;  // [s]
  T value{};
};

template <class T>
class KeyframeTrack {
 public:
  KeyframeTrack() = default;
  /// Keys must have strictly increasing, finite times and finite values; throws follicle::Error
  /// naming `where` and the offending key otherwise. An empty track evaluates to zero.
  KeyframeTrack(std::vector<Key<T>> keys, Interp interp, const std::string& where = "track");

  /// Value, first and second time derivative at time t [s] (clamped outside the key range).
  T value(double t) const { return eval(t, 0); }
  T derivative(double t) const { return eval(t, 1); }
  T second_derivative(double t) const { return eval(t, 2); }

  const std::vector<Key<T>>& keys() const { return m_keys; }
  Interp interp() const { return m_interp; }
  bool empty() const { return m_keys.empty(); }
  double start_time() const { return m_keys.empty() ? 0.0 : m_keys.front().t; }
  double end_time() const { return m_keys.empty() ? 0.0 : m_keys.back().t; }

 private:
  T eval(double t, int order) const;
  T zero() const;
  T tangent(std::size_t k) const;

  std::vector<Key<T>> m_keys;
  Interp m_interp = Interp::linear;
};

using ScalarTrack = KeyframeTrack<double>;
using Vec2Track = KeyframeTrack<Vec2>;
using VectorTrack = KeyframeTrack<Vec3>;

extern template class KeyframeTrack<double>;
extern template class KeyframeTrack<Vec2>;
extern template class KeyframeTrack<Vec3>;

}  // namespace follicle::anim
