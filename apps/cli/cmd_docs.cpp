// follicle docs scene-format|face-setup [--write FILE] [--check]: the generated key tables of
// docs/scene-format.md and docs/face-setup.md (hidden command for maintainers).
#include <fmt/format.h>

#include <algorithm>

#include "commands.hpp"
#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"
#include "follicle/scene/scene_docs.hpp"

namespace follicle::cli {

int run_docs(const GlobalOptions& g, const DocsArgs& a) {
  const auto topics = scene::doc_topics();
  if (std::find(topics.begin(), topics.end(), a.topic) == topics.end())
    throw UsageError(
        fmt::format("unknown docs topic '{}': expected scene-format or face-setup", a.topic));
  if (a.write.empty()) {
    for (const auto& [name, table] : scene::doc_blocks(a.topic))
      fmt::print("<!-- generated:{} -->\n{}<!-- end generated:{} -->\n\n", name, table, name);
    return 0;
  }
  const std::string before = read_file(a.write);
  if (a.check) {
    const auto stale = scene::stale_doc_blocks(a.topic, before);
    if (stale.empty()) return 0;
    std::string names;
    for (const auto& s : stale) names += (names.empty() ? "" : ", ") + s;
    follicle::fail_at(a.write, "out of date in blocks: {} (run follicle docs {} --write {})", names,
                      a.topic, a.write);
  }
  const std::string after = scene::update_doc(a.topic, before);
  if (after != before) write_file_atomically(a.write, after);
  if (!g.quiet) fmt::print("{} {}\n", a.write, after != before ? "updated" : "already up to date");
  return 0;
}

}  // namespace follicle::cli
