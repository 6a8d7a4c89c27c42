// The CPU resolve pass (resolve_cpu.hpp): the sRGB curve, the table against the exact curve,
// the box filter, unpremultiplying, the row flip and bad sizes.
#include "follicle/render/resolve_cpu.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <vector>

#include "follicle/core/error.hpp"
#include "follicle/core/rng.hpp"

using namespace follicle;
using namespace follicle::render;

namespace {

int exact8(double linear) {
  return int(std::lround(srgb_encode(linear) * 255));
}

}  // namespace

TEST(ResolveCpu, SrgbCurveHasItsPublishedValues) {
  EXPECT_DOUBLE_EQ(srgb_encode(0), 0);
  EXPECT_NEAR(srgb_encode(1), 1, 1e-12);
  EXPECT_NEAR(srgb_encode(0.5), 0.735356983, 1e-8);
  EXPECT_NEAR(srgb_encode(0.002), 12.92 * 0.002, 1e-15);  // linear toe
  // continuous at the knee 0.0031308
  EXPECT_NEAR(srgb_encode(0.0031308 - 1e-12), srgb_encode(0.0031308 + 1e-12), 1e-6);
  EXPECT_DOUBLE_EQ(srgb_encode(-1), 0);
  EXPECT_DOUBLE_EQ(srgb_encode(7), srgb_encode(1));
}

TEST(ResolveCpu, TableMatchesTheExactCurveAndFlipsRows) {
  // One row of 4,096 pixels sweeping [0, 1] densely (plus a second row of other values): every
  // channel equals the exactly encoded, rounded value but where the exact value lies within
  // 0.01 of a rounding boundary (where the table's 0.005-step error may round the other way).
  const int w = 4096, h = 2;
  std::vector<float> frame(4 * std::size_t(w) * h);
  Rng r = Rng::stream(3, 0);
  for (int x = 0; x < w; ++x)
    for (int c = 0; c < 4; ++c) {
      frame[4 * std::size_t(x) + std::size_t(c)] = float((x + 0.37 * c) / (w - 1));
      frame[4 * (std::size_t(w) + std::size_t(x)) + std::size_t(c)] = float(r.uniform(0, 1));
    }
  image::ImageRGBA8 out(w, h);
  resolve_srgb_cpu(frame.data(), w, h, 1, false, out);
  int checked = 0;
  for (int row = 0; row < h; ++row)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        // GL row `row` is image row h - 1 - row.
        const double v = frame[4 * (std::size_t(row) * w + std::size_t(x)) + std::size_t(c)];
        const double e = srgb_encode(v) * 255;
        const int got = out.at(x, h - 1 - row, c);
        if (std::abs(e - std::floor(e) - 0.5) < 0.01) {
          EXPECT_LE(std::abs(got - exact8(v)), 1);
          continue;
        }
        ++checked;
        ASSERT_EQ(got, exact8(v)) << "row " << row << " x " << x << " c " << c << " v " << v;
      }
  EXPECT_GT(checked, 3 * w * h * 95 / 100);
  // Alpha is stored linearly.
  EXPECT_EQ(out.at(w - 1, h - 1, 3), 255);
  EXPECT_EQ(out.at(0, h - 1, 3), int(std::lround(0.37 * 3 / (w - 1) * 255)));
}

TEST(ResolveCpu, BoxFilterAndUnpremultiply) {
  // k = 2: the four samples of output pixel (0, 0) average in linear space before encoding.
  const int k = 2, w = 2, h = 1;
  std::vector<float> frame(4 * std::size_t(w * k) * std::size_t(h * k), 0.0f);
  auto set = [&](int x, int y, float v, float a) {
    float* p = &frame[4 * (std::size_t(y) * std::size_t(w * k) + std::size_t(x))];
    p[0] = p[1] = p[2] = v;
    p[3] = a;
  };
  set(0, 0, 1.0f, 1.0f);
  set(1, 0, 0.0f, 1.0f);
  set(0, 1, 0.0f, 0.0f);
  set(1, 1, 0.0f, 0.0f);
  set(2, 0, 0.2f, 0.5f);  // pixel 1: premultiplied 0.2 at alpha 0.5 -> 0.4 unpremultiplied
  set(3, 0, 0.2f, 0.5f);
  set(2, 1, 0.2f, 0.5f);
  set(3, 1, 0.2f, 0.5f);
  image::ImageRGBA8 out(w, h);
  resolve_srgb_cpu(frame.data(), w * k, h * k, k, false, out);
  EXPECT_EQ(out.at(0, 0, 0), exact8(0.25));
  EXPECT_EQ(out.at(0, 0, 3), int(std::lround(0.5 * 255)));
  EXPECT_EQ(out.at(1, 0, 0), exact8(0.2));
  resolve_srgb_cpu(frame.data(), w * k, h * k, k, true, out);
  EXPECT_EQ(out.at(0, 0, 0), exact8(0.5));  // 0.25 / 0.5
  EXPECT_EQ(out.at(1, 0, 0), exact8(0.4));
}

TEST(ResolveCpu, SameBytesForAnyThreadCount) {
  const int w = 64, h = 48;
  std::vector<float> frame(4 * std::size_t(w) * h);
  Rng r = Rng::stream(5, 0);
  for (float& v : frame) v = float(r.uniform(-0.1, 1.2));
  image::ImageRGBA8 a(w, h), b(w, h);
  tbb::task_arena one(1), two(2);
  one.execute([&] { resolve_srgb_cpu(frame.data(), w, h, 1, false, a); });
  two.execute([&] { resolve_srgb_cpu(frame.data(), w, h, 1, false, b); });
  EXPECT_TRUE(std::equal(a.data(), a.data() + 4 * w * h, b.data()));
}

TEST(ResolveCpu, BadSizesFail) {
  std::vector<float> frame(4 * 16, 0.5f);
  image::ImageRGBA8 out(4, 4);
  EXPECT_NO_THROW(resolve_srgb_cpu(frame.data(), 4, 4, 1, false, out));
  EXPECT_THROW(resolve_srgb_cpu(frame.data(), 4, 4, 2, false, out), Error);
  EXPECT_THROW(resolve_srgb_cpu(frame.data(), 4, 4, 0, false, out), Error);
  EXPECT_THROW(resolve_srgb_cpu(nullptr, 4, 4, 1, false, out), Error);
  image::ImageRGBA8 empty;
  EXPECT_THROW(resolve_srgb_cpu(frame.data(), 4, 4, 1, false, empty), Error);
}

TEST(ResolveCpu, HalfFloatsWidenExactly) {
  EXPECT_EQ(half_bits_to_float(0x0000), 0.0f);
  EXPECT_EQ(half_bits_to_float(0x3C00), 1.0f);
  EXPECT_EQ(half_bits_to_float(0xC000), -2.0f);
  EXPECT_EQ(half_bits_to_float(0x3555), 0.333251953125f);
  EXPECT_EQ(half_bits_to_float(0x7BFF), 65504.0f);               // largest finite
  EXPECT_EQ(half_bits_to_float(0x0001), std::ldexp(1.0f, -24));  // smallest subnormal
  EXPECT_EQ(half_bits_to_float(0x0400), std::ldexp(1.0f, -14));  // smallest normal
  EXPECT_TRUE(std::isinf(half_bits_to_float(0x7C00)));
  EXPECT_TRUE(std::isnan(half_bits_to_float(0x7E00)));
  // Every finite pattern: monotone in its magnitude bits, and the table path agrees.
  std::vector<uint16_t> all(65536);
  for (uint32_t h = 0; h < 65536; ++h) all[h] = uint16_t(h);
  std::vector<float> wide(all.size());
  CpuResolve().half_to_float(all.data(), all.size(), wide.data());
  for (uint32_t h = 1; h < 0x7C00; ++h) {
    ASSERT_GT(wide[h], wide[h - 1]) << h;
    ASSERT_EQ(wide[h | 0x8000], -wide[h]);
  }
}
