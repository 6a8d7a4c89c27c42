// ParticleGrid (Bando 2003 §3.3 neighbour search) at the size and radius of `follicle bench
// lcp-wind`: 100,000 hair particles on a jittered lattice of spacing a = 5 mm, Verlet radius
// R = 2h (1 + skin) with h = 0.8 a and skin 0.15 (9.2 mm, also the cell). Argument: threads.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/hair/lcp_scenario_bando2003.hpp"
#include "follicle/hair/particle_grid.hpp"

namespace {

using namespace follicle;

constexpr double kSpacing = 0.005;
constexpr double kRadius = 2 * 0.8 * kSpacing * (1 + 0.15);

/// nx * nz strands of `len` particles (the lcp-wind block, hair::lcp_strand_block), jittered by
/// 10 %.
std::vector<Vec3> lattice(int nx, int nz, int len, uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec3> x = hair::lcp_strand_block(nx, nz, len, kSpacing).x;
  for (Vec3& p : x)
    p += 0.1 * kSpacing * Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
  return x;
}

void BM_ParticleGridNeighbourLists(benchmark::State& state) {
  Context ctx(int(state.range(0)));
  const auto x = lattice(50, 20, 100, 7);
  hair::ParticleGrid grid;
  std::vector<uint32_t> off, nb;
  for (auto _ : state) {
    grid.build(x, kRadius);
    grid.neighbour_lists(ctx, x, kRadius, off, nb);
    benchmark::DoNotOptimize(nb.data());
  }
  state.counters["entries"] = double(nb.size());
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(x.size()));
}

void BM_ParticleGridNeighbourListsPlain(benchmark::State& state) {
  // The same with the plain distance loop instead of the SIMD one (identical lists).
  Context ctx(int(state.range(0)));
  const auto x = lattice(50, 20, 100, 7);
  hair::ParticleGrid grid;
  grid.set_simd(false);
  std::vector<uint32_t> off, nb;
  for (auto _ : state) {
    grid.build(x, kRadius);
    grid.neighbour_lists(ctx, x, kRadius, off, nb);
    benchmark::DoNotOptimize(nb.data());
  }
}

void BM_ParticleGridRebuild(benchmark::State& state) {
  // The whole neighbour rebuild of LcpSolver::rebuild_neighbours: grid, lists, sort and mirror.
  Context ctx(int(state.range(0)));
  const auto x = lattice(50, 20, 100, 7);
  hair::ParticleGrid grid;
  std::vector<uint32_t> off, nb, mirror;
  for (auto _ : state) {
    grid.build(x, kRadius);
    grid.neighbour_lists(ctx, x, kRadius, off, nb);
    if (!hair::sort_and_mirror(ctx, off, nb, mirror)) state.SkipWithError("asymmetric lists");
    benchmark::DoNotOptimize(mirror.data());
  }
}

void BM_ParticleGridCrossLists(benchmark::State& state) {
  // 25,000 air particles (spacing 2.5 a) querying the hair grid, as in the SPH air coupling.
  Context ctx(int(state.range(0)));
  const auto hair = lattice(50, 20, 100, 7);
  std::vector<Vec3> air;
  Rng rng(9);
  for (int k = 0; k < 40; ++k)
    for (int j = 0; j < 25; ++j)
      for (int i = 0; i < 25; ++i)
        air.push_back(2.5 * kSpacing * Vec3(i, -k, j) +
                      kSpacing * Vec3(rng.uniform(), rng.uniform(), rng.uniform()));
  hair::ParticleGrid grid;
  grid.build(ctx, hair, kRadius);
  std::vector<uint32_t> off, nb;
  for (auto _ : state) {
    grid.cross_lists(ctx, air, hair, kRadius, off, nb);
    benchmark::DoNotOptimize(nb.data());
  }
  state.counters["entries"] = double(nb.size());
}

void BM_ParticleGridSortAndMirror(benchmark::State& state) {
  Context ctx(int(state.range(0)));
  const auto x = lattice(50, 20, 100, 7);
  hair::ParticleGrid grid;
  grid.build(x, kRadius);
  std::vector<uint32_t> off, nb0, nb, mirror;
  grid.neighbour_lists(ctx, x, kRadius, off, nb0);
  for (auto _ : state) {
    state.PauseTiming();
    nb = nb0;
    state.ResumeTiming();
    if (!hair::sort_and_mirror(ctx, off, nb, mirror)) state.SkipWithError("asymmetric lists");
    benchmark::DoNotOptimize(mirror.data());
  }
}

}  // namespace

BENCHMARK(BM_ParticleGridNeighbourLists)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_ParticleGridNeighbourListsPlain)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_ParticleGridRebuild)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ParticleGridCrossLists)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ParticleGridSortAndMirror)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
