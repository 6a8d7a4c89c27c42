#include "follicle/skin/blendshapes.hpp"

#include <algorithm>
#include <set>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/skin/adaptive_refine_volino1999.hpp"

namespace follicle::skin {

namespace {
constexpr double kMovedEps = 1e-9;  // [m]: offsets below this are not stored
}

Blendshapes Blendshapes::from_meshes(const geom::TriMesh& neutral, std::vector<std::string> names,
                                     const std::vector<geom::TriMesh>& targets,
                                     const std::string& where) {
  if (names.size() != targets.size())
    fail("{}: {} blendshape names for {} targets", where, names.size(), targets.size());
  Blendshapes b;
  b.m_num_vertices = neutral.positions.size();
  std::set<std::string> seen;
  for (std::size_t t = 0; t < targets.size(); ++t) {
    const std::string& name = names[t];
    const geom::TriMesh& m = targets[t];
    if (name.empty()) fail("{}: blendshape {} has no name", where, t);
    if (!seen.insert(name).second) fail("{}: two blendshapes are named \"{}\"", where, name);
    if (m.positions.size() != neutral.positions.size())
      fail(
          "{}: blendshape \"{}\" has {} vertices and the mesh {}: a target must be the same mesh "
          "(vertex count and order) with the vertices moved",
          where, name, m.positions.size(), neutral.positions.size());
    if (m.faces.size() != neutral.faces.size())
      fail("{}: blendshape \"{}\" has {} triangles and the mesh {}: not the same topology", where,
           name, m.faces.size(), neutral.faces.size());
    // Same polygons: the readers cut a quad along the diagonal that suits its shape, so a target
    // may split a quad the other way; its triangles still use the vertices of the neutral's
    // triangles cut from the same polygon, which lie next to them in face order (a polygon of n
    // sides gives n - 2 consecutive triangles; kWindow covers up to the readers' 64 sides).
    constexpr std::size_t kWindow = 62;
    for (std::size_t f = 0; f < m.faces.size(); ++f) {
      if (m.faces[f] == neutral.faces[f]) continue;
      const std::size_t lo = f > kWindow ? f - kWindow : 0;
      const std::size_t hi = std::min(m.faces.size(), f + kWindow + 1);
      for (int k = 0; k < 3; ++k) {
        bool found = false;
        for (std::size_t g = lo; g < hi && !found; ++g)
          found = (neutral.faces[g].array() == m.faces[f][k]).any();
        if (!found)
          fail(
              "{}: blendshape \"{}\" differs from the mesh at triangle {} (vertices {} {} {}, "
              "the mesh's {} {} {}): not the same topology (a target must be the same mesh "
              "with the vertices moved)",
              where, name, f, m.faces[f][0], m.faces[f][1], m.faces[f][2], neutral.faces[f][0],
              neutral.faces[f][1], neutral.faces[f][2]);
      }
    }
    std::vector<std::uint32_t> idx;
    std::vector<Vec3> off;
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
      const Vec3 d = m.positions[i] - neutral.positions[i];
      if (!d.allFinite()) fail("{}: blendshape \"{}\" has a non-finite vertex {}", where, name, i);
      if (d.norm() > kMovedEps) {
        idx.push_back(std::uint32_t(i));
        off.push_back(d);
      }
    }
    b.m_names.push_back(name);
    b.m_index.push_back(std::move(idx));
    b.m_offset.push_back(std::move(off));
  }
  return b;
}

int Blendshapes::index(const std::string& name) const {
  const auto it = std::find(m_names.begin(), m_names.end(), name);
  return it == m_names.end() ? -1 : int(it - m_names.begin());
}

double Blendshapes::max_offset(std::size_t i) const {
  double m = 0;
  for (const Vec3& d : m_offset.at(i)) m = std::max(m, d.norm());
  return m;
}

void Blendshapes::accumulate(const Context& ctx, const std::vector<double>& weights,
                             std::vector<Vec3>& positions) const {
  if (weights.empty()) return;
  if (weights.size() != size())
    fail("blendshapes: {} weights for {} targets", weights.size(), size());
  if (positions.size() != m_num_vertices)
    fail("blendshapes: {} positions for a mesh of {} vertices", positions.size(), m_num_vertices);
  // Target after target (each target's vertices are distinct, so one target runs in parallel):
  // the sum has the same order, and value, for any thread count.
  for (std::size_t t = 0; t < size(); ++t) {
    const double w = weights[t];
    if (w == 0.0) continue;
    const auto& idx = m_index[t];
    const auto& off = m_offset[t];
    parallel_for(
        ctx, 0, idx.size(), [&](std::size_t k) { positions[idx[k]] += w * off[k]; }, 4096);
  }
}

Blendshapes Blendshapes::refined(const RefinedMesh& refined) const {
  if (std::size_t(refined.base_vertices) != m_num_vertices)
    fail("blendshapes: refined mesh has {} base vertices, the targets {}", refined.base_vertices,
         m_num_vertices);
  Blendshapes b;
  b.m_names = m_names;
  b.m_num_vertices = refined.mesh.positions.size();
  for (std::size_t t = 0; t < size(); ++t) {
    std::vector<Vec3> dense(m_num_vertices, Vec3::Zero());
    for (std::size_t k = 0; k < m_index[t].size(); ++k) dense[m_index[t][k]] = m_offset[t][k];
    const auto all = refined.propagate(dense);
    std::vector<std::uint32_t> idx;
    std::vector<Vec3> off;
    for (std::size_t i = 0; i < all.size(); ++i)
      if (all[i].norm() > kMovedEps) {
        idx.push_back(std::uint32_t(i));
        off.push_back(all[i]);
      }
    b.m_index.push_back(std::move(idx));
    b.m_offset.push_back(std::move(off));
  }
  return b;
}

}  // namespace follicle::skin
