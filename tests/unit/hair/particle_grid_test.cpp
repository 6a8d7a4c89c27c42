// ParticleGrid (Bando 2003 §3.3 neighbour search): the lists must hold exactly the pairs closer
// than the radius, in the documented order (27 cells in z, y, x order, each cell by index), for
// any thread count, so that the solvers' sums do not change with the search's implementation.
#include "follicle/hair/particle_grid.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/rng.hpp"

using namespace follicle;
using namespace follicle::hair;

namespace {

using Lists = std::vector<std::vector<uint32_t>>;

std::array<int, 3> cell_of(const Vec3& p, double inv) {
  return {int(std::floor(p.x() * inv)), int(std::floor(p.y() * inv)), int(std::floor(p.z() * inv))};
}

/// O(27 n^2) reference of the documented order: for each query, the cells around its cell in
/// (dz, dy, dx) order, each cell's grid points (cell from `cell_pts`) by increasing index, kept
/// when the distance to `dist_pts` is below the radius.
Lists ordered_reference(const std::vector<Vec3>& cell_pts, const std::vector<Vec3>& dist_pts,
                        const std::vector<Vec3>& queries, double cell, double radius, bool self) {
  const double inv = 1.0 / cell, r2 = radius * radius;
  std::vector<std::array<int, 3>> cells(cell_pts.size());
  for (std::size_t j = 0; j < cell_pts.size(); ++j) cells[j] = cell_of(cell_pts[j], inv);
  Lists out(queries.size());
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const auto c = cell_of(queries[i], inv);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          for (std::size_t j = 0; j < cell_pts.size(); ++j) {
            if (cells[j] != std::array<int, 3>{c[0] + dx, c[1] + dy, c[2] + dz}) continue;
            if (self && j == i) continue;
            if ((dist_pts[j] - queries[i]).squaredNorm() < r2) out[i].push_back(uint32_t(j));
          }
  }
  return out;
}

/// Every j (j != i when self) closer than the radius, by index: the lists as sets.
Lists brute_force_sets(const std::vector<Vec3>& pts, const std::vector<Vec3>& queries,
                       double radius, bool self) {
  Lists out(queries.size());
  for (std::size_t i = 0; i < queries.size(); ++i)
    for (std::size_t j = 0; j < pts.size(); ++j)
      if ((!self || j != i) && (pts[j] - queries[i]).squaredNorm() < radius * radius)
        out[i].push_back(uint32_t(j));
  return out;
}

Lists from_csr(const std::vector<uint32_t>& off, const std::vector<uint32_t>& nb) {
  EXPECT_FALSE(off.empty());
  EXPECT_EQ(off.empty() ? 0u : off.back(), nb.size());
  Lists out(off.empty() ? 0 : off.size() - 1);
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i].assign(nb.begin() + off[i], nb.begin() + off[i + 1]);
  return out;
}

Lists sorted_lists(Lists l) {
  for (auto& v : l) std::sort(v.begin(), v.end());
  return l;
}

std::vector<Vec3> random_points(std::size_t n, double lo, double hi, uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec3> x(n);
  for (auto& p : x) p = Vec3(rng.uniform(lo, hi), rng.uniform(lo, hi), rng.uniform(lo, hi));
  return x;
}

std::vector<Vec3> clustered_points(std::size_t n, uint64_t seed) {
  // A few tight Gaussian blobs (dozens of points per cell) plus sparse points far apart (many
  // occupied cells relative to the hash table: bucket collisions).
  Rng rng(seed);
  std::vector<Vec3> x;
  for (std::size_t i = 0; i < n; ++i) {
    if (i % 4 == 3) {
      x.push_back(Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)));
      continue;
    }
    const double cx = 0.03 * double(i % 5), cy = -0.02 * double(i % 3);
    x.push_back(Vec3(cx + 0.004 * rng.normal(), cy + 0.004 * rng.normal(), 0.003 * rng.normal()));
  }
  return x;
}

std::vector<Vec3> boundary_lattice(double cell) {
  // Points exactly on the cell boundaries (multiples of the cell), negative coordinates
  // included; with radius == cell the axis neighbours at distance == cell are excluded.
  std::vector<Vec3> x;
  for (int k = -4; k <= 3; ++k)
    for (int j = -3; j <= 4; ++j)
      for (int i = -5; i <= 2; ++i) x.push_back(cell * Vec3(i, j, k));
  x.push_back(x[7]);  // a coincident pair
  return x;
}

// Neighbour lists of x from a serial grid build and 1 thread (off1, nb1) and from the parallel
// build and 2 threads (off2, nb2).
struct SerialAndParallel {
  std::vector<uint32_t> off1, nb1, off2, nb2;
};
SerialAndParallel lists_1_and_2_threads(const std::vector<Vec3>& x, double cell, double radius) {
  Context ctx1(1), ctx2(2);
  ParticleGrid serial, parallel;
  serial.build(x, cell);
  parallel.build(ctx2, x, cell);
  SerialAndParallel r;
  serial.neighbour_lists(ctx1, x, radius, r.off1, r.nb1);
  parallel.neighbour_lists(ctx2, x, radius, r.off2, r.nb2);
  return r;
}

/// The lists of a grid whose distance test is the plain loop (set_simd(false)).
void plain_lists(const std::vector<Vec3>& x, double cell, double radius, std::vector<uint32_t>& off,
                 std::vector<uint32_t>& nb) {
  Context ctx(2);
  ParticleGrid grid;
  grid.set_simd(false);
  grid.build(ctx, x, cell);
  grid.neighbour_lists(ctx, x, radius, off, nb);
}

void expect_neighbour_lists_match(const std::vector<Vec3>& x, double cell, double radius) {
  const auto [off1, nb1, off2, nb2] = lists_1_and_2_threads(x, cell, radius);
  const Lists got = from_csr(off1, nb1);
  EXPECT_EQ(got, ordered_reference(x, x, x, cell, radius, true));
  // The plain distance loop and the SIMD one give the same lists.
  std::vector<uint32_t> offp, nbp;
  plain_lists(x, cell, radius, offp, nbp);
  EXPECT_EQ(offp, off1);
  EXPECT_EQ(nbp, nb1);
  if (radius <= cell) {
    EXPECT_EQ(sorted_lists(got), brute_force_sets(x, x, radius, true));
  }
  // The thread count and the parallel build change nothing.
  EXPECT_EQ(off1, off2);
  EXPECT_EQ(nb1, nb2);
  // for_each_candidate visits the same order (sph_density relies on it).
  ParticleGrid serial;
  serial.build(x, cell);
  for (std::size_t i = 0; i < x.size(); i += 7) {
    std::vector<uint32_t> cand;
    serial.for_each_candidate(x[i], [&](uint32_t j) {
      if (j != i && (x[j] - x[i]).squaredNorm() < radius * radius) cand.push_back(j);
    });
    EXPECT_EQ(cand, got[i]) << i;
  }
}

}  // namespace

TEST(ParticleGrid, RandomPointsMatchTheBruteForceInTheDocumentedOrder) {
  const auto x = random_points(1500, -0.05, 0.05, 1);
  expect_neighbour_lists_match(x, 0.012, 0.012);  // radius == cell
  expect_neighbour_lists_match(x, 0.012, 0.007);  // radius < cell (SphAir: cell = max(2h, rc))
}

TEST(ParticleGrid, ClusteredPointsMatchTheBruteForce) {
  const auto x = clustered_points(1600, 2);
  ParticleGrid grid;
  grid.build(x, 0.005);
  EXPECT_FALSE(grid.dense());  // sparse points far apart: the hashed cells
  expect_neighbour_lists_match(x, 0.005, 0.005);
}

TEST(ParticleGrid, DenseAndHashedCellsGiveTheSameLists) {
  // The same points with and without a far outlier: the first grid is a dense box of cells (rows
  // of three cells scanned as one run), the second hashed (one run per cell). Lists of the
  // common points must be identical, entry for entry, and the outlier has none. Densities from
  // under one to dozens of points per cell give runs of every length modulo the SIMD width.
  for (const double cell : {0.005, 0.008, 0.02}) {
    const auto x = random_points(900, -0.03, 0.03, 31);
    auto y = x;
    y.push_back(Vec3(40.0, -25.0, 3.0));
    ParticleGrid gx, gy;
    gx.build(x, cell);
    gy.build(y, cell);
    EXPECT_TRUE(gx.dense());
    EXPECT_FALSE(gy.dense());
    Context ctx(2);
    std::vector<uint32_t> offx, nbx, offy, nby;
    gx.neighbour_lists(ctx, x, cell, offx, nbx);
    gy.neighbour_lists(ctx, y, cell, offy, nby);
    ASSERT_EQ(offy.size(), offx.size() + 1);
    EXPECT_EQ(std::vector<uint32_t>(offy.begin(), offy.end() - 1), offx);
    EXPECT_EQ(offy.back(), offx.back());
    EXPECT_EQ(nby, nbx);
    EXPECT_EQ(from_csr(offx, nbx), ordered_reference(x, x, x, cell, cell, true));
    for (const bool simd : {true, false})
      for (ParticleGrid* g : {&gx, &gy}) {
        // Queries inside, around and outside the grid's box (the dense rows are clipped to the
        // box), against the SIMD and the plain distance test.
        const auto q = random_points(300, -0.06, 0.06, 32);
        const auto& pts = g == &gx ? x : y;
        std::vector<uint32_t> off, nb;
        g->set_simd(simd);
        g->cross_lists(ctx, q, pts, 0.8 * cell, off, nb);
        EXPECT_EQ(from_csr(off, nb), ordered_reference(pts, pts, q, cell, 0.8 * cell, false))
            << cell << " simd " << simd << " dense " << g->dense();
      }
  }
}

TEST(ParticleGrid, BoxesOneOrTwoCellsThickMatchTheBruteForce) {
  // Dense boxes one or two cells thick in x, y or z: a row of cells clipped at the box's ends
  // must not run into the neighbouring row (with one or two cells per row, that row holds
  // true neighbours: they would appear twice or out of order).
  for (int axis = 0; axis < 3; ++axis)
    for (const double thick : {0.6, 1.7}) {
      auto x = random_points(600, -0.03, 0.03, 40 + uint64_t(axis));
      for (auto& p : x) p[axis] = 0.01 * thick * (p[axis] + 0.03) / 0.06;
      ParticleGrid grid;
      grid.build(x, 0.01);
      ASSERT_TRUE(grid.dense());
      expect_neighbour_lists_match(x, 0.01, 0.01);
    }
}

TEST(ParticleGrid, RunsOfEveryLengthModuloTheSimdWidth) {
  // One row of points along x, k points per cell (k = 1..9), all at the same y and z: every run
  // of a row has length 3k or 2k at the ends, so the vector loop ends with 0..3 leftover slots.
  // All points lie within the radius of their cell neighbours except those two cells away.
  for (int k = 1; k <= 9; ++k) {
    const double cell = 0.01;
    std::vector<Vec3> x;
    for (int c = 0; c < 6; ++c)
      for (int m = 0; m < k; ++m)
        x.push_back(Vec3(cell * (c + (m + 0.5) / (k + 0.25)), 0.003 * (m % 3), 0.002));
    ParticleGrid grid;
    grid.build(x, cell);
    ASSERT_TRUE(grid.dense());
    Context ctx(1);
    for (const bool simd : {true, false}) {
      grid.set_simd(simd);
      std::vector<uint32_t> off, nb;
      grid.neighbour_lists(ctx, x, cell, off, nb);
      EXPECT_EQ(from_csr(off, nb), ordered_reference(x, x, x, cell, cell, true))
          << k << " " << simd;
      EXPECT_EQ(sorted_lists(from_csr(off, nb)), brute_force_sets(x, x, cell, true));
    }
  }
}

TEST(ParticleGrid, PointsOnCellBoundariesMatchTheBruteForce) {
  expect_neighbour_lists_match(boundary_lattice(0.01), 0.01, 0.01);
  expect_neighbour_lists_match(boundary_lattice(0.25), 0.25, 0.25);
  expect_neighbour_lists_match(boundary_lattice(0.01), 0.01, 0.0100001);  // axis pairs included
}

TEST(ParticleGrid, EmptyAndSinglePoint) {
  Context ctx(2);
  ParticleGrid grid;
  std::vector<uint32_t> off{5, 6}, nb{1, 2, 3};
  grid.build(std::vector<Vec3>{}, 0.01);
  grid.neighbour_lists(ctx, {}, 0.01, off, nb);
  EXPECT_EQ(off, std::vector<uint32_t>{0});
  EXPECT_TRUE(nb.empty());
  const std::vector<Vec3> one{Vec3(-0.3, 0.2, -1e-9)};
  grid.build(one, 0.01);
  grid.neighbour_lists(ctx, one, 0.01, off, nb);
  EXPECT_EQ(off, (std::vector<uint32_t>{0, 0}));
  EXPECT_TRUE(nb.empty());
  // Queries against an empty grid find nothing; an empty query set gives one offset.
  grid.build(std::vector<Vec3>{}, 0.01);
  grid.cross_lists(ctx, one, {}, 0.01, off, nb);
  EXPECT_EQ(off, (std::vector<uint32_t>{0, 0}));
  grid.build(one, 0.01);
  grid.cross_lists(ctx, {}, one, 0.01, off, nb);
  EXPECT_EQ(off, std::vector<uint32_t>{0});
  EXPECT_TRUE(nb.empty());
  EXPECT_THROW(grid.build(one, 0.0), std::exception);
}

TEST(ParticleGrid, ThreadCountDoesNotChangeLargeLists) {
  // Enough points for the parallel build and many list chunks; a jittered lattice as the hair
  // block of `follicle bench lcp-wind` (spacing a, Verlet radius 2 h (1 + skin), h = 0.8 a).
  const double a = 0.005, R = 2 * 0.8 * a * 1.15;
  Rng rng(5);
  std::vector<Vec3> x;
  for (int k = 0; k < 20; ++k)
    for (int j = 0; j < 12; ++j)
      for (int i = 0; i < 20; ++i)
        x.push_back(a * Vec3(i, -k, j) +
                    0.1 * a * Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)));
  const auto [off1, nb1, off2, nb2] = lists_1_and_2_threads(x, R, R);
  ASSERT_GT(nb1.size(), 10 * x.size());
  ParticleGrid dense;
  dense.build(x, R);
  EXPECT_TRUE(dense.dense());
  EXPECT_EQ(off1, off2);
  EXPECT_EQ(nb1, nb2);
  EXPECT_EQ(sorted_lists(from_csr(off1, nb1)), brute_force_sets(x, x, R, true));
  // Rebuilding the same grid object over other points leaves no trace of the first build.
  Context ctx2(2);
  ParticleGrid g;
  std::vector<uint32_t> off, nb;
  g.build(ctx2, x, R);
  g.neighbour_lists(ctx2, x, R, off, nb);
  const auto y = random_points(1500, -0.02, 0.03, 8);
  g.build(ctx2, y, R);
  g.neighbour_lists(ctx2, y, R, off, nb);
  EXPECT_EQ(from_csr(off, nb), ordered_reference(y, y, y, R, R, true));
}

TEST(ParticleGrid, CrossListsMatchTheBruteForceInTheDocumentedOrder) {
  const auto grid_pts = clustered_points(1200, 3);
  const auto queries = random_points(900, -0.06, 0.1, 4);
  for (double radius : {0.005, 0.0031}) {
    Context ctx1(1), ctx2(2);
    ParticleGrid grid;
    grid.build(ctx2, grid_pts, 0.005);
    std::vector<uint32_t> off1, nb1, off2, nb2;
    grid.cross_lists(ctx1, queries, grid_pts, radius, off1, nb1);
    grid.cross_lists(ctx2, queries, grid_pts, radius, off2, nb2);
    const Lists got = from_csr(off1, nb1);
    EXPECT_EQ(got, ordered_reference(grid_pts, grid_pts, queries, 0.005, radius, false));
    EXPECT_EQ(sorted_lists(got), brute_force_sets(grid_pts, queries, radius, false));
    EXPECT_EQ(off1, off2);
    EXPECT_EQ(nb1, nb2);
  }
  // Queries that are the grid points themselves: the self lists plus the point itself.
  const auto x = random_points(800, -0.02, 0.02, 6);
  Context ctx(2);
  ParticleGrid grid;
  grid.build(x, 0.008);
  std::vector<uint32_t> off, nb;
  grid.cross_lists(ctx, x, x, 0.008, off, nb);
  EXPECT_EQ(from_csr(off, nb), ordered_reference(x, x, x, 0.008, 0.008, false));
}

TEST(ParticleGrid, ListsOfPointsOtherThanTheBuildPointsUseTheBuildCells) {
  // Lists asked for positions that moved since the build: candidates come from the cells of the
  // build, distances from the given positions (the grid's contract; nothing is cached wrongly).
  const auto x = random_points(1000, -0.03, 0.03, 12);
  auto y = x;
  Rng rng(13);
  for (auto& p : y) p += 0.002 * Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
  Context ctx(2);
  ParticleGrid grid;
  grid.build(x, 0.01);
  std::vector<uint32_t> off, nb;
  grid.neighbour_lists(ctx, y, 0.01, off, nb);
  EXPECT_EQ(from_csr(off, nb), ordered_reference(x, y, y, 0.01, 0.01, true));
  grid.cross_lists(ctx, x, y, 0.01, off, nb);
  EXPECT_EQ(from_csr(off, nb), ordered_reference(x, y, x, 0.01, 0.01, false));
}

namespace {
/// The sort-then-cursor algorithm sort_and_mirror is specified by (std::sort of each list).
bool reference_sort_and_mirror(const std::vector<uint32_t>& off, std::vector<uint32_t>& nb,
                               std::vector<uint32_t>& mirror) {
  const std::size_t n = off.size() - 1;
  for (std::size_t i = 0; i < n; ++i) std::sort(nb.begin() + off[i], nb.begin() + off[i + 1]);
  mirror.assign(nb.size(), 0);
  std::vector<uint32_t> cursor(off.begin(), off.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    for (uint32_t e = off[i]; e < off[i + 1]; ++e) {
      const uint32_t j = nb[e];
      if (j == i) {  // a self entry is no pair
        mirror.clear();
        return false;
      }
      if (j < i) continue;
      if (j >= n || cursor[j] >= off[j + 1] || nb[cursor[j]] != i) {
        mirror.clear();
        return false;
      }
      mirror[e] = cursor[j];
      mirror[cursor[j]++] = e;
    }
  for (std::size_t j = 0; j < n; ++j)
    if (cursor[j] < off[j + 1] && nb[cursor[j]] < j) {
      mirror.clear();
      return false;
    }
  return true;
}
}  // namespace

TEST(ParticleGrid, SortAndMirrorPairsEveryEntryAndRejectsAsymmetricLists) {
  const auto x = clustered_points(2000, 21);
  Context ctx1(1), ctx2(2);
  ParticleGrid grid;
  grid.build(x, 0.004);
  std::vector<uint32_t> off, nb0;
  grid.neighbour_lists(ctx2, x, 0.004, off, nb0);
  ASSERT_GT(nb0.size(), 5 * x.size());
  std::vector<uint32_t> nb1 = nb0, nb2 = nb0, nbr = nb0, m1, m2, mr;
  ASSERT_TRUE(sort_and_mirror(ctx1, off, nb1, m1));
  ASSERT_TRUE(sort_and_mirror(ctx2, off, nb2, m2));
  ASSERT_TRUE(reference_sort_and_mirror(off, nbr, mr));
  EXPECT_EQ(nb1, nbr);
  EXPECT_EQ(m1, mr);
  EXPECT_EQ(nb2, nbr);
  EXPECT_EQ(m2, mr);
  for (std::size_t i = 0; i + 1 < off.size(); ++i)
    for (uint32_t e = off[i]; e < off[i + 1]; ++e) {
      ASSERT_EQ(m1[m1[e]], e);
      ASSERT_EQ(nb1[m1[e]], i);
    }
  // Asymmetric variants: an entry removed from one side, an entry pointing past the end, an
  // entry replaced by another index, a duplicated entry. Each is rejected as the reference does.
  auto check = [&](const std::vector<uint32_t>& o, const std::vector<uint32_t>& n) {
    std::vector<uint32_t> a = n, b = n, ma{7}, mb;
    const bool ok = sort_and_mirror(ctx2, o, a, ma);
    EXPECT_EQ(ok, reference_sort_and_mirror(o, b, mb));
    EXPECT_FALSE(ok);
    EXPECT_TRUE(ma.empty());
  };
  std::vector<uint32_t> o = off, n = nb0;
  n.erase(n.begin() + o[10]);
  for (std::size_t i = 11; i < o.size(); ++i) --o[i];
  check(o, n);
  n = nb0;
  n[off[30]] = uint32_t(x.size());
  check(off, n);
  n = nb0;
  n[off[40]] = n[off[40]] == 0 ? 1 : 0;
  check(off, n);
  check({0, 2, 3}, {1, 1, 0});
  check({0, 1, 1}, {1});
  check({0, 0, 1}, {0});
  // Self entries: symmetric as lists (an entry i in list i is its own transpose) but no pair;
  // gathering them through the mirror index read pair 0's force and kernel value.
  check({0, 1, 2}, {0, 1});
  check({0, 2, 3}, {0, 1, 0});
  o = off;
  n = nb0;
  n.insert(n.begin() + o[50], 50);
  for (std::size_t i = 51; i < o.size(); ++i) ++o[i];
  check(o, n);
}
