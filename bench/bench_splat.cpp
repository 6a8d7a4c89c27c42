// Hair splat rendering benchmarks: the same workload as `follicle bench lcp-render`.
#include "bench_common.hpp"

namespace {

using follicle::bench::run_workload;

// The target: 2,000 particles, self-shadowing, 512^2.
void BM_LcpRender(benchmark::State& state) {
  run_workload(state, "lcp-render", {});
}
// Cost of the light-view pass: self-shadowing off; and the paper's per-particle read done by
// the sliced GPU light pass with one slice per particle (ADR 0003).
void BM_LcpRenderNoSelfShadow(benchmark::State& state) {
  run_workload(state, "lcp-render", {{"self_shadow", 0}});
}
void BM_LcpRenderGpuPerParticleRead(benchmark::State& state) {
  run_workload(state, "lcp-render", {{"gpu_light_pass", 1}, {"slices", 2000}});
}
// The GL view pass and resolve instead of the CPU ones (ADR 0007).
void BM_LcpRenderGlViewPass(benchmark::State& state) {
  run_workload(state, "lcp-render", {{"gpu_view_pass", 1}});
}
void BM_LcpRenderSupersample2(benchmark::State& state) {
  run_workload(state, "lcp-render", {{"supersample", 2}});
}

}  // namespace

BENCHMARK(BM_LcpRender)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LcpRenderNoSelfShadow)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LcpRenderGpuPerParticleRead)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LcpRenderGlViewPass)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LcpRenderSupersample2)->Unit(benchmark::kMillisecond)->UseRealTime();
