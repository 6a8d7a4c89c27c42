// Core benchmarks: deterministic reduction overhead.
#include <benchmark/benchmark.h>

#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/parallel.hpp"

static void BM_DeterministicReduce(benchmark::State& state) {
  follicle::Context ctx(int(state.range(1)));
  std::vector<double> v(std::size_t(state.range(0)), 1.0);
  for (auto _ : state) {
    double s = follicle::deterministic_reduce(
        ctx, v.size(), 4096, 0.0,
        [&](std::size_t a, std::size_t b) {
          double acc = 0;
          for (std::size_t i = a; i < b; ++i) acc += v[i];
          return acc;
        },
        [](double x, double y) { return x + y; });
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * state.range(0));
}
BENCHMARK(BM_DeterministicReduce)->Args({1 << 20, 1})->Args({1 << 20, 2});
