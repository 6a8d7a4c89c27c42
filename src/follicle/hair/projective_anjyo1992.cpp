#include "follicle/hair/projective_anjyo1992.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/rng.hpp"

namespace follicle::hair {

void ProjectiveParams::validate() const {
  validate_params(*this, "projective");
  if (inertia != "paper" && inertia != "uniform")
    fail_at("projective.inertia", "unknown inertia arrangement \"{}\"; expected paper or uniform",
            inertia);
}

namespace {

double nearest_branch(double phi, double hint) {
  return phi + 2 * kPi * std::round((hint - phi) / (2 * kPi));
}

}  // namespace

void direction_angles(const Vec3& dir, double phi_hint, double& theta, double& phi) {
  const double h = std::hypot(dir.x(), dir.z());
  if (h < 1e-12) {
    phi = phi_hint;
    theta = dir.y() >= 0 ? 0.0 : kPi;
    return;
  }
  const double t1 = std::atan2(h, dir.y());
  const double p1 = nearest_branch(std::atan2(dir.x(), dir.z()), phi_hint);
  const double p2 = nearest_branch(std::atan2(dir.x(), dir.z()) + kPi, phi_hint);
  if (std::abs(p1 - phi_hint) <= std::abs(p2 - phi_hint)) {
    theta = t1;
    phi = p1;
  } else {
    theta = -t1;
    phi = p2;
  }
}

ProjectiveSolver::ProjectiveSolver(const ProjectiveParams& params, const sim::Ellipsoid& hull,
                                   const geom::StrandSet& rest, uint64_t seed)
    : m_p(params), m_hull(hull), m_rest(rest), m_seed(seed) {
  m_p.validate();
  m_n = rest.num_strands();
  for (std::size_t s = 0; s < m_n; ++s) {
    if (rest.strand_size(s) < 2) fail("projective solver: strand {} has fewer than 2 points", s);
    m_k = std::max(m_k, int(rest.strand_size(s)) - 1);
  }
  const std::size_t K = std::size_t(m_k), N = m_n;
  m_nseg.resize(N);
  m_len.assign(K * N, 0.0);
  m_gain.assign(K * N, 0.0);
  m_theta0.assign(K * N, 0.0);
  m_phi0.assign(K * N, 0.0);
  m_root.resize(N);
  for (std::size_t s = 0; s < N; ++s) {
    const uint32_t b = rest.offsets[s];
    const int k = int(rest.strand_size(s)) - 1;
    m_nseg[s] = k;
    m_root[s] = rest.points[b].cast<double>();
    double L = 0;
    for (int i = 1; i <= k; ++i)
      L += (rest.points[b + i] - rest.points[b + i - 1]).cast<double>().norm();
    double hint = 0;
    for (int i = 1; i <= k; ++i) {
      const std::size_t idx = std::size_t(i - 1) * N + s;
      const Vec3 seg = (rest.points[b + i] - rest.points[b + i - 1]).cast<double>();
      m_len[idx] = seg.norm();
      const Vec3 dir = m_len[idx] > 0 ? Vec3(seg / m_len[idx]) : Vec3(0, -1, 0);
      direction_angles(dir, hint, m_theta0[idx], m_phi0[idx]);
      hint = m_phi0[idx];
      // §3.2.1: I_i = I_S k / i with I_S = ρ L³/3 the strand's moment about the root; the
      // force and its lever are the strand's (ρ L a at L/2), so that c_i u_i F_θ reduces to
      // (3 i / (2 k L)) a_θ and the tip segment turns like the whole strand as a rigid stick.
      // "uniform": every segment like the tip.
      const double prof = m_p.inertia == "paper" ? double(i) / k : 1.0;
      m_gain[idx] = L > 0 ? m_p.inertia_scale * 1.5 * prof / L : 0.0;
    }
  }
  m_lenf.assign(m_len.begin(), m_len.end());
  m_gainf.assign(m_gain.begin(), m_gain.end());
  m_rootx.resize(N);
  m_rooty.resize(N);
  m_rootz.resize(N);
  for (std::size_t s = 0; s < N; ++s) {
    m_rootx[s] = float(m_root[s].x());
    m_rooty[s] = float(m_root[s].y());
    m_rootz[s] = float(m_root[s].z());
  }
  if (m_p.rest_spring > 0) {
    m_dir0x.resize(K * N);
    m_dir0y.resize(K * N);
    m_dir0z.resize(K * N);
    for (std::size_t idx = 0; idx < K * N; ++idx) {
      const Vec3 d0 = segment_direction(m_theta0[idx], m_phi0[idx]);
      m_dir0x[idx] = float(d0.x());
      m_dir0y[idx] = float(d0.y());
      m_dir0z[idx] = float(d0.z());
    }
  }
}

double ProjectiveSolver::gain(std::size_t s, int i) const {
  return m_gain[std::size_t(i - 1) * m_n + s];
}

ProjectiveState ProjectiveSolver::initial_state() const {
  ProjectiveState st;
  st.theta = m_theta0;
  st.theta_prev = m_theta0;
  st.phi = m_phi0;
  st.phi_prev = m_phi0;
  const std::size_t N = m_n;
  st.nodes.assign(std::size_t(m_k + 1) * N, Vec3::Zero());
  for (std::size_t s = 0; s < N; ++s) {
    const uint32_t b = m_rest.offsets[s];
    for (int i = 0; i <= m_k; ++i) {
      const int ii = std::min(i, m_nseg[s]);
      st.nodes[std::size_t(i) * N + s] = m_rest.points[b + ii].cast<double>();
    }
  }
  return st;
}

namespace {

constexpr std::size_t kChunk = 256;  // strands per block: ~30 float scratch rows stay in L1

// Per-block scratch (structure of arrays over the block's strands).
struct Scratch {
  float px[kChunk], py[kChunk], pz[kChunk];     // node p_{i-1} (advanced)
  float pdx[kChunk], pdy[kChunk], pdz[kChunk];  // final direction of s_{i-1}
  float vx[kChunk], vy[kChunk], vz[kChunk];     // displacement of p_{i-1} this step
  float tf[kChunk], pf[kChunk];                 // angles (reduced, float)
  float sth[kChunk], cth[kChunk], sph[kChunk], cph[kChunk];
  float ax[kChunk], ay[kChunk], az[kChunk];  // force per unit mass after the pseudo-force field
  float g[kChunk];                           // c_i u_i (with the top-of-head factor)
  float inc_t[kChunk], inc_p[kChunk];        // Δt² c u F_θ, Δt² c v F_φ
  float dx[kChunk], dy[kChunk], dz[kChunk];  // old direction of s_i
  float nx[kChunk], ny[kChunk], nz[kChunk];  // new direction of s_i
  float vm[kChunk];                          // largest squared speed of the strand's nodes
  float psth[kChunk], pcth[kChunk], psph[kChunk], pcph[kChunk];  // previous angles (pole)
  double c[8][kChunk];                                           // gathered pole-case lanes
  float len[kChunk], gain[kChunk], nsegf[kChunk];  // inputs copied in (padded to whole vectors)
  float d0x[kChunk], d0y[kChunk], d0z[kChunk];
  int list[kChunk];
  int flag[kChunk];
};

// GCC/Clang vector extensions: 4 floats, portable SIMD for the block loops (plain loops with
// selects are not auto-vectorised by GCC for SSE2).
typedef float vf __attribute__((vector_size(16)));
typedef int vi __attribute__((vector_size(16)));
constexpr std::size_t kW = 4;
inline vf ld(const float* p) {
  vf v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void st4(float* p, const vf& v) {
  std::memcpy(p, &v, sizeof v);
}
inline vf splat(float x) {
  return vf{x, x, x, x};
}

// sin and cos of n floats (n a multiple of kW; |x| <= ~1e3 as here, where angles are reduced to
// [-π, π]) with one shared reduction to [-π/4, π/4] (3-part Cody-Waite) and the single-precision
// minimax polynomials of Cephes sinf/cosf (about 1 ulp). Hand-written because neither libm nor
// Eigen offers a fused vector sincos (Eigen's separate sin and cos took a third of the step).
inline void sincos_block(const float* x, float* s, float* c, std::size_t n) {
  constexpr float magic = 12582912.0f;  // 1.5 * 2^23: x + magic rounds x to an integer
  for (std::size_t j = 0; j < n; j += kW) {
    const vf v = ld(x + j);
    const vf k = v * 0.636619772367581f + magic;  // 2/π
    vi q;
    std::memcpy(&q, &k, sizeof q);  // low mantissa bits of k: the quadrant
    const vf kf = k - magic;
    const vf r = ((v - kf * 1.5703125f) - kf * 4.837512969970703125e-4f) -
                 kf * 7.54978995489188216e-8f;  // π/2 in three parts
    const vf z = r * r;
    const vf sp = r + r * z * (-1.6666654611e-1f + z * (8.3321608736e-3f + z * -1.9515295891e-4f));
    const vf cp =
        1.0f - 0.5f * z +
        z * z * (4.166664568298827e-2f + z * (-1.388731625493765e-3f + z * 2.443315711809948e-5f));
    const vi swap = (q & 1) != 0;
    const vf sn = swap ? cp : sp, cs = swap ? sp : cp;
    st4(s + j, (q & 2) != 0 ? -sn : sn);
    st4(c + j, ((q + 1) & 2) != 0 ? -cs : cs);
  }
}
typedef double vd __attribute__((vector_size(16)));
constexpr std::size_t kWd = 2;
inline vd ldd(const double* p) {
  vd v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline vd splatd(double x) {
  return vd{x, x};
}
inline vd sqrt_v(vd x) {
  return vd{std::sqrt(x[0]), std::sqrt(x[1])};
}
inline vd abs_v(vd x) {
  return x < 0.0 ? -x : x;
}
// atan2 by the minimax polynomial of Abramowitz & Stegun 4.4.49 (|error| <= 2e-8 rad), 2 lanes.
inline vd atan2_v(vd y, vd x) {
  const vd ax = abs_v(x), ay = abs_v(y);
  const vd mx = ax > ay ? ax : ay, mn = ax > ay ? ay : ax;
  const vd a = mn / (mx > 0.0 ? mx : splatd(1.0)), s = a * a;
  vd r =
      a *
      (1.0 +
       s * (-0.3333314528 +
            s * (0.1999355085 +
                 s * (-0.1420889944 +
                      s * (0.1065626393 +
                           s * (-0.0752896400 +
                                s * (0.0429096138 + s * (-0.0161657367 + s * 0.0028662257))))))));
  r = ay > ax ? 0.5 * kPi - r : r;
  r = x < 0.0 ? kPi - r : r;
  return y < 0.0 ? -r : r;
}
inline vd nearest_branch_v(vd phi, vd hint) {
  constexpr double magic = 6755399441055744.0;  // rounds to nearest by two additions
  const vd k = ((hint - phi) * (1.0 / (2.0 * kPi)) + magic) - magic;
  return phi + 2.0 * kPi * k;
}
// direction_angles() for two directions at once (same branch rule).
inline void direction_angles_v(vd x, vd y, vd z, vd hint, vd& theta, vd& phi) {
  const vd h = sqrt_v(x * x + z * z);
  const vd t1 = atan2_v(h, y), a = atan2_v(x, z);
  const vd p1 = nearest_branch_v(a, hint), p2 = nearest_branch_v(a + kPi, hint);
  const auto first = abs_v(p1 - hint) <= abs_v(p2 - hint);
  const auto pole = h < 1e-12;
  theta = pole ? (y >= 0.0 ? splatd(0.0) : splatd(kPi)) : (first ? t1 : -t1);
  phi = pole ? hint : (first ? p1 : p2);
}

// Angle reduced to [-π, π] for the single-precision sin/cos (φ may wind up over time)
// (k rounded by the 1.5 * 2^52 trick: pure additions, so the loop vectorises; NaN and Inf give
// NaN.)
inline float reduce_angle(double x) {
  constexpr double inv2pi = 1.0 / (2.0 * kPi), magic = 6755399441055744.0;
  const double k = (x * inv2pi + magic) - magic;
  return float(x - 2.0 * kPi * k);
}

// atan2 by the minimax polynomial of Abramowitz & Stegun 4.4.49 (|error| <= 2e-8 rad on [0, 1]),
// inline instead of libm because the hot fix-up loops call it for a third of all segments.
inline double atan2_fast(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const double mx = std::max(ax, ay), mn = std::min(ax, ay);
  const double a = mx > 0 ? mn / mx : 0.0, s = a * a;
  double r =
      a *
      (1.0 +
       s * (-0.3333314528 +
            s * (0.1999355085 +
                 s * (-0.1420889944 +
                      s * (0.1065626393 +
                           s * (-0.0752896400 +
                                s * (0.0429096138 + s * (-0.0161657367 + s * 0.0028662257))))))));
  if (ay > ax) r = 0.5 * kPi - r;
  if (x < 0) r = kPi - r;
  return y < 0 ? -r : r;
}

inline double nearest_branch_fast(double phi, double hint) {
  const double v = (hint - phi) * (1.0 / (2.0 * kPi));
  const double k = (v > -1e9 && v < 1e9) ? double(int64_t(v + (v >= 0 ? 0.5 : -0.5))) : 0.0;
  return phi + 2.0 * kPi * k;
}

// direction_angles() for a single-precision direction with the fast atan2 (same branch rule).
inline void direction_angles_fast(double x, double y, double z, double phi_hint, double& theta,
                                  double& phi) {
  const double h = std::sqrt(x * x + z * z);
  if (h < 1e-12) {
    phi = phi_hint;
    theta = y >= 0 ? 0.0 : kPi;
    return;
  }
  const double t1 = atan2_fast(h, y), a = atan2_fast(x, z);
  const double p1 = nearest_branch_fast(a, phi_hint), p2 = nearest_branch_fast(a + kPi, phi_hint);
  if (std::abs(p1 - phi_hint) <= std::abs(p2 - phi_hint)) {
    theta = t1;
    phi = p1;
  } else {
    theta = -t1;
    phi = p2;
  }
}

}  // namespace

// One step of (4)' and (5)'. Layout: [segment][strand] rows; the loop runs over blocks of
// kChunk strands (parallel_chunks), and inside a block over segments i = 1..K (root to tip, each
// segment needs the advanced p_{i-1}) with simple inner loops over the block's strands that the
// compiler vectorises. The arithmetic is single precision, the angle state double (the
// increments are added in double, so tiny steps are not lost). Rare cases (segment nearly
// parallel to y, joint angle clamped by σ, node pushed out of the hull, fluctuation) are
// flagged in the vector loops and redone per strand in double precision afterwards. Every
// strand's result depends only on its own data, so any thread count gives identical output.
sim::StepReport ProjectiveSolver::step(const Context& ctx, const ProjectiveInput& in,
                                       ProjectiveState& st) const {
  const std::size_t N = m_n, K = std::size_t(m_k);
  const double dt = m_p.dt, dt2 = dt * dt;
  const Mat3 RT = in.head.rotation.toRotationMatrix().transpose();
  // Forces in the head frame: gravity, wind, and the inertial (fictitious) forces of the moving
  // frame: -a_0 - α × r - ω × (ω × r) (Coriolis is neglected, as the paper neglects friction).
  const Vec3 base = RT * (in.gravity + in.wind - in.head.acceleration);
  const Vec3 w = RT * in.head.angular_velocity;
  const Vec3 al = RT * in.head.angular_acceleration;
  const bool fluct = m_p.fluctuation > 0 && st.step % uint64_t(m_p.fluctuation_interval) == 0;
  const double cos_sig_root = std::cos(m_p.stiffness_root_deg * kPi / 180.0);
  const double cos_sig = std::cos(m_p.stiffness_deg * kPi / 180.0);
  const double damp = 1.0 - m_p.damping * dt;
  const double alpha = m_p.alpha;
  // Hull in the head frame: q = M (p - c), M = diag(1/r) R^T; gradient ∝ R (q ./ r).
  const Mat3 Mq = m_hull.radii.cwiseInverse().asDiagonal() * m_hull.rotation.transpose();
  const Mat3 Mg = m_hull.rotation * m_hull.radii.cwiseInverse().asDiagonal();
  const Eigen::Matrix3f mq = Mq.cast<float>(), mg = Mg.cast<float>();
  const Eigen::Vector3f cf = m_hull.centre.cast<float>();
  const float near2 = float((1.0 + m_p.near_head) * (1.0 + m_p.near_head));
  const float alpha2 = float(alpha * alpha), epsf = float(m_p.epsilon);
  const float bx = float(base.x()), by = float(base.y()), bz = float(base.z());
  const float wx = float(w.x()), wy = float(w.y()), wz = float(w.z());
  const float lx = float(al.x()), ly = float(al.y()), lz = float(al.z());
  const float dt2f = float(dt2), top_scale = float(m_p.top_inertia_scale);
  const float top_h = float(m_p.top_height), rest_k = float(m_p.rest_spring);
  const float pole = float(m_p.parallel_threshold), ext = float(m_p.epsilon_extent);
  const bool top = m_p.top_inertia_scale != 1.0, rest = m_p.rest_spring > 0;
  const bool pseudo = m_p.pseudo_force, rotating = w.squaredNorm() + al.squaredNorm() > 0;
  const float inv_dt2 = float(1.0 / dt2), max_v2 = float(m_p.max_speed * m_p.max_speed);
  const std::size_t nchunks = (N + kChunk - 1) / kChunk;
  std::vector<sim::StepReport> reports(nchunks);
  // New angles are written over the previous ones (read first), then the arrays are swapped.
  double* TH = st.theta.data();
  double* PH = st.phi.data();
  double* THN = st.theta_prev.data();
  double* PHN = st.phi_prev.data();

  parallel_chunks(ctx, N, kChunk, [&](std::size_t s0, std::size_t s1) {
    sim::StepReport rep;
    const std::size_t n = s1 - s0;
    std::unique_ptr<Scratch> sp(new Scratch);
    Scratch& S = *sp;
    const int* nseg = m_nseg.data() + s0;
    for (std::size_t j = 0; j < n; ++j) {
      S.px[j] = m_rootx[s0 + j];
      S.py[j] = m_rooty[s0 + j];
      S.pz[j] = m_rootz[s0 + j];
      S.pdx[j] = S.pdy[j] = S.pdz[j] = 0.0f;
      S.vx[j] = S.vy[j] = S.vz[j] = 0.0f;
      S.vm[j] = 0.0f;
      S.nsegf[j] = float(nseg[j]);
    }
    const std::size_t n4 = (n + kW - 1) / kW * kW;
    for (std::size_t j = n; j < n4; ++j) {  // padding lanes: inactive, zero-length segments
      S.px[j] = S.py[j] = S.pz[j] = 0.0f;
      S.nsegf[j] = 0.0f;
      S.len[j] = S.gain[j] = S.tf[j] = S.pf[j] = 0.0f;
      S.d0x[j] = S.d0y[j] = S.d0z[j] = 0.0f;
    }
    for (std::size_t i = 1; i <= K; ++i) {
      const std::size_t row = (i - 1) * N + s0;
      const double* th = TH + row;
      const double* ph = PH + row;
      double* thn = THN + row;  // in: θ^{n-1}; out: θ^{n+1}
      double* phn = PHN + row;
      const float* len = m_lenf.data() + row;
      const float* gain = m_gainf.data() + row;
      const bool root_joint = int(i - 1) <= m_p.stiffness_root_segments;
      const double cs = root_joint ? cos_sig_root : cos_sig;
      const float fi = float(i);

      for (std::size_t j = 0; j < n; ++j) {
        S.tf[j] = reduce_angle(th[j]);
        S.pf[j] = reduce_angle(ph[j]);
        S.len[j] = len[j];
        S.gain[j] = gain[j];
      }
      if (rest) {
        for (std::size_t j = 0; j < n; ++j) {
          S.d0x[j] = m_dir0x[row + j];
          S.d0y[j] = m_dir0y[row + j];
          S.d0z[j] = m_dir0z[row + j];
        }
      }
      sincos_block(S.tf, S.sth, S.cth, n4);
      sincos_block(S.pf, S.sph, S.cph, n4);

      // Forces, pseudo-force field (§3.2.2), top-of-head inertia, (4)' and (5)' increments.
      const vf one = splat(1.0f), zero = splat(0.0f);
      for (std::size_t j = 0; j < n4; j += kW) {
        const vf d = ld(S.len + j);
        const vf sth = ld(S.sth + j), cth = ld(S.cth + j), sph = ld(S.sph + j), cph = ld(S.cph + j);
        const vf dx = sth * sph, dy = cth, dz = sth * cph;
        st4(S.dx + j, dx);
        st4(S.dy + j, dy);
        st4(S.dz + j, dz);
        const vf px = ld(S.px + j), py = ld(S.py + j), pz = ld(S.pz + j);
        vf ax = splat(bx), ay = splat(by), az = splat(bz);
        if (rotating) {
          // -α × mid - ω × (ω × mid) at the segment midpoint
          const vf mx = px + 0.5f * d * dx, my = py + 0.5f * d * dy, mz = pz + 0.5f * d * dz;
          const vf cx = wy * mz - wz * my, cy = wz * mx - wx * mz, cz = wx * my - wy * mx;
          ax -= (ly * mz - lz * my) + (wy * cz - wz * cy);
          ay -= (lz * mx - lx * mz) + (wz * cx - wx * cz);
          az -= (lx * my - ly * mx) + (wx * cy - wy * cx);
        }
        const vf nsf = ld(S.nsegf + j);
        if (pseudo) {
          // Near the head ((|q| - 1) < near_head) and against it ((D, F) < α |D| |F|) -> ε F.
          const vf ex = px + d * dx - cf.x(), ey = py + d * dy - cf.y(), ez = pz + d * dz - cf.z();
          const vf qx = mq(0, 0) * ex + mq(0, 1) * ey + mq(0, 2) * ez;
          const vf qy = mq(1, 0) * ex + mq(1, 1) * ey + mq(1, 2) * ez;
          const vf qz = mq(2, 0) * ex + mq(2, 1) * ey + mq(2, 2) * ez;
          const vf q2 = qx * qx + qy * qy + qz * qz;
          const vf Dx = mg(0, 0) * qx + mg(0, 1) * qy + mg(0, 2) * qz;
          const vf Dy = mg(1, 0) * qx + mg(1, 1) * qy + mg(1, 2) * qz;
          const vf Dz = mg(2, 0) * qx + mg(2, 1) * qy + mg(2, 2) * qz;
          const vf da = Dx * ax + Dy * ay + Dz * az;
          const vf t = alpha2 * (Dx * Dx + Dy * Dy + Dz * Dz) * (ax * ax + ay * ay + az * az);
          // da < α |D||a| without square roots (sign cases of α and da).
          const vi against = alpha < 0 ? ((da < 0) & (da * da > t)) : ((da < 0) | (da * da < t));
          const vi applies = (fi <= ext * nsf + 1e-6f) & (q2 < near2) & against;
          const vf f = applies ? splat(epsf) : one;
          ax *= f;
          ay *= f;
          az *= f;
        }
        vf G = ld(S.gain + j);
        if (top) {
          const vf ey =
              mq(1, 0) * (px - cf.x()) + mq(1, 1) * (py - cf.y()) + mq(1, 2) * (pz - cf.z());
          G = ey > top_h ? G * top_scale : G;
        }
        if (rest) {
          const vf r = G > 0 ? rest_k / (G > 0 ? G : one) : zero;
          ax += r * (ld(S.d0x + j) - dx);
          ay += r * (ld(S.d0y + j) - dy);
          az += r * (ld(S.d0z + j) - dz);
        }
        st4(S.ax + j, ax);
        st4(S.ay + j, ay);
        st4(S.az + j, az);
        st4(S.g + j, G);
        const vf Fth = ax * cth * sph - ay * sth + az * cth * cph;  // (F, V_θ)
        const vf Fph0 = ax * cph - az * sph;                        // (F, V_φ) up to sign θ
        const vf abs_sth = sth < 0 ? -sth : sth;
        const vf Fph = sth >= 0 ? Fph0 : -Fph0;
        // (4)' and (5)': u_i = |s_i|/2, v_i = |s_i| |sin θ| / 2 -> v_i / u_i = |sin θ|.
        st4(S.inc_t + j, dt2f * G * Fth);
        st4(S.inc_p + j, dt2f * G * abs_sth * Fph);
        const vi fl = (abs_sth < pole) & (fi <= nsf);
        std::memcpy(S.flag + j, &fl, sizeof fl);
      }
      std::size_t m = 0;
      for (std::size_t j = 0; j < n; ++j) {
        S.list[m] = int(j);
        m += std::size_t(S.flag[j] != 0);
      }
      for (std::size_t q = 0; q < m; ++q) {
        S.tf[q] = reduce_angle(thn[S.list[q]]);  // still θ^{n-1}, φ^{n-1}
        S.pf[q] = reduce_angle(phn[S.list[q]]);
      }
      sincos_block(S.tf, S.psth, S.pcth, m);
      sincos_block(S.pf, S.psph, S.pcph, m);
      // Gathered into contiguous lanes, then two strands at a time in double precision.
      for (std::size_t q = 0; q < m; ++q) {
        const std::size_t j = std::size_t(S.list[q]);
        S.c[0][q] = S.dx[j];
        S.c[1][q] = S.dy[j];
        S.c[2][q] = S.dz[j];
        S.c[3][q] = double(S.psth[q]) * S.psph[q];
        S.c[4][q] = double(S.psth[q]) * S.pcph[q];
        S.c[5][q] = dt2 * double(S.g[j]) * S.ax[j];
        S.c[6][q] = dt2 * double(S.g[j]) * S.az[j];
        S.c[7][q] = ph[j];
      }
      for (std::size_t q = m; q < (m + kWd - 1) / kWd * kWd; ++q)
        for (auto& c : S.c) c[q] = 0.0;
      for (std::size_t q = 0; q < m; q += kWd) {
        const vd hx = ldd(S.c[0] + q), dy = ldd(S.c[1] + q), hz = ldd(S.c[2] + q);
        vd nx = hx + damp * (hx - ldd(S.c[3] + q)) + ldd(S.c[5] + q);
        vd nz = hz + damp * (hz - ldd(S.c[4] + q)) + ldd(S.c[6] + q);
        const vd h2 = nx * nx + nz * nz;
        const vd r = h2 > 1.0 ? 1.0 / sqrt_v(h2 > 1.0 ? h2 : splatd(1.0)) : splatd(1.0);
        nx *= r;
        nz *= r;
        const vd y2 = 1.0 - nx * nx - nz * nz;
        const vd yv = sqrt_v(y2 > 0.0 ? y2 : splatd(0.0));
        vd tn, pn, t, p;
        direction_angles_v(nx, dy >= 0.0 ? yv : -yv, nz, ldd(S.c[7] + q), tn, pn);
        direction_angles_v(hx, dy, hz, pn, t, p);  // the current angles on the same branch
        std::memcpy(S.c[0] + q, &tn, sizeof tn);
        std::memcpy(S.c[1] + q, &pn, sizeof pn);
        std::memcpy(S.c[2] + q, &t, sizeof t);
        std::memcpy(S.c[3] + q, &p, sizeof p);
      }
      for (std::size_t j = 0; j < n; ++j) {
        const double t0 = th[j], p0 = ph[j];
        thn[j] = t0 + damp * (t0 - thn[j]) + double(S.inc_t[j]);
        phn[j] = p0 + damp * (p0 - phn[j]) + double(S.inc_p[j]);
      }
      for (std::size_t q = 0; q < m; ++q) {
        const std::size_t j = std::size_t(S.list[q]);
        thn[j] = S.c[0][q];
        phn[j] = S.c[1][q];
        TH[row + j] = S.c[2][q];
        PH[row + j] = S.c[3][q];
      }
      if (fluct) {
        for (std::size_t j = 0; j < n; ++j) {
          if (int(i) > nseg[j]) continue;
          const std::size_t idx = row + j;
          Rng rng = Rng::stream(m_seed ^ (st.step * 0x9E3779B97F4A7C15ull), idx);
          thn[j] += m_p.fluctuation * rng.uniform(-1.0, 1.0);
          phn[j] += m_p.fluctuation * rng.uniform(-1.0, 1.0);
        }
      }
      if (fluct) {
        for (std::size_t j = 0; j < n; ++j) {
          S.tf[j] = reduce_angle(thn[j]);
          S.pf[j] = reduce_angle(phn[j]);
        }
        sincos_block(S.tf, S.sth, S.cth, n);
        sincos_block(S.pf, S.sph, S.cph, n);
      } else {
        // sin/cos of the new angles from the old ones by the addition theorems with short Taylor
        // series of the (small) change; changes above 0.1 rad and the pole lanes (re-branched
        // angles) are recomputed directly.
        for (std::size_t j = 0; j < n; ++j) {
          S.tf[j] = float(thn[j] - th[j]);
          S.pf[j] = float(phn[j] - ph[j]);
        }
        for (std::size_t j = 0; j < n4; j += kW) {
          const vf a = ld(S.tf + j), b = ld(S.pf + j);
          const vf za = a * a, zb = b * b;
          const vf sa = a * (1.0f - za * (1.0f / 6.0f) * (1.0f - za * 0.05f));
          const vf ca = 1.0f - za * 0.5f * (1.0f - za * (1.0f / 12.0f));
          const vf sb = b * (1.0f - zb * (1.0f / 6.0f) * (1.0f - zb * 0.05f));
          const vf cb = 1.0f - zb * 0.5f * (1.0f - zb * (1.0f / 12.0f));
          const vf s_t = ld(S.sth + j), c_t = ld(S.cth + j);
          const vf s_p = ld(S.sph + j), c_p = ld(S.cph + j);
          st4(S.sth + j, s_t * ca + c_t * sa);
          st4(S.cth + j, c_t * ca - s_t * sa);
          st4(S.sph + j, s_p * cb + c_p * sb);
          st4(S.cph + j, c_p * cb - s_p * sb);
          const vi big = ((a > 0.1f) | (a < -0.1f) | (b > 0.1f) | (b < -0.1f));
          vi fl;
          std::memcpy(&fl, S.flag + j, sizeof fl);
          fl = fl | big;
          std::memcpy(S.flag + j, &fl, sizeof fl);
        }
        std::size_t mb = 0;
        for (std::size_t j = 0; j < n; ++j) {
          S.list[mb] = int(j);
          mb += std::size_t(S.flag[j] != 0);
        }
        for (std::size_t q = 0; q < mb; ++q) {
          S.tf[q] = reduce_angle(thn[S.list[q]]);
          S.pf[q] = reduce_angle(phn[S.list[q]]);
        }
        sincos_block(S.tf, S.psth, S.pcth, mb);
        sincos_block(S.pf, S.psph, S.pcph, mb);
        for (std::size_t q = 0; q < mb; ++q) {
          const std::size_t j = std::size_t(S.list[q]);
          S.sth[j] = S.psth[q];
          S.cth[j] = S.pcth[q];
          S.sph[j] = S.psph[q];
          S.cph[j] = S.pcph[q];
        }
      }
      for (std::size_t j = 0; j < n; ++j) {
        S.nx[j] = S.sth[j] * S.sph[j];
        S.ny[j] = S.cth[j];
        S.nz[j] = S.sth[j] * S.cph[j];
      }
      // §3.2.3 joint angle ϑ at p_{i-1} (the bend between s_{i-1} and s_i) limited to σ: flagged
      // in single precision with a small margin, clamped exactly in double per strand.
      if (i >= 2 && cs > -1.0) {
        // Clamped to σ minus 2e-5 rad so that single-precision rounding never exceeds σ.
        const double csm = std::cos(std::acos(cs) - 2e-5), ssm = std::sqrt(1.0 - csm * csm);
        const float csf = float(csm);
        std::size_t mc = 0;
        for (std::size_t j = 0; j < n; ++j) {
          const float c = S.pdx[j] * S.nx[j] + S.pdy[j] * S.ny[j] + S.pdz[j] * S.nz[j];
          S.list[mc] = int(j);
          mc += std::size_t((c < csf) & (fi <= float(nseg[j])));
        }
        for (std::size_t q = 0; q < mc; ++q) {
          const std::size_t j = std::size_t(S.list[q]);
          S.c[0][q] = S.pdx[j];
          S.c[1][q] = S.pdy[j];
          S.c[2][q] = S.pdz[j];
          S.c[3][q] = S.nx[j];
          S.c[4][q] = S.ny[j];
          S.c[5][q] = S.nz[j];
          S.c[6][q] = phn[j];
        }
        for (std::size_t q = mc; q < (mc + kWd - 1) / kWd * kWd; ++q)
          for (auto& c : S.c) c[q] = 0.0;
        for (std::size_t q = 0; q < mc; q += kWd) {
          const vd px = ldd(S.c[0] + q), py = ldd(S.c[1] + q), pz = ldd(S.c[2] + q);
          const vd nx = ldd(S.c[3] + q), ny = ldd(S.c[4] + q), nz = ldd(S.c[5] + q);
          const vd c = px * nx + py * ny + pz * nz;
          vd ex = nx - c * px, ey = ny - c * py, ez = nz - c * pz;
          const vd en = sqrt_v(ex * ex + ey * ey + ez * ez);
          // Antiparallel (no plane): any direction perpendicular to pd.
          const auto deg = en <= 1e-6;
          const vd ox = abs_v(px) < 0.9 ? splatd(0.0) : -pz,
                   oy = abs_v(px) < 0.9 ? -pz : splatd(0.0),
                   oz = abs_v(px) < 0.9 ? py : px;  // pd × (x or y axis)
          ex = deg ? ox : ex;
          ey = deg ? oy : ey;
          ez = deg ? oz : ez;
          const vd inv = 1.0 / sqrt_v(ex * ex + ey * ey + ez * ez);
          const vd dx = csm * px + ssm * ex * inv, dy = csm * py + ssm * ey * inv,
                   dz = csm * pz + ssm * ez * inv;
          vd tn, pn;
          direction_angles_v(dx, dy, dz, ldd(S.c[6] + q), tn, pn);
          std::memcpy(S.c[0] + q, &tn, sizeof tn);
          std::memcpy(S.c[1] + q, &pn, sizeof pn);
          std::memcpy(S.c[3] + q, &dx, sizeof dx);
          std::memcpy(S.c[4] + q, &dy, sizeof dy);
          std::memcpy(S.c[5] + q, &dz, sizeof dz);
        }
        for (std::size_t q = 0; q < mc; ++q) {
          const std::size_t j = std::size_t(S.list[q]);
          thn[j] = S.c[0][q];
          phn[j] = S.c[1][q];
          S.nx[j] = float(S.c[3][q]);
          S.ny[j] = float(S.c[4][q]);
          S.nz[j] = float(S.c[5][q]);
        }
      }
      if (m_p.ellipsoid_constraint) {
        for (std::size_t j = 0; j < n; ++j) {
          if (int(i) > nseg[j]) continue;
          const double d = m_len[row + j];
          const Vec3 p0(S.px[j], S.py[j], S.pz[j]);
          const Vec3 pnew = p0 + d * Vec3(S.nx[j], S.ny[j], S.nz[j]);
          if (m_hull.value(pnew) >= 0) continue;
          const Vec3 t = m_hull.push_out(pnew) - p0;
          if (!(t.norm() > 0)) continue;
          const Vec3 nd = t.normalized();
          double tn = thn[j], pn = phn[j];
          direction_angles(nd, pn, tn, pn);
          thn[j] = tn;
          phn[j] = pn;
          S.nx[j] = float(nd.x());
          S.ny[j] = float(nd.y());
          S.nz[j] = float(nd.z());
        }
      }
      // Advance p_i; the node's displacement accumulates the change of the segment directions
      // from the root, which gives the speed without reading the old positions.
      Vec3* node = st.nodes.data() + i * N + s0;
      int bad = 0;
      for (std::size_t j = 0; j < n; ++j) {
        const float d = len[j];
        S.px[j] += d * S.nx[j];
        S.py[j] += d * S.ny[j];
        S.pz[j] += d * S.nz[j];
        S.vx[j] += d * (S.nx[j] - S.dx[j]);
        S.vy[j] += d * (S.ny[j] - S.dy[j]);
        S.vz[j] += d * (S.nz[j] - S.dz[j]);
        S.pdx[j] = S.nx[j];
        S.pdy[j] = S.ny[j];
        S.pdz[j] = S.nz[j];
        const float v2 = (S.vx[j] * S.vx[j] + S.vy[j] * S.vy[j] + S.vz[j] * S.vz[j]) * inv_dt2;
        S.vm[j] = v2 > S.vm[j] ? v2 : S.vm[j];
        bad |= !(v2 <= max_v2);  // NaN fails every comparison
      }
      for (std::size_t j = 0; j < n; ++j) node[j] = Vec3(S.px[j], S.py[j], S.pz[j]);
      if (bad) {
        for (std::size_t j = 0; j < n; ++j) {
          const float v2 = (S.vx[j] * S.vx[j] + S.vy[j] * S.vy[j] + S.vz[j] * S.vz[j]) * inv_dt2;
          if (!std::isfinite(thn[j]) || !std::isfinite(phn[j]) || !std::isfinite(S.px[j]) ||
              !std::isfinite(S.py[j]) || !std::isfinite(S.pz[j]))
            rep.mark_non_finite(s0 + j);
          else if (v2 > max_v2)
            rep.mark_blow_up(s0 + j);
        }
      }
    }
    float vmax2 = 0.0f;
    for (std::size_t j = 0; j < n; ++j) vmax2 = std::max(vmax2, S.vm[j]);
    rep.max_speed = std::sqrt(double(vmax2));
    reports[s0 / kChunk] = rep;
  });
  std::swap(st.theta, st.theta_prev);
  std::swap(st.phi, st.phi_prev);
  sim::StepReport out;
  for (const auto& r : reports) out.merge(r);
  out.finish("projective_anjyo1992", m_p.max_speed);
  ++st.step;
  return out;
}

void ProjectiveSolver::positions(const ProjectiveState& st, const HeadMotion& head,
                                 geom::StrandSet& out) const {
  out.offsets = m_rest.offsets;
  out.points.resize(m_rest.points.size());
  const Mat3 R = head.rotation.toRotationMatrix();
  for (std::size_t s = 0; s < m_n; ++s) {
    const uint32_t b = m_rest.offsets[s];
    for (int i = 0; i <= m_nseg[s]; ++i)
      out.points[b + i] = (R * st.nodes[std::size_t(i) * m_n + s] + head.position).cast<float>();
  }
}

}  // namespace follicle::hair
