// follicle validate SCENE...: strict parse + every asset loaded.
#include <fmt/format.h>

#include "commands.hpp"
#include "follicle/scene/session.hpp"

namespace follicle::cli {

int run_validate(const GlobalOptions& g, const ValidateArgs& a) {
  auto ctx = make_context(g);
  for (const auto& path : a.scenes) {
    auto session = scene::Session::load(path, *ctx);
    session.load_all_assets();
    if (!g.quiet) fmt::print("ok: {}\n", path);
  }
  return 0;
}

}  // namespace follicle::cli
