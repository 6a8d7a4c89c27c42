// The per-particle light pass of Bando 2003 §3.4 (pseudo-code lines 6-12) on the CPU; see
// splat_light_bando2003.hpp and docs/adr/0005-cpu-splat-light-pass.md.
#include "follicle/render/splat_light_bando2003.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

#include "follicle/core/error.hpp"
#include "follicle/render/splat_bando2003.hpp"

namespace follicle::render {
namespace {

/// Where a bilinear read of a w x h row-major float image with clamped edges samples: rows ya
/// and yb (yb is ya or ya + 1), columns xa and xb, weights fx and fy.
struct BilinearTap {
  int xa = 0, xb = 0, ya = 0, yb = 0;
  float fx = 0, fy = 0;
};

/// The taps of a bilinear read at (x, y) in texel units with texel centres at integer + 1/2.
BilinearTap bilinear_tap(int w, int h, double x, double y) {
  x -= 0.5;
  y -= 0.5;
  const double fx0 = std::floor(x), fy0 = std::floor(y);
  BilinearTap t;
  t.fx = float(x - fx0);
  t.fy = float(y - fy0);
  const int x0 = int(fx0), y0 = int(fy0);
  t.xa = std::clamp(x0, 0, w - 1);
  t.xb = std::clamp(x0 + 1, 0, w - 1);
  t.ya = std::clamp(y0, 0, h - 1);
  t.yb = std::clamp(y0 + 1, 0, h - 1);
  return t;
}

/// The horizontal half of a bilinear read of `t` in one of its rows `r`.
inline float bilinear_row(const float* r, const BilinearTap& t) {
  return r[t.xa] + t.fx * (r[t.xb] - r[t.xa]);
}

/// The vertical half: the read of `t` from its rows' values `top` (row ya) and `bot` (row yb).
inline float bilinear_mix(float top, float bot, const BilinearTap& t) {
  return top + t.fy * (bot - top);
}

/// Bilinear read of a row-major float image with clamped edges; (x, y) in texel units with
/// texel centres at integer + 1/2.
float bilinear(const std::vector<float>& img, int w, int h, double x, double y) {
  const BilinearTap t = bilinear_tap(w, h, x, y);
  return bilinear_mix(bilinear_row(img.data() + std::size_t(t.ya) * std::size_t(w), t),
                      bilinear_row(img.data() + std::size_t(t.yb) * std::size_t(w), t), t);
}

/// [lo, hi] of x where 0 <= c + k x <= 1 (empty: lo > hi).
void unit_interval(double c, double k, double& lo, double& hi) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  if (std::abs(k) < 1e-300) {
    if (c >= 0 && c <= 1) {
      lo = -inf;
      hi = inf;
    } else {
      lo = inf;
      hi = -inf;
    }
    return;
  }
  const double a = -c / k, b = (1 - c) / k;
  lo = std::min(a, b);
  hi = std::max(a, b);
}

void check_particle(const LightSplatParticle& p, std::size_t i) {
  auto bad = [&](const char* what, double v) {
    fail("splat light pass: particle {} {} {} is invalid", i, what, v);
  };
  if (!p.pos.allFinite()) fail("splat light pass: particle {} position is not finite", i);
  if (!p.t.allFinite() || std::abs(p.t.norm() - 1) > 1e-3)
    fail("splat light pass: particle {} direction is not a finite unit vector", i);
  if (!(std::isfinite(p.half_w) && p.half_w > 0)) bad("half-width", p.half_w);
  if (!(std::isfinite(p.half_l) && p.half_l > 0)) bad("half-length", p.half_l);
  if (!(p.alpha >= 0 && p.alpha <= 1)) bad("opacity", p.alpha);
  if (!(p.min_sin > 0 && p.min_sin <= 1)) bad("min sin(theta)", p.min_sin);
  if (!(std::isfinite(p.opacity_scale) && p.opacity_scale >= 0))
    bad("shadow opacity scale", p.opacity_scale);
  if (!(p.vis >= 0 && p.vis <= 1)) bad("objects' visibility", p.vis);
}

}  // namespace

namespace {

/// Bilinear read of a padded level (see SplatAlphaTexture::padded) at (x, y) in
/// [1/2, w + 1/2] x [1/2, h + 1/2]: padded texel coordinates shifted by -1/2, i.e. texel i's
/// centre is at i + 1 (u w + 1/2 for u in [0, 1]).
inline float padded_bilinear(const float* a, int stride, float x, float y) {
  const int ix = int(x), iy = int(y);  // x, y >= 0: truncation is floor
  const float fx = x - float(ix), fy = y - float(iy);
  const float* r0 = a + std::size_t(iy) * std::size_t(stride) + std::size_t(ix);
  const float* r1 = r0 + stride;
  const float top = r0[0] + fx * (r0[1] - r0[0]);
  const float bot = r1[0] + fx * (r1[1] - r1[0]);
  return top + fy * (bot - top);
}

std::vector<float> pad_level(const std::vector<float>& img, int w, int h) {
  const int sw = w + 2;
  std::vector<float> out(std::size_t(sw) * std::size_t(h + 2));
  for (int y = -1; y <= h; ++y)
    for (int x = -1; x <= w; ++x)
      out[std::size_t(y + 1) * std::size_t(sw) + std::size_t(x + 1)] =
          img[std::size_t(std::clamp(y, 0, h - 1)) * std::size_t(w) +
              std::size_t(std::clamp(x, 0, w - 1))];
  return out;
}

}  // namespace

SplatAlphaTexture::SplatAlphaTexture(const image::ImageRGBA8& img) {
  if (img.empty() || img.width() < 1 || img.height() < 1)
    fail("splat light pass: the hair texture is empty");
  int w = img.width(), h = img.height();
  std::vector<float> cur(std::size_t(w) * std::size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      cur[std::size_t(y) * std::size_t(w) + std::size_t(x)] = float(img.at(x, y, 3)) / 255.0f;
  for (;;) {
    m_levels.push_back(Level{w, h, pad_level(cur, w, h)});
    if (w == 1 && h == 1) break;
    // glGenerateMipmap: the next level is this one filtered linearly at the new texel centres
    // (a 2x2 box for even sizes), stored as 8-bit unorm like the GL texture.
    const int nw = std::max(1, w / 2), nh = std::max(1, h / 2);
    std::vector<float> next(std::size_t(nw) * std::size_t(nh));
    for (int y = 0; y < nh; ++y)
      for (int x = 0; x < nw; ++x) {
        const float v = bilinear(cur, w, h, (x + 0.5) * w / nw, (y + 0.5) * h / nh);
        next[std::size_t(y) * std::size_t(nw) + std::size_t(x)] = std::round(v * 255.0f) / 255.0f;
      }
    cur = std::move(next);
    w = nw;
    h = nh;
  }
}

int SplatAlphaTexture::level_for(double rho) const {
  // OpenGL 3.3 §3.8.11: lambda = log2(rho); MIPMAP_NEAREST takes level 0 for lambda <= 1/2,
  // else ceil(lambda + 1/2) - 1, clamped to the last level.
  if (!(rho > 0) || !std::isfinite(rho)) return 0;
  const double lambda = std::log2(rho);
  if (lambda <= 0.5) return 0;
  return std::min(levels() - 1, int(std::ceil(lambda + 0.5)) - 1);
}

float SplatAlphaTexture::sample(double u, double v, int level) const {
  const Level& l = m_levels[std::size_t(std::clamp(level, 0, levels() - 1))];
  // x = u w + 1/2 puts texel i's centre at i + 1 (its padded index); clamp-to-edge beyond the
  // edge texels' centres (the border repeats them).
  const double x = std::clamp(u * l.w + 0.5, 0.5, l.w + 0.5);
  const double y = std::clamp(v * l.h + 0.5, 0.5, l.h + 0.5);
  return padded_bilinear(l.a.data(), l.w + 2, float(x), float(y));
}

std::vector<int32_t> splat_light_order(const Vec3& travel,
                                       std::span<const LightSplatParticle> particles) {
  const std::size_t n = particles.size();
  std::vector<double> depth(n);
  for (std::size_t i = 0; i < n; ++i)
    depth[i] = travel.x() * particles[i].pos.x() + travel.y() * particles[i].pos.y() +
               travel.z() * particles[i].pos.z();
  std::vector<int32_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int32_t a, int32_t b) {
    return depth[std::size_t(a)] < depth[std::size_t(b)];
  });
  return order;
}

namespace {

/// Rows per band of the parallel light pass (see splat_light_pass_bando2003_banded()). Any
/// value gives the same result; 16 gives 2 threads enough bands to balance when the hair covers
/// only part of a 512^2 buffer, for one pass over the particles' row spans per band.
constexpr int kBandRows = 16;

/// One particle of the loop (line 8), set up once before the bands: its 5 line-9 reads and its
/// line-10 light-view billboard.
struct LightSplat {
  int32_t idx = 0;  // input index
  /// Line 9: where the 5 taps read the buffer; tap j is outside the buffer (reads 1) when
  /// inside[j] is false. Tap 0 is the centre, 1 and 2 at +-da, 3 and 4 at +-dc.
  std::array<BilinearTap, 5> tap{};
  std::array<bool, 5> inside{};
  /// Line 10: rows y0..y1 (none when y0 > y1) of the billboard (u, v) = M (x - w0), opacity
  /// fa, hair texture level `level`.
  int y0 = 0, y1 = -1;
  float fa = 0;
  Vec2 w0 = Vec2::Zero();
  double m00 = 0, m01 = 0, m10 = 0, m11 = 0;
  int level = 0;
};

/// Rows a particle touches: its splat rows and the rows its taps read (lo > hi: none).
struct RowSpan {
  int lo = std::numeric_limits<int>::max(), hi = std::numeric_limits<int>::min();
};

/// Line 10 for one row y of the billboard of `q`: row[x] *= 1 - a * alpha_tex over the pixel
/// centres of row y inside the billboard.
void splat_row(const LightSplat& q, int y, int size, const float* tex, int lw, int lh, float* row) {
  const int stride = lw + 2;
  const Vec2& w0 = q.w0;
  // Pixel centres (x + 1/2, y + 1/2) with u, v in [0, 1]: u and v are linear in x.
  const double py = y + 0.5 - w0.y();
  const double cu = q.m01 * py - q.m00 * w0.x(), cv = q.m11 * py - q.m10 * w0.x();
  double ulo, uhi, vlo, vhi;
  unit_interval(cu, q.m00, ulo, uhi);
  unit_interval(cv, q.m10, vlo, vhi);
  const double lo = std::max(ulo, vlo), hi = std::min(uhi, vhi);
  if (!(lo <= hi)) return;
  const int x0 = std::max(0, int(std::ceil(std::max(lo - 0.5, -1.0))));
  const int x1 = std::min(size - 1, int(std::ceil(std::min(hi - 0.5, double(size)))) - 1);
  // Padded texel coordinates of the level (u w + 1/2, v h + 1/2), linear along the row.
  const double tx0 = (cu + q.m00 * (x0 + 0.5)) * lw + 0.5,
               ty0 = (cv + q.m10 * (x0 + 0.5)) * lh + 0.5;
  const float dtx = float(q.m00 * lw), dty = float(q.m10 * lh);
  const float txlo = 0.5f, txhi = float(lw) + 0.5f, tylo = 0.5f, tyhi = float(lh) + 0.5f;
  const float fa = q.fa;
  for (int x = x0; x <= x1; ++x) {
    const float k = float(x - x0);
    const float tx = std::clamp(float(tx0) + k * dtx, txlo, txhi);
    const float ty = std::clamp(float(ty0) + k * dty, tylo, tyhi);
    row[x] *= 1.0f - fa * padded_bilinear(tex, stride, tx, ty);  // ZERO, 1 - SRC_ALPHA
  }
}

}  // namespace

void splat_light_pass_bando2003(const SplatLightParams& params,
                                std::span<const LightSplatParticle> particles,
                                const SplatAlphaTexture& texture, SplatLightResult& out) {
  // One thread: one band (no per-band overhead); the result is the same.
  const bool parallel = tbb::this_task_arena::max_concurrency() > 1;
  detail::splat_light_pass_bando2003_banded(params, particles, texture, out,
                                            parallel ? kBandRows : std::max(1, params.size));
}

void detail::splat_light_pass_bando2003_banded(const SplatLightParams& params,
                                               std::span<const LightSplatParticle> particles,
                                               const SplatAlphaTexture& texture,
                                               SplatLightResult& out, int band_rows) {
  if (band_rows < 1) fail("splat light pass: band height {} is not >= 1", band_rows);
  const int size = params.size;
  if (size < 1 || size > 16384)
    fail("splat light pass: light buffer size {} is outside [1, 16384]", size);
  if (!params.travel.allFinite() || std::abs(params.travel.norm() - 1) > 1e-6)
    fail("splat light pass: the light direction must be a finite unit vector");
  const Mat4& vp = params.light_vp;
  if (!vp.allFinite()) fail("splat light pass: the light projection is not finite");
  const double row3 = std::abs(vp(3, 0)) + std::abs(vp(3, 1)) + std::abs(vp(3, 2));
  if (row3 > 1e-9 * std::max(1.0, vp.topLeftCorner<3, 3>().norm()) || std::abs(vp(3, 3)) < 1e-12)
    fail("splat light pass: the light projection must be orthographic (a parallel light)");
  for (std::size_t i = 0; i < particles.size(); ++i) check_particle(particles[i], i);

  // Window coordinates (pixels, the buffer's texel units) of a world point: win = A p + b.
  const double half = 0.5 * size / vp(3, 3);
  Eigen::Matrix<double, 2, 3> A;
  A.row(0) = half * vp.block<1, 3>(0, 0);
  A.row(1) = half * vp.block<1, 3>(1, 0);
  const Vec2 b(half * vp(0, 3) + 0.5 * size, half * vp(1, 3) + 0.5 * size);
  auto window = [&](const Vec3& p) -> Vec2 { return A * p + b; };

  // Line 1 (and 6): a white buffer.
  const std::size_t n = particles.size();
  const std::size_t npix = std::size_t(size) * std::size_t(size);
  out.light.assign(npix, 1.0f);
  out.reach.assign(n, 1.0f);
  if (n == 0) return;
  const int tw = texture.width(), th = texture.height();

  // Line 7: ascending depth from the light.
  const std::vector<int32_t> order = splat_light_order(params.travel, particles);

  // The loop of lines 8-11 is sequential by definition (each read sees every earlier splat),
  // but a pixel only ever depends on the same pixel: the buffer is cut into bands of rows and
  // every band runs the whole loop on its own rows, in parallel. A bilinear read of rows ya and
  // yb = ya + 1 is a lerp within each row then one between the rows: at every particle's turn
  // the band holding ya computes the first row's lerp, the band holding yb the second's, and
  // the lerp between them is done after all bands, with the same float operations, so every
  // value is bit-identical to the sequential loop's for any band height and thread count.
  // First, per particle (in loop order k, in parallel): where its reads fall and its billboard.
  std::vector<LightSplat> splats(n);
  std::vector<RowSpan> spans(n);
  auto setup = [&](std::size_t k) {
    LightSplat& q = splats[k];
    RowSpan& span = spans[k];
    q.idx = order[k];
    const LightSplatParticle& p = particles[std::size_t(q.idx)];
    Vec3 along, across;
    double s = 1;
    splat_billboard_axes(p.t, params.travel, p.min_sin, along, across, s);
    // Line 9: the light reaching the particle, averaged over 5 taps of its footprint (the
    // same weights as kSplatGatherVs); a tap outside the buffer reads 1, as in
    // kSplatGatherVs's light_buffer().
    const Vec3 da = 0.5 * p.half_l * s * along, dc = 0.5 * p.half_w * across;
    const std::array<Vec3, 5> at = {p.pos, Vec3(p.pos + da), Vec3(p.pos - da), Vec3(p.pos + dc),
                                    Vec3(p.pos - dc)};
    for (std::size_t j = 0; j < 5; ++j) {
      const Vec2 w = window(at[j]);
      q.inside[j] = w.x() >= 0 && w.x() <= size && w.y() >= 0 && w.y() <= size;
      if (!q.inside[j]) continue;
      q.tap[j] = bilinear_tap(size, size, w.x(), w.y());
      span.lo = std::min(span.lo, q.tap[j].ya);
      span.hi = std::max(span.hi, q.tap[j].yb);
    }

    // Line 10: the light-view billboard (billboard_corner() with d_p = the light travel) of
    // opacity alpha/sin(theta) (§3.4) times the shadow opacity scale, not splatted when in
    // the objects' shadow (line 8, weighted by the PCF visibility) or not casting.
    const double a = std::min(1.0, p.alpha / s * p.opacity_scale) * p.vis * (p.casts ? 1.0 : 0.0);
    if (!(a > 0)) return;
    const Vec3 eu = 2 * p.half_w * across, ev = 2 * p.half_l * s * along;
    const Vec2 w0 = window(p.pos - 0.5 * eu - 0.5 * ev);  // corner uv = (0, 0)
    const Vec2 wu = A * eu, wv = A * ev;                  // window edges along u and v
    const double det = wu.x() * wv.y() - wu.y() * wv.x();
    if (!(std::abs(det) > 1e-12)) return;  // edge-on: covers no pixel centre
    // (u, v) = M (x - w0) with M the inverse of [wu wv].
    q.m00 = wv.y() / det;
    q.m01 = -wv.x() / det;
    q.m10 = -wu.y() / det;
    q.m11 = wu.x() / det;
    // Mip level from the texel footprint per pixel (constant: the projection is affine).
    const double rho =
        std::max(std::hypot(tw * q.m00, th * q.m10), std::hypot(tw * q.m01, th * q.m11));
    q.level = texture.level_for(rho);
    q.w0 = w0;
    q.fa = float(a);
    double ymin = w0.y(), ymax = w0.y();
    for (const Vec2& c : {Vec2(w0 + wu), Vec2(w0 + wv), Vec2(w0 + wu + wv)}) {
      ymin = std::min(ymin, c.y());
      ymax = std::max(ymax, c.y());
    }
    // Pixel centres inside the billboard, half-open like GL's rasterisation rule (a centre
    // on the top or right edge is not covered): y in [ymin, ymax), x in [lo, hi).
    q.y0 = std::max(0, int(std::ceil(ymin - 0.5)));
    q.y1 = std::min(size - 1, int(std::ceil(ymax - 0.5)) - 1);
    if (q.y0 <= q.y1) {
      span.lo = std::min(span.lo, q.y0);
      span.hi = std::max(span.hi, q.y1);
    }
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 64),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t k = r.begin(); k != r.end(); ++k) setup(k);
                    });

  // Lines 8-11 per band of rows [r0, r1); the row lerps of tap j of loop step k go to
  // top[5 k + j] (row ya) and bot[5 k + j] (row yb).
  std::vector<float> top(5 * n, 1.0f), bot(5 * n, 1.0f);
  float* const buf = out.light.data();
  const int nbands = (size + band_rows - 1) / band_rows;
  auto run_band = [&](int band) {
    const int r0 = band * band_rows, r1 = std::min(size, r0 + band_rows);
    auto row = [&](int y) { return buf + std::size_t(y) * std::size_t(size); };
    for (std::size_t k = 0; k < n; ++k) {  // line 8, in the order of line 7
      if (spans[k].hi < r0 || spans[k].lo >= r1) continue;
      const LightSplat& q = splats[k];
      for (std::size_t j = 0; j < 5; ++j) {  // line 9: the row lerps in this band
        const BilinearTap& t = q.tap[j];
        if (!q.inside[j]) continue;
        if (t.ya >= r0 && t.ya < r1) top[5 * k + j] = bilinear_row(row(t.ya), t);
        if (t.yb >= r0 && t.yb < r1) bot[5 * k + j] = bilinear_row(row(t.yb), t);
      }
      const int y0 = std::max(q.y0, r0), y1 = std::min(q.y1, r1 - 1);  // line 10
      if (y0 > y1) continue;
      const float* tex = texture.padded(q.level);
      const int lw = texture.width(q.level), lh = texture.height(q.level);
      for (int y = y0; y <= y1; ++y) splat_row(q, y, size, tex, lw, lh, row(y));
    }
  };
  tbb::parallel_for(tbb::blocked_range<int>(0, nbands, 1), [&](const tbb::blocked_range<int>& r) {
    for (int band = r.begin(); band != r.end(); ++band) run_band(band);
  });

  // Line 9: each tap's read, then their 5-tap average in the order and precision of
  // kSplatGatherVs's weights (a tap outside the buffer reads 1).
  for (std::size_t k = 0; k < n; ++k) {
    const LightSplat& q = splats[k];
    std::array<double, 5> v{};
    for (std::size_t j = 0; j < 5; ++j)
      v[j] = q.inside[j] ? double(bilinear_mix(top[5 * k + j], bot[5 * k + j], q.tap[j])) : 1.0;
    out.reach[std::size_t(q.idx)] = float(0.4 * v[0] + 0.15 * (v[1] + v[2] + v[3] + v[4]));
  }
  // Line 12: `buf` is the light map.
}

}  // namespace follicle::render
