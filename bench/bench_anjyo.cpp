// Google Benchmark front-end for the Anjyo 1992 workloads (same factories as `follicle bench`).
#include "bench_common.hpp"

static void run_anjyo(benchmark::State& state, const char* name) {
  follicle::bench::run_workload(state, name, {}, int(state.range(0)));
}

static void BM_AnjyoStyle(benchmark::State& s) {
  run_anjyo(s, "anjyo-style");
}
static void BM_AnjyoDynamics(benchmark::State& s) {
  run_anjyo(s, "anjyo-dynamics");
}
BENCHMARK(BM_AnjyoStyle)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_AnjyoDynamics)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
