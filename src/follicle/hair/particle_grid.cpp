#include "follicle/hair/particle_grid.hpp"

#include <algorithm>

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
  auto cell_and_bucket = [&](std::size_t i) {
    const Vec3& p = points[i];
    const std::array<int, 3> c{int(std::floor(p.x() * inv)), int(std::floor(p.y() * inv)),
                               int(std::floor(p.z() * inv))};
    cell_of[i] = c;
    bucket_of[i] = bucket(c[0], c[1], c[2]);
  };
  if (par)
    parallel_for(*ctx, 0, n, cell_and_bucket, 2048);
  else
    for (std::size_t i = 0; i < n; ++i) cell_and_bucket(i);
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

void ParticleGrid::cell_lists(const Context& ctx, const detail::CellTable& q,
                              const std::vector<Vec3>& qpts, bool self, double r2,
                              std::vector<uint32_t>& offsets, std::vector<uint32_t>& nbrs) const {
  // Query points are processed cell by cell: the 27 cells around a query cell are looked up once
  // and their points gathered into a contiguous scratch, which every query of the cell scans in
  // order. A query's list is thus the for_each_candidate order filtered by distance.
  const std::size_t n = qpts.size();
  const std::size_t ncells = q.cell_key.size();
  constexpr std::size_t kMaxParts = 128;
  const std::size_t per = std::max<std::size_t>(1, (ncells + kMaxParts - 1) / kMaxParts);
  const std::size_t nparts = (ncells + per - 1) / per;
  if (m_parts.size() < nparts) m_parts.resize(nparts);
  m_part_of.resize(n);
  m_pos_of.resize(n);
  offsets.assign(n + 1, 0);
  const detail::CellTable& g = m_cells;
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
          // The occupied cells among the 27 around the query cell, in (dz, dy, dx) order.
          const auto& key = q.cell_key[qc];
          struct Seg {
            uint32_t s0, s1;
            int dx, dy, dz;
          };
          std::array<Seg, 27> segs;
          std::size_t nseg = 0, k = 0;
          for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
              for (int dx = -1; dx <= 1; ++dx) {
                const int64_t c = g.find(key[0] + dx, key[1] + dy, key[2] + dz);
                if (c < 0) continue;
                segs[nseg++] = {g.cell_start[c], g.cell_start[c + 1], dx + 1, dy + 1, dz + 1};
                k += g.cell_start[c + 1] - g.cell_start[c];
              }
          const double* __restrict cx = g.x.data();
          const double* __restrict cy = g.y.data();
          const double* __restrict cz = g.z.data();
          const uint32_t* __restrict ci = g.sorted.data();
          for (uint32_t s = q.cell_start[qc]; s < q.cell_start[qc + 1]; ++s) {
            const uint32_t i = q.sorted[s];
            const double px = q.x[s], py = q.y[s], pz = q.z[s];
            const Vec3& p = qpts[i];
            P.mismatch |= !(p.x() == px && p.y() == py && p.z() == pz);
            if (P.out.size() < used + k) P.out.resize(std::max(2 * P.out.size(), used + k + 4096));
            uint32_t* __restrict o = P.out.data() + used;
            uint32_t cnt = 0;
            // Squared distance (in cells) from the query to the box of each neighbour cell, per
            // axis: a cell whose box is farther than the radius (with a margin far above the
            // rounding of the cell coordinates) holds no neighbour and is skipped.
            const double fx = px * g.inv - key[0], fy = py * g.inv - key[1],
                         fz = pz * g.inv - key[2];
            const double bx[3] = {fx * fx, 0.0, (1 - fx) * (1 - fx)};
            const double by[3] = {fy * fy, 0.0, (1 - fy) * (1 - fy)};
            const double bz[3] = {fz * fz, 0.0, (1 - fz) * (1 - fz)};
            for (std::size_t sg = 0; sg < nseg; ++sg) {
              const Seg& S = segs[sg];
              if (bx[S.dx] + by[S.dy] + bz[S.dz] > r2_cells) continue;
              // Same arithmetic as (x_j - p).squaredNorm() < r2: (dx^2 + dy^2) + dz^2.
              if (self)
                for (uint32_t t = S.s0; t < S.s1; ++t) {
                  const double ex = cx[t] - px, ey = cy[t] - py, ez = cz[t] - pz;
                  const double d2 = ex * ex + ey * ey + ez * ez;
                  o[cnt] = ci[t];
                  cnt += uint32_t((d2 < r2) & (ci[t] != i));
                }
              else
                for (uint32_t t = S.s0; t < S.s1; ++t) {
                  const double ex = cx[t] - px, ey = cy[t] - py, ez = cz[t] - pz;
                  const double d2 = ex * ex + ey * ey + ez * ez;
                  o[cnt] = ci[t];
                  cnt += uint32_t(d2 < r2);
                }
            }
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
