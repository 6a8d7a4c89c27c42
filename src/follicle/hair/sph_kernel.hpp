#pragma once
// Monaghan's cubic-spline smoothing kernel (Monaghan 1992, the paper's [27]) in 3-D, with
// W(h, r) = 0 for r > 2h, as used by the SPH density (3.1) and pressure force (3.16).
#include <algorithm>
#include <cmath>

#include "follicle/core/types.hpp"

namespace follicle::hair {

/// W(h, r) [1/m^3].
inline double sph_w(double h, double r) {
  const double sigma = 1.0 / (kPi * h * h * h);
  const double q = r / h;
  if (q < 1.0) return sigma * (1.0 - 1.5 * q * q + 0.75 * q * q * q);
  if (q < 2.0) {
    const double a = 2.0 - q;
    return sigma * 0.25 * a * a * a;
  }
  return 0.0;
}

/// dW/dr (h, r) [1/m^4], <= 0.
inline double sph_dw(double h, double r) {
  const double sigma = 1.0 / (kPi * h * h * h * h);
  const double q = r / h;
  if (q < 1.0) return sigma * (-3.0 * q + 2.25 * q * q);
  if (q < 2.0) {
    const double a = 2.0 - q;
    return sigma * (-0.75 * a * a);
  }
  return 0.0;
}

/// The same kernel with its constants precomputed, giving W and dW/dr from one evaluation of
/// q = r/h (the pair loops call it once per pair instead of sph_w + sph_dw). Evaluated without
/// branches as the difference of the two truncated cubics,
///   W = sigma/4 [(2 - q)_+^3 - 4 (1 - q)_+^3],  dW/dr = sigma'/4 [-3 (2 - q)_+^2 + 12 (1 -
///   q)_+^2],
/// which equals Monaghan's piecewise form on each piece: pair loops mix particles on both
/// pieces, where a branch per pair is mispredicted about half the time.
struct SphKernel {
  explicit SphKernel(double h)
      : inv_h(1.0 / h), sigma_w(1.0 / (kPi * h * h * h)), sigma_dw(1.0 / (kPi * h * h * h * h)) {}
  double inv_h, sigma_w, sigma_dw;
  /// W(h, r) [1/m^3].
  double w(double r) const {
    const double q = r * inv_h;
    const double a = std::max(2.0 - q, 0.0), b = std::max(1.0 - q, 0.0);
    return sigma_w * 0.25 * (a * a * a - 4.0 * b * b * b);
  }
  /// W and dW/dr at r.
  void w_dw(double r, double& w, double& dw) const {
    const double q = r * inv_h;
    const double a = std::max(2.0 - q, 0.0), b = std::max(1.0 - q, 0.0);
    w = sigma_w * 0.25 * (a * a * a - 4.0 * b * b * b);
    dw = sigma_dw * 0.75 * (4.0 * b * b - a * a);
  }
  /// d^2W/dr^2 at r [1/m^5] (the pair stiffness of the implicit step, ADR 0014).
  double d2w(double r) const {
    const double q = r * inv_h;
    const double a = std::max(2.0 - q, 0.0), b = std::max(1.0 - q, 0.0);
    return sigma_dw * inv_h * 1.5 * (a - 4.0 * b);
  }
};

}  // namespace follicle::hair
