// Google Benchmark front-end for the Anjyo 1992 workloads (same factories as `follicle bench`).
#include <benchmark/benchmark.h>

#include "follicle/core/context.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {
void add_anjyo_workloads(std::vector<Workload>& out);
}

static void run_anjyo(benchmark::State& state, const char* name) {
  using namespace follicle::workloads;
  std::vector<Workload> all;
  add_anjyo_workloads(all);
  const Workload& w = find_workload(all, name);
  follicle::Context ctx(int(state.range(0)));
  auto inst = w.make(ctx, w.default_sizes);
  for (auto _ : state) inst->run_once();
  state.SetItemsProcessed(int64_t(double(state.iterations()) * inst->items_per_iter()));
}

static void BM_AnjyoStyle(benchmark::State& s) {
  run_anjyo(s, "anjyo-style");
}
static void BM_AnjyoDynamics(benchmark::State& s) {
  run_anjyo(s, "anjyo-dynamics");
}
BENCHMARK(BM_AnjyoStyle)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_AnjyoDynamics)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
