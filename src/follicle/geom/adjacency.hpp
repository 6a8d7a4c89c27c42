#pragma once
// Mesh connectivity in compressed (CSR) form: vertex -> incident faces, vertex -> one-ring
// vertices, face -> edge-adjacent faces, boundary edges and boundary loops.
#include <cstdint>
#include <span>
#include <vector>

#include "follicle/geom/trimesh.hpp"

namespace follicle::geom {

struct MeshAdjacency {
  // vertex v's incident faces: vf_index[vf_offsets[v] .. vf_offsets[v+1]), ascending face order.
  std::vector<uint32_t> vf_offsets, vf_index;
  // vertex v's one-ring neighbours: vv_index[vv_offsets[v] .. vv_offsets[v+1]), ascending.
  std::vector<uint32_t> vv_offsets, vv_index;
  // face_neighbours[f][e] = the face across edge e of f, where edge e joins corner e and corner
  // (e+1)%3; -1 on a boundary edge or a non-manifold edge (shared by more than two faces).
  std::vector<Vec3i> face_neighbours;
  // Directed boundary edges (a, b) as they appear in their single face, sorted.
  std::vector<std::pair<int, int>> boundary_edges;
  // Closed boundary loops, each a vertex sequence following the face orientation.
  std::vector<std::vector<int>> boundary_loops;
  std::size_t nonmanifold_edges = 0;  // edges shared by more than two faces

  std::span<const uint32_t> vertex_faces(std::size_t v) const {
    return {vf_index.data() + vf_offsets[v], vf_offsets[v + 1] - vf_offsets[v]};
  }
  std::span<const uint32_t> vertex_neighbours(std::size_t v) const {
    return {vv_index.data() + vv_offsets[v], vv_offsets[v + 1] - vv_offsets[v]};
  }
  bool is_boundary_vertex(std::size_t v) const;
  std::vector<uint8_t> boundary_vertex_mask() const;
};

/// Builds all adjacency tables. O(F log F). Deterministic.
MeshAdjacency build_adjacency(const TriMesh& mesh);

}  // namespace follicle::geom
