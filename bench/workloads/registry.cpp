#include <fmt/format.h>

#include "follicle/core/error.hpp"
#include "follicle/core/params.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {

// Each workload file defines one of these; the list below is the single registry (no static
// registration, no globals).
void add_geom_workloads(std::vector<Workload>& out);
void add_render_workloads(std::vector<Workload>& out);
void add_fine_workloads(std::vector<Workload>& out);
void add_anjyo_workloads(std::vector<Workload>& out);
void add_skin_workloads(std::vector<Workload>& out);
void add_splat_workloads(std::vector<Workload>& out);
void add_lcp_workloads(std::vector<Workload>& out);
void add_hair_render_workloads(std::vector<Workload>& out);
void add_face_render_workloads(std::vector<Workload>& out);
void add_daldegan_workloads(std::vector<Workload>& out);
void add_viewer_workloads(std::vector<Workload>& out);

std::vector<Workload> all_workloads() {
  std::vector<Workload> out;
  add_geom_workloads(out);
  add_render_workloads(out);
  add_fine_workloads(out);
  add_anjyo_workloads(out);
  add_skin_workloads(out);
  add_splat_workloads(out);
  add_lcp_workloads(out);
  add_hair_render_workloads(out);
  add_face_render_workloads(out);
  add_daldegan_workloads(out);
  add_viewer_workloads(out);
  return out;
}

const Workload& find_workload(const std::vector<Workload>& all, const std::string& name) {
  std::vector<std::string> names;
  for (const auto& w : all) {
    if (w.name == name) return w;
    names.push_back(w.name);
  }
  std::string hint = did_you_mean(name, names);
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  fail("unknown workload '{}'{}; available: {}", name,
       hint.empty() ? "" : fmt::format(" (did you mean '{}'?)", hint), list);
}

Sizes resolve_sizes(const Workload& w, const Sizes& user) {
  Sizes out = w.default_sizes;
  for (const auto& [k, v] : user) {
    auto it = out.find(k);
    if (it == out.end()) {
      std::string keys;
      for (const auto& [dk, dv] : w.default_sizes) keys += (keys.empty() ? "" : ", ") + dk;
      fail("workload '{}' has no size '{}'; accepted: {}", w.name, k, keys.empty() ? "none" : keys);
    }
    it->second = v;
  }
  return out;
}

}  // namespace follicle::workloads
