// Skin benchmarks: the "face-update" and "harmonic-map" workloads at their default sizes.
#include <benchmark/benchmark.h>

#include "follicle/core/context.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {
void add_skin_workloads(std::vector<Workload>& out);
}

namespace {
void run(benchmark::State& state, const char* name) {
  using namespace follicle::workloads;
  std::vector<Workload> all;
  add_skin_workloads(all);
  const Workload& w = find_workload(all, name);
  follicle::Context ctx(int(state.range(0)));
  auto inst = w.make(ctx, resolve_sizes(w, {}));
  for (auto _ : state) inst->run_once();
  state.SetItemsProcessed(int64_t(double(state.iterations()) * inst->items_per_iter()));
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
