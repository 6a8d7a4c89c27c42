// The CPU per-particle light pass of Bando 2003 §3.4 (pseudo-code lines 6-12,
// splat_light_bando2003.hpp): analytic cases, order, bad input, and against the GPU pass with
// one slice per particle (the paper's algorithm on the GPU).
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>

#include "follicle/core/rng.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/render/camera.hpp"
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

// ---- the parallel pass against the sequential loop ---------------------------------------------
//
// splat_light_pass_bando2003() runs the loop over bands of buffer rows in parallel; it must give
// exactly (bit for bit) the values of the paper's sequential loop, written out here directly
// (same arithmetic, one buffer, one particle after the other).

namespace {

float ref_bilinear(const std::vector<float>& img, int w, int h, double x, double y) {
  x -= 0.5;
  y -= 0.5;
  const double fx0 = std::floor(x), fy0 = std::floor(y);
  const float fx = float(x - fx0), fy = float(y - fy0);
  const int x0 = int(fx0), y0 = int(fy0);
  const int xa = std::clamp(x0, 0, w - 1), xb = std::clamp(x0 + 1, 0, w - 1);
  const int ya = std::clamp(y0, 0, h - 1), yb = std::clamp(y0 + 1, 0, h - 1);
  const float* ra = img.data() + std::size_t(ya) * std::size_t(w);
  const float* rb = img.data() + std::size_t(yb) * std::size_t(w);
  const float top = ra[xa] + fx * (ra[xb] - ra[xa]);
  const float bot = rb[xa] + fx * (rb[xb] - rb[xa]);
  return top + fy * (bot - top);
}

float ref_padded_bilinear(const float* a, int stride, float x, float y) {
  const int ix = int(x), iy = int(y);
  const float fx = x - float(ix), fy = y - float(iy);
  const float* r0 = a + std::size_t(iy) * std::size_t(stride) + std::size_t(ix);
  const float* r1 = r0 + stride;
  const float top = r0[0] + fx * (r0[1] - r0[0]);
  const float bot = r1[0] + fx * (r1[1] - r1[0]);
  return top + fy * (bot - top);
}

void ref_unit_interval(double c, double k, double& lo, double& hi) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  if (std::abs(k) < 1e-300) {
    lo = c >= 0 && c <= 1 ? -inf : inf;
    hi = c >= 0 && c <= 1 ? inf : -inf;
    return;
  }
  const double a = -c / k, b = (1 - c) / k;
  lo = std::min(a, b);
  hi = std::max(a, b);
}

/// The sequential loop of Bando 2003 §3.4 lines 6-12 (valid input assumed).
SplatLightResult sequential_light_pass(const SplatLightParams& prm,
                                       const std::vector<LightSplatParticle>& ps,
                                       const SplatAlphaTexture& texture) {
  const int size = prm.size;
  const Mat4& vp = prm.light_vp;
  const double half = 0.5 * size / vp(3, 3);
  Eigen::Matrix<double, 2, 3> A;
  A.row(0) = half * vp.block<1, 3>(0, 0);
  A.row(1) = half * vp.block<1, 3>(1, 0);
  const Vec2 b(half * vp(0, 3) + 0.5 * size, half * vp(1, 3) + 0.5 * size);
  auto window = [&](const Vec3& p) -> Vec2 { return A * p + b; };
  SplatLightResult out;
  out.light.assign(std::size_t(size) * std::size_t(size), 1.0f);
  out.reach.assign(ps.size(), 1.0f);
  std::vector<float>& buf = out.light;
  auto read = [&](const Vec3& p) -> double {
    const Vec2 w = window(p);
    if (!(w.x() >= 0 && w.x() <= size && w.y() >= 0 && w.y() <= size)) return 1.0;
    return double(ref_bilinear(buf, size, size, w.x(), w.y()));
  };
  const int tw = texture.width(), th = texture.height();
  for (const int32_t idx : splat_light_order(prm.travel, ps)) {
    const LightSplatParticle& p = ps[std::size_t(idx)];
    // billboard_axes()
    Vec3 tp = p.t - p.t.dot(prm.travel) * prm.travel;
    double st = tp.norm();
    if (st < 1e-6) {
      tp = prm.travel.cross(std::abs(prm.travel.x()) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0));
      st = 0;
    }
    const Vec3 along = tp.normalized(), across = prm.travel.cross(along).normalized();
    const double s = std::max(st, p.min_sin);
    const Vec3 da = 0.5 * p.half_l * s * along, dc = 0.5 * p.half_w * across;
    out.reach[std::size_t(idx)] =
        float(0.4 * read(p.pos) +
              0.15 * (read(p.pos + da) + read(p.pos - da) + read(p.pos + dc) + read(p.pos - dc)));
    const double a = std::min(1.0, p.alpha / s * p.opacity_scale) * p.vis * (p.casts ? 1.0 : 0.0);
    if (!(a > 0)) continue;
    const Vec3 eu = 2 * p.half_w * across, ev = 2 * p.half_l * s * along;
    const Vec2 w0 = window(p.pos - 0.5 * eu - 0.5 * ev);
    const Vec2 wu = A * eu, wv = A * ev;
    const double det = wu.x() * wv.y() - wu.y() * wv.x();
    if (!(std::abs(det) > 1e-12)) continue;
    const double m00 = wv.y() / det, m01 = -wv.x() / det, m10 = -wu.y() / det, m11 = wu.x() / det;
    const double rho = std::max(std::hypot(tw * m00, th * m10), std::hypot(tw * m01, th * m11));
    const int level = texture.level_for(rho);
    const float* tex = texture.padded(level);
    const int lw = texture.width(level), lh = texture.height(level), stride = lw + 2;
    double ymin = w0.y(), ymax = w0.y();
    for (const Vec2& c : {Vec2(w0 + wu), Vec2(w0 + wv), Vec2(w0 + wu + wv)}) {
      ymin = std::min(ymin, c.y());
      ymax = std::max(ymax, c.y());
    }
    const int y0 = std::max(0, int(std::ceil(ymin - 0.5)));
    const int y1 = std::min(size - 1, int(std::ceil(ymax - 0.5)) - 1);
    for (int y = y0; y <= y1; ++y) {
      const double py = y + 0.5 - w0.y();
      const double cu = m01 * py - m00 * w0.x(), cv = m11 * py - m10 * w0.x();
      double ulo, uhi, vlo, vhi;
      ref_unit_interval(cu, m00, ulo, uhi);
      ref_unit_interval(cv, m10, vlo, vhi);
      const double lo = std::max(ulo, vlo), hi = std::min(uhi, vhi);
      if (!(lo <= hi)) continue;
      const int x0 = std::max(0, int(std::ceil(std::max(lo - 0.5, -1.0))));
      const int x1 = std::min(size - 1, int(std::ceil(std::min(hi - 0.5, double(size)))) - 1);
      const double tx0 = (cu + m00 * (x0 + 0.5)) * lw + 0.5,
                   ty0 = (cv + m10 * (x0 + 0.5)) * lh + 0.5;
      const float dtx = float(m00 * lw), dty = float(m10 * lh);
      const float fa = float(a);
      float* row = buf.data() + std::size_t(y) * std::size_t(size);
      for (int x = x0; x <= x1; ++x) {
        const float k = float(x - x0);
        const float tx = std::clamp(float(tx0) + k * dtx, 0.5f, float(lw) + 0.5f);
        const float ty = std::clamp(float(ty0) + k * dty, 0.5f, float(lh) + 0.5f);
        row[x] *= 1.0f - fa * ref_padded_bilinear(tex, stride, tx, ty);
      }
    }
  }
  return out;
}

/// Bit-for-bit equality of two light pass results (EXPECT_EQ on the floats), reporting the
/// first differing pixel / particle and how many differ.
void expect_identical(const SplatLightResult& want, const SplatLightResult& got, int size,
                      const std::string& what) {
  ASSERT_EQ(want.light.size(), got.light.size()) << what;
  ASSERT_EQ(want.reach.size(), got.reach.size()) << what;
  std::size_t bad = 0;
  for (std::size_t i = 0; i < want.light.size(); ++i) {
    if (want.light[i] == got.light[i]) continue;
    if (bad++ == 0) {
      EXPECT_EQ(want.light[i], got.light[i]) << what << ": light at (" << i % std::size_t(size)
                                             << ", " << i / std::size_t(size) << ")";
    }
  }
  EXPECT_EQ(bad, 0u) << what << ": light buffer pixels differ";
  bad = 0;
  for (std::size_t i = 0; i < want.reach.size(); ++i) {
    if (want.reach[i] == got.reach[i]) continue;
    if (bad++ == 0) {
      EXPECT_EQ(want.reach[i], got.reach[i]) << what << ": reach of particle " << i;
    }
  }
  EXPECT_EQ(bad, 0u) << what << ": reads differ";
}

/// The particle pass under `threads` TBB threads.
SplatLightResult run_in_arena(int threads, const SplatLightParams& prm,
                              const std::vector<LightSplatParticle>& ps,
                              const SplatAlphaTexture& tex, int band_rows = 0) {
  SplatLightResult r;
  tbb::task_arena arena(threads);
  arena.execute([&] {
    if (band_rows > 0)
      detail::splat_light_pass_bando2003_banded(prm, ps, tex, r, band_rows);
    else
      splat_light_pass_bando2003(prm, ps, tex, r);
  });
  return r;
}

/// The hair of make_hair_sheet_scene() as the renderer feeds it to the pass (SplatMaterial
/// defaults: half-width r, half-length 3 r, min sin 0.25), lit by the scene's key light with
/// the renderer's shadow projection fitted to head and hair; some particles partly in the
/// objects' shadow, a few not casting, varied shadow opacity.
std::pair<SplatLightParams, std::vector<LightSplatParticle>> hair_sheet_pass(int count, int size) {
  const RenderScene s = make_hair_sheet_scene(count);
  const ParticleItem& item = s.particles[0];
  const auto& set = *item.particles;
  std::vector<LightSplatParticle> ps;
  Eigen::AlignedBox3d box(Vec3::Constant(-0.1), Vec3::Constant(0.1));  // the head
  Rng rng(7);
  for (std::size_t i = 0; i < set.positions.size(); ++i) {
    LightSplatParticle p;
    p.pos = set.positions[i].cast<double>();
    p.t = set.directions[i].cast<double>().normalized();
    p.half_w = item.radius * item.splat.width_scale;
    p.half_l = item.radius * item.splat.length_scale;
    p.alpha = item.opacity;
    p.min_sin = item.splat.min_sin_theta;
    p.vis = rng.uniform() < 0.2 ? rng.uniform() : 1.0;
    p.casts = rng.uniform() < 0.95;
    p.opacity_scale = rng.uniform(0.5, 1.5);
    const double e = std::max(p.half_w, p.half_l);
    box.extend(p.pos - Vec3::Constant(e));
    box.extend(p.pos + Vec3::Constant(e));
    ps.push_back(p);
  }
  const Vec3 dir = s.lights[0].direction.normalized();
  const Vec3 c = box.center();
  const double r = 0.5 * box.diagonal().norm();
  SplatLightParams prm;
  prm.light_vp =
      orthographic(-r, r, -r, r, r * 0.5, r * 3.5) * look_at(c - dir * (2 * r), c, Vec3(0, 1, 0));
  prm.travel = dir;
  prm.size = size;
  return {prm, ps};
}

/// Random particles over (and a little beyond) the buffer of params() scaled to `size`: varied
/// sizes, directions (some along the light: edge-on and clamped sin(theta)), opacities, many
/// billboards straddling band boundaries and the buffer edges.
std::vector<LightSplatParticle> random_particles(int count, int size, uint64_t seed) {
  Rng rng(seed);
  std::vector<LightSplatParticle> ps;
  const double px = 2.0 / size;  // world units per pixel
  for (int i = 0; i < count; ++i) {
    LightSplatParticle p;
    p.pos = Vec3(rng.uniform(-1.1, 1.1), rng.uniform(-1.1, 1.1), rng.uniform(-1, 1));
    Vec3 t(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    if (i % 17 == 0) t = Vec3(0, 0, 1);  // along the light
    p.t = t.norm() > 1e-3 ? t.normalized() : Vec3(0, 1, 0);
    p.half_w = rng.uniform(0.3, 4) * px;
    p.half_l = rng.uniform(0.5, 12) * px;
    p.alpha = rng.uniform(0.05, 0.9);
    p.min_sin = rng.uniform(0.1, 1.0);
    p.vis = rng.uniform() < 0.1 ? 0.0 : 1.0;
    ps.push_back(p);
  }
  return ps;
}

SplatLightParams params_of_size(int size) {
  SplatLightParams p = params();
  p.size = size;
  return p;
}

/// Enough of the buffer is darkened and enough reads see it that a wrong band (a read of a
/// row split across bands at the wrong time, a particle skipped) would change values.
void expect_substantial(const SplatLightResult& r) {
  std::size_t dark = 0, shaded = 0;
  for (float v : r.light) dark += v < 0.9f ? 1 : 0;
  for (float v : r.reach) shaded += v < 0.9f ? 1 : 0;
  EXPECT_GT(dark, r.light.size() / 50);
  EXPECT_GT(shaded, r.reach.size() / 10);
}

}  // namespace

TEST(SplatLightCpuParallel, HairSheetMatchesTheSequentialLoopBitForBit) {
  const SplatAlphaTexture tex(make_hair_texture());
  for (const int size : {64, 511, 512}) {
    const auto [prm, ps] = hair_sheet_pass(2000, size);
    const SplatLightResult want = sequential_light_pass(prm, ps, tex);
    expect_substantial(want);
    SplatLightResult got;
    splat_light_pass_bando2003(prm, ps, tex, got);
    expect_identical(want, got, size, "size " + std::to_string(size));
    for (const int threads : {1, 2})
      expect_identical(
          want, run_in_arena(threads, prm, ps, tex), size,
          "size " + std::to_string(size) + ", " + std::to_string(threads) + " thread(s)");
  }
}

TEST(SplatLightCpuParallel, ResultDoesNotDependOnBandHeightOrThreads) {
  // Band heights from one row (every read split across two bands) to the whole buffer
  // (no boundary), odd heights whose last band is short, sizes that are not multiples of them.
  const SplatAlphaTexture tex(make_hair_texture());
  for (const int size : {37, 64, 100}) {
    const SplatLightParams prm = params_of_size(size);
    const auto ps = random_particles(600, size, uint64_t(size));
    const SplatLightResult want = sequential_light_pass(prm, ps, tex);
    expect_substantial(want);
    for (const int rows : {1, 2, 3, 7, 16, 33, size - 1, size, 4 * size})
      for (const int threads : {1, 2})
        expect_identical(want, run_in_arena(threads, prm, ps, tex, rows), size,
                         "size " + std::to_string(size) + ", band height " + std::to_string(rows) +
                             ", " + std::to_string(threads) + " thread(s)");
  }
  SplatLightResult r;
  EXPECT_THROW(detail::splat_light_pass_bando2003_banded(params(), {}, tex, r, 0), Error);
}

TEST(SplatLightCpuParallel, TapsOnBandBoundariesAndBufferEdgesMatchTheSequentialLoop) {
  // params(): 64^2, window = 32 (world + 1), so the particles below put billboard edges and
  // read taps exactly on rows 0, 16, 32, 48, 64 (band boundaries for heights 1, 2, 16, 32) and
  // half a row beside them; hair direction +y: the taps at +-da are half_l / 2 above and below
  // the centre, those at +-dc half_w / 2 left and right.
  auto at = [](double wx, double wy, double z, double half_w_px, double half_l_px, double alpha) {
    LightSplatParticle p = particle(z, alpha);
    p.pos = Vec3(wx / 32 - 1, wy / 32 - 1, z);
    p.half_w = half_w_px / 32;
    p.half_l = half_l_px / 32;
    return p;
  };
  std::vector<LightSplatParticle> ps;
  // Nearest: horizontal stripes across the buffer ending exactly on band boundaries (row 15
  // dark, row 16 not), straddling them, and running off the buffer's edges.
  ps.push_back(at(32, 8, 0.9, 40, 8, 0.5));       // rows 0..15
  ps.push_back(at(32, 24, 0.85, 40, 8, 0.25));    // rows 16..31
  ps.push_back(at(20, 40, 0.8, 12, 8, 0.6));      // rows 32..47, x 8..31
  ps.push_back(at(44, 32, 0.75, 9, 5, 0.4));      // rows 27..36, straddles 32
  ps.push_back(at(2, 62, 0.7, 7, 6.5, 0.7));      // off the left and top edges
  ps.push_back(at(63, 1.5, 0.65, 5.5, 9, 0.45));  // off the right and bottom edges
  ps.push_back(at(-3, 20, 0.6, 4, 4, 0.9));       // outside: covers no pixel
  {
    LightSplatParticle tilted = at(30, 30, 0.55, 6, 20, 0.5);
    tilted.t = Vec3(std::sin(0.5), std::cos(0.5), 0);  // crosses several band boundaries
    ps.push_back(tilted);
  }
  // Farther: probes whose taps fall on and half a row beside band boundaries and the buffer's
  // edges (y = 0 and 64 are inside, reading the clamped edge rows; beyond reads 1), each
  // splatting a little so later probes read it too.
  double z = 0.5;
  for (const double cy : {0.0, 0.25, 15.5, 16.0, 16.5, 31.75, 32.0, 47.999, 48.0, 63.75, 64.0})
    for (const double cx : {0.0, 0.5, 20.0, 43.25, 63.5, 64.0})
      for (const double h : {1.0, 16.0, 32.0}) {
        ps.push_back(at(cx, cy, z, h, h, 0.2));
        z -= 0.001;
      }
  // Centres just outside the buffer: with a tiny footprint all 5 taps are outside (read 1),
  // with a larger one the taps along the hair reach inside.
  ps.push_back(at(32, 64 + 1.0 / 64, z, 1.0 / 64, 1.0 / 64, 0.3));
  ps.push_back(at(20, -1.0 / 64, z - 0.001, 1.0 / 64, 1.0 / 64, 0.3));
  ps.push_back(at(40, 64 + 1.0 / 64, z - 0.002, 2, 2, 0.3));
  ps.push_back(at(64 + 1.0 / 64, 30, z - 0.003, 2, 2, 0.3));
  const SplatAlphaTexture tex(make_hair_texture());
  const SplatLightResult want = sequential_light_pass(params(), ps, tex);
  // The stripes really make rows 15 and 16 (and 31, 32) differ, and the probes read them.
  EXPECT_NE(px(want, 10, 15), px(want, 10, 16));
  EXPECT_NE(px(want, 10, 31), px(want, 10, 32));
  std::size_t shaded = 0;
  for (float v : want.reach) shaded += v < 0.95f ? 1 : 0;
  EXPECT_GT(shaded, want.reach.size() / 3);
  EXPECT_EQ(want.reach[ps.size() - 4], 1.0f);
  EXPECT_EQ(want.reach[ps.size() - 3], 1.0f);
  EXPECT_LT(want.reach[ps.size() - 2], 1.0f);
  SplatLightResult got;
  splat_light_pass_bando2003(params(), ps, tex, got);
  expect_identical(want, got, kSize, "default bands");
  for (const int rows : {1, 2, 15, 16, 17, 32, 64})
    for (const int threads : {1, 2})
      expect_identical(
          want, run_in_arena(threads, params(), ps, tex, rows), kSize,
          "band height " + std::to_string(rows) + ", " + std::to_string(threads) + " thread(s)");
  // The same with the white texture (full-strength splats, sharper edges).
  const SplatAlphaTexture flat(white());
  const SplatLightResult want_flat = sequential_light_pass(params(), ps, flat);
  for (const int rows : {1, 16, 32})
    expect_identical(want_flat, run_in_arena(2, params(), ps, flat, rows), kSize,
                     "white texture, band height " + std::to_string(rows));
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
