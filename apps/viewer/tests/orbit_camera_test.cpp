// OrbitCamera: round trips with render::Camera, and what a drag does on screen (checked by
// projecting points with the renderer's own camera maths).
#include "orbit_camera.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/render/camera.hpp"

namespace follicle::viewer {
namespace {

render::Camera make_camera(Vec3 eye, Vec3 target, Vec3 up) {
  render::Camera c;
  c.eye = eye;
  c.target = target;
  c.up = up;
  c.fov_y = 0.5;
  c.z_near = 0.05;
  c.z_far = 10;
  return c;
}

constexpr int kW = 640, kH = 480;

Vec2 pixel(const OrbitCamera& o, const Vec3& p) {
  const auto px = render::project_to_pixel(o.camera(), kW, kH, p);
  EXPECT_TRUE(px.has_value());
  return px.value_or(Vec2(0, 0));
}

TEST(OrbitCamera, RoundTripsSceneCameras) {
  for (const auto& c : {make_camera({0.33, 0.15, 0.51}, {0, 0.075, 0.01}, {0, 1, 0}),
                        make_camera({1, 2, 3}, {-1, 0.5, 0.2}, {0, 0, 2}),
                        make_camera({0, -4, 0.1}, {0, 0, 0}, {0.1, 0.2, 1})}) {
    const render::Camera r = OrbitCamera(c).camera();
    EXPECT_NEAR((r.eye - c.eye).norm(), 0.0, 1e-12);
    EXPECT_NEAR((r.target - c.target).norm(), 0.0, 1e-12);
    EXPECT_NEAR((r.up - c.up.normalized()).norm(), 0.0, 1e-12);
    EXPECT_EQ(r.fov_y, c.fov_y);
    EXPECT_EQ(r.z_near, c.z_near);
    EXPECT_EQ(r.z_far, c.z_far);
  }
}

TEST(OrbitCamera, RejectsDegenerateCameras) {
  EXPECT_THROW(OrbitCamera(make_camera({1, 1, 1}, {1, 1, 1}, {0, 1, 0})), Error);
  EXPECT_THROW(OrbitCamera(make_camera({0, 0, 1}, {0, 0, 0}, {0, 0, 0})), Error);
}

TEST(OrbitCamera, OrbitKeepsTargetAndDistanceAndFullTurnReturns) {
  const auto c = make_camera({0.3, 0.2, 0.6}, {0, 0.1, 0}, {0, 1, 0});
  OrbitCamera o(c);
  const double d0 = o.distance();
  o.orbit(123, -45);
  EXPECT_NEAR(o.distance(), d0, 1e-15);
  EXPECT_NEAR((o.eye() - o.target()).norm(), d0, 1e-12);
  EXPECT_EQ(o.target(), c.target);
  o.orbit(-123, 45);
  EXPECT_NEAR((o.eye() - c.eye).norm(), 0.0, 1e-12);
  OrbitCamera full(c);
  full.orbit(2 * kPi / OrbitCamera::kRadiansPerPixel, 0);
  EXPECT_NEAR((full.eye() - c.eye).norm(), 0.0, 1e-9);
}

TEST(OrbitCamera, PitchIsClampedAndTheCameraStaysValid) {
  OrbitCamera o(make_camera({0, 0, 1}, {0, 0, 0}, {0, 1, 0}));
  o.orbit(0, 1e6);
  EXPECT_DOUBLE_EQ(o.pitch(), OrbitCamera::kMaxPitch);
  EXPECT_NO_THROW(o.camera().validate());
  o.orbit(0, -1e7);
  EXPECT_DOUBLE_EQ(o.pitch(), -OrbitCamera::kMaxPitch);
  EXPECT_NO_THROW(o.camera().validate());
}

TEST(OrbitCamera, DragTurnsTheSceneWithTheMouse) {
  const auto c = make_camera({0.2, 0.1, 0.8}, {0, 0, 0}, {0, 1, 0});
  // A point between the target and the eye: it moves the way the mouse does.
  const Vec3 near_point = c.target + 0.3 * (c.eye - c.target);
  OrbitCamera o(c);
  const Vec2 p0 = pixel(o, near_point);
  o.orbit(20, 0);
  EXPECT_GT(pixel(o, near_point).x(), p0.x() + 1);
  OrbitCamera o2(c);
  o2.orbit(0, 20);
  EXPECT_GT(pixel(o2, near_point).y(), p0.y() + 1);
}

TEST(OrbitCamera, PanMovesThePointAtTargetDepthWithTheCursor) {
  OrbitCamera o(make_camera({0.3, 0.2, 0.6}, {0, 0.1, 0}, {0, 1, 0}));
  const Vec3 old_target = o.target();
  const Vec2 centre = pixel(o, old_target);
  const Vec3 dir0 = (o.eye() - o.target()).normalized();
  o.pan(37, -21, kH);
  const Vec2 moved = pixel(o, old_target);
  EXPECT_NEAR(moved.x() - centre.x(), 37.0, 1e-6);
  EXPECT_NEAR(moved.y() - centre.y(), -21.0, 1e-6);
  EXPECT_NEAR(((o.eye() - o.target()).normalized() - dir0).norm(), 0.0, 1e-12);
}

TEST(OrbitCamera, ZoomChangesOnlyTheDistanceAndIsReversible) {
  const auto c = make_camera({0.3, 0.2, 0.6}, {0, 0.1, 0}, {0, 1, 0});
  OrbitCamera o(c);
  const double d0 = o.distance();
  o.zoom(3);
  EXPECT_NEAR(o.distance(), d0 / std::pow(OrbitCamera::kZoomStep, 3), 1e-12);
  EXPECT_EQ(o.target(), c.target);
  EXPECT_NEAR(((o.eye() - o.target()).normalized() - (c.eye - c.target).normalized()).norm(), 0,
              1e-12);
  o.zoom(-3);
  EXPECT_NEAR((o.eye() - c.eye).norm(), 0.0, 1e-12);
  // Zoomed far in, the near plane still stays in front of the target.
  o.zoom(60);
  EXPECT_LT(o.camera().z_near, o.distance());
}

TEST(OrbitCamera, FrameFitsTheBoxAndKeepsTheViewDirection) {
  const auto c = make_camera({0.3, 0.2, 0.6}, {0, 0.1, 0}, {0, 1, 0});
  OrbitCamera o(c);
  const Vec3 dir0 = (o.eye() - o.target()).normalized();
  const Eigen::AlignedBox3d box(Vec3(1.0, 2.0, -0.5), Vec3(1.4, 2.3, -0.1));
  o.frame(box);
  EXPECT_NEAR((o.target() - box.center()).norm(), 0.0, 1e-12);
  EXPECT_NEAR(((o.eye() - o.target()).normalized() - dir0).norm(), 0.0, 1e-12);
  for (int i = 0; i < 8; ++i) {
    const Vec3 corner = box.corner(Eigen::AlignedBox3d::CornerType(i));
    const Vec2 p = pixel(o, corner);
    EXPECT_GT(p.x(), 0);
    EXPECT_LT(p.x(), kW);
    EXPECT_GT(p.y(), 0);
    EXPECT_LT(p.y(), kH);
    const double depth = (corner - o.eye()).dot(-dir0);
    EXPECT_GT(depth, o.camera().z_near);
    EXPECT_LT(depth, o.camera().z_far);
  }
}

}  // namespace
}  // namespace follicle::viewer
