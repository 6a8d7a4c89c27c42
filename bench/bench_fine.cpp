// Fine-scale wrinkle benchmarks: the same workloads as `follicle bench fine-wrinkles`,
// `fine-modulation` and `hand-update`.
#include <benchmark/benchmark.h>

#include "follicle/core/context.hpp"
#include "workloads/workload.hpp"

namespace {

void run_fine(benchmark::State& state, const char* name, int threads) {
  using namespace follicle::workloads;
  follicle::Context ctx(threads);
  const auto all = all_workloads();
  const Workload& w = find_workload(all, name);
  std::unique_ptr<WorkloadInstance> inst;
  try {
    inst = w.make(ctx, resolve_sizes(w, {}));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  for (auto _ : state) inst->run_once();
  state.counters[w.throughput_unit] = benchmark::Counter(
      double(state.iterations()) * inst->items_per_iter(), benchmark::Counter::kIsRate);
}

void BM_FineWrinkles(benchmark::State& s) {
  run_fine(s, "fine-wrinkles", int(s.range(0)));
}
void BM_FineModulation(benchmark::State& s) {
  run_fine(s, "fine-modulation", int(s.range(0)));
}
void BM_HandUpdate(benchmark::State& s) {
  run_fine(s, "hand-update", int(s.range(0)));
}

}  // namespace

BENCHMARK(BM_FineWrinkles)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FineModulation)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_HandUpdate)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
