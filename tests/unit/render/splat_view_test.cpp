// The CPU view pass of Bando 2003 §3.4 (pseudo-code lines 17-21, splat_view_bando2003.hpp):
// coverage and blend against hand values, the depth test, the draw order, the texture's
// orientation, the near plane, thread-count independence, bad input, and the whole frame
// against the GL view pass.
#define GL_GLEXT_PROTOTYPES 1  // glGenFramebuffers & co. for the viewer-path test
#include <GL/gl.h>
#include <GL/glext.h>
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include "follicle/core/error.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/render/camera.hpp"
#include "follicle/render/splat_bando2003.hpp"
#include "follicle/render/splat_view_bando2003.hpp"
#include "render_test_util.hpp"

using namespace follicle;
using namespace follicle::render;
using namespace follicle::render::testutil;

namespace {

constexpr int kW = 64, kH = 48;

/// Orthographic camera looking down -z: world x in [-1, 1] -> window [0, 64], y in [-0.75, 0.75]
/// -> [0, 48] (32 px per world unit); z_ndc = -z (a point at z = 0 has window depth 1/2).
SplatViewParams ortho() {
  SplatViewParams p;
  p.view_proj = Mat4::Identity();
  p.view_proj(1, 1) = 1 / 0.75;
  p.view_proj(2, 2) = -1;
  p.eye = Vec3(0, 0, 100);  // far along +z: d_p is -z up to 1e-4 over the scene
  return p;
}

/// A hair along +y at the window centre (32, 24): half-width 4 px, half-length 8 px (sin = 1).
ViewSplatParticle particle(const Vec3& colour, double alpha, double x_px = 0, double z = 0) {
  ViewSplatParticle p;
  p.pos = Vec3(x_px / 32, 0, z);
  p.t = Vec3(0, 1, 0);
  p.half_w = 4.0 / 32;
  p.half_l = 8.0 / 32;
  p.alpha = alpha;
  p.min_sin = 0.1;
  p.color = colour;
  return p;
}

struct Buffers {
  std::vector<float> rgba, depth;
  explicit Buffers(float depth_value = 1.0f, Vec4 bg = Vec4(0.2, 0.4, 0.6, 1.0))
      : rgba(4 * std::size_t(kW) * kH), depth(std::size_t(kW) * kH, depth_value) {
    for (std::size_t i = 0; i < depth.size(); ++i)
      for (int c = 0; c < 4; ++c) rgba[4 * i + std::size_t(c)] = float(bg[c]);
  }
  SplatViewTarget target() {
    SplatViewTarget t;
    t.fb_width = kW;
    t.fb_height = kH;
    t.width = kW;
    t.height = kH;
    t.rgba = rgba.data();
    t.depth = depth.data();
    return t;
  }
  const float* px(int x, int y) const { return &rgba[4 * (std::size_t(y) * kW + std::size_t(x))]; }
};

std::vector<int32_t> identity_order(std::size_t n) {
  std::vector<int32_t> o(n);
  for (std::size_t i = 0; i < n; ++i) o[i] = int32_t(i);
  return o;
}

image::ImageRGBA8 white(int n = 8) {
  return image::ImageRGBA8(n, n, uint8_t(255));
}

}  // namespace

TEST(SplatView, OpaqueTextureCoversTheBillboardAndBlendsByAlpha) {
  Buffers b;
  const std::vector<ViewSplatParticle> ps = {particle(Vec3(1.0, 0.5, 0.0), 0.25)};
  const SplatColorTexture tex(white());
  splat_view_pass_bando2003(ortho(), ps, identity_order(1), tex, b.target());
  // The billboard spans x in [28, 36), y in [16, 32): 8 x 16 pixel centres.
  int covered = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const bool in = x >= 28 && x < 36 && y >= 16 && y < 32;
      const float* p = b.px(x, y);
      if (p[0] != 0.2f) ++covered;
      if (in) {
        EXPECT_FLOAT_EQ(p[0], 1.0f * 0.25f + 0.2f * 0.75f) << x << "," << y;
        EXPECT_FLOAT_EQ(p[1], 0.5f * 0.25f + 0.4f * 0.75f);
        EXPECT_FLOAT_EQ(p[2], 0.0f * 0.25f + 0.6f * 0.75f);
        EXPECT_FLOAT_EQ(p[3], 0.25f + 1.0f * 0.75f);
      } else {
        EXPECT_EQ(p[0], 0.2f) << x << "," << y;
      }
    }
  EXPECT_EQ(covered, 8 * 16);
}

TEST(SplatView, OpacityIsScaledByInverseSinTheta) {
  // t tilted 60 degrees towards the eye: sin(theta) = 1/2, the length halves, alpha doubles.
  Buffers b;
  ViewSplatParticle p = particle(Vec3(1, 1, 1), 0.25);
  p.t = Vec3(0, 0.5, std::sqrt(0.75));
  const SplatColorTexture tex(white());
  splat_view_pass_bando2003(ortho(), std::vector<ViewSplatParticle>{p}, identity_order(1), tex,
                            b.target());
  int rows = 0;
  for (int y = 0; y < kH; ++y)
    if (b.px(32, y)[0] != 0.2f) {
      ++rows;
      EXPECT_NEAR(b.px(32, y)[0], 0.5 + 0.2 * 0.5, 1e-6);  // alpha / sin = 0.5
    }
  EXPECT_EQ(rows, 8);
}

TEST(SplatView, ObjectsInFrontHideTheHair) {
  // Left half of the window has an object at depth 0.25 (in front of the billboard's 0.5), the
  // right half at 0.75 (behind it).
  Buffers b;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      b.depth[std::size_t(y) * kW + std::size_t(x)] = x < 32 ? 0.25f : 0.75f;
  const SplatColorTexture tex(white());
  splat_view_pass_bando2003(ortho(), std::vector<ViewSplatParticle>{particle(Vec3(1, 1, 1), 1)},
                            identity_order(1), tex, b.target());
  for (int y = 16; y < 32; ++y) {
    for (int x = 28; x < 32; ++x) EXPECT_EQ(b.px(x, y)[0], 0.2f) << x << "," << y;
    for (int x = 32; x < 36; ++x) EXPECT_EQ(b.px(x, y)[0], 1.0f) << x << "," << y;
  }
}

TEST(SplatView, BillboardsBlendInTheGivenOrder) {
  const std::vector<ViewSplatParticle> ps = {particle(Vec3(1, 0, 0), 0.5, 0, -0.1),
                                             particle(Vec3(0, 0, 1), 0.5, 0, 0.1)};
  const SplatColorTexture tex(white());
  Buffers a, b;
  splat_view_pass_bando2003(ortho(), ps, std::vector<int32_t>{0, 1}, tex, a.target());
  splat_view_pass_bando2003(ortho(), ps, std::vector<int32_t>{1, 0}, tex, b.target());
  // Red then blue: blue on top.
  const float r01 = (1.0f * 0.5f + 0.2f * 0.5f) * 0.5f, b01 = 1.0f * 0.5f + 0.6f * 0.5f * 0.5f;
  EXPECT_FLOAT_EQ(a.px(32, 24)[0], r01);
  EXPECT_FLOAT_EQ(a.px(32, 24)[2], b01);
  EXPECT_NE(a.px(32, 24)[0], b.px(32, 24)[0]);
  // splat_view_order puts the far particle (z = -0.1, with the eye on +z) first.
  Mat4 view = Mat4::Identity();
  EXPECT_EQ(splat_view_order(view, ps), (std::vector<int32_t>{0, 1}));
  std::vector<ViewSplatParticle> swapped = {ps[1], ps[0]};
  EXPECT_EQ(splat_view_order(view, swapped), (std::vector<int32_t>{1, 0}));
}

TEST(SplatView, TextureRowZeroIsAtTheRootSideEnd) {
  // Alpha only in the texture's first rows: those pixels sit at the -t end of the billboard
  // (v = 0, like billboard_corner's uv for corner y = -1), i.e. at the bottom for t = +y.
  image::ImageRGBA8 img(8, 8, uint8_t(255));
  for (int y = 2; y < 8; ++y)
    for (int x = 0; x < 8; ++x) img.at(x, y, 3) = 0;
  const SplatColorTexture tex(img);
  Buffers b;
  splat_view_pass_bando2003(ortho(), std::vector<ViewSplatParticle>{particle(Vec3(1, 1, 1), 1)},
                            identity_order(1), tex, b.target());
  int low = 0, high = 0;
  for (int y = 16; y < 32; ++y)
    if (b.px(32, y)[0] != 0.2f) (y < 24 ? low : high)++;
  EXPECT_GT(low, 2);
  EXPECT_EQ(high, 0);
}

TEST(SplatView, EmptyTextureMarginsAreSkippedWithoutChangingPixels) {
  // A streak in texel columns 3-4 and rows 2-12 of a 8 x 16 texture: the pass narrows each
  // row to the texture's non-empty box. Every pixel changes exactly when the bilinear alpha
  // at its (u, v) (SplatAlphaTexture::sample, level 0: the billboard is magnified) reaches the
  // discard threshold.
  image::ImageRGBA8 img(8, 16, uint8_t(255));
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 8; ++x) img.at(x, y, 3) = (x == 3 || x == 4) && y >= 2 && y <= 12 ? 200 : 0;
  const SplatColorTexture tex(img);
  EXPECT_EQ(tex.coverage(0), (std::array<int, 4>{3, 4, 2, 12}));
  const SplatAlphaTexture alpha(img);
  Buffers b;
  ViewSplatParticle p = particle(Vec3(1, 1, 1), 1);
  p.half_w = 5.0 / 32;   // 10 px for 8 texels: samples fall between texel centres
  p.half_l = 11.0 / 32;  // 22 px for 16 texels
  splat_view_pass_bando2003(ortho(), std::vector<ViewSplatParticle>{p}, identity_order(1), tex,
                            b.target());
  int drawn = 0;
  for (int y = 13; y < 35; ++y)
    for (int x = 27; x < 37; ++x) {
      const double u = (x + 0.5 - 27) / 10, v = (y + 0.5 - 13) / 22;
      const bool expect = alpha.sample(u, v, 0) >= SplatColorTexture::kSplatAlphaDiscard;
      EXPECT_EQ(b.px(x, y)[0] != 0.2f, expect) << x << "," << y;
      drawn += expect;
    }
  EXPECT_GT(drawn, 20);
  EXPECT_LT(drawn, 10 * 22 / 2);
}

TEST(SplatView, PerspectiveBillboardMatchesItsProjectedArea) {
  // A camera 1 m in front of a billboard facing it: 2 hw x 2 hl metres project to
  // (2 hw f / 1 m) pixels with f the focal length in pixels; perspective-correct uv keep a
  // uniform texture uniform.
  Camera cam;
  cam.eye = Vec3(0, 0, 1);
  cam.target = Vec3::Zero();
  cam.up = Vec3(0, 1, 0);
  cam.fov_y = 40 * kPi / 180;
  SplatViewParams prm;
  prm.view_proj = projection_matrix(cam, double(kW) / kH) * view_matrix(cam);
  prm.eye = cam.eye;
  ViewSplatParticle p = particle(Vec3(1, 1, 1), 1);
  p.pos = Vec3(0.01, 0.02, 0);
  p.half_w = 0.05;
  p.half_l = 0.1;
  Buffers b;
  splat_view_pass_bando2003(prm, std::vector<ViewSplatParticle>{p}, identity_order(1),
                            SplatColorTexture(white()), b.target());
  int covered = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (b.px(x, y)[0] != 0.2f) {
        ++covered;
        EXPECT_FLOAT_EQ(b.px(x, y)[0], 1.0f);
      }
  const double f = 0.5 * kH / std::tan(0.5 * 40 * kPi / 180);
  const double area = (2 * 0.05 * f) * (2 * 0.1 * f);
  EXPECT_NEAR(covered, area, 2 * (2 * 0.05 * f + 2 * 0.1 * f)) << area;
}

TEST(SplatView, BillboardThroughTheNearPlaneDrawsOnlyItsFrontPart) {
  Camera cam;
  cam.eye = Vec3(0, 0, 1);
  cam.target = Vec3::Zero();
  cam.up = Vec3(0, 1, 0);
  cam.z_near = 0.05;
  SplatViewParams prm;
  prm.view_proj = projection_matrix(cam, double(kW) / kH) * view_matrix(cam);
  prm.eye = cam.eye;
  // A hair pointing at the eye from below it, long enough to pass behind the eye.
  ViewSplatParticle p = particle(Vec3(1, 1, 1), 0.5);
  p.pos = Vec3(0, -0.05, 0.9);
  p.t = Vec3(0, 0.2, 1).normalized();
  p.half_l = 0.5;
  p.half_w = 0.02;
  p.min_sin = 1;  // full length
  Buffers b;
  ASSERT_NO_THROW(splat_view_pass_bando2003(prm, std::vector<ViewSplatParticle>{p},
                                            identity_order(1), SplatColorTexture(white()),
                                            b.target()));
  int covered = 0;
  for (float v : b.rgba) ASSERT_TRUE(std::isfinite(v));
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) covered += b.px(x, y)[0] != 0.2f;
  EXPECT_GT(covered, 0);
  EXPECT_LT(covered, kW * kH);
}

TEST(SplatView, SameResultForAnyThreadCountAndWindow) {
  std::vector<ViewSplatParticle> ps;
  Rng r = Rng::stream(7, 0);
  for (int i = 0; i < 300; ++i) {
    ViewSplatParticle p =
        particle(Vec3(r.uniform(0, 1), r.uniform(0, 1), r.uniform(0, 1)), r.uniform(0.1, 0.9));
    p.pos = Vec3(r.uniform(-1, 1), r.uniform(-0.8, 0.8), r.uniform(-0.5, 0.5));
    p.t = Vec3(r.uniform(-1, 1), r.uniform(-1, 1), r.uniform(-1, 1)).normalized();
    p.half_w = r.uniform(0.02, 0.1);
    p.half_l = r.uniform(0.05, 0.3);
    ps.push_back(p);
  }
  Mat4 view = Mat4::Identity();
  const std::vector<int32_t> order = splat_view_order(view, ps);
  const SplatColorTexture tex(make_hair_texture());
  auto run = [&](int threads) {
    Buffers b(0.6f);
    tbb::task_arena arena(threads);
    arena.execute([&] { splat_view_pass_bando2003(ortho(), ps, order, tex, b.target()); });
    return b.rgba;
  };
  const std::vector<float> one = run(1), two = run(2);
  EXPECT_TRUE(one == two);
  EXPECT_FALSE(one == Buffers(0.6f).rgba);
  // A window around the bounds gives the same pixels as the whole framebuffer.
  int box[4];
  splat_view_bounds(ortho(), ps, kW, kH, box);
  ASSERT_LT(box[0], box[2]);
  box[0] = std::max(box[0], 5);
  box[1] = std::max(box[1], 3);
  Buffers full(0.6f);
  splat_view_pass_bando2003(ortho(), ps, order, tex, full.target());
  const int ww = box[2] - box[0], wh = box[3] - box[1];
  std::vector<float> rgba(4 * std::size_t(ww) * wh), depth(std::size_t(ww) * wh, 0.6f);
  for (int y = 0; y < wh; ++y)
    for (int x = 0; x < ww; ++x)
      for (int c = 0; c < 4; ++c)
        rgba[4 * (std::size_t(y) * ww + x) + c] = Buffers(0.6f).px(0, 0)[c];
  SplatViewTarget t;
  t.fb_width = kW;
  t.fb_height = kH;
  t.x0 = box[0];
  t.y0 = box[1];
  t.width = ww;
  t.height = wh;
  t.rgba = rgba.data();
  t.depth = depth.data();
  splat_view_pass_bando2003(ortho(), ps, order, tex, t);
  for (int y = 0; y < wh; ++y)
    for (int x = 0; x < ww; ++x)
      for (int c = 0; c < 4; ++c)
        ASSERT_EQ(rgba[4 * (std::size_t(y) * ww + x) + c], full.px(box[0] + x, box[1] + y)[c])
            << x << "," << y;
}

TEST(SplatView, BadInputFailsCleanly) {
  const SplatColorTexture tex(white());
  const std::vector<ViewSplatParticle> ok = {particle(Vec3(1, 1, 1), 0.5)};
  auto run = [&](std::vector<ViewSplatParticle> ps, std::vector<int32_t> order, SplatViewTarget t) {
    splat_view_pass_bando2003(ortho(), ps, order, tex, t);
  };
  Buffers b;
  EXPECT_NO_THROW(run(ok, {0}, b.target()));
  auto bad = ok;
  bad[0].pos.x() = std::nan("");
  EXPECT_THROW(run(bad, {0}, b.target()), Error);
  bad = ok;
  bad[0].t = Vec3(0, 2, 0);
  EXPECT_THROW(run(bad, {0}, b.target()), Error);
  bad = ok;
  bad[0].alpha = 1.5;
  EXPECT_THROW(run(bad, {0}, b.target()), Error);
  bad = ok;
  bad[0].color = Vec3(-1, 0, 0);
  EXPECT_THROW(run(bad, {0}, b.target()), Error);
  EXPECT_THROW(run(ok, {1}, b.target()), Error);     // not a permutation
  EXPECT_THROW(run(ok, {0, 0}, b.target()), Error);  // wrong size
  SplatViewTarget t = b.target();
  t.x0 = 10;  // 10 + 64 > 64
  EXPECT_THROW(run(ok, {0}, t), Error);
  t = b.target();
  t.depth = nullptr;
  EXPECT_THROW(run(ok, {0}, t), Error);
  EXPECT_THROW(SplatColorTexture(image::ImageRGBA8()), Error);
}

// ---- against the GL view pass -------------------------------------------------------------------

class SplatViewGl : public RenderTest {};

TEST_F(SplatViewGl, CpuViewPassMatchesTheGlViewPass) {
  const RenderScene s = make_hair_sheet_scene(2000);
  RenderSettings rs;
  rs.width = 256;
  rs.height = 256;
  rs.supersample = 1;
  rs.shadow_map_size = 1024;
  rs.hair_light_map_size = 256;
  rs.hair_view_pass = "cpu";
  const auto cpu = renderer().render(s, rs);
  rs.hair_view_pass = "gpu";
  const auto gpu = renderer().render(s, rs);
  RenderScene bare = s;
  bare.particles.clear();
  const auto head = renderer().render(bare, rs);
  if (const char* d = std::getenv("FOLLICLE_RENDER_TEST_OUT")) {
    image::write_png(std::filesystem::path(d) / "splat_view_cpu.png", cpu);
    image::write_png(std::filesystem::path(d) / "splat_view_gpu.png", gpu);
  }
  double diff = 0;
  int hair = 0, far_off = 0;
  for (int y = 0; y < rs.height; ++y)
    for (int x = 0; x < rs.width; ++x) {
      int d = 0;
      for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(cpu.at(x, y, c)) - gpu.at(x, y, c)));
      diff += d;
      far_off += d > 8;
      for (int c = 0; c < 3; ++c) hair += c == 0 && cpu.at(x, y, c) != head.at(x, y, c);
    }
  const int n = rs.width * rs.height;
  EXPECT_GT(hair, n / 5);       // the hair covers a good part of the frame
  EXPECT_LT(diff / n, 1.0);     // mean max-channel difference below one 8-bit step
  EXPECT_LT(far_off, n / 500);  // a few edge pixels (mip level per quad vs per billboard)
}

TEST_F(SplatViewGl, ViewerPathMatchesTheImagePath) {
  // render() resolves the read-back frame on the CPU; render_to_framebuffer() (the viewer)
  // uploads the hair rectangle again and resolves with GL. Same picture within rounding (the
  // upload rounds the blended floats to half floats once more).
  const RenderScene s = make_hair_sheet_scene(1500);
  RenderSettings rs;
  rs.width = 160;
  rs.height = 128;
  rs.supersample = 2;
  rs.shadow_map_size = 1024;
  rs.hair_light_map_size = 256;
  const auto img = renderer().render(s, rs);  // makes the renderer's context current
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
  int worst = 0, differ = 0;
  for (int y = 0; y < rs.height; ++y)
    for (int x = 0; x < rs.width; ++x)
      for (int c = 0; c < 4; ++c) {
        // GL rows are bottom-up, image rows top-down.
        const int a = px[4 * (std::size_t(rs.height - 1 - y) * std::size_t(rs.width) + x) + c];
        const int d = std::abs(a - int(img.at(x, y, c)));
        worst = std::max(worst, d);
        differ += d > 0;
      }
  EXPECT_LE(worst, 2);
  EXPECT_LT(differ, rs.width * rs.height / 10);
  // and the hair is there: the two paths are not both empty
  RenderScene bare = s;
  bare.particles.clear();
  const auto head = renderer().render(bare, rs);
  int hair = 0;
  for (int y = 0; y < rs.height; ++y)
    for (int x = 0; x < rs.width; ++x) hair += img.at(x, y, 0) != head.at(x, y, 0);
  EXPECT_GT(hair, rs.width * rs.height / 6);
}
