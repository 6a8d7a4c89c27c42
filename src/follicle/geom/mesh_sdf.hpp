#pragma once
// Signed distance to a triangle mesh (negative inside), exact and sampled on a grid.
//
// MeshSignedDistance: Embree closest point. signed_distance(p, max) signs it by the angle-weighted
// pseudo-normal of the closest feature (face, edge or vertex; Bærentzen & Aanæs 2005: cheap,
// exact in exact arithmetic, but a closest feature picked by rounding among near-ties can flip
// it); signed_distance(p) and inside() use the parity of ray crossings (closed meshes), robust.
//
// SignedDistanceGrid: the signed distance sampled at the nodes of a regular grid over a box,
// clamped to ±band (only a narrow band is queried), signed by the crossing parity of one ray per
// grid row (closed meshes), read back by trilinear interpolation. A coarse grid of per-block minima
// lets callers skip points far from the surface with one lookup (`maybe_below`). Built once
// (closest-point queries in parallel), then read-only: queries are const and thread-safe.
#include <cstdint>
#include <memory>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/spatial_embree.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::geom {

class MeshSignedDistance {
 public:
  /// Copies the mesh (after check()) and builds its Embree query and pseudo-normals.
  explicit MeshSignedDistance(const TriMesh& mesh);
  ~MeshSignedDistance();
  MeshSignedDistance(MeshSignedDistance&&) noexcept;
  MeshSignedDistance& operator=(MeshSignedDistance&&) noexcept;

  /// Signed distance [m] to the surface, negative inside; within max_distance, else +-max_distance
  /// with sign 0 reported through `known` (false when nothing lies within max_distance).
  double signed_distance(const Vec3& p, double max_distance, bool* known = nullptr) const;
  /// Exact signed distance: closest-point distance, sign by inside().
  double signed_distance(const Vec3& p) const;
  /// Inside the (closed) mesh: parity of the surface crossings, majority of three rays.
  bool inside(const Vec3& p) const;

  const TriMesh& mesh() const { return m_mesh; }
  const MeshQuery& query() const { return *m_query; }

 private:
  TriMesh m_mesh;
  std::unique_ptr<MeshQuery> m_query;
  std::vector<Vec3> m_face_n;    // unit face normals
  std::vector<Vec3> m_vertex_n;  // angle-weighted vertex pseudo-normals
  std::vector<Vec3> m_edge_n;    // [3 * face + k]: edge opposite corner k, sum of both faces
};

struct SignedDistanceGridParams {
  double cell = 0.0025;  // [m] grid spacing
  double band = 0.012;   // [m] distances are exact within the band, clamped to ±band outside
  int block = 4;         // cells per coarse block (maybe_below)
};

class SignedDistanceGrid {
 public:
  SignedDistanceGrid() = default;
  /// Samples `sd` over the axis-aligned box [lo, hi] (grown to whole cells).
  SignedDistanceGrid(const Context& ctx, const MeshSignedDistance& sd, const Vec3& lo,
                     const Vec3& hi, const SignedDistanceGridParams& params = {});

  bool empty() const { return m_value.empty(); }
  /// Trilinear signed distance; points outside the box give +band (far outside).
  float value(float x, float y, float z) const;
  /// Trilinear value and its gradient (not normalised; zero outside the box).
  float value_gradient(float x, float y, float z, float g[3]) const;
  /// False when the interpolated distance at (x, y, z) is certainly above `level` (the minimum of
  /// the grid nodes of the coarse block around the point exceeds it): one lookup, no
  /// interpolation. Conservative: true does not mean below.
  bool maybe_below(float x, float y, float z, float level) const {
    const float fx = (x - m_origin[0]) * m_inv_block, fy = (y - m_origin[1]) * m_inv_block,
                fz = (z - m_origin[2]) * m_inv_block;
    if (!(fx >= 0.0f && fy >= 0.0f && fz >= 0.0f && fx < float(m_bdim[0]) &&
          fy < float(m_bdim[1]) && fz < float(m_bdim[2])))
      return false;
    const std::size_t b = (std::size_t(int(fz)) * std::size_t(m_bdim[1]) + std::size_t(int(fy))) *
                              std::size_t(m_bdim[0]) +
                          std::size_t(int(fx));
    return m_block_min[b] <= level;
  }

  float cell() const { return m_cell; }
  float band() const { return m_band; }
  const int* dims() const { return m_dim; }  // grid nodes per axis
  const float* origin() const { return m_origin; }

 private:
  float node(int i, int j, int k) const {
    return m_value[(std::size_t(k) * std::size_t(m_dim[1]) + std::size_t(j)) *
                       std::size_t(m_dim[0]) +
                   std::size_t(i)];
  }
  float m_origin[3] = {0, 0, 0};
  float m_cell = 1, m_inv_cell = 1, m_band = 0, m_inv_block = 1;
  int m_dim[3] = {0, 0, 0};    // nodes
  int m_bdim[3] = {0, 0, 0};   // coarse blocks
  std::vector<float> m_value;  // [k][j][i] node values
  std::vector<float>
      m_block_min;  // [bk][bj][bi] minimum over the block's nodes (and its far faces)
};

}  // namespace follicle::geom
