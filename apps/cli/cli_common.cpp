#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cctype>

#include "commands.hpp"

namespace follicle::cli {

std::unique_ptr<Context> make_context(const GlobalOptions& g) {
  auto log = std::make_shared<spdlog::logger>(
      "follicle", std::make_shared<spdlog::sinks::stderr_color_sink_mt>());
  log->set_pattern("follicle: %l: %v");
  log->set_level(g.quiet ? spdlog::level::err
                         : (g.verbose ? spdlog::level::debug : spdlog::level::warn));
  auto ctx = std::make_unique<Context>(g.threads, g.seed, log);
  ctx->set_progress(!g.quiet);
  return ctx;
}

void parse_frames(const std::string& s, int& first, int& last) {
  const auto bad = [&] {
    return UsageError(
        fmt::format("--frames expects A-B (e.g. 0-47) or one frame number, got '{}'", s));
  };
  if (s.empty()) return;
  const auto dash = s.find('-');
  auto num = [&](const std::string& t) {
    if (t.empty() || t.size() > 9) throw bad();
    for (char c : t)
      if (!std::isdigit(static_cast<unsigned char>(c))) throw bad();
    return std::stoi(t);
  };
  if (dash == std::string::npos) {
    first = last = num(s);
  } else {
    first = num(s.substr(0, dash));
    last = num(s.substr(dash + 1));
  }
  if (last < first)
    throw UsageError(fmt::format("--frames {}: the last frame is before the first", s));
}

}  // namespace follicle::cli
