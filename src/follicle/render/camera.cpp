#include "follicle/render/camera.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace follicle::render {

void Camera::validate() const {
  validate_params(*this, "camera");
  if ((target - eye).norm() <= 0) fail_at("camera", "eye and target coincide");
  if ((target - eye).normalized().cross(up).norm() < 1e-9)
    fail_at("camera.up", "up is zero or parallel to the viewing direction");
  if (z_near >= z_far) fail_at("camera", "z_near {} must be smaller than z_far {}", z_near, z_far);
}

Mat4 look_at(const Vec3& eye, const Vec3& target, const Vec3& up) {
  const Vec3 f = (target - eye).normalized();
  const Vec3 s = f.cross(up).normalized();
  const Vec3 u = s.cross(f);
  Mat4 m = Mat4::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m;
}

Mat4 view_matrix(const Camera& cam) {
  return look_at(cam.eye, cam.target, cam.up);
}

Mat4 perspective(double fov_y, double aspect, double n, double f) {
  const double t = 1.0 / std::tan(0.5 * fov_y);
  Mat4 m = Mat4::Zero();
  m(0, 0) = t / aspect;
  m(1, 1) = t;
  m(2, 2) = (f + n) / (n - f);
  m(2, 3) = 2 * f * n / (n - f);
  m(3, 2) = -1;
  return m;
}

Mat4 projection_matrix(const Camera& cam, double aspect) {
  return perspective(cam.fov_y, aspect, cam.z_near, cam.z_far);
}

Mat4 orthographic(double l, double r, double b, double t, double n, double f) {
  Mat4 m = Mat4::Identity();
  m(0, 0) = 2 / (r - l);
  m(1, 1) = 2 / (t - b);
  m(2, 2) = -2 / (f - n);
  m(0, 3) = -(r + l) / (r - l);
  m(1, 3) = -(t + b) / (t - b);
  m(2, 3) = -(f + n) / (f - n);
  return m;
}

std::optional<Vec2> project_to_pixel(const Camera& cam, int width, int height, const Vec3& p) {
  const Vec4 c =
      projection_matrix(cam, double(width) / height) * view_matrix(cam) * p.homogeneous();
  if (c.w() <= 0) return std::nullopt;
  const double x = c.x() / c.w(), y = c.y() / c.w();
  return Vec2((x * 0.5 + 0.5) * width, (0.5 - y * 0.5) * height);
}

bool box_in_view(const Camera& cam, double aspect, const Eigen::AlignedBox3d& box) {
  if (box.isEmpty()) return false;
  const Mat4 M = projection_matrix(cam, aspect) * view_matrix(cam);
  std::array<int, 6> beyond{};  // corners beyond -x, +x, -y, +y, near, far
  for (int k = 0; k < 8; ++k) {
    const Vec4 c = M * box.corner(Eigen::AlignedBox3d::CornerType(k)).homogeneous();
    for (int a = 0; a < 3; ++a) {
      if (c[a] < -c.w()) ++beyond[std::size_t(2 * a)];
      if (c[a] > c.w()) ++beyond[std::size_t(2 * a + 1)];
    }
  }
  return std::none_of(beyond.begin(), beyond.end(), [](int n) { return n == 8; });
}

}  // namespace follicle::render
