#pragma once
// Subcutaneous tissue (Bando 2002 §2.5.2): volume preservation lifts compressed skin.
// e_i = mean over the triangles at vertex i of (current area / rest area); the tissue under
// vertex i thins or thickens to h0_i / e_i, so the vertex moves along its normal by h0/e - h0.
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/image/image.hpp"
#include "follicle/skin/large_wrinkles_bando2002.hpp"

namespace follicle::skin {

struct TissueParams {
  bool enabled = true;
  double max_thickness = 0.004;      // thickness at map intensity 1 [m]
  double default_thickness = 0.002;  // used when no thickness map is given [m]
  std::string thickness_map;         // grayscale image in texture space (loaded by the caller)
  template <class V>
  void visit(V&& v) {
    v("enabled", enabled, ParamInfo{"apply the tissue layer", ""});
    v("max_thickness", max_thickness, ParamInfo{"thickness at white", "m", 0.0, 0.1});
    v("default_thickness", default_thickness,
      ParamInfo{"uniform thickness without a map", "m", 0.0, 0.1});
    v("thickness_map", thickness_map, ParamInfo{"grayscale thickness image (texture space)", ""});
  }
  void validate() const { validate_params(*this, "tissue"); }
};

/// Bilinear sample of a texture-space image at uv (u wraps, v = 0 is the bottom row).
double sample_texture(const image::ImageF& img, const Vec2& uv);

/// Per-vertex initial thickness h0: map intensity * max_thickness, or the default thickness.
std::vector<double> initial_thickness(const TextureSpaceMesh& tex, const image::ImageF* map,
                                      const TissueParams& params);

class SubcutaneousTissue {
 public:
  SubcutaneousTissue(const geom::TriMesh& rest, const TextureSpaceMesh& tex,
                     std::vector<double> h0);
  /// Per-vertex expansion ratio e_i from the current face areas (`face_area`, one per face).
  void expansion(const Context& ctx, const std::vector<double>& face_area,
                 std::vector<double>& e) const;
  /// Per-vertex normal offset h0/e - h0 [m].
  void offsets(const Context& ctx, const std::vector<double>& face_area,
               std::vector<double>& off) const;
  const std::vector<double>& thickness() const { return m_h0; }
  const std::vector<double>& rest_areas() const { return m_rest_area; }

 private:
  const TextureSpaceMesh* m_tex;  // owned by the caller, outlives this object
  std::vector<double> m_h0;
  std::vector<double> m_rest_area;
};

}  // namespace follicle::skin
