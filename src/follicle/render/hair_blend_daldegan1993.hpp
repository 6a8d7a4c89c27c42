#pragma once
// Hair rendering of Daldegan, Magnenat Thalmann, Kurihara & Thalmann 1993 §4 (after LeBlanc,
// Turner & Thalmann 1991, "Rendering hair using pixel blending and shadow buffers"), on the CPU.
// The paper's pipeline, per frame:
//   (1) the scene model projected onto each light: one scene shadow buffer per light (the GL
//       renderer draws it and reads it back);
//   (2) the hair projected onto each light, "drawing each hair segment into a Z-buffer":
//       rasterize_hair_depth();
//   (3) both depth maps composed into one composite shadow buffer per light:
//       compose_shadow_buffers() (per-texel minimum);
//   (4) the hairless scene rendered with its Z-buffer using the composite buffers (GL: the
//       composite is uploaded into the mesh pass's shadow map, so the hair shadows the skin);
//   (5) the hair segments blended into the scene image, the scene's Z-buffer deciding
//       visibility and the composite buffers shadowing: shade_hair_vertices() gives every
//       segment endpoint its intensity H of eq. (7), HairBlender draws the segments as
//       antialiased lines whose alpha is their pixel coverage.
// Everything here works on plain arrays (no GL) and is parallel over Context's threads with
// results that do not depend on the thread count. docs/equations/daldegan_render.md maps the
// steps to the functions and records the reading of eq. (7).
#include <tbb/enumerable_thread_specific.h>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/types.hpp"

namespace follicle::render {

/// The hair model "broken into straight 3D line segments" (§4): polylines in world space;
/// consecutive points i, i + 1 of a strand make one segment.
struct HairSegments {
  std::vector<Vec3f> points;          // world [m]
  std::vector<uint32_t> offsets{0};   // strand s: points [offsets[s], offsets[s + 1])
  std::vector<float> radius;          // per point [m]; empty or kNoRadius: no world width
                                      // there (the strand's width_px is used)
  std::vector<float> width_px;        // per strand: screen width [framebuffer px] without radius
  std::vector<float> opacity;         // per strand, [0, 1]
  std::vector<uint8_t> casts_shadow;  // per strand: 1 = drawn into the hair shadow buffers

  /// A point of `radius` without a world width (when other strands have one).
  static constexpr float kNoRadius = -1.0f;

  std::size_t num_strands() const { return offsets.size() - 1; }
  std::size_t num_points() const { return points.size(); }
  /// Appends a strand with its screen width, opacity and whether it casts hair shadows.
  void add_strand(std::span<const Vec3f> pts, float width = 1.0f, float alpha = 1.0f,
                  bool casts = true);
  /// Throws follicle::Error, prefixed by `where`, naming the first bad strand or point:
  /// offsets that do not start at 0, decrease or do not end at the point count; per-strand or
  /// per-point arrays of the wrong size; a point that is not finite; a radius < 0 other than
  /// kNoRadius; a width <= 0; an opacity outside [0, 1] (or NaN).
  void check(const std::string& where) const;
};

/// A depth map seen from a directional light: window depths in [0, 1] of an orthographic light
/// view-projection (GL conventions, glDepthRange(0, 1)); texel (x, y) covers window
/// [x, x + 1) x [y, y + 1) and is depth[y * size + x], row 0 at the bottom (glReadPixels
/// order); 1 = nothing nearer than the far plane.
struct ShadowBuffer {
  int size = 0;                      // texels per side
  Mat4 light_vp = Mat4::Identity();  // world -> clip, orthographic (last row 0 0 0 1)
  std::vector<float> depth;          // size * size

  float at(int x, int y) const {
    return depth[std::size_t(y) * std::size_t(size) + std::size_t(x)];
  }
  /// Edge of one texel in world units [m] (from the light_vp's x scale).
  double texel_world() const;
  /// Window-depth units per metre along the light (from the light_vp's z scale).
  double depth_per_metre() const;
  /// Throws follicle::Error, prefixed by `where`, for a size < 1, a depth array of the wrong
  /// size, a non-finite or non-orthographic light_vp.
  void check(const std::string& where) const;
};

/// Step (2): the casting strands' segments drawn into a Z-buffer seen from the light, each texel
/// keeping the smallest depth of the segments there. Conservative, so that a hair thinner than
/// a texel leaves no gaps: without radii, every texel the segment passes through (a grid walk,
/// Amanatides & Woo 1987) with the segment's nearest depth inside it; with radii, every texel
/// whose square meets the segment widened by its radius, with the depth of the segment's point
/// nearest the texel centre. Parallel over bands of rows; the result does not depend on the
/// thread count. Throws follicle::Error for bad hair (check()), a size outside [1, 16384] or a
/// light_vp that is not a finite orthographic projection.
ShadowBuffer rasterize_hair_depth(const Context& ctx, const HairSegments& hair,
                                  const Mat4& light_vp, int size);

/// rasterize_hair_depth() keeping its scratch memory (and reusing `out`'s) between calls: on
/// this kind of machine fresh pages cost as much as the drawing.
class HairDepthRasterizer {
 public:
  void rasterize(const Context& ctx, const HairSegments& hair, const Mat4& light_vp, int size,
                 ShadowBuffer& out);

 private:
  std::vector<float> m_win;  // per point: window x, y [texels], depth, half width [texels]
  std::vector<uint32_t> m_segs, m_start, m_items;
};

/// Step (3): the composite shadow buffer, per texel min(scene, hair). Throws follicle::Error
/// when the two buffers differ in size or projection.
ShadowBuffer compose_shadow_buffers(const Context& ctx, const ShadowBuffer& scene,
                                    const ShadowBuffer& hair);
/// The same in place: `scene` becomes the composite.
void compose_shadow_buffers_into(const Context& ctx, ShadowBuffer& scene, const ShadowBuffer& hair);

/// Percentage-closer filtering (Reeves, Salesin & Cook 1987) of `buf` at world point p: the
/// share of a box of (2 radius + 1) x (2 radius + 1) texels centred on p's projection (each
/// texel weighted by its overlap with the box, so the result is continuous in p) whose depth is
/// >= p's depth minus `bias` [m]. 1 outside the map or beyond its far plane. Texels outside
/// the map are clamped to its edge.
double shadow_pcf(const ShadowBuffer& buf, const Vec3& p, double bias, int radius);

/// One light of eq. (7).
struct HairLight {
  Vec3 to_light{0, 0, 1};                // unit direction towards the light
  Vec3 radiance{1, 1, 1};                // L_i: colour x intensity
  const ShadowBuffer* shadow = nullptr;  // composite buffer of this light; null: S_i = 1
};

enum class HairShadingMode {
  Daldegan1993,   // eq. (7)
  ShadowedColor,  // the given per-point colour c, times (k_a + (1 - k_a) S_key)
};

/// Coefficients of eq. (7) and of the shadow lookup. The colour channels: K_A = k_a c,
/// K_D = k_d c (c the hair colour), K_S = k_s (a white highlight), as the GL Kajiya-Kay pass.
struct HairShading {
  HairShadingMode mode = HairShadingMode::Daldegan1993;
  Vec3 ambient_light{1, 1, 1};     // L_A
  Vec3 color{0.25, 0.15, 0.08};    // c where there is no per-point colour
  double k_a = 0.15;               // ambient reflectance (K_A / c)
  double k_d = 0.8;                // diffuse (K_D / c)
  double k_s = 0.35;               // specular K_S
  double n = 40.0;                 // specular exponent
  double shadow_bias = 1.5;        // [shadow texels] constant bias of the lookup
  double shadow_slope_bias = 2.0;  // [shadow texels] x cot(angle of the hair to the light)
  int shadow_filter_radius = 1;    // PCF box of (2 r + 1)^2 texels
  int key_light = 0;               // ShadowedColor: the light whose S_i scales c; -1: none

  /// Throws follicle::Error, prefixed by `where`, for negative or non-finite coefficients, a
  /// filter radius outside [0, 16] or a key light < -1.
  void check(const std::string& where) const;
};

/// Eq. (7) at one point: H = L_A K_A + sum_i S_i L_i (K_D sin(theta_i) + K_S cos^n(theta_i +
/// phi - pi)), theta_i the angle between the tangent and the direction towards light i, phi the
/// angle between the tangent and the direction towards the eye (the Kajiya-Kay 1989 highlight
/// cone; the cosine is clamped at 0). `s` holds S_i per light (empty: all 1). Tangents need not
/// be unit; a zero tangent has no direction: only the ambient term is left.
Vec3 hair_intensity_daldegan1993(const Vec3& tangent, const Vec3& to_eye, const Vec3& color,
                                 const HairShading& sh, std::span<const HairLight> lights,
                                 std::span<const double> s = {});

/// The shadow bias [m] of a hair point with unit tangent t under a light (towards-light unit
/// direction l) whose buffer has texels of `texel` m: (shadow_bias + shadow_slope_bias *
/// min(cot, 8)) texels, cot = |t.l| / |t x l|, so that a hair does not shadow itself fully.
double hair_shadow_bias(const HairShading& sh, const Vec3& t, const Vec3& l, double texel);

/// Step (5), shading: out[i] for every point i of strands [strand_begin, strand_end), from the
/// tangent (central difference of the neighbours, like the GL strand pass) and S_i =
/// shadow_pcf() of each light's buffer with hair_shadow_bias(). Daldegan1993: eq. (7) with
/// c = point_color[i] (or sh.color when point_color is empty); ShadowedColor: point_color[i]
/// (required) times (k_a + (1 - k_a) S_key). `out` and `point_color` are indexed by point
/// (size hair.num_points(), or 0 for point_color). Parallel over strands. Throws
/// follicle::Error for mismatched sizes or bad coefficients.
void shade_hair_vertices(const Context& ctx, const HairSegments& hair, std::size_t strand_begin,
                         std::size_t strand_end, std::span<const Vec3f> point_color,
                         const HairShading& sh, std::span<const HairLight> lights, const Vec3& eye,
                         std::span<Vec3f> out);

/// The colour and depth buffers the hair is blended into: a window of a GL framebuffer, rows
/// bottom up (glReadPixels order). Pixel (x, y) of the window is framebuffer pixel
/// (x0 + x, y0 + y).
struct HairFrame {
  int fb_width = 0, fb_height = 0;            // full framebuffer (the viewport) [px]
  int x0 = 0, y0 = 0, width = 0, height = 0;  // the window (multiples of `samples`)
  float* rgba = nullptr;         // linear RGBA floats of the window, rows rgba_stride apart
  int rgba_stride = 0;           // pixels from one row to the next; 0: width
  const float* depth = nullptr;  // width * height window depths in [0, 1] (the scene Z)
  int samples = 1;               // k of a k-times supersampled framebuffer (see HairBlender)
};

/// Step (5), blending (LeBlanc et al. 1991 pixel blending). Each segment is an antialiased line
/// of width w framebuffer pixels (the strand's width_px, or 2 r times the pixels per metre at
/// its depth) whose alpha at a pixel is opacity x its coverage of the pixel: across the line,
/// the area of the pixel square inside the w-wide strip (exact, so thinner-than-a-pixel hair
/// gets about w x opacity and the coverage summed over pixels is w times the length at any
/// angle); along it, the overlap of a unit interval with the segment (a partition of unity
/// between the segments of a strand). Colour and depth are interpolated between the endpoints;
/// a pixel is drawn where the hair's depth is less than the scene's (GL_LESS; the hair writes
/// no depth). The result is the hair composited over the scene in depth order, as blending the
/// segments far to near with SRC_ALPHA, ONE_MINUS_SRC_ALPHA (alpha: ONE, ONE_MINUS_SRC_ALPHA)
/// would give; it is computed near to far with the "under" operator (same sum, rounding
/// aside) so that a pixel whose hair is opaque to within 1/4096 takes no further segments and
/// a segment over such pixels, or behind the scene there, is skipped whole (up to 1/4096 of a
/// hidden hair's colour is lost).
/// Depth order: the depth of the segment's midpoint; ties: the first in the input is in front.
/// In a k-times supersampled framebuffer (HairFrame::samples = k) the hair is drawn per block
/// of k x k pixels (a "cell", the output pixel): the analytic coverage of the cell is the mean
/// of its k^2 pixels' coverages, so the resolved image keeps the same antialiasing at 1/k^2 of
/// the work. A fragment nearer than all k^2 scene depths of its cell is drawn with its alpha,
/// one behind all of them not at all, one in between (an object's edge) with its alpha times
/// the share of the pixels it is in front of; the cell's hair is then composited over each of
/// its k^2 pixels. Rows of cells are split into bands of 16 drawn in parallel: the segments are
/// first copied band by band (in input order; a streaming pass), then every band sorts its own
/// (stable radix sort) and draws them, so the image does not depend on the thread count and no
/// band reads scattered memory. Segments are clipped at the near plane. prepare() projects and
/// bins; the scratch memory is kept between frames.
class HairBlender {
 public:
  /// Projects the segments with `view_proj` into a fb_width x fb_height framebuffer of k =
  /// `samples` supersampling (both sizes multiples of k) and bins them. Throws follicle::Error
  /// for bad hair or a bad framebuffer size / matrix.
  void prepare(const Context& ctx, const Mat4& view_proj, const HairSegments& hair, int fb_width,
               int fb_height, int samples = 1);
  /// The framebuffer pixels (x0, y0, x1, y1; half-open, multiples of k) the prepared segments
  /// can touch; all 0 when none is on screen.
  std::array<int, 4> bounds() const { return m_bounds; }
  /// Blends the prepared segments (`hair` must be the one given to prepare()) with one colour
  /// per point into `target`. Throws follicle::Error for a target that does not fit the
  /// prepared framebuffer, missing buffers or a colour array of the wrong size.
  void blend(const Context& ctx, const HairSegments& hair, std::span<const Vec3f> colors,
             const HairFrame& target);

  /// A point as the blend reads it.
  struct alignas(32) Point {
    float x, y, z;  // window position [cells] and depth
    float w_px;     // line width [cells]; < 0: behind the near plane
    float r, g, b;  // colour (set by blend())
    float alpha;    // the strand's opacity
  };
  /// A segment: its first point and band range.
  struct Segment {
    uint32_t point, bands;
  };
  /// A segment as a band draws it: window coordinates after clipping, half width, opacity and
  /// the colours at its ends (16-bit fractions of the frame's largest colour component).
  struct BandSegment {
    float ax, ay, az, bx, by, bz, hw, alpha;
    uint16_t ca[3], cb[3];
    uint32_t pad;
  };
  /// A band's draw order (one per thread, kept between frames).
  struct BandScratch {
    std::vector<uint64_t> order, tmp;  // (depth key << 32 | index in the band), near first
    std::vector<float> acc;            // the band's hair: premultiplied RGB, alpha per cell
    std::vector<float> zcell;          // per cell: nearest and farthest scene depth
    std::vector<int> open;             // per block of columns: cells not yet opaque
    std::vector<float> zmax;           // per block of columns: the farthest scene depth
  };

 private:
  Mat4 m_view_proj = Mat4::Identity();
  int m_fb_w = 0, m_fb_h = 0, m_k = 1;  // framebuffer and supersampling
  int m_cw = 0, m_ch = 0;               // cells
  const HairSegments* m_hair = nullptr;
  std::vector<Point> m_pts;              // per point
  std::vector<uint32_t> m_seg_base;      // per strand: its first segment
  std::vector<Segment> m_segs;           // per segment
  std::vector<uint32_t> m_band_start;    // per band of rows: its first entry in m_band_segs
  std::vector<BandSegment> m_band_segs;  // the segments of every band, in input order
  std::array<int, 4> m_bounds{0, 0, 0, 0};
  tbb::enumerable_thread_specific<BandScratch> m_scratch;
};

/// prepare() + blend() of a HairBlender for `target`'s framebuffer, for one-off use.
void blend_hair(const Context& ctx, const Mat4& view_proj, const HairSegments& hair,
                std::span<const Vec3f> colors, const HairFrame& target);

}  // namespace follicle::render
