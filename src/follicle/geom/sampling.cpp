#include "follicle/geom/sampling.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"

namespace follicle::geom {

AreaSampler::AreaSampler(const TriMesh& mesh) : m_mesh(&mesh) {
  m_cdf.resize(mesh.num_faces());
  double acc = 0;
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    acc += mesh.face_area(f);
    m_cdf[f] = acc;
  }
  m_total = acc;
  if (!(m_total > 0) || !std::isfinite(m_total))
    fail("AreaSampler: mesh '{}' has total area {}, expected a positive finite area", mesh.name,
         m_total);
}

SurfaceSample AreaSampler::sample(Rng& rng) const {
  const double u = rng.uniform() * m_total;
  auto it = std::upper_bound(m_cdf.begin(), m_cdf.end(), u);
  std::size_t f = std::size_t(it - m_cdf.begin());
  if (f >= m_cdf.size()) f = m_cdf.size() - 1;
  // Uniform point in a triangle: b = (1 - sqrt(r1), sqrt(r1)(1 - r2), sqrt(r1) r2).
  const double s = std::sqrt(rng.uniform());
  const double r2 = rng.uniform();
  SurfaceSample out;
  out.face = int(f);
  out.bary = Vec3(1 - s, s * (1 - r2), s * r2);
  const Vec3i& t = m_mesh->faces[f];
  out.point = out.bary[0] * m_mesh->positions[std::size_t(t[0])] +
              out.bary[1] * m_mesh->positions[std::size_t(t[1])] +
              out.bary[2] * m_mesh->positions[std::size_t(t[2])];
  return out;
}

std::vector<SurfaceSample> sample_uniform(const Context& ctx, const TriMesh& mesh, std::size_t n,
                                          uint64_t seed) {
  const AreaSampler sampler(mesh);
  std::vector<SurfaceSample> out(n);
  parallel_for(
      ctx, 0, n,
      [&](std::size_t i) {
        Rng rng = Rng::stream(seed, i);
        out[i] = sampler.sample(rng);
      },
      1024);
  return out;
}

double poisson_disc_distance_for_count(double area, std::size_t n) {
  if (n == 0 || !(area > 0)) fail("poisson_disc_distance_for_count: need area > 0 and n > 0");
  return std::sqrt(0.7 * area / double(n));
}

std::vector<uint32_t> poisson_disc_accept(const std::vector<Vec3>& points, double r,
                                          std::size_t max_points) {
  if (!(r > 0) || !std::isfinite(r)) fail("poisson_disc_accept: distance must be > 0, got {}", r);
  // Dart throwing in the given order (serial: acceptance depends on earlier decisions).
  // Hash grid with cells of edge r: a conflicting sample lies in the 27 surrounding cells.
  const double inv = 1.0 / r;
  auto key = [](int64_t x, int64_t y, int64_t z) {
    return (uint64_t(x) * 73856093ull) ^ (uint64_t(y) * 19349663ull) ^ (uint64_t(z) * 83492791ull);
  };
  struct Cell {
    int64_t x, y, z;
  };
  std::unordered_multimap<uint64_t, uint32_t> grid;
  std::vector<uint32_t> out;
  const double r2 = r * r;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    const Vec3 q = p * inv;
    const Cell cc{int64_t(std::floor(q.x())), int64_t(std::floor(q.y())),
                  int64_t(std::floor(q.z()))};
    bool ok = true;
    for (int64_t dz = -1; dz <= 1 && ok; ++dz)
      for (int64_t dy = -1; dy <= 1 && ok; ++dy)
        for (int64_t dx = -1; dx <= 1 && ok; ++dx) {
          auto [b, e] = grid.equal_range(key(cc.x + dx, cc.y + dy, cc.z + dz));
          for (auto it = b; it != e; ++it)
            if ((points[it->second] - p).squaredNorm() < r2) {
              ok = false;
              break;
            }
        }
    if (!ok) continue;
    grid.emplace(key(cc.x, cc.y, cc.z), uint32_t(i));
    out.push_back(uint32_t(i));
    if (max_points && out.size() >= max_points) break;
  }
  return out;
}

std::vector<SurfaceSample> sample_poisson_disc(const Context& ctx, const TriMesh& mesh,
                                               const PoissonDiscParams& params, uint64_t seed) {
  params.validate();
  const AreaSampler sampler(mesh);
  const double r = params.min_distance;
  const double want = std::ceil(params.oversampling * sampler.total_area() / (r * r));
  if (want > double(params.max_candidates))
    fail(
        "sample_poisson_disc: min_distance {} m on {} m^2 needs {} candidates, more than "
        "max_candidates {}",
        r, sampler.total_area(), want, params.max_candidates);
  const auto candidates = sample_uniform(ctx, mesh, std::size_t(std::max(1.0, want)), seed);
  std::vector<Vec3> points(candidates.size());
  for (std::size_t i = 0; i < candidates.size(); ++i) points[i] = candidates[i].point;
  std::vector<SurfaceSample> out;
  for (uint32_t i : poisson_disc_accept(points, params.min_distance, params.max_points))
    out.push_back(candidates[i]);
  return out;
}

}  // namespace follicle::geom
