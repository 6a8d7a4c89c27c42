#include "follicle/render/preview_scene.hpp"

#include <algorithm>
#include <cmath>

namespace follicle::render {

geom::StrandSet every_kth_strand(const geom::StrandSet& s, std::size_t k) {
  k = std::max<std::size_t>(k, 1);
  geom::StrandSet out;
  const bool radius = !s.radius.empty(), color = !s.color.empty();
  for (std::size_t i = 0; i < s.num_strands(); i += k) {
    for (uint32_t p = s.offsets[i]; p < s.offsets[i + 1]; ++p) {
      out.points.push_back(s.points[p]);
      if (radius) out.radius.push_back(s.radius[p]);
      if (color) out.color.push_back(s.color[p]);
    }
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

namespace {
// The reduced set of `src` for keep_every = k, from the cache when the source is unchanged.
template <class T, class Entry, class Make>
std::shared_ptr<const T> cached(std::vector<Entry>& cache, const std::shared_ptr<const T>& src,
                                std::size_t k, Make&& make) {
  for (auto& e : cache)
    if (!e.source.expired() && e.source.lock() == src && e.keep_every == k) return e.reduced;
  auto r = std::make_shared<const T>(make(*src, k));
  cache.erase(
      std::remove_if(cache.begin(), cache.end(), [](const Entry& e) { return e.source.expired(); }),
      cache.end());
  cache.push_back({src, k, r});
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
  std::size_t strands = 0, particles = 0;
  for (const auto& it : rs.strands)
    if (it.strands) strands += it.strands->num_strands();
  for (const auto& it : rs.particles)
    if (it.particles) particles += it.particles->size();
  const std::size_t ks = (strands + std::size_t(p.max_strands) - 1) / std::size_t(p.max_strands);
  if (ks > 1) {
    // Thinner hair drawn wider: the strands that remain cover about what all of them did (up to
    // three times the width).
    const double widen = std::min(3.0, std::sqrt(double(ks)));
    for (auto& it : rs.strands) {
      if (!it.strands) continue;
      it.strands = cached<geom::StrandSet>(m_strands, it.strands, ks, every_kth_strand);
      it.material.width_px *= widen;
    }
  }
  const std::size_t kp =
      (particles + std::size_t(p.max_particles) - 1) / std::size_t(p.max_particles);
  if (kp > 1)
    for (auto& it : rs.particles) {
      if (!it.particles) continue;
      it.particles = cached<geom::ParticleSet>(m_particles, it.particles, kp, every_kth_particle);
      it.radius *= std::sqrt(double(kp));
    }
}

}  // namespace follicle::render
