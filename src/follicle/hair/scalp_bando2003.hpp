#pragma once
// Scalp parameterization for particle hair (Bando 2003 §3.3.1, Fig. 3.2 a-c): the scalp is
// trimmed from the head mesh by four Catmull-Rom curves (a closed loop: curve k ends where curve
// k+1 starts), embedded in the unit square D = [0,1]^2 by a piecewise-linear harmonic map
// (curve 0 -> v = 0, curve 1 -> u = 1, curve 2 -> v = 1, curve 3 -> u = 0), so that
// phi^-1(u, v) is the scalp point. The hair length map L(u, v) is a grayscale image scaled by
// the maximum hair length; root particles lie down to s = -s_r beneath the scalp.
#include <array>
#include <cstdint>
#include <vector>

#include "follicle/core/params.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/image/image.hpp"

namespace follicle::hair {

struct ScalpParams {
  double root_depth = 0.012;  // s_r [m], depth of the hair root (>= the particle spacing)
  double max_length = 0.25;   // [m] hair length where the length map is white
  int curve_samples = 64;     // samples per Catmull-Rom curve for trimming
  template <class V>
  void visit(V&& v) {
    v("root_depth", root_depth, ParamInfo{"root depth s_r beneath the scalp", "m", 0.0, 1.0});
    v("max_length", max_length, ParamInfo{"maximum hair length", "m", 1e-4, 10.0});
    v("curve_samples", curve_samples, ParamInfo{"samples per boundary curve", "", 4, 10000});
  }
  void validate() const { validate_params(*this, "scalp"); }
};

/// Four Catmull-Rom control polygons in the head mesh's frame [m]; each needs >= 2 points.
using ScalpCurves = std::array<std::vector<Vec3>, 4>;

/// A point of the scalp found from (u, v).
struct ScalpPoint {
  Vec3 position = Vec3::Zero();  // phi^-1(u, v)
  Vec3 normal = Vec3::UnitZ();   // unit scalp normal n(u, v)
};

class Scalp {
 public:
  /// Trims the scalp from `head` with the four curves and embeds it in the unit square.
  /// Throws follicle::Error (naming the curve/field) on malformed curves or when the trimmed
  /// region is empty or not a disk.
  static Scalp trim(const geom::TriMesh& head, const ScalpCurves& curves, const ScalpParams& p);

  /// Sets the hair length map: `map` values in [0, 1] (row 0 = v = 1), times max_length.
  /// An empty map means L = max_length everywhere. Throws on values outside [0, 1].
  void set_length_map(const image::ImageF& map);

  /// phi^-1(u, v) with its normal; (u, v) are clamped to D.
  ScalpPoint point(const Vec2& uv) const;
  /// L(u, v) [m].
  double length(const Vec2& uv) const;
  /// An area-uniform random (u, v) on the scalp.
  Vec2 sample_uv(Rng& rng) const;
  /// (u, v) of the scalp vertex nearest to a world point (e.g. the whirl).
  Vec2 nearest_uv(const Vec3& p) const;

  const geom::TriMesh& mesh() const { return m_mesh; }  // trimmed scalp, uvs = embedding
  const std::vector<int>& source_vertices() const { return m_source; }  // head vertex ids
  double root_depth() const { return m_params.root_depth; }
  double max_length() const { return m_params.max_length; }
  double area() const { return m_area; }
  const image::ImageF& length_map() const { return m_length_map; }

 private:
  void build_lookup();
  geom::TriMesh m_mesh;
  std::vector<int> m_source;
  ScalpParams m_params;
  image::ImageF m_length_map;
  double m_area = 0;
  std::vector<double> m_cum_area;
  int m_grid = 1;
  std::vector<std::vector<uint32_t>> m_cells;  // uv grid -> faces overlapping the cell
};

}  // namespace follicle::hair
