#include "follicle/geom/strands.hpp"

#include <cmath>

#include "follicle/core/error.hpp"

namespace follicle::geom {

void StrandSet::add_strand(const std::vector<Vec3f>& pts) {
  const bool with_radius = !radius.empty();
  const bool with_color = !color.empty();
  points.insert(points.end(), pts.begin(), pts.end());
  offsets.push_back(uint32_t(points.size()));
  if (with_radius) radius.resize(points.size(), radius.back());
  if (with_color) color.resize(points.size(), color.back());
}

void StrandSet::check(const std::string& where) const {
  if (offsets.empty() || offsets.front() != 0)
    fail_at(where, "strand offsets must start with 0 (got {} offsets)", offsets.size());
  for (std::size_t s = 0; s + 1 < offsets.size(); ++s)
    if (offsets[s + 1] < offsets[s])
      fail_at(where, "strand {} has decreasing offsets {} > {}", s, offsets[s], offsets[s + 1]);
  if (offsets.back() != points.size())
    fail_at(where, "last strand offset is {} but there are {} points", offsets.back(),
            points.size());
  if (!radius.empty() && radius.size() != points.size())
    fail_at(where, "{} radii for {} points, expected none or one per point", radius.size(),
            points.size());
  if (!color.empty() && color.size() != points.size())
    fail_at(where, "{} colours for {} points, expected none or one per point", color.size(),
            points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite()) fail_at(where, "strand point {} is not finite", i);
  for (std::size_t i = 0; i < radius.size(); ++i)
    if (!std::isfinite(radius[i]) || radius[i] < 0)
      fail_at(where, "strand point {} has radius {}, expected a finite value >= 0", i, radius[i]);
  for (std::size_t i = 0; i < color.size(); ++i)
    if (!color[i].allFinite()) fail_at(where, "strand point {} has a non-finite colour", i);
}

void ParticleSet::check(const std::string& where) const {
  const std::size_t n = positions.size();
  auto size_ok = [&](std::size_t m, const char* what) {
    if (m != 0 && m != n)
      fail_at(where, "{} {} for {} particles, expected none or one per particle", m, what, n);
  };
  size_ok(directions.size(), "directions");
  size_ok(radius.size(), "radii");
  size_ok(color.size(), "colours");
  size_ok(opacity.size(), "opacities");
  for (std::size_t i = 0; i < n; ++i)
    if (!positions[i].allFinite()) fail_at(where, "particle {} position is not finite", i);
  for (std::size_t i = 0; i < directions.size(); ++i)
    if (!directions[i].allFinite()) fail_at(where, "particle {} direction is not finite", i);
  for (std::size_t i = 0; i < radius.size(); ++i)
    if (!std::isfinite(radius[i]) || radius[i] < 0)
      fail_at(where, "particle {} has radius {}, expected a finite value >= 0", i, radius[i]);
  for (std::size_t i = 0; i < opacity.size(); ++i)
    if (!(opacity[i] >= 0 && opacity[i] <= 1))
      fail_at(where, "particle {} has opacity {}, expected [0, 1]", i, opacity[i]);
}

}  // namespace follicle::geom
