#pragma once
// Texture-space mapping of a body-part mesh without usable texture coordinates (Bando 2002 §2.4,
// thesis p. 10): "We use planar or cylindrical projection depending on the shape of the body part.
// Cylindrical projection may produce a seam ... If distortion of the current projected mesh is not
// negligible, we fix the boundary vertices of the mesh, and smooth the internal vertices by
// minimizing the total energy of springs placed along the edges" (Eck et al. harmonic weights,
// boundary made less concave first).
//
// The whole pipeline for a scan: every connected part (head, eyeballs, teeth) becomes its own
// chart; a chart is projected (planar for a face mask, cylindrical about the up axis for a head
// that wraps around, with the seam cut at the back), the cut chart is a disk whose outer boundary
// is fixed (relaxed toward convex as in the paper) and whose inside is the harmonic map. Holes
// (eyes, mouth) are closed by virtual fans while solving so that the solve is a Tutte embedding;
// when the relaxed boundary still leaves folded triangles, the chart's boundary is placed on a
// circle by arc length (Eck/Floater: a convex boundary and positive weights cannot fold). Charts
// are scaled to one texel density (metres per texture unit) and packed into [0,1]^2, each turned
// so that `up` reads upwards in v.
// Measured: on whole heads (the bundled scan, Sintel, ICT) the relaxed cylindrical boundary still
// folds near the crown, so their head chart takes the circle boundary (conformal, fold-free, but
// the face gets a smaller share of the texture than a cylinder would give it).
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/harmonic_map.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::geom {

enum class MappingMethod { Auto, Uv, Planar, Cylindrical };
constexpr std::array<std::pair<MappingMethod, const char*>, 4> follicle_enum_names(MappingMethod) {
  return {{{MappingMethod::Auto, "auto"},
           {MappingMethod::Uv, "uv"},
           {MappingMethod::Planar, "planar"},
           {MappingMethod::Cylindrical, "cylindrical"}}};
}
const char* to_string(MappingMethod m);

struct TextureMappingParams {
  /// auto: the mesh's own UVs when it has them, otherwise per part cylindrical when the part
  /// wraps around the up axis (a head), planar when it does not (a face mask).
  MappingMethod method = MappingMethod::Auto;
  bool harmonic = true;        // §2.4 distortion minimization (false: the projection alone)
  Vec3 up = Vec3::UnitY();     // mesh frame: cylinder axis / planar v direction
  Vec3 front = Vec3::UnitZ();  // mesh frame: the face's direction (cylinder seam opposite)
  int relax_iterations = 50;   // boundary relaxation sweeps (§2.4 "less concave")
  double relax_step = 0.5;
  bool circle_boundary = false;  // place every chart's boundary on a circle at once
  template <class V>
  void visit(V&& v) {
    v("method", method,
      ParamInfo{"auto (the mesh's UVs, else planar or cylindrical per part), uv, planar, "
                "cylindrical"});
    v("harmonic", harmonic,
      ParamInfo{"minimize the projection's distortion with a harmonic map (Bando 2002 §2.4)"});
    v("up", up,
      ParamInfo{"up direction in the mesh's frame (cylinder axis); in a scene, left at its "
                "default it is the mesh asset's up",
                "", -1e3, 1e3});
    v("front", front,
      ParamInfo{"direction the face looks, mesh frame (the cylinder's seam is behind); in a "
                "scene, left at its default it is the mesh asset's front",
                "", -1e3, 1e3});
    v("relax_iterations", relax_iterations,
      ParamInfo{"boundary relaxation sweeps before the harmonic solve", "", 0, 10000});
    v("relax_step", relax_step, ParamInfo{"relaxation step", "", 0.0, 1.0});
    v("circle_boundary", circle_boundary,
      ParamInfo{"place each chart's boundary on a circle (otherwise only when the relaxed "
                "projection folds)"});
  }
  void validate() const;
};

struct TextureMappingReport {
  MappingMethod method = MappingMethod::Uv;  // what was used (planar/cylindrical: of the largest)
  int charts = 0;                            // connected parts mapped
  int planar_charts = 0, cylindrical_charts = 0;
  int circle_charts = 0;       // charts whose boundary went on a circle (the fold fallback)
  int flipped = 0;             // UV triangles with opposite orientation (0 for a harmonic map)
  int degenerate = 0;          // zero-area UV triangles
  double stretch_mean = 0;     // area-weighted mean singular-value ratio of the 3D -> UV map
  double stretched_area = 0;   // share of the 3D area stretched more than 4:1
  double metres_per_unit = 0;  // texture scale of the packed charts
  std::string summary() const;
};

/// The mesh with a one-to-one texture space in uvs/uv_faces (positions, faces, normals and name
/// unchanged; the UVs are split where charts are cut). Method uv returns the mesh as it is and
/// fails when it has no UVs. Throws follicle::Error for an empty mesh or bad parameters.
TriMesh map_to_texture_space(const TriMesh& mesh, const TextureMappingParams& params,
                             TextureMappingReport* report = nullptr);

/// Signed-area check of a mesh's own UV layout over its faces: triangles folded against the
/// majority orientation of their connected part, and zero-area ones.
struct UvFolds {
  int flipped = 0;
  int degenerate = 0;
};
UvFolds count_uv_folds(const TriMesh& mesh);

}  // namespace follicle::geom
