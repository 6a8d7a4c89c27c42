#pragma once
// Hair pores (Anjyo 1992 §2 step [α]): regions given in the hull's polar coordinates, sampled
// uniformly by area on the ellipsoid, then moved onto the real scalp.
#include <cstdint>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/types.hpp"
#include "follicle/hair/scalp.hpp"
#include "follicle/sim/ellipsoid.hpp"

namespace follicle::hair {

/// A pore region: azimuth φ and zenith θ ranges on the hull (conventions in sim/ellipsoid.hpp:
/// φ = 0 at the face, +π/2 at the head's left (+x), ±π at the back; θ = 0 at the crown).
/// An azimuth range with azimuth_min > azimuth_max wraps through ±π (e.g. the back: 2.5 .. -2.5).
struct PoreRegion {
  double azimuth_min = -kPi;   // [rad]
  double azimuth_max = kPi;    // [rad]
  double zenith_min = 0.0;     // [rad]
  double zenith_max = 1.9;     // [rad]
  double density = 2.0e5;      // [strands/m²] of hull surface (real scalps: ~2e6)
  double length = 0.2;         // [m] hair length before cutting
  double length_jitter = 0.0;  // relative: length *= 1 + jitter * U(-1, 1)

  template <class V>
  void visit(V&& v) {
    v("azimuth_min", azimuth_min,
      {"azimuth range start (0 = face, +pi/2 = left)", "rad", -kPi, kPi});
    v("azimuth_max", azimuth_max, {"azimuth range end", "rad", -kPi, kPi});
    v("zenith_min", zenith_min, {"zenith range start (0 = crown)", "rad", 0.0, kPi});
    v("zenith_max", zenith_max, {"zenith range end", "rad", 0.0, kPi});
    v("density", density, {"pores per square metre of hull", "1/m^2", 0.0, 1e8});
    v("length", length, {"hair length", "m", 1e-4, 5.0});
    v("length_jitter", length_jitter, {"relative random length variation", "", 0.0, 0.99});
  }
  void validate() const;
  /// Whether a pore at (azimuth, zenith) lies in the region (handles the wrap through ±π).
  bool contains(double azimuth, double zenith) const;
  /// Solid angle [sr] of the region in the hull's parametric angles.
  double solid_angle() const;
};

/// Sampled roots, structure of arrays.
struct HairRoots {
  std::vector<Vec3> position;    // on the scalp (or on the hull when no scalp is given) [m]
  std::vector<Vec3> direction;   // unit initial beam direction: the hull normal (Fig. 4a)
  std::vector<Vec2> polar;       // (azimuth, zenith) of the pore on the hull
  std::vector<double> length;    // [m]
  std::vector<uint32_t> region;  // index of the PoreRegion the root came from
  std::size_t size() const { return position.size(); }
  void append(const HairRoots& o);
};

/// Samples round(area * density) pores per region, uniformly by hull area (rejection sampling on
/// the parametric sphere), each from its own random stream (seed, region, index), so the result
/// does not depend on the thread count. With `scalp`, every root moves to the closest point of
/// the real head surface.
HairRoots sample_pores(const Context& ctx, const sim::Ellipsoid& hull,
                       const std::vector<PoreRegion>& regions, uint64_t seed,
                       const ClosestPointFn& scalp = {});

/// Area [m²] of a region on the hull (Monte Carlo with a fixed seed, 1e-3 relative accuracy).
double region_area(const sim::Ellipsoid& hull, const PoreRegion& region);

}  // namespace follicle::hair
