#pragma once
// The view pass of Bando, Chen & Nishita 2003 hair splatting on the CPU (§3.4 of the thesis in
// ../shared/papers/000_c01fb93c031b01a4.txt, pseudo-code lines 17-21):
//
//   17. Enable depth-buffering (test against the objects, no writes).
//   18. Sort the particles in descending order of depth from the eye.
//   19. for each particle
//   20.   Render the particle with a billboard (colour from the light it receives).
//   21. end for
//
// It reproduces kSplatViewVs / kSplatViewFs of the GL pass exactly in its geometry: the
// billboard of billboard_corner() with d_p from the eye to the particle, perspective-correct
// texture coordinates (the inverse of the billboard's homography), the depth of the billboard's
// plane tested GL_LESS against the objects' depth, the hair texture sampled like
// GL_LINEAR_MIPMAP_NEAREST with CLAMP_TO_EDGE (the mip level chosen once per billboard from its
// footprint at the centre), texels with alpha < 0.004 discarded, and the blend
// (SRC_ALPHA, ONE_MINUS_SRC_ALPHA; alpha ONE, ONE_MINUS_SRC_ALPHA) in linear float. Rows are
// split into bands run in parallel, each band walking all particles in the same order, so the
// result is identical for any thread count. docs/adr/0007-cpu-splat-view-pass.md says why this
// is the default on a software rasteriser.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "follicle/core/types.hpp"
#include "follicle/image/image.hpp"
#include "follicle/render/splat_light_bando2003.hpp"

namespace follicle::render {

/// One particle of the view pass, world space.
struct ViewSplatParticle {
  Vec3 pos = Vec3::Zero();
  Vec3 t{0, 1, 0};            // unit hair direction t_i
  double half_w = 0.001;      // billboard half-width across t_i [m]
  double half_l = 0.003;      // billboard half-length along t_i [m] (before the sin scale)
  double alpha = 1.0;         // opacity alpha_i in [0, 1] (scaled by 1/sin(theta) here)
  double min_sin = 0.25;      // lower clamp of sin(theta), in (0, 1]
  Vec3 color = Vec3::Ones();  // shaded linear RGB of the particle (the vertex shader's vColor)
};

/// A hair texture's RGBA with its mip chain: each channel's chain is SplatAlphaTexture's (the
/// 8-bit glGenerateMipmap), stored interleaved per level with a one-texel border (like
/// SplatAlphaTexture::padded) for 4-wide reads; sampled like GL_LINEAR_MIPMAP_NEAREST with
/// CLAMP_TO_EDGE.
class SplatColorTexture {
 public:
  /// Throws follicle::Error for an empty image.
  explicit SplatColorTexture(const image::ImageRGBA8& img);
  int levels() const { return m_alpha.levels(); }
  int width(int level = 0) const { return m_alpha.width(level); }
  int height(int level = 0) const { return m_alpha.height(level); }
  int level_for(double rho) const { return m_alpha.level_for(rho); }
  /// (w + 2) x (h + 2) RGBA texels of a level, texel (x, y) at 4 [(y + 1)(w + 2) + x + 1].
  const float* padded_rgba(int level) const { return m_rgba[std::size_t(level)].data(); }
  /// Texels of a level with alpha >= kSplatAlphaDiscard lie in columns [box[0], box[1]] and
  /// rows [box[2], box[3]] (level texel indices); an empty level has box[0] > box[1]. A sample
  /// whose bilinear footprint lies outside is discarded, so the pass skips those pixels.
  const std::array<int, 4>& coverage(int level) const { return m_cover[std::size_t(level)]; }

  /// kSplatViewFs discards fragments whose texel alpha is below this.
  static constexpr float kSplatAlphaDiscard = 0.004f;

 private:
  SplatAlphaTexture m_alpha;                // the alpha chain (and the level geometry)
  std::vector<std::vector<float>> m_rgba;   // per level, interleaved
  std::vector<std::array<int, 4>> m_cover;  // per level, see coverage()
};

/// The colour and depth buffers the pass draws into: a window of a GL framebuffer, rows bottom
/// up (glReadPixels order). Pixel (x, y) of the window is framebuffer pixel (x0 + x, y0 + y).
struct SplatViewTarget {
  int fb_width = 0, fb_height = 0;            // full framebuffer (the viewport) [px]
  int x0 = 0, y0 = 0, width = 0, height = 0;  // the window read back
  float* rgba = nullptr;  // linear RGBA floats of the window's pixels, rows rgba_stride apart
  int rgba_stride = 0;    // pixels from one row of `rgba` to the next; 0: width
  const float* depth = nullptr;  // width * height window depths in [0, 1] (GL_LESS test)
};

struct SplatViewParams {
  Mat4 view_proj = Mat4::Identity();  // world -> clip of the camera
  Vec3 eye = Vec3::Zero();            // camera position (d_p = normalize(pos - eye))
};

/// Line 18: particle indices far first (ascending view-space z for a right-handed view matrix
/// looking down -z), stable.
std::vector<int32_t> splat_view_order(const Mat4& view,
                                      std::span<const ViewSplatParticle> particles);

/// The framebuffer pixels (x0, y0, x1, y1 half-open, clamped to the framebuffer) that the
/// billboards of `particles` can touch; empty (x0 >= x1) when none is visible.
void splat_view_bounds(const SplatViewParams& params, std::span<const ViewSplatParticle> particles,
                       int fb_width, int fb_height, int bounds[4]);

/// Lines 19-21: the billboards in `order` (back to front) blended into `target`. Throws
/// follicle::Error naming the particle for non-finite or out-of-range data and for a target
/// whose buffers are missing or that does not fit its framebuffer.
void splat_view_pass_bando2003(const SplatViewParams& params,
                               std::span<const ViewSplatParticle> particles,
                               std::span<const int32_t> order, const SplatColorTexture& texture,
                               const SplatViewTarget& target);

}  // namespace follicle::render
