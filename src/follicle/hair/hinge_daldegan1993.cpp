#include "follicle/hair/hinge_daldegan1993.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/core/params.hpp"

namespace follicle::hair {

void HingeParams::validate() const {
  validate_params(*this, "hinge");
  if (polar_frame != "rest" && polar_frame != "head")
    fail_at("hinge.polar_frame", "unknown polar frame \"{}\"; expected rest or head", polar_frame);
  if (inertia != "outboard" && inertia != "segment")
    fail_at("hinge.inertia", "unknown inertia \"{}\"; expected outboard or segment", inertia);
}

namespace {

constexpr std::size_t kChunk = 64;  // strands per block: the block's rows stay in L1/L2

// Angle reduced to [-π, π] for the single-precision sin/cos (angles may wind up over time).
// (Rounding by adding and subtracting 1.5 * 2^52: two additions instead of a libm call.)
inline float reduce_angle(double x) {
  constexpr double inv2pi = 1.0 / (2.0 * kPi), magic = 6755399441055744.0;
  const double k = (x * inv2pi + magic) - magic;
  return float(x - 2.0 * kPi * k);
}

// x - 2π k with k the nearest integer to x / 2π: the angle difference on (-π, π]. The springs
// (3) pull an angle to the nearest turn of its styled value, so an angle that wound up (φ near a
// pole of the polar frame) does not unwind turn by turn.
inline double wrap_pi(double x) {
  constexpr double inv2pi = 1.0 / (2.0 * kPi), magic = 6755399441055744.0;
  return x - 2.0 * kPi * ((x * inv2pi + magic) - magic);
}

// sin and cos of |x| <= ~π in single precision: one reduction to [-π/4, π/4] (3-part Cody-Waite)
// and the minimax polynomials of Cephes sinf/cosf (about 1 ulp).
inline void sincos_f(float x, float& s, float& c) {
  constexpr float magic = 12582912.0f;  // 1.5 * 2^23: x + magic rounds x to an integer
  const float k = (x * 0.636619772367581f + magic) - magic;  // 2/π
  const int q = int(k);
  const float r =
      ((x - k * 1.5703125f) - k * 4.837512969970703125e-4f) - k * 7.54978995489188216e-8f;
  const float z = r * r;
  const float sp = r + r * z * (-1.6666654611e-1f + z * (8.3321608736e-3f + z * -1.9515295891e-4f));
  const float cp =
      1.0f - 0.5f * z +
      z * z * (4.166664568298827e-2f + z * (-1.388731625493765e-3f + z * 2.443315711809948e-5f));
  // Quadrant selection by arithmetic (no branches or selects, so loops vectorise).
  const float swap = float(q & 1);
  const float sn = sp + swap * (cp - sp), cs = cp + swap * (sp - cp);
  s = sn * float(1 - (q & 2));
  c = cs * float(1 - ((q + 1) & 2));
}

struct V3f {
  float x, y, z;
};
inline V3f operator+(V3f a, V3f b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline V3f operator-(V3f a, V3f b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline V3f operator*(float s, V3f a) {
  return {s * a.x, s * a.y, s * a.z};
}
inline float dot(V3f a, V3f b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline V3f cross(V3f a, V3f b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline V3f mul(const float* m, V3f v) {  // row-major 3x3
  return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
          m[6] * v.x + m[7] * v.y + m[8] * v.z};
}
inline Vec3 to_d(V3f v) {
  return Vec3(v.x, v.y, v.z);
}
inline V3f to_f(const Vec3& v) {
  return {float(v.x()), float(v.y()), float(v.z())};
}

// Direction and its two partial derivatives (head frame) of a segment with polar frame (X, Y, Z).
struct SegTrig {
  V3f d, et, ep;  // d, ∂d/∂θ, ∂d/∂φ
};
inline SegTrig seg_trig(float st, float ct, float sp, float cp, V3f X, V3f Y, V3f Z) {
  SegTrig t;
  // Local: d = (sθ sφ, cθ, sθ cφ), ∂d/∂θ = (cθ sφ, -sθ, cθ cφ), ∂d/∂φ = (sθ cφ, 0, -sθ sφ).
  t.d = (st * sp) * X + ct * Y + (st * cp) * Z;
  t.et = (ct * sp) * X + (-st) * Y + (ct * cp) * Z;
  t.ep = (st * cp) * X + (-st * sp) * Z;
  return t;
}

// Everything a block of the step reads.
struct StepArgs {
  const HingeParams* p = nullptr;
  const sim::CylinderBody* body = nullptr;
  std::size_t N = 0, K = 0;
  const int* nseg = nullptr;
  const float *len = nullptr, *gain = nullptr, *pen = nullptr, *kt = nullptr, *kp = nullptr,
              *gd = nullptr, *th0 = nullptr, *ph0 = nullptr;
  const float *fy[3] = {nullptr, nullptr, nullptr}, *fz[3] = {nullptr, nullptr, nullptr};
  const float* root[3] = {nullptr, nullptr, nullptr};
  double *TH = nullptr, *PH = nullptr, *WT = nullptr, *WP = nullptr;
  float* cdist = nullptr;
  Vec3f* cnorm = nullptr;
  Vec3* nodes = nullptr;
  int substeps = 1;
  double h = 0;
  float hf = 0;
  V3f b{0, 0, 0}, h0{0, 0, 0}, om{0, 0, 0};
  float M[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  float cw = 0, kc = 0, cc = 0, contact = 0, max_v2 = 0;
  bool project = false;
};

// Direction on the great circle from a (t = 0) to b (t = 1).
Vec3 arc(const Vec3& a, const Vec3& b, double t) {
  const Vec3 c = a.cross(b);
  const double s = c.norm(), co = a.dot(b);
  const double ang = std::atan2(s, co);
  Vec3 axis;
  if (s > 1e-12) {
    axis = c / s;
  } else {  // parallel or opposite: any axis across a
    axis = a.unitOrthogonal();
  }
  return Eigen::AngleAxisd(t * ang, axis) * a;
}

bool outside_f(const sim::CylinderBody& body, const Vec3& p) {
  sim::CylinderContactF c;
  return body.contact(float(p.x()), float(p.y()), float(p.z()), 0.0f, c) < 0;
}

// Ours (not in the paper): turns the segment about its (already final) start node B so that its
// end leaves the body. `n`, `dist`: the contact normal and (P - Q)·N at the current end. First
// the end is moved onto the tangent plane a little outside and the length restored (at most three
// times); if that fails, among candidate directions known to be outside (the segment's direction
// at the start of the step, the contact normal, their mean, the body's up) the first one found
// bounds a bisection on the great circle from the current direction, which ends on the outside
// side. Returns false (direction unchanged) when no candidate is outside. On return `n` is the
// normal of the last contact (for the inelastic velocity update).
bool project_direction(const sim::CylinderBody& body, const Vec3& B, double l, const Vec3& d_in,
                       const Vec3& d_old, Vec3& n, float dist, Vec3& d_out) {
  // Usually one or two moves of the end node to the tangent plane of the table's surface (T of
  // §3.2, a little outside), the segment's length restored each time, put it outside.
  Vec3 P = B + l * d_in;
  for (int it = 0; it < 3; ++it) {
    const Vec3 T = P + (1e-5 - double(dist)) * n;
    const Vec3 v = T - B;
    const double nv = v.norm();
    if (!(nv > 1e-12 * l)) break;
    const Vec3 d = v / nv;
    P = B + l * d;
    sim::CylinderContactF c;
    if (body.contact(float(P.x()), float(P.y()), float(P.z()), 0.0f, c) < 0) {
      d_out = d;
      return true;
    }
    n = Vec3(c.nx, c.ny, c.nz);
    dist = c.distance;
  }
  // Otherwise a bisection on the great circle towards a direction known to be outside.
  const Vec3 up = body.num_parts() > 0 ? body.part(0).axis().up : Vec3::UnitY();
  const Vec3 cand[4] = {d_old, (d_old + n).normalized(), n, up};
  for (const Vec3& c : cand) {
    if (!c.allFinite() || !(c.squaredNorm() > 0.5)) continue;
    if (!outside_f(body, B + l * c)) continue;
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 24; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (outside_f(body, B + l * arc(d_in, c, mid)))
        hi = mid;
      else
        lo = mid;
    }
    d_out = arc(d_in, c, hi);
    if (outside_f(body, B + l * d_out)) return true;
    d_out = c;  // rounding of the arc: the candidate itself is outside
    return true;
  }
  return false;
}

// Per-block scratch, structure of arrays over the block's strands (one row = one segment).
struct Scratch {
  // Start node of the row's segment at t (A) and at t + h (B): position and velocity.
  float Ax[kChunk], Ay[kChunk], Az[kChunk], Avx[kChunk], Avy[kChunk], Avz[kChunk];
  float Bx[kChunk], By[kChunk], Bz[kChunk], Bvx[kChunk], Bvy[kChunk], Bvz[kChunk];
  // End node at t (P) and at t + h (Q).
  float Px[kChunk], Py[kChunk], Pz[kChunk], Pvx[kChunk], Pvy[kChunk], Pvz[kChunk];
  float Qx[kChunk], Qy[kChunk], Qz[kChunk], Qvx[kChunk], Qvy[kChunk], Qvz[kChunk];
  // Phase A: d, ∂d/∂θ, ∂d/∂φ at t, the field f at the centre, and the kick's terms.
  float dx[kChunk], dy[kChunk], dz[kChunk];
  float etx[kChunk], ety[kChunk], etz[kChunk], epx[kChunk], epy[kChunk], epz[kChunk];
  float fx[kChunk], fy[kChunk], fz[kChunk];
  float ft[kChunk], fp[kChunk], bt[kChunk], bp[kChunk], bs[kChunk], be[kChunk];
  float pt[kChunk], pp[kChunk], Kt[kChunk], Kp[kChunk], Ct[kChunk], Cp[kChunk];
  // Phase B: d, ∂d/∂θ, ∂d/∂φ at t + h.
  float ndx[kChunk], ndy[kChunk], ndz[kChunk];
  float netx[kChunk], nety[kChunk], netz[kChunk], nepx[kChunk], nepy[kChunk], nepz[kChunk];
  float vmax2[kChunk], nan[kChunk];  // largest squared node speed; NaN/Inf accumulator
  int flag[kChunk];                  // candidates for the collision tests
};

// One block of strands [s0, s1) for params.substeps sub-steps. Layout [segment][strand]: the
// outer loop runs over segments root to tip (each needs its start node), the inner loops over the
// block's strands: plain branch-free loops the compiler vectorises, and two scalar passes for
// the collision (most nodes leave them at the early rejections). Per segment and sub-step h:
//   Phase A (state at t): direction and velocity of the segment from its angles, external field
//     at its centre; the reaction constraint (4)-(6) at its end node; the kick
//     ω += h M_ext / I (the uniform field b with weight ½, see below).
//   (1)+(3): the damped hinge oscillator over h by the implicit midpoint rule.
//   Phase B (state at t + h): new direction and node, the projection (ours), the second half
//     kick of the uniform field with the new direction.
// Rows beyond a short strand's tip are inert (zero length, zero gains): computed, unchanged.
// Compiled for plain x86-64 and for AVX2 (twice the lanes, the same IEEE operations lane by lane:
// avx2 does not enable FMA contraction), picked at load time by the CPU.
#if defined(__x86_64__) && defined(__GNUC__)
#define FOLLICLE_HINGE_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define FOLLICLE_HINGE_CLONES
#endif
FOLLICLE_HINGE_CLONES void step_block(const StepArgs& a, std::size_t s0, std::size_t s1,
                                      sim::StepReport& rep, std::size_t& unresolved, Scratch& S) {
  const std::size_t n = s1 - s0, N = a.N, K = a.K;
  for (std::size_t j = 0; j < n; ++j) {
    S.vmax2[j] = 0.0f;
    S.nan[j] = 0.0f;
  }
  const double h = a.h;
  const V3f b = a.b, h0 = a.h0, om = a.om;
  const float cw = a.cw;
  const float* M = a.M;
  for (int sub = 0; sub < a.substeps; ++sub) {
    const bool last = sub + 1 == a.substeps;
    for (std::size_t j = 0; j < n; ++j) {
      S.Ax[j] = S.Bx[j] = a.root[0][s0 + j];
      S.Ay[j] = S.By[j] = a.root[1][s0 + j];
      S.Az[j] = S.Bz[j] = a.root[2][s0 + j];
      S.Avx[j] = S.Avy[j] = S.Avz[j] = S.Bvx[j] = S.Bvy[j] = S.Bvz[j] = 0.0f;
    }
    for (std::size_t i = 0; i < K; ++i) {
      const std::size_t base = i * N + s0;
      const float* __restrict len = a.len + base;
      const float* __restrict fy0 = a.fy[0] + base, * __restrict fy1 = a.fy[1] + base, * __restrict fy2 = a.fy[2] + base;
      const float* __restrict fz0 = a.fz[0] + base, * __restrict fz1 = a.fz[1] + base, * __restrict fz2 = a.fz[2] + base;
      double* __restrict TH = a.TH + base, * __restrict PH = a.PH + base;
      double* __restrict WT = a.WT + base, * __restrict WP = a.WP + base;
      // ---- Phase A: the configuration at t (vectorised). `ivdep`: the scratch rows, the state
      // rows and the solver's rows never overlap (GCC 12 otherwise gives up on these loops).
#pragma GCC ivdep
      for (std::size_t j = 0; j < n; ++j) {
        const float l = len[j];
        const V3f Y{fy0[j], fy1[j], fy2[j]}, Z{fz0[j], fz1[j], fz2[j]};
        const V3f X = cross(Y, Z);
        float st, ct, sp, cp;
        sincos_f(reduce_angle(TH[j]), st, ct);
        sincos_f(reduce_angle(PH[j]), sp, cp);
        const SegTrig o = seg_trig(st, ct, sp, cp, X, Y, Z);
        const V3f A{S.Ax[j], S.Ay[j], S.Az[j]}, vA{S.Avx[j], S.Avy[j], S.Avz[j]};
        const V3f w = float(WT[j]) * o.et + float(WP[j]) * o.ep;  // d'
        const V3f c = A + (0.5f * l) * o.d, vc = vA + (0.5f * l) * w;
        const V3f P = A + l * o.d, vP = vA + l * w;
        // External field per unit mass at the centre (head frame): Euler and centrifugal
        // forces and the air's -Ω×r in M c, Coriolis, wind drag on the hinge's motion; the drag
        // of the segment's own turn is in gd (implicit).
        const V3f f = mul(M, c) + h0 - 2.0f * cross(om, vc) - cw * vA;
        S.dx[j] = o.d.x;
        S.dy[j] = o.d.y;
        S.dz[j] = o.d.z;
        S.etx[j] = o.et.x;
        S.ety[j] = o.et.y;
        S.etz[j] = o.et.z;
        S.epx[j] = o.ep.x;
        S.epy[j] = o.ep.y;
        S.epz[j] = o.ep.z;
        S.fx[j] = f.x;
        S.fy[j] = f.y;
        S.fz[j] = f.z;
        S.Px[j] = P.x;
        S.Py[j] = P.y;
        S.Pz[j] = P.z;
        S.Pvx[j] = vP.x;
        S.Pvy[j] = vP.y;
        S.Pvz[j] = vP.z;
        S.ft[j] = dot(f, o.et);
        S.fp[j] = dot(f, o.ep);
        S.bt[j] = dot(b, o.et);
        S.bp[j] = dot(b, o.ep);
        S.bs[j] = S.be[j] = 0.5f;
        S.pt[j] = S.pp[j] = S.Kt[j] = S.Kp[j] = S.Ct[j] = S.Cp[j] = 0.0f;
      }
      // ---- The reaction constraint (4)-(6) at the end nodes in contact (scalar).
      // The contacts found at the end of the previous (sub-)step, where the nodes are now (up to
      // the rounding of a projection); NaN (a fresh state): tested here.
      if (a.body) {
        const float* __restrict cdist = a.cdist + base;
        const Vec3f* __restrict cnorm = a.cnorm + base;
        for (std::size_t j = 0; j < n; ++j) {
          if (!(cdist[j] <= 1e30f) && !std::isnan(cdist[j])) continue;  // +inf: not near
          if (!(len[j] > 0.0f)) continue;
          sim::CylinderContactF cc;
          if (std::isnan(cdist[j])) {
            if (a.body->contact(S.Px[j], S.Py[j], S.Pz[j], a.contact, cc) < 0) continue;
          } else {
            cc.distance = cdist[j];
            cc.nx = cnorm[j].x();
            cc.ny = cnorm[j].y();
            cc.nz = cnorm[j].z();
          }
          const V3f Nv{cc.nx, cc.ny, cc.nz};
          const V3f et{S.etx[j], S.ety[j], S.etz[j]}, ep{S.epx[j], S.epy[j], S.epz[j]};
          const V3f Fin = V3f{S.fx[j], S.fy[j], S.fz[j]} + b;  // F_input: every force on s_i
          const float fn = dot(Fin, Nv);
          // Inelastic: the constraint acts only while the input force does not lift P.
          if (!(fn < 0.0f)) continue;
          // (4) F_unconstrained = F_in - (F_in·N) N (b is taken whole in this kick).
          const V3f Fu = Fin - fn * Nv;
          S.ft[j] = dot(Fu, et);
          S.fp[j] = dot(Fu, ep);
          S.bt[j] = S.bp[j] = 0.0f;
          S.bs[j] = S.be[j] = 0.0f;
          // (5) F_constrained = -(k PT + c V·N) N at P (lever l): PT = (P - T)·N <= 0; V·N of
          // the hinge's motion here, the segment's own turn in the implicit solve (linearised:
          // stiffness k l² (e·N)², damping c l² (e·N)² per angle).
          const float PT = std::min(cc.distance, 0.0f);
          const V3f vA{S.Avx[j], S.Avy[j], S.Avz[j]};
          const float Fc = -(a.kc * PT + a.cc * dot(vA, Nv));
          const float pen = a.pen[base + j], pl = pen * len[j];
          const float nt = dot(Nv, et), np = dot(Nv, ep);
          S.pt[j] = pen * Fc * nt;
          S.pp[j] = pen * Fc * np;
          if (PT < 0.0f) {
            S.Kt[j] = pl * a.kc * nt * nt;
            S.Kp[j] = pl * a.kc * np * np;
          }
          S.Ct[j] = pl * a.cc * nt * nt;
          S.Cp[j] = pl * a.cc * np * np;
          // (6) F_output = F_unconstrained + F_constrained: both enter the kick.
        }
      }
      // ---- Kick, hinge oscillator, Phase B (vectorised).
      {
        const float* __restrict gain = a.gain + base, * __restrict kt = a.kt + base, * __restrict kp = a.kp + base, * __restrict gd = a.gd + base;
        const float* __restrict th0 = a.th0 + base, * __restrict ph0 = a.ph0 + base;
#pragma GCC ivdep
        for (std::size_t j = 0; j < n; ++j) {
          // (2) external moments per unit inertia; kick.
          double wt = WT[j] + h * double(gain[j] * (S.ft[j] + S.bs[j] * S.bt[j]) + S.pt[j]);
          double wp = WP[j] + h * double(gain[j] * (S.fp[j] + S.bs[j] * S.bp[j]) + S.pp[j]);
          // (1), (3): I q'' + γ q' + k (q - q0) = 0 over h by the implicit midpoint rule,
          //   ω' = ((1 - σ) ω - h (k/I)(q - q0)) / (1 + σ),  σ = (h/2)(γ/I + (k/I) h/2),
          //   q' = q + h (ω + ω')/2,
          // with the linearised (5) added to k and γ.
          const double ktj = kt[j], kpj = kp[j], gdj = gd[j];
          const double sig_t =
              0.5 * h * (gdj + double(S.Ct[j]) + 0.5 * h * (ktj + double(S.Kt[j])));
          const double sig_p =
              0.5 * h * (gdj + double(S.Cp[j]) + 0.5 * h * (kpj + double(S.Kp[j])));
          const double th = TH[j], ph = PH[j];
          const double dth = wrap_pi(th - double(th0[j])), dph = wrap_pi(ph - double(ph0[j]));
          const double wt1 = ((1.0 - sig_t) * wt - h * ktj * dth) / (1.0 + sig_t);
          const double wp1 = ((1.0 - sig_p) * wp - h * kpj * dph) / (1.0 + sig_p);
          const double thn = th + 0.5 * h * (wt + wt1), phn = ph + 0.5 * h * (wp + wp1);
          TH[j] = thn;
          PH[j] = phn;
          WT[j] = wt1;
          WP[j] = wp1;
          const float l = len[j];
          const V3f Y{fy0[j], fy1[j], fy2[j]}, Z{fz0[j], fz1[j], fz2[j]};
          const V3f X = cross(Y, Z);
          float st, ct, sp, cp;
          sincos_f(reduce_angle(thn), st, ct);
          sincos_f(reduce_angle(phn), sp, cp);
          const SegTrig e = seg_trig(st, ct, sp, cp, X, Y, Z);
          S.ndx[j] = e.d.x;
          S.ndy[j] = e.d.y;
          S.ndz[j] = e.d.z;
          S.netx[j] = e.et.x;
          S.nety[j] = e.et.y;
          S.netz[j] = e.et.z;
          S.nepx[j] = e.ep.x;
          S.nepy[j] = e.ep.y;
          S.nepz[j] = e.ep.z;
          S.Qx[j] = S.Bx[j] + l * e.d.x;
          S.Qy[j] = S.By[j] + l * e.d.y;
          S.Qz[j] = S.Bz[j] + l * e.d.z;
        }
      }
      // ---- Nodes near the body for the next step; ours: end nodes still inside are turned
      // about B onto the surface (scalar).
      if (a.body) {
        float* __restrict cdist = a.cdist + base;
        Vec3f* __restrict cnorm = a.cnorm + base;
        for (std::size_t j = 0; j < n; ++j) S.flag[j] = 0;
        a.body->mark_candidates(S.Qx, S.Qy, S.Qz, n, a.contact, S.flag);
        for (std::size_t j = 0; j < n; ++j) {
          cdist[j] = std::numeric_limits<float>::infinity();
          const float l = len[j];
          if (!S.flag[j] || !(l > 0.0f)) continue;
          sim::CylinderContactF cc;
          if (a.body->contact(S.Qx[j], S.Qy[j], S.Qz[j], a.contact, cc) < 0) continue;
          // Near the body; a node put back onto the surface below is in contact there (PT = 0).
          cdist[j] = a.project ? std::max(cc.distance, 0.0f) : cc.distance;
          cnorm[j] = Vec3f(cc.nx, cc.ny, cc.nz);
          if (!a.project || !(cc.depth_radial > 0.0f)) continue;  // not inside the surface
          const std::size_t idx = base + j;
          const V3f Y{a.fy[0][idx], a.fy[1][idx], a.fy[2][idx]};
          const V3f Z{a.fz[0][idx], a.fz[1][idx], a.fz[2][idx]};
          const V3f X = cross(Y, Z);
          const Vec3 Bd(S.Bx[j], S.By[j], S.Bz[j]);
          const Vec3 din = Vec3(S.ndx[j], S.ndy[j], S.ndz[j]).normalized();
          const Vec3 dold = Vec3(S.dx[j], S.dy[j], S.dz[j]).normalized();
          Vec3 Nd(cc.nx, cc.ny, cc.nz), dn;
          if (!project_direction(*a.body, Bd, double(l), din, dold, Nd, cc.distance, dn)) {
            ++unresolved;
            continue;
          }
          const Vec3 local(dn.dot(to_d(X)), dn.dot(to_d(Y)), dn.dot(to_d(Z)));
          double th = TH[j], ph = PH[j];
          double th2 = th, ph2 = ph;
          direction_angles(local, ph, th2, ph2);
          th2 += 2.0 * kPi * std::round((th - th2) / (2.0 * kPi));
          th = th2;
          ph = ph2;
          const SegTrig e = seg_trig(float(std::sin(th)), float(std::cos(th)), float(std::sin(ph)),
                                     float(std::cos(ph)), X, Y, Z);
          const Vec3 Qd = Bd + double(l) * dn;
          // Inelastic: drop the inward normal velocity v_n of the end node with the smallest
          // change of (θ', φ') (the metric of (1)): Δω = -v_n Jᵀ N / |Jᵀ N|², J = l (∂d/∂θ,
          // ∂d/∂φ); never adding kinetic energy. (Dividing by |∂d/∂φ|² instead would blow up
          // near a pole of the polar frame.)
          const Vec3 et = to_d(e.et), ep = to_d(e.ep);
          double wt = WT[j], wp = WP[j];
          const Vec3 vB(S.Bvx[j], S.Bvy[j], S.Bvz[j]);
          const double vn = (vB + double(l) * (wt * et + wp * ep)).dot(Nd);
          const double jt = double(l) * et.dot(Nd), jp = double(l) * ep.dot(Nd);
          const double jj = jt * jt + jp * jp;
          if (vn < 0.0 && jj > 1e-8 * double(l) * double(l)) {
            const double w0 = std::hypot(wt, wp);
            wt -= vn * jt / jj;
            wp -= vn * jp / jj;
            const double w1 = std::hypot(wt, wp);
            if (w1 > w0) {
              wt *= w0 / w1;
              wp *= w0 / w1;
            }
          }
          TH[j] = th;
          PH[j] = ph;
          WT[j] = wt;
          WP[j] = wp;
          S.netx[j] = e.et.x;
          S.nety[j] = e.et.y;
          S.netz[j] = e.et.z;
          S.nepx[j] = e.ep.x;
          S.nepy[j] = e.ep.y;
          S.nepz[j] = e.ep.z;
          S.Qx[j] = float(Qd.x());
          S.Qy[j] = float(Qd.y());
          S.Qz[j] = float(Qd.z());
        }
      }
      // ---- Second half kick of the uniform field at t + h; speeds; next row (vectorised).
      {
        const float* __restrict gain = a.gain + base;
#pragma GCC ivdep
        for (std::size_t j = 0; j < n; ++j) {
          const V3f et{S.netx[j], S.nety[j], S.netz[j]}, ep{S.nepx[j], S.nepy[j], S.nepz[j]};
          const float gb = gain[j] * S.be[j];
          const double wt = WT[j] + h * double(gb * dot(b, et));
          const double wp = WP[j] + h * double(gb * dot(b, ep));
          WT[j] = wt;
          WP[j] = wp;
          const float l = len[j];
          const V3f vQ = V3f{S.Bvx[j], S.Bvy[j], S.Bvz[j]} + l * (float(wt) * et + float(wp) * ep);
          const float v2 = dot(vQ, vQ);
          S.vmax2[j] = v2 > S.vmax2[j] ? v2 : S.vmax2[j];
          // NaN/Inf anywhere turns the accumulator into NaN for good.
          S.nan[j] += (v2 - v2) + float(TH[j] - TH[j]) + float(PH[j] - PH[j]);
          S.Ax[j] = S.Px[j];
          S.Ay[j] = S.Py[j];
          S.Az[j] = S.Pz[j];
          S.Avx[j] = S.Pvx[j];
          S.Avy[j] = S.Pvy[j];
          S.Avz[j] = S.Pvz[j];
          S.Bx[j] = S.Qx[j];
          S.By[j] = S.Qy[j];
          S.Bz[j] = S.Qz[j];
          S.Bvx[j] = vQ.x;
          S.Bvy[j] = vQ.y;
          S.Bvz[j] = vQ.z;
        }
      }
      if (last) {
        Vec3* nodes = a.nodes + (i + 1) * N + s0;
        for (std::size_t j = 0; j < n; ++j) nodes[j] = Vec3(S.Qx[j], S.Qy[j], S.Qz[j]);
      }
    }
  }
  for (std::size_t j = 0; j < n; ++j) {
    const std::size_t s = s0 + j;
    const bool bad = !(S.nan[j] == 0.0f);
    if (!bad) rep.max_speed = std::max(rep.max_speed, double(std::sqrt(S.vmax2[j])));
    if (bad)
      rep.mark_non_finite(s);
    else if (S.vmax2[j] > a.max_v2)
      rep.mark_blow_up(s);
  }
}

Mat3 skew(const Vec3& v) {
  Mat3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

}  // namespace

HingeSolver::HingeSolver(const HingeParams& params, const geom::StrandSet& rest,
                         std::shared_ptr<const sim::CylinderBody> collider)
    : m_p(params), m_body(std::move(collider)), m_rest(rest) {
  m_p.validate();
  rest.check("hinge solver rest strands");
  m_n = rest.num_strands();
  for (std::size_t s = 0; s < m_n; ++s) {
    if (rest.strand_size(s) < 2) fail("hinge solver: strand {} has fewer than 2 points", s);
    m_k = std::max(m_k, int(rest.strand_size(s)) - 1);
  }
  m_mu = m_p.density * kPi * m_p.radius * m_p.radius;
  const std::size_t K = std::size_t(m_k), N = m_n, KN = K * N;
  m_nseg.resize(N);
  for (auto* v : {&m_len_d, &m_arm_d, &m_inertia_d, &m_kt_d, &m_kp_d, &m_gamma_d})
    v->assign(KN, 0.0);
  for (auto* v : {&m_theta0, &m_phi0, &m_len, &m_gain, &m_pen, &m_kt, &m_kp, &m_gd})
    v->assign(KN, 0.0f);
  for (int c = 0; c < 3; ++c) {
    m_fy[c].assign(KN, 0.0f);
    m_fz[c].assign(KN, 0.0f);
    m_root[c].assign(N, 0.0f);
  }
  // Padding rows: a valid frame (head axes), zero length, inert.
  for (std::size_t idx = 0; idx < KN; ++idx) {
    m_fy[1][idx] = 1.0f;
    m_fz[2][idx] = 1.0f;
  }
  const bool head_frame = m_p.polar_frame == "head";
  const bool outboard = m_p.inertia == "outboard";
  const double sc = m_p.inertia_scale, ref = m_p.reference_length;
  for (std::size_t s = 0; s < N; ++s) {
    const uint32_t b0 = rest.offsets[s];
    const int k = int(rest.strand_size(s)) - 1;
    m_nseg[s] = k;
    for (int c = 0; c < 3; ++c) m_root[c][s] = rest.points[b0][c];
    std::vector<double> len(std::size_t(k) + 1, 0.0);
    double L = 0;
    for (int i = 1; i <= k; ++i) {
      len[std::size_t(i)] = (rest.points[b0 + i] - rest.points[b0 + i - 1]).cast<double>().norm();
      L += len[std::size_t(i)];
    }
    double outb = L, cum = 0, hint = 0;
    Vec3 prev_dir(0, -1, 0);
    for (int i = 1; i <= k; ++i) {
      const std::size_t idx = row(s, i);
      const double l = len[std::size_t(i)];
      const Vec3 seg = (rest.points[b0 + i] - rest.points[b0 + i - 1]).cast<double>();
      const Vec3 d0 = l > 0 ? Vec3(seg / l) : prev_dir;
      prev_dir = d0;
      // Polar frame: pole Y, equator zero Z (local x = Y × Z).
      Vec3 Y = Vec3::UnitY(), Z = Vec3::UnitZ();
      if (!head_frame) {
        Z = d0;
        const Vec3 c = d0.cross(Vec3::UnitY());
        Y = c.norm() > 1e-6 ? Vec3(c.normalized()) : Vec3::UnitX();
      }
      for (int c = 0; c < 3; ++c) {
        m_fy[c][idx] = float(Y[c]);
        m_fz[c][idx] = float(Z[c]);
      }
      double th0 = 0, ph0 = 0;
      if (head_frame) {
        direction_angles(d0, hint, th0, ph0);
        hint = ph0;
      } else {
        th0 = 0.5 * kPi;
        ph0 = 0.0;
      }
      m_theta0[idx] = float(th0);
      m_phi0[idx] = float(ph0);
      const double arm_raw = outboard ? outb : l;
      outb -= l;
      const double frac = L > 0 ? (cum + 0.5 * l) / L : 0.0;
      cum += l;
      m_len_d[idx] = l;
      m_len[idx] = float(l);
      if (!(l > 1e-9)) continue;  // zero-length segment: inert
      const double arm = std::max(arm_raw, l);
      const double I = sc * m_mu * arm * arm * arm / 3.0;
      const double ks = ref > 0 ? (arm / ref) * (arm / ref) : 1.0;
      const double gs = ref > 0 ? std::pow(arm / ref, 2.5) : 1.0;
      const double prof = 1.0 + (m_p.tip_stiffness - 1.0) * frac;
      m_arm_d[idx] = arm;
      m_inertia_d[idx] = I;
      m_kt_d[idx] = m_p.k_theta * prof * ks;
      m_kp_d[idx] = m_p.k_phi * prof * ks;
      m_gamma_d[idx] = m_p.damping * gs;
      m_gain[idx] = float(1.5 / (arm * sc));
      m_pen[idx] = float(3.0 * l / (arm * arm * sc));
      m_kt[idx] = float(m_kt_d[idx] / I);
      m_kp[idx] = float(m_kp_d[idx] / I);
      // Drag of the arm's own turn, ∫ c_w s² ds = c_w a³/3, over I = s μ a³/3.
      m_gd[idx] = float(m_gamma_d[idx] / I + m_p.drag / (m_mu * sc));
    }
  }
}

double HingeSolver::inertia(std::size_t s, int i) const {
  return m_inertia_d[row(s, i)];
}
double HingeSolver::k_theta(std::size_t s, int i) const {
  return m_kt_d[row(s, i)];
}
double HingeSolver::k_phi(std::size_t s, int i) const {
  return m_kp_d[row(s, i)];
}
double HingeSolver::damping(std::size_t s, int i) const {
  return m_gamma_d[row(s, i)];
}
double HingeSolver::arm(std::size_t s, int i) const {
  return m_arm_d[row(s, i)];
}

Vec3 HingeSolver::direction(std::size_t s, int i, double theta, double phi) const {
  const std::size_t idx = row(s, i);
  const Vec3 Y(m_fy[0][idx], m_fy[1][idx], m_fy[2][idx]),
      Z(m_fz[0][idx], m_fz[1][idx], m_fz[2][idx]);
  const Vec3 X = Y.cross(Z);
  const Vec3 dl = segment_direction(theta, phi);
  return dl.x() * X + dl.y() * Y + dl.z() * Z;
}

void HingeSolver::angles(std::size_t s, int i, const Vec3& dir, double phi_hint, double& theta,
                         double& phi) const {
  const std::size_t idx = row(s, i);
  const Vec3 Y(m_fy[0][idx], m_fy[1][idx], m_fy[2][idx]),
      Z(m_fz[0][idx], m_fz[1][idx], m_fz[2][idx]);
  const Vec3 X = Y.cross(Z);
  direction_angles(Vec3(dir.dot(X), dir.dot(Y), dir.dot(Z)), phi_hint, theta, phi);
}

HingeState HingeSolver::initial_state() const {
  HingeState st;
  const std::size_t N = m_n, KN = std::size_t(m_k) * N;
  st.theta.assign(m_theta0.begin(), m_theta0.end());
  st.phi.assign(m_phi0.begin(), m_phi0.end());
  st.dtheta.assign(KN, 0.0);
  st.dphi.assign(KN, 0.0);
  st.nodes.assign(std::size_t(m_k + 1) * N, Vec3::Zero());
  st.contact_distance.assign(KN, std::numeric_limits<float>::quiet_NaN());
  st.contact_normal.assign(KN, Vec3f::Zero());
  for (std::size_t s = 0; s < N; ++s) {
    const uint32_t b = m_rest.offsets[s];
    for (int i = 0; i <= m_k; ++i)
      st.nodes[std::size_t(i) * N + s] = m_rest.points[b + std::min(i, m_nseg[s])].cast<double>();
  }
  return st;
}

sim::StepReport HingeSolver::step(const Context& ctx, const HingeInput& in, HingeState& st) const {
  const std::size_t N = m_n, K = std::size_t(m_k);
  if (st.theta.size() != K * N || st.phi.size() != K * N || st.dtheta.size() != K * N ||
      st.dphi.size() != K * N || st.nodes.size() != (K + 1) * N)
    fail(
        "hinge solver: state has the wrong size (expected {} angles and {} nodes); use "
        "initial_state()",
        K * N, (K + 1) * N);
  const double h = m_p.dt / m_p.substeps;
  const Mat3 RT = in.head.rotation.normalized().toRotationMatrix().transpose();
  // Head-frame fields: the uniform part b (gravity and the frame's linear acceleration), the
  // angular velocity Ω and acceleration Λ; the air moves at RT (wind - v_0) - Ω × r relative to
  // the frame. Per unit mass: f(r, v) = b - Λ×r - Ω×(Ω×r) - 2 Ω×v + c_w/μ (u_air(r) - v).
  const Vec3 b = RT * (in.gravity - in.head.acceleration);
  const Vec3 om = RT * in.head.angular_velocity, la = RT * in.head.angular_acceleration;
  const double cw = m_p.drag / m_mu;
  const Vec3 h0 = cw * (RT * (in.wind_velocity - in.head.velocity));
  const Mat3 M = -skew(la) - skew(om) * skew(om) - cw * skew(om);

  StepArgs a;
  a.p = &m_p;
  a.body = m_body.get();
  a.N = N;
  a.K = K;
  a.nseg = m_nseg.data();
  a.len = m_len.data();
  a.gain = m_gain.data();
  a.pen = m_pen.data();
  a.kt = m_kt.data();
  a.kp = m_kp.data();
  a.gd = m_gd.data();
  a.th0 = m_theta0.data();
  a.ph0 = m_phi0.data();
  for (int c = 0; c < 3; ++c) {
    a.fy[c] = m_fy[c].data();
    a.fz[c] = m_fz[c].data();
    a.root[c] = m_root[c].data();
  }
  a.TH = st.theta.data();
  a.PH = st.phi.data();
  a.WT = st.dtheta.data();
  a.WP = st.dphi.data();
  a.nodes = st.nodes.data();
  if (st.contact_distance.size() != K * N)  // (a hand-made state)
    st.contact_distance.assign(K * N, std::numeric_limits<float>::quiet_NaN());
  if (st.contact_normal.size() != K * N) st.contact_normal.assign(K * N, Vec3f::Zero());
  a.cdist = st.contact_distance.data();
  a.cnorm = st.contact_normal.data();
  a.substeps = m_p.substeps;
  a.h = h;
  a.hf = float(h);
  a.b = to_f(b);
  a.h0 = to_f(h0);
  a.om = to_f(om);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a.M[3 * r + c] = float(M(r, c));
  a.cw = float(cw);
  a.kc = float(m_p.collision_k);
  a.cc = float(m_p.collision_c);
  a.contact = float(m_p.contact_distance);
  a.max_v2 = float(m_p.max_speed * m_p.max_speed);
  a.project = m_p.projection && m_body != nullptr;

  const std::size_t nchunks = (N + kChunk - 1) / kChunk;
  std::vector<sim::StepReport> reports(nchunks);
  std::vector<std::size_t> unresolved(nchunks, 0);
  parallel_chunks(ctx, N, kChunk, [&](std::size_t s0, std::size_t s1) {
    sim::StepReport rep;
    std::size_t u = 0;
    Scratch scratch;  // on the stack (~25 KB), no allocation per step
    step_block(a, s0, s1, rep, u, scratch);
    reports[s0 / kChunk] = rep;
    unresolved[s0 / kChunk] = u;
  });
  sim::StepReport out;
  st.unresolved = 0;
  for (std::size_t c = 0; c < nchunks; ++c) {
    out.merge(reports[c]);
    st.unresolved += unresolved[c];
  }
  if (!std::isfinite(out.max_speed)) out.max_speed = 0.0;
  out.finish("hinge_daldegan1993", m_p.max_speed);
  st.time += m_p.dt;
  ++st.step;
  return out;
}

void HingeSolver::positions(const HingeState& st, const HeadMotion& head,
                            geom::StrandSet& out) const {
  out.offsets = m_rest.offsets;
  out.points.resize(m_rest.points.size());
  const Mat3 R = head.rotation.normalized().toRotationMatrix();
  for (std::size_t s = 0; s < m_n; ++s) {
    const uint32_t b = m_rest.offsets[s];
    for (int i = 0; i <= m_nseg[s]; ++i)
      out.points[b + i] = (R * st.nodes[std::size_t(i) * m_n + s] + head.position).cast<float>();
  }
}

double HingeSolver::kinetic_energy(const HingeState& st) const {
  double e = 0;
  for (std::size_t idx = 0; idx < st.dtheta.size() && idx < m_inertia_d.size(); ++idx)
    e += 0.5 * m_inertia_d[idx] * (st.dtheta[idx] * st.dtheta[idx] + st.dphi[idx] * st.dphi[idx]);
  return e;
}

double HingeSolver::potential_energy(const HingeState& st, const HingeInput& in) const {
  const Vec3 g = in.head.rotation.normalized().toRotationMatrix().transpose() * in.gravity;
  double e = 0;
  for (std::size_t s = 0; s < m_n; ++s)
    for (int i = 1; i <= m_nseg[s]; ++i) {
      const std::size_t idx = row(s, i);
      if (!(m_len_d[idx] > 1e-9)) continue;
      const double dt = wrap_pi(st.theta[idx] - double(m_theta0[idx]));
      const double dp = wrap_pi(st.phi[idx] - double(m_phi0[idx]));
      const double a = m_arm_d[idx];
      e += 0.5 * m_kt_d[idx] * dt * dt + 0.5 * m_kp_d[idx] * dp * dp -
           m_mu * a * (0.5 * a) * g.dot(direction(s, i, st.theta[idx], st.phi[idx]));
    }
  return e;
}

}  // namespace follicle::hair
