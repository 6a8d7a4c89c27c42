// The CPU per-particle light pass of Bando 2003 §3.4 (pseudo-code lines 6-12,
// splat_light_bando2003.hpp): analytic cases, order, bad input, and against the GPU pass with
// one slice per particle (the paper's algorithm on the GPU).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "follicle/image/image_io.hpp"
#include "follicle/render/splat_bando2003.hpp"
#include "follicle/render/splat_light_bando2003.hpp"
#include "render_test_util.hpp"

using namespace follicle;
using namespace follicle::render;
using namespace follicle::render::testutil;

namespace {

constexpr int kSize = 64;

/// Light travelling towards -z; world x, y in [-1, 1] fill the buffer (32 px per world unit),
/// so pixel centres are at world (k + 1/2) / 32 - 1.
SplatLightParams params() {
  SplatLightParams p;
  p.light_vp = Mat4::Identity();
  p.light_vp(2, 2) = -1;  // depth grows along the travel direction (irrelevant to the pass)
  p.travel = Vec3(0, 0, -1);
  p.size = kSize;
  return p;
}

/// A particle whose centre and 5 read taps fall on pixel centres: half-width 8 px, half-length
/// 16 px, hair direction +y (across the light: sin(theta) = 1).
LightSplatParticle particle(double z, double alpha) {
  LightSplatParticle p;
  p.pos = Vec3(0.5 / 32, 0.5 / 32, z);  // the centre of pixel (32, 32)
  p.t = Vec3(0, 1, 0);
  p.half_w = 8.0 / 32;
  p.half_l = 16.0 / 32;
  p.alpha = alpha;
  return p;
}

image::ImageRGBA8 white(int n = 4) {
  return image::ImageRGBA8(n, n, uint8_t(255));
}

double px(const SplatLightResult& r, int x, int y) {
  return r.light[std::size_t(y) * kSize + std::size_t(x)];
}

/// The 5-tap read weights of kSplatGatherVs at (u, v) offsets of the billboard.
double five_tap_coverage(const SplatAlphaTexture& tex, int level) {
  return 0.4 * tex.sample(0.5, 0.5, level) +
         0.15 * (tex.sample(0.5, 0.75, level) + tex.sample(0.5, 0.25, level) +
                 tex.sample(0.75, 0.5, level) + tex.sample(0.25, 0.5, level));
}

}  // namespace

TEST(SplatLightCpu, ParticleBehindReadsTheLightThroughTheNearOne) {
  const SplatAlphaTexture tex(white());
  const std::vector<LightSplatParticle> ps = {particle(-0.5, 0.3), particle(0.5, 0.3)};
  SplatLightResult r;
  splat_light_pass_bando2003(params(), ps, tex, r);
  // Particle 1 (z = 0.5) is nearer the light travelling towards -z: it reads the white buffer.
  EXPECT_FLOAT_EQ(r.reach[1], 1.0f);
  EXPECT_NEAR(r.reach[0], 1.0 - 0.3, 1e-6);
  // The light map: (1 - a)^2 inside both billboards (16 x 32 px around pixel (32, 32)), 1 out.
  EXPECT_NEAR(px(r, 32, 32), 0.7 * 0.7, 1e-6);
  EXPECT_NEAR(px(r, 25, 17), 0.7 * 0.7, 1e-6);
  EXPECT_NEAR(px(r, 38, 47), 0.7 * 0.7, 1e-6);
  EXPECT_FLOAT_EQ(float(px(r, 23, 32)), 1.0f);
  EXPECT_FLOAT_EQ(float(px(r, 40, 32)), 1.0f);
  EXPECT_FLOAT_EQ(float(px(r, 32, 15)), 1.0f);
  EXPECT_FLOAT_EQ(float(px(r, 32, 48)), 1.0f);
  // Exactly the 16 x 32 pixel centres inside the billboard are covered.
  int covered = 0;
  for (float v : r.light) covered += v < 1.0f ? 1 : 0;
  EXPECT_EQ(covered, 16 * 32);
}

TEST(SplatLightCpu, HairTextureCoverageAttenuatesTheRead) {
  // With the procedural hair texture the particle behind reads 1 - alpha x (the 5-tap average
  // of the texture at the mip level GL would pick: 64 x 128 texels over 16 x 32 px -> rho = 4,
  // level 2).
  const SplatAlphaTexture tex(make_hair_texture());
  const int level = tex.level_for(4.0);
  EXPECT_EQ(level, 2);
  const double cov = five_tap_coverage(tex, level);
  ASSERT_GT(cov, 0.05);
  const std::vector<LightSplatParticle> ps = {particle(-0.5, 0.6), particle(0.5, 0.6)};
  SplatLightResult r;
  splat_light_pass_bando2003(params(), ps, tex, r);
  EXPECT_FLOAT_EQ(r.reach[1], 1.0f);
  EXPECT_NEAR(r.reach[0], 1.0 - 0.6 * cov, 1e-5);
  // The shadow opacity scale, the 1/sin(theta) rule and the objects' visibility scale alpha.
  std::vector<LightSplatParticle> q = ps;
  q[1].opacity_scale = 0.5;
  q[1].vis = 0.5;
  splat_light_pass_bando2003(params(), q, tex, r);
  EXPECT_NEAR(r.reach[0], 1.0 - 0.6 * 0.5 * 0.5 * cov, 1e-5);
  q = ps;
  q[1].casts = false;
  splat_light_pass_bando2003(params(), q, tex, r);
  EXPECT_FLOAT_EQ(r.reach[0], 1.0f);  // the particle ahead does not cast
  EXPECT_NEAR(px(r, 32, 32), 1.0 - 0.6 * tex.sample(0.5, 0.5, level), 1e-6);  // only its own
}

TEST(SplatLightCpu, OpacityScalesWithInverseSinTheta) {
  // The near particle's hair at 60 degrees to the light: sin(theta) = sin(60), the billboard's
  // length shrinks by it and its opacity grows by 1/sin(theta) (§3.4).
  const SplatAlphaTexture tex(white());
  const double th = 60 * kPi / 180;
  std::vector<LightSplatParticle> ps = {particle(-0.5, 0.3), particle(0.5, 0.3)};
  ps[1].t = Vec3(0, std::sin(th), std::cos(th));
  SplatLightResult r;
  splat_light_pass_bando2003(params(), ps, tex, r);
  EXPECT_NEAR(r.reach[0], 1.0 - 0.3 / std::sin(th), 1e-6);
  int rows = 0;  // rows darkened by the near particle too (the far one covers 32 rows)
  for (int y = 0; y < kSize; ++y) rows += px(r, 32, y) < 0.7 - 1e-3 ? 1 : 0;
  EXPECT_NEAR(rows, 32 * std::sin(th), 1.0);
}

TEST(SplatLightCpu, OrderFollowsTheLightNotTheInput) {
  const SplatAlphaTexture tex(white());
  std::vector<LightSplatParticle> ps = {particle(0.5, 0.4), particle(-0.5, 0.2)};
  SplatLightResult r;
  splat_light_pass_bando2003(params(), ps, tex, r);
  EXPECT_FLOAT_EQ(r.reach[0], 1.0f);  // nearest reads 1
  EXPECT_NEAR(r.reach[1], 0.6, 1e-6);
  // Flip the light: the other particle is the nearest now; the light map is the same product.
  SplatLightParams back = params();
  back.travel = Vec3(0, 0, 1);
  SplatLightResult s;
  splat_light_pass_bando2003(back, ps, tex, s);
  EXPECT_NEAR(s.reach[0], 0.8, 1e-6);
  EXPECT_FLOAT_EQ(s.reach[1], 1.0f);
  EXPECT_NEAR(px(s, 32, 32), 0.6 * 0.8, 1e-6);
  EXPECT_NEAR(px(r, 32, 32), px(s, 32, 32), 1e-7);
  // Order helper: ascending travel . pos, stable on ties.
  std::vector<LightSplatParticle> t = {particle(0, 1), particle(1, 1), particle(0, 1),
                                       particle(-1, 1)};
  EXPECT_EQ(splat_light_order(Vec3(0, 0, -1), t), (std::vector<int32_t>{1, 0, 2, 3}));
  EXPECT_EQ(splat_light_order(Vec3(0, 0, 1), t), (std::vector<int32_t>{3, 0, 2, 1}));
}

TEST(SplatLightCpu, ParticleOutsideTheBufferReadsFullLight) {
  const SplatAlphaTexture tex(white());
  std::vector<LightSplatParticle> ps = {particle(0.5, 1.0), particle(-0.5, 0.5)};
  ps[1].pos.x() = 3.0;  // off the buffer
  SplatLightResult r;
  splat_light_pass_bando2003(params(), ps, tex, r);
  EXPECT_FLOAT_EQ(r.reach[1], 1.0f);
  EXPECT_NEAR(px(r, 32, 32), 0.0, 1e-7);  // the opaque one blocks all light
}

TEST(SplatLightCpu, MipChainAveragesAndLevelSelectionFollowsGl) {
  image::ImageRGBA8 img(4, 4, uint8_t(0));
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) img.at(x, y, 3) = (x + y) % 2 ? 255 : 0;  // checker
  const SplatAlphaTexture tex(img);
  ASSERT_EQ(tex.levels(), 3);
  EXPECT_EQ(tex.width(1), 2);
  EXPECT_EQ(tex.height(2), 1);
  EXPECT_NEAR(tex.sample(0.3, 0.6, 1), 128.0 / 255, 1e-6);  // 2x2 box of the checker, rounded
  EXPECT_NEAR(tex.sample(0.125, 0.125, 0), 0.0, 1e-7);      // texel centre
  EXPECT_NEAR(tex.sample(0.375, 0.125, 0), 1.0, 1e-7);
  EXPECT_NEAR(tex.sample(0.25, 0.125, 0), 0.5, 1e-7);  // bilinear half way
  EXPECT_EQ(tex.level_for(0.5), 0);                    // magnified
  EXPECT_EQ(tex.level_for(1.4), 0);                    // lambda < 1/2
  EXPECT_EQ(tex.level_for(2.0), 1);
  EXPECT_EQ(tex.level_for(64.0), 2);  // clamped to the last level
}

TEST(SplatLightCpu, SameInputGivesSameOutput) {
  const RenderScene s = make_hair_sheet_scene(800);
  const auto& set = *s.particles[0].particles;
  std::vector<LightSplatParticle> ps;
  for (std::size_t i = 0; i < set.positions.size(); ++i) {
    LightSplatParticle p;
    p.pos = set.positions[i].cast<double>();
    p.t = set.directions[i].cast<double>().normalized();
    p.half_w = 0.006;
    p.half_l = 0.018;
    p.alpha = 0.5;
    ps.push_back(p);
  }
  SplatLightParams prm;
  prm.size = 128;
  prm.travel = Vec3(0.3, -0.9, 0.3).normalized();
  const Vec3 d = prm.travel, up = Vec3(1, 0, 0).cross(d).normalized(), side = d.cross(up);
  prm.light_vp = Mat4::Identity();
  prm.light_vp.block<1, 3>(0, 0) = 4 * side.transpose();
  prm.light_vp.block<1, 3>(1, 0) = 4 * up.transpose();
  prm.light_vp.block<1, 3>(2, 0) = d.transpose();
  const SplatAlphaTexture tex(make_hair_texture());
  SplatLightResult a, b;
  splat_light_pass_bando2003(prm, ps, tex, a);
  splat_light_pass_bando2003(prm, ps, tex, b);
  EXPECT_TRUE(a.light == b.light);
  EXPECT_TRUE(a.reach == b.reach);
  // Some light is blocked and the reads fall with depth on average.
  double lo = 1;
  for (float v : a.light) lo = std::min(lo, double(v));
  EXPECT_LT(lo, 0.5);
  const auto order = splat_light_order(prm.travel, ps);
  double first = 0, last = 0;
  const std::size_t k = order.size() / 5;
  for (std::size_t i = 0; i < k; ++i) {
    first += a.reach[std::size_t(order[i])];
    last += a.reach[std::size_t(order[order.size() - 1 - i])];
  }
  EXPECT_GT(first, last);
}

TEST(SplatLightCpu, BadInputFailsCleanly) {
  const SplatAlphaTexture tex(white());
  const std::vector<LightSplatParticle> ok = {particle(0, 0.5)};
  SplatLightResult r;
  auto expect_error = [&](const SplatLightParams& p, const std::vector<LightSplatParticle>& ps,
                          const char* word) {
    try {
      splat_light_pass_bando2003(p, ps, tex, r);
      ADD_FAILURE() << "no error for " << word;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
    }
  };
  SplatLightParams p = params();
  p.size = 0;
  expect_error(p, ok, "size");
  p = params();
  p.light_vp(3, 2) = -1;  // perspective
  expect_error(p, ok, "orthographic");
  p = params();
  p.travel = Vec3(0, 0, -2);
  expect_error(p, ok, "direction");
  auto bad = ok;
  bad[0].pos.x() = std::nan("");
  expect_error(params(), bad, "position");
  bad = ok;
  bad[0].alpha = 1.5;
  expect_error(params(), bad, "opacity");
  bad = ok;
  bad[0].t = Vec3(0, 0, 0);
  expect_error(params(), bad, "direction");
  bad = ok;
  bad[0].half_w = 0;
  expect_error(params(), bad, "half-width");
  bad = ok;
  bad[0].vis = -0.1;
  expect_error(params(), bad, "visibility");
  EXPECT_THROW(SplatAlphaTexture{image::ImageRGBA8{}}, Error);
  // No particles: a white buffer.
  splat_light_pass_bando2003(params(), {}, tex, r);
  EXPECT_EQ(r.light.size(), std::size_t(kSize * kSize));
  EXPECT_TRUE(r.reach.empty());
  for (float v : r.light) ASSERT_EQ(v, 1.0f);
}

// ---- against the GPU pass ---------------------------------------------------------------------

namespace {

RenderSettings small_settings(int w, int h) {
  RenderSettings r;
  r.width = w;
  r.height = h;
  r.supersample = 1;
  r.shadow_map_size = 1024;
  r.hair_light_map_size = 256;
  return r;
}

void maybe_save(const image::ImageRGBA8& img, const std::string& name) {
  if (const char* d = std::getenv("FOLLICLE_RENDER_TEST_OUT"))
    image::write_png(std::filesystem::path(d) / name, img);
}

/// Mean absolute luminance difference relative to the mean luminance, and the largest one.
std::pair<double, double> image_diff(const image::ImageRGBA8& a, const image::ImageRGBA8& b) {
  double diff = 0, sum = 0, worst = 0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) {
      const double d = std::abs(luminance(a, x, y) - luminance(b, x, y));
      diff += d;
      worst = std::max(worst, d);
      sum += luminance(a, x, y);
    }
  return {sum > 0 ? diff / sum : 1.0, worst};
}

}  // namespace

class SplatLightGl : public RenderTest {
 protected:
  /// Renders `s` with the exact GPU pass (one slice per particle) and the CPU pass: the images
  /// agree closely, and far more closely than with the effect `off` switches off (so the
  /// comparison measures something).
  void expect_cpu_matches_exact_gpu(RenderScene s, RenderSettings gpu, const std::string& tag,
                                    void (*off)(RenderScene&)) {
    gpu.hair_light_pass = "gpu";
    gpu.hair_light_slices = 1 << 20;  // >= the particle count: per-particle reads on the GPU
    RenderSettings cpu = gpu;
    cpu.hair_light_pass = "cpu";
    const auto a = renderer().render(s, gpu);
    const auto b = renderer().render(s, cpu);
    maybe_save(a, "splat_light_" + tag + "_gpu.png");
    maybe_save(b, "splat_light_" + tag + "_cpu.png");
    const auto [rel, worst] = image_diff(a, b);
    EXPECT_LT(rel, 0.01) << "worst pixel " << worst;
    EXPECT_LT(worst, 12.0);
    off(s);
    const double effect = image_diff(b, renderer().render(s, cpu)).first;
    EXPECT_GT(effect, 4 * rel) << tag << ": effect " << effect << ", cpu vs gpu " << rel;
  }
};

TEST_F(SplatLightGl, CpuPassMatchesTheGpuPassWithOneSlicePerParticle) {
  // The synthetic head with hanging hair: hair self-shadowing and the light map on the head.
  RenderScene s = make_hair_sheet_scene(1200);
  RenderSettings gpu = small_settings(160, 160);
  gpu.hair_light_map_size = 384;
  // Self-shadowing is on in both: switching it off changes the image far more than the pass.
  expect_cpu_matches_exact_gpu(s, gpu, "sheet",
                               [](RenderScene& r) { r.particles[0].splat.self_shadow = false; });
}

TEST_F(SplatLightGl, CpuPassShadowsTheHeadLikeTheGpuPass) {
  // Hair above a sphere lit from above: the light map darkens the sphere under the hair the
  // same way with both passes.
  RenderScene s;
  s.camera.eye = Vec3(0, 0.4, 4);
  s.camera.target = Vec3(0, 0.3, 0);
  s.camera.fov_y = 0.8;
  s.background = Vec3(0, 0, 0);
  s.ambient_color = Vec3(0, 0, 0);
  DirectionalLight l;
  l.direction = Vec3(0.2, -1, 0.1).normalized();
  s.lights.push_back(l);
  MeshItem m;
  m.mesh = make_sphere(1.0);
  m.material.specular = 0;
  m.material.ambient = 0;
  s.meshes.push_back(m);
  auto ps = std::make_shared<geom::ParticleSet>();
  for (int k = 0; k < 6; ++k)
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 6; ++i) {
        ps->positions.emplace_back(float(-0.8 + 0.1 * i), float(1.3 + 0.08 * j),
                                   float(0.2 + 0.1 * k));
        ps->directions.emplace_back(1.0f, 0.1f * float(k - 3), 0.0f);
      }
  ParticleItem it;
  it.particles = ps;
  it.shading = ParticleShading::HairSplat;
  it.radius = 0.06;
  it.opacity = 0.5;
  s.particles.push_back(it);
  // The shadow on the sphere is really there: without casting it the image changes far more.
  expect_cpu_matches_exact_gpu(s, small_settings(128, 128), "head",
                               [](RenderScene& r) { r.particles[0].splat.cast_shadow = false; });
}

TEST_F(SplatLightGl, UnknownLightPassFails) {
  RenderScene s = make_hair_sheet_scene(100);
  RenderSettings rs = small_settings(32, 32);
  rs.hair_light_pass = "fpga";
  try {
    (void)renderer().render(s, rs);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("hair_light_pass"), std::string::npos) << e.what();
  }
}
