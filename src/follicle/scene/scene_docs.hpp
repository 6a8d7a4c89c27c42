#pragma once
// docs/scene-format.md and docs/face-setup.md tables generated from the structs' visit() lists,
// so every key is documented with its type, unit, default and range. A doc holds blocks
//   <!-- generated:camera --> ...table... <!-- end generated:camera -->
// which `follicle docs <topic> --write docs/<topic>.md` refreshes and a unit test checks.
#include <string>
#include <utility>
#include <vector>

namespace follicle::scene {

/// The generated documents: "scene-format" (docs/scene-format.md, the scene file) and
/// "face-setup" (docs/face-setup.md, the face-setup file a skin rig's `muscles` names).
std::vector<std::string> doc_topics();
/// (block name, markdown table) of a topic: "top" for the top-level keys, then one per top-level
/// section. Throws follicle::Error for an unknown topic.
std::vector<std::pair<std::string, std::string>> doc_blocks(const std::string& topic);
/// `markdown` with every generated block of `topic` replaced by the current table; blocks
/// missing from the document are appended at the end under a "## `name`" heading.
std::string update_doc(const std::string& topic, const std::string& markdown);
/// Names of blocks of `topic` that are missing or out of date in `markdown` (empty = in sync).
std::vector<std::string> stale_doc_blocks(const std::string& topic, const std::string& markdown);

/// The "scene-format" topic.
std::vector<std::pair<std::string, std::string>> scene_doc_blocks();
/// `markdown` with every generated block replaced by the current table; blocks missing from the
/// document are appended at the end under a "## `name`" heading.
std::string update_scene_doc(const std::string& markdown);
/// Names of blocks that are missing or out of date in `markdown` (empty = in sync).
std::vector<std::string> stale_scene_doc_blocks(const std::string& markdown);

}  // namespace follicle::scene
