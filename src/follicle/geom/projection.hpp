#pragma once
// Planar and cylindrical projection of a mesh to the 2D texture space (Bando 2002 §2.4).
#include <vector>

#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::geom {

/// Planar projection: u = (p - origin).u_axis / scale, v = (p - origin).v_axis / scale.
struct PlanarProjection {
  Vec3 origin = Vec3::Zero();  // [m]
  Vec3 u_axis = Vec3::UnitX();
  Vec3 v_axis = Vec3::UnitY();
  double scale = 1.0;  // [m per texture unit]
  template <class V>
  void visit(V&& v) {
    v("origin", origin, ParamInfo{"projection origin", "m"});
    v("u_axis", u_axis, ParamInfo{"texture u direction", ""});
    v("v_axis", v_axis, ParamInfo{"texture v direction", ""});
    v("scale", scale, ParamInfo{"metres per texture unit", "m", 1e-9, 1e9});
  }
  void validate() const;
};

/// Cylindrical projection about an axis: u = angle/(2 pi) in [0,1) measured from `zero_dir`
/// (counter-clockwise about `axis`), v = height along `axis` / height_scale.
struct CylindricalProjection {
  Vec3 origin = Vec3::Zero();     // a point on the axis [m]
  Vec3 axis = Vec3::UnitY();      // cylinder axis (v direction)
  Vec3 zero_dir = Vec3::UnitZ();  // direction of u = 0.5 (the seam is opposite, at u = 0)
  double height_scale = 1.0;      // [m per texture unit]
  template <class V>
  void visit(V&& v) {
    v("origin", origin, ParamInfo{"point on the axis", "m"});
    v("axis", axis, ParamInfo{"cylinder axis", ""});
    v("zero_dir", zero_dir, ParamInfo{"direction mapped to u = 0.5", ""});
    v("height_scale", height_scale,
      ParamInfo{"metres per texture unit along the axis", "m", 1e-9, 1e9});
  }
  void validate() const;
};

/// Per-vertex planar texture coordinates.
std::vector<Vec2> project_planar(const std::vector<Vec3>& positions, const PlanarProjection& p);
/// Per-vertex cylindrical texture coordinates, u in [0, 1).
std::vector<Vec2> project_cylindrical(const std::vector<Vec3>& positions,
                                      const CylindricalProjection& p);

/// Stores per-vertex texture coordinates in mesh.uvs / uv_faces. With `wrap_u`, triangles that
/// straddle the u seam (u span > 0.5) get extra UV entries shifted by +1 so that every triangle is
/// continuous in texture space; the texture space is then treated as wrapped around (u mod 1).
void assign_uvs(TriMesh& mesh, const std::vector<Vec2>& vertex_uv, bool wrap_u);

/// Wrapped difference a - b in u (result in [-0.5, 0.5)), plain in v.
Vec2 wrapped_uv_delta(const Vec2& a, const Vec2& b);

/// A planar projection fitted to the mesh: the plane spanned by the two largest principal axes,
/// oriented so that `view_dir` (e.g. the face's forward direction) is its normal's side, scaled
/// so the result fits [0,1]^2.
PlanarProjection fit_planar_projection(const std::vector<Vec3>& positions, const Vec3& view_dir,
                                       const Vec3& up);

}  // namespace follicle::geom
