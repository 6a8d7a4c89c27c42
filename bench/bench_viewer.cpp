// Viewer frame benchmark: the same workload as `follicle bench viewer-frame` (issue 25 item 2).
#include "bench_common.hpp"

namespace {

void BM_ViewerFrame(benchmark::State& state) {
  follicle::bench::run_workload(state, "viewer-frame", {{"moving", double(state.range(0))}});
}

}  // namespace

BENCHMARK(BM_ViewerFrame)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
