// follicle bench WORKLOAD... [--size K=V ...] [--threads N] [--list]
// Setup (the workload factory) is untimed; then run_once() repeats until at least
// --min-seconds have passed (at least one iteration). One JSON object per line on stdout.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/log.hpp"
#include "follicle/core/progress.hpp"
#include "workloads/workload.hpp"

namespace follicle::cli {

namespace {

workloads::Sizes parse_sizes(const std::vector<std::string>& items) {
  workloads::Sizes out;
  for (const auto& s : items) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == s.size())
      throw UsageError(fmt::format("--size expects KEY=NUMBER, got '{}'", s));
    const std::string key = s.substr(0, eq), value = s.substr(eq + 1);
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(value, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != value.size() || !std::isfinite(v))
      throw UsageError(fmt::format("--size {}: '{}' is not a number", key, value));
    out[key] = v;
  }
  return out;
}

}  // namespace

int run_bench(const GlobalOptions& g, const BenchArgs& a) {
  const auto all = workloads::all_workloads();
  if (a.list) {
    for (const auto& w : all) {
      std::string sizes;
      for (const auto& [k, v] : w.default_sizes)
        sizes += fmt::format("{}{}={}", sizes.empty() ? "" : " ", k, v);
      fmt::print("{:<18} {} [{}] ({})\n", w.name, w.description, sizes, w.throughput_unit);
    }
    return 0;
  }
  if (a.workloads.empty()) throw UsageError("bench: name a workload (see follicle bench --list)");
  if (!(a.min_seconds >= 0.0)) throw UsageError("--min-seconds must be >= 0");
  const auto user = parse_sizes(a.sizes);
  auto ctx = make_context(g);
  for (const auto& name : a.workloads) {
    const auto& w = workloads::find_workload(all, name);
    const auto sizes = workloads::resolve_sizes(w, user);
    ctx->log().info("bench {}: setup", w.name);
    auto inst = w.make(*ctx, sizes);  // untimed setup
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    long iterations = 0;
    double elapsed = 0.0;
    {
      // The bar shows the share of the minimum run time done (it appears after one second).
      const std::size_t steps = 100;
      std::size_t shown = 0;
      Progress progress("bench " + w.name, steps, !g.quiet);
      do {
        inst->run_once();
        ++iterations;
        elapsed = std::chrono::duration<double>(clock::now() - start).count();
        const auto done = a.min_seconds > 0
                              ? std::min(steps, std::size_t(elapsed / a.min_seconds * steps))
                              : steps;
        if (done > shown) {
          progress.tick(done - shown);
          shown = done;
        }
      } while (elapsed < a.min_seconds);
    }
    const double per_iter = elapsed / double(iterations);
    nlohmann::json params = nlohmann::json::object();
    for (const auto& [k, v] : sizes) params[k] = v;
    nlohmann::json line = {{"workload", w.name},
                           {"params", params},
                           {"threads", ctx->threads()},
                           {"iterations", iterations},
                           {"seconds_per_iter", per_iter},
                           {"throughput", per_iter > 0 ? inst->items_per_iter() / per_iter : 0.0},
                           {"throughput_unit", w.throughput_unit}};
    fmt::print("{}\n", line.dump());
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace follicle::cli
