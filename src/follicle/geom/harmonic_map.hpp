#pragma once
// Harmonic maps (Eck et al. 1995 weights) for texture-space parameterization (Bando 2002 §2.4)
// and general harmonic interpolation of per-vertex data with fixed rows (Bando 2002 §2.6.1).
//
// Spring energy E = 1/2 sum_{edges ij} k_ij |x_i - x_j|^2 with the Eck et al. harmonic spring
// constants k_ij = (cot a_ij + cot b_ij) / 2 (a, b: angles opposite edge ij). Negative constants
// (obtuse configurations) are clamped to a small positive floor so the system stays an M-matrix
// (Tutte: no fold-overs for a convex fixed boundary). Solved with Eigen SimplicialLDLT (AMD).
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::geom {

/// Minimizes the spring energy with the rows listed in `fixed_vertices` held at `fixed_values`
/// (one row per fixed vertex, any number of columns). Returns a num_vertices() x cols matrix whose
/// fixed rows equal `fixed_values`. Vertices in components without any fixed vertex get 0.
/// Throws follicle::Error on bad indices, duplicates, size mismatch or a non-finite input.
Eigen::MatrixXd harmonic_interpolate(const TriMesh& mesh, const std::vector<int>& fixed_vertices,
                                     const Eigen::MatrixXd& fixed_values);

/// Eck et al. spring constants per undirected edge, as (i, j, k_ij) with i < j, sorted.
struct SpringEdge {
  int i, j;
  double k;
};
std::vector<SpringEdge> harmonic_spring_weights(const TriMesh& mesh);

/// Reusable solver: the sparsity pattern is analysed (AMD) and factorized once for a given set
/// of fixed vertices; solve() is then two triangular solves per column.
class HarmonicSolver {
 public:
  HarmonicSolver(const TriMesh& mesh, const std::vector<int>& fixed_vertices);
  ~HarmonicSolver();
  HarmonicSolver(HarmonicSolver&&) noexcept;
  HarmonicSolver& operator=(HarmonicSolver&&) noexcept;
  /// fixed_values: fixed_vertices.size() x cols.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& fixed_values) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m;
};

/// Per-vertex texture coordinates of a mesh whose UVs are not split at seams (every position
/// vertex has one UV); empty when some vertex carries two different UVs.
std::vector<Vec2> per_vertex_uvs(const TriMesh& mesh, double tolerance = 1e-9);

/// Quality of a texture-space map (per-vertex UVs over mesh.faces).
struct UvQuality {
  int flipped = 0;             // triangles whose UV orientation is opposite to the majority
  int degenerate = 0;          // zero UV area
  double area_distortion = 0;  // area-weighted mean |log(uv area ratio / global ratio)|
  double stretch_mean = 0;     // area-weighted mean of sigma_max/sigma_min of the 3D->UV Jacobian
  double stretch_max = 0;
};
UvQuality evaluate_uv_quality(const TriMesh& mesh, const std::vector<Vec2>& vertex_uv);

/// sigma_max / sigma_min of the affine map from triangle (p0, p1, p2) to UV triangle (t0, t1, t2);
/// infinity when the UV triangle is degenerate.
double uv_stretch(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec2& t0, const Vec2& t1,
                  const Vec2& t2);

/// Ordered boundary loops (vertex indices), longest (3D length) first.
std::vector<std::vector<int>> boundary_loops(const TriMesh& mesh);

struct HarmonicMapParams {
  bool keep_own_uvs = true;      // keep the mesh's UVs when they are one-to-one
  int relax_iterations = 50;     // boundary relaxation sweeps (concave -> less concave)
  double relax_step = 0.5;       // fraction of the way to the neighbour midpoint per sweep
  bool circle_boundary = false;  // fix the outer loop on a circle instead of its projection
  bool fit_unit_square = true;   // scale/translate the result into [0,1]^2 (aspect kept)
  template <class V>
  void visit(V&& v) {
    v("keep_own_uvs", keep_own_uvs, ParamInfo{"keep one-to-one mesh UVs", ""});
    v("relax_iterations", relax_iterations, ParamInfo{"boundary relaxation sweeps", "", 0, 10000});
    v("relax_step", relax_step, ParamInfo{"relaxation step", "", 0.0, 1.0});
    v("circle_boundary", circle_boundary, ParamInfo{"map outer boundary to a circle", ""});
    v("fit_unit_square", fit_unit_square, ParamInfo{"fit into the unit square", ""});
  }
  void validate() const { validate_params(*this, "harmonic_map"); }
};

struct HarmonicMapReport {
  bool kept_own_uvs = false;
  int relaxed_vertices = 0;  // boundary vertices moved by the relaxation step
  UvQuality before;          // of the initial projection (or own UVs)
  UvQuality after;
};

/// Distortion minimization with fixed boundary (§2.4): starting from `initial_uv` (one per
/// vertex, e.g. a planar/cylindrical projection), relaxes concave outer-boundary vertices, fixes
/// the outer boundary loop and solves the harmonic map for the rest. Returns per-vertex UVs.
std::vector<Vec2> harmonic_parameterize(const TriMesh& mesh, const std::vector<Vec2>& initial_uv,
                                        const HarmonicMapParams& params,
                                        HarmonicMapReport* report = nullptr);

/// Makes `mesh` carry a one-to-one per-vertex texture map: keeps its own UVs when they are
/// one-to-one (and params.keep_own_uvs), otherwise runs harmonic_parameterize from `projection`
/// and stores the result as uvs/uv_faces (uv_faces = faces).
HarmonicMapReport make_texture_space(TriMesh& mesh, const std::vector<Vec2>& projection,
                                     const HarmonicMapParams& params);

}  // namespace follicle::geom
