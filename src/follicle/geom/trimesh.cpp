#include "follicle/geom/trimesh.hpp"

#include <cmath>

#include "follicle/core/error.hpp"

namespace follicle::geom {

void TriMesh::compute_normals() {
  normals.assign(positions.size(), Vec3::Zero());
  for (const Vec3i& f : faces) {
    const Vec3& a = positions[std::size_t(f[0])];
    const Vec3& b = positions[std::size_t(f[1])];
    const Vec3& c = positions[std::size_t(f[2])];
    const Vec3 n = (b - a).cross(c - a);  // length = 2 * area: area weighting for free
    for (int k = 0; k < 3; ++k) normals[std::size_t(f[k])] += n;
  }
  for (Vec3& n : normals) {
    const double len = n.norm();
    n = len > 0 ? Vec3(n / len) : Vec3(0, 0, 1);
  }
}

Vec3 TriMesh::face_normal(std::size_t fi) const {
  const Vec3i& f = faces[fi];
  const Vec3 n = (positions[std::size_t(f[1])] - positions[std::size_t(f[0])])
                     .cross(positions[std::size_t(f[2])] - positions[std::size_t(f[0])]);
  const double len = n.norm();
  return len > 0 ? Vec3(n / len) : Vec3::Zero();
}

double TriMesh::face_area(std::size_t fi) const {
  const Vec3i& f = faces[fi];
  return 0.5 * (positions[std::size_t(f[1])] - positions[std::size_t(f[0])])
                   .cross(positions[std::size_t(f[2])] - positions[std::size_t(f[0])])
                   .norm();
}

Eigen::AlignedBox3d TriMesh::bounds() const {
  Eigen::AlignedBox3d b;  // empty
  for (const Vec3& p : positions) b.extend(p);
  return b;
}

void TriMesh::check(const std::string& where) const {
  const auto nv = int64_t(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i)
    if (!positions[i].allFinite())
      fail_at(where, "vertex {} has a non-finite coordinate ({}, {}, {})", i, positions[i].x(),
              positions[i].y(), positions[i].z());
  // Finite but so large that areas, normals and distances overflow (a 1e308 coordinate gave a
  // surface area of inf): no head, hand or scene is a million kilometres across (checked in the
  // file's units by the readers and in metres after conversion).
  constexpr double kMaxCoordinate = 1e9;
  for (std::size_t i = 0; i < positions.size(); ++i)
    if (positions[i].cwiseAbs().maxCoeff() > kMaxCoordinate)
      fail_at(where,
              "vertex {} has coordinate ({:g}, {:g}, {:g}), beyond +-{:g}: a corrupt file or "
              "wrong units",
              i, positions[i].x(), positions[i].y(), positions[i].z(), kMaxCoordinate);
  for (std::size_t f = 0; f < faces.size(); ++f)
    for (int k = 0; k < 3; ++k)
      if (faces[f][k] < 0 || faces[f][k] >= nv)
        fail_at(where, "face {} references vertex {}, expected an index in [0, {})", f, faces[f][k],
                nv);
  if (uvs.empty() != uv_faces.empty())
    fail_at(where, "{} UVs but {} UV faces: both must be empty or neither", uvs.size(),
            uv_faces.size());
  if (!uvs.empty()) {
    if (uv_faces.size() != faces.size())
      fail_at(where, "{} UV faces for {} faces, expected one per face", uv_faces.size(),
              faces.size());
    const auto nuv = int64_t(uvs.size());
    for (std::size_t i = 0; i < uvs.size(); ++i)
      if (!uvs[i].allFinite()) fail_at(where, "UV {} is not finite", i);
    for (std::size_t f = 0; f < uv_faces.size(); ++f)
      for (int k = 0; k < 3; ++k)
        if (uv_faces[f][k] < 0 || uv_faces[f][k] >= nuv)
          fail_at(where, "face {} references UV {}, expected an index in [0, {})", f,
                  uv_faces[f][k], nuv);
  }
  if (!normals.empty()) {
    if (normals.size() != positions.size())
      fail_at(where, "{} normals for {} vertices, expected one per vertex or none", normals.size(),
              positions.size());
    for (std::size_t i = 0; i < normals.size(); ++i)
      if (!normals[i].allFinite()) fail_at(where, "normal {} is not finite", i);
  }
}

void TriMesh::transform(const Affine3& xf) {
  for (Vec3& p : positions) p = xf * p;
  if (!normals.empty()) {
    // Normals transform by the inverse transpose of the linear part.
    const Mat3 nm = xf.linear().inverse().transpose();
    for (Vec3& n : normals) {
      n = nm * n;
      const double len = n.norm();
      if (len > 0) n /= len;
    }
  }
  if (xf.linear().determinant() < 0)  // mirroring flips orientation: keep faces outward
    for (std::size_t f = 0; f < faces.size(); ++f) {
      std::swap(faces[f][1], faces[f][2]);
      if (!uv_faces.empty()) std::swap(uv_faces[f][1], uv_faces[f][2]);
    }
}

void TriMesh::scale(double s) {
  for (Vec3& p : positions) p *= s;
  if (s < 0) {
    for (Vec3& n : normals) n = -n;
    for (std::size_t f = 0; f < faces.size(); ++f) {
      std::swap(faces[f][1], faces[f][2]);
      if (!uv_faces.empty()) std::swap(uv_faces[f][1], uv_faces[f][2]);
    }
  }
}

}  // namespace follicle::geom
