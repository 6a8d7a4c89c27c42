#pragma once
// Uniform-grid fixed-radius neighbour search over points (particles, SPH, root spacing).
// Build: points are counting-sorted by cell (stable, so the layout is deterministic) into a
// structure-of-arrays copy; cells along x are contiguous, so a query scans one contiguous run
// of points per (y, z) row of cells. Queries work for any radius (cells in range are scanned).
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/types.hpp"

namespace follicle::geom {

/// Neighbour lists in CSR form: neighbours of point i are index[offsets[i] .. offsets[i+1]),
/// ascending, never containing i itself.
struct NeighbourList {
  std::vector<uint32_t> offsets{0};
  std::vector<uint32_t> index;
  std::span<const uint32_t> of(std::size_t i) const {
    return {index.data() + offsets[i], offsets[i + 1] - offsets[i]};
  }
  std::size_t size() const { return offsets.size() - 1; }
};

class NeighbourGrid {
 public:
  NeighbourGrid() = default;
  /// Builds over `points` with cells of edge `cell_size` (use the query radius). The cell size
  /// is enlarged automatically if the grid would need more than ~4 cells per point. Throws
  /// follicle::Error on non-finite points or a non-positive cell size.
  void build(const Context& ctx, std::span<const Vec3f> points, float cell_size);
  void build(const Context& ctx, std::span<const Vec3> points, double cell_size);

  std::size_t size() const { return m_index.size(); }
  float cell_size() const { return m_cell; }

  /// Calls f(original_index, squared_distance) for every point with |x - p| <= r, in the grid's
  /// (deterministic) storage order.
  template <class F>
  void for_each_within(const Vec3f& p, float r, F&& f) const;
  /// Indices of all points with |x - p| <= r, ascending.
  void query(const Vec3f& p, float r, std::vector<uint32_t>& out) const;
  std::vector<uint32_t> query(const Vec3f& p, float r) const {
    std::vector<uint32_t> out;
    query(p, r, out);
    return out;
  }
  /// Neighbours within r of every point (self excluded), parallel, deterministic.
  NeighbourList neighbour_lists(const Context& ctx, float r) const;
  /// All pairs (i, j), i < j, with |xi - xj| <= r, sorted by (i, j).
  std::vector<std::pair<uint32_t, uint32_t>> all_pairs(const Context& ctx, float r) const;

  /// Storage order: sorted_index()[k] is the original index of the k-th stored point.
  std::span<const uint32_t> sorted_index() const { return m_index; }

 private:
  template <class P>
  void build_impl(const Context& ctx, std::span<const P> points, double cell_size);
  int clampi(float v, int hi) const {
    const float c = std::floor(v);
    return c < 0 ? 0 : (c > float(hi) ? hi : int(c));
  }

  float m_cell = 0, m_inv_cell = 0;
  Vec3f m_origin = Vec3f::Zero();
  int m_dim[3] = {0, 0, 0};
  std::vector<uint32_t> m_cell_start;  // size ncells+1
  std::vector<float> m_x, m_y, m_z;    // sorted SoA copies
  std::vector<uint32_t> m_index;       // sorted -> original
};

template <class F>
void NeighbourGrid::for_each_within(const Vec3f& p, float r, F&& f) const {
  if (m_index.empty() || !(r >= 0)) return;
  const float pad = r + 1e-4f * m_cell;  // cell range only: never miss a point on a cell border
  const int x0 = clampi((p.x() - pad - m_origin.x()) * m_inv_cell, m_dim[0] - 1);
  const int x1 = clampi((p.x() + pad - m_origin.x()) * m_inv_cell, m_dim[0] - 1);
  const int y0 = clampi((p.y() - pad - m_origin.y()) * m_inv_cell, m_dim[1] - 1);
  const int y1 = clampi((p.y() + pad - m_origin.y()) * m_inv_cell, m_dim[1] - 1);
  const int z0 = clampi((p.z() - pad - m_origin.z()) * m_inv_cell, m_dim[2] - 1);
  const int z1 = clampi((p.z() + pad - m_origin.z()) * m_inv_cell, m_dim[2] - 1);
  const float r2 = r * r;
  for (int z = z0; z <= z1; ++z)
    for (int y = y0; y <= y1; ++y) {
      const std::size_t row =
          (std::size_t(z) * std::size_t(m_dim[1]) + std::size_t(y)) * std::size_t(m_dim[0]);
      const uint32_t b = m_cell_start[row + std::size_t(x0)];
      const uint32_t e = m_cell_start[row + std::size_t(x1) + 1];
      for (uint32_t k = b; k < e; ++k) {
        const float dx = m_x[k] - p.x(), dy = m_y[k] - p.y(), dz = m_z[k] - p.z();
        const float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 <= r2) f(m_index[k], d2);
      }
    }
}

}  // namespace follicle::geom
