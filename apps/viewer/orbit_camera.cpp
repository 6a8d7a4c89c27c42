#include "orbit_camera.hpp"

#include <algorithm>
#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/render/framing.hpp"

namespace follicle::viewer {

void OrbitCamera::set_from(const render::Camera& cam) {
  const Vec3 offset = cam.eye - cam.target;
  if (!(offset.norm() > 0)) fail("camera: eye and target coincide");
  if (!(cam.up.norm() > 0)) fail("camera: up vector is zero");
  m_up = cam.up.normalized();
  // Yaw 0 is the +z axis projected onto the plane perpendicular to up (x when up is along z).
  Vec3 ref = Vec3::UnitZ() - Vec3::UnitZ().dot(m_up) * m_up;
  if (ref.norm() < 1e-6) ref = Vec3::UnitX() - Vec3::UnitX().dot(m_up) * m_up;
  m_a = ref.normalized();
  m_b = m_up.cross(m_a);
  m_target = cam.target;
  m_distance = offset.norm();
  const Vec3 d = offset / m_distance;
  m_pitch = std::clamp(std::asin(std::clamp(d.dot(m_up), -1.0, 1.0)), -kMaxPitch, kMaxPitch);
  m_yaw = std::atan2(d.dot(m_b), d.dot(m_a));
  m_fov_y = cam.fov_y;
  m_near = cam.z_near;
  m_far = cam.z_far;
}

Vec3 OrbitCamera::eye() const {
  const double c = std::cos(m_pitch);
  const Vec3 dir = c * (std::cos(m_yaw) * m_a + std::sin(m_yaw) * m_b) + std::sin(m_pitch) * m_up;
  return m_target + m_distance * dir;
}

render::Camera OrbitCamera::camera() const {
  render::Camera c;
  c.eye = eye();
  c.target = m_target;
  c.up = m_up;
  c.fov_y = m_fov_y;
  // Keep the scene's clip planes, but never clip the target itself when zoomed in or out.
  c.z_near = std::min(m_near, 0.5 * m_distance);
  c.z_far = std::max(m_far, 2.0 * m_distance);
  return c;
}

void OrbitCamera::orbit(double dx, double dy) {
  m_yaw -= dx * kRadiansPerPixel;
  m_yaw = std::remainder(m_yaw, 2 * kPi);
  m_pitch = std::clamp(m_pitch + dy * kRadiansPerPixel, -kMaxPitch, kMaxPitch);
}

void OrbitCamera::pan(double dx, double dy, double viewport_h) {
  if (!(viewport_h > 0)) return;
  // Size of one pixel at the target's depth.
  const double world_per_px = 2.0 * m_distance * std::tan(0.5 * m_fov_y) / viewport_h;
  const Vec3 forward = (m_target - eye()).normalized();
  const Vec3 right = forward.cross(m_up).normalized();
  const Vec3 up = right.cross(forward);
  m_target += world_per_px * (-dx * right + dy * up);
}

void OrbitCamera::zoom(double steps) {
  m_distance *= std::pow(kZoomStep, -steps);
  m_distance = std::clamp(m_distance, 1e-4, 1e6);
}

void OrbitCamera::frame(const Eigen::AlignedBox3d& box) {
  const render::Camera c = render::frame_box(box, eye() - m_target, m_fov_y, 0.9, m_up);
  const double yaw = m_yaw, pitch = m_pitch;
  m_target = c.target;
  m_distance = (c.eye - c.target).norm();
  m_near = c.z_near;
  m_far = c.z_far;
  m_yaw = yaw;  // same direction; avoid round-off drift through set_from()
  m_pitch = pitch;
}

}  // namespace follicle::viewer
