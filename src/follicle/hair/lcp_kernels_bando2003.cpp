#include "follicle/hair/lcp_kernels_bando2003.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "follicle/core/cpu.hpp"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define FOLLICLE_LCP_KERNELS_HAVE_AVX2 1
#endif

namespace follicle::hair::detail {

Vec3 hair_pair_force(const HairPairInputs& in, const HairPairConsts& c, uint32_t i, uint32_t j) {
  // Every expression below is mirrored operation for operation by the AVX2 kernel: change
  // both together (the test LcpKernels.BatchKernelGivesTheScalarBits checks the bits).
  const Vec3 xi = in.x[i], vi = in.v[i], ti = in.t[i];
  const double mi = in.mass[i], pi = in.p_rho2[i];
  const Vec3 xab = in.x[j] - xi;
  const double r = std::sqrt(xab.squaredNorm());
  const Vec3 xh = xab * (1.0 / r);
  double w, dw;
  c.kernel.w_dw(r, w, dw);
  const double mj = in.mass[j];
  // (3.16) SPH pressure force: -m_i m_j (P_i/rho_i^2 + P_j/rho_j^2) dW/dx_i,
  // dW/dx_i = -W' x^_ij
  Vec3 f = mi * mj * (pi + in.p_rho2[j]) * dw * xh;
  // Collision direction d_n = t_i x t_j. Near-colinear hairs: the paper prints
  // d_n = t_i - (t_i . x^_ij) x^_ij, which for side-by-side hairs (x_ij normal to t) is
  // t_i, i.e. ALONG the hair, contradicting "normal to the hair directions". We use the
  // part of x^_ij normal to t_i, d_n = x^_ij - (x^_ij . t_i) t_i, which the case needs.
  // Both are computed and one selected: neighbouring hairs are often near-colinear.
  const Vec3 dc = ti.cross(in.t[j]);
  const Vec3 dp = xh - xh.dot(ti) * ti;
  const double dc2 = dc.squaredNorm(), dp2 = dp.squaredNorm();
  const bool colinear = dc2 < c.eps2;
  const double dn2 = colinear ? dp2 : dc2;
  const Vec3 dn(colinear ? dp.x() : dc.x(), colinear ? dp.y() : dc.y(), colinear ? dp.z() : dc.z());
  if (dn2 >= 1e-18) {
    const Vec3 dh = dn * (1.0 / std::sqrt(dn2));
    const Vec3 vab = in.v[j] - vi;
    // d_c and d_f are given per reduced mass and per normalised kernel W/W(h,0) so one
    // setting works for any particle count: d_c(paper) = d_c mu / W(h, 0).
    const double muw = mi * mj / (mi + mj) * (w * c.inv_w0);
    const double vn = vab.dot(dh);
    // (3.17) only while the pair approaches along d_n
    const double dc_on = vn * xab.dot(dh) < 0 ? c.collision_damping : 0.0;
    f += dc_on * muw * vn * dh;
    f += c.friction_damping * muw * (vab - vn * dh);  // (3.18) d_f W (v_ij . d^_t) d^_t
  }
  return f;
}

Vec3 spring_force(const SpringInputs& in, std::size_t q) {
  // Loose spring with damping.
  const double r = in.conn_r[q];
  if (!(r > 0)) return Vec3::Zero();
  const Vec3 xh = in.conn_xh[q];
  const double ak = in.alpha[q] * in.k[q];  // current coefficient alpha_ij k_ij
  const double ext = r - in.l0[q];
  // Compressed springs are scaled: bending stiffness relative to tensile stiffness (§3.3.2).
  const double kk = ext < 0 ? ak * in.compression_scale : ak;
  const double cd = in.damp[q] * std::sqrt(kk);  // 2 zeta sqrt(k mu), critical damping ratio zeta
  return (kk * ext + cd * (in.v[in.pair_b[q]] - in.v[in.pair_a[q]]).dot(xh)) * xh;
}

namespace {

// Slots s0 .. s1 - 1, the interacting ones written from index out on; returns the index after
// the last one written.
std::size_t active_from(const Vec3* x, const uint32_t* pair_i, const uint32_t* pair_j,
                        const HairPairConsts& c, std::size_t s0, std::size_t s1, double* w,
                        uint32_t* act_i, uint32_t* act_j, uint32_t* act_slot, std::size_t out) {
  // Without branches on the distance: with the Verlet skin about a third of the listed pairs
  // lie beyond 2h, in no predictable order.
  std::size_t cnt = out;
  for (std::size_t s = s0; s < s1; ++s) {
    const uint32_t i = pair_i[s], j = pair_j[s];
    const double d2 = (x[j] - x[i]).squaredNorm();
    const double wk = c.kernel.w(std::sqrt(d2));
    const bool inside = d2 < c.r2max;
    w[s] = inside ? wk : 0.0;
    act_i[cnt] = i;
    act_j[cnt] = j;
    act_slot[cnt] = uint32_t(s);
    cnt += (inside && d2 > 0) ? 1 : 0;
  }
  return cnt;
}

std::size_t active_scalar(const Vec3* x, const uint32_t* pair_i, const uint32_t* pair_j,
                          const HairPairConsts& c, std::size_t s0, std::size_t s1, double* w,
                          uint32_t* act_i, uint32_t* act_j, uint32_t* act_slot) {
  return active_from(x, pair_i, pair_j, c, s0, s1, w, act_i, act_j, act_slot, s0) - s0;
}

void batch_scalar(const HairPairInputs& in, const HairPairConsts& c, const uint32_t* i,
                  const uint32_t* j, const uint32_t* slot, std::size_t count, Vec3* out) {
  for (std::size_t k = 0; k < count; ++k) out[slot[k]] = hair_pair_force(in, c, i[k], j[k]);
}

}  // namespace

namespace {
// The (3.15) term of one connection end: (A x^_ij, B) into out[0..3] (lcp_geometry_terms).
inline void direction_term(const Vec3& ti, const Vec3& xh, double ak, double c0, double s0,
                           double* out) {
  const double d = ti.dot(xh);
  const double pn = (ti - d * xh).norm();
  const double sp = pn > 1e-12 ? ak * s0 / pn : 0.0;
  const Vec3 a = (ak * c0 - sp * d) * xh;
  out[0] = a.x();
  out[1] = a.y();
  out[2] = a.z();
  out[3] = sp;
}
}  // namespace

void lcp_geometry_terms(const DirectionTermInputs& in, std::size_t q0, std::size_t q1, double* r,
                        Vec3* xh, double* term) {
  lcp_geometry(in.x, in.pair_a, in.pair_b, q0, q1, r, xh);
  for (std::size_t q = q0; q < q1; ++q) {
    double* o = term + 8 * q;
    if (!(r[q] > 0)) {
      std::fill(o, o + 8, 0.0);
      continue;
    }
    const double ak = in.alpha[q] * in.k[q];
    direction_term(in.t[in.pair_a[q]], xh[q], ak, in.cos_a[q], in.sin_a[q], o);
    direction_term(in.t[in.pair_b[q]], -1.0 * xh[q], ak, in.cos_b[q], in.sin_b[q], o + 4);
  }
}

void lcp_direction_sum(const DirectionSumInputs& in, std::size_t i0, std::size_t i1, Vec3* t) {
  // t_i^j = cos0 x^ + sin0 (t_i - (t_i . x^) x^) / |t_i - (t_i . x^) x^|, so
  // sum_j ak t_i^j = sum_j [A_j x^_j] + (sum_j B_j) t_i with the terms of lcp_geometry_terms.
  // A skipped end (|x_ab| not > 0) has zero terms; adding +0 to the sums (which start at +0 and
  // so never hold -0) changes no bit.
  for (std::size_t i = i0; i < i1; ++i) {
    if (in.root[i]) continue;
    const Vec3 ti = t[i];
    Vec3 acc = Vec3::Zero();
    double bsum = 0;
    for (uint32_t e = in.ts_off[i]; e < in.ts_off[i + 1]; ++e) {
      const double* o = in.term + 8 * std::size_t(in.ts_pairs[e]);
      acc += Vec3(o[0], o[1], o[2]);
      bsum += o[3];
    }
    for (uint32_t e = in.rs_off[i]; e < in.rs_off[i + 1]; ++e) {
      const double* o = in.term + 8 * std::size_t(in.rs_pairs[e]) + 4;
      acc += Vec3(o[0], o[1], o[2]);
      bsum += o[3];
    }
    acc += bsum * ti;
    const double an = acc.norm();
    if (an > 1e-300 && std::isfinite(an)) t[i] = acc / an;
  }
}

void lcp_springs(const SpringInputs& in, std::size_t q0, std::size_t q1, Vec3* spring_f) {
  for (std::size_t q = q0; q < q1; ++q) {
    if (in.alpha_r)  // (3.14): a is root-side (in N_r(b)), b is tip-side (in N_t(a))
      in.alpha[q] = 0.5 * (in.alpha_r[in.pair_b[q]] + in.alpha_t[in.pair_a[q]]);
    spring_f[q] = spring_force(in, q);
  }
}

void lcp_geometry(const Vec3* x, const uint32_t* pair_a, const uint32_t* pair_b, std::size_t q0,
                  std::size_t q1, double* r, Vec3* xh) {
  for (std::size_t q = q0; q < q1; ++q) {
    const Vec3 d = x[pair_b[q]] - x[pair_a[q]];  // x_ab
    r[q] = d.norm();
    xh[q] = d * (1.0 / r[q]);
  }
}

void lcp_gather(const GatherInputs& in, std::size_t i0, std::size_t i1, Vec3* force) {
  // A fixed order: deterministic for any thread count, and each pair's two contributions are
  // exact negations.
  for (std::size_t i = i0; i < i1; ++i) {
    Vec3 f = Vec3::Zero();
    for (uint32_t e = in.ts_off[i]; e < in.ts_off[i + 1]; ++e) f += in.spring_f[in.ts_pairs[e]];
    for (uint32_t e = in.rs_off[i]; e < in.rs_off[i + 1]; ++e) f -= in.spring_f[in.rs_pairs[e]];
    if (in.hh) {
      // The lists are sorted: entries below nbr_upper[i] are pairs evaluated by the other end.
      const uint32_t e0 = in.nbr_off[i], eu = in.nbr_upper[i], e1 = in.nbr_off[i + 1];
      for (uint32_t e = e0; e < eu; ++e) f -= in.pair_f[in.nbr_pair[e]];
      const uint32_t p0 = in.pair_off[i];  // pair slot of entry e >= eu: p0 + (e - eu)
      for (uint32_t e = eu; e < e1; ++e) f += in.pair_f[p0 + (e - eu)];
    }
    force[i] = f;
  }
}

void air_density(const AirInputs& in, std::size_t i0, std::size_t i1, double* rho) {
  const SphKernel& K = in.kernel;
  for (std::size_t i = i0; i < i1; ++i) {
    double r = in.mass * K.w(0.0);
    for (uint32_t e = in.off[i]; e < in.off[i + 1]; ++e)
      r += in.mass * K.w((in.x[in.nb[e]] - in.x[i]).norm());  // (3.1)
    rho[i] = r;
  }
}

namespace {
// The pressure term (3.16) of entry e of particle i added to s (nothing for r <= 0):
// -m_i m_j (P_i/rho_i^2 + P_j/rho_j^2) grad_i W, grad_i W = -W'(r) d/r.
inline void add_air_pressure(const AirInputs& in, std::size_t i, uint32_t e, Vec3& s) {
  const uint32_t j = in.nb[e];
  const Vec3 d = in.x[j] - in.x[i];
  const double r = d.norm();
  if (r <= 0) return;
  double w, dw;
  in.kernel.w_dw(r, w, dw);
  s += (in.mass * in.mass * (in.p_rho2[i] + in.p_rho2[j]) * dw / r) * d;
}
}  // namespace

void air_pressure(const AirInputs& in, std::size_t i0, std::size_t i1, Vec3* f) {
  for (std::size_t i = i0; i < i1; ++i) {
    Vec3 s = Vec3::Zero();
    for (uint32_t e = in.off[i]; e < in.off[i + 1]; ++e) add_air_pressure(in, i, e, s);
    f[i] = s;
  }
}

namespace {
// Mirrored operation for operation by avx2::air_drag (LcpKernels.AirDragKernelGivesTheScalarBits).
inline Vec3 air_drag_entry(const AirDragInputs& in, std::size_t i, uint32_t e) {
  const uint32_t h = in.nb[e];
  const double r = (in.x[i] - in.hair_x[h]).norm();
  return in.drag * in.mu[h] * (in.kernel.w(r) * in.inv_w0) * (in.v[i] - in.hair_v[h]);
}
}  // namespace

void air_drag(const AirDragInputs& in, std::size_t i0, std::size_t i1, Vec3* f) {
  for (std::size_t i = i0; i < i1; ++i)
    for (uint32_t e = in.off[i]; e < in.off[i + 1]; ++e) f[e] = air_drag_entry(in, i, e);
}

#ifdef FOLLICLE_LCP_KERNELS_HAVE_AVX2
FOLLICLE_AVX2_BEGIN
// AVX2 without FMA: no contraction, so each lane rounds exactly as the scalar code.
namespace avx2 {

// Hand-written SIMD (no library in the stack gathers from an array of Vec3): GCC vector
// extensions for the arithmetic, AVX2 gathers for the per-particle inputs.
typedef double V __attribute__((vector_size(32)));

inline V splat(double s) {
  return V{s, s, s, s};
}
// The masked form with every lane on: the plain _mm256_i32gather_pd starts from an undefined
// register, which GCC 12 reports as maybe-uninitialized.
// Four Vec3 (or four doubles) by index. Plain loads and a 4x4 transpose instead of
// vgatherdpd: three gathers of x, y, z measured 2.6x slower per Vec3 on the 2-core machine
// (AMD EPYC; 1.4 vs 0.55 ns per element, L2-resident and 2.4 MB arrays alike). The same values
// either way, so the results do not change.
struct V3 {
  V x, y, z;
};
inline V3 load3(const Vec3* base, const uint32_t* idx) {
  const double* p0 = base[idx[0]].data();
  const double* p1 = base[idx[1]].data();
  const double* p2 = base[idx[2]].data();
  const double* p3 = base[idx[3]].data();
  const __m256d a =
      _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p0)), _mm_loadu_pd(p2), 1);
  const __m256d b =
      _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p1)), _mm_loadu_pd(p3), 1);
  return {V(_mm256_unpacklo_pd(a, b)), V(_mm256_unpackhi_pd(a, b)), V{p0[2], p1[2], p2[2], p3[2]}};
}
inline V3 load3(const Vec3* p) {  // p[0..3]
  const uint32_t idx[4] = {0, 1, 2, 3};
  return load3(p, idx);
}
inline void store3(Vec3* p, const V3& a) {  // p[0..3]
  for (int l = 0; l < 4; ++l) p[l] = Vec3(a.x[l], a.y[l], a.z[l]);
}
inline V loadu(const double* p) {
  return V(_mm256_loadu_pd(p));
}
inline V load1(const double* base, const uint32_t* idx) {
  return V{base[idx[0]], base[idx[1]], base[idx[2]], base[idx[3]]};
}
inline V vsqrt(V a) {
  return V(_mm256_sqrt_pd(__m256d(a)));
}

void batch(const HairPairInputs& in, const HairPairConsts& c, const uint32_t* I, const uint32_t* J,
           const uint32_t* S, std::size_t count, Vec3* out) {
  const V zero = splat(0.0), one = splat(1.0), two = splat(2.0), four = splat(4.0);
  const V inv_h = splat(c.kernel.inv_h), sw = splat(c.kernel.sigma_w * 0.25),
          sdw = splat(c.kernel.sigma_dw * 0.75);  // SphKernel::w_dw
  const V inv_w0 = splat(c.inv_w0), eps2 = splat(c.eps2), tiny = splat(1e-18);
  const V cd = splat(c.collision_damping), fd = splat(c.friction_damping);
  std::size_t k = 0;
  for (; k + 4 <= count; k += 4) {
    const V3 xi = load3(in.x, I + k), xj = load3(in.x, J + k);
    const V3 ti = load3(in.t, I + k);
    const V tix = ti.x, tiy = ti.y, tiz = ti.z;
    const V mi = load1(in.mass, I + k), pi = load1(in.p_rho2, I + k);
    const V mj = load1(in.mass, J + k), pj = load1(in.p_rho2, J + k);
    const V ax = xj.x - xi.x, ay = xj.y - xi.y, az = xj.z - xi.z;  // x_ab
    const V r = vsqrt(ax * ax + ay * ay + az * az);
    const V inv_r = one / r;
    const V hx = ax * inv_r, hy = ay * inv_r, hz = az * inv_r;  // x^_ij
    const V q = r * inv_h;
    V a = two - q, b = one - q;
    a = a < zero ? zero : a;  // std::max(., 0.0)
    b = b < zero ? zero : b;
    const V w = sw * (a * a * a - four * b * b * b);
    const V dw = sdw * (four * b * b - a * a);
    const V s16 = mi * mj * (pi + pj) * dw;  // (3.16)
    V fx = s16 * hx, fy = s16 * hy, fz = s16 * hz;
    const V3 tj = load3(in.t, J + k);
    const V tjx = tj.x, tjy = tj.y, tjz = tj.z;
    const V dcx = tiy * tjz - tiz * tjy, dcy = tiz * tjx - tix * tjz, dcz = tix * tjy - tiy * tjx;
    const V d = hx * tix + hy * tiy + hz * tiz;
    const V dpx = hx - d * tix, dpy = hy - d * tiy, dpz = hz - d * tiz;
    const V dc2 = dcx * dcx + dcy * dcy + dcz * dcz, dp2 = dpx * dpx + dpy * dpy + dpz * dpz;
    const auto colinear = dc2 < eps2;
    const V dn2 = colinear ? dp2 : dc2;
    const V nx = colinear ? dpx : dcx, ny = colinear ? dpy : dcy, nz = colinear ? dpz : dcz;
    const V inv_n = one / vsqrt(dn2);
    const V ex = nx * inv_n, ey = ny * inv_n, ez = nz * inv_n;  // d^_n
    const V3 vi = load3(in.v, I + k), vj = load3(in.v, J + k);
    const V vax = vj.x - vi.x, vay = vj.y - vi.y, vaz = vj.z - vi.z;  // v_ij
    const V muw = mi * mj / (mi + mj) * (w * inv_w0);
    const V vn = vax * ex + vay * ey + vaz * ez;
    const V xn = ax * ex + ay * ey + az * ez;
    const V dc_on = vn * xn < zero ? cd : zero;  // (3.17) while approaching
    const V s17 = dc_on * muw * vn;
    const V s18 = fd * muw;  // (3.18)
    const V gx = (fx + s17 * ex) + s18 * (vax - vn * ex);
    const V gy = (fy + s17 * ey) + s18 * (vay - vn * ey);
    const V gz = (fz + s17 * ez) + s18 * (vaz - vn * ez);
    const auto on = dn2 >= tiny;
    fx = on ? gx : fx;
    fy = on ? gy : fy;
    fz = on ? gz : fz;
    for (int l = 0; l < 4; ++l) out[S[k + l]] = Vec3(fx[l], fy[l], fz[l]);
  }
  batch_scalar(in, c, I + k, J + k, S + k, count - k, out);
}

std::size_t active(const Vec3* x, const uint32_t* pair_i, const uint32_t* pair_j,
                   const HairPairConsts& c, std::size_t s0, std::size_t s1, double* w,
                   uint32_t* act_i, uint32_t* act_j, uint32_t* act_slot) {
  const V zero = splat(0.0), one = splat(1.0), two = splat(2.0), four = splat(4.0);
  const V inv_h = splat(c.kernel.inv_h), sw = splat(c.kernel.sigma_w * 0.25),
          r2max = splat(c.r2max);  // SphKernel::w
  std::size_t cnt = s0, s = s0;
  for (; s + 4 <= s1; s += 4) {
    const V3 xi = load3(x, pair_i + s), xj = load3(x, pair_j + s);
    const V dx = xj.x - xi.x, dy = xj.y - xi.y, dz = xj.z - xi.z;
    const V d2 = dx * dx + dy * dy + dz * dz;
    const V q = vsqrt(d2) * inv_h;
    V a = two - q, b = one - q;
    a = a < zero ? zero : a;
    b = b < zero ? zero : b;
    const V wk = sw * (a * a * a - four * b * b * b);
    const auto inside = d2 < r2max;
    const V wv = inside ? wk : zero;
    std::memcpy(w + s, &wv, sizeof(wv));
    const int act = _mm256_movemask_pd(__m256d(V(inside & (d2 > zero))));
    for (int l = 0; l < 4; ++l) {  // compaction without branches
      act_i[cnt] = pair_i[s + l];
      act_j[cnt] = pair_j[s + l];
      act_slot[cnt] = uint32_t(s + l);
      cnt += (act >> l) & 1;
    }
  }
  return active_from(x, pair_i, pair_j, c, s, s1, w, act_i, act_j, act_slot, cnt) - s0;
}

// lcp_springs with four connections per step (spring_force's operations, lane by lane).
void springs(const SpringInputs& in, std::size_t q0, std::size_t q1, Vec3* spring_f) {
  const V zero = splat(0.0), half = splat(0.5), cs = splat(in.compression_scale);
  std::size_t q = q0;
  for (; q + 4 <= q1; q += 4) {
    V alpha;
    if (in.alpha_r) {  // (3.14)
      alpha = half * (load1(in.alpha_r, in.pair_b + q) + load1(in.alpha_t, in.pair_a + q));
      std::memcpy(in.alpha + q, &alpha, sizeof(alpha));
    } else {
      alpha = loadu(in.alpha + q);
    }
    const V r = loadu(in.conn_r + q);
    const V3 xh = load3(in.conn_xh + q);
    const V ak = alpha * loadu(in.k + q);
    const V ext = r - loadu(in.l0 + q);
    const V kk = ext < zero ? ak * cs : ak;
    const V cd = loadu(in.damp + q) * vsqrt(kk);
    const V3 va = load3(in.v, in.pair_a + q), vb = load3(in.v, in.pair_b + q);
    const V dot = (vb.x - va.x) * xh.x + (vb.y - va.y) * xh.y + (vb.z - va.z) * xh.z;
    const V f = kk * ext + cd * dot;
    const auto ok = r > zero;
    store3(spring_f + q, {ok ? f * xh.x : zero, ok ? f * xh.y : zero, ok ? f * xh.z : zero});
  }
  lcp_springs(in, q, q1, spring_f);
}

// lcp_geometry with four connections per step.
void geometry(const Vec3* x, const uint32_t* pair_a, const uint32_t* pair_b, std::size_t q0,
              std::size_t q1, double* r, Vec3* xh) {
  const V one = splat(1.0);
  std::size_t q = q0;
  for (; q + 4 <= q1; q += 4) {
    const V3 a = load3(x, pair_a + q), b = load3(x, pair_b + q);
    const V dx = b.x - a.x, dy = b.y - a.y, dz = b.z - a.z;
    const V rr = vsqrt(dx * dx + dy * dy + dz * dz);
    const V inv = one / rr;
    std::memcpy(r + q, &rr, sizeof(rr));
    store3(xh + q, {dx * inv, dy * inv, dz * inv});
  }
  lcp_geometry(x, pair_a, pair_b, q, q1, r, xh);
}

inline void transpose4(V& a, V& b, V& c, V& d) {
  const __m256d t0 = _mm256_unpacklo_pd(__m256d(a), __m256d(b));
  const __m256d t1 = _mm256_unpackhi_pd(__m256d(a), __m256d(b));
  const __m256d t2 = _mm256_unpacklo_pd(__m256d(c), __m256d(d));
  const __m256d t3 = _mm256_unpackhi_pd(__m256d(c), __m256d(d));
  a = V(_mm256_permute2f128_pd(t0, t2, 0x20));
  b = V(_mm256_permute2f128_pd(t1, t3, 0x20));
  c = V(_mm256_permute2f128_pd(t0, t2, 0x31));
  d = V(_mm256_permute2f128_pd(t1, t3, 0x31));
}

// direction_term for four connection ends: (A x^, B) per lane, zero where `ok` is false.
inline void direction_terms(const V3& ti, V hx, V hy, V hz, V ak, V c0, V s0, V ok_mask, V out[4]) {
  const V zero = splat(0.0), tiny = splat(1e-12);
  const V d = ti.x * hx + ti.y * hy + ti.z * hz;
  const V px = ti.x - d * hx, py = ti.y - d * hy, pz = ti.z - d * hz;
  const V pn = vsqrt(px * px + py * py + pz * pz);
  const V sp = pn > tiny ? ak * s0 / pn : zero;
  const V a = ak * c0 - sp * d;
  const auto ok = ok_mask != zero;
  out[0] = ok ? a * hx : zero;
  out[1] = ok ? a * hy : zero;
  out[2] = ok ? a * hz : zero;
  out[3] = ok ? sp : zero;
}

// lcp_geometry_terms with four connections per step.
void geometry_terms(const DirectionTermInputs& in, std::size_t q0, std::size_t q1, double* r,
                    Vec3* xh, double* term) {
  const V zero = splat(0.0), one = splat(1.0), minus = splat(-1.0);
  std::size_t q = q0;
  for (; q + 4 <= q1; q += 4) {
    const V3 a = load3(in.x, in.pair_a + q), b = load3(in.x, in.pair_b + q);
    const V dx = b.x - a.x, dy = b.y - a.y, dz = b.z - a.z;
    const V rr = vsqrt(dx * dx + dy * dy + dz * dz);
    const V inv = one / rr;
    const V hx = dx * inv, hy = dy * inv, hz = dz * inv;
    std::memcpy(r + q, &rr, sizeof(rr));
    store3(xh + q, {hx, hy, hz});
    const V ok = rr > zero ? one : zero;
    const V ak = loadu(in.alpha + q) * loadu(in.k + q);
    V ta[4], tb[4];
    direction_terms(load3(in.t, in.pair_a + q), hx, hy, hz, ak, loadu(in.cos_a + q),
                    loadu(in.sin_a + q), ok, ta);
    direction_terms(load3(in.t, in.pair_b + q), minus * hx, minus * hy, minus * hz, ak,
                    loadu(in.cos_b + q), loadu(in.sin_b + q), ok, tb);
    transpose4(ta[0], ta[1], ta[2], ta[3]);  // lane l of component c -> connection l's row
    transpose4(tb[0], tb[1], tb[2], tb[3]);
    double* o = term + 8 * q;
    for (int l = 0; l < 4; ++l) {
      _mm256_storeu_pd(o + 8 * l, __m256d(ta[l]));
      _mm256_storeu_pd(o + 8 * l + 4, __m256d(tb[l]));
    }
  }
  lcp_geometry_terms(in, q, q1, r, xh, term);
}

// air_density / air_pressure with four list entries per step; the sums stay sequential.
struct AirEntries {
  V r, a, b, dx, dy, dz;  // |x_j - x_i|, (2 - q)_+, (1 - q)_+, x_j - x_i
};
inline AirEntries air_entries(const AirInputs& in, const uint32_t* nb, const Vec3& xi) {
  const V zero = splat(0.0), one = splat(1.0), two = splat(2.0);
  const V3 xj = load3(in.x, nb);
  AirEntries E;
  E.dx = xj.x - splat(xi.x());
  E.dy = xj.y - splat(xi.y());
  E.dz = xj.z - splat(xi.z());
  E.r = vsqrt(E.dx * E.dx + E.dy * E.dy + E.dz * E.dz);
  const V q = E.r * splat(in.kernel.inv_h);
  E.a = two - q;
  E.b = one - q;
  E.a = E.a < zero ? zero : E.a;  // std::max(., 0.0)
  E.b = E.b < zero ? zero : E.b;
  return E;
}

void air_density(const AirInputs& in, std::size_t i0, std::size_t i1, double* rho) {
  const V m = splat(in.mass), four = splat(4.0), sw = splat(in.kernel.sigma_w * 0.25);
  for (std::size_t i = i0; i < i1; ++i) {
    const Vec3 xi = in.x[i];
    double r = in.mass * in.kernel.w(0.0);
    uint32_t e = in.off[i];
    const uint32_t e1 = in.off[i + 1];
    for (; e + 4 <= e1; e += 4) {
      const AirEntries E = air_entries(in, in.nb + e, xi);
      const V mw = m * (sw * (E.a * E.a * E.a - four * E.b * E.b * E.b));  // SphKernel::w
      for (int l = 0; l < 4; ++l) r += mw[l];
    }
    for (; e < e1; ++e) r += in.mass * in.kernel.w((in.x[in.nb[e]] - xi).norm());
    rho[i] = r;
  }
}

void air_pressure(const AirInputs& in, std::size_t i0, std::size_t i1, Vec3* f) {
  const V four = splat(4.0), zero = splat(0.0), sdw = splat(in.kernel.sigma_dw * 0.75);
  const double mm = in.mass * in.mass;
  for (std::size_t i = i0; i < i1; ++i) {
    const Vec3 xi = in.x[i];
    const double pi = in.p_rho2[i];
    double sx = 0, sy = 0, sz = 0;
    uint32_t e = in.off[i];
    const uint32_t e1 = in.off[i + 1];
    for (; e + 4 <= e1; e += 4) {
      const AirEntries E = air_entries(in, in.nb + e, xi);
      const V dw = sdw * (four * E.b * E.b - E.a * E.a);  // SphKernel::w_dw
      const V c = splat(mm) * (splat(pi) + load1(in.p_rho2, in.nb + e)) * dw / E.r;
      const V px = c * E.dx, py = c * E.dy, pz = c * E.dz;
      const auto skip = E.r <= zero;
      for (int l = 0; l < 4; ++l)
        if (!skip[l]) {
          sx += px[l];
          sy += py[l];
          sz += pz[l];
        }
    }
    Vec3 s(sx, sy, sz);
    for (; e < e1; ++e) add_air_pressure(in, i, e, s);
    f[i] = s;
  }
}

void air_drag(const AirDragInputs& in, std::size_t i0, std::size_t i1, Vec3* f) {
  const V zero = splat(0.0), one = splat(1.0), two = splat(2.0), four = splat(4.0);
  const V inv_h = splat(in.kernel.inv_h), sw = splat(in.kernel.sigma_w * 0.25);
  const V inv_w0 = splat(in.inv_w0), d = splat(in.drag);
  for (std::size_t i = i0; i < i1; ++i) {
    const Vec3 xa = in.x[i], va = in.v[i];
    uint32_t e = in.off[i];
    const uint32_t e1 = in.off[i + 1];
    for (; e + 4 <= e1; e += 4) {
      const V3 xh = load3(in.hair_x, in.nb + e), vh = load3(in.hair_v, in.nb + e);
      const V dx = splat(xa.x()) - xh.x, dy = splat(xa.y()) - xh.y, dz = splat(xa.z()) - xh.z;
      const V q = vsqrt(dx * dx + dy * dy + dz * dz) * inv_h;
      V a = two - q, b = one - q;
      a = a < zero ? zero : a;  // std::max(., 0.0)
      b = b < zero ? zero : b;
      const V w = sw * (a * a * a - four * b * b * b);  // SphKernel::w
      const V c = d * load1(in.mu, in.nb + e) * (w * inv_w0);
      store3(f + e, V3{c * (splat(va.x()) - vh.x), c * (splat(va.y()) - vh.y),
                       c * (splat(va.z()) - vh.z)});
    }
    for (; e < e1; ++e) f[e] = air_drag_entry(in, i, e);
  }
}

}  // namespace avx2
FOLLICLE_AVX2_END
#endif

LcpKernels lcp_kernels(bool allow_simd) {
#ifdef FOLLICLE_LCP_KERNELS_HAVE_AVX2
  if (allow_simd && cpu_has_avx2())
    return {&avx2::active,       &avx2::batch,          &avx2::springs,
            &avx2::geometry,     &avx2::geometry_terms, &avx2::air_density,
            &avx2::air_pressure, &avx2::air_drag,       true};
#endif
  (void)allow_simd;
  return {&active_scalar, &batch_scalar, &lcp_springs, &lcp_geometry, &lcp_geometry_terms,
          &air_density,   &air_pressure, &air_drag,    false};
}

}  // namespace follicle::hair::detail
