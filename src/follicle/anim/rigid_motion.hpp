#pragma once
// Rigid motion track (e.g. a head turn or a head shake): position keys p(t) [m] and rotation keys
// phi(t) [rad] given as rotation vectors (axis * angle, world frame, exponential map), both
// interpolated by KeyframeTrack. A rest point x maps to
//     x(t) = R(t) (x - pivot) + pivot + p(t),        R(t) = exp([phi(t)]x).
// The sample holds the transform and the derivatives the hair solvers need for inertial forces:
// velocity/acceleration of the pivot, spatial angular velocity omega = J_l(phi) dphi/dt and
// angular acceleration alpha = d omega / dt (exact, by forward-mode automatic differentiation of
// J_l(phi(t)) dphi/dt with Eigen's AutoDiffScalar).
#include "follicle/anim/keyframe_track.hpp"
#include "follicle/core/types.hpp"

namespace follicle::anim {

struct RigidSample {
  double t = 0;
  Mat3 rotation = Mat3::Identity();
  Vec3 translation = Vec3::Zero();           // p(t) [m]
  Vec3 pivot = Vec3::Zero();                 // rest pivot [m]; current centre = pivot + p(t)
  Vec3 velocity = Vec3::Zero();              // dp/dt [m/s]
  Vec3 acceleration = Vec3::Zero();          // d2p/dt2 [m/s^2]
  Vec3 angular_velocity = Vec3::Zero();      // omega, world frame [rad/s]
  Vec3 angular_acceleration = Vec3::Zero();  // d omega/dt [rad/s^2]

  Vec3 centre() const { return pivot + translation; }
  /// Rest point -> current point.
  Vec3 apply(const Vec3& x_rest) const { return rotation * (x_rest - pivot) + centre(); }
  Affine3 transform() const;
  /// Velocity and acceleration of the body point currently at world position x.
  Vec3 point_velocity(const Vec3& x) const {
    return velocity + angular_velocity.cross(x - centre());
  }
  Vec3 point_acceleration(const Vec3& x) const;
};

class RigidMotionTrack {
 public:
  RigidMotionTrack() = default;
  RigidMotionTrack(VectorTrack position, VectorTrack rotation, const Vec3& pivot = Vec3::Zero());

  RigidSample sample(double t) const;
  const VectorTrack& position() const { return m_position; }
  const VectorTrack& rotation() const { return m_rotation; }
  const Vec3& pivot() const { return m_pivot; }
  double start_time() const;
  double end_time() const;

  /// A head turn: yaw about `axis` from 0 to `angle` [rad] over [t0, t1], smooth, held after.
  static RigidMotionTrack turn(const Vec3& pivot, const Vec3& axis, double angle, double t0,
                               double t1);
  /// A head shake: `cycles` oscillations of amplitude `angle` about `axis` over [t0, t1].
  static RigidMotionTrack shake(const Vec3& pivot, const Vec3& axis, double angle, int cycles,
                                double t0, double t1);

 private:
  VectorTrack m_position, m_rotation;
  Vec3 m_pivot = Vec3::Zero();
};

/// Rotation matrix exp([phi]x) of a rotation vector.
Mat3 rotation_from_vector(const Vec3& phi);
/// Left Jacobian of SO(3) applied to v: J_l(phi) v (spatial angular velocity for v = dphi/dt).
Vec3 left_jacobian_times(const Vec3& phi, const Vec3& v);

}  // namespace follicle::anim
