#pragma once
// Mesh-to-mesh distance: area-uniform samples on A are projected to B (Embree closest point)
// and vice versa. Reports one-sided and two-sided mean, RMS, 95th percentile and maximum
// (Hausdorff estimate; the vertices are included in the maximum so it never misses a spike at a
// vertex). Per-vertex distances of A to B serve error-coloured renders.
#include <cstdint>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::geom {

struct DistanceStats {
  double mean = 0, rms = 0, p95 = 0, max = 0;  // [m]
  std::size_t count = 0;
};

/// Statistics of a list of distances (p95: nearest-rank percentile).
DistanceStats distance_stats(const std::vector<double>& d);

struct MeshDistanceParams {
  uint64_t samples = 100000;  // area-uniform samples on each mesh
  uint64_t seed = 1;
  template <class V>
  void visit(V&& v) {
    v("samples", samples, ParamInfo{"area-uniform samples per mesh", "", 1, 1e9});
    v("seed", seed, ParamInfo{"random seed"});
  }
  void validate() const { validate_params(*this, "mesh_distance"); }
};

struct MeshDistanceReport {
  DistanceStats a_to_b, b_to_a;
  DistanceStats two_sided;  // over the union of both sample sets; max = Hausdorff distance
};

MeshDistanceReport mesh_distance(const Context& ctx, const TriMesh& a, const TriMesh& b,
                                 const MeshDistanceParams& params = {});

/// Distance from every vertex of `a` to the surface of `b` [m].
std::vector<double> vertex_distances(const Context& ctx, const TriMesh& a, const TriMesh& b);

}  // namespace follicle::geom
