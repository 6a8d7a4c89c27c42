// Daldegan et al. 1993 §4 hair rendering on the CPU; see hair_blend_daldegan1993.hpp and
// docs/equations/daldegan_render.md.
//
// Both rasterisers (the light's hair Z-buffer and the view's blended lines) cut the buffer into
// bands of rows. The segments touching each band are listed (the blend: copied) with a stable
// parallel counting sort (bucket() below: the order within a band is the input order, whatever
// the chunking), so every band sees its segments in the same order and is drawn by one task:
// the result does not depend on the thread count. The blend's depth order is a stable LSD
// radix sort of each band's (depth key, index) pairs.
//
// Speed (100k strands x 30 points, 2.9M segments, 2048² shadow buffers, a 1024² image at
// supersampling 2): the first versions read the segments of a band in depth order straight
// from the per-point arrays (one cache and TLB miss per segment and band: 2.5 s of CPU for the
// blend alone); copying them band by band in memory order, sorting per band, drawing per cell
// (k x k pixels) near to far with early opacity / scene-depth rejection brought the blend to
// ~0.6 s CPU; the light's Z-buffer walks the texels a zero-width segment crosses (~0.2 s CPU
// per light).
#include "follicle/render/hair_blend_daldegan1993.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"

namespace follicle::render {
namespace {

constexpr int kDepthBandRows = 16;             // rows per band of the light's hair Z-buffer
constexpr int kBlendBandRows = 16;             // rows per band of the blend
constexpr int kBlockCols = 16;                 // columns per block of the blend's opacity culling
constexpr float kOpaque = 1.0f - 1.0f / 4096;  // a pixel's hair alpha taken as opaque
constexpr double kMaxCot = 8.0;                // clamp of the slope factor of the shadow bias

/// Stable parallel bucketing (a counting sort): item j of [0, n), in order, goes into every
/// bucket b of range(j) = {lo, hi} (lo <= b <= hi; none when lo > hi) as value(j). Within a
/// bucket the items keep their order, so the result depends neither on the chunking nor on the
/// thread count. start[b] .. start[b + 1] index the items of bucket b in `out` (which is only
/// grown, never shrunk: its size may exceed start[buckets]).
template <class T, class Range, class Value>
void bucket(const Context& ctx, std::size_t n, std::size_t buckets, Range&& range, Value&& value,
            std::vector<uint32_t>& start, std::vector<T>& out) {
  start.assign(buckets + 1, 0);
  if (n == 0 || buckets == 0) return;
  const std::size_t nc = std::clamp<std::size_t>(n / 16384, 1, 64);
  const std::size_t chunk = (n + nc - 1) / nc;
  std::vector<uint64_t> pos(nc * buckets, 0);  // counts, then write positions
  parallel_for(
      ctx, 0, nc,
      [&](std::size_t c) {
        uint64_t* cnt = pos.data() + c * buckets;
        const std::size_t e = std::min(n, (c + 1) * chunk);
        for (std::size_t j = c * chunk; j < e; ++j) {
          const auto [lo, hi] = range(j);
          for (int b = lo; b <= hi; ++b) ++cnt[b];
        }
      },
      1);
  uint64_t acc = 0;
  for (std::size_t b = 0; b < buckets; ++b) {
    if (acc > std::numeric_limits<uint32_t>::max()) break;
    start[b] = uint32_t(acc);
    for (std::size_t c = 0; c < nc; ++c) {
      const uint64_t k = pos[c * buckets + b];
      pos[c * buckets + b] = acc;
      acc += k;
    }
  }
  if (acc > std::numeric_limits<uint32_t>::max())
    fail("hair pass: {} segment-band entries exceed the 32-bit index range", acc);
  start[buckets] = uint32_t(acc);
  if (out.size() < acc) out.resize(std::size_t(acc));  // grown only: no refill every frame
  parallel_for(
      ctx, 0, nc,
      [&](std::size_t c) {
        uint64_t* p = pos.data() + c * buckets;
        const std::size_t e = std::min(n, (c + 1) * chunk);
        for (std::size_t j = c * chunk; j < e; ++j) {
          const auto [lo, hi] = range(j);
          if (lo > hi) continue;
          const T v = value(j);
          for (int b = lo; b <= hi; ++b) out[std::size_t(p[b]++)] = v;
        }
      },
      1);
}

/// The zero-width segment (ax, ay) -> (bx, by) (texel units, depths az -> bz) drawn into the
/// Z-buffer rows [r0, r1) of a size x size buffer: every texel whose square the segment passes
/// through keeps the smaller of its depth and the segment's nearest depth inside it (the depth
/// is linear along the segment, so that is its depth where it enters or leaves the texel).
/// Amanatides & Woo 1987 grid traversal, started where the segment enters the band.
void walk_segment(double ax, double ay, double az, double bx, double by, double bz, int r0, int r1,
                  int size, float* depth) {
  const double dx = bx - ax, dy = by - ay;
  double t0 = 0, t1 = 1;  // the part of the segment within the band's rows (with a margin)
  if (std::abs(dy) > 1e-12) {
    double ta = (r0 - 1e-6 - ay) / dy, tb = (r1 + 1e-6 - ay) / dy;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return;
  } else if (ay < r0 - 1e-6 || ay > r1 + 1e-6) {
    return;
  }
  const double sx = ax + t0 * dx, sy = ay + t0 * dy;
  int tx = int(std::floor(sx)), ty = int(std::floor(sy));
  const int step_x = dx > 0 ? 1 : -1, step_y = dy > 0 ? 1 : -1;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double dtx = std::abs(dx) > 1e-12 ? 1 / std::abs(dx) : kInf;
  const double dty = std::abs(dy) > 1e-12 ? 1 / std::abs(dy) : kInf;
  // Parameters t where the segment crosses the next vertical / horizontal texel edge.
  double tmx = dtx == kInf ? kInf : t0 + (dx > 0 ? tx + 1 - sx : sx - tx) * dtx;
  double tmy = dty == kInf ? kInf : t0 + (dy > 0 ? ty + 1 - sy : sy - ty) * dty;
  double t = t0;
  const double dz = bz - az;
  // At most one step per texel edge crossed, plus the first texel.
  const int max_steps = int(std::abs(dx) * (t1 - t0) + std::abs(dy) * (t1 - t0)) + 3;
  for (int it = 0; it < max_steps; ++it) {
    const double tn = std::min({tmx, tmy, t1});
    if (ty >= r0 && ty < r1 && tx >= 0 && tx < size) {
      const float z = float(std::clamp(az + std::min(t, tn) * dz, 0.0, 1.0));
      const float z2 = float(std::clamp(az + std::max(t, tn) * dz, 0.0, 1.0));
      float& d = depth[std::size_t(ty) * std::size_t(size) + std::size_t(tx)];
      d = std::min(d, std::min(z, z2));
    }
    if (tn >= t1) break;
    if (tmx <= tmy) {
      tx += step_x;
      tmx += dtx;
    } else {
      ty += step_y;
      tmy += dty;
    }
    t = tn;
  }
}

void check_light_vp(const Mat4& vp, const std::string& where) {
  if (!vp.allFinite()) fail_at(where, "the light view-projection is not finite");
  if (vp(3, 0) != 0 || vp(3, 1) != 0 || vp(3, 2) != 0 || vp(3, 3) != 1)
    fail_at(where, "the light view-projection is not orthographic (last row must be 0 0 0 1)");
  if (!(vp.row(0).head<3>().norm() > 0) || !(vp.row(1).head<3>().norm() > 0) ||
      !(vp.row(2).head<3>().norm() > 0))
    fail_at(where, "the light view-projection is singular");
}

/// Strand of every segment and its first point, for the strands with `keep(s)`.
template <class Keep>
void list_segments(const Context& ctx, const HairSegments& hair, Keep&& keep,
                   std::vector<uint32_t>& seg_point, std::vector<uint32_t>* seg_strand) {
  const std::size_t ns = hair.num_strands();
  std::vector<uint32_t> base(ns + 1, 0);
  for (std::size_t s = 0; s < ns; ++s) {
    const uint32_t n = hair.offsets[s + 1] - hair.offsets[s];
    base[s + 1] = base[s] + (keep(s) && n >= 2 ? n - 1 : 0);
  }
  seg_point.resize(base[ns]);
  if (seg_strand) seg_strand->resize(base[ns]);
  parallel_for(
      ctx, 0, ns,
      [&](std::size_t s) {
        for (uint32_t k = 0; k < base[s + 1] - base[s]; ++k) {
          seg_point[base[s] + k] = hair.offsets[s] + k;
          if (seg_strand) (*seg_strand)[base[s] + k] = uint32_t(s);
        }
      },
      256);
}

}  // namespace

// ---- HairSegments ------------------------------------------------------------------------------

void HairSegments::add_strand(std::span<const Vec3f> pts, float width, float alpha, bool casts) {
  points.insert(points.end(), pts.begin(), pts.end());
  offsets.push_back(uint32_t(points.size()));
  if (!radius.empty()) radius.resize(points.size(), radius.back());
  width_px.push_back(width);
  opacity.push_back(alpha);
  casts_shadow.push_back(casts ? 1 : 0);
}

void HairSegments::check(const std::string& where) const {
  if (offsets.empty() || offsets.front() != 0)
    fail_at(where, "strand offsets must start with 0 (got {} offsets)", offsets.size());
  const std::size_t ns = num_strands();
  for (std::size_t s = 0; s < ns; ++s)
    if (offsets[s + 1] < offsets[s])
      fail_at(where, "strand offsets decrease at strand {} ({} after {})", s, offsets[s + 1],
              offsets[s]);
  if (offsets.back() != points.size())
    fail_at(where, "strand offsets end at {} but there are {} points", offsets.back(),
            points.size());
  if (width_px.size() != ns || opacity.size() != ns || casts_shadow.size() != ns)
    fail_at(where, "{} widths, {} opacities, {} shadow flags for {} strands (one per strand)",
            width_px.size(), opacity.size(), casts_shadow.size(), ns);
  if (!radius.empty() && radius.size() != points.size())
    fail_at(where, "{} radii for {} points (one per point or none)", radius.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite())
      fail_at(where, "point {} ({}, {}, {}) is not finite", i, points[i].x(), points[i].y(),
              points[i].z());
  for (std::size_t i = 0; i < radius.size(); ++i)
    if (!(std::isfinite(radius[i]) && (radius[i] >= 0 || radius[i] == kNoRadius)))
      fail_at(where, "radius {} of point {} is not a finite value >= 0 (or kNoRadius)", radius[i],
              i);
  for (std::size_t s = 0; s < ns; ++s) {
    if (!(std::isfinite(width_px[s]) && width_px[s] > 0))
      fail_at(where, "width {} px of strand {} is not a finite value > 0", width_px[s], s);
    if (!(opacity[s] >= 0 && opacity[s] <= 1))
      fail_at(where, "opacity {} of strand {} is outside [0, 1]", opacity[s], s);
  }
}

// ---- shadow buffers -----------------------------------------------------------------------------

double ShadowBuffer::texel_world() const {
  return 2.0 / (light_vp.row(0).head<3>().norm() * size);
}

double ShadowBuffer::depth_per_metre() const {
  return 0.5 * light_vp.row(2).head<3>().norm();
}

void ShadowBuffer::check(const std::string& where) const {
  if (size < 1 || size > 16384) fail_at(where, "shadow buffer size {} is outside [1, 16384]", size);
  if (depth.size() != std::size_t(size) * std::size_t(size))
    fail_at(where, "shadow buffer has {} depths for {}x{} texels", depth.size(), size, size);
  check_light_vp(light_vp, where);
}

ShadowBuffer rasterize_hair_depth(const Context& ctx, const HairSegments& hair,
                                  const Mat4& light_vp, int size) {
  HairDepthRasterizer r;
  ShadowBuffer out;
  r.rasterize(ctx, hair, light_vp, size, out);
  return out;
}

void HairDepthRasterizer::rasterize(const Context& ctx, const HairSegments& hair,
                                    const Mat4& light_vp, int size, ShadowBuffer& out) {
  const std::string where = "hair shadow buffer";
  if (size < 1 || size > 16384) fail_at(where, "size {} is outside [1, 16384]", size);
  check_light_vp(light_vp, where);
  hair.check(where);
  out.size = size;
  out.light_vp = light_vp;
  out.depth.assign(std::size_t(size) * std::size_t(size), 1.0f);
  const std::size_t np = hair.num_points();
  if (np == 0) return;
  const double n = size;
  const double texels_per_m = 0.5 * n * light_vp.row(0).head<3>().norm();
  // Window position (texels), depth and half width (texels) of every point; orthographic, so
  // no clipping by w.
  m_win.resize(4 * np);
  const bool radii = !hair.radius.empty();
  parallel_chunks(ctx, np, 8192, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const Vec4 c = light_vp * hair.points[i].cast<double>().homogeneous();
      float* w = &m_win[4 * i];
      w[0] = float((c.x() * 0.5 + 0.5) * n);
      w[1] = float((c.y() * 0.5 + 0.5) * n);
      w[2] = float(c.z() * 0.5 + 0.5);
      w[3] = radii && hair.radius[i] >= 0 ? float(texels_per_m * double(hair.radius[i])) : 0.0f;
    }
  });
  list_segments(
      ctx, hair, [&](std::size_t s) { return hair.casts_shadow[s] != 0; }, m_segs, nullptr);
  const int bands = (size + kDepthBandRows - 1) / kDepthBandRows;
  bucket<uint32_t>(
      ctx, m_segs.size(), std::size_t(bands),
      [&](std::size_t j) {
        const float* a = &m_win[4 * std::size_t(m_segs[j])];
        const double e = 0.5 * (double(a[3]) + double(a[7])) * 2 + 1.5;
        const double y0 = std::min(a[1], a[5]) - e, y1 = std::max(a[1], a[5]) + e;
        if (y1 < 0 || y0 >= n) return std::pair<int, int>{1, 0};
        return std::pair<int, int>{int(std::max(0.0, y0) / kDepthBandRows),
                                   int(std::min(n - 1, y1) / kDepthBandRows)};
      },
      [&](std::size_t j) { return m_segs[j]; }, m_start, m_items);
  parallel_for(
      ctx, 0, std::size_t(bands),
      [&](std::size_t band) {
        const int r0 = int(band) * kDepthBandRows, r1 = std::min(size, r0 + kDepthBandRows);
        const uint32_t k0 = m_start[band], k1 = m_start[band + 1];
        for (uint32_t k = k0; k < k1; ++k) {
          if (k + 8 < k1) __builtin_prefetch(&m_win[4 * std::size_t(m_items[k + 8])]);
          const float* a = &m_win[4 * std::size_t(m_items[k])];
          const double ax = a[0], ay = a[1], az = a[2], bx = a[4], by = a[5], bz = a[6];
          const double dx = bx - ax, dy = by - ay;
          if (a[3] == 0 && a[7] == 0) {
            // No width: exactly the texels the segment passes through (a grid walk).
            walk_segment(ax, ay, az, bx, by, bz, r0, r1, size, out.depth.data());
            continue;
          }
          const double len = std::sqrt(dx * dx + dy * dy);
          double ux = 1, uy = 0;
          if (len > 1e-12) {
            ux = dx / len;
            uy = dy / len;
          }
          const double nx = -uy, ny = ux;
          const double inv_len = len > 1e-12 ? 1 / len : 0;
          const double inv_nx = std::abs(nx) > 1e-12 ? 1 / nx : 0;
          const double inv_ux = std::abs(ux) > 1e-12 ? 1 / ux : 0;
          const double hw = 0.5 * (double(a[3]) + double(a[7]));
          // A texel square meets the widened segment's strip when its centre is within
          // hw + (|nx| + |ny|) / 2 of the line, and the segment's extent along it.
          const double ep = hw + 0.5 * (std::abs(nx) + std::abs(ny));
          const double ea = hw + 0.5 * (std::abs(ux) + std::abs(uy));
          const double ymin = std::min(ay, by) - ep - ea, ymax = std::max(ay, by) + ep + ea;
          const int y_lo = std::max(r0, int(std::floor(ymin)));
          const int y_hi = std::min(r1 - 1, int(std::floor(ymax)));
          for (int y = y_lo; y <= y_hi; ++y) {
            const double ry = y + 0.5 - ay;
            double lo = 0.5, hi = n - 0.5;  // texel centres
            if (inv_nx != 0) {
              const double m = ax - ny * ry * inv_nx, r = ep * std::abs(inv_nx);
              lo = std::max(lo, m - r);
              hi = std::min(hi, m + r);
            } else if (std::abs(ny * ry) > ep) {
              continue;
            }
            if (inv_ux != 0) {
              const double m = ax - uy * ry * inv_ux;
              double t0 = m - ea * inv_ux, t1 = m + (len + ea) * inv_ux;
              if (inv_ux < 0) std::swap(t0, t1);
              lo = std::max(lo, t0);
              hi = std::min(hi, t1);
            } else if (uy * ry < -ea || uy * ry > len + ea) {
              continue;
            }
            const int x0 = std::max(0, int(std::ceil(lo - 0.5)));
            const int x1 = std::min(size - 1, int(std::floor(hi - 0.5)));
            float* row = out.depth.data() + std::size_t(y) * std::size_t(size);
            double s = ux * (x0 + 0.5 - ax) + uy * ry;
            for (int x = x0; x <= x1; ++x, s += ux) {
              const double t = std::clamp(s * inv_len, 0.0, 1.0);
              const float z = float(std::clamp(az + t * (bz - az), 0.0, 1.0));
              row[x] = std::min(row[x], z);
            }
          }
        }
      },
      1);
}

ShadowBuffer compose_shadow_buffers(const Context& ctx, const ShadowBuffer& scene,
                                    const ShadowBuffer& hair) {
  ShadowBuffer out = scene;
  compose_shadow_buffers_into(ctx, out, hair);
  return out;
}

void compose_shadow_buffers_into(const Context& ctx, ShadowBuffer& scene,
                                 const ShadowBuffer& hair) {
  scene.check("scene shadow buffer");
  hair.check("hair shadow buffer");
  if (scene.size != hair.size)
    fail("compose shadow buffers: the scene buffer is {}x{}, the hair buffer {}x{}", scene.size,
         scene.size, hair.size, hair.size);
  if (!scene.light_vp.isApprox(hair.light_vp, 1e-12))
    fail("compose shadow buffers: the scene and hair buffers have different light projections");
  float* d = scene.depth.data();
  const float* h = hair.depth.data();
  parallel_chunks(ctx, scene.depth.size(), 1 << 16, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) d[i] = std::min(d[i], h[i]);
  });
}

namespace {

/// PCF of `buf` at window position (sx, sy) [texels] for depth `z` and bias `bias_depth`
/// (window depth units); see shadow_pcf().
double pcf_window(const ShadowBuffer& buf, double sx, double sy, double z, double bias_depth,
                  int radius) {
  const int size = buf.size;
  const double n = size;
  if (!(sx >= 0 && sx <= n && sy >= 0 && sy <= n) || !(z <= 1)) return 1.0;
  const float ref = float(z - bias_depth);
  const double h = radius + 0.5;
  const double x0 = sx - h, x1 = sx + h, y0 = sy - h, y1 = sy + h;
  const int i0 = int(std::floor(x0)), i1 = int(std::ceil(x1)) - 1;
  const int j0 = int(std::floor(y0)), j1 = int(std::ceil(y1)) - 1;
  // Texel weights: the overlap of each texel with the box, per axis (2 r + 2 texels at most).
  constexpr int kMaxTaps = 2 * 16 + 2;
  double wx[kMaxTaps];
  int ix[kMaxTaps];
  const int nx = std::min(i1 - i0 + 1, kMaxTaps);
  for (int k = 0; k < nx; ++k) {
    const int i = i0 + k;
    wx[k] = std::max(0.0, std::min(x1, i + 1.0) - std::max(x0, double(i)));
    ix[k] = std::clamp(i, 0, size - 1);
  }
  double lit = 0;
  for (int j = j0; j <= j1; ++j) {
    const double wy = std::min(y1, j + 1.0) - std::max(y0, double(j));
    if (wy <= 0) continue;
    const float* row =
        buf.depth.data() + std::size_t(std::clamp(j, 0, size - 1)) * std::size_t(size);
    double lit_row = 0;
    for (int k = 0; k < nx; ++k)
      if (ref <= row[ix[k]]) lit_row += wx[k];
    lit += wy * lit_row;
  }
  return std::clamp(lit / (4 * h * h), 0.0, 1.0);
}

}  // namespace

double shadow_pcf(const ShadowBuffer& buf, const Vec3& p, double bias, int radius) {
  const Vec4 c = buf.light_vp * p.homogeneous();
  const double n = buf.size;
  return pcf_window(buf, (c.x() * 0.5 + 0.5) * n, (c.y() * 0.5 + 0.5) * n, c.z() * 0.5 + 0.5,
                    bias * buf.depth_per_metre(), radius);
}

// ---- eq. (7) ------------------------------------------------------------------------------------

void HairShading::check(const std::string& where) const {
  auto nonneg = [&](const char* name, double v) {
    if (!(std::isfinite(v) && v >= 0)) fail_at(where, "{} = {} must be finite and >= 0", name, v);
  };
  nonneg("k_a", k_a);
  nonneg("k_d", k_d);
  nonneg("k_s", k_s);
  nonneg("n", n);
  nonneg("shadow_bias", shadow_bias);
  nonneg("shadow_slope_bias", shadow_slope_bias);
  if (!ambient_light.allFinite() || ambient_light.minCoeff() < 0)
    fail_at(where, "the ambient light L_A must be finite and >= 0");
  if (!color.allFinite() || color.minCoeff() < 0)
    fail_at(where, "the hair colour must be finite and >= 0");
  if (shadow_filter_radius < 0 || shadow_filter_radius > 16)
    fail_at(where, "shadow_filter_radius = {} is outside [0, 16]", shadow_filter_radius);
  if (key_light < -1) fail_at(where, "key_light = {} must be >= -1", key_light);
}

Vec3 hair_intensity_daldegan1993(const Vec3& tangent, const Vec3& to_eye, const Vec3& color,
                                 const HairShading& sh, std::span<const HairLight> lights,
                                 std::span<const double> s) {
  // (7) H = L_A K_A + sum_i S_i L_i (K_D sin(theta) + K_S cos^n(theta + phi - pi))
  Vec3 h = sh.ambient_light.cwiseProduct(sh.k_a * color);
  const double tn = tangent.norm(), en = to_eye.norm();
  if (!(tn > 0) || !(en > 0)) return h;
  const Vec3 t = tangent / tn;
  const double te = std::clamp(t.dot(to_eye) / en, -1.0, 1.0);  // cos(phi)
  const double se = std::sqrt(1 - te * te);                     // sin(phi)
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const double ln = lights[i].to_light.norm();
    if (!(ln > 0)) continue;
    const double tl = std::clamp(t.dot(lights[i].to_light) / ln, -1.0, 1.0);  // cos(theta)
    const double sl = std::sqrt(1 - tl * tl);                                 // sin(theta)
    // cos(theta + phi - pi) = sin(theta) sin(phi) - cos(theta) cos(phi) (Kajiya-Kay 1989)
    const double cs = sl * se - tl * te;
    const double spec = cs > 0 ? std::pow(cs, sh.n) : 0.0;
    const double si = s.empty() ? 1.0 : s[i];
    h += si * lights[i].radiance.cwiseProduct(sh.k_d * sl * color + Vec3::Constant(sh.k_s * spec));
  }
  return h;
}

double hair_shadow_bias(const HairShading& sh, const Vec3& t, const Vec3& l, double texel) {
  const double tn = t.norm(), ln = l.norm();
  double cot = 0;
  if (tn > 0 && ln > 0) {
    const double c = std::abs(t.dot(l)) / (tn * ln);
    const double s = std::sqrt(std::max(0.0, 1 - c * c));
    cot = s > c / kMaxCot ? c / s : kMaxCot;
  }
  return (sh.shadow_bias + sh.shadow_slope_bias * cot) * texel;
}

void shade_hair_vertices(const Context& ctx, const HairSegments& hair, std::size_t strand_begin,
                         std::size_t strand_end, std::span<const Vec3f> point_color,
                         const HairShading& sh, std::span<const HairLight> lights, const Vec3& eye,
                         std::span<Vec3f> out) {
  const std::string where = "hair shading";
  hair.check(where);
  sh.check(where);
  if (strand_begin > strand_end || strand_end > hair.num_strands())
    fail_at(where, "strands [{}, {}) are not within the {} strands", strand_begin, strand_end,
            hair.num_strands());
  if (out.size() != hair.num_points())
    fail_at(where, "{} output colours for {} points", out.size(), hair.num_points());
  if (!point_color.empty() && point_color.size() != hair.num_points())
    fail_at(where, "{} point colours for {} points", point_color.size(), hair.num_points());
  if (sh.mode == HairShadingMode::ShadowedColor && point_color.empty())
    fail_at(where, "shadowed colour shading needs one colour per point");
  if (!eye.allFinite()) fail_at(where, "the eye position is not finite");
  if (lights.size() > 64) fail_at(where, "{} lights given, at most 64", lights.size());
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const HairLight& l = lights[i];
    if (!l.to_light.allFinite() || !(l.to_light.norm() > 0))
      fail_at(where, "light {} direction is not a finite non-zero vector", i);
    if (!l.radiance.allFinite()) fail_at(where, "light {} radiance is not finite", i);
    if (l.shadow) l.shadow->check(fmt::format("{}: light {}", where, i));
  }
  const bool shadowed = sh.mode == HairShadingMode::ShadowedColor;
  const int key = shadowed && sh.key_light < int(lights.size()) ? sh.key_light : -1;
  // Per light, what every point needs: the unit direction, the radiance, and for the shadow
  // lookup the rows of the light's projection and the buffer's scales (the same arithmetic as
  // hair_intensity_daldegan1993(), hair_shadow_bias() and shadow_pcf(), hoisted).
  struct Pre {
    Vec3 l, radiance;
    const ShadowBuffer* buf = nullptr;
    Eigen::Matrix<double, 3, 4> rows;  // x, y, z rows of light_vp, scaled to window units
    double texel = 0, depth_per_m = 0;
  };
  std::vector<Pre> pre(lights.size());
  for (std::size_t li = 0; li < lights.size(); ++li) {
    Pre& q = pre[li];
    q.l = lights[li].to_light.normalized();
    q.radiance = lights[li].radiance;
    q.buf = lights[li].shadow;
    if (!q.buf) continue;
    const double n = q.buf->size;
    const Mat4& m = q.buf->light_vp;
    q.rows.row(0) = 0.5 * n * m.row(0);
    q.rows(0, 3) += 0.5 * n;
    q.rows.row(1) = 0.5 * n * m.row(1);
    q.rows(1, 3) += 0.5 * n;
    q.rows.row(2) = 0.5 * m.row(2);
    q.rows(2, 3) += 0.5;
    q.texel = q.buf->texel_world();
    q.depth_per_m = q.buf->depth_per_metre();
  }
  const int radius = sh.shadow_filter_radius;
  const double bias0 = sh.shadow_bias, bias1 = sh.shadow_slope_bias;
  const float nspec = float(sh.n);
  parallel_for(
      ctx, strand_begin, strand_end,
      [&](std::size_t st) {
        const uint32_t b = hair.offsets[st], e = hair.offsets[st + 1];
        for (uint32_t i = b; i < e; ++i) {
          const Vec3f tf = hair.points[std::min(i + 1, e - 1)] - hair.points[i > b ? i - 1 : b];
          const Vec3 p = hair.points[i].cast<double>();
          const Vec3 c = point_color.empty() ? sh.color : point_color[i].cast<double>();
          const double tn = tf.cast<double>().norm();
          const Vec3 t = tn > 0 ? Vec3(tf.cast<double>() / tn) : Vec3::Zero();
          // S_i of light li, with cos(theta) = tl and sin(theta) = sl of the hair to the light.
          auto shadow = [&](const Pre& q, double tl, double sl) {
            if (!q.buf) return 1.0;
            const double cot =
                tn > 0 ? (sl > std::abs(tl) / kMaxCot ? std::abs(tl) / sl : kMaxCot) : 0.0;
            const double bias = (bias0 + bias1 * cot) * q.texel;
            const Vec4 ph = p.homogeneous();
            return pcf_window(*q.buf, q.rows.row(0).dot(ph), q.rows.row(1).dot(ph),
                              q.rows.row(2).dot(ph), bias * q.depth_per_m, radius);
          };
          auto angles = [&](const Pre& q, double& tl, double& sl) {
            tl = std::clamp(t.dot(q.l), -1.0, 1.0);
            sl = std::sqrt(1 - tl * tl);
          };
          if (shadowed) {
            double sk = 1.0;
            if (key >= 0) {
              double tl, sl;
              angles(pre[std::size_t(key)], tl, sl);
              sk = shadow(pre[std::size_t(key)], tl, sl);
            }
            out[i] = (c * (sh.k_a + (1 - sh.k_a) * sk)).cast<float>();
            continue;
          }
          // (7) H = L_A K_A + sum_i S_i L_i (K_D sin(theta) + K_S cos^n(theta + phi - pi))
          Vec3 h = sh.ambient_light.cwiseProduct(sh.k_a * c);
          const Vec3 to_eye = eye - p;
          const double en = to_eye.norm();
          if (tn > 0 && en > 0) {
            const double te = std::clamp(t.dot(to_eye) / en, -1.0, 1.0);
            const double se = std::sqrt(1 - te * te);
            for (const Pre& q : pre) {
              double tl, sl;
              angles(q, tl, sl);
              const double si = shadow(q, tl, sl);
              if (si <= 0) continue;
              const double cs = sl * se - tl * te;
              const double spec = cs > 0 ? double(std::pow(float(cs), nspec)) : 0.0;
              h += si * q.radiance.cwiseProduct(sh.k_d * sl * c + Vec3::Constant(sh.k_s * spec));
            }
          }
          out[i] = h.cast<float>();
        }
      },
      64);
}

// ---- blending -----------------------------------------------------------------------------------

namespace {

/// The share of a unit pixel square on the side n.(q - centre) <= t of a line with unit normal
/// n = (nx, ny): the cumulative distribution of the square's projection onto n, a trapezoid
/// of support |t| <= h2 = (|nx| + |ny|) / 2 and flat top |t| <= h1 = ||nx| - |ny|| / 2.
struct SquareCdf {
  float lo = 1, sm = 0, h1 = 0.5f, h2 = 0.5f, inv_lo = 1, inv_2ls = 0;
  SquareCdf(float nx, float ny) {
    lo = std::max(std::abs(nx), std::abs(ny));
    sm = std::min(std::abs(nx), std::abs(ny));
    h1 = 0.5f * (lo - sm);
    h2 = 0.5f * (lo + sm);
    inv_lo = 1 / lo;
    inv_2ls = sm > 1e-6f ? 0.5f / (lo * sm) : 0;
  }
  float operator()(float t) const {
    if (t <= -h2) return 0;
    if (t >= h2) return 1;
    if (inv_2ls == 0) return (t + h2) * inv_lo;  // axis-aligned: linear
    if (t <= -h1) return (t + h2) * (t + h2) * inv_2ls;
    if (t >= h1) return 1 - (h2 - t) * (h2 - t) * inv_2ls;
    return 0.5f * sm * inv_lo + (t + h1) * inv_lo;
  }
};

/// A segment in window coordinates, after clipping at the near plane.
struct SegWin {
  double ax, ay, az, bx, by, bz;  // endpoints: window x, y [px] and depth
  double hw;                      // half width [px]
  double ta, tb;                  // their parameters along the 3D segment (for the colours)
};

/// The window form of segment (p, p + 1); false when it lies wholly behind the near plane.
bool segment_window(const Mat4& vp, const HairSegments& hair, uint32_t p,
                    const HairBlender::Point& a, const HairBlender::Point& b, int fb_w, int fb_h,
                    SegWin& s) {
  if (a.w_px >= 0 && b.w_px >= 0) {
    s = {a.x, a.y, a.z, b.x, b.y, b.z, 0.25 * (double(a.w_px) + double(b.w_px)), 0.0, 1.0};
    return true;
  }
  if (a.w_px < 0 && b.w_px < 0) return false;
  // One end behind the near plane z + w = 0: clip there (in double, from the world points).
  const Vec4 ca = vp * hair.points[p].cast<double>().homogeneous();
  const Vec4 cb = vp * hair.points[p + 1].cast<double>().homogeneous();
  const double da = ca.z() + ca.w(), db = cb.z() + cb.w();
  const double t = da / (da - db);
  const Vec4 cc = ca + t * (cb - ca);
  if (!(cc.w() > 1e-12)) return false;
  const double x = (cc.x() / cc.w() * 0.5 + 0.5) * fb_w, y = (cc.y() / cc.w() * 0.5 + 0.5) * fb_h;
  const double z = cc.z() / cc.w() * 0.5 + 0.5;
  if (a.w_px >= 0)
    s = {a.x, a.y, a.z, x, y, z, 0.5 * double(a.w_px), 0.0, t};
  else
    s = {x, y, z, b.x, b.y, b.z, 0.5 * double(b.w_px), t, 1.0};
  return true;
}

}  // namespace

void HairBlender::prepare(const Context& ctx, const Mat4& view_proj, const HairSegments& hair,
                          int fb_width, int fb_height, int samples) {
  const std::string where = "hair blend";
  if (fb_width < 1 || fb_height < 1 || fb_width > 65536 || fb_height > 65536)
    fail_at(where, "framebuffer {}x{} is not a valid size", fb_width, fb_height);
  if (samples < 1 || samples > 16 || fb_width % samples != 0 || fb_height % samples != 0)
    fail_at(where, "supersampling {} does not divide the {}x{} framebuffer", samples, fb_width,
            fb_height);
  if (!view_proj.allFinite()) fail_at(where, "the view-projection is not finite");
  hair.check(where);
  m_view_proj = view_proj;
  m_fb_w = fb_width;
  m_fb_h = fb_height;
  m_k = samples;
  m_cw = fb_width / samples;
  m_ch = fb_height / samples;
  const int cell_w = m_cw, cell_h = m_ch;
  const float inv_k = 1.0f / float(samples);
  m_hair = &hair;
  m_bounds = {0, 0, 0, 0};
  const std::size_t np = hair.num_points(), ns = hair.num_strands();
  m_pts.resize(np);
  // Cells per metre at clip w = 1 (perspective: divided by w; orthographic: w = 1).
  const double px_per_m = 0.5 * cell_h * view_proj.row(1).head<3>().norm();
  const bool radii = !hair.radius.empty();
  parallel_for(
      ctx, 0, ns,
      [&](std::size_t st) {
        for (uint32_t i = hair.offsets[st]; i < hair.offsets[st + 1]; ++i) {
          const Vec4 c = view_proj * hair.points[i].cast<double>().homogeneous();
          Point& w = m_pts[i];
          w.r = w.g = w.b = 0;
          w.alpha = hair.opacity[st];
          if (!(c.w() > 1e-12 && c.z() + c.w() >= 0)) {
            w.x = w.y = w.z = 0;
            w.w_px = -1;
            continue;
          }
          const double iw = 1 / c.w();
          w.x = float((c.x() * iw * 0.5 + 0.5) * cell_w);
          w.y = float((c.y() * iw * 0.5 + 0.5) * cell_h);
          w.z = float(c.z() * iw * 0.5 + 0.5);
          w.w_px = radii && hair.radius[i] >= 0 ? float(2 * double(hair.radius[i]) * px_per_m * iw)
                                                : hair.width_px[st] * inv_k;
        }
      },
      64);
  m_seg_base.assign(ns + 1, 0);
  for (std::size_t s = 0; s < ns; ++s) {
    const uint32_t n = hair.offsets[s + 1] - hair.offsets[s];
    m_seg_base[s + 1] = m_seg_base[s] + (n >= 2 ? n - 1 : 0);
  }
  const std::size_t nseg = m_seg_base[ns];
  m_segs.resize(nseg);
  // Per segment: its band range; the union of the segments' pixel boxes by a reduction
  // (min / max: exact in any order).
  using Box = std::array<double, 4>;
  const double inf = std::numeric_limits<double>::infinity();
  const Box box = deterministic_reduce(
      ctx, ns, 256, Box{inf, inf, -inf, -inf},
      [&](std::size_t s0, std::size_t s1) {
        Box bx{inf, inf, -inf, -inf};
        for (std::size_t st = s0; st < s1; ++st) {
          const uint32_t first = hair.offsets[st];
          for (uint32_t j = m_seg_base[st]; j < m_seg_base[st + 1]; ++j) {
            const uint32_t p = first + (j - m_seg_base[st]);
            Segment& sg = m_segs[j];
            sg = {p, 0xffffu};  // band lo 0xffff > hi 0: in no band
            SegWin s;
            if (m_pts[p].alpha <= 0 ||
                !segment_window(view_proj, hair, p, m_pts[p], m_pts[p + 1], cell_w, cell_h, s))
              continue;
            const double e = s.hw + 1.5;
            const double x0 = std::min(s.ax, s.bx) - e, x1 = std::max(s.ax, s.bx) + e;
            const double y0 = std::min(s.ay, s.by) - e, y1 = std::max(s.ay, s.by) + e;
            if (!(x1 >= 0 && x0 < cell_w && y1 >= 0 && y0 < cell_h)) continue;  // also NaN
            bx = {std::min(bx[0], x0), std::min(bx[1], y0), std::max(bx[2], x1),
                  std::max(bx[3], y1)};
            const int b0 = int(std::max(0.0, y0)) / kBlendBandRows;
            const int b1 = int(std::min(double(cell_h - 1), y1)) / kBlendBandRows;
            sg.bands = uint32_t(b0) | uint32_t(b1) << 16;
          }
        }
        return bx;
      },
      [](Box a, const Box& b) {
        return Box{std::min(a[0], b[0]), std::min(a[1], b[1]), std::max(a[2], b[2]),
                   std::max(a[3], b[3])};
      });
  if (box[0] < box[2]) {
    const int k = samples;
    m_bounds = {k * int(std::clamp(std::floor(box[0]), 0.0, double(cell_w))),
                k * int(std::clamp(std::floor(box[1]), 0.0, double(cell_h))),
                k * int(std::clamp(std::ceil(box[2]) + 1, 0.0, double(cell_w))),
                k * int(std::clamp(std::ceil(box[3]) + 1, 0.0, double(cell_h)))};
    if (m_bounds[0] >= m_bounds[2] || m_bounds[1] >= m_bounds[3]) m_bounds = {0, 0, 0, 0};
  }
}

namespace {

/// Stable LSD radix sort of (key << 32 | index) values by the key (4 passes of 8 bits).
void radix_sort_by_key(std::vector<uint64_t>& v, std::vector<uint64_t>& tmp) {
  tmp.resize(v.size());
  for (int sh = 32; sh < 64; sh += 8) {
    std::size_t count[257] = {};
    for (const uint64_t x : v) ++count[((x >> sh) & 255) + 1];
    if (count[((v.front() >> sh) & 255) + 1] == v.size()) continue;  // one digit: no change
    for (int d = 0; d < 256; ++d) count[d + 1] += count[d];
    for (const uint64_t x : v) tmp[count[(x >> sh) & 255]++] = x;
    v.swap(tmp);
  }
}

}  // namespace

void HairBlender::blend(const Context& ctx, const HairSegments& hair, std::span<const Vec3f> colors,
                        const HairFrame& target) {
  const std::string where = "hair blend";
  const HairFrame& tg = target;
  if (m_hair != &hair || hair.num_points() != m_pts.size())
    fail_at(where, "blend() needs the hair given to prepare()");
  if (tg.fb_width != m_fb_w || tg.fb_height != m_fb_h || tg.samples != m_k)
    fail_at(where, "the target framebuffer is {}x{} at supersampling {}, prepare() had {}x{} at {}",
            tg.fb_width, tg.fb_height, tg.samples, m_fb_w, m_fb_h, m_k);
  if (tg.x0 % m_k != 0 || tg.y0 % m_k != 0 || tg.width % m_k != 0 || tg.height % m_k != 0)
    fail_at(where, "window {}x{} at ({}, {}) is not aligned to the supersampling {}", tg.width,
            tg.height, tg.x0, tg.y0, m_k);
  if (tg.width < 0 || tg.height < 0 || tg.x0 < 0 || tg.y0 < 0 || tg.x0 + tg.width > tg.fb_width ||
      tg.y0 + tg.height > tg.fb_height)
    fail_at(where, "window {}x{} at ({}, {}) does not fit the {}x{} framebuffer", tg.width,
            tg.height, tg.x0, tg.y0, tg.fb_width, tg.fb_height);
  if (colors.size() != hair.num_points())
    fail_at(where, "{} colours for {} points", colors.size(), hair.num_points());
  if (tg.width == 0 || tg.height == 0 || m_segs.empty()) return;
  if (!tg.rgba || !tg.depth) fail_at(where, "the colour or depth buffer is missing");
  if (tg.rgba_stride != 0 && tg.rgba_stride < tg.width)
    fail_at(where, "colour row stride {} is less than the window width {}", tg.rgba_stride,
            tg.width);
  // Colours travel as 16-bit fractions of the largest component (a max: exact in any order).
  const float cmax = deterministic_reduce(
      ctx, colors.size(), 1 << 16, 0.0f,
      [&](std::size_t b, std::size_t e) {
        float m = 0;
        for (std::size_t i = b; i < e; ++i) {
          const Vec3f& c = colors[i];
          if (!c.allFinite() || c.minCoeff() < 0) return std::numeric_limits<float>::quiet_NaN();
          m = std::max(m, c.maxCoeff());
        }
        return m;
      },
      [](float a, float b) { return std::isnan(a) || std::isnan(b) ? a + b : std::max(a, b); });
  if (!std::isfinite(cmax)) fail_at(where, "a point colour is not finite and >= 0");
  const float to16 = cmax > 0 ? 65535.0f / cmax : 0.0f, from16 = cmax / 65535.0f;
  parallel_chunks(ctx, m_pts.size(), 8192, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      m_pts[i].r = colors[i].x();
      m_pts[i].g = colors[i].y();
      m_pts[i].b = colors[i].z();
    }
  });
  // Every band's segments, in input order: one streaming pass over the segments.
  const int bands = (m_ch + kBlendBandRows - 1) / kBlendBandRows;
  bucket<BandSegment>(
      ctx, m_segs.size(), std::size_t(bands),
      [&](std::size_t j) {
        const uint32_t r = m_segs[j].bands;
        return std::pair<int, int>{int(r & 0xffffu), int(r >> 16)};
      },
      [&](std::size_t j) {
        const uint32_t p = m_segs[j].point;
        const Point& pa = m_pts[p];
        const Point& pb = m_pts[p + 1];
        SegWin s;
        BandSegment b{};
        if (!segment_window(m_view_proj, hair, p, pa, pb, m_cw, m_ch, s)) return b;
        b.ax = float(s.ax);
        b.ay = float(s.ay);
        b.az = float(s.az);
        b.bx = float(s.bx);
        b.by = float(s.by);
        b.bz = float(s.bz);
        b.hw = float(s.hw);
        b.alpha = pa.alpha;
        const float c0[3] = {pa.r, pa.g, pa.b}, c1[3] = {pb.r, pb.g, pb.b};
        for (int c = 0; c < 3; ++c) {
          const float ca = c0[c] + float(s.ta) * (c1[c] - c0[c]);
          const float cb = c0[c] + float(s.tb) * (c1[c] - c0[c]);
          b.ca[c] = uint16_t(std::clamp(ca * to16 + 0.5f, 0.0f, 65535.0f));
          b.cb[c] = uint16_t(std::clamp(cb * to16 + 0.5f, 0.0f, 65535.0f));
        }
        return b;
      },
      m_band_start, m_band_segs);
  const std::size_t stride = std::size_t(tg.rgba_stride ? tg.rgba_stride : tg.width);
  const int k = m_k, kk = k * k;
  const float inv_kk = 1.0f / float(kk);
  // The window in cells.
  const int wx0 = tg.x0 / k, wy0 = tg.y0 / k, ww = tg.width / k, wh = tg.height / k;
  const int b_first = wy0 / kBlendBandRows;
  const int b_last = (wy0 + wh - 1) / kBlendBandRows;
  parallel_for(
      ctx, std::size_t(b_first), std::size_t(b_last) + 1,
      [&](std::size_t band) {
        const int r0 = std::max(wy0, int(band) * kBlendBandRows);
        const int r1 = std::min(wy0 + wh, int(band + 1) * kBlendBandRows);
        const uint32_t k0 = m_band_start[band], k1 = m_band_start[band + 1];
        if (k0 == k1) return;
        const BandSegment* segs = m_band_segs.data() + k0;
        // Near to far by the midpoint depth (depths >= 0, whose float bits order like the
        // values), stable: ties keep the input order.
        BandScratch& sc = m_scratch.local();
        sc.order.resize(k1 - k0);
        for (uint32_t j = 0; j < k1 - k0; ++j) {
          const float zm = std::max(0.0f, 0.5f * (segs[j].az + segs[j].bz));
          uint32_t bits;
          std::memcpy(&bits, &zm, 4);
          sc.order[j] = uint64_t(bits) << 32 | j;
        }
        radix_sort_by_key(sc.order, sc.tmp);
        // The band's hair alone (premultiplied), composited under what is in front; per cell
        // the nearest and farthest scene depth of its k x k pixels; per block of kBlockCols
        // columns the count of cells not yet opaque and the farthest scene depth.
        const int rows = r1 - r0;
        const int nblocks = (ww + kBlockCols - 1) / kBlockCols;
        sc.acc.assign(4 * std::size_t(rows) * std::size_t(ww), 0.0f);
        sc.zcell.resize(2 * std::size_t(rows) * std::size_t(ww));
        sc.open.resize(std::size_t(nblocks));
        sc.zmax.assign(std::size_t(nblocks), 0.0f);
        for (int b = 0; b < nblocks; ++b)
          sc.open[std::size_t(b)] = rows * (std::min(ww, (b + 1) * kBlockCols) - b * kBlockCols);
        int open_blocks = nblocks;
        for (int cy = r0; cy < r1; ++cy) {
          float* zc = sc.zcell.data() + 2 * std::size_t(cy - r0) * std::size_t(ww);
          for (int cx = 0; cx < ww; ++cx) {
            float lo = 2, hi = -1;
            for (int j = 0; j < k; ++j) {
              const float* d = tg.depth + std::size_t((cy - wy0) * k + j) * std::size_t(tg.width) +
                               std::size_t(cx * k);
              for (int i = 0; i < k; ++i) {
                lo = std::min(lo, d[i]);
                hi = std::max(hi, d[i]);
              }
            }
            zc[2 * cx] = lo;
            zc[2 * cx + 1] = hi;
            float& m = sc.zmax[std::size_t(cx / kBlockCols)];
            m = std::max(m, hi);
          }
        }
        const std::size_t n_order = sc.order.size();
        for (std::size_t oi = 0; oi < n_order; ++oi) {
          if (open_blocks == 0) break;  // the band's hair is opaque everywhere
          if (oi + 8 < n_order) __builtin_prefetch(&segs[uint32_t(sc.order[oi + 8])]);
          const BandSegment& s = segs[uint32_t(sc.order[oi])];
          const float ax = s.ax, ay = s.ay, bx = s.bx, by = s.by;
          const float dx = bx - ax, dy = by - ay;
          const float len = std::sqrt(dx * dx + dy * dy);
          if (!(len > 1e-6f) || !(s.alpha > 0)) continue;  // end-on (no coverage), or culled
          const float hw = s.hw;
          {  // skip a segment over blocks whose hair is opaque or whose scene is nearer
            const float e = hw + 1.5f;
            const int c0 = std::max(0, int(std::floor(std::min(ax, bx) - e)) - wx0);
            const int c1 = std::min(ww - 1, int(std::floor(std::max(ax, bx) + e)) - wx0);
            if (c0 > c1) continue;
            const float zmin = std::min(s.az, s.bz);
            bool any = false;
            for (int b = c0 / kBlockCols; b <= c1 / kBlockCols && !any; ++b)
              any = sc.open[std::size_t(b)] > 0 && zmin < sc.zmax[std::size_t(b)];
            if (!any) continue;
          }
          const float inv_len = 1 / len;
          const float ux = dx * inv_len, uy = dy * inv_len, nx = -uy, ny = ux;
          const SquareCdf cdf(nx, ny);
          const float reach = hw + cdf.h2;
          const double az = s.az, dz = double(s.bz) - s.az;
          const float alpha = s.alpha;
          float ca[3], dc[3];
          for (int c = 0; c < 3; ++c) {
            ca[c] = float(s.ca[c]) * from16;
            dc[c] = float(s.cb[c]) * from16 - ca[c];
          }
          const int y_lo = std::max(r0, int(std::floor(std::min(ay, by) - hw - 1.5f)));
          const int y_hi = std::min(r1 - 1, int(std::floor(std::max(ay, by) + hw + 1.5f)));
          // Per row: the cell centres x with |n.(p - a)| < hw + h2 and -1/2 < u.(p - a) <
          // len + 1/2 (coverage > 0): an interval whose ends move linearly with the row.
          const bool steep_n = std::abs(nx) > 1e-6f, steep_u = std::abs(ux) > 1e-6f;
          const float inv_nx = steep_n ? 1 / nx : 0, inv_ux = steep_u ? 1 / ux : 0;
          const float rn = reach * std::abs(inv_nx);
          const float ua = (inv_ux < 0 ? len + 0.5f : -0.5f) * inv_ux;  // lower end offset
          const float ub = (inv_ux < 0 ? -0.5f : len + 0.5f) * inv_ux;  // upper end offset
          for (int y = y_lo; y <= y_hi; ++y) {
            const float ry = float(y) + 0.5f - ay;
            float lo = float(wx0) + 0.5f, hi = float(wx0 + ww) - 0.5f;  // cell centres
            if (steep_n) {
              const float m = ax - ny * ry * inv_nx;
              lo = std::max(lo, m - rn);
              hi = std::min(hi, m + rn);
            } else if (std::abs(ny * ry) >= reach) {
              continue;
            }
            if (steep_u) {
              const float m = ax - uy * ry * inv_ux;
              lo = std::max(lo, m + ua);
              hi = std::min(hi, m + ub);
            } else if (uy * ry <= -0.5f || uy * ry >= len + 0.5f) {
              continue;
            }
            if (!(lo <= hi)) continue;
            // Cells x with lo <= x + 1/2 <= hi (lo >= 1/2: the conversion truncates).
            const int x0 = int(std::ceil(lo - 0.5f));
            const int x1 = int(hi - 0.5f);
            if (x0 > x1) continue;
            float* arow = sc.acc.data() + 4 * std::size_t(y - r0) * std::size_t(ww);
            const float* zrow = sc.zcell.data() + 2 * std::size_t(y - r0) * std::size_t(ww);
            const float rx0 = float(x0) + 0.5f - ax;
            float d = nx * rx0 + ny * ry, sa = ux * rx0 + uy * ry;
            for (int x = x0; x <= x1; ++x, d += nx, sa += ux) {
              const int cx = x - wx0;
              float* px = arow + 4 * std::size_t(cx);
              if (px[3] >= kOpaque) continue;  // nothing behind shows any more
              // Across: the area of the cell inside the strip; along: the overlap of a unit
              // interval with the segment.
              const float across = cdf(d + hw) - cdf(d - hw);
              const float along = std::min(sa + 0.5f, len) - std::max(sa - 0.5f, 0.0f);
              if (across <= 0 || along <= 0) continue;
              const float t = std::clamp(sa * inv_len, 0.0f, 1.0f);
              const float z = float(az + double(t) * dz);
              // GL_LESS against the scene's Z-buffer, per pixel of the cell.
              float shown = 1;
              if (!(z < zrow[2 * cx])) {
                if (!(z < zrow[2 * cx + 1])) continue;  // behind all of them
                int n = 0;
                for (int j = 0; j < k; ++j) {
                  const float* dd = tg.depth +
                                    std::size_t((y - wy0) * k + j) * std::size_t(tg.width) +
                                    std::size_t(cx * k);
                  for (int i = 0; i < k; ++i) n += z < dd[i];
                }
                shown = float(n) * inv_kk;
              }
              const float a = std::min(1.0f, alpha * across * along) * shown;
              // Under: what is already there is in front.
              const float w = (1 - px[3]) * a;
              for (int c = 0; c < 3; ++c) px[c] += w * (ca[c] + t * dc[c]);
              px[3] += w;
              if (px[3] >= kOpaque) {
                const int b = cx / kBlockCols;
                if (--sc.open[std::size_t(b)] == 0) --open_blocks;
              }
            }
          }
        }
        // The band's hair over each pixel of its cells.
        for (int cy = r0; cy < r1; ++cy) {
          const float* arow = sc.acc.data() + 4 * std::size_t(cy - r0) * std::size_t(ww);
          for (int j = 0; j < k; ++j) {
            float* crow = tg.rgba + 4 * std::size_t((cy - wy0) * k + j) * stride;
            for (int cx = 0; cx < ww; ++cx) {
              const float* a = arow + 4 * std::size_t(cx);
              if (!(a[3] > 0)) continue;
              const float t = 1 - a[3];
              for (int i = 0; i < k; ++i) {
                float* px = crow + 4 * std::size_t(cx * k + i);
                for (int c = 0; c < 4; ++c) px[c] = a[c] + t * px[c];
              }
            }
          }
        }
      },
      1);
}

void blend_hair(const Context& ctx, const Mat4& view_proj, const HairSegments& hair,
                std::span<const Vec3f> colors, const HairFrame& target) {
  HairBlender b;
  b.prepare(ctx, view_proj, hair, target.fb_width, target.fb_height, target.samples);
  b.blend(ctx, hair, colors, target);
}

}  // namespace follicle::render
