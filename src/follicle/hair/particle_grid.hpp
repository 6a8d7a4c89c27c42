#pragma once
// Uniform-grid neighbour search for particles (Bando 2003 §3.3: "a grid of voxels of size 2h").
// Hand-written rather than a general geom grid because the solvers need (a) neighbour lists in a
// fixed order that does not depend on the thread count and (b) a rebuild every time step without
// allocation. Points are counting-sorted by cell, stably by index, so every occupied cell is one
// contiguous run of slots holding its points in increasing index order. The cells are a dense
// table over the box of occupied cells when that box is small (at most 2 x points cells, rounded
// up to a power of two), else a hash table. The candidate order (the 27 cells around a point in
// z, y, x order, each cell's points by index) is a pure function of the positions and the cell
// size, independent of the layout, the hash and the thread count.
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/types.hpp"

namespace follicle::hair {

namespace detail {
/// Points grouped by integer cell: cell -> contiguous slots, slot -> point index (increasing
/// within a cell) and position (SoA). Two layouts of the cells, chosen by the points alone:
/// - dense: when the box of occupied cells has at most as many cells as the hash table would have
///   buckets, every cell of the box is a table entry (empty ones included), numbered
///   c = ((cz - lo_z) dim_y + (cy - lo_y)) dim_x + (cx - lo_x). Cells adjacent in x are then
///   adjacent in the slots: the three cells dx = -1..1 of a row are one contiguous run, which the
///   list build scans in one go.
/// - hashed: bucket -> cells (hash collisions share a bucket), only occupied cells are entries.
struct CellTable {
  double inv = 1.0;
  bool dense = false;
  std::array<int, 3> lo{}, dim{};                // dense: first cell and cells per axis
  uint32_t mask = 0;                             // hashed: buckets - 1
  std::vector<uint32_t> bucket_cells;            // hashed: bucket -> first cell, buckets + 1
  std::vector<uint32_t> cell_start;              // cell -> first slot, size cells + 1
  std::vector<std::array<int, 3>> cell_key;      // hashed: integer coordinates of each cell
  std::vector<uint32_t> sorted;                  // point index of each slot
  std::vector<double> x, y, z;                   // position of each slot
  std::vector<uint32_t> start, fill, bucket_of;  // scratch of the build
  std::vector<std::array<int, 3>> cell_of, cell_sorted;

  void build(const Context* ctx, const std::vector<Vec3>& points, double inv_cell);
  void build_hashed(std::size_t n, std::size_t nb);
  bool empty() const { return cell_start.empty(); }
  /// Number of cell entries (dense: all cells of the box).
  std::size_t cells() const { return cell_start.empty() ? 0 : cell_start.size() - 1; }
  /// Integer coordinates of cell entry c.
  std::array<int, 3> key(std::size_t c) const {
    if (!dense) return cell_key[c];
    const std::size_t row = c / std::size_t(dim[0]);
    return {lo[0] + int(c % std::size_t(dim[0])), lo[1] + int(row % std::size_t(dim[1])),
            lo[2] + int(row / std::size_t(dim[1]))};
  }
  uint32_t bucket(int cx, int cy, int cz) const {
    uint64_t h = uint64_t(uint32_t(cx)) * 73856093ull ^ uint64_t(uint32_t(cy)) * 19349663ull ^
                 uint64_t(uint32_t(cz)) * 83492791ull;
    return uint32_t(h & mask);
  }
  /// The cell with these coordinates, or -1 when no point lies in it.
  int64_t find(int cx, int cy, int cz) const {
    if (dense) {
      const int64_t ix = int64_t(cx) - lo[0], iy = int64_t(cy) - lo[1], iz = int64_t(cz) - lo[2];
      if (ix < 0 || iy < 0 || iz < 0 || ix >= dim[0] || iy >= dim[1] || iz >= dim[2]) return -1;
      const int64_t c = (iz * dim[1] + iy) * dim[0] + ix;
      return cell_start[std::size_t(c)] == cell_start[std::size_t(c) + 1] ? -1 : c;
    }
    const uint32_t b = bucket(cx, cy, cz);
    for (uint32_t c = bucket_cells[b]; c < bucket_cells[b + 1]; ++c) {
      const auto& k = cell_key[c];
      if (k[0] == cx && k[1] == cy && k[2] == cz) return int64_t(c);
    }
    return -1;
  }
};

/// Reused buffers of one chunk of query cells (list building).
struct ListPart {
  std::vector<uint32_t> out;  // the chunk's lists, back to back
  std::vector<double> x, y, z;
  std::vector<uint32_t> idx;
  bool mismatch = false;
};
}  // namespace detail

class ParticleGrid {
 public:
  /// Buckets `points` into cells of edge `cell` [m].
  void build(const std::vector<Vec3>& points, double cell);
  /// The same grid (identical order), with the cell and bucket computation in parallel.
  void build(const Context& ctx, const std::vector<Vec3>& points, double cell);

  /// Calls f(j) for every point j in the 27 cells around p (a superset of the points within
  /// `cell` of p; callers test the distance). Order: cells by (dz, dy, dx) in -1..1 (dx fastest),
  /// within a cell by increasing index.
  template <class F>
  void for_each_candidate(const Vec3& p, F&& f) const {
    if (m_cells.empty()) return;
    const double inv = m_cells.inv;
    const int cx = int(std::floor(p.x() * inv)), cy = int(std::floor(p.y() * inv)),
              cz = int(std::floor(p.z() * inv));
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int64_t c = m_cells.find(cx + dx, cy + dy, cz + dz);
          if (c < 0) continue;
          for (uint32_t s = m_cells.cell_start[c]; s < m_cells.cell_start[c + 1]; ++s)
            f(m_cells.sorted[s]);
        }
  }

  /// CSR neighbour lists: for each i, every j != i with |x_j - x_i| < radius (radius <= cell),
  /// in for_each_candidate order. `points` must be the points the grid was built over. Parallel;
  /// the output does not depend on the thread count. Uses scratch buffers of the grid: do not run
  /// two list builds on one grid at the same time (for_each_candidate may run concurrently).
  void neighbour_lists(const Context& ctx, const std::vector<Vec3>& points, double radius,
                       std::vector<uint32_t>& offsets, std::vector<uint32_t>& nbrs) const;

  /// Neighbours in another point set (this grid built over `grid_points`) for each query point,
  /// in for_each_candidate order (same conditions as neighbour_lists).
  void cross_lists(const Context& ctx, const std::vector<Vec3>& queries,
                   const std::vector<Vec3>& grid_points, double radius,
                   std::vector<uint32_t>& offsets, std::vector<uint32_t>& nbrs) const;

  /// Whether the last build laid the cells out as a dense box (else hashed; see CellTable).
  bool dense() const { return m_cells.dense; }
  /// The list builds test distances with the SIMD kernel when the CPU has one (default) or with
  /// the plain loop; the lists are identical (for tests and benchmarks).
  void set_simd(bool on) { m_simd = on; }

 private:
  void cell_lists(const Context& ctx, const detail::CellTable& q, const std::vector<Vec3>& qpts,
                  bool self, double r2, std::vector<uint32_t>& offsets,
                  std::vector<uint32_t>& nbrs) const;

  detail::CellTable m_cells;
  bool m_simd = true;
  mutable detail::CellTable m_query_cells;            // cross_lists: the query points by cell
  mutable std::vector<detail::ListPart> m_parts;      // per chunk of query cells
  mutable std::vector<uint32_t> m_part_of, m_pos_of;  // where each query's list was written
};

/// Sorts each CSR list by neighbour index and fills mirror[e] with the entry (j -> i) of every
/// entry e = (i -> j), so a per-pair value computed once at the lower-index end can be gathered
/// by the other end in a fixed order (deterministic, equal and opposite). The lists must be
/// symmetric and free of self entries; returns false (mirror cleared) when they are not.
bool sort_and_mirror(const Context& ctx, const std::vector<uint32_t>& offsets,
                     std::vector<uint32_t>& nbrs, std::vector<uint32_t>& mirror);

}  // namespace follicle::hair
