#include "follicle/geom/mesh_distance.hpp"

#include <algorithm>
#include <cmath>

#include "follicle/core/parallel.hpp"
#include "follicle/geom/sampling.hpp"
#include "follicle/geom/spatial_embree.hpp"

namespace follicle::geom {

DistanceStats distance_stats(const std::vector<double>& d) {
  DistanceStats s;
  s.count = d.size();
  if (d.empty()) return s;
  double sum = 0, sum2 = 0, mx = 0;
  for (double x : d) {
    sum += x;
    sum2 += x * x;
    mx = std::max(mx, x);
  }
  s.mean = sum / double(d.size());
  s.rms = std::sqrt(sum2 / double(d.size()));
  s.max = mx;
  std::vector<double> tmp = d;
  const std::size_t rank = std::size_t(std::ceil(0.95 * double(d.size())));
  const std::size_t k = rank == 0 ? 0 : rank - 1;
  std::nth_element(tmp.begin(), tmp.begin() + std::ptrdiff_t(k), tmp.end());
  s.p95 = tmp[k];
  return s;
}

namespace {
std::vector<double> sample_distances(const Context& ctx, const TriMesh& from, const MeshQuery& to,
                                     std::size_t n, uint64_t seed) {
  const auto samples = sample_uniform(ctx, from, n, seed);
  std::vector<double> d(samples.size());
  parallel_for(
      ctx, 0, samples.size(),
      [&](std::size_t i) { d[i] = to.closest_point(samples[i].point).distance; }, 512);
  return d;
}

std::vector<double> vertex_distances_q(const Context& ctx, const TriMesh& a, const MeshQuery& qb) {
  std::vector<double> d(a.num_vertices());
  parallel_for(
      ctx, 0, d.size(), [&](std::size_t i) { d[i] = qb.closest_point(a.positions[i]).distance; },
      512);
  return d;
}
}  // namespace

MeshDistanceReport mesh_distance(const Context& ctx, const TriMesh& a, const TriMesh& b,
                                 const MeshDistanceParams& params) {
  params.validate();
  const MeshQuery qa(a), qb(b);
  const auto dab = sample_distances(ctx, a, qb, params.samples, params.seed);
  const auto dba = sample_distances(ctx, b, qa, params.samples, params.seed ^ 0x5DEECE66Dull);
  MeshDistanceReport r;
  r.a_to_b = distance_stats(dab);
  r.b_to_a = distance_stats(dba);
  std::vector<double> all = dab;
  all.insert(all.end(), dba.begin(), dba.end());
  r.two_sided = distance_stats(all);
  // Vertices can carry the largest error (spikes); include them in the maxima.
  const auto vab = vertex_distances_q(ctx, a, qb);
  const auto vba = vertex_distances_q(ctx, b, qa);
  for (double x : vab) r.a_to_b.max = std::max(r.a_to_b.max, x);
  for (double x : vba) r.b_to_a.max = std::max(r.b_to_a.max, x);
  r.two_sided.max = std::max(r.a_to_b.max, r.b_to_a.max);
  return r;
}

std::vector<double> vertex_distances(const Context& ctx, const TriMesh& a, const TriMesh& b) {
  const MeshQuery qb(b);
  return vertex_distances_q(ctx, a, qb);
}

}  // namespace follicle::geom
