// Face rendering benchmarks: the "face-render" workload (wrinkled default head, Lafortune skin
// BRDF, 640x480 headless), render only and with the face update every frame.
#include <benchmark/benchmark.h>

#include "follicle/core/context.hpp"
#include "workloads/workload.hpp"

namespace {

void run_face_render(benchmark::State& state, follicle::workloads::Sizes sizes) {
  using namespace follicle::workloads;
  follicle::Context ctx(0);
  const auto all = all_workloads();
  const Workload& w = find_workload(all, "face-render");
  std::unique_ptr<WorkloadInstance> inst;
  try {
    inst = w.make(ctx, resolve_sizes(w, sizes));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  for (auto _ : state) inst->run_once();
  state.counters[w.throughput_unit] = benchmark::Counter(
      double(state.iterations()) * inst->items_per_iter(), benchmark::Counter::kIsRate);
}

void BM_FaceRender(benchmark::State& state) {
  run_face_render(state, {{"supersample", double(state.range(0))}});
}
void BM_FaceRenderWithUpdate(benchmark::State& state) {
  run_face_render(state, {{"update", 1}});
}

}  // namespace

BENCHMARK(BM_FaceRender)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FaceRenderWithUpdate)->Unit(benchmark::kMillisecond)->UseRealTime();
