#pragma once
// Point location in a mesh's texture space: which face's UV triangle holds a texture position,
// and where inside it (barycentric weights). Wrinkle curves, direction keys and setup checks are
// given in texture space and must be found on the surface; a uniform grid over the UV bounding
// box holds the faces whose UV box overlaps each cell (about one face per cell).
#include <vector>

#include "follicle/core/types.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::geom {

struct UvHit {
  int face = -1;             // -1: on no UV triangle (within the tolerance)
  Vec3 bary = Vec3::Zero();  // weights of the face's three UV corners, clamped to >= 0, sum 1
};

class UvLocator {
 public:
  /// Copies the UV triangles of `mesh` (uv_faces over uvs). Throws follicle::Error when the mesh
  /// has no texture coordinates.
  explicit UvLocator(const TriMesh& mesh);
  /// The face whose UV triangle contains q (either winding; the first in face order where
  /// triangles overlap). `tolerance` (barycentric units) also accepts the least-outside face
  /// within it, for points on a border. Degenerate UV triangles never match.
  UvHit locate(const Vec2& q, double tolerance = 0.0) const;

 private:
  struct Tri {
    Vec2 a, b, c;
  };
  std::vector<Tri> m_tris;
  Vec2 m_lo = Vec2::Zero(), m_cell = Vec2::Ones();
  int m_nx = 1, m_ny = 1;
  std::vector<std::size_t> m_offsets;  // CSR: cell -> faces
  std::vector<int> m_faces;
};

/// dP/d(u, v) on face f: the 3x2 matrix taking a texture-space direction to the surface
/// tangent it maps to (zero for a degenerate UV triangle). Needs uv_faces.
Eigen::Matrix<double, 3, 2> uv_jacobian(const TriMesh& mesh, std::size_t face);

/// UV island of every face (faces joined by shared UV indices), numbered 0.. in face order.
std::vector<int> uv_islands(const TriMesh& mesh);

}  // namespace follicle::geom
