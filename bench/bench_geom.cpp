// Geometry benchmarks: the same workloads as `follicle bench mesh-load|closest-point|
// neighbour-search`. Arguments: the size (queries or particles) and the thread count.
#include <benchmark/benchmark.h>

#include "follicle/core/context.hpp"
#include "workloads/workload.hpp"

namespace {

using namespace follicle;
using namespace follicle::workloads;

void run(benchmark::State& state, const char* name, const Sizes& sizes, int threads) {
  const auto all = all_workloads();
  const Workload& w = find_workload(all, name);
  Context ctx(threads);
  auto inst = w.make(ctx, resolve_sizes(w, sizes));
  for (auto _ : state) inst->run_once();
  state.counters["items_per_s"] = benchmark::Counter(
      inst->items_per_iter() * double(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_MeshLoad(benchmark::State& state) {
  run(state, "mesh-load", {}, int(state.range(0)));
}
void BM_ClosestPoint(benchmark::State& state) {
  run(state, "closest-point", {{"queries", double(state.range(0))}}, int(state.range(1)));
}
void BM_NeighbourSearch(benchmark::State& state) {
  run(state, "neighbour-search", {{"particles", double(state.range(0))}}, int(state.range(1)));
}

}  // namespace

BENCHMARK(BM_MeshLoad)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClosestPoint)->Args({1000000, 1})->Args({1000000, 2})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NeighbourSearch)
    ->Args({1000000, 1})
    ->Args({1000000, 2})
    ->Unit(benchmark::kMillisecond);
