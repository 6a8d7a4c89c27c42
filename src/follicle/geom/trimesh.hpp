#pragma once
// TriMesh: an indexed triangle mesh in metres. Texture coordinates are indexed separately from
// positions (as in OBJ), so UV seams do not split the surface: `uv_faces[f]` holds the three UV
// indices of face f. Normals are per position vertex.
#include <string>
#include <vector>

#include "follicle/core/types.hpp"
#include "follicle/core/units.hpp"

namespace follicle::geom {

struct TriMesh {
  std::vector<Vec3> positions;  // [m]
  std::vector<Vec3i> faces;     // counter-clockwise seen from outside
  std::vector<Vec2> uvs;        // texture coordinates, may be empty
  std::vector<Vec3i> uv_faces;  // per-face UV indices; empty iff uvs is empty
  std::vector<Vec3> normals;    // per position vertex, may be empty (compute_normals())
  std::string name;

  std::size_t num_vertices() const { return positions.size(); }
  std::size_t num_faces() const { return faces.size(); }
  bool has_uvs() const { return !uvs.empty(); }
  bool has_normals() const { return normals.size() == positions.size(); }

  /// Area-weighted vertex normals (angle-weighted would be nicer on scans; area is standard).
  void compute_normals();
  Vec3 face_normal(std::size_t f) const;  // unit, zero for degenerate faces
  double face_area(std::size_t f) const;
  Eigen::AlignedBox3d bounds() const;
  /// Throws follicle::Error when indices are out of range or coordinates are not finite.
  void check(const std::string& where) const;
  void transform(const Affine3& xf);  // positions and normals
  void scale(double s);
};

}  // namespace follicle::geom
