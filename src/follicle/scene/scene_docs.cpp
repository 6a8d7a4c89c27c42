#include "follicle/scene/scene_docs.hpp"

#include <algorithm>

#include "follicle/core/error.hpp"
#include "follicle/scene/scene.hpp"
#include "follicle/skin/skin_json.hpp"

namespace follicle::scene {

namespace {

std::string begin_marker(const std::string& name) {
  return "<!-- generated:" + name + " -->\n";
}
std::string end_marker(const std::string& name) {
  return "<!-- end generated:" + name + " -->";
}

// Finds [content_begin, content_end) of block `name`; false when absent.
bool find_block(const std::string& md, const std::string& name, std::size_t& b, std::size_t& e) {
  const auto bm = begin_marker(name);
  const auto p = md.find(bm);
  if (p == std::string::npos) return false;
  const auto q = md.find(end_marker(name), p + bm.size());
  if (q == std::string::npos) return false;
  b = p + bm.size();
  e = q;
  return true;
}

}  // namespace

namespace {

// Rows grouped into blocks by their top-level key ("top" for plain keys).
std::vector<std::pair<std::string, std::string>> grouped_blocks(const std::vector<DocRow>& rows) {
  std::vector<std::pair<std::string, std::vector<DocRow>>> groups{{"top", {}}};
  for (const auto& r : rows) {
    const auto cut = r.key.find_first_of(".[");
    if (cut == std::string::npos) {
      groups[0].second.push_back(r);
      continue;
    }
    const std::string section = r.key.substr(0, cut);
    auto it = std::find_if(groups.begin(), groups.end(),
                           [&](const auto& g) { return g.first == section; });
    if (it == groups.end()) {
      groups.emplace_back(section, std::vector<DocRow>{});
      it = groups.end() - 1;
    }
    it->second.push_back(r);
  }
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [name, g] : groups) out.emplace_back(name, doc_table(g));
  return out;
}

}  // namespace

std::vector<std::string> doc_topics() {
  return {"scene-format", "face-setup"};
}

std::vector<std::pair<std::string, std::string>> doc_blocks(const std::string& topic) {
  if (topic == "scene-format") return grouped_blocks(doc_rows<Scene>(""));
  if (topic == "face-setup") return grouped_blocks(doc_rows<skin::FaceSetup>(""));
  fail("unknown docs topic '{}': expected scene-format or face-setup", topic);
}

std::string update_doc(const std::string& topic, const std::string& markdown) {
  std::string md = markdown;
  for (const auto& [name, table] : doc_blocks(topic)) {
    std::size_t b = 0, e = 0;
    if (find_block(md, name, b, e)) {
      md.replace(b, e - b, table);
    } else {
      if (!md.empty() && md.back() != '\n') md += '\n';
      md += "\n## `" + name + "`\n\n" + begin_marker(name) + table + end_marker(name) + "\n";
    }
  }
  return md;
}

std::vector<std::string> stale_doc_blocks(const std::string& topic, const std::string& markdown) {
  std::vector<std::string> out;
  for (const auto& [name, table] : doc_blocks(topic)) {
    std::size_t b = 0, e = 0;
    if (!find_block(markdown, name, b, e) || markdown.substr(b, e - b) != table)
      out.push_back(name);
  }
  return out;
}

std::vector<std::pair<std::string, std::string>> scene_doc_blocks() {
  return doc_blocks("scene-format");
}

std::string update_scene_doc(const std::string& markdown) {
  return update_doc("scene-format", markdown);
}

std::vector<std::string> stale_scene_doc_blocks(const std::string& markdown) {
  return stale_doc_blocks("scene-format", markdown);
}

}  // namespace follicle::scene
