#pragma once
// Context: what every long-running function receives instead of globals: a logger, the thread
// budget (a TBB arena of that size) and the base random seed.
#include <tbb/task_arena.h>

#include <cstdint>
#include <memory>

namespace spdlog {
class logger;
}

namespace follicle {

class Context {
 public:
  /// threads <= 0 means "all hardware threads". The logger defaults to a quiet stderr logger.
  explicit Context(int threads = 0, uint64_t seed = 1, std::shared_ptr<spdlog::logger> log = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  int threads() const { return m_threads; }
  uint64_t seed() const { return m_seed; }
  spdlog::logger& log() const { return *m_log; }
  std::shared_ptr<spdlog::logger> logger_ptr() const { return m_log; }
  tbb::task_arena& arena() const { return *m_arena; }
  /// Whether long work inside the library (settling hair, growing grooms) may draw a progress bar
  /// (follicle::Progress, which draws only on a terminal and never in CI). Off by default: a
  /// program linking Follicle decides; the CLI switches it on unless --quiet.
  bool progress() const { return m_progress; }
  void set_progress(bool on) { m_progress = on; }

 private:
  int m_threads;
  uint64_t m_seed;
  bool m_progress = false;
  std::shared_ptr<spdlog::logger> m_log;
  std::unique_ptr<tbb::task_arena> m_arena;
};

}  // namespace follicle
