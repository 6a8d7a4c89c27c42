#pragma once
// StrandSet: many polylines (hair strands) stored as structure-of-arrays. Strand s owns points
// [offsets[s], offsets[s+1]). Point 0 of a strand is its root. Per-point radius [m] and linear
// RGB colour are optional (empty or one entry per point).
#include <cstdint>
#include <string>
#include <vector>

#include "follicle/core/types.hpp"

namespace follicle::geom {

struct StrandSet {
  std::vector<uint32_t> offsets{0};  // size num_strands()+1
  std::vector<Vec3f> points;         // [m]
  std::vector<float> radius;         // [m], empty or points.size()
  std::vector<Vec3f> color;          // linear RGB in [0,1], empty or points.size()

  std::size_t num_strands() const { return offsets.size() - 1; }
  std::size_t num_points() const { return points.size(); }
  uint32_t strand_begin(std::size_t s) const { return offsets[s]; }
  uint32_t strand_size(std::size_t s) const { return offsets[s + 1] - offsets[s]; }
  /// Appends a strand; radius/colour arrays are extended only if already in use.
  void add_strand(const std::vector<Vec3f>& pts);
  void clear() { *this = StrandSet{}; }
  /// Throws follicle::Error when offsets are inconsistent or a coordinate is not finite.
  void check(const std::string& where) const;
};

/// ParticleSet: points with a per-particle radius, colour and (for hair particles) a unit
/// direction t_i. Used for particle hair (Bando 2003), SPH air and debug splats.
struct ParticleSet {
  std::vector<Vec3f> positions;   // [m]
  std::vector<Vec3f> directions;  // unit tangent, empty or positions.size()
  std::vector<float> radius;      // [m], empty or positions.size()
  std::vector<Vec3f> color;       // linear RGB, empty or positions.size()
  std::vector<float> opacity;     // [0,1], empty or positions.size()

  std::size_t size() const { return positions.size(); }
  void check(const std::string& where) const;
};

}  // namespace follicle::geom
