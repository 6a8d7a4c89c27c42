// Hair rendering benchmark: the same workload as `follicle bench hair-render`.
#include <benchmark/benchmark.h>

#include "follicle/core/context.hpp"
#include "workloads/workload.hpp"

namespace {

void BM_HairRender(benchmark::State& state) {
  using namespace follicle::workloads;
  follicle::Context ctx(0);
  const auto all = all_workloads();
  std::unique_ptr<WorkloadInstance> inst;
  try {
    const Workload& w = find_workload(all, "hair-render");
    inst = w.make(ctx, resolve_sizes(w, {{"strands", double(state.range(0))}}));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  for (auto _ : state) inst->run_once();
  state.counters["strands/s"] = benchmark::Counter(
      double(state.iterations()) * inst->items_per_iter(), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK(BM_HairRender)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond)->UseRealTime();
