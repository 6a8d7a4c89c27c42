// Face rendering benchmarks: the "face-render" workload (wrinkled default head, Lafortune skin
// BRDF, 640x480 headless), render only and with the face update every frame.
#include "bench_common.hpp"

namespace {

void run_face_render(benchmark::State& state, const follicle::workloads::Sizes& sizes) {
  follicle::bench::run_workload(state, "face-render", sizes);
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
