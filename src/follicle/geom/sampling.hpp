#pragma once
// Surface sampling on triangle meshes: area-uniform random samples and Poisson-disc samples
// (dart throwing over an area-uniform candidate pool, Euclidean distance). Sample i always
// uses Rng::stream(seed, i), so results do not depend on the thread count.
#include <cstdint>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::geom {

struct SurfaceSample {
  int face = -1;
  Vec3 bary = Vec3::Zero();  // corner weights, sum 1
  Vec3 point = Vec3::Zero();
};

/// Picks faces with probability proportional to area (binary search in the area CDF) and a
/// uniform point inside (square-root warp).
class AreaSampler {
 public:
  explicit AreaSampler(const TriMesh& mesh);  // throws when the total area is zero
  SurfaceSample sample(Rng& rng) const;
  double total_area() const { return m_total; }
  const TriMesh& mesh() const { return *m_mesh; }

 private:
  const TriMesh* m_mesh;
  std::vector<double> m_cdf;  // cumulative face areas
  double m_total = 0;
};

/// n area-uniform samples; sample i draws from Rng::stream(seed, i). Parallel.
std::vector<SurfaceSample> sample_uniform(const Context& ctx, const TriMesh& mesh, std::size_t n,
                                          uint64_t seed);

struct PoissonDiscParams {
  double min_distance = 1e-3;  // [m] no two samples closer than this (Euclidean)
  double oversampling = 8.0;   // candidates per min_distance^2 of surface area
  uint64_t max_points = 0;     // stop after this many accepted samples (0 = no limit)
  uint64_t max_candidates = 50'000'000;
  template <class V>
  void visit(V&& v) {
    v("min_distance", min_distance, ParamInfo{"minimum distance between samples", "m", 1e-9, 1e9});
    v("oversampling", oversampling,
      ParamInfo{"candidates per min_distance^2 of area", "", 0.1, 1e4});
    v("max_points", max_points,
      ParamInfo{"maximum number of samples (0 = unlimited)", "", 0, 1e12});
    v("max_candidates", max_candidates, ParamInfo{"candidate pool limit", "", 1, 1e10});
  }
  void validate() const { validate_params(*this, "poisson_disc"); }
};

/// Dart throwing over given points: the indices of the points accepted, in order, when no
/// earlier accepted point lies within r (Euclidean; hash grid of cell r). Stops after max_points
/// accepted points (0 = no limit). Throws follicle::Error for r <= 0.
std::vector<uint32_t> poisson_disc_accept(const std::vector<Vec3>& points, double r,
                                          std::size_t max_points = 0);

/// Poisson-disc samples: area-uniform candidates are accepted in order when no accepted sample
/// lies within min_distance (hash-grid test). Deterministic for a given seed.
std::vector<SurfaceSample> sample_poisson_disc(const Context& ctx, const TriMesh& mesh,
                                               const PoissonDiscParams& params, uint64_t seed);

/// A min_distance that yields roughly n Poisson-disc samples on a surface of the given area
/// (dart throwing saturates at ~0.7 * area / r^2 samples).
double poisson_disc_distance_for_count(double area, std::size_t n);

}  // namespace follicle::geom
