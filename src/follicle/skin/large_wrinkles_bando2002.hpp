#pragma once
// Large-scale (expressive) wrinkles of Bando et al. 2002 (thesis §2.5.1, §2.5.3): each wrinkle
// is a cubic Bezier furrow in texture space with depth d, width w and rest amplitude ratio r.
// Vertices near the furrow are displaced along their normals by M(s) S(l), with l the
// perpendicular texture-space distance (converted to metres by the local texture scale) and s
// the shrinkage (2.3) of the skin perpendicular to the furrow, measured on the animated mesh.
// The paper's face has one texture chart; real heads lay several UV islands over each other, so
// each curve is given to the island holding most of it and touches only that island's skin.
#include <array>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/skin/wrinkle_shape_bando2002.hpp"

namespace follicle::skin {

struct LargeWrinkle {
  std::string name;
  std::array<Vec2, 4> control{Vec2(0.4, 0.5), Vec2(0.45, 0.5), Vec2(0.55, 0.5),
                              Vec2(0.6, 0.5)};  // texture space
  double depth = 0.003;                         // d [m]
  double width = 0.003;                         // w [m]
  double r = 0.0;                               // (2.4) rest amplitude ratio in [0, 1]
  double end_taper = 0.15;  // fraction of the curve parameter over which depth fades at each end
  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"wrinkle name", ""});
    v("p0", control[0], ParamInfo{"Bezier control point 0 (texture space)", "", -10.0, 10.0});
    v("p1", control[1], ParamInfo{"Bezier control point 1", "", -10.0, 10.0});
    v("p2", control[2], ParamInfo{"Bezier control point 2", "", -10.0, 10.0});
    v("p3", control[3], ParamInfo{"Bezier control point 3", "", -10.0, 10.0});
    v("depth", depth, ParamInfo{"furrow depth d", "m", 0.0, 0.1});
    v("width", width, ParamInfo{"furrow width w", "m", 1e-6, 0.1});
    v("r", r, ParamInfo{"rest amplitude ratio r", "", 0.0, 1.0});
    v("end_taper", end_taper, ParamInfo{"end taper fraction", "", 0.0, 0.5});
  }
  void validate() const { validate_params(*this, "wrinkle '" + name + "'"); }
  static constexpr const char* kRequired[] = {"p0", "p1", "p2", "p3"};
};

/// Texture-space view of a mesh with the adjacency the wrinkle code needs.
struct TextureSpaceMesh {
  std::vector<Vec2> vertex_uv;               // one UV per position vertex (first occurrence)
  std::vector<std::array<Vec2, 3>> face_uv;  // per face corner (consistent inside a face)
  std::vector<std::size_t> vf_offsets;       // vertex -> incident faces (CSR)
  std::vector<int> vf_faces;
  std::vector<char> vf_corner;  // corner index of the vertex in that face
  static TextureSpaceMesh build(const geom::TriMesh& mesh);
};

/// Precomputed data of one wrinkle on one rest mesh; rebuilt alone when its parameters change.
struct WrinkleInfluence {
  struct Side {
    int j2 = -1, j3 = -1;         // the other two vertices of the triangle in direction +-d_p
    double a = 0, b = 0;          // d_p = a e2 + b e3 in texture space
    double rest2 = 0, rest3 = 0;  // rest 3D lengths of edges v1v2, v1v3
    double rest_span = 0;         // |a X2 + b X3| in the rest 3D triangle
  };
  struct Entry {
    int vertex = -1;
    double shape = 0;  // S(l) * taper [m]
    double l = 0;      // perpendicular distance [m]
    std::array<Side, 2> side;
    int nsides = 0;
  };
  std::vector<Entry> entries;
  double texture_scale = 0;  // metres per texture unit around this wrinkle
  int island = -1;  // UV island the curve lies on (geom::uv_islands numbering); -1: on none
};

/// How L' in (2.3) is measured for the triangle in direction d_p.
enum class ShrinkageMethod {
  /// Paper's construction: edges v1v2, v1v3 scaled by their 3D length ratios t2, t3 inside the
  /// texture space, L' where the ray d_p meets the scaled edge (exact only when the two edges
  /// scale alike; underestimates uniaxial shrinkage on refined/irregular triangulations).
  edge_scaling,
  /// Same L'/L taken from the triangle's affine deformation: the segment a e2 + b e3 along d_p
  /// maps to a X2 + b X3 in 3D, rest and current; exact for any triangulation and identical to
  /// edge_scaling when both edges scale alike. Default.
  deformation,
};

/// The wrinkle layer over a (refined) rest mesh.
class WrinkleLayer {
 public:
  WrinkleLayer(const geom::TriMesh& rest, std::vector<LargeWrinkle> wrinkles,
               double cutoff_widths = 10.0, ShrinkageMethod method = ShrinkageMethod::deformation);
  std::size_t num_wrinkles() const { return m_wrinkles.size(); }
  const LargeWrinkle& wrinkle(std::size_t i) const { return m_wrinkles[i]; }
  const std::vector<LargeWrinkle>& wrinkles() const { return m_wrinkles; }
  /// Replaces one wrinkle; only its influence (its affected vertices) is recomputed.
  /// Returns the number of vertices recomputed.
  std::size_t set_wrinkle(std::size_t i, const LargeWrinkle& w);
  const WrinkleInfluence& influence(std::size_t i) const { return m_infl[i]; }
  const TextureSpaceMesh& texture_mesh() const { return m_tex; }

  /// (2.3) shrinkage of every entry of wrinkle i on the deformed positions (average of sides).
  void shrinkage(const Context& ctx, std::size_t i, const std::vector<Vec3>& deformed,
                 std::vector<double>& s) const;
  /// Per-vertex scalar height h_v = sum_wrinkles M(s) S(l) (2.1)(2.4) on the deformed positions.
  /// `height` is resized and overwritten.
  void heights(const Context& ctx, const std::vector<Vec3>& deformed,
               std::vector<double>& height) const;
  /// Rest-state heights (s = 0, i.e. M = r), e.g. for the aged face.
  void rest_heights(std::vector<double>& height) const;

 private:
  void build(std::size_t i);
  int curve_island(const BezierDistance& bd) const;
  void build_vertex_index();
  double entry_shrinkage(const WrinkleInfluence::Entry& e, const std::vector<Vec3>& p) const;
  geom::TriMesh m_rest;
  // Vertex -> (wrinkle, entry) lists over the affected vertices, in wrinkle order, so heights()
  // is one parallel pass that sums each vertex's wrinkles in a fixed order (deterministic).
  std::vector<int> m_vtx;
  std::vector<std::size_t> m_vtx_offsets;
  std::vector<std::pair<int, int>> m_vtx_refs;
  TextureSpaceMesh m_tex;
  std::vector<LargeWrinkle> m_wrinkles;
  std::vector<WrinkleInfluence> m_infl;
  double m_cutoff;
  ShrinkageMethod m_method;
  double m_global_scale = 1;
  std::vector<int> m_face_island;  // UV island of every rest face
};

/// Metres per texture unit over a set of faces: sqrt(sum A_3d / sum A_uv).
double texture_scale(const geom::TriMesh& mesh, const TextureSpaceMesh& tex,
                     const std::vector<int>& faces);

}  // namespace follicle::skin
