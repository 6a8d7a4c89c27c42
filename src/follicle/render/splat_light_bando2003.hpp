#pragma once
// The light pass of Bando, Chen & Nishita 2003 hair splatting, on the CPU, exactly per particle
// (§3.4 of the thesis in ../shared/papers/000_c01fb93c031b01a4.txt, pseudo-code lines 6-12):
//
//    6. Disable depth-buffering.
//    7. Sort the particles in ascending order of depth.
//    8. for each particle not in the objects' shadows
//    9.   Read the intensity of the pixel where the particle is projected.
//   10.   Render the particle with a billboard.
//   11. end for
//   12. Read the color buffer for light mapping.
//
// The light buffer starts white (line 1); each particle, in ascending depth from the parallel
// light, first reads the buffer at its position (the light attenuated by every nearer
// particle), then multiplies the buffer by (1 - alpha) over its light-view billboard. The
// final buffer is the light map of the head and torso (line 16). Pure CPU (no GL), used by
// splat_gl.cpp as the default light pass (RenderSettings::hair_light_pass = "cpu") and
// reproducing its GPU programs' sampling: the read is the 5-tap bilinear footprint average of
// kSplatGatherVs, the billboard is billboard_corner() with d_p = the light's travel direction,
// and the hair texture is sampled like GL_LINEAR_MIPMAP_NEAREST with CLAMP_TO_EDGE.
// See docs/adr/0005-cpu-splat-light-pass.md.
#include <cstdint>
#include <span>
#include <vector>

#include "follicle/core/types.hpp"
#include "follicle/image/image.hpp"

namespace follicle::render {

/// One particle of the light pass, world space.
struct LightSplatParticle {
  Vec3 pos = Vec3::Zero();
  Vec3 t{0, 1, 0};           // unit hair direction t_i
  double half_w = 0.001;     // billboard half-width across t_i [m]
  double half_l = 0.003;     // billboard half-length along t_i [m] (before the sin(theta) scale)
  double alpha = 1.0;        // opacity alpha_i in [0, 1]
  double min_sin = 0.25;     // lower clamp of sin(theta), in (0, 1]
  double opacity_scale = 1;  // SplatMaterial::shadow_opacity_scale (>= 0)
  bool casts = true;         // SplatMaterial::cast_shadow: splatted into the buffer (line 10)
  double vis = 1.0;          // objects' shadow-map visibility in [0, 1] (line 8)
};

/// The alpha channel of a hair texture and its mip chain (2x2 box averages rounded like the
/// 8-bit glGenerateMipmap), sampled like GL_LINEAR_MIPMAP_NEAREST with CLAMP_TO_EDGE.
class SplatAlphaTexture {
 public:
  /// Throws follicle::Error for an empty image.
  explicit SplatAlphaTexture(const image::ImageRGBA8& img);
  int levels() const { return int(m_levels.size()); }
  int width(int level = 0) const { return m_levels[std::size_t(level)].w; }
  int height(int level = 0) const { return m_levels[std::size_t(level)].h; }
  /// GL mip selection for a footprint of `rho` level-0 texels per pixel: level 0 when
  /// magnified or lambda = log2(rho) <= 1/2, else the nearest level, at most the last one.
  int level_for(double rho) const;
  /// Bilinear alpha in [0, 1] at (u, v) in [0, 1]^2 (u across = image x, v along = image row),
  /// texel centres at (i + 1/2) / size, edges clamped.
  float sample(double u, double v, int level) const;
  /// A level's alpha with a one-texel border replicating its edge (CLAMP_TO_EDGE without
  /// clamping): (w + 2) x (h + 2) floats, row-major, texel (x, y) at [(y + 1)(w + 2) + x + 1].
  const float* padded(int level) const { return m_levels[std::size_t(level)].a.data(); }

 private:
  struct Level {
    int w = 0, h = 0;
    std::vector<float> a;  // alpha in [0, 1], padded as described at padded()
  };
  std::vector<Level> m_levels;
};

struct SplatLightParams {
  /// World -> clip of the light: orthographic (parallel light, §3.4; last row 0 0 0 1), the
  /// shadow map's projection. The buffer covers clip x, y in [-1, 1].
  Mat4 light_vp = Mat4::Identity();
  Vec3 travel{0, 0, -1};  // unit direction the light travels (d_p of the light-view billboards)
  int size = 512;         // light buffer resolution (RenderSettings::hair_light_map_size)
};

struct SplatLightResult {
  /// The light buffer after the last particle (line 12), size x size, row-major, row 0 at clip
  /// y = -1 (the layout of a GL texture uploaded from it): the light map.
  std::vector<float> light;
  /// Per particle (input index): the light reaching it through the hair (line 9), i.e. the
  /// buffer before its own splat, 5-tap footprint average.
  std::vector<float> reach;
};

/// Line 7: particle indices in ascending depth from the light (travel . pos), stable (ties keep
/// the input order). Used by both the CPU and the GPU light pass.
std::vector<int32_t> splat_light_order(const Vec3& travel,
                                       std::span<const LightSplatParticle> particles);

/// Lines 6-12 for `particles` (exact per-particle read, no slicing), in parallel over bands of
/// buffer rows with TBB in the caller's task arena, bit-identical to the sequential loop for
/// any thread count. Reuses `out`'s storage.
/// Throws follicle::Error naming the particle for non-finite or out-of-range data, and for a
/// non-orthographic projection, a size outside [1, 16384] or a non-unit travel direction.
void splat_light_pass_bando2003(const SplatLightParams& params,
                                std::span<const LightSplatParticle> particles,
                                const SplatAlphaTexture& texture, SplatLightResult& out);

namespace detail {
/// splat_light_pass_bando2003() with the buffer cut into bands of `band_rows` rows (>= 1), run
/// in parallel with TBB in the caller's task arena. The result is bit-identical to the
/// sequential loop for every band height and thread count (tested).
void splat_light_pass_bando2003_banded(const SplatLightParams& params,
                                       std::span<const LightSplatParticle> particles,
                                       const SplatAlphaTexture& texture, SplatLightResult& out,
                                       int band_rows);
}  // namespace detail

}  // namespace follicle::render
