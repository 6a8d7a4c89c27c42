#include "follicle/render/preview_scene.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace follicle::render {

geom::StrandSet every_kth_strand(const geom::StrandSet& s, std::size_t k, std::size_t m) {
  k = std::max<std::size_t>(k, 1);
  m = std::max<std::size_t>(m, 1);
  geom::StrandSet out;
  const bool radius = !s.radius.empty(), color = !s.color.empty();
  auto keep = [&](uint32_t p) {
    out.points.push_back(s.points[p]);
    if (radius) out.radius.push_back(s.radius[p]);
    if (color) out.color.push_back(s.color[p]);
  };
  for (std::size_t i = 0; i < s.num_strands(); i += k) {
    const uint32_t b = s.offsets[i], e = s.offsets[i + 1];
    for (uint32_t p = b; p < e; p += uint32_t(m)) keep(p);
    // The tip always stays, so the strand keeps its length.
    if (e > b && (e - 1 - b) % m != 0) keep(e - 1);
    out.offsets.push_back(uint32_t(out.points.size()));
  }
  return out;
}

geom::ParticleSet every_kth_particle(const geom::ParticleSet& s, std::size_t k) {
  k = std::max<std::size_t>(k, 1);
  geom::ParticleSet out;
  const float grow = float(std::sqrt(double(k)));
  for (std::size_t i = 0; i < s.size(); i += k) {
    out.positions.push_back(s.positions[i]);
    if (!s.directions.empty()) out.directions.push_back(s.directions[i]);
    if (!s.radius.empty()) out.radius.push_back(s.radius[i] * grow);
    if (!s.color.empty()) out.color.push_back(s.color[i]);
    if (!s.opacity.empty()) out.opacity.push_back(s.opacity[i]);
  }
  return out;
}

geom::TriMesh simplified_mesh(const geom::TriMesh& m, std::size_t max_faces) {
  geom::TriMesh out = m;
  if (!out.has_normals()) out.compute_normals();
  if (m.faces.size() <= std::max<std::size_t>(max_faces, 1)) return out;
  // meshoptimizer works on one index space: weld each distinct (position, UV) corner pair into
  // one vertex. A UV seam then is an open border of the welded mesh, and locked borders keep
  // both of its sides, and the mesh's true borders, where they are.
  const bool uv = m.has_uvs() && m.uv_faces.size() == m.faces.size();
  std::unordered_map<uint64_t, uint32_t> weld;
  std::vector<std::pair<int, int>> corner;  // welded vertex -> (position, UV)
  std::vector<float> xyz;
  std::vector<uint32_t> idx;
  idx.reserve(3 * m.faces.size());
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int p = m.faces[f][c], t = uv ? m.uv_faces[f][c] : 0;
      const uint64_t key = (uint64_t(uint32_t(p)) << 32) | uint32_t(t);
      auto [it, added] = weld.try_emplace(key, uint32_t(corner.size()));
      if (added) {
        corner.emplace_back(p, t);
        for (int j = 0; j < 3; ++j) xyz.push_back(float(m.positions[std::size_t(p)][j]));
      }
      idx.push_back(it->second);
    }
  std::vector<uint32_t> dst(idx.size());
  float error = 0;
  const std::size_t n =
      meshopt_simplify(dst.data(), idx.data(), idx.size(), xyz.data(), corner.size(),
                       3 * sizeof(float), 3 * max_faces, 0.01f, meshopt_SimplifyLockBorder, &error);
  out.faces.clear();
  out.uv_faces.clear();
  for (std::size_t i = 0; i + 2 < n; i += 3) {
    Vec3i f, t;
    for (int c = 0; c < 3; ++c) {
      f[c] = corner[dst[i + std::size_t(c)]].first;
      t[c] = corner[dst[i + std::size_t(c)]].second;
    }
    out.faces.push_back(f);
    if (uv) out.uv_faces.push_back(t);
  }
  return out;
}

namespace {
// The faces of `m` as one number (FNV-1a over the position and UV indices).
std::size_t topology_hash(const geom::TriMesh& m) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&](const std::vector<Vec3i>& v) {
    for (const Vec3i& f : v)
      for (int c = 0; c < 3; ++c) h = (h ^ uint64_t(uint32_t(f[c]))) * 1099511628211ull;
  };
  mix(m.faces);
  mix(m.uv_faces);
  return std::size_t(h);
}

// The reduced set of `src` for the reduction `key`, from the cache when the source is unchanged.
template <class T, class Entry, class Make>
std::shared_ptr<const T> cached(std::vector<Entry>& cache, const std::shared_ptr<const T>& src,
                                std::pair<std::size_t, std::size_t> key, Make&& make) {
  for (auto& e : cache)
    if (!e.source.expired() && e.source.lock() == src && e.key == key) return e.reduced;
  auto r = std::make_shared<const T>(make(*src));
  cache.erase(
      std::remove_if(cache.begin(), cache.end(), [](const Entry& e) { return e.source.expired(); }),
      cache.end());
  cache.push_back({src, key, r});
  if (cache.size() > 64) cache.erase(cache.begin());
  return r;
}
}  // namespace

void PreviewReducer::reduce(RenderScene& rs, RenderSettings& s, const PreviewParams& p) {
  p.validate();
  s.width = std::max(1, int(std::lround(s.width * p.scale)));
  s.height = std::max(1, int(std::lround(s.height * p.scale)));
  s.supersample = 1;
  s.shadow_map_size = std::min(s.shadow_map_size, p.shadow_map_size);
  std::size_t strands = 0, points = 0, particles = 0;
  for (const auto& it : rs.strands)
    if (it.strands) {
      strands += it.strands->num_strands();
      points += it.strands->points.size();
    }
  for (const auto& it : rs.particles)
    if (it.particles) particles += it.particles->size();
  // Every ks-th strand (at least 1: a scene without strands keeps its items as they are) ...
  const std::size_t ks = std::max<std::size_t>(
      1, (strands + std::size_t(p.max_strands) - 1) / std::size_t(p.max_strands));
  // ... and of those every m-th point while more than max_points remain.
  const std::size_t kept_points = (points + ks - 1) / ks;
  const std::size_t m = (kept_points + std::size_t(p.max_points) - 1) / std::size_t(p.max_points);
  if (ks > 1 || m > 1) {
    // Thinner hair drawn wider: the strands that remain cover about what all of them did (up to
    // three times the width).
    const double widen = std::min(3.0, std::sqrt(double(ks)));
    for (auto& it : rs.strands) {
      if (!it.strands) continue;
      it.strands = cached<geom::StrandSet>(
          m_strands, it.strands, {ks, m},
          [&](const geom::StrandSet& src) { return every_kth_strand(src, ks, m); });
      it.material.width_px *= widen;
    }
  }
  const std::size_t max_tri = std::size_t(p.max_triangles);
  for (auto& it : rs.meshes) {
    if (!it.mesh || it.mesh->faces.size() <= max_tri) continue;
    it.mesh = cached<geom::TriMesh>(m_meshes, it.mesh, {max_tri, 1}, [&](const geom::TriMesh& src) {
      const std::size_t h = topology_hash(src);
      for (const Topology& t : m_topologies)
        if (t.vertices == src.positions.size() && t.hash == h && t.max_triangles == max_tri) {
          geom::TriMesh r = src;  // the same faces seen before: only the vertices are new
          if (!r.has_normals()) r.compute_normals();
          r.faces = t.faces;
          r.uv_faces = t.uv_faces;
          return r;
        }
      geom::TriMesh r = simplified_mesh(src, max_tri);
      m_topologies.push_back({src.positions.size(), h, max_tri, r.faces, r.uv_faces});
      if (m_topologies.size() > 8) m_topologies.erase(m_topologies.begin());
      return r;
    });
  }
  const std::size_t kp =
      (particles + std::size_t(p.max_particles) - 1) / std::size_t(p.max_particles);
  if (kp > 1)
    for (auto& it : rs.particles) {
      if (!it.particles) continue;
      it.particles = cached<geom::ParticleSet>(
          m_particles, it.particles, {kp, 1},
          [&](const geom::ParticleSet& src) { return every_kth_particle(src, kp); });
      it.radius *= std::sqrt(double(kp));
    }
}

}  // namespace follicle::render
