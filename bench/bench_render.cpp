// Rendering benchmarks: the same workloads as `follicle bench render-head`.
#include <benchmark/benchmark.h>

#include "follicle/core/context.hpp"
#include "workloads/workload.hpp"

namespace {

void run_workload(benchmark::State& state, const char* name, follicle::workloads::Sizes sizes) {
  using namespace follicle::workloads;
  follicle::Context ctx(0);
  const auto all = all_workloads();
  const Workload& w = find_workload(all, name);
  std::unique_ptr<WorkloadInstance> inst;
  try {
    inst = w.make(ctx, resolve_sizes(w, sizes));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  for (auto _ : state) inst->run_once();
  state.counters[w.throughput_unit] = benchmark::Counter(
      double(state.iterations()) * inst->items_per_iter(), benchmark::Counter::kIsRate);
}

void BM_RenderHead(benchmark::State& state) {
  run_workload(state, "render-head", {{"supersample", double(state.range(0))}});
}
void BM_RenderHeadLafortune(benchmark::State& state) {
  run_workload(state, "render-head", {{"lafortune", 1}});
}

}  // namespace

BENCHMARK(BM_RenderHead)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RenderHeadLafortune)->Unit(benchmark::kMillisecond)->UseRealTime();
