#pragma once
// docs/scene-format.md tables generated from the scene structs' visit() lists, so every key is
// documented with its type, unit, default and range. The doc holds blocks
//   <!-- generated:camera --> ...table... <!-- end generated:camera -->
// which `follicle docs scene-format --write docs/scene-format.md` refreshes and a unit test checks.
#include <string>
#include <utility>
#include <vector>

namespace follicle::scene {

/// (block name, markdown table): "top" for the top-level keys, then one per top-level section.
std::vector<std::pair<std::string, std::string>> scene_doc_blocks();
/// `markdown` with every generated block replaced by the current table; blocks missing from the
/// document are appended at the end under a "## `name`" heading.
std::string update_scene_doc(const std::string& markdown);
/// Names of blocks that are missing or out of date in `markdown` (empty = in sync).
std::vector<std::string> stale_scene_doc_blocks(const std::string& markdown);

}  // namespace follicle::scene
