#include "follicle/sim/cylinder_table_daldegan1993.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"

namespace follicle::sim {

void CylinderBodyParams::validate() const {
  validate_params(*this, "cylinder_body");
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const std::string where = "cylinder_body.parts[" + std::to_string(k) + "]";
    validate_params(parts[k], where);
    if (!(parts[k].top > parts[k].bottom))
      fail_at(where, "band [{}, {}] is empty: expected bottom < top (fractions of the extent)",
              parts[k].bottom, parts[k].top);
  }
}

namespace {

// Orthonormalised copy of an axis; throws on a degenerate one.
CylinderAxis checked_axis(const CylinderAxis& in) {
  CylinderAxis a = in;
  if (!a.origin.allFinite() || !a.up.allFinite() || !a.reference.allFinite() ||
      !std::isfinite(a.y0) || !std::isfinite(a.y1))
    fail("cylinder table: axis has a non-finite value");
  const double nu = a.up.norm();
  if (!(nu > 1e-12)) fail("cylinder table: up direction has zero length");
  a.up /= nu;
  a.reference -= a.reference.dot(a.up) * a.up;
  const double nr = a.reference.norm();
  if (!(nr > 1e-9 * std::max(1.0, in.reference.norm())))
    fail(
        "cylinder table: reference direction is parallel to up; expected a direction across the "
        "axis");
  a.reference /= nr;
  if (!(a.y1 > a.y0))
    fail("cylinder table: height range [{}, {}] is empty; expected y0 < y1", a.y0, a.y1);
  return a;
}

}  // namespace

CylinderTable CylinderTable::build(const Context& ctx, const geom::TriMesh& mesh,
                                   const CylinderAxis& axis, int azimuth_samples,
                                   int height_samples, double margin) {
  const geom::MeshQuery query(mesh);
  return build(ctx, mesh, query, axis, azimuth_samples, height_samples, margin);
}

CylinderTable CylinderTable::build(const Context& ctx, const geom::TriMesh& mesh,
                                   const geom::MeshQuery& query, const CylinderAxis& axis,
                                   int azimuth_samples, int height_samples, double margin) {
  if (azimuth_samples < 3)
    fail("cylinder table: {} azimuth samples; expected at least 3", azimuth_samples);
  if (height_samples < 2)
    fail("cylinder table: {} height samples; expected at least 2", height_samples);
  if (!(margin >= 0.0) || !std::isfinite(margin))
    fail("cylinder table: margin {} m; expected a finite value >= 0", margin);
  if (mesh.positions.empty() || mesh.faces.empty()) fail("cylinder table: the mesh is empty");
  CylinderTable t;
  t.m_axis = checked_axis(axis);
  const CylinderAxis& a = t.m_axis;
  t.m_side = a.up.cross(a.reference);
  t.m_m = azimuth_samples;
  t.m_n = height_samples;
  t.m_margin = margin;
  // Rays start outside every vertex (largest distance from the axis, plus slack) and run towards
  // the axis: the first hit is the outermost crossing of the line from the axis.
  double reach = 0.0;
  for (const Vec3& p : mesh.positions) {
    const Vec3 d = p - a.origin;
    reach = std::max(reach, (d - d.dot(a.up) * a.up).norm());
  }
  reach = reach * 1.01 + 1e-3;
  const int m = t.m_m, n = t.m_n;
  const std::size_t stride = std::size_t(m + 1);
  t.m_r.assign(stride * std::size_t(n), 0.0f);
  t.m_nx.assign(t.m_r.size(), 0.0f);
  t.m_ny.assign(t.m_r.size(), 0.0f);
  t.m_nz.assign(t.m_r.size(), 0.0f);
  const bool smooth = mesh.has_normals();
  parallel_for(
      ctx, 0, std::size_t(n),
      [&](std::size_t j) {
        const double y = t.sample_height(int(j));
        const Vec3 centre = a.origin + y * a.up;
        for (int i = 0; i < m; ++i) {
          const double th = t.sample_azimuth(i);
          Vec3 dir = std::cos(th) * a.reference + std::sin(th) * t.m_side;
          geom::RayHit hit = query.intersect(centre + reach * dir, -dir, 0.0, reach);
          // A ray through a shared edge or vertex can slip between the triangles (the ray
          // caster is not watertight): retry with the line turned and lifted by a hair before
          // recording "no body".
          for (int k = 0; k < 4 && !hit.hit; ++k) {
            const double dth = (k % 2 ? -1e-6 : 1e-6) * (k < 2 ? 1 : 7);
            const Vec3 lift = ((k / 2) ? -1e-7 : 1e-7) * reach * a.up;
            dir = std::cos(th + dth) * a.reference + std::sin(th + dth) * t.m_side;
            hit = query.intersect(centre + lift + reach * dir, -dir, 0.0, reach);
          }
          if (!hit.hit) continue;
          const double r = reach - hit.distance;
          if (!(r > 0.0)) continue;
          Vec3 nrm = Vec3::Zero();
          const Vec3i& f = mesh.faces[std::size_t(hit.face)];
          if (smooth)
            nrm = hit.bary[0] * mesh.normals[std::size_t(f[0])] +
                  hit.bary[1] * mesh.normals[std::size_t(f[1])] +
                  hit.bary[2] * mesh.normals[std::size_t(f[2])];
          if (!(nrm.squaredNorm() > 1e-24)) nrm = mesh.face_normal(std::size_t(hit.face));
          if (!(nrm.squaredNorm() > 1e-24)) nrm = dir;
          nrm.normalize();
          if (nrm.dot(dir) < 0.0) nrm = -nrm;  // outward: along the ray leaving the solid
          const std::size_t k = j * stride + std::size_t(i);
          t.m_r[k] = float(r);
          t.m_nx[k] = float(nrm.x());
          t.m_ny[k] = float(nrm.y());
          t.m_nz[k] = float(nrm.z());
        }
      },
      1);
  // Column m repeats column 0; row maxima for the early rejection.
  for (int j = 0; j < n; ++j) {
    const std::size_t k0 = std::size_t(j) * stride;
    t.m_r[k0 + std::size_t(m)] = t.m_r[k0];
    t.m_nx[k0 + std::size_t(m)] = t.m_nx[k0];
    t.m_ny[k0 + std::size_t(m)] = t.m_ny[k0];
    t.m_nz[k0 + std::size_t(m)] = t.m_nz[k0];
  }
  t.m_sector_max.assign(std::size_t(n - 1) * kSectors, 0.0f);
  for (int j = 0; j + 1 < n; ++j)
    for (int sec = 0; sec < kSectors; ++sec) {
      // Columns whose cells meet the sector [sec, sec + 1) × 2π/16, one more either side.
      const int c0 = int(std::floor(double(sec) * m / kSectors)) - 1;
      const int c1 = int(std::ceil(double(sec + 1) * m / kSectors)) + 1;
      float mx = 0.0f;
      for (int jj = j; jj <= j + 1; ++jj)
        for (int c = c0; c <= c1; ++c) {
          const int i = ((c % m) + m) % m;
          mx = std::max(mx, t.m_r[std::size_t(jj) * stride + std::size_t(i)]);
        }
      // Slack for float rounding: the interpolated radius is a weighted mean of these samples.
      t.m_sector_max[std::size_t(j) * kSectors + std::size_t(sec)] = mx * (1.0f + 1e-6f);
      t.m_rmax = std::max(t.m_rmax, double(mx));
    }
  for (int c = 0; c < 3; ++c) {
    t.m_o[c] = float(a.origin[c]);
    t.m_u[c] = float(a.up[c]);
    t.m_a[c] = float(a.reference[c]);
    t.m_b[c] = float(t.m_side[c]);
  }
  t.m_y0 = float(a.y0);
  t.m_y1 = float(a.y1);
  t.m_inv_dy = float((n - 1) / (a.y1 - a.y0));
  t.m_marginf = float(margin);
  t.m_inv_dth = float(m / (2.0 * kPi));
  return t;
}

Vec3 CylinderTable::sample_point(int i, int j) const {
  const double th = sample_azimuth(i);
  return m_axis.origin + sample_height(j) * m_axis.up +
         radius(i, j) * (std::cos(th) * m_axis.reference + std::sin(th) * m_side);
}

double CylinderTable::coverage() const {
  if (m_m == 0) return 0.0;
  std::size_t hits = 0;
  for (int j = 0; j < m_n; ++j)
    for (int i = 0; i < m_m; ++i) hits += m_r[index(i, j)] > 0.0f ? 1 : 0;
  return double(hits) / double(std::size_t(m_m) * std::size_t(m_n));
}

bool CylinderTable::evaluate_near(float x, float z, float r2, float fj, int j, float extra,
                                  bool reject, Eval& e) const {
  const float tj = fj - float(j);
  float th = detail::fast_atan2(z, x);
  if (th < 0.0f) th += 6.28318548f;
  const float fi = th * m_inv_dth;
  int i = int(fi);
  if (i > m_m - 1) i = m_m - 1;
  if (i < 0) i = 0;
  const float ti = fi - float(i);
  const std::size_t k00 = std::size_t(j) * std::size_t(m_m + 1) + std::size_t(i);
  const std::size_t k10 = k00 + 1, k01 = k00 + std::size_t(m_m + 1), k11 = k01 + 1;
  const float w00 = (1.0f - ti) * (1.0f - tj), w10 = ti * (1.0f - tj);
  const float w01 = (1.0f - ti) * tj, w11 = ti * tj;
  const float r00 = m_r[k00], r10 = m_r[k10], r01 = m_r[k01], r11 = m_r[k11];
  const float wv = (r00 > 0.0f ? w00 : 0.0f) + (r10 > 0.0f ? w10 : 0.0f) +
                   (r01 > 0.0f ? w01 : 0.0f) + (r11 > 0.0f ? w11 : 0.0f);
  if (!(wv >= 0.5f)) return false;  // over a gap (radius-0 samples)
  e.over = true;
  e.rq = (w00 * r00 + w10 * r10 + w01 * r01 + w11 * r11) / wv;  // misses hold 0
  e.rp = std::sqrt(r2);
  const float grown = e.rq + m_marginf;
  e.inside = e.rp < grown + extra;
  if (!e.inside && reject) return false;
  float nx = w00 * m_nx[k00] + w10 * m_nx[k10] + w01 * m_nx[k01] + w11 * m_nx[k11];
  float ny = w00 * m_ny[k00] + w10 * m_ny[k10] + w01 * m_ny[k01] + w11 * m_ny[k11];
  float nz = w00 * m_nz[k00] + w10 * m_nz[k10] + w01 * m_nz[k01] + w11 * m_nz[k11];
  // Radial unit vector of P (on the axis itself: azimuth 0).
  float ex = 1.0f, ez = 0.0f;
  if (e.rp > 0.0f) {
    ex = x / e.rp;
    ez = z / e.rp;
  }
  const float erx = ex * m_a[0] + ez * m_b[0], ery = ex * m_a[1] + ez * m_b[1],
              erz = ex * m_a[2] + ez * m_b[2];
  const float nn = nx * nx + ny * ny + nz * nz;
  if (nn > 1e-12f) {
    const float inv = 1.0f / std::sqrt(nn);
    nx *= inv;
    ny *= inv;
    nz *= inv;
  } else {  // opposite normals cancelled: the radial direction
    nx = erx;
    ny = ery;
    nz = erz;
  }
  // (P - Q)·N with Q - P = (grown - r_p) e_r.
  e.c.depth_radial = grown - e.rp;
  e.c.distance = -(grown - e.rp) * (erx * nx + ery * ny + erz * nz);
  e.c.nx = nx;
  e.c.ny = ny;
  e.c.nz = nz;
  e.er[0] = erx;
  e.er[1] = ery;
  e.er[2] = erz;
  return e.inside;
}

// Built for plain x86-64 and for AVX2 (the same results; picked at load time by the CPU).
#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target_clones("avx2", "default")))
#endif
void CylinderTable::mark_candidates(const float* __restrict px, const float* __restrict py,
                                    const float* __restrict pz, std::size_t n, float extra,
                                    int* __restrict flag) const {
  if (m_n < 2) return;
  // The same arithmetic as locate(), branch-free (selects and integer ops), so it vectorises; a
  // point out of the height range reads a clamped row and is dropped by the range test.
  const float o0 = m_o[0], o1 = m_o[1], o2 = m_o[2], u0 = m_u[0], u1 = m_u[1], u2 = m_u[2];
  const float a0 = m_a[0], a1 = m_a[1], a2 = m_a[2], b0 = m_b[0], b1 = m_b[1], b2 = m_b[2];
  const float y0 = m_y0, y1 = m_y1, inv_dy = m_inv_dy, grow = m_marginf + extra;
  const int jmax = m_n - 2;
  const float* __restrict sec = m_sector_max.data();
  for (std::size_t k = 0; k < n; ++k) {
    const float dx = px[k] - o0, dy = py[k] - o1, dz = pz[k] - o2;
    const float y = dx * u0 + dy * u1 + dz * u2;
    const int in_range = int(y >= y0) & int(y <= y1);
    // Clamped to [0, jmax]; a NaN (bad input, reported by the solver) maps to row 0, never to an
    // out-of-range int conversion.
    const float fr = (y - y0) * inv_dy;
    const float fj = fr > 0.0f ? (fr < float(jmax) ? fr : float(jmax)) : 0.0f;
    const int j = int(fj);
    const float x = dx * a0 + dy * a1 + dz * a2;
    const float z = dx * b0 + dy * b1 + dz * b2;
    const float ax = std::fabs(x), az = std::fabs(z);
    // Quadrant q (0: x >= 0, z >= 0; 1: x < 0, z >= 0; 2: both < 0; 3: x >= 0, z < 0), then the
    // sub-sector from tan 22.5°, 45°, 67.5° of the angle from the quadrant's first axis.
    const int xn = int(x < 0.0f), zn = int(z < 0.0f), odd = xn ^ zn;
    const int q = 2 * zn + odd;
    const int se = int(az > 0.41421356f * ax) + int(az > ax) + int(az > 2.41421356f * ax);
    const int so = int(ax > 0.41421356f * az) + int(ax > az) + int(ax > 2.41421356f * az);
    const int sub = se + odd * (so - se);
    const float reach = sec[j * kSectors + 4 * q + sub] + grow;
    flag[k] |= in_range & int(x * x + z * z < reach * reach);
  }
}

void CylinderBody::mark_candidates(const float* px, const float* py, const float* pz, std::size_t n,
                                   float extra, int* flag) const {
  for (const CylinderTable& t : m_parts) t.mark_candidates(px, py, pz, n, extra, flag);
}

CylinderQuery CylinderTable::query(const Vec3& p, double extra) const {
  CylinderQuery q;
  q.part = 0;
  const Vec3 d = p - m_axis.origin;
  q.height = d.dot(m_axis.up);
  const double x = d.dot(m_axis.reference), z = d.dot(m_side);
  q.r_p = std::hypot(x, z);
  q.azimuth = std::atan2(z, x);
  if (q.azimuth < 0) q.azimuth += 2.0 * kPi;
  Eval e;
  // The decision is the single-precision one of contact(), so every caller agrees on it.
  q.inside = evaluate(float(p.x()), float(p.y()), float(p.z()), float(extra), false, e);
  q.over_body = e.over;
  if (!e.over) return q;
  q.r_q = e.rq;
  q.normal = Vec3(e.c.nx, e.c.ny, e.c.nz);
  const Vec3 er(e.er[0], e.er[1], e.er[2]);
  q.surface = p + (double(e.rq) + m_margin - double(e.rp)) * er;
  q.distance = (p - q.surface).dot(q.normal);
  q.closest = p - q.distance * q.normal;
  return q;
}

CylinderQuery CylinderBody::query(const Vec3& p, double extra) const {
  CylinderQuery best;
  bool best_inside = false;
  for (std::size_t k = 0; k < m_parts.size(); ++k) {
    CylinderQuery q = m_parts[k].query(p, extra);
    if (!q.over_body) continue;
    q.part = int(k);
    const bool better = best.part < 0 || (q.inside && !best_inside) ||
                        (q.inside == best_inside && q.distance < best.distance);
    if (better) {
      best = q;
      best_inside = q.inside;
    }
  }
  if (best.part < 0) {
    best = CylinderQuery{};
    best.part = -1;
  }
  return best;
}

bool CylinderBody::inside(const Vec3& p, double extra) const {
  CylinderContactF c;
  return contact(float(p.x()), float(p.y()), float(p.z()), float(extra), c) >= 0;
}

// ---- automatic bands and the body builder --------------------------------------------------

namespace {

struct Frame {
  Vec3 up, front, side;
};

Frame make_frame(const Vec3& up, const Vec3& front) {
  if (!up.allFinite() || !front.allFinite()) fail("cylinder body: up or front is not finite");
  Frame f;
  const double nu = up.norm();
  if (!(nu > 1e-12)) fail("cylinder body: up direction has zero length");
  f.up = up / nu;
  f.front = front - front.dot(f.up) * f.up;
  const double nf = f.front.norm();
  if (!(nf > 1e-9 * std::max(1.0, front.norm())))
    fail("cylinder body: front direction is parallel to up; expected a horizontal direction");
  f.front /= nf;
  f.side = f.up.cross(f.front);
  return f;
}

}  // namespace

std::vector<CylinderPartParams> auto_cylinder_parts(const geom::TriMesh& mesh, const Vec3& up,
                                                    const Vec3& front, double overlap) {
  if (mesh.positions.empty()) fail("cylinder body: the mesh is empty");
  const Frame fr = make_frame(up, front);
  double hmin = std::numeric_limits<double>::infinity(), hmax = -hmin;
  for (const Vec3& p : mesh.positions) {
    hmin = std::min(hmin, p.dot(fr.up));
    hmax = std::max(hmax, p.dot(fr.up));
  }
  const double H = hmax - hmin;
  if (!(H > 0)) fail("cylinder body: the mesh is flat along up");
  // Lateral extent per slice (vertices binned by height; empty slices copy their neighbour).
  constexpr int B = 64;
  std::vector<double> lo(B, std::numeric_limits<double>::infinity()), hi(B, -lo[0]);
  for (const Vec3& p : mesh.positions) {
    const int b = std::clamp(int((p.dot(fr.up) - hmin) / H * B), 0, B - 1);
    const double s = p.dot(fr.side);
    lo[std::size_t(b)] = std::min(lo[std::size_t(b)], s);
    hi[std::size_t(b)] = std::max(hi[std::size_t(b)], s);
  }
  std::vector<double> w(B, -1.0);
  for (int b = 0; b < B; ++b)
    if (hi[std::size_t(b)] >= lo[std::size_t(b)])
      w[std::size_t(b)] = hi[std::size_t(b)] - lo[std::size_t(b)];
  for (int b = 1; b < B; ++b)
    if (w[std::size_t(b)] < 0) w[std::size_t(b)] = w[std::size_t(b - 1)];
  for (int b = B - 2; b >= 0; --b)
    if (w[std::size_t(b)] < 0) w[std::size_t(b)] = w[std::size_t(b + 1)];
  std::vector<double> ws(B);
  for (int b = 0; b < B; ++b) {
    const int b0 = std::max(0, b - 1), b1 = std::min(B - 1, b + 1);
    double s = 0;
    for (int k = b0; k <= b1; ++k) s += w[std::size_t(k)];
    ws[std::size_t(b)] = s / (b1 - b0 + 1);
  }
  auto frac = [&](int b) { return double(b) / B; };  // bottom of slice b
  // Scanning down: the head's widest slice is the first running maximum followed by a
  // narrowing below 80 % of it.
  int head = -1;
  double run = 0;
  int run_b = B - 1;
  for (int b = B - 1; b >= 0; --b) {
    if (ws[std::size_t(b)] > run) {
      run = ws[std::size_t(b)];
      run_b = b;
    } else if (ws[std::size_t(b)] < 0.8 * run) {
      head = run_b;
      break;
    }
  }
  std::vector<CylinderPartParams> parts;
  auto band = [&](const char* name, double b0, double b1) {
    CylinderPartParams p;
    p.name = name;
    p.bottom = std::clamp(b0, 0.0, 1.0);
    p.top = std::clamp(b1, 0.0, 1.0);
    parts.push_back(p);
  };
  if (head < 0) {
    band("body", 0.0, 1.0);
    return parts;
  }
  // The neck: the narrowest slice below the head before the width grows past 1.5× it.
  int neck = head;
  int shoulders = -1;
  for (int b = head; b >= 0; --b) {
    if (ws[std::size_t(b)] < ws[std::size_t(neck)]) neck = b;
    if (ws[std::size_t(b)] > 1.5 * ws[std::size_t(neck)]) {
      shoulders = b;
      break;
    }
  }
  const double yn = frac(neck) + 0.5 / B;
  if (shoulders < 0) {
    band("head", yn - overlap, 1.0);
    band("neck", 0.0, yn + overlap);
  } else {
    const double ys = frac(shoulders) + 1.0 / B;
    band("head", yn - overlap, 1.0);
    band("neck", ys - overlap, yn + overlap);
    band("trunk", 0.0, ys + overlap);
  }
  return parts;
}

CylinderBody build_cylinder_body(const Context& ctx, const geom::TriMesh& mesh, const Vec3& up,
                                 const Vec3& front, const CylinderBodyParams& params) {
  params.validate();
  if (mesh.positions.empty() || mesh.faces.empty()) fail("cylinder body: the mesh is empty");
  mesh.check("cylinder body mesh");
  const Frame fr = make_frame(up, front);
  const std::vector<CylinderPartParams> parts =
      params.parts.empty() ? auto_cylinder_parts(mesh, up, front, params.overlap) : params.parts;
  double hmin = std::numeric_limits<double>::infinity(), hmax = -hmin;
  for (const Vec3& p : mesh.positions) {
    hmin = std::min(hmin, p.dot(fr.up));
    hmax = std::max(hmax, p.dot(fr.up));
  }
  const double H = hmax - hmin;
  if (!(H > 0)) fail("cylinder body: the mesh is flat along up");
  const geom::MeshQuery query(mesh);
  CylinderBody body;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const double y0 = hmin + parts[k].bottom * H, y1 = hmin + parts[k].top * H;
    // Area-weighted centroid of the band's triangles (by their centroid's height), so a densely
    // meshed face does not pull the axis forward as a vertex mean would.
    Vec3 acc = Vec3::Zero();
    double area = 0;
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
      const Vec3i& F = mesh.faces[f];
      const Vec3 c = (mesh.positions[std::size_t(F[0])] + mesh.positions[std::size_t(F[1])] +
                      mesh.positions[std::size_t(F[2])]) /
                     3.0;
      const double h = c.dot(fr.up);
      if (h < y0 || h > y1) continue;
      const double A = mesh.face_area(f);
      acc += A * c;
      area += A;
    }
    if (!(area > 0))
      fail_at("cylinder_body.parts[" + std::to_string(k) + "]",
              "band [{}, {}] of the extent holds no triangle", parts[k].bottom, parts[k].top);
    const Vec3 c = acc / area;
    CylinderAxis axis;
    axis.origin = c - c.dot(fr.up) * fr.up;  // heights are measured from the plane through 0
    axis.up = fr.up;
    axis.reference = fr.front;
    axis.y0 = y0;
    axis.y1 = y1;
    body.add_part(parts[k].name,
                  CylinderTable::build(ctx, mesh, query, axis, params.azimuth_samples,
                                       params.height_samples, params.margin));
  }
  return body;
}

}  // namespace follicle::sim
