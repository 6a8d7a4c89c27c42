#include "follicle/image/metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace follicle;
using namespace follicle::image;

TEST(ImageMetrics, IdenticalImagesHaveZeroErrorAndInfinitePsnr) {
  ImageRGBA8 a(8, 8, 100);
  const ImageDiff d = compare_images(a, a);
  EXPECT_EQ(d.rmse, 0.0);
  EXPECT_EQ(d.max_abs, 0.0);
  EXPECT_EQ(d.share_over, 0.0);
  EXPECT_TRUE(std::isinf(d.psnr));
}

TEST(ImageMetrics, KnownDifferences8Bit) {
  // 4 pixels, gray; one pixel off by 20, one by 4: mse = (400 + 16) / 4 = 104.
  ImageGray8 a(2, 2, 50), b(2, 2, 50);
  b.at(0, 0) = 70;
  b.at(1, 1) = 46;
  DiffOptions opt;
  opt.threshold = 5;
  const ImageDiff d = compare_images(a, b, opt);
  EXPECT_NEAR(d.rmse, std::sqrt(104.0), 1e-12);
  EXPECT_NEAR(d.psnr, 20 * std::log10(255.0 / std::sqrt(104.0)), 1e-9);
  EXPECT_EQ(d.max_abs, 20.0);
  EXPECT_EQ(d.pixels_over, 1u);
  EXPECT_DOUBLE_EQ(d.share_over, 0.25);
}

TEST(ImageMetrics, FloatPeakAndAlphaHandling) {
  ImageRGBAF a(1, 2, 0.f), b(1, 2, 0.f);
  b.at(0, 0, 3) = 1.0f;  // alpha only
  b.at(0, 1, 0) = 0.5f;
  const ImageDiff all = compare_images(a, b);
  EXPECT_NEAR(all.rmse, std::sqrt((1.0 + 0.25) / 8.0), 1e-12);
  EXPECT_EQ(all.pixels_over, 2u);
  DiffOptions na;
  na.ignore_alpha = true;
  const ImageDiff rgb = compare_images(a, b, na);
  EXPECT_NEAR(rgb.rmse, std::sqrt(0.25 / 6.0), 1e-12);
  EXPECT_EQ(rgb.max_abs, 0.5);
  EXPECT_EQ(rgb.pixels_over, 1u);
  EXPECT_NEAR(rgb.psnr, 20 * std::log10(1.0 / rgb.rmse), 1e-12);
}

TEST(ImageMetrics, SizeMismatchIsError) {
  EXPECT_THROW(compare_images(ImageF(2, 2), ImageF(2, 3)), Error);
}
