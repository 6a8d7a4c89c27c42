#pragma once
// Shared driver of the Google Benchmarks: one workload of `follicle bench` (the same factory and
// sizes), timed per run_once(), with its throughput as a rate counter.
#include <benchmark/benchmark.h>

#include <exception>
#include <memory>

#include "follicle/core/context.hpp"
#include "follicle/core/resources.hpp"
#include "workloads/workload.hpp"

namespace follicle::bench {

/// Runs workload `name` with `sizes` over its defaults on `threads` threads (0: all cores). A
/// workload that cannot be set up here (no GL, missing data) skips with its error.
inline void run_workload(benchmark::State& state, const char* name,
                         const workloads::Sizes& sizes = {}, int threads = 0) {
  using namespace follicle::workloads;
  // As `follicle bench` does in main(): benchmark_main owns main() here.
  follicle::keep_freed_heap_memory();
  Context ctx(threads);
  const auto all = all_workloads();
  const Workload& w = find_workload(all, name);
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

}  // namespace follicle::bench
