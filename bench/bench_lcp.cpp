// Google Benchmark front-end for the Bando 2003 LCP workloads (same factories as `follicle bench`).
#include "bench_common.hpp"

static void run_lcp(benchmark::State& state, const char* name) {
  follicle::bench::run_workload(state, name, {}, int(state.range(0)));
}

static void BM_LcpStep(benchmark::State& s) {
  run_lcp(s, "lcp-step");
}
static void BM_LcpFrame(benchmark::State& s) {
  run_lcp(s, "lcp-frame");
}
static void BM_LcpWind(benchmark::State& s) {
  run_lcp(s, "lcp-wind");
}
BENCHMARK(BM_LcpStep)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LcpFrame)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_LcpWind)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
