// Hair rendering of Daldegan et al. 1993 §4 (hair_blend_daldegan1993.hpp): eq. (7) in analytic
// configurations, the hair Z-buffer seen from a light, the composite buffer, percentage-closer
// filtering, line coverage, the scene Z test, the blend order, thread-count independence, bad
// input; then the whole pipeline in the GL renderer (hair shadows on a plane, hair hidden by an
// opaque quad, the viewer path) and a golden image.
#define GL_GLEXT_PROTOTYPES 1  // glGenFramebuffers & co. for the viewer-path test
#include <GL/gl.h>
#include <GL/glext.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <vector>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/image/metrics.hpp"
#include "follicle/render/camera.hpp"
#include "follicle/render/hair_blend_daldegan1993.hpp"
#include "render_test_util.hpp"

using namespace follicle;
using namespace follicle::render;
using namespace follicle::render::testutil;

namespace {

HairShading plain(double ka, double kd, double ks, double n = 10) {
  HairShading sh;
  sh.k_a = ka;
  sh.k_d = kd;
  sh.k_s = ks;
  sh.n = n;
  sh.ambient_light = Vec3(1, 1, 1);
  return sh;
}

HairLight light(const Vec3& to_light, double intensity = 1.0) {
  HairLight l;
  l.to_light = to_light.normalized();
  l.radiance = Vec3::Constant(intensity);
  return l;
}

/// Orthographic "light" over world x, y in [-1, 1]; window depth = (1 - z) / 2 (so nearer the
/// light = larger z). Texel (i, j) centre at world x = -1 + (i + 1/2) 2/size.
Mat4 ortho_light() {
  Mat4 m = Mat4::Identity();
  m(2, 2) = -1;
  return m;
}

ShadowBuffer flat_buffer(int size, float depth) {
  ShadowBuffer b;
  b.size = size;
  b.light_vp = ortho_light();
  b.depth.assign(std::size_t(size) * std::size_t(size), depth);
  return b;
}

/// A framebuffer of colour `bg` and scene depth `depth`.
struct Frame {
  int w, h;
  std::vector<float> rgba, depth;
  Frame(int w_, int h_, float d = 1.0f, Vec4 bg = Vec4(0, 0, 0, 1))
      : w(w_), h(h_), rgba(4 * std::size_t(w_) * std::size_t(h_)), depth(std::size_t(w_) * h_, d) {
    for (std::size_t i = 0; i < depth.size(); ++i)
      for (int c = 0; c < 4; ++c) rgba[4 * i + std::size_t(c)] = float(bg[c]);
  }
  HairFrame target() {
    HairFrame t;
    t.fb_width = t.width = w;
    t.fb_height = t.height = h;
    t.rgba = rgba.data();
    t.depth = depth.data();
    return t;
  }
  double sum(int c) const {
    double s = 0;
    for (std::size_t i = 0; i < depth.size(); ++i) s += rgba[4 * i + std::size_t(c)];
    return s;
  }
};

/// World = window for a w x h framebuffer: x in [0, w] -> window x, y likewise, depth (1 - z)/2
/// (orthographic).
Mat4 pixel_camera(int w, int h) {
  Mat4 m = Mat4::Identity();
  m(0, 0) = 2.0 / w;
  m(0, 3) = -1;
  m(1, 1) = 2.0 / h;
  m(1, 3) = -1;
  m(2, 2) = -1;
  return m;
}

std::vector<Vec3f> colours(const HairSegments& h, const Vec3f& c) {
  return std::vector<Vec3f>(h.num_points(), c);
}

/// n random strands of `pts` points in the unit box (a messy tangle), seed-determined.
HairSegments random_hair(int n, int pts, uint64_t seed, float width = 1.0f) {
  Rng rng(seed);
  HairSegments h;
  for (int s = 0; s < n; ++s) {
    std::vector<Vec3f> p;
    Vec3f x(float(rng.uniform(-0.8, 0.8)), float(rng.uniform(-0.8, 0.8)),
            float(rng.uniform(-0.5, 0.5)));
    const Vec3f d(float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)));
    for (int i = 0; i < pts; ++i) {
      p.push_back(x);
      x += 0.05f * d + Vec3f(float(rng.uniform(-0.01, 0.01)), float(rng.uniform(-0.01, 0.01)),
                             float(rng.uniform(-0.01, 0.01)));
    }
    h.add_strand(p, width, float(rng.uniform(0.3, 1.0)), s % 3 != 0);
  }
  return h;
}

}  // namespace

// ---- eq. (7)
// --------------------------------------------------------------------------------------

TEST(DaldeganShading, TangentPerpendicularToLightGivesFullDiffuse) {
  const Vec3 c(0.5, 0.3, 0.2);
  const HairLight l = light(Vec3(0, 1, 0), 2.0);
  // sin(theta) = 1; no ambient, no specular: H = L K_D c.
  const Vec3 h = hair_intensity_daldegan1993(Vec3(1, 0, 0), Vec3(0, 0, 1), c, plain(0, 0.8, 0),
                                             std::span(&l, 1));
  EXPECT_NEAR(h.x(), 2.0 * 0.8 * 0.5, 1e-12);
  EXPECT_NEAR(h.y(), 2.0 * 0.8 * 0.3, 1e-12);
  EXPECT_NEAR(h.z(), 2.0 * 0.8 * 0.2, 1e-12);
  // At 30 degrees the diffuse term is sin(30 deg) = 1/2 of that.
  const Vec3 h30 = hair_intensity_daldegan1993(Vec3(1, std::sqrt(3.0), 0), Vec3(0, 0, 1), c,
                                               plain(0, 0.8, 0), std::span(&l, 1));
  EXPECT_NEAR(h30.x(), 0.5 * h.x(), 1e-12);
}

TEST(DaldeganShading, TangentParallelToLightGivesNoDiffuse) {
  const HairLight l = light(Vec3(0, 1, 0));
  // theta = 0: sin = 0; the eye at right angles to the hair: cos(theta + phi - pi) = 0.
  const Vec3 h = hair_intensity_daldegan1993(Vec3(0, 3, 0), Vec3(0, 0, 5), Vec3(1, 1, 1),
                                             plain(0, 0.8, 0.5), std::span(&l, 1));
  EXPECT_NEAR(h.norm(), 0.0, 1e-12);
  // ... and the tangent's sign does not matter.
  const Vec3 g = hair_intensity_daldegan1993(Vec3(0, -1, 0), Vec3(0, 0, 5), Vec3(1, 1, 1),
                                             plain(0, 0.8, 0.5), std::span(&l, 1));
  EXPECT_NEAR(g.norm(), 0.0, 1e-12);
}

TEST(DaldeganShading, SpecularPeaksOnTheKajiyaKayCone) {
  // Light at theta = 60 deg from the tangent x; the eye on the mirror cone (phi = 180 - 60 deg):
  // cos(theta + phi - pi) = 1, the full K_S.
  const double th = kPi / 3;
  const HairLight l = light(Vec3(std::cos(th), std::sin(th), 0));
  const Vec3 eye(-std::cos(th), 0, std::sin(th));
  const Vec3 c(0.4, 0.4, 0.4);
  const Vec3 h =
      hair_intensity_daldegan1993(Vec3(1, 0, 0), eye, c, plain(0, 0.5, 0.3, 25), std::span(&l, 1));
  EXPECT_NEAR(h.x(), 0.5 * std::sin(th) * 0.4 + 0.3, 1e-12);
  // Off the cone by 30 deg: cos^25(30 deg).
  const double off = kPi / 6;
  const Vec3 eye2(-std::cos(th - off), 0, std::sin(th - off));
  const Vec3 h2 =
      hair_intensity_daldegan1993(Vec3(1, 0, 0), eye2, c, plain(0, 0.5, 0.3, 25), std::span(&l, 1));
  EXPECT_NEAR(h2.x(), 0.5 * std::sin(th) * 0.4 + 0.3 * std::pow(std::cos(off), 25), 1e-12);
  // The eye on the light's side of the cone (phi = theta): cos(2 theta - pi) = -cos(2 theta)
  // = 1/2 at 60 deg.
  const Vec3 h3 = hair_intensity_daldegan1993(Vec3(1, 0, 0), Vec3(std::cos(th), 0, std::sin(th)), c,
                                              plain(0, 0.5, 0.3, 2), std::span(&l, 1));
  EXPECT_NEAR(h3.x(), 0.5 * std::sin(th) * 0.4 + 0.3 * 0.25, 1e-12);
}

TEST(DaldeganShading, AmbientAndShadowingCoefficients) {
  HairShading sh = plain(0.2, 0.8, 0.0);
  sh.ambient_light = Vec3(0.5, 1.0, 2.0);
  const Vec3 c(0.5, 0.5, 0.5);
  // No lights: L_A K_A only.
  const Vec3 a = hair_intensity_daldegan1993(Vec3(1, 0, 0), Vec3(0, 0, 1), c, sh, {});
  EXPECT_NEAR(a.x(), 0.5 * 0.2 * 0.5, 1e-12);
  EXPECT_NEAR(a.z(), 2.0 * 0.2 * 0.5, 1e-12);
  // Two lights, S = (1/2, 0): only half the first light's term is added.
  const HairLight ls[2] = {light(Vec3(0, 1, 0)), light(Vec3(0, 0, 1), 3.0)};
  const double s[2] = {0.5, 0.0};
  const Vec3 h = hair_intensity_daldegan1993(Vec3(1, 0, 0), Vec3(0, 0, 1), c, sh, ls, s);
  EXPECT_NEAR(h.x(), a.x() + 0.5 * 0.8 * 0.5, 1e-12);
  // S = 1 for both: the second light (also at right angles to the hair) adds 3 times as much.
  const Vec3 full = hair_intensity_daldegan1993(Vec3(1, 0, 0), Vec3(0, 0, 1), c, sh, ls);
  EXPECT_NEAR(full.x(), a.x() + 4 * 0.8 * 0.5, 1e-12);
}

TEST(DaldeganShading, ShadowBiasGrowsWithTheSlope) {
  HairShading sh;
  sh.shadow_bias = 1.5;
  sh.shadow_slope_bias = 2.0;
  // Hair across the light: no slope.
  EXPECT_NEAR(hair_shadow_bias(sh, Vec3(1, 0, 0), Vec3(0, 1, 0), 0.01), 0.015, 1e-15);
  // 45 degrees: cot = 1.
  EXPECT_NEAR(hair_shadow_bias(sh, Vec3(1, 1, 0), Vec3(0, 1, 0), 0.01), 0.035, 1e-12);
  // Along the light: clamped at cot = 8.
  EXPECT_NEAR(hair_shadow_bias(sh, Vec3(0, 1, 0), Vec3(0, 1, 0), 0.01), 0.175, 1e-12);
}

// ---- shadow buffers
// ------------------------------------------------------------------------------

TEST(DaldeganShadow, HorizontalHairDrawsALineIntoTheCompositeBuffer) {
  const Context ctx(2, 1);
  // A plane at z = 0 (window depth 1/2) everywhere; a hair along x at y = 0.1, z = 0.4 (window
  // depth 0.3) from x = -0.5 to 0.5.
  const int n = 64;
  const ShadowBuffer plane = flat_buffer(n, 0.5f);
  HairSegments hair;
  const std::vector<Vec3f> pts = {Vec3f(-0.5f, 0.1f, 0.4f), Vec3f(0.0f, 0.1f, 0.4f),
                                  Vec3f(0.5f, 0.1f, 0.4f)};
  hair.add_strand(pts);
  const ShadowBuffer hb = rasterize_hair_depth(ctx, hair, ortho_light(), n);
  const ShadowBuffer comp = compose_shadow_buffers(ctx, plane, hb);
  // y = 0.1 is window y 35.2: the line crosses the squares of texel row 35 only; x from -0.5
  // to 0.5 is window x 16 to 48.
  const int row = 35;
  for (int x = 17; x < 47; ++x) {
    EXPECT_FLOAT_EQ(hb.at(x, row), 0.3f) << x;
    EXPECT_FLOAT_EQ(comp.at(x, row), 0.3f) << x;
  }
  EXPECT_FLOAT_EQ(comp.at(32, row - 2), 0.5f);  // the plane beside it
  EXPECT_FLOAT_EQ(comp.at(32, row + 2), 0.5f);
  EXPECT_FLOAT_EQ(hb.at(32, row + 2), 1.0f);  // nothing there
  EXPECT_FLOAT_EQ(comp.at(5, row), 0.5f);     // beyond the hair's end
  // The composite is the per-texel minimum: a plane nearer than the hair hides it.
  const ShadowBuffer near_plane = flat_buffer(n, 0.1f);
  const ShadowBuffer c2 = compose_shadow_buffers(ctx, near_plane, hb);
  EXPECT_FLOAT_EQ(c2.at(32, row), 0.1f);
  // A plane point under the hair (z = 0) is in shadow, one far from it is lit.
  EXPECT_LT(shadow_pcf(comp, Vec3(0.0, 0.1, 0.0), 0.01, 0), 0.5);
  EXPECT_EQ(shadow_pcf(comp, Vec3(0.0, -0.5, 0.0), 0.01, 1), 1.0);
  // ... and the hair itself, at its own depth with a small bias, is lit.
  EXPECT_EQ(shadow_pcf(comp, Vec3(0.0, 0.1, 0.4), 0.01, 1), 1.0);
}

TEST(DaldeganShadow, ThinDiagonalHairLeavesNoGaps) {
  const Context ctx(1, 1);
  const int n = 128;
  HairSegments hair;
  // z varies along the hair: depth (1 - z) / 2 from 0.45 to 0.25.
  const Vec3f a(-0.71f, -0.43f, 0.1f), b(0.66f, 0.52f, 0.5f);
  const std::vector<Vec3f> pts = {a, b};
  hair.add_strand(pts);
  const ShadowBuffer hb = rasterize_hair_depth(ctx, hair, ortho_light(), n);
  // Every texel the segment passes through (dense sampling) is written, with the depth of the
  // hair there (within the depth change across one texel).
  for (int k = 0; k <= 4000; ++k) {
    const float t = float(k) / 4000;
    const Vec3f p = a + t * (b - a);
    const int i = int((p.x() * 0.5f + 0.5f) * n), j = int((p.y() * 0.5f + 0.5f) * n);
    const float z = (1 - p.z()) / 2;
    EXPECT_NEAR(hb.at(i, j), z, 0.004) << i << " " << j;
  }
  // and the line is thin: about one to two texels per column, nothing far from it.
  int written = 0;
  for (float d : hb.depth) written += d < 1.0f;
  const double cols = (b.x() - a.x()) / 2 * n;
  EXPECT_LT(written, 2.6 * cols);
  EXPECT_GT(written, 1.0 * cols);
}

TEST(DaldeganShadow, PcfIsStrictlyBetweenZeroAndOneAtAnEdge) {
  // Left half occluded (depth 0.2), right half open (1).
  const int n = 32;
  ShadowBuffer b = flat_buffer(n, 1.0f);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n / 2; ++x) b.depth[std::size_t(y) * n + std::size_t(x)] = 0.2f;
  // Receiver at depth 0.5 (z = 0). The edge is at world x = 0.
  double prev = -1;
  for (int k = -40; k <= 40; ++k) {
    const double x = k * 0.25 * 2.0 / n;  // quarter-texel steps
    const double s = shadow_pcf(b, Vec3(x, 0, 0), 0.0, 1);
    EXPECT_GE(s, prev - 1e-12) << "monotone across the edge";
    prev = s;
    if (std::abs(x) < 1.5 * 2.0 / n) {
      EXPECT_GT(s, 0.0) << x;
      EXPECT_LT(s, 1.0) << x;
    }
    if (x < -1.6 * 2.0 / n) {
      EXPECT_EQ(s, 0.0) << x;
    }
    if (x > 1.6 * 2.0 / n) {
      EXPECT_EQ(s, 1.0) << x;
    }
  }
  EXPECT_NEAR(shadow_pcf(b, Vec3(0, 0, 0), 0.0, 1), 0.5, 1e-12);
  EXPECT_NEAR(shadow_pcf(b, Vec3(0, 0, 0), 0.0, 0), 0.5, 1e-12);
  // Outside the map: lit.
  EXPECT_EQ(shadow_pcf(b, Vec3(-1.5, 0, 0), 0.0, 1), 1.0);
  // A receiver nearer the light than the occluder (z = 0.8: depth 0.1) is lit.
  EXPECT_EQ(shadow_pcf(b, Vec3(-0.5, 0, 0.8), 0.0, 1), 1.0);
  // The bias (world metres; 1/2 window depth per metre here) lets a receiver just behind the
  // occluder count as lit: depth 0.22 - 0.05 < 0.2.
  EXPECT_EQ(shadow_pcf(b, Vec3(-0.5, 0, 0.56), 0.0, 1), 0.0);
  EXPECT_EQ(shadow_pcf(b, Vec3(-0.5, 0, 0.56), 0.1, 1), 1.0);
}

TEST(DaldeganShadow, ShadowedColourShadingDarkensTheLowerHair) {
  // Anjyo-style colours kept, times (k_a + (1 - k_a) S): two hairs along x, one above the other
  // under a light from +z.
  const Context ctx(2, 1);
  // A layer of 9 hairs 0.02 apart at z = 0.5 over one hair at z = 0, wider and longer than it
  // by more than the filter box.
  HairSegments hair;
  for (int i = 0; i < 9; ++i) {
    const float y = -0.08f + 0.02f * float(i);
    const std::vector<Vec3f> top = {Vec3f(-0.6f, y, 0.5f), Vec3f(0.6f, y, 0.5f)};
    hair.add_strand(top);
  }
  const std::vector<Vec3f> low = {Vec3f(-0.3f, 0, 0.0f), Vec3f(0.3f, 0, 0.0f)};
  hair.add_strand(low);
  const ShadowBuffer hb = rasterize_hair_depth(ctx, hair, ortho_light(), 64);
  const ShadowBuffer comp = compose_shadow_buffers(ctx, flat_buffer(64, 1.0f), hb);
  HairLight l = light(Vec3(0, 0, 1));
  l.shadow = &comp;
  HairShading sh;
  sh.mode = HairShadingMode::ShadowedColor;
  sh.k_a = 0.2;
  sh.key_light = 0;
  const std::vector<Vec3f> c(20, Vec3f(0.6f, 0.4f, 0.2f));
  std::vector<Vec3f> out(20);
  shade_hair_vertices(ctx, hair, 0, 10, c, sh, std::span(&l, 1), Vec3(0, -3, 1), out);
  EXPECT_NEAR(out[8].x(), 0.6f, 1e-6);  // top: lit, colour kept
  EXPECT_NEAR(out[9].y(), 0.4f, 1e-6);
  EXPECT_NEAR(out[18].x(), 0.12f, 1e-6);  // lower: in the top layer's shadow, ambient part only
  EXPECT_NEAR(out[19].z(), 0.04f, 1e-6);
  // Eq. (7) on the same hair: the lower hair keeps only L_A K_A.
  HairShading d = plain(0.1, 0.8, 0.3);
  d.color = Vec3(0.5, 0.5, 0.5);
  shade_hair_vertices(ctx, hair, 0, 10, {}, d, std::span(&l, 1), Vec3(0, -3, 1), out);
  EXPECT_NEAR(out[18].x(), 0.05f, 1e-6);
  EXPECT_GT(out[8].x(), 0.05f + 0.8f * 0.5f - 1e-5f);  // sin(theta) = 1 for the top ones
}

TEST(DaldeganShadow, VertexShadingIsEq7WithFilteredShadows) {
  // shade_hair_vertices() against the per-point functions it is made of.
  const Context ctx(2, 1);
  const HairSegments hair = random_hair(300, 10, 3);
  const ShadowBuffer hb = rasterize_hair_depth(ctx, hair, ortho_light(), 128);
  Mat4 tilted = ortho_light();
  tilted.topLeftCorner<3, 3>() =
      0.7 * Eigen::AngleAxisd(0.4, Vec3(1, 0.5, 0).normalized()).toRotationMatrix();
  const ShadowBuffer hb2 = rasterize_hair_depth(ctx, hair, tilted, 96);
  HairLight ls[2] = {light(Vec3(0.2, -0.1, 1), 0.9), light(Vec3(-0.3, 0.8, 0.4), 0.5)};
  ls[0].shadow = &hb;
  ls[1].shadow = &hb2;
  ls[1].radiance = Vec3(0.5, 0.4, 0.3);
  HairShading sh = plain(0.12, 0.7, 0.4, 33);
  sh.ambient_light = Vec3(0.3, 0.3, 0.35);
  sh.shadow_filter_radius = 2;
  std::vector<Vec3f> c(hair.num_points());
  for (std::size_t i = 0; i < c.size(); ++i)
    c[i] = Vec3f(0.2f + 0.001f * float(i % 300), 0.3f, 0.1f);
  const Vec3 eye(0.3, -0.2, 4);
  std::vector<Vec3f> out(hair.num_points());
  shade_hair_vertices(ctx, hair, 0, hair.num_strands(), c, sh, ls, eye, out);
  int partial = 0;
  for (std::size_t st = 0; st < hair.num_strands(); ++st) {
    const uint32_t b = hair.offsets[st], e = hair.offsets[st + 1];
    for (uint32_t i = b; i < e; ++i) {
      const Vec3 t =
          (hair.points[std::min(i + 1, e - 1)] - hair.points[i > b ? i - 1 : b]).cast<double>();
      const Vec3 p = hair.points[i].cast<double>();
      double s[2];
      for (int l = 0; l < 2; ++l) {
        const double bias = hair_shadow_bias(sh, t, ls[l].to_light, ls[l].shadow->texel_world());
        s[l] = shadow_pcf(*ls[l].shadow, p, bias, 2);
        partial += s[l] > 0 && s[l] < 1;
      }
      const Vec3 h = hair_intensity_daldegan1993(t, eye - p, c[i].cast<double>(), sh, ls, s);
      ASSERT_NEAR(out[i].x(), h.x(), 1e-5 * (1 + h.x())) << i;
      ASSERT_NEAR(out[i].z(), h.z(), 1e-5 * (1 + h.z())) << i;
    }
  }
  EXPECT_GT(partial, 100);  // the comparison covers filtered shadow edges
}

// ---- blending
// ------------------------------------------------------------------------------------

TEST(DaldeganBlend, CoverageOfAQuarterPixelLineIntegratesToWidthTimesLength) {
  const Context ctx(2, 1);
  for (const double ang : {0.0, 0.3, kPi / 4, 1.1, kPi / 2, 2.5}) {
    Frame f(160, 160);
    HairSegments h;
    const double len = 100;
    const Vec3f c(80.3f, 80.6f, 0);
    const Vec3f d = Vec3f(float(std::cos(ang)), float(std::sin(ang)), 0) * float(len / 2);
    const std::vector<Vec3f> pts = {c - d, c + d};
    h.add_strand(pts, 0.25f, 1.0f);
    blend_hair(ctx, pixel_camera(f.w, f.h), h, colours(h, Vec3f(1, 1, 1)), f.target());
    EXPECT_NEAR(f.sum(0), 0.25 * len, 0.01 * 0.25 * len) << ang;
    EXPECT_NEAR(f.sum(3), f.depth.size() * 1.0, 1e-3);  // alpha stays 1 over an opaque frame
    // the same hair as a 7-segment polyline covers the same (joints overlap only slightly)
    Frame g(160, 160);
    HairSegments p;
    std::vector<Vec3f> q;
    for (int i = 0; i <= 7; ++i) q.push_back(c - d + (2.0f * float(i) / 7) * d);
    p.add_strand(q, 0.25f, 1.0f);
    blend_hair(ctx, pixel_camera(g.w, g.h), p, colours(p, Vec3f(1, 1, 1)), g.target());
    EXPECT_NEAR(g.sum(0), 0.25 * len, 0.02 * 0.25 * len) << ang;
    // The alpha of a pixel is its area inside the line: the width where the line runs along
    // the pixel grid, up to width x sqrt(2) (the pixel's diagonal) at 45 degrees.
    double peak = 0;
    for (std::size_t i = 0; i < f.depth.size(); ++i) peak = std::max(peak, double(f.rgba[4 * i]));
    const double chord = 1 / std::max(std::abs(std::cos(ang)), std::abs(std::sin(ang)));
    EXPECT_LE(peak, 0.25 * chord + 1e-5) << ang;
    EXPECT_GT(peak, 0.2) << ang;
    if (chord < 1 + 1e-9) {
      EXPECT_NEAR(peak, 0.25, 1e-6) << ang;
    }
  }
  // Wider than a pixel: width times length too, and opaque in the middle.
  Frame f(160, 160);
  HairSegments h;
  const std::vector<Vec3f> pts = {Vec3f(30.2f, 40.7f, 0), Vec3f(120.9f, 110.1f, 0)};
  h.add_strand(pts, 3.0f, 0.5f);
  blend_hair(ctx, pixel_camera(f.w, f.h), h, colours(h, Vec3f(1, 1, 1)), f.target());
  const double len = (pts[1] - pts[0]).norm();
  EXPECT_NEAR(f.sum(0), 0.5 * 3.0 * len, 0.01 * 1.5 * len);
}

TEST(DaldeganBlend, HairBehindTheSceneIsInvisible) {
  const Context ctx(2, 1);
  const HairSegments hair = random_hair(200, 12, 7, 2.0f);
  Mat4 vp = Mat4::Identity();  // world x, y in [-1, 1] fill the frame
  vp(2, 2) = 0.1;              // depth (1 + 0.1 z) / 2: in [0.44, 0.56] for this hair
  // An opaque quad nearer than all the hair (depth 0.3) covers the frame: nothing changes.
  Frame f(96, 80, 0.3f, Vec4(0.2, 0.4, 0.6, 1));
  const std::vector<float> before = f.rgba;
  blend_hair(ctx, vp, hair, colours(hair, Vec3f(1, 0, 0)), f.target());
  EXPECT_EQ(f.rgba, before);
  // Behind it (depth 0.9) the hair shows.
  Frame g(96, 80, 0.9f, Vec4(0.2, 0.4, 0.6, 1));
  blend_hair(ctx, vp, hair, colours(hair, Vec3f(1, 0, 0)), g.target());
  EXPECT_GT(g.sum(0), Frame(96, 80, 0.9f, Vec4(0.2, 0.4, 0.6, 1)).sum(0) + 50);
  // Half the frame (x < 48) covered by the quad: no pixel there changes.
  Frame q(96, 80, 0.9f, Vec4(0.2, 0.4, 0.6, 1));
  for (int y = 0; y < 80; ++y)
    for (int x = 0; x < 48; ++x) q.depth[std::size_t(y) * 96 + std::size_t(x)] = 0.3f;
  const std::vector<float> qb = q.rgba;
  blend_hair(ctx, vp, hair, colours(hair, Vec3f(1, 0, 0)), q.target());
  int changed_left = 0, changed_right = 0;
  for (int y = 0; y < 80; ++y)
    for (int x = 0; x < 96; ++x) {
      const std::size_t i = 4 * (std::size_t(y) * 96 + std::size_t(x));
      (x < 48 ? changed_left : changed_right) += q.rgba[i] != qb[i];
    }
  EXPECT_EQ(changed_left, 0);
  EXPECT_GT(changed_right, 200);
}

TEST(DaldeganBlend, NearerHairIsInFrontWhateverTheInputOrder) {
  const Context ctx(2, 1);
  for (int order = 0; order < 2; ++order) {
    Frame f(40, 40);
    HairSegments h;
    // Two wide opaque hairs crossing at the centre: red nearer (z = 0.5), blue farther.
    const std::vector<Vec3f> red = {Vec3f(5, 20, 0.5f), Vec3f(35, 20, 0.5f)};
    const std::vector<Vec3f> blue = {Vec3f(20, 5, -0.5f), Vec3f(20, 35, -0.5f)};
    if (order == 0) {
      h.add_strand(red, 4.0f);
      h.add_strand(blue, 4.0f);
    } else {
      h.add_strand(blue, 4.0f);
      h.add_strand(red, 4.0f);
    }
    std::vector<Vec3f> c(4);
    const bool red_first = order == 0;
    for (int i = 0; i < 4; ++i)
      c[std::size_t(i)] = (i < 2) == red_first ? Vec3f(1, 0, 0) : Vec3f(0, 0, 1);
    blend_hair(ctx, pixel_camera(f.w, f.h), h, c, f.target());
    const float* px = f.rgba.data() + 4 * (20 * 40 + 20);
    EXPECT_FLOAT_EQ(px[0], 1.0f) << order;
    EXPECT_FLOAT_EQ(px[2], 0.0f) << order;
  }
}

TEST(DaldeganBlend, NearPlaneClipsAndPerspectiveWidthsFollowTheRadius) {
  const Context ctx(1, 1);
  Camera cam;
  cam.eye = Vec3(0, 0, 2);
  cam.target = Vec3(0, 0, 0);
  cam.fov_y = 0.8;
  cam.z_near = 0.1;
  const Mat4 vp = projection_matrix(cam, 1.0) * view_matrix(cam);
  // A hair from behind the camera to the far side of the origin, tilted so it is seen.
  HairSegments h;
  const std::vector<Vec3f> pts = {Vec3f(0.05f, -0.2f, 3.0f), Vec3f(0.05f, 0.2f, -1.0f)};
  h.add_strand(pts, 1.5f);
  Frame f(64, 64);
  blend_hair(ctx, vp, h, colours(h, Vec3f(1, 1, 1)), f.target());
  for (float v : f.rgba) ASSERT_TRUE(std::isfinite(v));
  EXPECT_GT(f.sum(0), 10.0);
  // With radii, the line's width is 2 r in pixels at its depth: a hair across the view at the
  // origin (distance 2) covers 2 r * (64 / 2) / tan(0.4) / 2 pixels per pixel of length.
  HairSegments w;
  const std::vector<Vec3f> across = {Vec3f(-0.5f, 0.01f, 0), Vec3f(0.5f, 0.01f, 0)};
  w.add_strand(across);
  w.radius.assign(2, 0.01f);
  Frame g(64, 64);
  blend_hair(ctx, vp, w, colours(w, Vec3f(1, 1, 1)), g.target());
  const double px_per_m = 32 / std::tan(0.4) / 2;
  EXPECT_NEAR(g.sum(0), 0.02 * px_per_m * 1.0 * px_per_m, 0.02 * 0.02 * px_per_m * px_per_m);
}

TEST(DaldeganBlend, SameResultForOneAndTwoThreads) {
  const Context one(1, 1), two(2, 1);
  const HairSegments hair = random_hair(3000, 16, 11, 1.3f);
  Mat4 vp = Mat4::Identity();
  vp(2, 2) = 0.5;
  // Depth maps.
  const ShadowBuffer h1 = rasterize_hair_depth(one, hair, ortho_light(), 256);
  const ShadowBuffer h2 = rasterize_hair_depth(two, hair, ortho_light(), 256);
  EXPECT_EQ(h1.depth, h2.depth);
  // Shading.
  HairLight l = light(Vec3(0.3, 0.2, 1));
  l.shadow = &h1;
  std::vector<Vec3f> c1(hair.num_points()), c2(hair.num_points());
  shade_hair_vertices(one, hair, 0, hair.num_strands(), {}, HairShading{}, std::span(&l, 1),
                      Vec3(0, 0, 5), c1);
  shade_hair_vertices(two, hair, 0, hair.num_strands(), {}, HairShading{}, std::span(&l, 1),
                      Vec3(0, 0, 5), c2);
  EXPECT_EQ(c1, c2);
  // Blend into a window of the framebuffer.
  Frame f1(200, 150, 0.8f, Vec4(0.1, 0.1, 0.1, 1)), f2(200, 150, 0.8f, Vec4(0.1, 0.1, 0.1, 1));
  for (int y = 0; y < 150; ++y)
    for (int x = 0; x < 200; ++x)
      f1.depth[std::size_t(y) * 200 + x] = f2.depth[std::size_t(y) * 200 + x] =
          0.45f + 0.1f * float((x * 7 + y * 13) % 17) / 17;
  blend_hair(one, vp, hair, c1, f1.target());
  blend_hair(two, vp, hair, c2, f2.target());
  EXPECT_EQ(f1.rgba, f2.rgba);
  // A window read back around the hair gives the same pixels as the full frame.
  HairBlender b;
  b.prepare(two, vp, hair, 200, 150);
  const auto box = b.bounds();
  ASSERT_LT(box[0], box[2]);
  Frame f3(200, 150, 0.8f, Vec4(0.1, 0.1, 0.1, 1));
  f3.depth = f1.depth;
  HairFrame t = f3.target();
  t.x0 = box[0];
  t.y0 = box[1];
  t.width = box[2] - box[0];
  t.height = box[3] - box[1];
  t.rgba = f3.rgba.data() + 4 * (std::size_t(t.y0) * 200 + std::size_t(t.x0));
  t.rgba_stride = 200;
  std::vector<float> wd;
  for (int y = t.y0; y < t.y0 + t.height; ++y)
    for (int x = t.x0; x < t.x0 + t.width; ++x) wd.push_back(f1.depth[std::size_t(y) * 200 + x]);
  t.depth = wd.data();
  b.blend(two, hair, c2, t);
  EXPECT_EQ(f3.rgba, f1.rgba);
}

TEST(DaldeganBlend, SupersampledFramebufferIsDrawnPerCell) {
  // A k = 2 framebuffer gets, in each of a cell's four pixels, what a k = 1 framebuffer of
  // half the size gets in the cell's pixel (same projection, widths in framebuffer pixels).
  const Context ctx(2, 1);
  HairSegments one = random_hair(400, 12, 5, 1.5f), two = one;
  for (float& w : two.width_px) w *= 2;
  Mat4 vp = Mat4::Identity();
  vp(2, 2) = 0.5;
  Frame f1(60, 40, 0.8f, Vec4(0.1, 0.2, 0.3, 1)), f2(120, 80, 0.8f, Vec4(0.1, 0.2, 0.3, 1));
  blend_hair(ctx, vp, one, colours(one, Vec3f(0.9f, 0.6f, 0.3f)), f1.target());
  HairFrame t2 = f2.target();
  t2.samples = 2;
  blend_hair(ctx, vp, two, colours(two, Vec3f(0.9f, 0.6f, 0.3f)), t2);
  double worst = 0;
  for (int y = 0; y < 80; ++y)
    for (int x = 0; x < 120; ++x)
      for (int c = 0; c < 4; ++c)
        worst = std::max(worst, std::abs(double(f2.rgba[4 * (std::size_t(y) * 120 + x) + c]) -
                                         f1.rgba[4 * (std::size_t(y / 2) * 60 + x / 2) + c]));
  EXPECT_LT(worst, 1e-5);
  EXPECT_GT(f1.sum(0), Frame(60, 40, 0.8f, Vec4(0.1, 0.2, 0.3, 1)).sum(0) + 50);
  // An object's edge inside a cell: the hair is in front of two of its four pixels and gets
  // half its alpha there.
  HairSegments h;
  const std::vector<Vec3f> pts = {Vec3f(2, 10.5f, 0), Vec3f(38, 10.5f, 0)};
  h.add_strand(pts, 4.0f);  // 2 cells wide, opaque: alpha 1 on the cells of rows 4 and 5
  Frame e(40, 20, 1.0f, Vec4(0, 0, 0, 1));
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 40; ++x)
      if (x % 2 == 1) e.depth[std::size_t(y) * 40 + x] = 0.2f;  // the hair's 0.5 is behind
  HairFrame te = e.target();
  te.samples = 2;
  blend_hair(ctx, pixel_camera(40, 20), h, colours(h, Vec3f(1, 1, 1)), te);
  EXPECT_NEAR(e.rgba[4 * (10 * 40 + 20)], 0.5, 1e-6);
  EXPECT_NEAR(e.rgba[4 * (10 * 40 + 21)], 0.5, 1e-6);  // composited over all of the cell
  // Bad supersampling: not dividing the framebuffer, or a window off the cell grid.
  HairBlender b;
  EXPECT_THROW(b.prepare(ctx, vp, h, 41, 20, 2), Error);
  b.prepare(ctx, vp, h, 40, 20, 2);
  HairFrame off = te;
  off.x0 = 1;
  off.width = 38;
  EXPECT_THROW(b.blend(ctx, h, colours(h, Vec3f(1, 1, 1)), off), Error);
}

TEST(DaldeganBlend, BadInputIsAClearError) {
  const Context ctx(1, 1);
  HairSegments h;
  const std::vector<Vec3f> pts = {Vec3f(0, 0, 0), Vec3f(1, 0, 0)};
  h.add_strand(pts);
  Frame f(8, 8);
  const auto msg = [](auto&& fn) {
    try {
      fn();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // NaN point
  HairSegments bad = h;
  bad.points[1].y() = std::nanf("");
  EXPECT_NE(msg([&] { rasterize_hair_depth(ctx, bad, ortho_light(), 16); }).find("point 1"),
            std::string::npos);
  EXPECT_NE(msg([&] {
              blend_hair(ctx, pixel_camera(8, 8), bad, colours(bad, Vec3f(1, 1, 1)), f.target());
            }).find("not finite"),
            std::string::npos);
  // A negative radius other than kNoRadius is refused; kNoRadius (no world width) is not.
  HairSegments neg = h;
  neg.radius = {0.01f, -0.5f};
  EXPECT_NE(msg([&] { rasterize_hair_depth(ctx, neg, ortho_light(), 16); }).find("radius -0.5"),
            std::string::npos);
  neg.radius = {0.01f, HairSegments::kNoRadius};
  EXPECT_EQ(msg([&] { rasterize_hair_depth(ctx, neg, ortho_light(), 16); }), "no error");
  // zero-size buffers and frames
  EXPECT_NE(msg([&] { rasterize_hair_depth(ctx, h, ortho_light(), 0); }).find("size 0"),
            std::string::npos);
  ShadowBuffer empty;
  EXPECT_NE(msg([&] { compose_shadow_buffers(ctx, empty, empty); }).find("size 0"),
            std::string::npos);
  Frame z(8, 8);
  HairFrame zt = z.target();
  zt.fb_width = 0;
  EXPECT_NE(msg([&] {
              blend_hair(ctx, pixel_camera(8, 8), h, colours(h, Vec3f(1, 1, 1)), zt);
            }).find("framebuffer 0x8"),
            std::string::npos);
  // mismatched buffers
  EXPECT_NE(
      msg([&] { compose_shadow_buffers(ctx, flat_buffer(8, 1), flat_buffer(16, 1)); }).find("8x8"),
      std::string::npos);
  // perspective light
  Mat4 persp = Mat4::Identity();
  persp(3, 2) = -1;
  EXPECT_NE(msg([&] { rasterize_hair_depth(ctx, h, persp, 16); }).find("orthographic"),
            std::string::npos);
  // wrong array sizes
  EXPECT_NE(msg([&] {
              blend_hair(ctx, pixel_camera(8, 8), h, {}, f.target());
            }).find("0 colours for 2 points"),
            std::string::npos);
  HairSegments w = h;
  w.width_px[0] = 0;
  EXPECT_NE(msg([&] { w.check("hair"); }).find("width 0 px of strand 0"), std::string::npos);
  HairSegments o = h;
  o.offsets.back() = 5;
  EXPECT_NE(msg([&] { o.check("hair"); }).find("end at 5"), std::string::npos);
  HairFrame off = f.target();
  off.x0 = 4;
  EXPECT_NE(msg([&] {
              blend_hair(ctx, pixel_camera(8, 8), h, colours(h, Vec3f(1, 1, 1)), off);
            }).find("does not fit"),
            std::string::npos);
  HairShading sh;
  sh.n = -1;
  std::vector<Vec3f> out(2);
  EXPECT_NE(msg([&] {
              shade_hair_vertices(ctx, h, 0, 1, {}, sh, {}, Vec3(0, 0, 1), out);
            }).find("n = -1"),
            std::string::npos);
  sh = HairShading{};
  sh.mode = HairShadingMode::ShadowedColor;
  EXPECT_NE(msg([&] {
              shade_hair_vertices(ctx, h, 0, 1, {}, sh, {}, Vec3(0, 0, 1), out);
            }).find("one colour per point"),
            std::string::npos);
}

// ---- the renderer
// --------------------------------------------------------------------------------

namespace {

/// A plane y = 0 (2 x 2 m), a light from straight above, a sheet of `n` hairs along x at
/// height 0.3 m spanning z in [-0.05, 0.05], seen from above and in front.
RenderScene hair_over_plane(bool hair_shadow, int n = 40) {
  RenderScene s;
  s.camera.eye = Vec3(0, 2.0, 2.0);
  s.camera.target = Vec3(0, 0, 0);
  s.camera.fov_y = 0.8;
  s.background = Vec3(0.1, 0.1, 0.1);
  s.ambient_color = Vec3(1, 1, 1);
  DirectionalLight l;
  l.direction = Vec3(0, -1, 0);
  s.lights.push_back(l);
  MeshItem plane;
  plane.mesh = make_quad(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 0, -2));
  plane.material.base_color = Vec3(0.8, 0.8, 0.8);
  plane.material.ambient = 0.1;
  plane.material.specular = 0;
  s.meshes.push_back(plane);
  auto st = std::make_shared<geom::StrandSet>();
  for (int i = 0; i < n; ++i) {
    const float z = -0.05f + 0.1f * float(i) / float(n - 1);
    std::vector<Vec3f> p;
    for (int k = 0; k <= 10; ++k) p.emplace_back(-0.6f + 0.12f * float(k), 0.3f, z);
    st->add_strand(p);
  }
  StrandItem si;
  si.strands = st;
  si.material.shading = StrandShading::Daldegan1993;
  si.material.color = Vec3(0.6, 0.4, 0.2);
  si.hair_shadow = hair_shadow;
  si.cast_shadow = hair_shadow;  // without either the hair casts nothing
  s.strands.push_back(si);
  return s;
}

RenderSettings settings(int w, int h) {
  RenderSettings r;
  r.width = w;
  r.height = h;
  r.supersample = 2;
  r.shadow_map_size = 1024;
  return r;
}

void maybe_save(const image::ImageRGBA8& img, const std::string& name) {
  if (const char* d = std::getenv("FOLLICLE_RENDER_TEST_OUT"))
    image::write_png(std::filesystem::path(d) / name, img);
}

/// A sphere of radius r at c with n strands of `pts` points on it (Fibonacci roots), growing
/// along the normal and bending down under a "gravity" curve.
std::shared_ptr<geom::StrandSet> furry_sphere(int n, int pts, double r, const Vec3& c, double len) {
  auto st = std::make_shared<geom::StrandSet>();
  st->points.reserve(std::size_t(n) * std::size_t(pts));
  st->offsets.reserve(std::size_t(n) + 1);
  Rng rng(5);
  const double golden = kPi * (3 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double y = 1 - 2 * (i + 0.5) / n;
    const double rad = std::sqrt(1 - y * y);
    const double th = golden * i;
    const Vec3 nrm(rad * std::cos(th), y, rad * std::sin(th));
    const double l = len * rng.uniform(0.8, 1.2);
    Vec3 p = c + r * nrm;
    Vec3 d = nrm;
    const double step = l / (pts - 1);
    for (int k = 0; k < pts; ++k) {
      st->points.push_back(p.cast<float>());
      d = (d + Vec3(0, -0.12, 0) +
           0.05 * Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)))
              .normalized();
      p += step * d;
    }
    st->offsets.push_back(uint32_t(st->points.size()));
  }
  return st;
}

RenderScene furry_scene(int n, int pts) {
  RenderScene s;
  s.camera.eye = Vec3(0.3, 0.9, 2.4);
  s.camera.target = Vec3(0, -0.15, 0);
  s.camera.fov_y = 0.75;
  s.background = Vec3(0.12, 0.12, 0.14);
  s.ambient_color = Vec3(0.6, 0.6, 0.65);
  DirectionalLight key;
  key.direction = Vec3(0.5, -1, -0.35);
  s.lights.push_back(key);
  DirectionalLight rim;
  rim.direction = Vec3(-0.8, -0.3, 0.6);
  rim.intensity = 0.4;
  s.lights.push_back(rim);
  MeshItem ground;
  ground.mesh = make_quad(Vec3(0, -0.75, 0), Vec3(3, 0, 0), Vec3(0, 0, -3));
  ground.material.base_color = Vec3(0.6, 0.62, 0.65);
  ground.material.specular = 0.05;
  s.meshes.push_back(ground);
  MeshItem ball;
  ball.mesh = make_sphere(0.5);
  ball.material.base_color = Vec3(0.8, 0.55, 0.45);
  s.meshes.push_back(ball);
  StrandItem fur;
  fur.strands = furry_sphere(n, pts, 0.5, Vec3::Zero(), 0.2);
  fur.material.shading = StrandShading::Daldegan1993;
  fur.material.color = Vec3(0.55, 0.33, 0.15);
  fur.material.diffuse = 0.8;
  fur.material.specular = 0.3;
  fur.material.shininess = 30;
  fur.material.ambient = 0.25;
  fur.material.width_px = 0.6;
  fur.material.opacity = 0.9;
  fur.hair_shadow = true;
  s.strands.push_back(fur);
  return s;
}

double json_number(const std::string& text, const std::string& key) {
  const auto at = text.find("\"" + key + "\"");
  if (at == std::string::npos) throw Error("tolerance file has no key " + key);
  return std::stod(text.substr(text.find(':', at) + 1));
}

}  // namespace

class DaldeganGl : public RenderTest {};

TEST_F(DaldeganGl, HairShadowDarkensThePlaneUnderIt) {
  const int w = 128, h = 128;
  const auto lit = renderer().render(hair_over_plane(false), settings(w, h));
  const auto shadowed = renderer().render(hair_over_plane(true), settings(w, h));
  maybe_save(shadowed, "daldegan_plane_shadow.png");
  Camera cam = hair_over_plane(true).camera;
  // The shadow of the sheet lies on the plane under it (light from straight above).
  const auto under = project_to_pixel(cam, w, h, Vec3(-0.3, 0, 0));
  const auto hair_px = project_to_pixel(cam, w, h, Vec3(-0.3, 0.3, 0));
  const auto away = project_to_pixel(cam, w, h, Vec3(-0.3, 0, 0.5));
  ASSERT_TRUE(under && hair_px && away);
  ASSERT_GT(std::abs(under->y() - hair_px->y()), 6.0);  // the hair does not hide its shadow
  const double l_lit = luminance(lit, int(under->x()), int(under->y()));
  const double l_sh = luminance(shadowed, int(under->x()), int(under->y()));
  EXPECT_LT(l_sh, 0.6 * l_lit) << l_sh << " vs " << l_lit;
  // Away from the shadow the plane is unchanged.
  EXPECT_NEAR(luminance(shadowed, int(away->x()), int(away->y())),
              luminance(lit, int(away->x()), int(away->y())), 1.0);
  // The hair itself is drawn in both.
  const double l_hair = luminance(shadowed, int(hair_px->x()), int(hair_px->y()));
  EXPECT_GT(std::abs(l_hair - l_lit), 10.0);
}

TEST_F(DaldeganGl, VertexColourHairCastsAndReceivesShadows) {
  // Anjyo-style colours (StrandShading::VertexColor) with hair_shadow: the colours are kept
  // (times the shadow factor of the key light) and the hair shadows the plane like the
  // Daldegan1993 items. Without hair_shadow (and cast_shadow) they are lit without shadows and
  // cast nothing.
  const int w = 128, h = 128;
  auto scene = [](bool hair_shadow) {
    RenderScene s = hair_over_plane(hair_shadow);
    auto st = std::make_shared<geom::StrandSet>(*s.strands[0].strands);
    st->color.assign(st->points.size(), Vec3f(0.9f, 0.3f, 0.1f));
    s.strands[0].strands = st;
    s.strands[0].material.shading = StrandShading::VertexColor;
    s.strands[0].cast_shadow = false;  // as the scene's Anjyo hair: no GL shadow map
    return s;
  };
  const auto lit = renderer().render(scene(false), settings(w, h));
  const auto shadowed = renderer().render(scene(true), settings(w, h));
  maybe_save(shadowed, "daldegan_vertex_colour.png");
  const Camera cam = hair_over_plane(true).camera;
  const auto under = project_to_pixel(cam, w, h, Vec3(-0.3, 0, 0));
  const auto hair_px = project_to_pixel(cam, w, h, Vec3(-0.3, 0.3, 0));
  ASSERT_TRUE(under && hair_px);
  EXPECT_LT(luminance(shadowed, int(under->x()), int(under->y())),
            0.6 * luminance(lit, int(under->x()), int(under->y())));
  // The sheet's top hairs are lit: their red dominates as in the vertex colour.
  const int hx = int(hair_px->x()), hy = int(hair_px->y());
  EXPECT_GT(shadowed.at(hx, hy, 0), shadowed.at(hx, hy, 1) + 40);
}

TEST_F(DaldeganGl, HairBehindAnOpaqueQuadIsInvisible) {
  RenderScene s = hair_over_plane(true);
  s.lights[0].cast_shadow = false;
  MeshItem wall;  // between the camera and the whole scene
  wall.mesh = make_quad(Vec3(0, 1.0, 1.0), Vec3(4, 0, 0), Vec3(0, 4, -4) / std::sqrt(2.0));
  s.meshes.push_back(wall);
  const auto with_hair = renderer().render(s, settings(96, 96));
  RenderScene bare = s;
  bare.strands.clear();
  const auto without = renderer().render(bare, settings(96, 96));
  int worst = 0;
  for (int y = 0; y < 96; ++y)
    for (int x = 0; x < 96; ++x)
      for (int c = 0; c < 4; ++c)
        worst = std::max(worst, std::abs(int(with_hair.at(x, y, c)) - int(without.at(x, y, c))));
  EXPECT_LE(worst, 1);  // CPU vs GL resolve rounding only
  // Without the wall the hair shows.
  const auto seen = renderer().render(hair_over_plane(true), settings(96, 96));
  const auto seen_bare = [&] {
    RenderScene b = hair_over_plane(true);
    b.strands.clear();
    return renderer().render(b, settings(96, 96));
  }();
  int differ = 0;
  for (int y = 0; y < 96; ++y)
    for (int x = 0; x < 96; ++x)
      differ += std::abs(int(seen.at(x, y, 1)) - int(seen_bare.at(x, y, 1))) > 8;
  EXPECT_GT(differ, 100);
}

TEST_F(DaldeganGl, ViewerPathMatchesTheImagePath) {
  const RenderScene s = hair_over_plane(true);
  const RenderSettings rs = settings(120, 100);
  const auto img = renderer().render(s, rs);
  GLuint tex = 0, fbo = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, rs.width, rs.height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
               nullptr);
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
  ASSERT_EQ(glCheckFramebufferStatus(GL_FRAMEBUFFER), GLenum(GL_FRAMEBUFFER_COMPLETE));
  renderer().render_to_framebuffer(s, rs, fbo);
  std::vector<uint8_t> px(4 * std::size_t(rs.width) * std::size_t(rs.height));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, rs.width, rs.height, GL_RGBA, GL_UNSIGNED_BYTE, px.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDeleteFramebuffers(1, &fbo);
  glDeleteTextures(1, &tex);
  int worst = 0;
  for (int y = 0; y < rs.height; ++y)
    for (int x = 0; x < rs.width; ++x)
      for (int c = 0; c < 4; ++c) {
        const int a = px[4 * (std::size_t(rs.height - 1 - y) * std::size_t(rs.width) + x) + c];
        worst = std::max(worst, std::abs(a - int(img.at(x, y, c))));
      }
  EXPECT_LE(worst, 2);  // the upload rounds to half floats once more
}

TEST_F(DaldeganGl, BadStrandDataNamesTheItem) {
  RenderScene s = hair_over_plane(true, 4);
  auto st = std::make_shared<geom::StrandSet>(*s.strands[0].strands);
  st->points[3].x() = std::nanf("");
  s.strands[0].strands = st;
  try {
    renderer().render(s, settings(32, 32));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("strands[0]: point 3 is not finite"), std::string::npos)
        << e.what();
  }
  RenderScene o = hair_over_plane(true, 4);
  o.strands[0].material.opacity = 2;
  EXPECT_THROW(renderer().render(o, settings(32, 32)), Error);
}

TEST_F(DaldeganGl, FurrySphereMatchesGolden) {
  // A furry ball over a plane: scene and hair shadows (two lights, the second without a GL
  // shadow map), eq. (7), blended lines. Regenerate with FOLLICLE_UPDATE_GOLDEN=1 and look at it.
  const RenderScene s = furry_scene(6000, 12);
  const RenderSettings rs = settings(160, 120);
  const auto img = renderer().render(s, rs);
  maybe_save(img, "daldegan_furry_sphere.png");
  const auto dir = test::source_dir() / "tests/golden/render";
  const auto golden = dir / "daldegan_furry_sphere.png";
  if (std::getenv("FOLLICLE_UPDATE_GOLDEN")) {
    image::write_png(golden, img);
    GTEST_SKIP() << "golden image written to " << golden;
  }
  ASSERT_TRUE(std::filesystem::exists(golden)) << "no golden image " << golden;
  const std::string tol = read_file(dir / "daldegan_furry_sphere.tolerance.json");
  image::DiffOptions opt;
  opt.threshold = json_number(tol, "pixel_threshold");
  const auto d = image::compare_images(img, image::read_png_rgba(golden), opt);
  EXPECT_GE(d.psnr, json_number(tol, "min_psnr_db"));
  EXPECT_LE(d.share_over, json_number(tol, "max_share_over"));
}

TEST_F(DaldeganGl, MeasureLargeFur) {
  // Timing of the workload (100k strands x 30 points at 1024², two lights); only with
  // FOLLICLE_DALDEGAN_MEASURE=1 (no timing is asserted).
  if (!std::getenv("FOLLICLE_DALDEGAN_MEASURE")) GTEST_SKIP() << "FOLLICLE_DALDEGAN_MEASURE unset";
  const RenderScene s = furry_scene(100000, 30);
  RenderSettings rs = settings(1024, 1024);
  rs.shadow_map_size = 2048;
  if (const char* v = std::getenv("FOLLICLE_DALDEGAN_SHADOW")) rs.shadow_map_size = std::atoi(v);
  {
    // The CPU steps alone, on the same hair (world = model space here).
    const Context ctx(2, 1);
    HairSegments hair;
    const geom::StrandSet& st = *s.strands[0].strands;
    hair.points = st.points;
    hair.offsets = st.offsets;
    hair.width_px.assign(st.num_strands(), 1.2f);
    hair.opacity.assign(st.num_strands(), 0.9f);
    hair.casts_shadow.assign(st.num_strands(), 1);
    const Mat4 vp = projection_matrix(s.camera, 1.0) * view_matrix(s.camera);
    Mat4 lvp = Mat4::Identity();
    lvp(0, 0) = lvp(1, 1) = lvp(2, 2) = 1 / 2.2;
    // CPU time of the process (both threads): the machine is shared, wall time is noisy.
    auto cpu_ms = [] {
      timespec ts{};
      clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
      return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
    };
    auto tick = [&cpu_ms, t = cpu_ms()]() mutable {
      const double n = cpu_ms();
      const double ms = n - t;
      t = n;
      return ms;
    };
    HairDepthRasterizer raster;
    ShadowBuffer hb;
    HairBlender blender;
    std::vector<Vec3f> col(hair.num_points());
    Frame f(2048, 2048);
    // The ball's depth (radius 0.5 at the origin) as the scene Z-buffer.
    const Mat4 inv = vp.inverse();
    for (int y = 0; y < 2048; ++y)
      for (int x = 0; x < 2048; ++x) {
        const Vec4 a = inv * Vec4((x + 0.5) / 1024 - 1, (y + 0.5) / 1024 - 1, -1, 1);
        const Vec4 b = inv * Vec4((x + 0.5) / 1024 - 1, (y + 0.5) / 1024 - 1, 1, 1);
        const Vec3 o = a.head<3>() / a.w(), d = (b.head<3>() / b.w() - o).normalized();
        const double bq = o.dot(d), cq = o.squaredNorm() - 0.25, disc = bq * bq - cq;
        if (disc < 0) continue;
        const Vec4 c = vp * (o + (-bq - std::sqrt(disc)) * d).homogeneous();
        f.depth[std::size_t(y) * 2048 + std::size_t(x)] = float(0.5 * c.z() / c.w() + 0.5);
      }
    const std::vector<float> clear = f.rgba;
    for (int rep = 0; rep < 3; ++rep) {
      f.rgba = clear;
      tick();
      raster.rasterize(ctx, hair, lvp, rs.shadow_map_size, hb);
      const double t_r = tick();
      HairLight l = light(Vec3(0, 1, 0));
      l.shadow = &hb;
      shade_hair_vertices(ctx, hair, 0, hair.num_strands(), {}, HairShading{}, std::span(&l, 1),
                          s.camera.eye, col);
      const double t_s = tick();
      blender.prepare(ctx, vp, hair, 2048, 2048, 2);
      const double t_p = tick();
      HairFrame t = f.target();
      t.samples = 2;
      blender.blend(ctx, hair, col, t);
      const double t_b = tick();
      std::printf("CPU time: raster %.1f  shade %.1f  prepare %.1f  blend %.1f ms\n", t_r, t_s, t_p,
                  t_b);
    }
  }
  if (std::string(std::getenv("FOLLICLE_DALDEGAN_MEASURE")) == "cpu") return;
  for (int rep = 0; rep < 3; ++rep) {
    const auto t0 = std::chrono::steady_clock::now();
    timespec c0{}, c1{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
    const auto img = renderer().render(s, rs);
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = (c1.tv_sec - c0.tv_sec) * 1e3 + (c1.tv_nsec - c0.tv_nsec) * 1e-6;
    std::printf("furry sphere 100k x 30 at 1024^2: %.1f ms wall, %.1f ms CPU (all threads)\n", ms,
                cpu);
    if (rep == 0) maybe_save(img, "daldegan_furry_1024.png");
  }
}
