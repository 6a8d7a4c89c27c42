#pragma once
// FaceRig: the whole per-frame skin update of Bando 2002 §2.5 on a (refined) face mesh:
//   Waters muscles + jaw (+ blendshape targets) -> subcutaneous tissue (h0/e - h0 along normals) ->
//   large-scale wrinkles M(s) S(l) along normals, with s measured on the animated surface.
// Construction precomputes everything (refinement, muscle influence lists, wrinkle stencils);
// update() is a handful of parallel sparse passes (deterministic for any thread count).
#include <memory>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/image/image.hpp"
#include "follicle/skin/adaptive_refine_volino1999.hpp"
#include "follicle/skin/blendshapes.hpp"
#include "follicle/skin/large_wrinkles_bando2002.hpp"
#include "follicle/skin/muscles_waters1987.hpp"
#include "follicle/skin/tissue_bando2002.hpp"

namespace follicle::skin {

struct FaceRigParams {
  TissueParams tissue;
  RefineParams refine;
  bool wrinkles_enabled = true;
  double wrinkle_cutoff_widths = 10.0;  // S(l) is cut at l = this * w (|S| < 5e-4 d there)
  template <class V>
  void visit(V&& v) {
    v("tissue", tissue, ParamInfo{"subcutaneous tissue", ""});
    v("refine", refine, ParamInfo{"adaptive refinement", ""});
    v("wrinkles_enabled", wrinkles_enabled, ParamInfo{"apply large-scale wrinkles", ""});
    v("wrinkle_cutoff_widths", wrinkle_cutoff_widths,
      ParamInfo{"shape function cut-off in widths", "", 4.0, 50.0});
  }
  void validate() const { validate_params(*this, "face_rig"); }
};

/// Output of one update (also holds scratch buffers; reuse it across frames).
struct FaceState {
  std::vector<Vec3> positions;         // final skin surface [m]
  std::vector<Vec3> normals;           // of the final surface
  std::vector<Vec3> animated;          // after muscles, jaw and tissue (no wrinkles)
  std::vector<double> wrinkle_height;  // per vertex, sum of M(s) S(l) [m]
  // scratch
  std::vector<Vec3> muscle_pos, face_n;
  std::vector<double> face_area, offsets;
};

class FaceRig {
 public:
  /// `base` must have UVs (a texture-space map); `thickness_map` may be null.
  FaceRig(const geom::TriMesh& base, MuscleSet muscles, std::vector<LargeWrinkle> wrinkles,
          const FaceRigParams& params, const image::ImageF* thickness_map = nullptr);
  ~FaceRig();
  FaceRig(const FaceRig&) = delete;
  FaceRig& operator=(const FaceRig&) = delete;

  /// The refined rest mesh the rig deforms (positions, faces, uvs, uv_faces).
  const geom::TriMesh& rest_mesh() const { return m_refined.mesh; }
  const RefinedMesh& refined() const { return m_refined; }
  const MuscleSet& muscles() const { return m_muscles; }
  const WrinkleLayer& wrinkle_layer() const { return *m_wrinkles; }
  const FaceRigParams& params() const { return m_params; }

  MusclePose neutral_pose() const;
  MusclePose expression_pose(const std::string& name, double weight = 1.0) const;

  /// Blendshape targets on the base mesh (same vertex count and order as `base`), carried to the
  /// refined mesh; a pose's shape_weights then blend them in (in addition to the muscles).
  void set_blendshapes(const Blendshapes& on_base);
  const Blendshapes& blendshapes() const { return m_shapes; }

  /// Full deformation update. pose.shape_weights has one weight per blendshape target or none.
  void update(const Context& ctx, const MusclePose& pose, FaceState& out) const;
  /// The deformed mesh of a state (rest topology and UVs, state positions and normals).
  geom::TriMesh deformed_mesh(const FaceState& s) const;

  /// Edits one wrinkle; only its affected vertices are recomputed (no re-refinement).
  std::size_t set_wrinkle(std::size_t i, const LargeWrinkle& w) {
    return m_wrinkles->set_wrinkle(i, w);
  }
  void set_wrinkles_enabled(bool on) { m_params.wrinkles_enabled = on; }

 private:
  FaceRigParams m_params;
  MuscleSet m_muscles;
  RefinedMesh m_refined;
  std::unique_ptr<WrinkleLayer> m_wrinkles;
  std::unique_ptr<MuscleField> m_field;
  std::unique_ptr<SubcutaneousTissue> m_tissue;
  Blendshapes m_shapes;  // on the refined mesh
};

/// Area-weighted vertex normals, parallel and deterministic (vertex -> face CSR of `tex`).
void compute_vertex_normals(const Context& ctx, const geom::TriMesh& topo,
                            const TextureSpaceMesh& tex, const std::vector<Vec3>& positions,
                            std::vector<Vec3>& face_n, std::vector<double>& face_area,
                            std::vector<Vec3>& normals);

}  // namespace follicle::skin
