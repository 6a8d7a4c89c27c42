// Hair splat rendering benchmarks: the same workload as `follicle bench lcp-render`.
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

// The target: 2,000 particles, self-shadowing, 512^2.
void BM_LcpRender(benchmark::State& state) {
  run_workload(state, "lcp-render", {});
}
// Cost of the light-view pass: self-shadowing off; and the paper's per-particle read.
void BM_LcpRenderNoSelfShadow(benchmark::State& state) {
  run_workload(state, "lcp-render", {{"self_shadow", 0}});
}
void BM_LcpRenderPerParticleRead(benchmark::State& state) {
  run_workload(state, "lcp-render", {{"slices", 2000}});
}
void BM_LcpRenderSupersample2(benchmark::State& state) {
  run_workload(state, "lcp-render", {{"supersample", 2}});
}

}  // namespace

BENCHMARK(BM_LcpRender)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LcpRenderNoSelfShadow)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LcpRenderPerParticleRead)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LcpRenderSupersample2)->Unit(benchmark::kMillisecond)->UseRealTime();
