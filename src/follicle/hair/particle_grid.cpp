#include "follicle/hair/particle_grid.hpp"

#include <algorithm>
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

#include "follicle/core/cpu.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"

namespace follicle::hair {

namespace detail {

void CellTable::build(const Context* ctx, const std::vector<Vec3>& points, double inv_cell) {
  inv = inv_cell;
  const std::size_t n = points.size();
  std::size_t nb = 64;
  while (nb < 2 * n) nb *= 2;
  mask = uint32_t(nb - 1);
  const bool par = ctx && ctx->threads() > 1 && n >= 4096;
  bucket_of.resize(n);
  cell_of.resize(n);
  auto cell = [&](std::size_t i) {
    const Vec3& p = points[i];
    cell_of[i] = {int(std::floor(p.x() * inv)), int(std::floor(p.y() * inv)),
                  int(std::floor(p.z() * inv))};
  };
  if (par)
    parallel_for(*ctx, 0, n, cell, 2048);
  else
    for (std::size_t i = 0; i < n; ++i) cell(i);
  // The box of the occupied cells decides the layout (dense when it has at most nb cells).
  dense = false;
  if (n > 0) {
    std::array<int, 3> mn = cell_of[0], mx = cell_of[0];
    for (std::size_t i = 1; i < n; ++i)
      for (int a = 0; a < 3; ++a) {
        mn[a] = std::min(mn[a], cell_of[i][a]);
        mx[a] = std::max(mx[a], cell_of[i][a]);
      }
    int64_t cells = 1;
    dense = true;
    for (int a = 0; a < 3 && dense; ++a) {
      const int64_t d = int64_t(mx[a]) - int64_t(mn[a]) + 1;
      dense = d <= int64_t(nb) && cells * d <= int64_t(nb);
      cells *= d;
      dim[a] = int(d);
    }
    lo = mn;
  }
  if (dense) {
    // Counting sort by cell, stable by index; the cells are the table entries.
    const std::size_t ncells = std::size_t(dim[0]) * std::size_t(dim[1]) * std::size_t(dim[2]);
    auto id = [&](std::size_t i) {
      const auto& c = cell_of[i];
      bucket_of[i] =
          uint32_t((std::size_t(c[2] - lo[2]) * std::size_t(dim[1]) + std::size_t(c[1] - lo[1])) *
                       std::size_t(dim[0]) +
                   std::size_t(c[0] - lo[0]));
    };
    if (par)
      parallel_for(*ctx, 0, n, id, 4096);
    else
      for (std::size_t i = 0; i < n; ++i) id(i);
    bucket_cells.clear();
    cell_key.clear();
    cell_start.assign(ncells + 1, 0);
    for (std::size_t i = 0; i < n; ++i) ++cell_start[bucket_of[i] + 1];
    for (std::size_t c = 0; c < ncells; ++c) cell_start[c + 1] += cell_start[c];
    fill.assign(cell_start.begin(), cell_start.end() - 1);
    sorted.resize(n);
    for (std::size_t i = 0; i < n; ++i) sorted[fill[bucket_of[i]]++] = uint32_t(i);
  } else {
    build_hashed(n, nb);
  }
  x.resize(n);
  y.resize(n);
  z.resize(n);
  auto copy = [&](std::size_t s) {
    const Vec3& p = points[sorted[s]];
    x[s] = p.x();
    y[s] = p.y();
    z[s] = p.z();
  };
  if (par)
    parallel_for(*ctx, 0, n, copy, 4096);
  else
    for (std::size_t s = 0; s < n; ++s) copy(s);
}

void CellTable::build_hashed(std::size_t n, std::size_t nb) {
  for (std::size_t i = 0; i < n; ++i) {
    const auto& c = cell_of[i];
    bucket_of[i] = bucket(c[0], c[1], c[2]);
  }
  // Counting sort by bucket, stable by index.
  start.assign(nb + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++start[bucket_of[i] + 1];
  for (std::size_t b = 0; b < nb; ++b) start[b + 1] += start[b];
  fill.assign(start.begin(), start.end() - 1);
  sorted.resize(n);
  cell_sorted.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const uint32_t slot = fill[bucket_of[i]]++;
    sorted[slot] = uint32_t(i);
    cell_sorted[slot] = cell_of[i];
  }
  // Split each bucket into its cells. A bucket shared by several cells (hash collision) is
  // regrouped cell by cell (cells in order of first appearance), keeping the index order within
  // each cell.
  bucket_cells.resize(nb + 1);
  cell_start.clear();
  cell_key.clear();
  std::vector<std::pair<std::array<int, 3>, uint32_t>> mixed;
  for (std::size_t b = 0; b < nb; ++b) {
    bucket_cells[b] = uint32_t(cell_key.size());
    const uint32_t s0 = start[b], s1 = start[b + 1];
    if (s0 == s1) continue;
    bool one = true;
    for (uint32_t s = s0 + 1; s < s1 && one; ++s) one = cell_sorted[s] == cell_sorted[s0];
    if (one) {
      cell_key.push_back(cell_sorted[s0]);
      cell_start.push_back(s0);
      continue;
    }
    mixed.clear();
    for (uint32_t s = s0; s < s1; ++s) mixed.emplace_back(cell_sorted[s], sorted[s]);
    uint32_t w = s0;
    for (std::size_t k = 0; k < mixed.size(); ++k) {
      if (mixed[k].second == UINT32_MAX) continue;  // already emitted with its cell
      const std::array<int, 3> key = mixed[k].first;
      cell_key.push_back(key);
      cell_start.push_back(w);
      for (std::size_t m = k; m < mixed.size(); ++m)
        if (mixed[m].second != UINT32_MAX && mixed[m].first == key) {
          cell_sorted[w] = key;
          sorted[w++] = mixed[m].second;
          mixed[m].second = UINT32_MAX;
        }
    }
  }
  bucket_cells[nb] = uint32_t(cell_key.size());
  cell_start.push_back(uint32_t(n));
}

}  // namespace detail

void ParticleGrid::build(const Context& ctx, const std::vector<Vec3>& points, double cell) {
  if (!(cell > 0) || !std::isfinite(cell)) fail("particle grid: cell size {} must be > 0", cell);
  m_cells.build(&ctx, points, 1.0 / cell);
}

void ParticleGrid::build(const std::vector<Vec3>& points, double cell) {
  if (!(cell > 0) || !std::isfinite(cell)) fail("particle grid: cell size {} must be > 0", cell);
  m_cells.build(nullptr, points, 1.0 / cell);
}

namespace {
/// Point-by-point lists through for_each_candidate: the reference order, used when the points
/// given to the list functions are not the ones the grid was built over.
template <class Search>
void build_lists(const Context& ctx, std::size_t n, std::vector<uint32_t>& offsets,
                 std::vector<uint32_t>& nbrs, Search&& search) {
  constexpr std::size_t kChunk = 512;
  const std::size_t nchunks = (n + kChunk - 1) / kChunk;
  std::vector<std::vector<uint32_t>> parts(nchunks);
  offsets.assign(n + 1, 0);
  parallel_for(
      ctx, 0, nchunks,
      [&](std::size_t c) {
        auto& out = parts[c];
        out.clear();
        const std::size_t e = std::min(n, (c + 1) * kChunk);
        for (std::size_t i = c * kChunk; i < e; ++i) {
          const std::size_t before = out.size();
          search(i, out);
          offsets[i + 1] = uint32_t(out.size() - before);
        }
      },
      1);
  for (std::size_t i = 0; i < n; ++i) offsets[i + 1] += offsets[i];
  nbrs.resize(offsets[n]);
  for (std::size_t c = 0; c < nchunks; ++c)
    std::copy(parts[c].begin(), parts[c].end(), nbrs.begin() + offsets[c * kChunk]);
}

bool same_points(const Context& ctx, const detail::CellTable& t, const std::vector<Vec3>& pts) {
  if (pts.size() != t.sorted.size()) return false;
  constexpr std::size_t kGrain = 8192;
  const std::size_t n = pts.size();
  return deterministic_reduce(
             ctx, n, kGrain, 1,
             [&](std::size_t s0, std::size_t s1) {
               int ok = 1;
               for (std::size_t s = s0; s < s1; ++s) {
                 const Vec3& p = pts[t.sorted[s]];
                 ok &= int(p.x() == t.x[s] && p.y() == t.y[s] && p.z() == t.z[s]);
               }
               return ok;
             },
             [](int a, int b) { return a & b; }) != 0;
}
}  // namespace

namespace {
/// A run of consecutive slots to scan.
struct Range {
  uint32_t s0, s1;
};

/// The distance test over the slots of `rg`, in order: writes the index of every slot t with
/// (x_t - p)^2 < r2 (squared norm summed as (dx^2 + dy^2) + dz^2, the arithmetic of
/// Vec3::squaredNorm) and index != self to o, returns the count. Plain loop, branch-free.
uint32_t filter_plain(const detail::CellTable& g, const Range* rg, std::size_t nr, double px,
                      double py, double pz, double r2, uint32_t self, uint32_t* __restrict o) {
  const double* __restrict cx = g.x.data();
  const double* __restrict cy = g.y.data();
  const double* __restrict cz = g.z.data();
  const uint32_t* __restrict ci = g.sorted.data();
  uint32_t cnt = 0;
  for (std::size_t k = 0; k < nr; ++k)
    for (uint32_t t = rg[k].s0; t < rg[k].s1; ++t) {
      const double ex = cx[t] - px, ey = cy[t] - py, ez = cz[t] - pz;
      const double d2 = ex * ex + ey * ey + ez * ez;
      o[cnt] = ci[t];
      cnt += uint32_t((d2 < r2) & (ci[t] != self));
    }
  return cnt;
}

#if defined(__x86_64__) && defined(__GNUC__)
#define FOLLICLE_GRID_AVX2 1
/// Byte shuffles that move the selected 32-bit lanes of a 4-lane mask to the front, in order.
struct CompactTable {
  alignas(16) uint8_t shuf[16][16];
  uint8_t count[16];
};
constexpr CompactTable make_compact_table() {
  CompactTable t{};
  for (int m = 0; m < 16; ++m) {
    int w = 0;
    for (int lane = 0; lane < 4; ++lane)
      if (m & (1 << lane)) {
        for (int b = 0; b < 4; ++b) t.shuf[m][4 * w + b] = uint8_t(4 * lane + b);
        ++w;
      }
    for (int b = 4 * w; b < 16; ++b) t.shuf[m][b] = 0x80;  // zero the rest
    t.count[m] = uint8_t(w);
  }
  return t;
}
constexpr CompactTable kCompact = make_compact_table();

/// filter_plain with AVX2: four candidates per step (the same IEEE operations per lane, no FMA,
/// so the same decisions), a lane mask compacted by a byte shuffle and stored unaligned (o must
/// have room for 4 entries past the count). The last 1-3 slots of a range are read by masked
/// loads.
FOLLICLE_AVX2_BEGIN
uint32_t filter_avx2(const detail::CellTable& g, const Range* rg, std::size_t nr, double px,
                     double py, double pz, double r2, uint32_t self, uint32_t* __restrict o) {
  const double* cx = g.x.data();
  const double* cy = g.y.data();
  const double* cz = g.z.data();
  const uint32_t* ci = g.sorted.data();
  const __m256d vx = _mm256_set1_pd(px), vy = _mm256_set1_pd(py), vz = _mm256_set1_pd(pz);
  const __m256d vr2 = _mm256_set1_pd(r2);
  const __m128i vself = _mm_set1_epi32(int(self));
  uint32_t cnt = 0;
  auto step = [&](__m256d X, __m256d Y, __m256d Z, __m128i id, int valid) {
    const __m256d ex = _mm256_sub_pd(X, vx), ey = _mm256_sub_pd(Y, vy), ez = _mm256_sub_pd(Z, vz);
    const __m256d d2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(ex, ex), _mm256_mul_pd(ey, ey)),
                                     _mm256_mul_pd(ez, ez));
    int m = _mm256_movemask_pd(_mm256_cmp_pd(d2, vr2, _CMP_LT_OQ));
    m &= ~_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(id, vself))) & valid;
    const __m128i sh = _mm_load_si128(reinterpret_cast<const __m128i*>(kCompact.shuf[m]));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(o + cnt), _mm_shuffle_epi8(id, sh));
    cnt += kCompact.count[m];
  };
  for (std::size_t k = 0; k < nr; ++k) {
    uint32_t t = rg[k].s0;
    const uint32_t s1 = rg[k].s1;
    for (; t + 4 <= s1; t += 4)
      step(_mm256_loadu_pd(cx + t), _mm256_loadu_pd(cy + t), _mm256_loadu_pd(cz + t),
           _mm_loadu_si128(reinterpret_cast<const __m128i*>(ci + t)), 15);
    if (t < s1) {
      const int rest = int(s1 - t);  // 1..3
      const __m128i l32 = _mm_cmpgt_epi32(_mm_set1_epi32(rest), _mm_setr_epi32(0, 1, 2, 3));
      const __m256i l64 = _mm256_cvtepi32_epi64(l32);
      step(_mm256_maskload_pd(cx + t, l64), _mm256_maskload_pd(cy + t, l64),
           _mm256_maskload_pd(cz + t, l64),
           _mm_maskload_epi32(reinterpret_cast<const int*>(ci + t), l32), (1 << rest) - 1);
    }
  }
  return cnt;
}
FOLLICLE_AVX2_END
#endif

bool have_avx2() {
#ifdef FOLLICLE_GRID_AVX2
  return cpu_has_avx2();
#else
  return false;
#endif
}
}  // namespace

void ParticleGrid::cell_lists(const Context& ctx, const detail::CellTable& q,
                              const std::vector<Vec3>& qpts, bool self, double r2,
                              std::vector<uint32_t>& offsets, std::vector<uint32_t>& nbrs) const {
  // Query points are processed cell by cell: the cells around a query cell are looked up once,
  // then each query of the cell scans their slots (in (dz, dy, dx) order, each cell's points by
  // index) through the distance test. A query's list is thus the for_each_candidate order
  // filtered by distance. In a dense table a row of three cells in x is one run of slots.
  const std::size_t n = qpts.size();
  const std::size_t ncells = q.cells();
  constexpr std::size_t kMaxParts = 128;
  const std::size_t per = std::max<std::size_t>(1, (ncells + kMaxParts - 1) / kMaxParts);
  const std::size_t nparts = (ncells + per - 1) / per;
  if (m_parts.size() < nparts) m_parts.resize(nparts);
  m_part_of.resize(n);
  m_pos_of.resize(n);
  offsets.assign(n + 1, 0);
  const detail::CellTable& g = m_cells;
  const bool simd = m_simd && have_avx2();
  // Skip threshold of the cell boxes in cell units: (r / cell)^2 plus a margin of 1e-6.
  const double r2_cells = r2 * g.inv * g.inv * (1 + 1e-6) + 1e-6;
  parallel_for(
      ctx, 0, nparts,
      [&](std::size_t part) {
        detail::ListPart& P = m_parts[part];
        P.mismatch = false;
        std::size_t used = 0;
        const std::size_t c1 = std::min(ncells, (part + 1) * per);
        for (std::size_t qc = part * per; qc < c1; ++qc) {
          if (q.cell_start[qc] == q.cell_start[qc + 1]) continue;
          const auto key = q.key(qc);
          // The runs around the query cell, in (dz, dy, dx) order: a dense grid gives one run
          // per row (cells dx = xa..xb of it, row id of dx = 0 in `base`), a hashed grid one
          // run per occupied cell (xa = xb = its dx).
          struct Seg {
            int64_t base;
            int xa, xb, dy, dz;
          };
          std::array<Seg, 27> segs;
          std::size_t nseg = 0, k = 0;
          if (g.dense) {
            const int xa = std::max(-1, g.lo[0] - key[0]);
            const int xb = std::min(1, g.lo[0] + g.dim[0] - 1 - key[0]);
            for (int dz = -1; dz <= 1; ++dz)
              for (int dy = -1; dy <= 1; ++dy) {
                const int64_t iy = int64_t(key[1]) + dy - g.lo[1];
                const int64_t iz = int64_t(key[2]) + dz - g.lo[2];
                if (xa > xb || iy < 0 || iz < 0 || iy >= g.dim[1] || iz >= g.dim[2]) continue;
                const int64_t base = (iz * g.dim[1] + iy) * g.dim[0] + (int64_t(key[0]) - g.lo[0]);
                const uint32_t s0 = g.cell_start[std::size_t(base + xa)];
                const uint32_t s1 = g.cell_start[std::size_t(base + xb + 1)];
                if (s0 == s1) continue;
                segs[nseg++] = {base, xa, xb, dy + 1, dz + 1};
                k += s1 - s0;
              }
          } else {
            for (int dz = -1; dz <= 1; ++dz)
              for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                  const int64_t c = g.find(key[0] + dx, key[1] + dy, key[2] + dz);
                  if (c < 0) continue;
                  segs[nseg++] = {c - dx, dx, dx, dy + 1, dz + 1};
                  k += g.cell_start[std::size_t(c) + 1] - g.cell_start[std::size_t(c)];
                }
          }
          for (uint32_t s = q.cell_start[qc]; s < q.cell_start[qc + 1]; ++s) {
            const uint32_t i = q.sorted[s];
            const double px = q.x[s], py = q.y[s], pz = q.z[s];
            const Vec3& p = qpts[i];
            P.mismatch |= !(p.x() == px && p.y() == py && p.z() == pz);
            if (P.out.size() < used + k + 4)
              P.out.resize(std::max(2 * P.out.size(), used + k + 4096));
            // Squared distance (in cells) from the query to the box of each neighbour cell, per
            // axis: a cell whose box is farther than the radius (with a margin far above the
            // rounding of the cell coordinates) holds no neighbour and is skipped (a row keeps
            // its cells within reach: the middle one whenever any is, as bx = 0 there).
            const double fx = px * g.inv - key[0], fy = py * g.inv - key[1],
                         fz = pz * g.inv - key[2];
            const double bx[3] = {fx * fx, 0.0, (1 - fx) * (1 - fx)};
            const double by[3] = {fy * fy, 0.0, (1 - fy) * (1 - fy)};
            const double bz[3] = {fz * fz, 0.0, (1 - fz) * (1 - fz)};
            std::array<Range, 27> rg;
            std::size_t nr = 0;
            for (std::size_t sg = 0; sg < nseg; ++sg) {
              const Seg& S = segs[sg];
              const double byz = by[S.dy] + bz[S.dz];
              if (byz > r2_cells) continue;  // then the row's middle cell (bx = 0) is in reach
              const int xa = std::max(S.xa, int(bx[0] + byz > r2_cells) - 1);
              const int xb = std::min(S.xb, 1 - int(bx[2] + byz > r2_cells));
              if (xa > xb) continue;
              rg[nr++] = {g.cell_start[std::size_t(S.base + xa)],
                          g.cell_start[std::size_t(S.base + xb + 1)]};
            }
            const uint32_t me = self ? i : UINT32_MAX;
            uint32_t* o = P.out.data() + used;
#ifdef FOLLICLE_GRID_AVX2
            const uint32_t cnt = simd ? filter_avx2(g, rg.data(), nr, px, py, pz, r2, me, o)
                                      : filter_plain(g, rg.data(), nr, px, py, pz, r2, me, o);
#else
            const uint32_t cnt = filter_plain(g, rg.data(), nr, px, py, pz, r2, me, o);
#endif
            m_part_of[i] = uint32_t(part);
            m_pos_of[i] = uint32_t(used);
            offsets[i + 1] = cnt;
            used += cnt;
          }
        }
      },
      1);
  for (std::size_t i = 0; i < n; ++i) offsets[i + 1] += offsets[i];
  nbrs.resize(offsets[n]);
  parallel_for(
      ctx, 0, n,
      [&](std::size_t i) {
        const uint32_t* __restrict src = m_parts[m_part_of[i]].out.data() + m_pos_of[i];
        uint32_t* __restrict dst = nbrs.data() + offsets[i];
        const uint32_t cnt = offsets[i + 1] - offsets[i];
        for (uint32_t t = 0; t < cnt; ++t) dst[t] = src[t];
      },
      2048);
}

void ParticleGrid::neighbour_lists(const Context& ctx, const std::vector<Vec3>& points,
                                   double radius, std::vector<uint32_t>& offsets,
                                   std::vector<uint32_t>& nbrs) const {
  const double r2 = radius * radius;
  if (!m_cells.empty() && points.size() == m_cells.sorted.size()) {
    cell_lists(ctx, m_cells, points, true, r2, offsets, nbrs);
    bool mismatch = false;
    for (const auto& P : m_parts) mismatch |= P.mismatch;
    if (!mismatch) return;
  }
  build_lists(ctx, points.size(), offsets, nbrs, [&](std::size_t i, std::vector<uint32_t>& out) {
    const Vec3& p = points[i];
    for_each_candidate(p, [&](uint32_t j) {
      if (j != i && (points[j] - p).squaredNorm() < r2) out.push_back(j);
    });
  });
}

void ParticleGrid::cross_lists(const Context& ctx, const std::vector<Vec3>& queries,
                               const std::vector<Vec3>& grid_points, double radius,
                               std::vector<uint32_t>& offsets, std::vector<uint32_t>& nbrs) const {
  const double r2 = radius * radius;
  if (!m_cells.empty() && same_points(ctx, m_cells, grid_points)) {
    m_query_cells.build(&ctx, queries, m_cells.inv);
    cell_lists(ctx, m_query_cells, queries, false, r2, offsets, nbrs);
    return;
  }
  build_lists(ctx, queries.size(), offsets, nbrs, [&](std::size_t i, std::vector<uint32_t>& out) {
    const Vec3& p = queries[i];
    for_each_candidate(p, [&](uint32_t j) {
      if ((grid_points[j] - p).squaredNorm() < r2) out.push_back(j);
    });
  });
}

namespace {
/// The sort-then-cursor algorithm: each list sorted, then visiting i in increasing order consumes
/// the lower-index part of each list j in order, so one cursor per particle finds every mirror
/// entry in O(entries). This defines the result (also of the rejected cases).
bool sort_then_match(const Context& ctx, const std::vector<uint32_t>& offsets,
                     std::vector<uint32_t>& nbrs, std::vector<uint32_t>& mirror) {
  const std::size_t n = offsets.empty() ? 0 : offsets.size() - 1;
  parallel_for(
      ctx, 0, n,
      [&](std::size_t i) { std::sort(nbrs.begin() + offsets[i], nbrs.begin() + offsets[i + 1]); },
      64);
  mirror.assign(nbrs.size(), 0);
  std::vector<uint32_t> cursor(offsets.begin(), offsets.end() - (n ? 1 : 0));
  for (std::size_t i = 0; i < n; ++i)
    for (uint32_t e = offsets[i]; e < offsets[i + 1]; ++e) {
      const uint32_t j = nbrs[e];
      if (j == i) {  // a self entry: no pair, and its mirror would alias pair 0
        mirror.clear();
        return false;
      }
      if (j < i) continue;
      const uint32_t c = j < n ? cursor[j]++ : 0;
      if (j >= n || c >= offsets[j + 1] || nbrs[c] != i) {
        mirror.clear();
        return false;
      }
      mirror[e] = c;
      mirror[c] = e;
    }
  // Every lower-index entry must have been matched.
  for (std::size_t j = 0; j < n; ++j)
    if (cursor[j] < offsets[j + 1] && nbrs[cursor[j]] < j) {
      mirror.clear();
      return false;
    }
  return true;
}

/// Transposes the CSR lists `in` into `out` (same offsets): row j of out gets every i with j in
/// row i of in, by increasing i. When `pos` is given, pos[e] receives the slot of out that entry
/// e of in went to; with `expect`, every slot must already hold the i that goes there. Returns
/// false when a row of out would overflow, an index is >= n, a row holds its own index (a self
/// entry: no pair, though it is its own transpose) or `expect` differs (then the lists are not
/// symmetric pair lists). Serial: one pass over the entries; two threads each scanning all entries
/// for half of the rows measured slower (memory bound).
bool transpose(const std::vector<uint32_t>& offsets, const uint32_t* in, uint32_t* out,
               uint32_t* pos, const uint32_t* expect) {
  const std::size_t n = offsets.size() - 1;
  std::vector<uint32_t> cursor(offsets.begin(), offsets.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    for (uint32_t e = offsets[i]; e < offsets[i + 1]; ++e) {
      const uint32_t j = in[e];
      if (j >= n || j == i) return false;  // index beyond the particles, or a self entry
      const uint32_t c = cursor[j]++;
      if (c >= offsets[j + 1] || (expect && expect[c] != i)) return false;
      if (out) out[c] = uint32_t(i);
      if (pos) pos[e] = c;
    }
  return true;
}
}  // namespace

bool sort_and_mirror(const Context& ctx, const std::vector<uint32_t>& offsets,
                     std::vector<uint32_t>& nbrs, std::vector<uint32_t>& mirror) {
  // Fast path: for symmetric lists the transpose T of the lists is the sorted lists (row j of T
  // holds the i with j in list i, by increasing i), and transposing T once more pairs the k-th
  // entry i of row j with the k-th entry j of row i, which is the pairing of the cursor
  // algorithm. T is accepted only when it equals its own transpose; then the lists equal T as
  // multisets, so the result is exactly sort_then_match's. Otherwise (asymmetric lists, self
  // entries) the lists are restored and sort_then_match gives the rejection.
  const std::size_t n = offsets.empty() ? 0 : offsets.size() - 1;
  if (n == 0 || offsets[n] != nbrs.size() || offsets[0] != 0)
    return sort_then_match(ctx, offsets, nbrs, mirror);
  mirror.resize(nbrs.size());
  if (!transpose(offsets, nbrs.data(), mirror.data(), nullptr, nullptr))
    return sort_then_match(ctx, offsets, nbrs, mirror);  // nbrs untouched
  // mirror holds T; nbrs' storage receives T's mirror entries.
  if (!transpose(offsets, mirror.data(), nullptr, nbrs.data(), mirror.data())) {
    // Not symmetric: rebuild the lists as the transpose of T, then take the reference path.
    transpose(offsets, mirror.data(), nbrs.data(), nullptr, nullptr);
    return sort_then_match(ctx, offsets, nbrs, mirror);
  }
  nbrs.swap(mirror);
  return true;
}

}  // namespace follicle::hair
