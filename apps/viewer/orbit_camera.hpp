#pragma once
// OrbitCamera: the viewer's mouse camera. It orbits a target point on a sphere (yaw about the
// scene's up axis, pitch towards it), pans the target in the view plane and dollies the
// distance. Converts to and from render::Camera, so the scene file's camera is the start and
// "reset" state. Pure maths, no GL, so it is unit-tested without a window.
#include <Eigen/Geometry>

#include "follicle/core/types.hpp"
#include "follicle/render/render_scene.hpp"

namespace follicle::viewer {

class OrbitCamera {
 public:
  OrbitCamera() { set_from(render::Camera{}); }
  explicit OrbitCamera(const render::Camera& cam) { set_from(cam); }

  /// Takes eye, target, up, fov and clip planes from `cam` (throws follicle::Error when eye ==
  /// target or up is zero). Pitch is clamped to +-kMaxPitch.
  void set_from(const render::Camera& cam);
  render::Camera camera() const;

  /// Mouse drag by (dx, dy) window pixels (y down): the scene turns with the mouse.
  void orbit(double dx, double dy);
  /// Mouse drag by (dx, dy) window pixels in a viewport `viewport_h` pixels tall: the point under
  /// the cursor (at the target's depth) follows the mouse.
  void pan(double dx, double dy, double viewport_h);
  /// Mouse wheel: `steps` > 0 moves closer (each step divides the distance by kZoomStep).
  void zoom(double steps);
  /// Keeps the view direction and fits `box` into the view (render::frame_box).
  void frame(const Eigen::AlignedBox3d& box);

  const Vec3& target() const { return m_target; }
  double distance() const { return m_distance; }
  double yaw() const { return m_yaw; }      // [rad]
  double pitch() const { return m_pitch; }  // [rad]
  Vec3 eye() const;

  static constexpr double kMaxPitch = 1.55;  // [rad], just under 90 degrees
  static constexpr double kRadiansPerPixel = 0.008;
  static constexpr double kZoomStep = 1.15;

 private:
  Vec3 m_target{0, 0, 0};
  Vec3 m_up{0, 1, 0};     // unit world up
  Vec3 m_a{0, 0, 1};      // unit, perpendicular to m_up: direction of yaw = 0
  Vec3 m_b{1, 0, 0};      // m_up x m_a: direction of yaw = +90 degrees
  double m_distance = 1;  // [m]
  double m_yaw = 0;
  double m_pitch = 0;
  double m_fov_y = 0.6;
  double m_near = 0.01;
  double m_far = 100;
};

}  // namespace follicle::viewer
