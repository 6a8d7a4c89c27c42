// The view pass of Bando 2003 §3.4 (pseudo-code lines 17-21) on the CPU; see
// splat_view_bando2003.hpp and docs/adr/0007-cpu-splat-view-pass.md.
//
// Written here rather than taken from a library: what is needed is an exact reproduction of
// the GL pass's billboard (kSplatCommon's billboard_corner), its sampling and its blend, so
// that "cpu" and "gpu" view passes draw the same hair; a general software rasteriser would add
// its own conventions.
//
// Geometry. A billboard is the plane patch P(u, v) = O + u E_u + v E_v, (u, v) in [0, 1]^2
// (u across, v along the hair: the texture coordinates of billboard_corner). Its clip position
// is M (u, v, 1) with the 4x3 matrix M = VP [E_u 0 | E_v 0 | O 1]; the window position is the
// homography H = [W/2 (m0 + m3); H/2 (m1 + m3); m3] of (u, v, 1) (m_k the rows of M). Its inverse
// G maps a pixel centre (x, y, 1) to (a, b, q) = (u, v, 1) / w_clip: q = 1 / w_clip > 0 in front
// of the eye, u = a / q, v = b / q, and z_ndc = m2 . (a, b, q) is affine in (x, y). Along a row,
// a, b, q and z are linear in x, so the pixels with u, v in [0, 1], q > 0 and z_ndc in [-1, 1]
// (the triangles' coverage after clipping) form one interval computed per row; inside it only
// the division, the texture read, the depth test and the blend remain per pixel.
#include "follicle/render/splat_view_bando2003.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>

#include "follicle/core/error.hpp"
#include "follicle/render/splat_bando2003.hpp"

namespace follicle::render {
namespace {

constexpr int kBandRows = 8;  // rows per parallel task
constexpr double kInf = std::numeric_limits<double>::infinity();

/// Per-billboard state of the pass.
struct Setup {
  bool visible = false;
  int bx0 = 0, by0 = 0, bx1 = 0, by1 = 0;  // framebuffer pixels, half-open
  // (a w_tex, b h_tex, q) and z_ndc at pixel centre (bx0 + 1/2 + k, by0 + 1/2 + j): each
  // [0] k + [1] j + [2].
  double a[3] = {}, b[3] = {}, q[3] = {}, z[3] = {};
  // The row's pixel interval: k with c1 j + c0 + d k >= 0 for the 7 constraints of
  // row_interval(); inv = 1 / d (0 when d is 0).
  double c1[7] = {}, c0[7] = {}, d[7] = {}, inv[7] = {};
  float color[4] = {0, 0, 0, 1};  // shaded RGB, 1
  float alpha = 0;                // min(1, alpha / s)
  int level = 0;
};

/// Sets the 7 half-planes of the coverage (see the file comment): q > 0 (in front of the eye;
/// made strict by a margin far below a pixel), a >= u0 q, u1 q - a >= 0 (u w in [u0, u1], a
/// scaled by the level width w), the same for b and [v0, v1], 1 + z >= 0, 1 - z >= 0. [u0, u1]
/// is [0, w] narrowed to where the texture is not empty: a sample at texel coordinate
/// u w + 1/2 < c0 (the first column with alpha >= the discard threshold) reads only columns
/// before c0, one at >= c1 + 2 only columns after c1, and a bilinear mix of texels below the
/// threshold stays below it, so those pixels would be discarded anyway.
void set_constraints(Setup& st, double w, double h, const std::array<int, 4>& cover) {
  const double u0 = std::max(0.0, cover[0] - 0.5), u1 = std::min(w, cover[1] + 1.5);
  const double v0 = std::max(0.0, cover[2] - 0.5), v1 = std::min(h, cover[3] + 1.5);
  const double qs = 1e-9 * (std::abs(st.q[0]) + std::abs(st.q[1]) + std::abs(st.q[2]));
  const double rows[7][3] = {
      {st.q[0], st.q[1], st.q[2] - qs},
      {st.a[0] - u0 * st.q[0], st.a[1] - u0 * st.q[1], st.a[2] - u0 * st.q[2]},
      {u1 * st.q[0] - st.a[0], u1 * st.q[1] - st.a[1], u1 * st.q[2] - st.a[2]},
      {st.b[0] - v0 * st.q[0], st.b[1] - v0 * st.q[1], st.b[2] - v0 * st.q[2]},
      {v1 * st.q[0] - st.b[0], v1 * st.q[1] - st.b[1], v1 * st.q[2] - st.b[2]},
      {st.z[0], st.z[1], 1 + st.z[2]},
      {-st.z[0], -st.z[1], 1 - st.z[2]}};
  for (int i = 0; i < 7; ++i) {
    st.d[i] = rows[i][0];
    st.c1[i] = rows[i][1];
    st.c0[i] = rows[i][2];
    st.inv[i] = std::abs(rows[i][0]) > 1e-300 ? 1 / rows[i][0] : 0;
  }
}

/// The pixels k (from bx0) of row j inside the billboard, narrowed from [lo, hi].
bool row_interval(const Setup& st, double j, double& lo, double& hi) {
  for (int i = 0; i < 7; ++i) {
    const double c = st.c1[i] * j + st.c0[i];
    if (st.inv[i] == 0) {
      if (c < 0) return false;
    } else if (st.d[i] > 0) {
      lo = std::max(lo, -c * st.inv[i]);
    } else {
      hi = std::min(hi, -c * st.inv[i]);
    }
  }
  return lo <= hi;
}

void check_particle(const ViewSplatParticle& p, std::size_t i) {
  auto bad = [&](const char* what, double v) {
    fail("splat view pass: particle {} {} {} is invalid", i, what, v);
  };
  if (!p.pos.allFinite()) fail("splat view pass: particle {} position is not finite", i);
  if (!p.t.allFinite() || std::abs(p.t.norm() - 1) > 1e-3)
    fail("splat view pass: particle {} direction is not a finite unit vector", i);
  if (!(std::isfinite(p.half_w) && p.half_w > 0)) bad("half-width", p.half_w);
  if (!(std::isfinite(p.half_l) && p.half_l > 0)) bad("half-length", p.half_l);
  if (!(p.alpha >= 0 && p.alpha <= 1)) bad("opacity", p.alpha);
  if (!(p.min_sin > 0 && p.min_sin <= 1)) bad("min sin(theta)", p.min_sin);
  if (!p.color.allFinite() || p.color.minCoeff() < 0)
    fail("splat view pass: particle {} colour is not a finite non-negative RGB", i);
}

/// The billboard's plane patch: origin (uv = 0) and edges along u and v (billboard_corner()).
void billboard_patch(const ViewSplatParticle& p, const Vec3& eye, Vec3& o, Vec3& eu, Vec3& ev,
                     double& s) {
  const Vec3 dp = (p.pos - eye).normalized();
  Vec3 along, across;
  splat_billboard_axes(p.t, dp, p.min_sin, along, across, s);
  eu = 2 * p.half_w * across;
  ev = 2 * p.half_l * s * along;
  o = p.pos - 0.5 * eu - 0.5 * ev;
}

/// Window-space bounding box (framebuffer pixels, half-open, clamped) of the part of the patch
/// in front of the near plane; false when none of it is.
bool patch_bounds(const Mat4& vp, const Vec3& o, const Vec3& eu, const Vec3& ev, int fw, int fh,
                  int box[4]) {
  Vec4 c[4];
  const Vec3 corners[4] = {o, o + eu, o + eu + ev, o + ev};
  for (int k = 0; k < 4; ++k) c[k] = vp * corners[k].homogeneous();
  // Clip the quad against the near plane z + w >= 0 (Sutherland-Hodgman, one plane).
  double xmin = kInf, xmax = -kInf, ymin = kInf, ymax = -kInf;
  auto add = [&](const Vec4& h) {
    const double w = std::max(h.w(), 1e-300);
    const double x = (h.x() / w * 0.5 + 0.5) * fw, y = (h.y() / w * 0.5 + 0.5) * fh;
    xmin = std::min(xmin, x);
    xmax = std::max(xmax, x);
    ymin = std::min(ymin, y);
    ymax = std::max(ymax, y);
  };
  int kept = 0;
  for (int k = 0; k < 4; ++k) {
    const Vec4& a = c[k];
    const Vec4& b = c[(k + 1) % 4];
    const double da = a.z() + a.w(), db = b.z() + b.w();
    if (da >= 0) {
      add(a);
      ++kept;
    }
    if ((da >= 0) != (db >= 0)) add(a + (da / (da - db)) * (b - a));
  }
  if (kept == 0 ||
      !(std::isfinite(xmin) && std::isfinite(xmax) && std::isfinite(ymin) && std::isfinite(ymax)))
    return false;
  // Pixel centres (i + 1/2) inside [min, max]: i in [ceil(min - 1/2), floor(max - 1/2)].
  box[0] = int(std::clamp(std::ceil(xmin - 0.5), 0.0, double(fw)));
  box[1] = int(std::clamp(std::ceil(ymin - 0.5), 0.0, double(fh)));
  box[2] = int(std::clamp(std::floor(xmax - 0.5) + 1, 0.0, double(fw)));
  box[3] = int(std::clamp(std::floor(ymax - 0.5) + 1, 0.0, double(fh)));
  return box[0] < box[2] && box[1] < box[3];
}

Setup make_setup(const SplatViewParams& prm, const ViewSplatParticle& p,
                 const SplatColorTexture& tex, int fw, int fh) {
  Setup st;
  Vec3 o, eu, ev;
  double s = 1;
  billboard_patch(p, prm.eye, o, eu, ev, s);
  int box[4];
  if (!patch_bounds(prm.view_proj, o, eu, ev, fw, fh, box)) return st;
  Eigen::Matrix<double, 4, 3> m;
  m.col(0) = prm.view_proj * Vec4(eu.x(), eu.y(), eu.z(), 0);
  m.col(1) = prm.view_proj * Vec4(ev.x(), ev.y(), ev.z(), 0);
  m.col(2) = prm.view_proj * o.homogeneous();
  Mat3 h;
  h.row(0) = 0.5 * fw * (m.row(0) + m.row(3));
  h.row(1) = 0.5 * fh * (m.row(1) + m.row(3));
  h.row(2) = m.row(3);
  const double det = h.determinant();
  if (!(std::abs(det) > 1e-300) || !std::isfinite(det)) return st;  // edge-on
  const Mat3 g = h.inverse();
  // Pixel centre of (k, j) = (bx0 + 1/2 + k, by0 + 1/2 + j).
  const Vec3 base(box[0] + 0.5, box[1] + 0.5, 1.0);
  const Eigen::RowVector3d mz = m.row(2);
  const Vec3 zc = (mz * g).transpose();  // z_ndc = zc . (x, y, 1)
  for (int r = 0; r < 3; ++r) {
    double* dst = r == 0 ? st.a : r == 1 ? st.b : st.q;
    dst[0] = g(r, 0);
    dst[1] = g(r, 1);
    dst[2] = g.row(r).dot(base);
  }
  st.z[0] = zc.x();
  st.z[1] = zc.y();
  st.z[2] = zc.dot(base);
  // Mip level from the texel footprint per pixel at the billboard's centre (GL picks it per
  // 2x2 pixel quad; a billboard spans few pixels, so one level per billboard).
  const Vec4 cc = prm.view_proj * p.pos.homogeneous();
  const double cx = (cc.x() / cc.w() * 0.5 + 0.5) * fw, cy = (cc.y() / cc.w() * 0.5 + 0.5) * fh;
  const Vec3 abq = g * Vec3(cx, cy, 1);
  const double qq = abq.z();
  const double dudx = (g(0, 0) * qq - abq.x() * g(2, 0)) / (qq * qq);
  const double dvdx = (g(1, 0) * qq - abq.y() * g(2, 0)) / (qq * qq);
  const double dudy = (g(0, 1) * qq - abq.x() * g(2, 1)) / (qq * qq);
  const double dvdy = (g(1, 1) * qq - abq.y() * g(2, 1)) / (qq * qq);
  const double tw = tex.width(), th = tex.height();
  const double rho = std::max(std::hypot(tw * dudx, th * dvdx), std::hypot(tw * dudy, th * dvdy));
  st.level = tex.level_for(rho);
  // a, b in texels of the level: u w = a / q.
  const double lw = tex.width(st.level), lh = tex.height(st.level);
  for (double& c : st.a) c *= lw;
  for (double& c : st.b) c *= lh;
  const std::array<int, 4>& cover = tex.coverage(st.level);
  if (cover[0] > cover[1]) return st;  // the whole level is below the discard threshold
  set_constraints(st, lw, lh, cover);
  for (int c = 0; c < 3; ++c) st.color[c] = float(p.color[c]);
  st.alpha = float(std::min(1.0, p.alpha / s));  // Bando 2003 §3.4: opacity / sin(theta)
  st.bx0 = box[0];
  st.by0 = box[1];
  st.bx1 = box[2];
  st.by1 = box[3];
  st.visible = st.alpha > 0;
  return st;
}

// 4 floats (one RGBA texel or pixel) as one SSE/NEON register where the target has one.
using V4 = float __attribute__((vector_size(16)));
using V4I = int32_t __attribute__((vector_size(16)));  // lane masks of V4 comparisons

inline V4 load4(const float* p) {
  V4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

inline void store4(float* p, V4 v) {
  std::memcpy(p, &v, sizeof v);
}

/// Rows [y0, y1) of the target: the billboards of `order` (those touching the rows, back to
/// front), clipped to those rows.
void splat_rows(const std::vector<Setup>& setups, std::span<const int32_t> order,
                const SplatColorTexture& tex, const SplatViewTarget& tg, int y0, int y1) {
  const int stride_px = tg.rgba_stride > 0 ? tg.rgba_stride : tg.width;
  for (const int32_t idx : order) {
    const Setup& st = setups[std::size_t(idx)];
    if (!st.visible || st.by1 <= y0 || st.by0 >= y1) continue;
    const int ya = std::max(y0, st.by0), yb = std::min(y1, st.by1);
    const int xa = std::max(st.bx0, tg.x0), xb = std::min(st.bx1, tg.x0 + tg.width);
    if (xa >= xb) continue;
    const int lw = tex.width(st.level), lh = tex.height(st.level), stride = lw + 2;
    const float* texels = tex.padded_rgba(st.level);
    const float txhi = float(lw) + 0.5f, tyhi = float(lh) + 0.5f;
    const V4 colour = load4(st.color);
    for (int y = ya; y < yb; ++y) {
      const double j = y - st.by0;
      double lo = xa - st.bx0, hi = xb - 1 - st.bx0;
      if (!row_interval(st, j, lo, hi)) continue;
      const int k0 = int(std::ceil(lo)), k1 = int(std::floor(hi));
      if (k0 > k1) continue;
      float* row = tg.rgba + (std::size_t(y - tg.y0) * std::size_t(stride_px)) * 4;
      const float* drow = tg.depth + std::size_t(y - tg.y0) * std::size_t(tg.width);
      const float a0 = float(st.a[1] * j + st.a[2]), b0 = float(st.b[1] * j + st.b[2]),
                  q0 = float(st.q[1] * j + st.q[2]), z0 = float(st.z[1] * j + st.z[2]);
      const float da = float(st.a[0]), db = float(st.b[0]), dq = float(st.q[0]),
                  dz = float(st.z[0]);
      const float* dwin = drow - tg.x0 + st.bx0;               // depth at k
      float* cwin = row + 4 * std::ptrdiff_t(st.bx0 - tg.x0);  // colour at k
      // The texel read and the blend of pixel k, given its padded texel coordinates and
      // whether it is in front of the objects. A pixel hidden by the objects (GL_LESS) or on
      // the empty part of the billboard (kSplatViewFs discards alpha < 0.004) blends with
      // sa = 0, which leaves it unchanged: selecting instead of branching keeps the loop free
      // of unpredictable jumps.
      auto shade = [&](int k, std::size_t texel, float fx, float fy, bool front) {
        const float* t0 = texels + 4 * texel;
        const float* t1 = t0 + 4 * std::size_t(stride);
        const V4 a00 = load4(t0), a01 = load4(t0 + 4), a10 = load4(t1), a11 = load4(t1 + 4);
        const V4 top = a00 + fx * (a01 - a00), bot = a10 + fx * (a11 - a10);
        V4 t = top + fy * (bot - top);
        const float sa =
            front && t[3] >= SplatColorTexture::kSplatAlphaDiscard ? st.alpha * t[3] : 0.0f;
        t[3] = 1.0f;  // colour (r, g, b, 1) x texel (r, g, b, 1) x sa: alpha sa
        float* px = cwin + 4 * std::ptrdiff_t(k);
        store4(px, colour * t * sa + load4(px) * (1.0f - sa));
      };
      // Four pixels at a time for the per-pixel coordinates (depth, 1/q, texel position), then
      // the rest one by one; the arithmetic per pixel is the same either way.
      int k = k0;
      const V4 lane = {0.0f, 1.0f, 2.0f, 3.0f};
      const V4 lo_v = {0.5f, 0.5f, 0.5f, 0.5f};
      const V4 txhi_v = {txhi, txhi, txhi, txhi}, tyhi_v = {tyhi, tyhi, tyhi, tyhi};
      for (; k + 3 <= k1; k += 4) {
        const V4 fk = float(k) + lane;
        const V4 depth = 0.5f * (z0 + dz * fk) + 0.5f;
        const V4 iq = 1.0f / (q0 + dq * fk);
        V4 tx = (a0 + da * fk) * iq + 0.5f, ty = (b0 + db * fk) * iq + 0.5f;
        tx = tx < lo_v ? lo_v : tx;
        tx = tx > txhi_v ? txhi_v : tx;
        ty = ty < lo_v ? lo_v : ty;
        ty = ty > tyhi_v ? tyhi_v : ty;
        const V4I front = depth < load4(dwin + k);  // GL_LESS against the objects
        const V4I ix = __builtin_convertvector(tx, V4I), iy = __builtin_convertvector(ty, V4I);
        const V4 fx = tx - __builtin_convertvector(ix, V4),
                 fy = ty - __builtin_convertvector(iy, V4);
        const V4I texel = iy * stride + ix;
        for (int l = 0; l < 4; ++l)
          shade(k + l, std::size_t(texel[l]), fx[l], fy[l], front[l] != 0);
      }
      for (; k <= k1; ++k) {
        const float fk = float(k);
        const float depth = 0.5f * (z0 + dz * fk) + 0.5f;
        const float iq = 1.0f / (q0 + dq * fk);
        const float tx = std::clamp((a0 + da * fk) * iq + 0.5f, 0.5f, txhi);
        const float ty = std::clamp((b0 + db * fk) * iq + 0.5f, 0.5f, tyhi);
        const int ix = int(tx), iy = int(ty);  // tx, ty > 0: truncation is floor
        shade(k, std::size_t(iy) * std::size_t(stride) + std::size_t(ix), tx - float(ix),
              ty - float(iy), depth < dwin[k]);
      }
    }
  }
}

}  // namespace

namespace {
const image::ImageRGBA8& non_empty(const image::ImageRGBA8& img) {
  if (img.empty()) fail("splat view pass: the hair texture is empty");
  return img;
}
}  // namespace

SplatColorTexture::SplatColorTexture(const image::ImageRGBA8& img) : m_alpha(non_empty(img)) {
  m_rgba.resize(std::size_t(m_alpha.levels()));
  for (int l = 0; l < m_alpha.levels(); ++l)
    m_rgba[std::size_t(l)].assign(
        4 * std::size_t(m_alpha.width(l) + 2) * std::size_t(m_alpha.height(l) + 2), 0.0f);
  // Channel c's chain is SplatAlphaTexture's of an image whose alpha is channel c; alpha's is
  // m_alpha.
  auto put = [&](int c, const SplatAlphaTexture& chain) {
    for (int l = 0; l < chain.levels(); ++l) {
      const float* src = chain.padded(l);
      std::vector<float>& dst = m_rgba[std::size_t(l)];
      for (std::size_t i = 0; i < dst.size() / 4; ++i) dst[4 * i + std::size_t(c)] = src[i];
    }
  };
  image::ImageRGBA8 ch(img.width(), img.height());
  for (int c = 0; c < 3; ++c) {
    for (int y = 0; y < img.height(); ++y)
      for (int x = 0; x < img.width(); ++x) ch.at(x, y, 3) = img.at(x, y, c);
    put(c, SplatAlphaTexture(ch));
  }
  put(3, m_alpha);
  for (int l = 0; l < levels(); ++l) {
    const int w = width(l), h = height(l);
    std::array<int, 4> box = {w, -1, h, -1};
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (m_rgba[std::size_t(l)]
                  [4 * (std::size_t(y + 1) * std::size_t(w + 2) + std::size_t(x + 1)) + 3] >=
            kSplatAlphaDiscard) {
          box = {std::min(box[0], x), std::max(box[1], x), std::min(box[2], y),
                 std::max(box[3], y)};
        }
    m_cover.push_back(box);
  }
}

std::vector<int32_t> splat_view_order(const Mat4& view,
                                      std::span<const ViewSplatParticle> particles) {
  const std::size_t n = particles.size();
  std::vector<double> z(n);
  for (std::size_t i = 0; i < n; ++i)
    z[i] = view(2, 0) * particles[i].pos.x() + view(2, 1) * particles[i].pos.y() +
           view(2, 2) * particles[i].pos.z();
  std::vector<int32_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int32_t a, int32_t b) { return z[std::size_t(a)] < z[std::size_t(b)]; });
  return order;
}

void splat_view_bounds(const SplatViewParams& params, std::span<const ViewSplatParticle> particles,
                       int fb_width, int fb_height, int bounds[4]) {
  bounds[0] = fb_width;
  bounds[1] = fb_height;
  bounds[2] = 0;
  bounds[3] = 0;
  for (const ViewSplatParticle& p : particles) {
    Vec3 o, eu, ev;
    double s = 1;
    billboard_patch(p, params.eye, o, eu, ev, s);
    int box[4];
    if (!patch_bounds(params.view_proj, o, eu, ev, fb_width, fb_height, box)) continue;
    bounds[0] = std::min(bounds[0], box[0]);
    bounds[1] = std::min(bounds[1], box[1]);
    bounds[2] = std::max(bounds[2], box[2]);
    bounds[3] = std::max(bounds[3], box[3]);
  }
  if (bounds[0] >= bounds[2] || bounds[1] >= bounds[3])
    bounds[0] = bounds[1] = bounds[2] = bounds[3] = 0;
}

void splat_view_pass_bando2003(const SplatViewParams& params,
                               std::span<const ViewSplatParticle> particles,
                               std::span<const int32_t> order, const SplatColorTexture& texture,
                               const SplatViewTarget& target) {
  const SplatViewTarget& tg = target;
  if (tg.fb_width < 1 || tg.fb_height < 1 || tg.fb_width > 65536 || tg.fb_height > 65536)
    fail("splat view pass: framebuffer {}x{} is not a valid size", tg.fb_width, tg.fb_height);
  if (tg.width < 0 || tg.height < 0 || tg.x0 < 0 || tg.y0 < 0 || tg.x0 + tg.width > tg.fb_width ||
      tg.y0 + tg.height > tg.fb_height)
    fail("splat view pass: window {}x{} at ({}, {}) does not fit the {}x{} framebuffer", tg.width,
         tg.height, tg.x0, tg.y0, tg.fb_width, tg.fb_height);
  if (tg.width == 0 || tg.height == 0 || particles.empty()) return;
  if (!tg.rgba || !tg.depth) fail("splat view pass: the colour or depth buffer is missing");
  if (tg.rgba_stride != 0 && tg.rgba_stride < tg.width)
    fail("splat view pass: colour row stride {} is less than the window width {}", tg.rgba_stride,
         tg.width);
  if (!params.view_proj.allFinite() || !params.eye.allFinite())
    fail("splat view pass: the camera is not finite");
  if (order.size() != particles.size())
    fail("splat view pass: {} draw orders for {} particles", order.size(), particles.size());
  std::vector<char> seen(particles.size(), 0);
  for (const int32_t i : order) {
    if (i < 0 || std::size_t(i) >= particles.size() || seen[std::size_t(i)])
      fail("splat view pass: the draw order is not a permutation of the particles (index {})", i);
    seen[std::size_t(i)] = 1;
  }
  for (std::size_t i = 0; i < particles.size(); ++i) check_particle(particles[i], i);

  std::vector<Setup> setups(particles.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, particles.size(), 64),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i)
                        setups[i] =
                            make_setup(params, particles[i], texture, tg.fb_width, tg.fb_height);
                    });
  // Lines 19-21 per band of rows; every band sees its billboards in the draw order. The lists
  // per band (built in order, sequentially) spare each band a walk over all billboards.
  const int bands = (tg.height + kBandRows - 1) / kBandRows;
  std::vector<std::vector<int32_t>> in_band{std::size_t(bands)};
  for (const int32_t idx : order) {
    const Setup& st = setups[std::size_t(idx)];
    if (!st.visible || st.by1 <= tg.y0 || st.by0 >= tg.y0 + tg.height) continue;
    const int b0 = std::max(0, (st.by0 - tg.y0) / kBandRows);
    const int b1 = std::min(bands - 1, (st.by1 - 1 - tg.y0) / kBandRows);
    for (int b = b0; b <= b1; ++b) in_band[std::size_t(b)].push_back(idx);
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, bands, 1), [&](const tbb::blocked_range<int>& r) {
    for (int band = r.begin(); band != r.end(); ++band) {
      const int y0 = tg.y0 + band * kBandRows;
      const int y1 = std::min(tg.y0 + tg.height, y0 + kBandRows);
      splat_rows(setups, in_band[std::size_t(band)], texture, tg, y0, y1);
    }
  });
}

}  // namespace follicle::render
