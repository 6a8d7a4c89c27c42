#include "follicle/anim/rigid_motion.hpp"

#include <algorithm>
#include <cmath>
#include <unsupported/Eigen/AutoDiff>

namespace follicle::anim {

namespace {

// J_l(phi) v = v + a(th) phi x v + b(th) phi x (phi x v), a = (1 - cos th)/th^2,
// b = (th - sin th)/th^3, with Taylor series for small angles. Templated on the scalar so the
// same code runs on doubles and on AutoDiffScalar (for the exact time derivative).
template <class S>
Eigen::Matrix<S, 3, 1> jl_times(const Eigen::Matrix<S, 3, 1>& phi,
                                const Eigen::Matrix<S, 3, 1>& v) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const S th2 = phi.squaredNorm();
  S a, b;
  if (th2 < S(1e-4)) {
    a = S(0.5) - th2 / S(24) + th2 * th2 / S(720);
    b = S(1.0 / 6.0) - th2 / S(120) + th2 * th2 / S(5040);
  } else {
    const S th = sqrt(th2);
    a = (S(1) - cos(th)) / th2;
    b = (th - sin(th)) / (th2 * th);
  }
  const Eigen::Matrix<S, 3, 1> pv = phi.cross(v);
  return v + pv * a + phi.cross(pv) * b;
}

}  // namespace

Mat3 rotation_from_vector(const Vec3& phi) {
  const double th = phi.norm();
  if (th == 0.0) return Mat3::Identity();
  return Eigen::AngleAxisd(th, phi / th).toRotationMatrix();
}

Vec3 left_jacobian_times(const Vec3& phi, const Vec3& v) {
  return jl_times<double>(phi, v);
}

Affine3 RigidSample::transform() const {
  Affine3 xf = Affine3::Identity();
  xf.linear() = rotation;
  xf.translation() = centre() - rotation * pivot;
  return xf;
}

Vec3 RigidSample::point_acceleration(const Vec3& x) const {
  const Vec3 r = x - centre();
  return acceleration + angular_acceleration.cross(r) +
         angular_velocity.cross(angular_velocity.cross(r));
}

RigidMotionTrack::RigidMotionTrack(VectorTrack position, VectorTrack rotation, const Vec3& pivot)
    : m_position(std::move(position)), m_rotation(std::move(rotation)), m_pivot(pivot) {
  if (!pivot.allFinite()) fail("rigid motion pivot is not finite");
}

double RigidMotionTrack::start_time() const {
  if (m_position.empty()) return m_rotation.start_time();
  if (m_rotation.empty()) return m_position.start_time();
  return std::min(m_position.start_time(), m_rotation.start_time());
}

double RigidMotionTrack::end_time() const {
  return std::max(m_position.end_time(), m_rotation.end_time());
}

RigidSample RigidMotionTrack::sample(double t) const {
  RigidSample s;
  s.t = t;
  s.pivot = m_pivot;
  s.translation = m_position.value(t);
  s.velocity = m_position.derivative(t);
  s.acceleration = m_position.second_derivative(t);
  const Vec3 phi = m_rotation.value(t);
  const Vec3 dphi = m_rotation.derivative(t);
  const Vec3 ddphi = m_rotation.second_derivative(t);
  s.rotation = rotation_from_vector(phi);
  // omega = J_l(phi) dphi; alpha = d/dt omega, forward-mode AD with one derivative direction (t).
  using AD = Eigen::AutoDiffScalar<Eigen::Matrix<double, 1, 1>>;
  Eigen::Matrix<AD, 3, 1> phi_ad, dphi_ad;
  for (int i = 0; i < 3; ++i) {
    phi_ad[i] = AD(phi[i], Eigen::Matrix<double, 1, 1>(dphi[i]));
    dphi_ad[i] = AD(dphi[i], Eigen::Matrix<double, 1, 1>(ddphi[i]));
  }
  const Eigen::Matrix<AD, 3, 1> w = jl_times<AD>(phi_ad, dphi_ad);
  for (int i = 0; i < 3; ++i) {
    s.angular_velocity[i] = w[i].value();
    s.angular_acceleration[i] = w[i].derivatives().size() ? w[i].derivatives()[0] : 0.0;
  }
  return s;
}

RigidMotionTrack RigidMotionTrack::turn(const Vec3& pivot, const Vec3& axis, double angle,
                                        double t0, double t1) {
  if (!(t1 > t0)) fail("turn: t1 ({}) must be after t0 ({})", t1, t0);
  const Vec3 a = axis.normalized();
  // Keys sampled from the ease-in/ease-out profile angle * (1 - cos(pi u)) / 2, u in [0, 1]:
  // the motion starts and ends with (nearly) zero angular velocity.
  std::vector<Key<Vec3>> keys;
  const int n = 16;
  for (int i = 0; i <= n; ++i) {
    const double u = double(i) / n;
    keys.push_back({t0 + (t1 - t0) * u, a * (angle * 0.5 * (1.0 - std::cos(kPi * u)))});
  }
  return RigidMotionTrack(VectorTrack({}, Interp::smooth),
                          VectorTrack(std::move(keys), Interp::smooth, "turn.rotation"), pivot);
}

RigidMotionTrack RigidMotionTrack::shake(const Vec3& pivot, const Vec3& axis, double angle,
                                         int cycles, double t0, double t1) {
  if (!(t1 > t0)) fail("shake: t1 ({}) must be after t0 ({})", t1, t0);
  if (cycles < 1) fail("shake: cycles must be >= 1, got {}", cycles);
  const Vec3 a = axis.normalized();
  std::vector<Key<Vec3>> keys;
  const int n = 4 * cycles;  // quarter periods: 0, +A, 0, -A, 0, ...
  for (int i = 0; i <= n; ++i) {
    const double t = t0 + (t1 - t0) * double(i) / n;
    const double v = (i % 4 == 1) ? angle : (i % 4 == 3) ? -angle : 0.0;
    keys.push_back({t, a * v});
  }
  return RigidMotionTrack(VectorTrack({}, Interp::smooth),
                          VectorTrack(std::move(keys), Interp::smooth, "shake.rotation"), pivot);
}

}  // namespace follicle::anim
