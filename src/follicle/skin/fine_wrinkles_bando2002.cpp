#include "follicle/skin/fine_wrinkles_bando2002.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <limits>
#include <map>
#include <memory>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/geom/harmonic_map.hpp"
#include "follicle/image/raster.hpp"
#include "follicle/skin/wrinkle_shape_bando2002.hpp"

namespace follicle::skin {

namespace {

constexpr float kLutLo = -6.0f;  // M(s) table range [kLutLo, 1]
constexpr int kLutN = 8192;

void check_uv_mesh(const geom::TriMesh& mesh, const char* what) {
  if (!mesh.has_uvs() || mesh.uv_faces.size() != mesh.faces.size())
    fail("{}: the body-part mesh needs texture coordinates (uvs and uv_faces)", what);
}

/// Position index of each uv vertex (first face corner that references it; -1 if unused).
std::vector<int> positions_of_uvs(const geom::TriMesh& mesh) {
  std::vector<int> pos(mesh.uvs.size(), -1);
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int t = mesh.uv_faces[f][c];
      if (t < 0 || std::size_t(t) >= mesh.uvs.size())
        fail("uv face {} refers to uv {} (have {})", f, t, mesh.uvs.size());
      if (pos[t] < 0) pos[t] = mesh.faces[f][c];
    }
  return pos;
}

Vec2 to_texel(const Vec2& uv, int n) {
  return Vec2(uv.x() * n, (1.0 - uv.y()) * n);
}
Vec2 dir_to_texel(const Vec2& d) {
  return Vec2(d.x(), -d.y());
}

/// floor and ceil to int for the texel loops: std::floor compiles to a library call on the
/// baseline x86-64 target (no SSE4.1 roundsd) and was a visible part of the furrow walk. Exact
/// for |x| < 1e9; larger values are clamped first (texel indices are far smaller).
inline int ifloor(double x) {
  x = x > -1e9 ? std::min(x, 1e9) : -1e9;  // NaN -> -1e9
  const int i = int(x);
  return i - int(x < double(i));
}
inline int iceil(double x) {
  x = x > -1e9 ? std::min(x, 1e9) : -1e9;  // NaN -> -1e9
  const int i = int(x);
  return i + int(x > double(i));
}

/// Barycentric coordinates (b1, b2) of p in triangle (a, b, c); returns false when degenerate.
bool barycentric(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c, double& b1,
                 double& b2) {
  const Vec2 e1 = b - a, e2 = c - a, q = p - a;
  const double det = e1.x() * e2.y() - e1.y() * e2.x();
  if (std::abs(det) < 1e-300) return false;
  b1 = (q.x() * e2.y() - q.y() * e2.x()) / det;
  b2 = (e1.x() * q.y() - e1.y() * q.x()) / det;
  return true;
}

/// Segment-segment intersection: parameter t along p->q of the crossing with a->b, or -1.
double segment_hit(const Vec2& p, const Vec2& q, const Vec2& a, const Vec2& b) {
  const Vec2 r = q - p, s = b - a;
  const double den = r.x() * s.y() - r.y() * s.x();
  if (std::abs(den) < 1e-18) return -1;  // parallel: treated as no crossing
  const Vec2 ap = a - p;
  const double tn = ap.x() * s.y() - ap.y() * s.x(), un = ap.x() * r.y() - ap.y() * r.x();
  // Early out without dividing, only where the test below surely fails (most grid candidates).
  const double sg = den > 0 ? 1.0 : -1.0, ad = std::abs(den) * (1.0 + 1e-12);
  if (sg * tn <= 0.0 || sg * un < 0.0 || sg * tn > ad || sg * un > ad) return -1;
  const double t = tn / den;
  const double u = un / den;
  if (t <= 1e-9 || t > 1.0 || u < 0.0 || u > 1.0) return -1;
  return t;
}

/// A working image of n values in 2 MiB pages where the kernel allows it (madvise): the furrow
/// walk reads and writes the 2048^2 images at scattered places, and with 4 KiB pages nearly
/// every texel row it touches was a TLB miss.
template <class T>
class BigBuffer {
 public:
  BigBuffer(std::size_t n, T fill) : m_n(n) {
    constexpr std::size_t kHuge = std::size_t(2) << 20;
    const std::size_t bytes =
        std::max<std::size_t>(kHuge, (n * sizeof(T) + kHuge - 1) / kHuge * kHuge);
    m_p.reset(static_cast<T*>(std::aligned_alloc(kHuge, bytes)));
    if (!m_p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(m_p.get(), bytes, MADV_HUGEPAGE);  // a hint; failure only costs speed
#endif
    std::fill(m_p.get(), m_p.get() + n, fill);
  }
  T* data() {
    return m_p.get();
  }
  const T* data() const {
    return m_p.get();
  }
  std::size_t size() const {
    return m_n;
  }
  T& operator[](std::size_t i) {
    return m_p.get()[i];
  }
  const T& operator[](std::size_t i) const {
    return m_p.get()[i];
  }

 private:
  struct Free {
    void operator()(T* p) const { std::free(p); }
  };
  std::unique_ptr<T, Free> m_p;
  std::size_t m_n;
};

/// Uniform grid of furrow segments in texel space for step 4's intersection test. Hand-written
/// (a tiny structure; geom's Embree BVH would have to be rebuilt after every segment). Each cell
/// keeps its own copy of the segments that touch it (no indirection: the lookups were cache
/// misses); a segment met in two cells is simply tested twice, which leaves the minimum alone.
class SegmentGrid {
 public:
  SegmentGrid(int size, double cell) : m_cell(cell) {
    m_n = std::max(1, int(std::ceil(size / cell)));
    m_cells.resize(std::size_t(m_n) * m_n);
  }
  void add(const Vec2& a, const Vec2& b, int furrow) {
    visit_cells(a, b, [&](std::vector<Seg>& c) { c.push_back({a, b, furrow}); });
  }
  /// Closest crossing of p->q with a segment of another furrow: t in (0, 1], or -1.
  double closest_hit(const Vec2& p, const Vec2& q, int furrow) {
    double best = -1;
    visit_cells(p, q, [&](std::vector<Seg>& c) {
      for (const Seg& sg : c) {
        if (sg.furrow == furrow) continue;
        const double t = segment_hit(p, q, sg.a, sg.b);
        if (t > 0 && (best < 0 || t < best)) best = t;
      }
    });
    return best;
  }

 private:
  struct Seg {
    Vec2 a, b;
    int furrow;
  };
  template <class F>
  void visit_cells(const Vec2& a, const Vec2& b, F&& f) {
    const int x0 = clampi(ifloor(std::min(a.x(), b.x()) / m_cell));
    const int x1 = clampi(ifloor(std::max(a.x(), b.x()) / m_cell));
    const int y0 = clampi(ifloor(std::min(a.y(), b.y()) / m_cell));
    const int y1 = clampi(ifloor(std::max(a.y(), b.y()) / m_cell));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) f(m_cells[std::size_t(y) * m_n + x]);
  }
  int clampi(int i) const { return std::clamp(i, 0, m_n - 1); }
  double m_cell;
  int m_n = 1;
  std::vector<std::vector<Seg>> m_cells;
};

/// Rows of the capsule of radius R around segment ab (the points within R of it), for the
/// stroke rasterizers below. Hand-written: the furrow walk draws two strokes per step and
/// scanning each stroke's bounding box was the hot spot of §2.6.2.
class CapsuleRows {
 public:
  CapsuleRows(const Vec2& a, const Vec2& b, double R) : m_a(a), m_b(b), m_R2(R * R) {
    const Vec2 ab = b - a;
    const double len = ab.norm();
    if (len > 0) {
      const Vec2 u = ab / len;
      // The band: 0 <= u.(p - a) <= len and |n.(p - a)| <= R with n = (-u.y, u.x); on a row
      // both are linear in x (constants per segment here, one multiply-add per row below).
      m_along = {u.x(), u.y(), 0.0, len, u.x() != 0.0 ? 1.0 / u.x() : 0.0};
      m_across = {-u.y(), u.x(), -R, R, u.y() != 0.0 ? -1.0 / u.y() : 0.0};
      m_band = true;
    }
  }
  /// Texels x0..x1 of the row whose centre line is y = yc that can hold a centre within R of
  /// the segment (one texel of margin for rounding), clipped to [0, w-1]; false when none.
  bool span(double yc, int w, int& x0, int& x1) const {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    auto disc = [&](const Vec2& c) {
      const double dy = yc - c.y(), q = m_R2 - dy * dy;
      if (q >= 0) {
        const double hw = std::sqrt(q);
        lo = std::min(lo, c.x() - hw);
        hi = std::max(hi, c.x() + hw);
      }
    };
    disc(m_a);
    disc(m_b);
    if (m_band) {
      const double dy = yc - m_a.y();
      double l = -std::numeric_limits<double>::infinity(), h = -l;
      for (const Linear* c : {&m_along, &m_across}) {
        // vmin <= slope (x - a.x) + off <= vmax, off = dy_coef * dy
        const double off = c->dy_coef * dy;
        if (c->slope == 0.0) {
          if (off < c->vmin || off > c->vmax) return lo <= hi && finish(lo, hi, w, x0, x1);
          continue;
        }
        double e0 = (c->vmin - off) * c->inv_slope, e1 = (c->vmax - off) * c->inv_slope;
        if (e0 > e1) std::swap(e0, e1);
        l = std::max(l, e0);
        h = std::min(h, e1);
      }
      if (l <= h) {
        lo = std::min(lo, m_a.x() + l);
        hi = std::max(hi, m_a.x() + h);
      }
    }
    return lo <= hi && finish(lo, hi, w, x0, x1);
  }

 private:
  struct Linear {
    double slope, dy_coef, vmin, vmax, inv_slope;
  };
  static bool finish(double lo, double hi, int w, int& x0, int& x1) {
    // Texel x has its centre at x + 0.5.
    x0 = std::max(0, ifloor(lo - 0.5) - 1);
    x1 = std::min(w - 1, iceil(hi - 0.5) + 1);
    return x0 <= x1;
  }
  Vec2 m_a, m_b;
  double m_R2;
  bool m_band = false;
  Linear m_along{}, m_across{};
};

/// The rows of a stroke of half-width r from a to b on a w x h texel grid (rows ylo .. yhi - 1
/// only): image/raster.cpp's box (r + 1 around the segment) intersected row by row with the
/// capsule of radius `reach` about the segment. Calls row(y, yc, x0, x1) for every row whose
/// span [x0, x1] is not empty, after prefetching that span two rows ahead in `grid` (the rows are
/// cache misses). Returns false (nothing visited) for non-finite input.
template <class T, class Row>
bool for_segment_rows(int w, int h, const Vec2& a, const Vec2& b, double r, double reach,
                      const T* grid, int ylo, int yhi, Row&& row) {
  if (!a.allFinite() || !b.allFinite() || !std::isfinite(r) || r < 0) return false;
  const int bx0 = std::max(0, ifloor(std::min(a.x(), b.x()) - r - 1));
  const int by0 = std::max(ylo, ifloor(std::min(a.y(), b.y()) - r - 1));
  const int bx1 = std::min(w - 1, iceil(std::max(a.x(), b.x()) + r + 1));
  const int by1 = std::min({h - 1, yhi - 1, iceil(std::max(a.y(), b.y()) + r + 1)});
  if (bx0 > bx1 || by0 > by1) return true;
  const CapsuleRows cap(a, b, reach);
  for (int y = by0; y <= by1; ++y) {
    const double yc = y + 0.5;
    int x0, x1;
    if (!cap.span(yc, w, x0, x1)) continue;
    x0 = std::max(x0, bx0);
    x1 = std::min(x1, bx1);
    if (y + 2 <= by1) {
      const T* ahead = grid + (std::size_t(y) + 2) * std::size_t(w);
      __builtin_prefetch(ahead + x0);
      __builtin_prefetch(ahead + x1);
    }
    row(y, yc, x0, x1);
  }
  return true;
}

/// The texels of image::draw_line(img, a, b, width, ...) with their coverage: calls
/// f(texel index, cov) for every texel with cov > 0, with the same distance and coverage
/// arithmetic as image/raster.cpp, so blending gives the same values texel for texel. Visits in
/// each row only the texels of the stroke's capsule instead of draw_line's whole bounding box,
/// and does not allocate. Returns false (nothing visited) for non-finite input.
/// Only rows ylo .. yhi - 1 are visited (a band of the image; default all).
template <class F>
bool visit_segment(int w, int h, const Vec2& a, const Vec2& b, double width, const float* img,
                   F&& f, int ylo = 0, int yhi = std::numeric_limits<int>::max()) {
  const double r = 0.5 * width;
  const Vec2 ab = b - a;
  const double l2 = ab.squaredNorm();
  // Coverage needs d < r + 0.5.
  const double out = r + 0.5 + 1e-6, out2 = out * out;
  return for_segment_rows(w, h, a, b, r, out, img, ylo, yhi, [&](int y, double yc, int x0, int x1) {
    const std::size_t rowi = std::size_t(y) * std::size_t(w);
    for (int x = x0; x <= x1; ++x) {
      // image/raster.cpp seg_dist and coverage, the same expressions.
      const Vec2 p(x + 0.5, yc);
      double t = l2 > 0 ? (p - a).dot(ab) / l2 : 0.0;
      t = std::clamp(t, 0.0, 1.0);
      const double d2 = (p - (a + t * ab)).squaredNorm();
      if (d2 >= out2) continue;  // d >= r + 0.5: no coverage (no sqrt)
      const double d = std::sqrt(d2);
      const double cov = std::clamp(0.5 + r - d, 0.0, 1.0);
      if (cov > 0) f(rowi + std::size_t(x), cov);
    }
  });
}

/// Occupancy (§2.6.2 step 6): sets occ[i] = 1 where image::draw_line(.., width, 1.0f,
/// Blend::Max) would write a coverage float(cov) >= 0.5. Texels clearly inside (d <= r - 1e-6)
/// or outside (d >= r + 1e-6) are decided from the squared distance; the ones in between by
/// the exact coverage expression, so the result is the same texel for texel.
void mark_segment(int n, const Vec2& a, const Vec2& b, double width, uint8_t* occ) {
  const double r = 0.5 * width, m = 1e-6;
  const double in2 = r > m ? (r - m) * (r - m) : -1.0, out2 = (r + m) * (r + m);
  const Vec2 ab = b - a;
  const double l2 = ab.squaredNorm();
  for_segment_rows(n, n, a, b, r, r + m, occ, 0, n, [&](int y, double yc, int x0, int x1) {
    uint8_t* row = occ + std::size_t(y) * std::size_t(n);
    // Texel x: true when it lies in the core (d <= r - 1e-6); otherwise marks it by the exact
    // coverage rule.
    auto core = [&](int x) {
      const Vec2 p(x + 0.5, yc);
      double t = l2 > 0 ? (p - a).dot(ab) / l2 : 0.0;
      t = std::clamp(t, 0.0, 1.0);
      const double d2 = (p - (a + t * ab)).squaredNorm();
      if (d2 <= in2) return true;
      if (d2 < out2) {
        const double cov = std::clamp(0.5 + r - std::sqrt(d2), 0.0, 1.0);  // raster.cpp's
        if (float(cov) * 1.0f >= 0.5f) row[x] = 1;
      }
      return false;
    };
    // The core is a capsule, which is convex: its texel centres on a row form one run. Scan in
    // from both ends of the span to the run and fill it without evaluating it.
    int xl = x0;
    while (xl <= x1 && !core(xl)) ++xl;
    if (xl > x1) return;
    int xr = x1;
    while (xr > xl && !core(xr)) --xr;
    std::memset(row + xl, 1, std::size_t(xr - xl + 1));
  });
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// §2.6.1 direction field

std::vector<Vec2> interpolate_direction_field(const geom::TriMesh& mesh,
                                              const std::vector<DirectionKey>& keys,
                                              const std::string& where) {
  check_uv_mesh(mesh, "direction field");
  const std::vector<int> pos = positions_of_uvs(mesh);
  // The spring graph is the texture-space mesh (uv vertices, uv faces) with the 3D geometry of
  // the surface: the same energy as the mapping's distortion minimization (§2.4).
  geom::TriMesh g;
  g.positions.resize(mesh.uvs.size(), Vec3::Zero());
  for (std::size_t t = 0; t < pos.size(); ++t)
    if (pos[t] >= 0) g.positions[t] = mesh.positions[pos[t]];
  g.faces = mesh.uv_faces;
  std::map<int, Vec2> fixed;  // later keys override earlier ones (seam keys come last)
  for (std::size_t k = 0; k < keys.size(); ++k) {
    const std::string at = fmt::format("{}[{}]", where, k);
    const DirectionKey& key = keys[k];
    if (key.vertex < 0 || std::size_t(key.vertex) >= mesh.uvs.size())
      fail_at(at, "vertex {} out of range: the mesh has {} uv vertices", key.vertex,
              mesh.uvs.size());
    if (!key.direction.allFinite()) fail_at(at, "direction is not finite");
    if (key.direction.norm() > 1.0 + 1e-9)
      fail_at(at, "direction magnitude {} is out of range: expected [0, 1]", key.direction.norm());
    fixed[key.vertex] = key.direction;
  }
  if (fixed.empty()) return std::vector<Vec2>(mesh.uvs.size(), Vec2::Zero());
  std::vector<int> fv;
  Eigen::MatrixXd vals(Eigen::Index(fixed.size()), 2);
  for (const auto& [v, d] : fixed) {
    vals.row(Eigen::Index(fv.size())) = d.transpose();
    fv.push_back(v);
  }
  const Eigen::MatrixXd x = geom::harmonic_interpolate(g, fv, vals);
  std::vector<Vec2> out(mesh.uvs.size());
  for (std::size_t t = 0; t < out.size(); ++t) {
    Vec2 d = x.row(Eigen::Index(t)).transpose();
    if (d.norm() > 1.0) d.normalize();
    out[t] = d;
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// (2.5)

FurrowParameters furrow_parameters(double m, double r_rand) {
  m = std::clamp(m, 0.0, 1.0);
  FurrowParameters p;
  p.N = int(std::floor(30.0 - 20.0 * m));  // (2.5) N = floor(30 - 20m)
  p.theta = (0.5 - 0.4 * m) * r_rand;      // (2.5) theta = (0.5 - 0.4m) r
  p.D = 4.0 + 2.0 * m;                     // (2.5) D = 4 + 2m
  p.I = 1.0 - m * m;                       // (2.5) I = 1 - m^2
  p.Wh = 2.0 * m;                          // (2.5) W_h = 2m
  p.Wo = 1.0 + 12.0 * m;                   // (2.5) W_o = 1 + 12m
  return p;
}

// ---------------------------------------------------------------------------------------------
// Texture-space rasterization

TexelMap rasterize_texture_space(const Context& ctx, const geom::TriMesh& mesh, int resolution) {
  check_uv_mesh(mesh, "rasterize_texture_space");
  if (resolution < 1 || resolution > 16384) fail("texture resolution {} out of range", resolution);
  const int n = resolution;
  TexelMap tm;
  tm.size = n;
  const std::size_t np = std::size_t(n) * n;
  const std::size_t nf = mesh.uv_faces.size();
  std::vector<std::array<Vec2, 3>> tp(nf);
  double area3 = 0, area_t = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    for (int c = 0; c < 3; ++c) tp[f][c] = to_texel(mesh.uvs[mesh.uv_faces[f][c]], n);
    const Vec2 e1 = tp[f][1] - tp[f][0], e2 = tp[f][2] - tp[f][0];
    area_t += 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
    const Vec3i& F = mesh.faces[f];
    area3 += 0.5 * (mesh.positions[F[1]] - mesh.positions[F[0]])
                       .cross(mesh.positions[F[2]] - mesh.positions[F[0]])
                       .norm();
  }
  tm.metres_per_texel = area_t > 0 ? std::sqrt(area3 / area_t) : 0.0;
  // Per face: the barycentric coordinates as affine functions of the texel centre (two
  // multiply-adds per texel instead of a solve) and the texel bounding box.
  struct Face {
    double a1x, a1y, a1c, a2x, a2y, a2c;
    int x0, x1, y0, y1;
  };
  std::vector<Face> fc(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    const auto& t = tp[f];
    Face& F = fc[f];
    const Vec2 e1 = t[1] - t[0], e2 = t[2] - t[0];
    const double det = e1.x() * e2.y() - e1.y() * e2.x();
    if (std::abs(det) < 1e-300) {  // degenerate in texture space: covers no texel
      F.y0 = 1;
      F.y1 = 0;
      continue;
    }
    // b1 = (q x e2) / det, b2 = (e1 x q) / det with q = p - t0.
    F.a1x = e2.y() / det;
    F.a1y = -e2.x() / det;
    F.a1c = -(F.a1x * t[0].x() + F.a1y * t[0].y());
    F.a2x = -e1.y() / det;
    F.a2y = e1.x() / det;
    F.a2c = -(F.a2x * t[0].x() + F.a2y * t[0].y());
    F.y0 = std::max(0, ifloor(std::min({t[0].y(), t[1].y(), t[2].y()}) - 0.5));
    F.y1 = std::min(n - 1, iceil(std::max({t[0].y(), t[1].y(), t[2].y()}) - 0.5));
    F.x0 = std::max(0, ifloor(std::min({t[0].x(), t[1].x(), t[2].x()}) - 0.5));
    F.x1 = std::min(n - 1, iceil(std::max({t[0].x(), t[1].x(), t[2].x()}) - 0.5));
  }
  // Bands of rows in parallel; within a band faces are drawn in order (last face wins on shared
  // edges), so the result does not depend on the thread count. Each band also clears its rows
  // (first touch on the thread that writes them) and lists its covered texels.
  tm.tri.resize(np);
  tm.b1.resize(np);
  tm.b2.resize(np);
  constexpr int kBand = 32;
  const int bands = (n + kBand - 1) / kBand;
  std::vector<std::vector<uint32_t>> band_cov;
  band_cov.resize(std::size_t(bands));
  parallel_for(
      ctx, 0, std::size_t(bands),
      [&](std::size_t band) {
        const int ylo = int(band) * kBand, yhi = std::min(n, ylo + kBand);
        const std::size_t i0 = std::size_t(ylo) * n, i1 = std::size_t(yhi) * n;
        std::fill(tm.tri.begin() + i0, tm.tri.begin() + i1, -1);
        std::fill(tm.b1.begin() + i0, tm.b1.begin() + i1, 0.f);
        std::fill(tm.b2.begin() + i0, tm.b2.begin() + i1, 0.f);
        for (std::size_t f = 0; f < nf; ++f) {
          const Face& F = fc[f];
          const int y0 = std::max(ylo, F.y0), y1 = std::min(yhi - 1, F.y1);
          for (int y = y0; y <= y1; ++y) {
            const double yc = y + 0.5;
            const double r1 = F.a1y * yc + F.a1c, r2 = F.a2y * yc + F.a2c;
            for (int x = F.x0; x <= F.x1; ++x) {
              const double xc = x + 0.5;
              const double b1 = F.a1x * xc + r1, b2 = F.a2x * xc + r2;
              const double eps = -1e-9;
              if (b1 < eps || b2 < eps || 1.0 - b1 - b2 < eps) continue;
              const std::size_t i = std::size_t(y) * n + x;
              tm.tri[i] = int32_t(f);
              tm.b1[i] = float(b1);
              tm.b2[i] = float(b2);
            }
          }
        }
        auto& cov = band_cov[band];
        for (std::size_t i = i0; i < i1; ++i)
          if (tm.tri[i] >= 0) cov.push_back(uint32_t(i));
      },
      1);
  std::size_t total = 0;
  for (const auto& c : band_cov) total += c.size();
  tm.covered.reserve(total);
  for (const auto& c : band_cov) tm.covered.insert(tm.covered.end(), c.begin(), c.end());
  return tm;
}

double resolve_unit_texels(const FineWrinkleParams& p, const TexelMap& texels) {
  if (p.unit_mm > 0 && texels.metres_per_texel > 0)
    return p.unit_mm * 1e-3 / texels.metres_per_texel;
  return p.unit_texels;
}

// ---------------------------------------------------------------------------------------------
// §2.6.2 furrow carving

namespace {

class Carver {
 public:
  Carver(const geom::TriMesh& mesh, const TexelMap& tm, const std::vector<Vec2>& dirs, double unit,
         uint64_t seed, HeightField& out, const SeamInit* init)
      : m_mesh(mesh),
        m_tm(tm),
        m_dirs(dirs),
        m_unit(unit),
        m_seed(seed),
        m_out(out),
        m_init(init),
        m_grid(tm.size, std::max(8.0, std::ceil(6.0 * unit))),
        m_h(std::size_t(tm.size) * tm.size, 1.0f),
        m_occ(std::size_t(tm.size) * tm.size, 1) {
    const int n = tm.size;
    out.height.resize(n, n, 1.0f);  // initialized in white (carved in m_h, copied at the end)
    // The occupancy image is only ever compared with 0.5 (and binarized at the end), and
    // max(old, c) >= 0.5 iff old >= 0.5 or c >= 0.5: it is kept as one byte per texel (a quarter
    // of the memory traffic of the float image), 1 = occupied.
    // 1 (forbidden) where the mesh is not mapped
    for (uint32_t i : tm.covered) m_occ[i] = 0;
    if (init) {
      const std::size_t np = std::size_t(n) * n;
      if (init->locked.size() != np || init->height.width() != n)
        fail("seam init does not match the texture resolution {}", n);
      for (std::size_t i = 0; i < np; ++i)
        if (init->locked[i]) {
          m_h[i] = init->height.data()[i];
          m_occ[i] = 1;
        }
      const Polylines& pl = init->furrows;
      for (std::size_t k = 0; k < pl.size(); ++k)
        for (uint32_t j = pl.offsets[k]; j + 1 < pl.offsets[k + 1]; ++j)
          m_grid.add(pl.points[j].cast<double>(), pl.points[j + 1].cast<double>(), -1);
    }
  }

  /// Direction d (texel space) at P by interpolating the three vertices of P's triangle (step 1);
  /// false when P is not on the mapped mesh.
  bool direction_at(const Vec2& P, Vec2& d) const {
    const int x = ifloor(P.x()), y = ifloor(P.y());
    if (!m_tm.inside(x, y)) return false;
    const int f = m_tm.tri[std::size_t(y) * m_tm.size + x];
    if (f < 0) return false;
    const Vec3i& T = m_mesh.uv_faces[f];
    const int n = m_tm.size;
    double b1, b2;
    if (!barycentric(P, to_texel(m_mesh.uvs[T[0]], n), to_texel(m_mesh.uvs[T[1]], n),
                     to_texel(m_mesh.uvs[T[2]], n), b1, b2))
      return false;
    const Vec2 du = (1 - b1 - b2) * m_dirs[T[0]] + b1 * m_dirs[T[1]] + b2 * m_dirs[T[2]];
    d = dir_to_texel(du);
    return true;
  }

  void prefetch_texel(const Vec2& P) const {
    const int x = ifloor(P.x()), y = ifloor(P.y());
    if (m_tm.inside(x, y)) __builtin_prefetch(m_tm.tri.data() + std::size_t(y) * m_tm.size + x);
  }

  bool occupied(const Vec2& P) const {
    const int x = ifloor(P.x()), y = ifloor(P.y());
    if (!m_tm.inside(x, y)) return true;
    return m_occ[std::size_t(y) * m_tm.size + x] != 0;
  }
  /// The carved height image and the binary occupancy image (§2.6.2 steps 5 and 6).
  /// §2.6.2 step 5 for every recorded stroke (image::draw_line with Blend::Min, texel for
  /// texel). Blending is order-dependent, so each band of rows applies all strokes that reach it
  /// in walk order: the result is the sequential one for any thread count.
  void carve_heights(const Context& ctx) {
    const int n = m_tm.size;
    constexpr int kBand = 64;
    const int bands = (n + kBand - 1) / kBand;
    std::vector<std::vector<uint32_t>> in_band;
    in_band.resize(std::size_t(bands));
    for (std::size_t k = 0; k < m_strokes.size(); ++k) {
      const Stroke& st = m_strokes[k];
      const double r = 0.5 * st.width;
      const int y0 = std::clamp(ifloor(std::min(st.a.y(), st.b.y()) - r - 1), 0, n - 1);
      const int y1 = std::clamp(iceil(std::max(st.a.y(), st.b.y()) + r + 1), 0, n - 1);
      for (int b = y0 / kBand; b <= y1 / kBand; ++b) in_band[std::size_t(b)].push_back(uint32_t(k));
    }
    float* hgt = m_h.data();
    parallel_for(
        ctx, 0, std::size_t(bands),
        [&](std::size_t b) {
          const int ylo = int(b) * kBand, yhi = std::min(n, ylo + kBand);
          for (uint32_t k : in_band[b]) {
            const Stroke& st = m_strokes[k];
            const float I = st.I;
            visit_segment(
                n, n, st.a, st.b, st.width, hgt,
                [&](std::size_t i, double cov) {
                  const float cf = float(cov);
                  hgt[i] = hgt[i] + cf * (std::min(hgt[i], I) - hgt[i]);
                },
                ylo, yhi);
          }
        },
        1);
  }

  void write_images(image::ImageF& height, image::ImageF& img) const {
    std::memcpy(height.data(), m_h.data(), m_h.size() * sizeof(float));
    img.resize(m_tm.size, m_tm.size, 0.0f);
    float* o = img.data();
    for (std::size_t i = 0; i < m_occ.size(); ++i) o[i] = m_occ[i] ? 1.0f : 0.0f;
  }
  bool locked(const Vec2& P) const {
    if (!m_init) return false;
    const int x = ifloor(P.x()), y = ifloor(P.y());
    if (!m_tm.inside(x, y)) return false;
    return m_init->locked[std::size_t(y) * m_tm.size + x] != 0;
  }

  /// Generates one furrow from P0 (both directions); false when nothing was carved.
  bool furrow(const Vec2& P0, int id) {
    Rng rng = Rng::stream(m_seed, uint64_t(id));
    auto& halves = m_halves;  // reused between furrows (no allocation per furrow)
    for (int side = 0; side < 2; ++side) {
      const double sign = side == 0 ? 1.0 : -1.0;  // the opposite field d -> -d
      std::vector<Vec2>& pts = halves[side];
      pts.clear();
      pts.push_back(P0);
      Vec2 P = P0;
      long n = std::numeric_limits<long>::max();  // n initialized to infinity
      for (;;) {
        Vec2 d;
        if (!direction_at(P, d)) break;  // step 1 (left the mapped mesh: stop)
        d *= sign;
        const double m = std::min(1.0, d.norm());
        if (m <= 0.0) break;
        const FurrowParameters fp = furrow_parameters(m, rng.uniform(-1.0, 1.0));
        n = std::min<long>(n, fp.N);                                  // step 2
        const double c = std::cos(fp.theta), s = std::sin(fp.theta);  // step 3
        const Vec2 dir = Vec2(c * d.x() - s * d.y(), s * d.x() + c * d.y()).normalized();
        Vec2 Q = P + dir * (fp.D * m_unit);  // step 4
        const double t = m_grid.closest_hit(P, Q, id);
        if (t > 0) {
          Q = P + t * (Q - P);
          n = 0;
        }
        prefetch_texel(Q);     // the next step's triangle lookup, loaded while carving
        if (locked(Q)) n = 0;  // seam strip: copied from the neighbour, do not grow into it
        // step 5: carve PQ on the height image with intensity I and width W_h. Nothing in the
        // walk reads the height image, so the strokes are recorded here and carved afterwards,
        // in this order, by carve_heights() (parallel over row bands).
        const double wh = fp.Wh * m_unit;
        if (!P.allFinite() || !Q.allFinite() || !std::isfinite(wh) || wh < 0)
          image::draw_line(m_out.height, P, Q, wh, float(fp.I), image::Blend::Min);  // throws
        m_strokes.push_back({P, Q, wh, float(fp.I)});
        const int sz = m_tm.size;
        // step 6: record PQ on the occupancy image with value 1 and width W_o (Blend::Max of
        // the coverage; only whether it reaches 0.5 matters, see the constructor)
        mark_segment(sz, P, Q, fp.Wo * m_unit, m_occ.data());
        m_grid.add(P, Q, id);
        pts.push_back(Q);
        ++m_out.segments;
        if (n == 0) break;  // step 7
        P = Q;
        --n;
      }
    }
    if (halves[0].size() < 2 && halves[1].size() < 2) return false;
    // One polyline: backward half reversed, then the forward half.
    for (std::size_t k = halves[1].size(); k-- > 1;)
      m_out.furrows.points.push_back(halves[1][k].cast<float>());
    for (const Vec2& q : halves[0]) m_out.furrows.points.push_back(q.cast<float>());
    m_out.furrows.offsets.push_back(uint32_t(m_out.furrows.points.size()));
    return true;
  }

 private:
  const geom::TriMesh& m_mesh;
  const TexelMap& m_tm;
  const std::vector<Vec2>& m_dirs;
  double m_unit;
  uint64_t m_seed;
  HeightField& m_out;
  const SeamInit* m_init;
  SegmentGrid m_grid;
  BigBuffer<float> m_h;                       // the height image while carving
  BigBuffer<uint8_t> m_occ;                   // occupancy: 1 = occupied (see the constructor)
  std::array<std::vector<Vec2>, 2> m_halves;  // the two halves of the current furrow
  struct Stroke {
    Vec2 a, b;
    double width;
    float I;
  };
  std::vector<Stroke> m_strokes;  // step 5's strokes in walk order (see carve_heights)
};

}  // namespace

HeightField carve_furrows(const Context& ctx, const geom::TriMesh& mesh, const TexelMap& texels,
                          std::vector<Vec2> directions, double unit_texels,
                          const FineWrinkleParams& p, uint64_t seed, const SeamInit* init) {
  p.validate();
  if (directions.size() != mesh.uvs.size())
    fail("carve_furrows: {} directions for {} uv vertices", directions.size(), mesh.uvs.size());
  if (!(unit_texels > 0) || !std::isfinite(unit_texels))
    fail("carve_furrows: unit_texels must be > 0, got {}", unit_texels);
  HeightField out;
  out.directions = std::move(directions);
  Carver carver(mesh, texels, out.directions, unit_texels, seed, out, init);
  int id = 0;
  if (!texels.covered.empty()) {
    // Random start points on the mapped mesh until many fail in a row.
    Rng pick = Rng::stream(seed ^ 0x5eedf00dULL, 0);
    int failures = 0;
    while (failures < p.max_failures) {
      const uint32_t i = texels.covered[pick.below(uint32_t(texels.covered.size()))];
      const Vec2 P(double(i % texels.size) + pick.uniform(),
                   double(i / texels.size) + pick.uniform());
      if (carver.occupied(P) || !carver.furrow(P, id)) {
        ++failures;
        ++out.failed_starts;
        continue;
      }
      ++id;
      ++out.random_furrows;
      failures = 0;
    }
    // Fill pass: every texel still free, in raster order.
    if (p.fill_pass) {
      for (uint32_t i : texels.covered) {
        const Vec2 P(double(i % texels.size) + 0.5, double(i / texels.size) + 0.5);
        if (carver.occupied(P)) continue;
        if (carver.furrow(P, id)) {
          ++id;
          ++out.fill_furrows;
        }
      }
    }
  }
  carver.carve_heights(ctx);
  // Binary occupancy, and the seam strip exactly as copied.
  carver.write_images(out.height, out.occupancy);
  if (init)
    for (std::size_t i = 0; i < init->locked.size(); ++i)
      if (init->locked[i]) out.height.data()[i] = init->height.data()[i];
  return out;
}

FineWrinkles generate_fine_wrinkles(const Context& ctx, const geom::TriMesh& mesh,
                                    const std::array<std::vector<DirectionKey>, 2>& keys,
                                    const FineWrinkleParams& p,
                                    const std::array<const SeamInit*, 2>& seams) {
  p.validate();
  FineWrinkles w;
  w.texels = rasterize_texture_space(ctx, mesh, p.resolution);
  w.unit_texels = resolve_unit_texels(p, w.texels);
  w.depth_m = p.depth_m;
  w.r = p.r;
  // The two fields are independent: one task each (direction field (§2.6.1) and carving).
  // A bad key of field 0 is reported before one of field 1, whichever task fails first.
  std::array<std::exception_ptr, 2> errors;
  parallel_for(
      ctx, 0, 2,
      [&](std::size_t k) {
        try {
          std::vector<DirectionKey> all = keys[k];
          if (seams[k])
            all.insert(all.end(), seams[k]->directions.begin(), seams[k]->directions.end());
          std::vector<Vec2> dirs =
              interpolate_direction_field(mesh, all, fmt::format("fine_wrinkles.fields[{}]", k));
          w.fields[k] =
              carve_furrows(ctx, mesh, w.texels, std::move(dirs), w.unit_texels, p,
                            Rng::stream(ctx.seed(), 0xF1E1D000ULL + k).next_u64(), seams[k]);
        } catch (...) {
          errors[k] = std::current_exception();
        }
      },
      1);
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
  return w;
}

// ---------------------------------------------------------------------------------------------
// §2.6.4 seams

SeamInit make_seam_init(const geom::TriMesh& mesh_a, const FineWrinkles& a, int field,
                        const geom::TriMesh& mesh_b, const TexelMap& texels_b,
                        const SharedStrip& strip) {
  if (field < 0 || field > 1) fail("make_seam_init: field must be 0 or 1, got {}", field);
  if (strip.faces_a.size() != strip.faces_b.size())
    fail("shared strip: {} faces in A, {} in B", strip.faces_a.size(), strip.faces_b.size());
  check_uv_mesh(mesh_a, "make_seam_init");
  check_uv_mesh(mesh_b, "make_seam_init");
  const HeightField& fa = a.fields[field];
  const int na = a.texels.size, nb = texels_b.size;
  SeamInit init;
  init.height.resize(nb, nb, 1.0f);
  init.locked.assign(std::size_t(nb) * nb, 0);
  std::vector<int> b_to_a(mesh_b.uv_faces.size(), -1), a_to_b(mesh_a.uv_faces.size(), -1);
  std::map<int, Vec2> dirs;
  for (std::size_t i = 0; i < strip.faces_a.size(); ++i) {
    const int fa_i = strip.faces_a[i], fb_i = strip.faces_b[i];
    if (fa_i < 0 || std::size_t(fa_i) >= mesh_a.uv_faces.size() || fb_i < 0 ||
        std::size_t(fb_i) >= mesh_b.uv_faces.size())
      fail("shared strip pair {}: face index out of range", i);
    b_to_a[fb_i] = fa_i;
    a_to_b[fa_i] = fb_i;
    // Directions: through the affine map uv_A -> uv_B of this triangle, magnitude kept.
    const Vec3i& TA = mesh_a.uv_faces[fa_i];
    const Vec3i& TB = mesh_b.uv_faces[fb_i];
    Eigen::Matrix2d EA, EB;
    EA << mesh_a.uvs[TA[1]] - mesh_a.uvs[TA[0]], mesh_a.uvs[TA[2]] - mesh_a.uvs[TA[0]];
    EB << mesh_b.uvs[TB[1]] - mesh_b.uvs[TB[0]], mesh_b.uvs[TB[2]] - mesh_b.uvs[TB[0]];
    if (std::abs(EA.determinant()) < 1e-300) continue;
    const Eigen::Matrix2d J = EB * EA.inverse();
    for (int c = 0; c < 3; ++c) {
      const Vec2 d = fa.directions[TA[c]];
      const Vec2 m = J * d;
      dirs[TB[c]] = m.norm() > 0 ? Vec2(m.normalized() * d.norm()) : Vec2::Zero();
    }
  }
  for (const auto& [v, d] : dirs) init.directions.push_back({v, d});
  // Heights: every B texel in a strip triangle samples A at the same barycentric point.
  auto sample_a = [&](const Vec2& p) {  // bilinear, texel space of A
    const double x = std::clamp(p.x() - 0.5, 0.0, double(na - 1));
    const double y = std::clamp(p.y() - 0.5, 0.0, double(na - 1));
    const int x0 = int(x), y0 = int(y), x1 = std::min(na - 1, x0 + 1),
              y1 = std::min(na - 1, y0 + 1);
    const double fx = x - x0, fy = y - y0;
    const auto& h = fa.height;
    return float((1 - fy) * ((1 - fx) * h.at(x0, y0) + fx * h.at(x1, y0)) +
                 fy * ((1 - fx) * h.at(x0, y1) + fx * h.at(x1, y1)));
  };
  for (uint32_t i : texels_b.covered) {
    const int fb_i = texels_b.tri[i];
    const int fa_i = b_to_a[fb_i];
    if (fa_i < 0) continue;
    const Vec3i& TA = mesh_a.uv_faces[fa_i];
    const double b1 = texels_b.b1[i], b2 = texels_b.b2[i];
    const Vec2 uva =
        (1 - b1 - b2) * mesh_a.uvs[TA[0]] + b1 * mesh_a.uvs[TA[1]] + b2 * mesh_a.uvs[TA[2]];
    init.height.data()[i] = sample_a(to_texel(uva, na));
    init.locked[i] = 1;
  }
  // Furrow segments of A inside the strip, mapped into B's texel space (obstacles for step 4).
  auto map_point = [&](const Vec2f& pa, Vec2& pb) {
    const int x = ifloor(pa.x()), y = ifloor(pa.y());
    if (!a.texels.inside(x, y)) return false;
    const int f = a.texels.tri[std::size_t(y) * na + x];
    if (f < 0 || a_to_b[f] < 0) return false;
    const Vec3i& TA = mesh_a.uv_faces[f];
    double b1, b2;
    if (!barycentric(pa.cast<double>(), to_texel(mesh_a.uvs[TA[0]], na),
                     to_texel(mesh_a.uvs[TA[1]], na), to_texel(mesh_a.uvs[TA[2]], na), b1, b2))
      return false;
    const Vec3i& TB = mesh_b.uv_faces[a_to_b[f]];
    pb = to_texel(
        (1 - b1 - b2) * mesh_b.uvs[TB[0]] + b1 * mesh_b.uvs[TB[1]] + b2 * mesh_b.uvs[TB[2]], nb);
    return true;
  };
  const Polylines& pl = fa.furrows;
  for (std::size_t k = 0; k < pl.size(); ++k)
    for (uint32_t j = pl.offsets[k]; j + 1 < pl.offsets[k + 1]; ++j) {
      Vec2 p, q;
      if (!map_point(pl.points[j], p) || !map_point(pl.points[j + 1], q)) continue;
      init.furrows.points.push_back(p.cast<float>());
      init.furrows.points.push_back(q.cast<float>());
      init.furrows.offsets.push_back(uint32_t(init.furrows.points.size()));
    }
  return init;
}

// ---------------------------------------------------------------------------------------------
// §2.6.4 animation: shrinkage (2.3) and modulation (2.4)

FineWrinkleAnimator::FineWrinkleAnimator(const geom::TriMesh& rest, const FineWrinkles& w)
    : m_size(w.texels.size),
      m_mpt(w.texels.metres_per_texel),
      m_depth(w.depth_m),
      m_r(w.r),
      m_texels(w.texels) {
  check_uv_mesh(rest, "FineWrinkleAnimator");
  m_pos_of_uv = positions_of_uvs(rest);
  m_uv_faces = rest.uv_faces;
  const std::size_t nuv = rest.uvs.size();
  // uv vertex -> incident faces
  std::vector<std::vector<int>> inc(nuv);
  for (std::size_t f = 0; f < rest.uv_faces.size(); ++f)
    for (int c = 0; c < 3; ++c) inc[rest.uv_faces[f][c]].push_back(int(f));
  for (int k = 0; k < 2; ++k) {
    const auto& dirs = w.fields[k].directions;
    if (dirs.size() != nuv)
      fail("FineWrinkleAnimator: field {} has {} directions for {} uvs", k, dirs.size(), nuv);
    m_sides[k].assign(nuv, {});
    for (std::size_t v = 0; v < nuv; ++v) {
      const Vec2 d = dirs[v];
      if (d.norm() <= 0) continue;
      const Vec2 dp = Vec2(-d.y(), d.x()).normalized();  // perpendicular to the wrinkle
      for (int side = 0; side < 2; ++side) {
        const Vec2 ray = side == 0 ? dp : Vec2(-dp);
        for (int f : inc[v]) {
          const Vec3i& T = rest.uv_faces[f];
          const int c = T[0] == int(v) ? 0 : T[1] == int(v) ? 1 : 2;
          const int c2 = (c + 1) % 3, c3 = (c + 2) % 3;
          const Vec2 e2 = rest.uvs[T[c2]] - rest.uvs[v], e3 = rest.uvs[T[c3]] - rest.uvs[v];
          Eigen::Matrix2d E;
          E << e2, e3;
          if (std::abs(E.determinant()) < 1e-300) continue;
          const Vec2 ab = E.inverse() * ray;                 // ray = a e2 + b e3
          if (ab.x() < -1e-12 || ab.y() < -1e-12) continue;  // the ray leaves through another face
          const Vec3i& F = rest.faces[f];
          Side s;
          s.v2 = F[c2];
          s.v3 = F[c3];
          s.a = float(std::max(0.0, ab.x()));
          s.b = float(std::max(0.0, ab.y()));
          const Vec3& x1 = rest.positions[F[c]];
          s.l2 = float((rest.positions[F[c2]] - x1).norm());
          s.l3 = float((rest.positions[F[c3]] - x1).norm());
          if (s.l2 <= 0 || s.l3 <= 0 || s.a + s.b <= 0) continue;
          m_sides[k][v][side] = s;
          break;
        }
      }
    }
    m_depth_img[k].resize(std::size_t(m_size) * m_size);
    const auto& h = w.fields[k].height.storage();
    for (std::size_t i = 0; i < h.size(); ++i) m_depth_img[k][i] = 1.0f - h[i];
  }
  m_lut.resize(kLutN + 1);
  for (int i = 0; i <= kLutN; ++i)
    m_lut[i] = float(amplitude_modulation(kLutLo + (1.0 - kLutLo) * i / kLutN, m_r));
  const std::size_t np = std::size_t(m_size) * m_size;
  m_blank.assign(np, 0.0f);
  m_act_row.assign(std::size_t(m_size) + 1, 0);
  for (std::size_t y = 0; y < std::size_t(m_size); ++y) {
    for (std::size_t i = y * m_size, e = i + m_size; i < e; ++i) {
      const int f = m_texels.tri[i];
      if (f < 0) continue;
      m_blank[i] = -0.0f;  // -(M(sa) * 0 + M(sb) * 0)
      if (m_depth_img[0][i] == 0.0f && m_depth_img[1][i] == 0.0f) continue;
      m_act_idx.push_back(uint32_t(i));
      m_act_face.push_back(f);
      m_act_b1.push_back(m_texels.b1[i]);
      m_act_b2.push_back(m_texels.b2[i]);
      m_act_d0.push_back(m_depth_img[0][i]);
      m_act_d1.push_back(m_depth_img[1][i]);
    }
    m_act_row[y + 1] = uint32_t(m_act_idx.size());
  }
}

void FineWrinkleAnimator::shrinkage(const Context& ctx, const std::vector<Vec3>& x,
                                    std::array<std::vector<float>, 2>& s) const {
  const std::size_t nuv = m_pos_of_uv.size();
  for (int k = 0; k < 2; ++k) s[k].resize(nuv);
  parallel_for(
      ctx, 0, nuv,
      [&](std::size_t v) {
        const int p1 = m_pos_of_uv[v];
        for (int k = 0; k < 2; ++k) {
          double sum = 0;
          int cnt = 0;
          for (const Side& sd : m_sides[k][v]) {
            if (sd.v2 < 0) continue;
            const double t2 = (x[sd.v2] - x[p1]).norm() / sd.l2;
            const double t3 = (x[sd.v3] - x[p1]).norm() / sd.l3;
            if (!(t2 > 0) || !(t3 > 0)) continue;
            sum += triangle_shrinkage(sd.a, sd.b, t2, t3);  // (2.3)
            ++cnt;
          }
          s[k][v] = cnt ? float(sum / cnt) : 0.0f;  // average of the +d_p and -d_p sides
        }
      },
      1024);
}

void FineWrinkleAnimator::shrinkage_texture(const Context& ctx, const std::vector<float>& s,
                                            image::ImageF& out) const {
  out.resize(m_size, m_size, 0.0f);
  float* o = out.data();
  parallel_for(
      ctx, 0, std::size_t(m_size),
      [&](std::size_t y) {
        for (std::size_t i = y * m_size, e = i + m_size; i < e; ++i) {
          const int f = m_texels.tri[i];
          if (f < 0) continue;
          const Vec3i& T = m_uv_faces[f];
          const float b1 = m_texels.b1[i], b2 = m_texels.b2[i];
          o[i] = (1 - b1 - b2) * s[T[0]] + b1 * s[T[1]] + b2 * s[T[2]];
        }
      },
      16);
}

void FineWrinkleAnimator::modulate(const Context& ctx, const std::array<std::vector<float>, 2>& s,
                                   image::ImageF& relief) const {
  if (relief.width() != m_size || relief.height() != m_size) relief.resize(m_size, m_size, 0.0f);
  float* o = relief.data();
  const uint32_t* row_begin = m_act_row.data();
  const uint32_t* idx = m_act_idx.data();
  const int32_t* tri = m_act_face.data();
  const float* B1 = m_act_b1.data();
  const float* B2 = m_act_b2.data();
  const float* d0 = m_act_d0.data();
  const float* d1 = m_act_d1.data();
  const float* blank = m_blank.data();
  const float* lut = m_lut.data();
  const float scale = float(kLutN) / (1.0f - kLutLo);
  const double r = m_r;
  // M(s) from a table with linear interpolation (max error ~1e-7 for r = 0.5); outside the
  // table range the exact (2.4).
  auto M = [&](float sv) -> float {
    const float u = (sv - kLutLo) * scale;
    if (u < 0.0f || u >= float(kLutN)) return float(amplitude_modulation(sv, r));
    const int j = int(u);
    const float f = u - float(j);
    return lut[j] + f * (lut[j + 1] - lut[j]);
  };
  const float* s0 = s[0].data();
  const float* s1 = s[1].data();
  const Vec3i* faces = m_uv_faces.data();
  const std::size_t n = std::size_t(m_size);
  parallel_for(
      ctx, 0, n,
      [&](std::size_t y) {
        std::copy(blank + y * n, blank + (y + 1) * n, o + y * n);  // 0 unmapped, -0 no furrow
        for (uint32_t k = row_begin[y], e = row_begin[y + 1]; k < e; ++k) {
          const Vec3i& T = faces[tri[k]];
          const float b1 = B1[k], b2 = B2[k], b0 = 1.0f - b1 - b2;
          const float sa = b0 * s0[T[0]] + b1 * s0[T[1]] + b2 * s0[T[2]];
          const float sb = b0 * s1[T[0]] + b1 * s1[T[1]] + b2 * s1[T[2]];
          o[idx[k]] = -(M(sa) * d0[k] + M(sb) * d1[k]);  // (2.4) per field, superimposed
        }
      },
      8);
}

void FineWrinkleAnimator::rest_relief(const Context& ctx, image::ImageF& relief) const {
  std::array<std::vector<float>, 2> zero;
  for (auto& z : zero) z.assign(m_pos_of_uv.size(), 0.0f);
  modulate(ctx, zero, relief);
}

}  // namespace follicle::skin
