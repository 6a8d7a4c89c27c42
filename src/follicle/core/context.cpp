#include "follicle/core/context.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>

namespace follicle {

Context::Context(int threads, uint64_t seed, std::shared_ptr<spdlog::logger> log)
    : m_threads(threads > 0 ? threads : tbb::info::default_concurrency()),
      m_seed(seed),
      m_log(std::move(log)) {
  if (!m_log) {
    // A private (unregistered) logger: no global registry is touched.
    m_log = std::make_shared<spdlog::logger>(
        "follicle", std::make_shared<spdlog::sinks::stderr_color_sink_mt>());
    m_log->set_level(spdlog::level::warn);
  }
  m_arena = std::make_unique<tbb::task_arena>(m_threads);
}

Context::~Context() = default;

}  // namespace follicle
