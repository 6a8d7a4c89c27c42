#pragma once
// Cylindrical radius tables for hair-body collision, Daldegan, Magnenat Thalmann, Kurihara,
// Thalmann 1993 §3.2 (Fig. 3). A body part is described in cylindrical coordinates (r, θ, y)
// about an axis; a table holds, for m azimuths × n heights, the radius where the line from the
// axis meets the body, with the surface normal there. A point P is inside the part when the
// interpolated radius r_q at P's azimuth and height exceeds P's radius r_p.
//
// Our choices where the paper is silent (docs/equations/daldegan_dynamics.md):
// - The line from the axis may cross the surface several times (ears, concave parts, closed
//   meshes seen from an off-centre axis). We record the OUTERMOST crossing (cast from outside
//   towards the axis, first hit): the part is then the solid swept by the table's radii, which
//   closes concavities conservatively; hair never ends up inside a pocket of the real surface.
//   Its normal is oriented along the outward ray.
// - Samples whose line meets nothing get radius 0 ("no body there"). Bilinear interpolation uses
//   only the corners with a body, renormalised; a point is over the body only when those corners
//   carry at least half of the bilinear weight (the boundary of a gap lies halfway between a hit
//   and a miss sample), so a radius-0 region never reports inside.
// - T ("the nearest surface point, approximated using linear interpolation"): Q is the point at
//   radius r_q (+ margin) on P's horizontal ray (the paper's corresponding point, same azimuth
//   and height); T is P projected onto the tangent plane at Q with the interpolated normal N,
//   i.e. T = P - ((P - Q)·N) N, exact for a planar patch and better than Q where the surface is
//   not parallel to the axis (the top of the head).
// - Points outside the height range [y0, y1] are never inside.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/spatial_embree.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::sim {

/// The cylindrical frame of one part: a point on the axis, the axis direction `up`, the
/// direction of azimuth 0 (`reference`, made orthogonal to up) and the height range, measured
/// along up from `origin`. Azimuth grows from reference towards up × reference.
struct CylinderAxis {
  Vec3 origin = Vec3::Zero();
  Vec3 up = Vec3::UnitY();
  Vec3 reference = Vec3::UnitZ();
  double y0 = 0.0;  // [m]
  double y1 = 1.0;  // [m]
};

/// Result of a query (double precision, for callers outside the hot loops).
struct CylinderQuery {
  bool over_body = false;  // within the height range and over a sampled body (radius > 0)
  bool inside = false;     // r_p < r_q + margin + extra
  int part = -1;           // index of the part in a CylinderBody (0 for a single table)
  double r_p = 0, azimuth = 0, height = 0;  // P in cylindrical coordinates ([m], [rad], [m])
  double r_q = 0;                           // interpolated table radius [m] (without margin)
  double distance = 0;          // (P - Q)·N [m]: the signed "PT" of (5), negative inside
  Vec3 surface = Vec3::Zero();  // Q: radius r_q + margin on P's ray
  Vec3 closest = Vec3::Zero();  // T: P projected onto the tangent plane at Q
  Vec3 normal = Vec3::Zero();   // N: interpolated unit outward normal
};

/// Result of the single-precision contact query used by the solvers' inner loops.
struct CylinderContactF {
  float distance = 0;            // (P - Q)·N, Q at radius r_q + margin
  float nx = 0, ny = 0, nz = 0;  // N
  float depth_radial = 0;        // r_q + margin - r_p (> 0 inside)
};

class CylinderTable {
 public:
  CylinderTable() = default;
  /// Samples `mesh` (with `query` built on it) about `axis`: azimuth_samples × height_samples
  /// lines, rows at y0 + (y1 - y0) j / (n - 1), columns at azimuth 2π i / m. Parallel over rows,
  /// deterministic. `margin` [m] grows the part radially in every query. Throws follicle::Error
  /// for a bad axis, fewer than 3 azimuths or 2 heights.
  static CylinderTable build(const Context& ctx, const geom::TriMesh& mesh,
                             const geom::MeshQuery& query, const CylinderAxis& axis,
                             int azimuth_samples, int height_samples, double margin = 0.0);
  /// Same, building the ray-cast structure itself.
  static CylinderTable build(const Context& ctx, const geom::TriMesh& mesh,
                             const CylinderAxis& axis, int azimuth_samples, int height_samples,
                             double margin = 0.0);

  /// Full query of P (same frame as the mesh). `extra` widens the inside test only.
  CylinderQuery query(const Vec3& p, double extra = 0.0) const;
  bool inside(const Vec3& p, double extra = 0.0) const { return query(p, extra).inside; }
  /// Single-precision test for the inner loops: true when P is within the height range, over
  /// the body and r_p < r_q + margin + extra; then fills `c`. Cheap rejections first (height,
  /// largest radius of the cell's rows) before the azimuth.
  inline bool contact(float px, float py, float pz, float extra, CylinderContactF& c) const;

  /// Everything evaluate() finds about a point (single precision).
  struct Eval {
    bool over = false, inside = false;
    float rp = 0, rq = 0;
    float er[3] = {0, 0, 0};  // radial unit vector of P
    CylinderContactF c;       // filled when over the body and (reject: inside)
  };
  /// The one implementation behind contact() and query(): `reject` enables the early exits
  /// (then Eval is complete only when the result is true); `e` must be freshly constructed.
  inline bool evaluate(float px, float py, float pz, float extra, bool reject, Eval& e) const;
  /// The cheap part: height range, cylindrical coordinates, (reject:) the rows' largest radius.
  inline bool locate(float px, float py, float pz, float extra, bool reject, float& x, float& z,
                     float& r2, float& fj, int& j) const;
  /// The part of evaluate() after the cheap rejections (azimuth, interpolation), out of line.
  /// `e` must be freshly constructed.
  bool evaluate_near(float x, float z, float r2, float fj, int j, float extra, bool reject,
                     Eval& e) const;

  /// Batch pre-test for the inner loops: sets flag[k] = 1 for every point k that may be in
  /// contact (within the height range and not rejected by the largest radius of its cell rows'
  /// 22.5° sector), leaves the others; a vectorised loop. contact() is exact for the flagged.
  void mark_candidates(const float* px, const float* py, const float* pz, std::size_t n,
                       float extra, int* flag) const;

  /// Table radius (0 = no body) and outward normal at sample (i, j) (i azimuth, j height).
  double radius(int i, int j) const { return m_r[index(i, j)]; }
  Vec3 normal(int i, int j) const {
    const std::size_t k = index(i, j);
    return Vec3(m_nx[k], m_ny[k], m_nz[k]);
  }
  /// The sample point itself (on the axis' cylinder at radius(i, j)).
  Vec3 sample_point(int i, int j) const;
  double sample_azimuth(int i) const { return 2.0 * kPi * i / m_m; }
  double sample_height(int j) const { return m_axis.y0 + (m_axis.y1 - m_axis.y0) * j / (m_n - 1); }

  int azimuth_samples() const { return m_m; }
  int height_samples() const { return m_n; }
  double margin() const { return m_margin; }
  const CylinderAxis& axis() const { return m_axis; }  // up and reference orthonormalised
  double max_radius() const { return m_rmax; }
  /// Fraction of samples with a body (radius > 0).
  double coverage() const;

 private:
  std::size_t index(int i, int j) const {
    return std::size_t(j) * std::size_t(m_m + 1) + std::size_t(i);
  }
  CylinderAxis m_axis;
  Vec3 m_side = Vec3::UnitX();  // up × reference (azimuth π/2)
  int m_m = 0, m_n = 0;
  double m_margin = 0, m_rmax = 0;
  // Single-precision copies of the frame for contact().
  float m_o[3] = {0, 0, 0}, m_u[3] = {0, 1, 0}, m_a[3] = {0, 0, 1}, m_b[3] = {1, 0, 0};
  float m_y0 = 0, m_y1 = 1, m_inv_dy = 1, m_marginf = 0, m_inv_dth = 1;
  // Rows of m + 1 columns (column m repeats column 0, so the azimuth never wraps in a lookup).
  std::vector<float> m_r, m_nx, m_ny, m_nz;
  static constexpr int kSectors = 16;
  // [n - 1][16]: largest radius of rows j and j + 1 over the columns of each 22.5° sector (and
  // one column beyond either side).
  std::vector<float> m_sector_max;
};

/// One height band of a body, in fractions of the mesh's extent along up (0 = lowest vertex,
/// 1 = highest).
struct CylinderPartParams {
  std::string name = "part";
  double bottom = 0.0;
  double top = 1.0;
  template <class V>
  void visit(V&& v) {
    v("name", name, {"name of the part (head, neck, trunk...)"});
    v("bottom", bottom, {"bottom of the band, fraction of the extent along up", "", 0.0, 1.0});
    v("top", top, {"top of the band, fraction of the extent along up", "", 0.0, 1.0});
  }
};

struct CylinderBodyParams {
  int azimuth_samples = 64;  // m
  int height_samples = 64;   // n, per part
  double margin = 0.0;       // [m] every part grown radially by this much
  // Explicit bands; empty = automatic head / neck / trunk split (auto_cylinder_parts).
  std::vector<CylinderPartParams> parts;
  double overlap = 0.03;  // automatic bands reach this fraction of the extent into their
                          // neighbours, so the junctions are covered by both parts
  template <class V>
  void visit(V&& v) {
    v("azimuth_samples", azimuth_samples, {"azimuth samples m per part", "", 3, 4096});
    v("height_samples", height_samples, {"height samples n per part", "", 2, 4096});
    v("margin", margin, {"radial clearance added to every part", "m", 0.0, 0.1});
    v("parts", parts, {"height bands (empty: automatic head/neck/trunk split)"});
    v("overlap", overlap,
      {"overlap of the automatic bands, fraction of the extent", "", 0.0, 0.25});
  }
  void validate() const;
};

/// Several parts (head, neck, trunk). A query reports the part where P is deepest.
class CylinderBody {
 public:
  CylinderBody() = default;
  void add_part(std::string name, CylinderTable table) {
    m_names.push_back(std::move(name));
    m_parts.push_back(std::move(table));
  }
  std::size_t num_parts() const { return m_parts.size(); }
  const CylinderTable& part(std::size_t i) const { return m_parts[i]; }
  const std::string& part_name(std::size_t i) const { return m_names[i]; }

  /// The query of the part with the smallest (most negative) distance among the parts where P
  /// is inside (r_p < r_q + margin + extra); when it is inside none, the over-body part with
  /// the smallest distance (part = -1 and inside = false when P is over no part).
  CylinderQuery query(const Vec3& p, double extra = 0.0) const;
  bool inside(const Vec3& p, double extra = 0.0) const;
  /// mark_candidates() of every part (flag[k] = 1 where some part may touch point k).
  /// (Defined in the .cpp after CylinderTable::mark_candidates: clang refuses a target_clones
  /// function used before its definition.)
  void mark_candidates(const float* px, const float* py, const float* pz, std::size_t n,
                       float extra, int* flag) const;
  /// contact() of the deepest part (inside the grown surface first, then the smallest
  /// distance); -1 when none.
  inline int contact(float px, float py, float pz, float extra, CylinderContactF& c) const;

 private:
  std::vector<CylinderTable> m_parts;
  std::vector<std::string> m_names;
};

/// The automatic bands of build_cylinder_body: the lateral width of the mesh (extent along
/// up × front) per height slice, smoothed; scanning down from the top, the head's widest slice,
/// then the narrowest slice below it (the neck, y_n); if the width below the neck grows past 1.5×
/// the neck's (shoulders, from y_s down), three bands: trunk [0, y_s], neck [y_s, y_n], head
/// [y_n, 1]; else head [y_n, 1] and neck [0, y_n]; when no narrowing is found, one band "body".
/// Bands are widened by `overlap` into their neighbours.
std::vector<CylinderPartParams> auto_cylinder_parts(const geom::TriMesh& mesh, const Vec3& up,
                                                    const Vec3& front, double overlap);

/// Builds one table per band: axis along `up` through the area-weighted centroid (in the
/// horizontal plane) of the band's triangles, azimuth 0 towards `front` (orthogonalised), height
/// range = the band. Works for any mesh orientation. Throws follicle::Error on bad parameters,
/// an empty mesh, up ∥ front or an empty band.
CylinderBody build_cylinder_body(const Context& ctx, const geom::TriMesh& mesh, const Vec3& up,
                                 const Vec3& front, const CylinderBodyParams& params);

// ---- inline single-precision query ------------------------------------------------------------

namespace detail {
/// atan2 by a minimax polynomial (|error| < 1e-5 rad), branch-light, for table lookups.
inline float fast_atan2(float y, float x) {
  const float ax = std::fabs(x), ay = std::fabs(y);
  const float mx = ax > ay ? ax : ay, mn = ax > ay ? ay : ax;
  const float a = mx > 0.0f ? mn / mx : 0.0f;
  const float s = a * a;
  float r =
      ((((-0.0117212f * s + 0.05265332f) * s - 0.11643287f) * s + 0.19354346f) * s - 0.33262347f) *
          s * a +
      0.99997726f * a;
  if (ay > ax) r = 1.57079637f - r;
  if (x < 0.0f) r = 3.14159274f - r;
  return y < 0.0f ? -r : r;
}
}  // namespace detail

inline bool CylinderTable::locate(float px, float py, float pz, float extra, bool reject, float& x,
                                  float& z, float& r2, float& fj, int& j) const {
  if (m_n < 2) return false;
  const float dx = px - m_o[0], dy = py - m_o[1], dz = pz - m_o[2];
  const float y = dx * m_u[0] + dy * m_u[1] + dz * m_u[2];
  if (!(y >= m_y0 && y <= m_y1)) return false;  // also rejects NaN
  fj = (y - m_y0) * m_inv_dy;
  j = int(fj);
  if (j > m_n - 2) j = m_n - 2;
  x = dx * m_a[0] + dy * m_a[1] + dz * m_a[2];
  z = dx * m_b[0] + dy * m_b[1] + dz * m_b[2];
  r2 = x * x + z * z;
  if (reject) {
    // No radius of the cell's two rows within P's sector of 22.5° reaches P: outside, without
    // the azimuth. Sector by comparisons: quadrant from the signs, then tan 22.5°, 45°, 67.5°.
    const float ax = std::fabs(x), az = std::fabs(z);
    const int q = z >= 0.0f ? (x >= 0.0f ? 0 : 1) : (x < 0.0f ? 2 : 3);
    const float u = (q & 1) ? az : ax, v = (q & 1) ? ax : az;  // v / u = tan(angle in quadrant)
    const int sub = int(v > 0.41421356f * u) + int(v > u) + int(v > 2.41421356f * u);
    const float reach =
        m_sector_max[std::size_t(j) * kSectors + std::size_t(4 * q + sub)] + m_marginf + extra;
    if (r2 >= reach * reach) return false;
  }
  return true;
}

inline bool CylinderTable::evaluate(float px, float py, float pz, float extra, bool reject,
                                    Eval& e) const {
  float x, z, r2, fj;
  int j;
  if (!locate(px, py, pz, extra, reject, x, z, r2, fj, j)) return false;
  return evaluate_near(x, z, r2, fj, j, extra, reject, e);
}

inline bool CylinderTable::contact(float px, float py, float pz, float extra,
                                   CylinderContactF& c) const {
  float x, z, r2, fj;
  int j;
  if (!locate(px, py, pz, extra, true, x, z, r2, fj, j)) return false;
  Eval e;
  if (!evaluate_near(x, z, r2, fj, j, extra, true, e)) return false;
  c = e.c;
  return true;
}

inline int CylinderBody::contact(float px, float py, float pz, float extra,
                                 CylinderContactF& c) const {
  // Parts where P is inside the (grown) surface itself come first, then the smallest distance.
  int best = -1;
  CylinderContactF t;
  for (std::size_t k = 0; k < m_parts.size(); ++k) {
    if (!m_parts[k].contact(px, py, pz, extra, t)) continue;
    const bool in = t.depth_radial > 0.0f, best_in = best >= 0 && c.depth_radial > 0.0f;
    if (best < 0 || (in && !best_in) || (in == best_in && t.distance < c.distance)) {
      c = t;
      best = int(k);
    }
  }
  return best;
}

}  // namespace follicle::sim
