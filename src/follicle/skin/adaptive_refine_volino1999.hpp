#pragma once
// Adaptive refinement around large-scale wrinkles (Bando 2002 §2.4/§2.5.1 after Volino and
// Thalmann 1999): edges near a wrinkle furrow that are longer than a target length are split at
// their midpoints, for a few levels. Marking is per edge, so both triangles sharing an edge split
// it at the same new vertex: the result has no T-junctions (crack-free). New vertices carry
// texture coordinates (split per UV chart) and their two parents, so any per-vertex quantity
// (weights, thickness) can be carried over by interpolation. With `smooth` (default) a new vertex
// is placed at the midpoint of the cubic PN-triangle edge through the two end points and their
// vertex normals, (a + b)/2 - ((b - a).n_a n_a + (a - b).n_b n_b)/8, so a refined region stays
// as smooth as the surface it approximates instead of showing the flat facets of the input
// mesh under smooth shading.
#include <array>
#include <vector>

#include "follicle/core/params.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/skin/large_wrinkles_bando2002.hpp"

namespace follicle::skin {

struct RefineParams {
  int max_levels = 3;          // split passes
  double edge_factor = 0.5;    // target edge length = edge_factor * wrinkle width
  double region_widths = 6.0;  // refine within this many widths of the furrow
  bool smooth = true;  // new vertices on the curved (PN-triangle) edge, not the flat midpoint
  double max_triangles = 4e6;  // budget: a level that would exceed it fails before splitting
  template <class V>
  void visit(V&& v) {
    v("smooth", smooth,
      ParamInfo{"place new vertices on the smooth surface through the normals", ""});
    v("max_levels", max_levels, ParamInfo{"refinement passes", "", 0, 8});
    v("edge_factor", edge_factor, ParamInfo{"target edge length / wrinkle width", "", 0.05, 10.0});
    v("region_widths", region_widths,
      ParamInfo{"refined band half-width in wrinkle widths", "", 0.0, 50.0});
    v("max_triangles", max_triangles,
      ParamInfo{"budget of triangles after refinement (refused before a level exceeds it)", "", 1e3,
                1e8});
  }
  void validate() const { validate_params(*this, "refine"); }
};

struct RefinedMesh {
  geom::TriMesh mesh;
  int base_vertices = 0;
  std::vector<std::array<int, 2>> parents;  // for vertex base_vertices + k: its two parents
  std::vector<int> base_face;               // refined face -> face of the input mesh

  /// Carries a per-vertex attribute of the base mesh to the refined mesh (parent average, in
  /// creation order, so a midpoint of midpoints is interpolated correctly).
  template <class T>
  std::vector<T> propagate(const std::vector<T>& base) const {
    std::vector<T> out(base);
    out.reserve(mesh.positions.size());
    for (const auto& p : parents)
      out.push_back(T(0.5 * (out[std::size_t(p[0])] + out[std::size_t(p[1])])));
    return out;
  }
};

/// Refines `base` (which must have UVs) around the wrinkles. With no wrinkles or max_levels = 0
/// the mesh is returned unchanged.
RefinedMesh refine_around_wrinkles(const geom::TriMesh& base,
                                   const std::vector<LargeWrinkle>& wrinkles,
                                   const RefineParams& params);

/// Number of T-junctions: mesh vertices lying strictly inside an edge of a face that does not use
/// them (checked on edges that have only one incident face). 0 for a crack-free refinement.
int count_t_junctions(const geom::TriMesh& mesh, double tolerance = 1e-9);

}  // namespace follicle::skin
