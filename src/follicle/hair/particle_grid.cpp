#include "follicle/hair/particle_grid.hpp"

#include <algorithm>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"

namespace follicle::hair {

void ParticleGrid::build(const Context& ctx, const std::vector<Vec3>& points, double cell) {
  if (ctx.threads() == 1 || points.size() < 4096) {
    build(points, cell);
    return;
  }
  if (!(cell > 0) || !std::isfinite(cell)) fail("particle grid: cell size {} must be > 0", cell);
  m_inv = 1.0 / cell;
  std::size_t nb = 64;
  while (nb < 2 * points.size()) nb *= 2;
  m_mask = uint32_t(nb - 1);
  const std::size_t n = points.size();
  m_bucket_of.resize(n);
  m_cell_of.resize(n);
  parallel_for(
      ctx, 0, n,
      [&](std::size_t i) {
        const Vec3& p = points[i];
        const std::array<int, 3> c{int(std::floor(p.x() * m_inv)), int(std::floor(p.y() * m_inv)),
                                   int(std::floor(p.z() * m_inv))};
        m_cell_of[i] = c;
        m_bucket_of[i] = bucket(c[0], c[1], c[2]);
      },
      2048);
  // Counting sort by bucket, stable by index (the serial build's order).
  m_start.assign(nb + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++m_start[m_bucket_of[i] + 1];
  for (std::size_t b = 0; b < nb; ++b) m_start[b + 1] += m_start[b];
  m_sorted.resize(n);
  m_cell_sorted.resize(n);
  m_fill.assign(m_start.begin(), m_start.end() - 1);
  for (std::size_t i = 0; i < n; ++i) {
    const uint32_t slot = m_fill[m_bucket_of[i]]++;
    m_sorted[slot] = uint32_t(i);
    m_cell_sorted[slot] = m_cell_of[i];
  }
}

void ParticleGrid::build(const std::vector<Vec3>& points, double cell) {
  if (!(cell > 0) || !std::isfinite(cell)) fail("particle grid: cell size {} must be > 0", cell);
  m_inv = 1.0 / cell;
  std::size_t nb = 64;
  while (nb < 2 * points.size()) nb *= 2;
  m_mask = uint32_t(nb - 1);
  m_start.assign(nb + 1, 0);
  m_bucket_of.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    const uint32_t b = bucket(int(std::floor(p.x() * m_inv)), int(std::floor(p.y() * m_inv)),
                              int(std::floor(p.z() * m_inv)));
    m_bucket_of[i] = b;
    ++m_start[b + 1];
  }
  for (std::size_t b = 0; b < nb; ++b) m_start[b + 1] += m_start[b];
  m_sorted.resize(points.size());
  std::vector<uint32_t> fill(m_start.begin(), m_start.end() - 1);
  m_cell_sorted.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const uint32_t slot = fill[m_bucket_of[i]]++;
    m_sorted[slot] = uint32_t(i);
    const Vec3& p = points[i];
    m_cell_sorted[slot] = {int(std::floor(p.x() * m_inv)), int(std::floor(p.y() * m_inv)),
                           int(std::floor(p.z() * m_inv))};
  }
}

namespace {
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
}  // namespace

void ParticleGrid::neighbour_lists(const Context& ctx, const std::vector<Vec3>& points,
                                   double radius, std::vector<uint32_t>& offsets,
                                   std::vector<uint32_t>& nbrs) const {
  const double r2 = radius * radius;
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
  build_lists(ctx, queries.size(), offsets, nbrs, [&](std::size_t i, std::vector<uint32_t>& out) {
    const Vec3& p = queries[i];
    for_each_candidate(p, [&](uint32_t j) {
      if ((grid_points[j] - p).squaredNorm() < r2) out.push_back(j);
    });
  });
}

bool sort_and_mirror(const Context& ctx, const std::vector<uint32_t>& offsets,
                     std::vector<uint32_t>& nbrs, std::vector<uint32_t>& mirror) {
  const std::size_t n = offsets.empty() ? 0 : offsets.size() - 1;
  parallel_for(
      ctx, 0, n,
      [&](std::size_t i) { std::sort(nbrs.begin() + offsets[i], nbrs.begin() + offsets[i + 1]); },
      64);
  // Visiting i in increasing order consumes the lower-index part of each list j in order, so one
  // cursor per particle finds every mirror entry in O(entries).
  mirror.assign(nbrs.size(), 0);
  std::vector<uint32_t> cursor(offsets.begin(), offsets.end() - (n ? 1 : 0));
  for (std::size_t i = 0; i < n; ++i)
    for (uint32_t e = offsets[i]; e < offsets[i + 1]; ++e) {
      const uint32_t j = nbrs[e];
      if (j <= i) continue;
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

}  // namespace follicle::hair
