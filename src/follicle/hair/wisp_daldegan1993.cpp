#include "follicle/hair/wisp_daldegan1993.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/core/rng.hpp"

namespace follicle::hair {

void WispParams::validate() const {
  validate_params(*this, "wisps");
  if (mode != "offset" && mode != "paper")
    fail_at("wisps.mode", "unknown wisp mode \"{}\"; expected offset or paper", mode);
}

namespace {

// Uniform grid over the guide roots for nearest-root queries in growing rings of cells.
class RootGrid {
 public:
  explicit RootGrid(const std::vector<Vec3>& pts) : m_pts(pts) {
    Eigen::AlignedBox3d box;
    for (const Vec3& p : pts) box.extend(p);
    m_lo = box.min();
    const Vec3 ext = box.sizes();
    // Roots lie on a surface: about two guides per occupied cell for a cap-like spread.
    const double area = std::max({ext.x() * ext.y(), ext.y() * ext.z(), ext.z() * ext.x(),
                                  ext.maxCoeff() * ext.maxCoeff() * 1e-6, 1e-18});
    m_h = std::max(std::sqrt(2.0 * area / double(pts.size())), 1e-9);
    for (int c = 0; c < 3; ++c) m_dim[c] = std::clamp(int(ext[c] / m_h) + 1, 1, 1024);
    for (int c = 0; c < 3; ++c) m_h = std::max(m_h, ext[c] / m_dim[c] * (1 + 1e-9));
    const std::size_t cells = std::size_t(m_dim[0]) * std::size_t(m_dim[1]) * std::size_t(m_dim[2]);
    m_start.assign(cells + 1, 0);
    std::vector<std::size_t> cell_of(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) {
      cell_of[i] = cell_index(cell_coord(pts[i]));
      ++m_start[cell_of[i] + 1];
    }
    for (std::size_t c = 0; c < cells; ++c) m_start[c + 1] += m_start[c];
    m_items.resize(pts.size());
    std::vector<uint32_t> fill(m_start.begin(), m_start.end() - 1);
    for (std::size_t i = 0; i < pts.size(); ++i)
      m_items[fill[cell_of[i]]++] = uint32_t(i);  // stable
  }

  // Nearest point to q (ties: lowest index).
  uint32_t nearest(const Vec3& q) const {
    long long qc[3], dim[3];
    for (int c = 0; c < 3; ++c) {
      qc[c] = (long long)std::clamp(std::floor((q[c] - m_lo[c]) / m_h), -1e12, 1e12);
      dim[c] = m_dim[c];
    }
    // Rings of Chebyshev radius r around q's (possibly outside) cell, from the first that meets
    // the grid; after ring r every point not yet seen is farther than r h from q.
    long long r0 = 0, rmax = 0;
    for (int c = 0; c < 3; ++c) {
      r0 = std::max({r0, -qc[c], qc[c] - (dim[c] - 1)});
      rmax = std::max({rmax, std::abs(qc[c]), std::abs(qc[c] - (dim[c] - 1))});
    }
    double best = std::numeric_limits<double>::infinity();
    uint32_t best_i = 0;
    for (long long r = r0; r <= rmax; ++r) {
      const long long z0 = std::max(0LL, qc[2] - r), z1 = std::min(dim[2] - 1, qc[2] + r);
      const long long y0 = std::max(0LL, qc[1] - r), y1 = std::min(dim[1] - 1, qc[1] + r);
      for (long long z = z0; z <= z1; ++z)
        for (long long y = y0; y <= y1; ++y) {
          const bool shell_zy = std::llabs(z - qc[2]) == r || std::llabs(y - qc[1]) == r;
          // Cells of the ring in this (z, y) row: all of them on the shell, else the two ends.
          const long long xs[2] = {qc[0] - r, qc[0] + r};
          const long long x0 = std::max(0LL, qc[0] - r), x1 = std::min(dim[0] - 1, qc[0] + r);
          auto scan = [&](long long x) {
            const std::size_t cell = cell_index(Eigen::Vector3i(int(x), int(y), int(z)));
            for (std::size_t k = m_start[cell]; k < m_start[cell + 1]; ++k) {
              const uint32_t i = m_items[k];
              const double d = (m_pts[i] - q).squaredNorm();
              if (d < best || (d == best && i < best_i)) {
                best = d;
                best_i = i;
              }
            }
          };
          if (shell_zy) {
            for (long long x = x0; x <= x1; ++x) scan(x);
          } else {
            for (int e = 0; e < (r > 0 ? 2 : 1); ++e)
              if (xs[e] >= 0 && xs[e] < dim[0]) scan(xs[e]);
          }
        }
      if (best <= (double(r) * m_h) * (double(r) * m_h)) break;
    }
    return best_i;
  }

 private:
  Eigen::Vector3i cell_coord(const Vec3& p) const {
    Eigen::Vector3i c;
    for (int k = 0; k < 3; ++k) c[k] = std::clamp(int((p[k] - m_lo[k]) / m_h), 0, m_dim[k] - 1);
    return c;
  }
  std::size_t cell_index(const Eigen::Vector3i& c) const {
    return (std::size_t(c[2]) * std::size_t(m_dim[1]) + std::size_t(c[1])) * std::size_t(m_dim[0]) +
           std::size_t(c[0]);
  }
  const std::vector<Vec3>& m_pts;
  Vec3 m_lo = Vec3::Zero();
  double m_h = 1.0;
  int m_dim[3] = {1, 1, 1};
  std::vector<std::size_t> m_start;
  std::vector<uint32_t> m_items;
};

// Rest arc-length fractions of the points of strand s (0 at the root, 1 at the tip; a strand of
// zero length gets its point index fraction).
void fractions(const geom::StrandSet& set, std::size_t s, float* out) {
  const uint32_t b = set.offsets[s], n = set.strand_size(s);
  double total = 0;
  for (uint32_t j = 1; j < n; ++j)
    total += (set.points[b + j] - set.points[b + j - 1]).cast<double>().norm();
  double acc = 0;
  out[0] = 0.0f;
  for (uint32_t j = 1; j < n; ++j) {
    acc += (set.points[b + j] - set.points[b + j - 1]).cast<double>().norm();
    out[j] = total > 0 ? float(acc / total) : float(double(j) / double(n - 1));
  }
  if (n > 1) out[n - 1] = 1.0f;
}

template <class ForEach>
WispBinding bind_impl(const geom::StrandSet& guides, const geom::StrandSet& full,
                      const WispParams& params, ForEach&& for_each) {
  params.validate();
  guides.check("wisp guides");
  full.check("wisp full hair");
  const std::size_t G = guides.num_strands(), F = full.num_strands();
  if (G == 0) fail("wisps: no guide strands to bind to");
  for (std::size_t g = 0; g < G; ++g)
    if (guides.strand_size(g) == 0) fail("wisps: guide strand {} has no point", g);
  for (std::size_t f = 0; f < F; ++f)
    if (full.strand_size(f) == 0) fail("wisps: strand {} of the full hair has no point", f);
  WispBinding b;
  b.paper = params.mode == "paper";
  b.guide_offsets = guides.offsets;
  b.guide_u.resize(guides.points.size());
  for (std::size_t g = 0; g < G; ++g) fractions(guides, g, b.guide_u.data() + guides.offsets[g]);
  b.offsets = full.offsets;
  b.u.resize(full.points.size());
  b.guide.resize(F);
  std::vector<Vec3> roots(G);
  for (std::size_t g = 0; g < G; ++g) roots[g] = guides.points[guides.offsets[g]].cast<double>();
  const RootGrid grid(roots);
  if (b.paper)
    b.shift.resize(F);
  else
    b.rest = full.points;
  for_each(F, [&](std::size_t f) {
    fractions(full, f, b.u.data() + full.offsets[f]);
    const Vec3 root = full.points[full.offsets[f]].cast<double>();
    const uint32_t g = grid.nearest(root);
    b.guide[f] = g;
    if (b.paper) {
      // "adding random numbers to the origin of the typical strands": the follower's own root
      // offset plus a uniform random point of the ball of radius `jitter` (stream f).
      Vec3 j = Vec3::Zero();
      if (params.jitter > 0) {
        Rng rng = Rng::stream(params.seed, f);
        do {
          j = Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        } while (j.squaredNorm() > 1.0);
        j *= params.jitter;
      }
      b.shift[f] = (root - roots[g] + j).cast<float>();
    }
  });
  return b;
}

template <class ForEach>
void apply_impl(const WispBinding& b, const geom::StrandSet& grest, const geom::StrandSet& gnow,
                const Quat& rotation, geom::StrandSet& out, ForEach&& for_each) {
  if (grest.offsets != b.guide_offsets)
    fail("wisps: the rest guides do not match the binding ({} strands / {} points expected)",
         b.num_guides(), b.guide_u.size());
  if (gnow.offsets != b.guide_offsets)
    fail("wisps: the current guides do not match the binding ({} strands / {} points expected)",
         b.num_guides(), b.guide_u.size());
  const Mat3 R = rotation.normalized().toRotationMatrix();
  const Mat3 RmI = R - Mat3::Identity();
  out.offsets = b.offsets;
  const std::size_t np = b.u.size();
  out.points.resize(np);
  if (out.radius.size() != np) out.radius.clear();
  if (out.color.size() != np) out.color.clear();
  for_each(b.num_followers(), [&](std::size_t f) {
    const uint32_t g = b.guide[f];
    const uint32_t gb = b.guide_offsets[g], gn = b.guide_offsets[g + 1] - gb;
    const uint32_t fb = b.offsets[f], fn = b.offsets[f + 1] - fb;
    const Vec3 shift = b.paper ? Vec3(R * b.shift[f].cast<double>()) : Vec3::Zero();
    uint32_t k = 0;  // guide segment [k, k+1] holding the fraction (fractions are ascending)
    for (uint32_t j = 0; j < fn; ++j) {
      const float u = b.u[fb + j];
      while (k + 2 < gn && b.guide_u[gb + k + 1] < u) ++k;
      Vec3 now, rest;
      if (gn == 1) {
        now = gnow.points[gb].cast<double>();
        rest = grest.points[gb].cast<double>();
      } else {
        const double u0 = b.guide_u[gb + k], u1 = b.guide_u[gb + k + 1];
        const double w = u1 > u0 ? std::clamp((double(u) - u0) / (u1 - u0), 0.0, 1.0) : 0.0;
        now = (1 - w) * gnow.points[gb + k].cast<double>() +
              w * gnow.points[gb + k + 1].cast<double>();
        rest = (1 - w) * grest.points[gb + k].cast<double>() +
               w * grest.points[gb + k + 1].cast<double>();
      }
      if (b.paper) {
        out.points[fb + j] = (now + shift).cast<float>();
      } else {
        // x = x_rest + (g_now - g_rest) + (R - I)(x_rest - g_rest) = g_now + R (x_rest - g_rest),
        // written so that still guides and R = I give x_rest bit for bit.
        const Vec3 xr = b.rest[fb + j].cast<double>();
        out.points[fb + j] = (xr + (now - rest) + RmI * (xr - rest)).cast<float>();
      }
    }
  });
}

auto serial = [](std::size_t n, const auto& f) {
  for (std::size_t i = 0; i < n; ++i) f(i);
};

}  // namespace

WispBinding bind_wisps(const geom::StrandSet& guides_rest, const geom::StrandSet& full_rest,
                       const WispParams& params) {
  return bind_impl(guides_rest, full_rest, params, serial);
}

WispBinding bind_wisps(const Context& ctx, const geom::StrandSet& guides_rest,
                       const geom::StrandSet& full_rest, const WispParams& params) {
  return bind_impl(guides_rest, full_rest, params,
                   [&](std::size_t n, const auto& f) { parallel_for(ctx, 0, n, f, 512); });
}

void apply_wisps(const WispBinding& binding, const geom::StrandSet& guides_rest,
                 const geom::StrandSet& guides_now, const Quat& head_rotation,
                 geom::StrandSet& full_out) {
  apply_impl(binding, guides_rest, guides_now, head_rotation, full_out, serial);
}

void apply_wisps(const WispBinding& binding, const geom::StrandSet& guides_rest,
                 const geom::StrandSet& guides_now, const HeadMotion& head,
                 geom::StrandSet& full_out) {
  apply_impl(binding, guides_rest, guides_now, head.rotation, full_out, serial);
}

void apply_wisps(const Context& ctx, const WispBinding& binding, const geom::StrandSet& guides_rest,
                 const geom::StrandSet& guides_now, const Quat& head_rotation,
                 geom::StrandSet& full_out) {
  apply_impl(binding, guides_rest, guides_now, head_rotation, full_out,
             [&](std::size_t n, const auto& f) { parallel_for(ctx, 0, n, f, 256); });
}

}  // namespace follicle::hair
