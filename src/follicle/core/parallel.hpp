#pragma once
// Data-parallel loops on the Context's TBB arena. Reductions are deterministic: the range is cut
// into chunks whose boundaries depend only on (n, grain), partial results are combined in chunk
// order, so any thread count gives bit-identical sums.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cstddef>
#include <vector>

#include "follicle/core/context.hpp"

namespace follicle {

/// Calls f(i) for i in [begin, end). f must only write state owned by index i.
template <class F>
void parallel_for(const Context& ctx, std::size_t begin, std::size_t end, F&& f,
                  std::size_t grain = 256) {
  if (end <= begin) return;
  if (ctx.threads() == 1 || end - begin <= grain) {
    for (std::size_t i = begin; i < end; ++i) f(i);
    return;
  }
  ctx.arena().execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, grain),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
                      });
  });
}

/// Calls f(chunk_begin, chunk_end) over fixed-size chunks (for loops that want a per-chunk
/// scratch buffer).
template <class F>
void parallel_chunks(const Context& ctx, std::size_t n, std::size_t chunk, F&& f) {
  if (n == 0) return;
  if (chunk == 0) chunk = 1;
  const std::size_t nchunks = (n + chunk - 1) / chunk;
  parallel_for(
      ctx, 0, nchunks, [&](std::size_t c) { f(c * chunk, std::min(n, (c + 1) * chunk)); }, 1);
}

/// Deterministic reduction: map(i0, i1) -> T over fixed chunks of `grain`, then
/// combine(acc, part) in chunk order starting from `init`.
template <class T, class Map, class Combine>
T deterministic_reduce(const Context& ctx, std::size_t n, std::size_t grain, T init, Map&& map,
                       Combine&& combine) {
  if (n == 0) return init;
  if (grain == 0) grain = 1;
  const std::size_t nchunks = (n + grain - 1) / grain;
  std::vector<T> parts(nchunks, init);
  parallel_for(
      ctx, 0, nchunks,
      [&](std::size_t c) { parts[c] = map(c * grain, std::min(n, (c + 1) * grain)); }, 1);
  T acc = init;
  for (auto& p : parts) acc = combine(acc, p);
  return acc;
}

}  // namespace follicle
