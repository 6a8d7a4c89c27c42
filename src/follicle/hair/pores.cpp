#include "follicle/hair/pores.hpp"

#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/rng.hpp"

namespace follicle::hair {

void PoreRegion::validate() const {
  validate_params(*this, "pore_region");
  if (zenith_min > zenith_max)
    fail_at("pore_region.zenith_min", "zenith_min {} must not exceed zenith_max {}", zenith_min,
            zenith_max);
}

static double azimuth_span(const PoreRegion& r) {
  return r.azimuth_min <= r.azimuth_max ? r.azimuth_max - r.azimuth_min
                                        : 2 * kPi - (r.azimuth_min - r.azimuth_max);
}

bool PoreRegion::contains(double az, double ze) const {
  if (ze < zenith_min || ze > zenith_max) return false;
  if (azimuth_min <= azimuth_max) return az >= azimuth_min && az <= azimuth_max;
  return az >= azimuth_min || az <= azimuth_max;
}

double PoreRegion::solid_angle() const {
  return azimuth_span(*this) * (std::cos(zenith_min) - std::cos(zenith_max));
}

void HairRoots::append(const HairRoots& o) {
  position.insert(position.end(), o.position.begin(), o.position.end());
  direction.insert(direction.end(), o.direction.begin(), o.direction.end());
  polar.insert(polar.end(), o.polar.begin(), o.polar.end());
  length.insert(length.end(), o.length.begin(), o.length.end());
  region.insert(region.end(), o.region.begin(), o.region.end());
}

namespace {

// Uniform direction in the region's (φ, cos θ) box: uniform in solid angle.
Vec3 sample_direction(Rng& rng, const PoreRegion& r, double& az, double& ze) {
  az = r.azimuth_min + rng.uniform() * azimuth_span(r);
  if (az > kPi) az -= 2 * kPi;
  const double c0 = std::cos(r.zenith_min), c1 = std::cos(r.zenith_max);
  const double c = c0 + rng.uniform() * (c1 - c0);
  ze = std::acos(std::clamp(c, -1.0, 1.0));
  const double s = std::sqrt(std::max(0.0, 1 - c * c));
  return Vec3(s * std::sin(az), c, s * std::cos(az));
}

}  // namespace

double region_area(const sim::Ellipsoid& hull, const PoreRegion& region) {
  Rng rng(12345);
  const int n = 20000;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    double az, ze;
    sum += hull.area_density(sample_direction(rng, region, az, ze));
  }
  return sum / n * region.solid_angle();
}

HairRoots sample_pores(const Context& ctx, const sim::Ellipsoid& hull,
                       const std::vector<PoreRegion>& regions, uint64_t seed,
                       const ClosestPointFn& scalp) {
  HairRoots all;
  const double gmax = hull.radii.prod() / hull.radii.minCoeff();  // max of area_density
  for (std::size_t ri = 0; ri < regions.size(); ++ri) {
    const PoreRegion& r = regions[ri];
    r.validate();
    const std::size_t n = std::size_t(std::llround(region_area(hull, r) * r.density));
    HairRoots part;
    part.position.resize(n);
    part.direction.resize(n);
    part.polar.resize(n);
    part.length.resize(n);
    part.region.assign(n, uint32_t(ri));
    parallel_for(
        ctx, 0, n,
        [&](std::size_t i) {
          Rng rng = Rng::stream(seed, (uint64_t(ri) << 40) + i);
          double az = 0, ze = 0;
          Vec3 q;
          for (int tries = 0; tries < 1000; ++tries) {  // rejection: accept with dA/dΩ / max
            q = sample_direction(rng, r, az, ze);
            if (rng.uniform() * gmax <= hull.area_density(q)) break;
          }
          const Vec3 p = hull.from_normalized(q);
          part.polar[i] = Vec2(az, ze);
          part.direction[i] = hull.normal(p);
          part.position[i] = scalp ? scalp(p).point : p;
          part.length[i] = r.length * (1.0 + r.length_jitter * rng.uniform(-1.0, 1.0));
        },
        64);
    all.append(part);
  }
  return all;
}

}  // namespace follicle::hair
