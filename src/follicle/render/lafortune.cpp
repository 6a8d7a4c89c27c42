#include "follicle/render/lafortune.hpp"

#include <algorithm>
#include <cmath>

namespace follicle::render {

LafortuneBrdf lafortune_skin_marschner() {
  // docs/skin-constants.md §4.1 (pbrt-v1 skin.cpp).
  LafortuneBrdf b;
  b.rho_d = Vec3(0.428425, 0.301341, 0.331054);
  b.lobes = {
      {Vec3(-1.131747, -1.016939, -0.966018), Vec3(-1.209182, -1.462488, -1.222419),
       Vec3(6.421658, 3.699932, 3.524889)},
      {Vec3(-0.546570, -0.643533, -0.638934), Vec3(0.380123, 0.410559, 0.437367),
       Vec3(3.685044, 4.266495, 4.539742)},
      {Vec3(-0.998888, -1.020153, -1.027479), Vec3(0.857998, 0.703913, 0.573625),
       Vec3(64.208486, 63.919687, 43.809866)},
  };
  return b;
}

Vec3 eval_lafortune(const LafortuneBrdf& brdf, const Vec3& wo, const Vec3& wi) {
  if (wo.z() <= 0 || wi.z() <= 0) return Vec3::Zero();
  Vec3 f = brdf.rho_d / kPi;
  const double xy = wo.x() * wi.x() + wo.y() * wi.y();
  const double z = wo.z() * wi.z();
  for (const LafortuneLobe& l : brdf.lobes) {
    for (int c = 0; c < 3; ++c) {
      // Clamp the base at 0 before pow, as pbrt's Spectrum::Pow does.
      const double base = std::max(0.0, l.cxy[c] * xy + l.cz[c] * z);
      f[c] += std::pow(base, l.n[c]);
    }
  }
  return f;
}

Vec3 lafortune_directional_albedo(const LafortuneBrdf& brdf, double theta_i, int n_theta,
                                  int n_phi) {
  const Vec3 wi(std::sin(theta_i), 0.0, std::cos(theta_i));
  const double dt = 0.5 * kPi / n_theta, dp = 2.0 * kPi / n_phi;
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < n_theta; ++i) {
    const double t = (i + 0.5) * dt;
    const double st = std::sin(t), ct = std::cos(t);
    Vec3 ring = Vec3::Zero();
    for (int j = 0; j < n_phi; ++j) {
      const double p = (j + 0.5) * dp;
      ring += eval_lafortune(brdf, Vec3(st * std::cos(p), st * std::sin(p), ct), wi);
    }
    sum += ring * (ct * st);
  }
  return sum * (dt * dp);
}

}  // namespace follicle::render
