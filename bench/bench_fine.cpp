// Fine-scale wrinkle benchmarks: the same workloads as `follicle bench fine-wrinkles`,
// `fine-modulation` and `hand-update`.
#include "bench_common.hpp"

namespace {

void run_fine(benchmark::State& s, const char* name, int threads) {
  follicle::bench::run_workload(s, name, {}, threads);
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
