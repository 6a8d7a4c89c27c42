#include "follicle/scene/scene_docs.hpp"

#include <algorithm>

#include "follicle/scene/scene.hpp"

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

std::vector<std::pair<std::string, std::string>> scene_doc_blocks() {
  const auto rows = doc_rows<Scene>("");
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

std::string update_scene_doc(const std::string& markdown) {
  std::string md = markdown;
  for (const auto& [name, table] : scene_doc_blocks()) {
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

std::vector<std::string> stale_scene_doc_blocks(const std::string& markdown) {
  std::vector<std::string> out;
  for (const auto& [name, table] : scene_doc_blocks()) {
    std::size_t b = 0, e = 0;
    if (!find_block(markdown, name, b, e) || markdown.substr(b, e - b) != table)
      out.push_back(name);
  }
  return out;
}

}  // namespace follicle::scene
