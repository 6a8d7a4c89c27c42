#include "follicle/geom/grid.hpp"

#include <algorithm>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"

namespace follicle::geom {

void NeighbourGrid::build(const Context& ctx, std::span<const Vec3f> points, float cell_size) {
  build_impl(ctx, points, double(cell_size));
}
void NeighbourGrid::build(const Context& ctx, std::span<const Vec3> points, double cell_size) {
  build_impl(ctx, points, cell_size);
}

template <class P>
void NeighbourGrid::build_impl(const Context& ctx, std::span<const P> points, double cell_size) {
  if (!(cell_size > 0) || !std::isfinite(cell_size))
    fail("NeighbourGrid: cell size {} must be a positive finite number", cell_size);
  if (points.size() >= std::size_t(UINT32_MAX))
    fail("NeighbourGrid: {} points exceed the 32-bit index range", points.size());
  const std::size_t n = points.size();
  // Bounds (deterministic: min/max are order-independent anyway).
  struct Box {
    Vec3f lo, hi;
    bool bad;
  };
  const Box init{Vec3f::Constant(std::numeric_limits<float>::max()),
                 Vec3f::Constant(-std::numeric_limits<float>::max()), false};
  const Box box = deterministic_reduce(
      ctx, n, 1 << 14, init,
      [&](std::size_t a, std::size_t b) {
        Box bx = init;
        for (std::size_t i = a; i < b; ++i) {
          const Vec3f q = points[i].template cast<float>();
          if (!q.allFinite()) bx.bad = true;
          bx.lo = bx.lo.cwiseMin(q);
          bx.hi = bx.hi.cwiseMax(q);
        }
        return bx;
      },
      [](const Box& x, const Box& y) {
        return Box{x.lo.cwiseMin(y.lo), x.hi.cwiseMax(y.hi), x.bad || y.bad};
      });
  if (box.bad) {
    for (std::size_t i = 0; i < n; ++i)
      if (!points[i].allFinite()) fail("NeighbourGrid: point {} is not finite", i);
  }
  const Vec3f lo = n ? box.lo : Vec3f::Zero();
  const Vec3f ext = n ? Vec3f(box.hi - box.lo) : Vec3f::Zero();
  double cell = cell_size;
  const double max_cells = std::max<double>(4.0 * double(n), 1 << 12);
  for (;;) {
    double total = 1;
    for (int k = 0; k < 3; ++k) total *= std::floor(double(ext[k]) / cell) + 1;
    if (total <= max_cells) break;
    cell *= std::max(1.01, std::cbrt(total / max_cells));
  }
  m_cell = float(cell);
  m_inv_cell = float(1.0 / cell);
  m_origin = lo;
  for (int k = 0; k < 3; ++k) m_dim[k] = int(std::floor(double(ext[k]) / cell)) + 1;
  const std::size_t ncells = std::size_t(m_dim[0]) * std::size_t(m_dim[1]) * std::size_t(m_dim[2]);
  // Cell id per point (parallel), then a stable counting sort (serial: memory bound, ~ms).
  std::vector<uint32_t> cell_of(n);
  parallel_for(
      ctx, 0, n,
      [&](std::size_t i) {
        const Vec3f q = points[i].template cast<float>();
        const int x = clampi((q.x() - lo.x()) * m_inv_cell, m_dim[0] - 1);
        const int y = clampi((q.y() - lo.y()) * m_inv_cell, m_dim[1] - 1);
        const int z = clampi((q.z() - lo.z()) * m_inv_cell, m_dim[2] - 1);
        cell_of[i] = uint32_t((std::size_t(z) * std::size_t(m_dim[1]) + std::size_t(y)) *
                                  std::size_t(m_dim[0]) +
                              std::size_t(x));
      },
      4096);
  m_cell_start.assign(ncells + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++m_cell_start[cell_of[i] + 1];
  for (std::size_t c = 0; c < ncells; ++c) m_cell_start[c + 1] += m_cell_start[c];
  m_index.resize(n);
  {
    std::vector<uint32_t> fill(m_cell_start.begin(), m_cell_start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) m_index[fill[cell_of[i]]++] = uint32_t(i);
  }
  m_x.resize(n);
  m_y.resize(n);
  m_z.resize(n);
  parallel_for(
      ctx, 0, n,
      [&](std::size_t k) {
        const Vec3f q = points[m_index[k]].template cast<float>();
        m_x[k] = q.x();
        m_y[k] = q.y();
        m_z[k] = q.z();
      },
      4096);
}

void NeighbourGrid::query(const Vec3f& p, float r, std::vector<uint32_t>& out) const {
  out.clear();
  for_each_within(p, r, [&](uint32_t i, float) { out.push_back(i); });
  std::sort(out.begin(), out.end());
}

NeighbourList NeighbourGrid::neighbour_lists(const Context& ctx, float r) const {
  const std::size_t n = m_index.size();
  NeighbourList out;
  out.offsets.assign(n + 1, 0);
  if (n == 0) return out;
  // Pass over storage order (cache-friendly), one buffer per fixed chunk.
  const std::size_t chunk = 8192;
  const std::size_t nchunks = (n + chunk - 1) / chunk;
  std::vector<std::vector<uint32_t>> bufs(nchunks);
  std::vector<uint32_t> counts(n, 0);  // by storage position
  parallel_chunks(ctx, n, chunk, [&](std::size_t k0, std::size_t k1) {
    auto& buf = bufs[k0 / chunk];
    buf.reserve((k1 - k0) * 16);
    for (std::size_t k = k0; k < k1; ++k) {
      const std::size_t start = buf.size();
      const uint32_t self = m_index[k];
      for_each_within(Vec3f(m_x[k], m_y[k], m_z[k]), r, [&](uint32_t j, float) {
        if (j != self) buf.push_back(j);
      });
      std::sort(buf.begin() + std::ptrdiff_t(start), buf.end());
      counts[k] = uint32_t(buf.size() - start);
    }
  });
  for (std::size_t k = 0; k < n; ++k) out.offsets[m_index[k] + 1] = counts[k];
  for (std::size_t i = 0; i < n; ++i) out.offsets[i + 1] += out.offsets[i];
  out.index.resize(out.offsets[n]);
  parallel_for(
      ctx, 0, nchunks,
      [&](std::size_t c) {
        std::size_t pos = 0;
        for (std::size_t k = c * chunk; k < std::min(n, (c + 1) * chunk); ++k) {
          std::copy_n(bufs[c].begin() + std::ptrdiff_t(pos), counts[k],
                      out.index.begin() + std::ptrdiff_t(out.offsets[m_index[k]]));
          pos += counts[k];
        }
      },
      1);
  return out;
}

std::vector<std::pair<uint32_t, uint32_t>> NeighbourGrid::all_pairs(const Context& ctx,
                                                                    float r) const {
  const NeighbourList nl = neighbour_lists(ctx, r);
  std::vector<std::pair<uint32_t, uint32_t>> out;
  out.reserve(nl.index.size() / 2);
  for (std::size_t i = 0; i < nl.size(); ++i)
    for (uint32_t j : nl.of(i))
      if (j > i) out.emplace_back(uint32_t(i), j);
  return out;
}

}  // namespace follicle::geom
