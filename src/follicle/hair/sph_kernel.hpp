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

}  // namespace follicle::hair
