// CPU resolve pass; see resolve_cpu.hpp.
#include "follicle/render/resolve_cpu.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "follicle/core/error.hpp"

namespace follicle::render {
namespace {

constexpr int kTable = 4096;  // intervals of the sRGB table over [0, 1]

/// [0, 1] (NaN -> 0, like GL's clamp of a NaN in practice).
float unit(float v) {
  return v > 0 ? std::min(v, 1.0f) : 0.0f;
}

/// Round to nearest of v in [0, 1] x 255 (GL's float -> unorm8 conversion).
uint8_t unorm8(float v) {
  return uint8_t(int(unit(v) * 255.0f + 0.5f));
}

}  // namespace

double srgb_encode(double c) {
  c = std::clamp(c, 0.0, 1.0);
  return c < 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1 / 2.4) - 0.055;
}

float half_bits_to_float(uint16_t h) {
  const int e = (h >> 10) & 31, m = h & 1023;
  const float mag = e == 0    ? std::ldexp(float(m), -24)  // zero and subnormals
                    : e == 31 ? (m == 0 ? std::numeric_limits<float>::infinity()
                                        : std::numeric_limits<float>::quiet_NaN())
                              : std::ldexp(float(1024 + m), e - 25);
  return (h & 0x8000) ? -mag : mag;
}

CpuResolve::CpuResolve() : m_srgb(2 * (kTable + 1)), m_half(65536) {
  // (value, slope) per interval in 8-bit units, the rounding's + 1/2 folded into the value.
  for (int i = 0; i <= kTable; ++i) {
    const double a = srgb_encode(double(i) / kTable);
    const double b = i < kTable ? srgb_encode(double(i + 1) / kTable) : a;
    m_srgb[2 * std::size_t(i)] = float(255 * a + 0.5);
    m_srgb[2 * std::size_t(i) + 1] = float(255 * (b - a));
  }
  for (uint32_t h = 0; h < 65536; ++h) m_half[h] = half_bits_to_float(uint16_t(h));
}

void CpuResolve::half_to_float(const uint16_t* src, std::size_t n, float* dst) const {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) dst[i] = m_half[src[i]];
                    });
}

void resolve_srgb_cpu(const float* rgba, int fb_w, int fb_h, int k, bool unpremultiply,
                      image::ImageRGBA8& out) {
  CpuResolve().resolve(rgba, fb_w, fb_h, k, unpremultiply, out);
}

void CpuResolve::resolve(const float* rgba, int fb_w, int fb_h, int k, bool unpremultiply,
                         image::ImageRGBA8& out) const {
  if (k < 1) fail("resolve: supersampling factor {} is not >= 1", k);
  if (!rgba || out.empty() || fb_w != k * out.width() || fb_h != k * out.height())
    fail("resolve: a {}x{} frame does not resolve {}x down to {}x{}", fb_w, fb_h, k, out.width(),
         out.height());
  const float* table = m_srgb.data();
  const int w = out.width(), h = out.height();
  const float inv_n = 1.0f / float(k * k);
  // One output pixel from its averaged linear RGBA.
  auto encode = [&](const float* s, uint8_t* d) {
    for (int c = 0; c < 3; ++c) {
      float v = s[c];
      if (unpremultiply) v = s[3] > 0 ? v / s[3] : 0.0f;
      const float t = unit(v) * float(kTable);
      const int i = int(t);
      const float* e = table + 2 * i;
      d[c] = uint8_t(int(e[0] + (t - float(i)) * e[1]));
    }
    d[3] = unorm8(s[3]);
  };
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y != r.end(); ++y) {
      uint8_t* dst = out.data() + std::size_t(h - 1 - y) * std::size_t(w) * 4;  // flip rows
      if (k == 1) {
        const float* src = rgba + std::size_t(y) * std::size_t(fb_w) * 4;
        for (int x = 0; x < w; ++x) encode(src + 4 * x, dst + 4 * x);
        continue;
      }
      for (int x = 0; x < w; ++x) {
        float s4[4] = {0, 0, 0, 0};
        for (int j = 0; j < k; ++j) {
          const float* src =
              rgba +
              (std::size_t(y * k + j) * std::size_t(fb_w) + std::size_t(x) * std::size_t(k)) * 4;
          for (int i = 0; i < k; ++i)
            for (int c = 0; c < 4; ++c) s4[c] += src[4 * i + c];
        }
        for (float& v : s4) v *= inv_n;
        encode(s4, dst + 4 * x);
      }
    }
  });
}

}  // namespace follicle::render
