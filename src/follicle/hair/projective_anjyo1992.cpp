#include "follicle/hair/projective_anjyo1992.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include <Eigen/Core>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/rng.hpp"

long g_pole = 0, g_clamp = 0;
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
  float vm[kChunk];  // largest squared speed of the strand's nodes
  int flag[kChunk];
};

// Angle reduced to (-2π, 2π) for the single-precision sin/cos (φ may wind up over time); NaN and
// huge values map to 0 (the double state keeps them, so blow-ups are still reported).
inline float reduce_angle(double x) {
  constexpr double inv2pi = 1.0 / (2.0 * kPi);
  const double xc = (x > -1e9) & (x < 1e9) ? x : 0.0;
  return float(xc - 2.0 * kPi * double(int(xc * inv2pi)) + (x - x));  // x - x: NaN for NaN/Inf
}

// Vectorised sin/cos of n floats (Eigen's SIMD psin/pcos; hand-written loops with libm calls do
// not vectorise).
inline void sincos_block(const float* x, float* s, float* c, std::size_t n) {
  using A = Eigen::Array<float, Eigen::Dynamic, 1>;
  const Eigen::Map<const A> X(x, Eigen::Index(n));
  Eigen::Map<A>(s, Eigen::Index(n)) = X.sin();
  Eigen::Map<A>(c, Eigen::Index(n)) = X.cos();
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
  const double sin_sig_root = std::sin(m_p.stiffness_root_deg * kPi / 180.0);
  const double sin_sig = std::sin(m_p.stiffness_deg * kPi / 180.0);
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
      const double ss = root_joint ? sin_sig_root : sin_sig;
      const float fi = float(i);

      for (std::size_t j = 0; j < n; ++j) {
        S.tf[j] = reduce_angle(th[j]);
        S.pf[j] = reduce_angle(ph[j]);
      }
      sincos_block(S.tf, S.sth, S.cth, n);
      sincos_block(S.pf, S.sph, S.cph, n);

      // Forces, pseudo-force field (§3.2.2), top-of-head inertia, (4)' and (5)' increments.
      for (std::size_t j = 0; j < n; ++j) {
        const float d = len[j];
        const float dx = S.sth[j] * S.sph[j], dy = S.cth[j], dz = S.sth[j] * S.cph[j];
        S.dx[j] = dx;
        S.dy[j] = dy;
        S.dz[j] = dz;
        float ax = bx, ay = by, az = bz;
        if (rotating) {
          // -α × mid - ω × (ω × mid) at the segment midpoint
          const float mx = S.px[j] + 0.5f * d * dx, my = S.py[j] + 0.5f * d * dy,
                      mz = S.pz[j] + 0.5f * d * dz;
          const float cx = wy * mz - wz * my, cy = wz * mx - wx * mz, cz = wx * my - wy * mx;
          ax -= (ly * mz - lz * my) + (wy * cz - wz * cy);
          ay -= (lz * mx - lx * mz) + (wz * cx - wx * cz);
          az -= (lx * my - ly * mx) + (wx * cy - wy * cx);
        }
        if (pseudo) {
          // Near the head ((|q| - 1) < near_head) and against it ((D, F) < α |D| |F|) -> ε F.
          const float ex = S.px[j] + d * dx - cf.x(), ey = S.py[j] + d * dy - cf.y(),
                      ez = S.pz[j] + d * dz - cf.z();
          const float qx = mq(0, 0) * ex + mq(0, 1) * ey + mq(0, 2) * ez;
          const float qy = mq(1, 0) * ex + mq(1, 1) * ey + mq(1, 2) * ez;
          const float qz = mq(2, 0) * ex + mq(2, 1) * ey + mq(2, 2) * ez;
          const float q2 = qx * qx + qy * qy + qz * qz;
          const float Dx = mg(0, 0) * qx + mg(0, 1) * qy + mg(0, 2) * qz;
          const float Dy = mg(1, 0) * qx + mg(1, 1) * qy + mg(1, 2) * qz;
          const float Dz = mg(2, 0) * qx + mg(2, 1) * qy + mg(2, 2) * qz;
          const float da = Dx * ax + Dy * ay + Dz * az;
          const float t = alpha2 * (Dx * Dx + Dy * Dy + Dz * Dz) * (ax * ax + ay * ay + az * az);
          // da < α |D||a| without square roots (sign cases of α and da).
          const bool against = alpha < 0 ? ((da < 0) & (da * da > t)) : ((da < 0) | (da * da < t));
          const bool applies = (fi <= ext * float(nseg[j]) + 1e-6f) & (q2 < near2) & against;
          const float f = applies ? epsf : 1.0f;
          ax *= f;
          ay *= f;
          az *= f;
        }
        float G = gain[j];
        if (top) {
          const float ey = (mq(1, 0) * (S.px[j] - cf.x()) + mq(1, 1) * (S.py[j] - cf.y()) +
                            mq(1, 2) * (S.pz[j] - cf.z()));
          G = ey > top_h ? G * top_scale : G;
        }
        if (rest) {
          const float r = G > 0 ? rest_k / G : 0.0f;
          ax += r * (m_dir0x[row + j] - dx);
          ay += r * (m_dir0y[row + j] - dy);
          az += r * (m_dir0z[row + j] - dz);
        }
        S.ax[j] = ax;
        S.ay[j] = ay;
        S.az[j] = az;
        S.g[j] = G;
        const float sth = S.sth[j], cth = S.cth[j], sph = S.sph[j], cph = S.cph[j];
        const float Fth = ax * cth * sph - ay * sth + az * cth * cph;  // (F, V_θ)
        const float sgn = sth >= 0 ? 1.0f : -1.0f;
        const float Fph = sgn * (ax * cph - az * sph);  // (F, V_φ)
        // (4)' and (5)': u_i = |s_i|/2, v_i = |s_i| |sin θ| / 2 -> v_i / u_i = |sin θ|.
        S.inc_t[j] = dt2f * G * Fth;
        S.inc_p[j] = dt2f * G * std::abs(sth) * Fph;
        S.flag[j] = (std::abs(sth) < pole) & (fi <= float(nseg[j]));
      }
      // Segment nearly parallel to y: the θ plane is spanned by y and F (Fig. 8), so the segment
      // turns towards the horizontal part of F with θ'' = c u F_θ. Near the pole this is the
      // small-angle form of (4)' for the horizontal offset h = (x, z) of the direction, written
      // as a vector so the state does not jump when the plane follows F. (Rare: per strand, in
      // double precision, before the general update overwrites θ^{n-1}.)
      for (std::size_t j = 0; j < n; ++j) {
        if (!S.flag[j]) continue;
        __atomic_fetch_add(&g_pole, 1, __ATOMIC_RELAXED);
        double t = th[j], p = ph[j];
        const Vec3 dir = segment_direction(t, p);
        const Vec3 dirp = segment_direction(thn[j], phn[j]);  // still θ^{n-1}, φ^{n-1}
        const Vec2 h(dir.x(), dir.z()), hp(dirp.x(), dirp.z());
        const Vec2 ah(S.ax[j], S.az[j]);
        Vec2 hn = h + damp * (h - hp) + dt2 * double(S.g[j]) * ah;
        if (hn.norm() > 1.0) hn.normalize();
        const double yv =
            (dir.y() >= 0 ? 1.0 : -1.0) * std::sqrt(std::max(0.0, 1.0 - hn.squaredNorm()));
        double tn, pn;
        direction_angles(Vec3(hn.x(), yv, hn.y()), p, tn, pn);
        direction_angles(dir, pn, t, p);  // the current angles on the same branch
        thn[j] = tn;
        phn[j] = pn;
        TH[row + j] = t;
        PH[row + j] = p;
      }
      for (std::size_t j = 0; j < n; ++j) {
        const double t0 = th[j], p0 = ph[j];
        const double tn = t0 + damp * (t0 - thn[j]) + double(S.inc_t[j]);
        const double pn = p0 + damp * (p0 - phn[j]) + double(S.inc_p[j]);
        thn[j] = S.flag[j] ? thn[j] : tn;
        phn[j] = S.flag[j] ? phn[j] : pn;
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
      for (std::size_t j = 0; j < n; ++j) {
        S.tf[j] = reduce_angle(thn[j]);
        S.pf[j] = reduce_angle(phn[j]);
      }
      sincos_block(S.tf, S.sth, S.cth, n);
      sincos_block(S.pf, S.sph, S.cph, n);
      for (std::size_t j = 0; j < n; ++j) {
        S.nx[j] = S.sth[j] * S.sph[j];
        S.ny[j] = S.cth[j];
        S.nz[j] = S.sth[j] * S.cph[j];
      }
      // §3.2.3 joint angle ϑ at p_{i-1} (the bend between s_{i-1} and s_i) limited to σ: flagged
      // in single precision with a small margin, clamped exactly in double per strand.
      if (i >= 2 && cs > -1.0) {
        const float csf = float(cs) + 1e-5f;
        for (std::size_t j = 0; j < n; ++j)
          S.flag[j] = S.pdx[j] * S.nx[j] + S.pdy[j] * S.ny[j] + S.pdz[j] * S.nz[j] < csf;
        for (std::size_t j = 0; j < n; ++j) {
          if (!S.flag[j] || int(i) > nseg[j]) continue;
          const std::size_t prow = row - N;  // s_{i-1}, already advanced (in THN/PHN)
          const Vec3 pd = segment_direction(THN[prow + j], PHN[prow + j]);
          Vec3 nd = segment_direction(thn[j], phn[j]);
          const double c = pd.dot(nd);
          if (!(c < cs)) continue;
          __atomic_fetch_add(&g_clamp, 1, __ATOMIC_RELAXED);
          Vec3 perp = nd - c * pd;
          const double pn = perp.norm();
          perp = pn > 1e-12 ? Vec3(perp / pn) : Vec3(pd.unitOrthogonal());
          nd = cs * pd + ss * perp;
          double tn = thn[j], pnn = phn[j];
          direction_angles(nd, pnn, tn, pnn);
          thn[j] = tn;
          phn[j] = pnn;
          S.nx[j] = float(nd.x());
          S.ny[j] = float(nd.y());
          S.nz[j] = float(nd.z());
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
