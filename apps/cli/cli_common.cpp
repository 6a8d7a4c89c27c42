#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "commands.hpp"

namespace follicle::cli {

std::unique_ptr<Context> make_context(const GlobalOptions& g) {
  auto log = std::make_shared<spdlog::logger>(
      "follicle", std::make_shared<spdlog::sinks::stderr_color_sink_mt>());
  log->set_pattern("follicle: %l: %v");
  log->set_level(g.quiet ? spdlog::level::err
                         : (g.verbose ? spdlog::level::debug : spdlog::level::warn));
  return std::make_unique<Context>(g.threads, g.seed, log);
}

}  // namespace follicle::cli
