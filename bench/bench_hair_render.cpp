// Hair rendering benchmark: the same workload as `follicle bench hair-render`.
#include "bench_common.hpp"

namespace {

void BM_HairRender(benchmark::State& state) {
  follicle::bench::run_workload(state, "hair-render", {{"strands", double(state.range(0))}});
}

}  // namespace

BENCHMARK(BM_HairRender)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond)->UseRealTime();
