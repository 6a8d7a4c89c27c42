// Google Benchmark front-end for the Daldegan 1993 workloads (same factories as `follicle bench`).
#include "bench_common.hpp"

static void run_daldegan(benchmark::State& state, const char* name,
                         const follicle::workloads::Sizes& sizes = {}) {
  follicle::bench::run_workload(state, name, sizes, int(state.range(0)));
}

static void BM_DaldeganStyle(benchmark::State& s) {
  run_daldegan(s, "daldegan-style");
}
static void BM_DaldeganDynamics(benchmark::State& s) {
  run_daldegan(s, "daldegan-dynamics");
}
static void BM_DaldeganRender(benchmark::State& s) {
  run_daldegan(s, "daldegan-render");
}
static void BM_DaldeganRenderSS2(benchmark::State& s) {
  run_daldegan(s, "daldegan-render", {{"supersample", 2}});
}
BENCHMARK(BM_DaldeganStyle)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DaldeganDynamics)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DaldeganRender)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DaldeganRenderSS2)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
