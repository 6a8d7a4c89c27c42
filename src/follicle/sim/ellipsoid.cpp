#include "follicle/sim/ellipsoid.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/core/params.hpp"

namespace follicle::sim {

Vec3 Ellipsoid::gradient(const Vec3& p) const {
  const Vec3 q = normalized(p);
  // dE/dp = R * (2 q ./ radii)
  return rotation * (2.0 * q.cwiseQuotient(radii));
}

Vec2 Ellipsoid::polar(const Vec3& p) const {
  const Vec3 q = normalized(p);
  const double r = q.norm();
  if (r == 0.0) return Vec2(0.0, 0.0);
  const double zenith = std::acos(std::clamp(q.y() / r, -1.0, 1.0));
  const double azimuth = std::atan2(q.x(), q.z());
  return Vec2(azimuth, zenith);
}

Vec3 Ellipsoid::surface_point(double azimuth, double zenith) const {
  const Vec3 q(std::sin(zenith) * std::sin(azimuth), std::cos(zenith),
               std::sin(zenith) * std::cos(azimuth));
  return from_normalized(q);
}

double Ellipsoid::area_density(const Vec3& q) const {
  // Parametric map q -> p = R diag(r) q from the unit sphere: dA = r_x r_y r_z |q ./ r| dΩ.
  return radii.prod() * q.cwiseQuotient(radii).norm();
}

Vec3 Ellipsoid::push_out(const Vec3& p, double margin) const {
  const Ellipsoid& e = *this;
  const Vec3 q = e.normalized(p);
  const double r = q.norm();
  if (r >= 1.0 && margin <= 0.0) return p;
  const Ellipsoid g = margin > 0.0 ? e.grown(margin) : e;
  const Vec3 qg = g.normalized(p);
  const double rg = qg.norm();
  if (rg >= 1.0) return p;
  if (rg < 1e-12) return g.surface_point(0.0, 0.0);  // at the centre: push to the crown
  return g.from_normalized(qg / rg);
}

Vec3 Ellipsoid::closest_point(const Vec3& p) const {
  // Closest point x on sum (x_i/r_i)^2 = 1 to local point y: x_i = r_i^2 y_i / (r_i^2 + t) with
  // f(t) = sum (r_i y_i / (r_i^2 + t))^2 - 1 = 0 (Eberly, "Distance from a point to an
  // ellipsoid"). f is monotone decreasing for t > -min r_i^2; bisection on a bracket is robust
  // for every point (Newton alone is not when y is near an axis); 200 halvings reach double
  // precision.
  const Vec3 y = rotation.transpose() * (p - centre);
  const Vec3 r2 = radii.cwiseProduct(radii);
  auto f = [&](double t) {
    double s = 0;
    for (int i = 0; i < 3; ++i) {
      const double v = radii[i] * y[i] / (r2[i] + t);
      s += v * v;
    }
    return s - 1.0;
  };
  const double rmin2 = r2.minCoeff();
  double lo = -rmin2 + 1e-15 * rmin2, hi = std::max(1.0, y.norm()) * radii.maxCoeff();
  if (y.norm() < 1e-15) {
    // Centre: the closest surface point is the end of the shortest semi-axis.
    int k = 0;
    radii.minCoeff(&k);
    Vec3 x = Vec3::Zero();
    x[k] = radii[k];
    return centre + rotation * x;
  }
  while (f(hi) > 0) hi *= 2;
  if (f(lo) < 0) {
    // y lies in the plane of the smallest axis inside the evolute: fall back to radial.
    return from_normalized(normalized(p).normalized());
  }
  for (int it = 0; it < 200 && hi - lo > 1e-18 * std::max(1.0, std::abs(hi)); ++it) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) > 0 ? lo : hi) = mid;
  }
  const double t = 0.5 * (lo + hi);
  Vec3 x;
  for (int i = 0; i < 3; ++i) x[i] = r2[i] * y[i] / (r2[i] + t);
  return centre + rotation * x;
}

void EllipsoidFitParams::validate() const {
  validate_params(*this, "ellipsoid_fit");
}

Ellipsoid fit_head_ellipsoid(const std::vector<Vec3>& positions, const EllipsoidFitParams& params) {
  params.validate();
  if (positions.size() < 9)
    fail("ellipsoid fit: need at least 9 vertices, got {}", positions.size());
  double ymax = -1e300;
  for (const auto& p : positions) {
    if (!p.allFinite()) fail("ellipsoid fit: a vertex is not finite");
    ymax = std::max(ymax, p.y());
  }
  std::vector<Vec3> cap;
  for (const auto& p : positions)
    if (p.y() >= ymax - params.cap_depth) cap.push_back(p);
  if (cap.size() < 9) fail("ellipsoid fit: only {} vertices in the cranium cap", cap.size());

  // Algebraic least squares, centred and scaled for conditioning.
  Vec3 mean = Vec3::Zero();
  for (const auto& p : cap) mean += p;
  mean /= double(cap.size());
  double scale = 0;
  for (const auto& p : cap) scale = std::max(scale, (p - mean).norm());
  Eigen::MatrixXd A(cap.size(), 6);
  for (std::size_t i = 0; i < cap.size(); ++i) {
    const Vec3 x = (cap[i] - mean) / scale;
    A.row(Eigen::Index(i)) << x.x() * x.x(), x.y() * x.y(), x.z() * x.z(), x.x(), x.y(), x.z();
  }
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(Eigen::Index(cap.size()));
  const Eigen::VectorXd c = A.colPivHouseholderQr().solve(b);
  Vec3 centre, radii;
  bool good = c[0] > 0 && c[1] > 0 && c[2] > 0;
  if (good) {
    const Vec3 cen(-c[3] / (2 * c[0]), -c[4] / (2 * c[1]), -c[5] / (2 * c[2]));
    const double g =
        1 + c[0] * cen.x() * cen.x() + c[1] * cen.y() * cen.y() + c[2] * cen.z() * cen.z();
    good = g > 0;
    if (good) {
      centre = mean + scale * cen;
      radii = scale * Vec3(std::sqrt(g / c[0]), std::sqrt(g / c[1]), std::sqrt(g / c[2]));
    }
  }
  if (!good || !radii.allFinite()) {
    // Fallback: the cap's bounding box, centred at the cap's bottom.
    Eigen::AlignedBox3d box;
    for (const auto& p : cap) box.extend(p);
    centre = box.center();
    centre.y() = box.min().y();
    radii = Vec3(box.sizes().x() / 2, box.sizes().y(), box.sizes().z() / 2);
  }
  const double rmin = radii.minCoeff();
  for (int i = 0; i < 3; ++i) radii[i] = std::clamp(radii[i], rmin, params.max_aspect * rmin);

  Ellipsoid e;
  e.centre = centre;
  e.radii = radii;
  // Uniform scale so that `coverage` of the cap is inside.
  std::vector<double> rs(cap.size());
  for (std::size_t i = 0; i < cap.size(); ++i) rs[i] = e.normalized(cap[i]).norm();
  std::sort(rs.begin(), rs.end());
  const std::size_t k =
      std::min(rs.size() - 1, std::size_t(std::ceil(params.coverage * double(rs.size()))) - 1);
  const double s = rs[k];
  if (!(s > 0) || !std::isfinite(s)) fail("ellipsoid fit degenerated (scale {})", s);
  e.radii *= s;
  e.radii.array() += params.margin;
  return e;
}

Ellipsoid fit_head_ellipsoid(const std::vector<Vec3>& positions, const Mat3& frame,
                             const EllipsoidFitParams& params) {
  if (!frame.allFinite() || (frame.transpose() * frame - Mat3::Identity()).norm() > 1e-9 ||
      frame.determinant() < 0)
    fail("ellipsoid fit: the head frame is not a rotation");
  std::vector<Vec3> local(positions.size());
  const Mat3 RT = frame.transpose();
  for (std::size_t i = 0; i < positions.size(); ++i) local[i] = RT * positions[i];
  Ellipsoid e = fit_head_ellipsoid(local, params);
  e.centre = frame * e.centre;
  e.rotation = frame;
  return e;
}

}  // namespace follicle::sim
