// Skin benchmarks: the "face-update" and "harmonic-map" workloads at their default sizes.
#include "bench_common.hpp"

namespace {
void run(benchmark::State& state, const char* name) {
  follicle::bench::run_workload(state, name, {}, int(state.range(0)));
}
void BM_FaceUpdate(benchmark::State& s) {
  run(s, "face-update");
}
void BM_HarmonicMap(benchmark::State& s) {
  run(s, "harmonic-map");
}
}  // namespace

BENCHMARK(BM_FaceUpdate)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_HarmonicMap)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
