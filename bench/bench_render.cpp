// Rendering benchmarks: the same workloads as `follicle bench render-head`.
#include "bench_common.hpp"

namespace {

using follicle::bench::run_workload;

void BM_RenderHead(benchmark::State& state) {
  run_workload(state, "render-head", {{"supersample", double(state.range(0))}});
}
void BM_RenderHeadLafortune(benchmark::State& state) {
  run_workload(state, "render-head", {{"lafortune", 1}});
}

}  // namespace

BENCHMARK(BM_RenderHead)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RenderHeadLafortune)->Unit(benchmark::kMillisecond)->UseRealTime();
