#pragma once
// Monaghan's cubic-spline smoothing kernel (Monaghan 1992, the paper's [27]) in 3-D, with
// W(h, r) = 0 for r > 2h, as used by the SPH density (3.1) and pressure force (3.16).
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
/// q = r/h (the pair loops call it once per pair instead of sph_w + sph_dw).
struct SphKernel {
  explicit SphKernel(double h)
      : inv_h(1.0 / h), sigma_w(1.0 / (kPi * h * h * h)), sigma_dw(1.0 / (kPi * h * h * h * h)) {}
  double inv_h, sigma_w, sigma_dw;
  /// W(h, r) [1/m^3].
  double w(double r) const {
    const double q = r * inv_h;
    if (q < 1.0) return sigma_w * (1.0 - 1.5 * q * q + 0.75 * q * q * q);
    if (q < 2.0) {
      const double a = 2.0 - q;
      return sigma_w * 0.25 * a * a * a;
    }
    return 0.0;
  }
  /// W and dW/dr at r.
  void w_dw(double r, double& w, double& dw) const {
    const double q = r * inv_h;
    if (q < 1.0) {
      w = sigma_w * (1.0 - 1.5 * q * q + 0.75 * q * q * q);
      dw = sigma_dw * (-3.0 * q + 2.25 * q * q);
    } else if (q < 2.0) {
      const double a = 2.0 - q;
      w = sigma_w * 0.25 * a * a * a;
      dw = sigma_dw * (-0.75 * a * a);
    } else {
      w = dw = 0.0;
    }
  }
};

}  // namespace follicle::hair
