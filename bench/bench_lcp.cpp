// Google Benchmark front-end for the Bando 2003 LCP workloads (same factories as `follicle bench`).
#include <benchmark/benchmark.h>

#include "follicle/core/context.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {
void add_lcp_workloads(std::vector<Workload>& out);
}

static void run_lcp(benchmark::State& state, const char* name) {
  using namespace follicle::workloads;
  std::vector<Workload> all;
  add_lcp_workloads(all);
  const Workload& w = find_workload(all, name);
  follicle::Context ctx(int(state.range(0)));
  auto inst = w.make(ctx, w.default_sizes);
  for (auto _ : state) inst->run_once();
  state.SetItemsProcessed(int64_t(double(state.iterations()) * inst->items_per_iter()));
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
