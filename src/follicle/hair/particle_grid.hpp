#pragma once
// Uniform-grid neighbour search for particles (Bando 2003 §3.3: "a grid of voxels of size 2h").
// Hand-written rather than a general geom grid because the solvers need (a) neighbour lists in a
// fixed order that does not depend on the thread count and (b) a rebuild every time step without
// allocation. Cells are hashed into a table (2 x points, power of two) and points are counting-
// sorted by bucket, stably by index: the neighbour order is a pure function of the positions.
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/types.hpp"

namespace follicle::hair {

class ParticleGrid {
 public:
  /// Buckets `points` into cells of edge `cell` [m].
  void build(const std::vector<Vec3>& points, double cell);
  /// The same grid (identical order), with the cell and bucket computation in parallel.
  void build(const Context& ctx, const std::vector<Vec3>& points, double cell);

  /// Calls f(j) for every point j in the 27 cells around p (a superset of the points within
  /// `cell` of p; hash collisions may add far points, callers test the distance). Order is fixed.
  template <class F>
  void for_each_candidate(const Vec3& p, F&& f) const {
    if (m_mask == 0 && m_start.empty()) return;
    const int cx = int(std::floor(p.x() * m_inv)), cy = int(std::floor(p.y() * m_inv)),
              cz = int(std::floor(p.z() * m_inv));
    // Points are accepted only in their own cell, so a bucket shared by two of the 27 cells
    // (hash collision) is not visited twice and far points sharing a bucket are skipped early.
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = cx + dx, y = cy + dy, z = cz + dz;
          const uint32_t b = bucket(x, y, z);
          for (uint32_t s = m_start[b]; s < m_start[b + 1]; ++s) {
            const auto& c = m_cell_sorted[s];
            if (c[0] == x && c[1] == y && c[2] == z) f(m_sorted[s]);
          }
        }
  }

  /// CSR neighbour lists: for each i, every j != i with |x_j - x_i| < radius (radius <= cell),
  /// in increasing grid order. Parallel, deterministic.
  void neighbour_lists(const Context& ctx, const std::vector<Vec3>& points, double radius,
                       std::vector<uint32_t>& offsets, std::vector<uint32_t>& nbrs) const;

  /// Neighbours in another point set (this grid built over `grid_points`) for each query point.
  void cross_lists(const Context& ctx, const std::vector<Vec3>& queries,
                   const std::vector<Vec3>& grid_points, double radius,
                   std::vector<uint32_t>& offsets, std::vector<uint32_t>& nbrs) const;

 private:
  uint32_t bucket(int x, int y, int z) const {
    uint64_t h = uint64_t(uint32_t(x)) * 73856093ull ^ uint64_t(uint32_t(y)) * 19349663ull ^
                 uint64_t(uint32_t(z)) * 83492791ull;
    return uint32_t(h & m_mask);
  }
  double m_inv = 1.0;
  uint32_t m_mask = 0;
  std::vector<uint32_t> m_start;   // bucket -> first slot, size buckets + 1
  std::vector<uint32_t> m_sorted;  // point indices by bucket
  std::vector<uint32_t> m_bucket_of;
  std::vector<std::array<int, 3>> m_cell_sorted;  // integer cell of each sorted point
  std::vector<std::array<int, 3>> m_cell_of;      // scratch of the parallel build
  std::vector<uint32_t> m_fill;                   // scratch of the parallel build
};

/// Sorts each CSR list by neighbour index and fills mirror[e] with the entry (j -> i) of every
/// entry e = (i -> j), so a per-pair value computed once at the lower-index end can be gathered
/// by the other end in a fixed order (deterministic, equal and opposite). The lists must be
/// symmetric and free of self entries; returns false (mirror cleared) when they are not.
bool sort_and_mirror(const Context& ctx, const std::vector<uint32_t>& offsets,
                     std::vector<uint32_t>& nbrs, std::vector<uint32_t>& mirror);

}  // namespace follicle::hair
