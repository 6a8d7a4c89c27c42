#include "follicle/image/raster.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace follicle;
using namespace follicle::image;

namespace {
double sum(const ImageF& img) {
  double s = 0;
  for (float v : img.storage()) s += v;
  return s;
}
}  // namespace

TEST(Raster, DiscAreaMatchesPiR2) {
  for (double r : {3.0, 7.3, 20.0}) {
    ImageF img(64, 64);
    draw_disc(img, Vec2(31.7, 32.2), r, 1.0f);
    EXPECT_NEAR(sum(img), kPi * r * r, 0.02 * kPi * r * r + 1.0) << r;
    EXPECT_FLOAT_EQ(img.at(31, 32), 1.0f);
    EXPECT_FLOAT_EQ(img.at(0, 0), 0.0f);
  }
}

TEST(Raster, HorizontalLineCoverageIsExact) {
  // Width 3 from x=10 to x=50 at y=20.5: rows 19,20,21 fully covered in the middle; the
  // total area is length*width + the two round caps (pi r^2).
  ImageF img(64, 40);
  draw_line(img, Vec2(10, 20.5), Vec2(50, 20.5), 3.0, 1.0f);
  EXPECT_FLOAT_EQ(img.at(30, 19), 1.0f);
  EXPECT_FLOAT_EQ(img.at(30, 20), 1.0f);
  EXPECT_FLOAT_EQ(img.at(30, 21), 1.0f);
  EXPECT_FLOAT_EQ(img.at(30, 22), 0.0f);
  EXPECT_FLOAT_EQ(img.at(30, 18), 0.0f);
  EXPECT_NEAR(sum(img), 40 * 3 + kPi * 1.5 * 1.5, 1.5);
  // Half-pixel offset gives half coverage on the edge rows.
  ImageF half(64, 40);
  draw_line(half, Vec2(10, 20.0), Vec2(50, 20.0), 3.0, 1.0f);  // covers y in [18.5, 21.5]
  EXPECT_FLOAT_EQ(half.at(30, 18), 0.5f);
  EXPECT_FLOAT_EQ(half.at(30, 21), 0.5f);
  EXPECT_FLOAT_EQ(half.at(30, 19), 1.0f);
  EXPECT_FLOAT_EQ(half.at(30, 20), 1.0f);
}

TEST(Raster, BlendModes) {
  ImageF img(16, 16, 0.5f);
  draw_disc(img, Vec2(8, 8), 4, 0.2f, Blend::Max);
  EXPECT_FLOAT_EQ(img.at(8, 8), 0.5f);
  draw_disc(img, Vec2(8, 8), 4, 0.2f, Blend::Min);
  EXPECT_FLOAT_EQ(img.at(8, 8), 0.2f);
  draw_disc(img, Vec2(8, 8), 4, 0.3f, Blend::Add);
  EXPECT_FLOAT_EQ(img.at(8, 8), 0.5f);
  EXPECT_FLOAT_EQ(img.at(0, 0), 0.5f);
}

TEST(Raster, PolylineDoesNotDoubleCountJoins) {
  ImageF a(64, 64), b(64, 64);
  draw_polyline(a, {Vec2(10, 10), Vec2(30, 30), Vec2(50, 10)}, 4.0, 1.0f, Blend::Add);
  for (float v : a.storage()) EXPECT_LE(v, 1.0f);
  draw_line(b, Vec2(10, 10), Vec2(30, 30), 4.0, 1.0f, Blend::Add);
  draw_line(b, Vec2(30, 30), Vec2(50, 10), 4.0, 1.0f, Blend::Add);
  EXPECT_GT(b.at(30, 29), 1.5f);  // two separate lines overlap at the join
}

TEST(Raster, ProfileSeesDistanceAndParameter) {
  ImageF img(40, 40);
  draw_line_profile(img, Vec2(5, 20), Vec2(35, 20), 6.0,
                    [](double d, double t) { return float(-(6.0 - d) * (t + 1.0)); });
  EXPECT_NEAR(img.at(20, 19), -(6.0 - 0.5) * (1.0 + 15.5 / 30.0), 1e-5);
  EXPECT_FLOAT_EQ(img.at(20, 30), 0.0f);
}

TEST(Raster, ShapesOutsideImageAreClippedAndBadInputThrows) {
  ImageF img(8, 8);
  draw_disc(img, Vec2(-100, -100), 5, 1.0f);
  draw_line(img, Vec2(-10, 4), Vec2(20, 4), 2, 1.0f);
  EXPECT_FLOAT_EQ(img.at(3, 3), 1.0f);
  EXPECT_THROW(draw_disc(img, Vec2(NAN, 0), 1, 1.0f), Error);
  EXPECT_THROW(draw_line(img, Vec2(0, 0), Vec2(1, 1), -1, 1.0f), Error);
}
