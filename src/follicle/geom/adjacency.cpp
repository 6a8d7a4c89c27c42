#include "follicle/geom/adjacency.hpp"

#include <algorithm>
#include <map>

namespace follicle::geom {

bool MeshAdjacency::is_boundary_vertex(std::size_t v) const {
  for (const auto& e : boundary_edges)
    if (std::size_t(e.first) == v || std::size_t(e.second) == v) return true;
  return false;
}

std::vector<uint8_t> MeshAdjacency::boundary_vertex_mask() const {
  std::vector<uint8_t> mask(vf_offsets.empty() ? 0 : vf_offsets.size() - 1, 0);
  for (const auto& e : boundary_edges) mask[std::size_t(e.first)] = mask[std::size_t(e.second)] = 1;
  return mask;
}

MeshAdjacency build_adjacency(const TriMesh& mesh) {
  MeshAdjacency a;
  const std::size_t nv = mesh.num_vertices(), nf = mesh.num_faces();
  // vertex -> faces (counting sort keeps faces ascending)
  a.vf_offsets.assign(nv + 1, 0);
  for (const Vec3i& f : mesh.faces)
    for (int k = 0; k < 3; ++k) ++a.vf_offsets[std::size_t(f[k]) + 1];
  for (std::size_t v = 0; v < nv; ++v) a.vf_offsets[v + 1] += a.vf_offsets[v];
  a.vf_index.resize(a.vf_offsets[nv]);
  {
    std::vector<uint32_t> fill(a.vf_offsets.begin(), a.vf_offsets.end() - 1);
    for (std::size_t fi = 0; fi < nf; ++fi)
      for (int k = 0; k < 3; ++k) {
        const auto v = std::size_t(mesh.faces[fi][k]);
        // a degenerate face listing v twice is recorded once
        if (fill[v] > a.vf_offsets[v] && a.vf_index[fill[v] - 1] == fi) continue;
        a.vf_index[fill[v]++] = uint32_t(fi);
      }
    // compact away the slots skipped for degenerate faces
    std::vector<uint32_t> offs(nv + 1, 0), idx;
    idx.reserve(a.vf_index.size());
    for (std::size_t v = 0; v < nv; ++v) {
      for (uint32_t i = a.vf_offsets[v]; i < fill[v]; ++i) idx.push_back(a.vf_index[i]);
      offs[v + 1] = uint32_t(idx.size());
    }
    a.vf_offsets.swap(offs);
    a.vf_index.swap(idx);
  }
  // vertex -> vertices
  a.vv_offsets.assign(nv + 1, 0);
  std::vector<uint32_t> ring;
  for (std::size_t v = 0; v < nv; ++v) {
    ring.clear();
    for (uint32_t fi : a.vertex_faces(v))
      for (int k = 0; k < 3; ++k) {
        const int w = mesh.faces[fi][k];
        if (std::size_t(w) != v) ring.push_back(uint32_t(w));
      }
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
    a.vv_index.insert(a.vv_index.end(), ring.begin(), ring.end());
    a.vv_offsets[v + 1] = uint32_t(a.vv_index.size());
  }
  // undirected edges: (min, max, face, edge slot), sorted
  struct HalfEdge {
    int lo, hi;
    uint32_t face;
    int slot;
  };
  std::vector<HalfEdge> he;
  he.reserve(3 * nf);
  for (std::size_t fi = 0; fi < nf; ++fi)
    for (int e = 0; e < 3; ++e) {
      const int x = mesh.faces[fi][e], y = mesh.faces[fi][(e + 1) % 3];
      if (x == y) continue;
      he.push_back({std::min(x, y), std::max(x, y), uint32_t(fi), e});
    }
  std::sort(he.begin(), he.end(), [](const HalfEdge& p, const HalfEdge& q) {
    return std::tie(p.lo, p.hi, p.face, p.slot) < std::tie(q.lo, q.hi, q.face, q.slot);
  });
  a.face_neighbours.assign(nf, Vec3i(-1, -1, -1));
  for (std::size_t i = 0; i < he.size();) {
    std::size_t j = i;
    while (j < he.size() && he[j].lo == he[i].lo && he[j].hi == he[i].hi) ++j;
    const std::size_t n = j - i;
    if (n == 1) {
      const auto& h = he[i];
      a.boundary_edges.emplace_back(mesh.faces[h.face][h.slot],
                                    mesh.faces[h.face][(h.slot + 1) % 3]);
    } else if (n == 2) {
      a.face_neighbours[he[i].face][he[i].slot] = int(he[i + 1].face);
      a.face_neighbours[he[i + 1].face][he[i + 1].slot] = int(he[i].face);
    } else {
      ++a.nonmanifold_edges;
    }
    i = j;
  }
  std::sort(a.boundary_edges.begin(), a.boundary_edges.end());
  // boundary loops: follow directed boundary edges a->b; start from the smallest unused edge
  std::multimap<int, std::size_t> from;  // start vertex -> edge index
  for (std::size_t i = 0; i < a.boundary_edges.size(); ++i)
    from.emplace(a.boundary_edges[i].first, i);
  std::vector<uint8_t> used(a.boundary_edges.size(), 0);
  for (std::size_t s = 0; s < a.boundary_edges.size(); ++s) {
    if (used[s]) continue;
    std::vector<int> loop;
    std::size_t e = s;
    while (true) {
      used[e] = 1;
      loop.push_back(a.boundary_edges[e].first);
      const int next = a.boundary_edges[e].second;
      if (next == a.boundary_edges[s].first) break;
      auto [lo, hi] = from.equal_range(next);
      std::size_t found = a.boundary_edges.size();
      for (auto it = lo; it != hi; ++it)
        if (!used[it->second]) {
          found = it->second;
          break;
        }
      if (found == a.boundary_edges.size()) break;  // open chain (non-manifold): stop
      e = found;
    }
    a.boundary_loops.push_back(std::move(loop));
  }
  return a;
}

}  // namespace follicle::geom
