// follicle docs scene-format [--write FILE] [--check]: the generated key tables of
// docs/scene-format.md (hidden command for maintainers).
#include <fmt/format.h>

#include "commands.hpp"
#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"
#include "follicle/scene/scene_docs.hpp"

namespace follicle::cli {

int run_docs(const GlobalOptions& g, const DocsArgs& a) {
  if (a.topic != "scene-format")
    throw UsageError(fmt::format("unknown docs topic '{}': expected scene-format", a.topic));
  if (a.write.empty()) {
    for (const auto& [name, table] : scene::scene_doc_blocks())
      fmt::print("<!-- generated:{} -->\n{}<!-- end generated:{} -->\n\n", name, table, name);
    return 0;
  }
  const std::string before = read_file(a.write);
  if (a.check) {
    const auto stale = scene::stale_scene_doc_blocks(before);
    if (stale.empty()) return 0;
    std::string names;
    for (const auto& s : stale) names += (names.empty() ? "" : ", ") + s;
    follicle::fail_at(a.write,
                      "out of date in blocks: {} (run follicle docs scene-format --write {})",
                      names, a.write);
  }
  const std::string after = scene::update_scene_doc(before);
  if (after != before) write_file_atomically(a.write, after);
  if (!g.quiet) fmt::print("{} {}\n", a.write, after != before ? "updated" : "already up to date");
  return 0;
}

}  // namespace follicle::cli
