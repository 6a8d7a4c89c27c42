// Geometry benchmarks: the same workloads as `follicle bench
// mesh-load|large-mesh-load|closest-point| neighbour-search`. Arguments: the size (queries or
// particles) and the thread count.
#include "bench_common.hpp"

namespace {

using follicle::workloads::Sizes;

void run(benchmark::State& state, const char* name, const Sizes& sizes, int threads) {
  follicle::bench::run_workload(state, name, sizes, threads);
}

void BM_MeshLoad(benchmark::State& state) {
  run(state, "mesh-load", {}, int(state.range(0)));
}
void BM_LargeMeshLoad(benchmark::State& state) {
  run(state, "large-mesh-load", {{"triangles", 1e6}, {"format", double(state.range(0))}}, 1);
}
void BM_ClosestPoint(benchmark::State& state) {
  run(state, "closest-point", {{"queries", double(state.range(0))}}, int(state.range(1)));
}
void BM_NeighbourSearch(benchmark::State& state) {
  run(state, "neighbour-search", {{"particles", double(state.range(0))}}, int(state.range(1)));
}

}  // namespace

BENCHMARK(BM_MeshLoad)->Arg(1)->Unit(benchmark::kMillisecond);
// 1M triangles; argument: 0 OBJ, 1 binary PLY, 2 ASCII PLY, 3 PLY triangle strips.
BENCHMARK(BM_LargeMeshLoad)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ClosestPoint)->Args({1000000, 1})->Args({1000000, 2})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NeighbourSearch)
    ->Args({1000000, 1})
    ->Args({1000000, 2})
    ->Unit(benchmark::kMillisecond);
