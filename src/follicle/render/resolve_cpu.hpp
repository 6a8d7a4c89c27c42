#pragma once
// The GL renderer's resolve pass (kResolveFs in shaders_gl.hpp) on the CPU, for frames whose
// colour buffer is on the CPU anyway (the "cpu" hair view pass, docs/adr/0007): box filter of
// k x k linear samples, optional unpremultiply, clamp to [0, 1], sRGB encode, 8-bit rounding.
// The sRGB curve comes from a 4,097-entry table with linear interpolation (error below 0.005
// of an 8-bit step, see the test); rows are resolved in parallel in the calling task arena.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "follicle/image/image.hpp"

namespace follicle::render {

/// The tables of the CPU resolve, built once (a renderer keeps one).
class CpuResolve {
 public:
  CpuResolve();
  /// `rgba`: fb_w x fb_h linear RGBA floats, rows bottom-up (glReadPixels order), with
  /// fb_w = k * out.width() and fb_h = k * out.height() of the already sized `out`; `out` rows
  /// are top-down. Throws follicle::Error for a size mismatch or k < 1.
  void resolve(const float* rgba, int fb_w, int fb_h, int k, bool unpremultiply,
               image::ImageRGBA8& out) const;
  /// IEEE half floats (an RGBA16F frame read as GL_HALF_FLOAT, which llvmpipe copies without
  /// converting) to floats, exactly, in parallel.
  void half_to_float(const uint16_t* src, std::size_t n, float* dst) const;

 private:
  std::vector<float> m_srgb;  // the sRGB curve: (255 value + 1/2, 255 slope) per table interval
  std::vector<float> m_half;  // the value of every half-float bit pattern
};

/// CpuResolve().resolve(...), for one-off use.
void resolve_srgb_cpu(const float* rgba, int fb_w, int fb_h, int k, bool unpremultiply,
                      image::ImageRGBA8& out);

/// The exact sRGB encoding of a linear value in [0, 1] (IEC 61966-2-1), for tests and the table.
double srgb_encode(double linear);

/// The exact value of an IEEE 754 binary16 bit pattern.
float half_bits_to_float(uint16_t h);

}  // namespace follicle::render
