// render::box_in_view: the frustum test behind the "outside the camera's view" warning.
#include <gtest/gtest.h>

#include "follicle/render/camera.hpp"

using namespace follicle;
using namespace follicle::render;

namespace {
Camera cam() {
  Camera c;
  c.eye = Vec3(0, 0, 1);
  c.target = Vec3(0, 0, 0);
  c.up = Vec3(0, 1, 0);
  c.fov_y = 0.5;  // rad: half-height tan(0.25) ~ 0.255 at distance 1
  c.z_near = 0.05;
  c.z_far = 10;
  return c;
}
Eigen::AlignedBox3d cube(const Vec3& c, double h) {
  return {c - Vec3::Constant(h), c + Vec3::Constant(h)};
}
}  // namespace

TEST(BoxInView, InsideAcrossAndBeyondEachPlane) {
  const Camera c = cam();
  EXPECT_TRUE(box_in_view(c, 1.0, cube(Vec3::Zero(), 0.1)));
  EXPECT_TRUE(box_in_view(c, 1.0, cube(Vec3(0.3, 0, 0), 0.1)));   // across the right edge
  EXPECT_FALSE(box_in_view(c, 1.0, cube(Vec3(0.5, 0, 0), 0.1)));  // right of the view
  EXPECT_FALSE(box_in_view(c, 1.0, cube(Vec3(-0.5, 0, 0), 0.1)));
  EXPECT_FALSE(box_in_view(c, 1.0, cube(Vec3(0, 0.5, 0), 0.1)));  // above
  EXPECT_FALSE(box_in_view(c, 1.0, cube(Vec3(0, 0, 2), 0.1)));    // behind the camera
  EXPECT_FALSE(box_in_view(c, 1.0, cube(Vec3(0, 0, -20), 0.1)));  // beyond far
  // A wide image sees further to the side.
  EXPECT_TRUE(box_in_view(c, 3.0, cube(Vec3(0.5, 0, 0), 0.1)));
  // The camera inside a big box sees it.
  EXPECT_TRUE(box_in_view(c, 1.0, cube(Vec3(0, 0, 1), 5.0)));
  EXPECT_FALSE(box_in_view(c, 1.0, Eigen::AlignedBox3d()));  // empty
}
