#include "follicle/hair/projective_anjyo1992.hpp"

#include <algorithm>
#include <cmath>

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
  constexpr std::size_t kChunk = 512;
  const std::size_t nchunks = (N + kChunk - 1) / kChunk;
  std::vector<sim::StepReport> reports(nchunks);

  parallel_chunks(ctx, N, kChunk, [&](std::size_t s0, std::size_t s1) {
    sim::StepReport rep;
    Vec3 prev_dir[kChunk];
    for (std::size_t s = s0; s < s1; ++s) prev_dir[s - s0] = Vec3::Zero();
    for (std::size_t i = 1; i <= K; ++i) {
      const std::size_t row = (i - 1) * N;
      const bool root_joint = int(i - 1) <= m_p.stiffness_root_segments;
      const double cs = root_joint ? cos_sig_root : cos_sig;
      const double ss = root_joint ? sin_sig_root : sin_sig;
      for (std::size_t s = s0; s < s1; ++s) {
        const int k = m_nseg[s];
        if (int(i) > k) continue;
        const std::size_t idx = row + s;
        const double d = m_len[idx];
        const Vec3 p0 = st.nodes[(i - 1) * N + s];  // already advanced (root to tip)
        double th = st.theta[idx], thp = st.theta_prev[idx];
        double ph = st.phi[idx], php = st.phi_prev[idx];
        const Vec3 dir = segment_direction(th, ph);
        const Vec3 mid = p0 + 0.5 * d * dir;
        Vec3 a = base - al.cross(mid) - w.cross(w.cross(mid));
        // §3.2.2 pseudo-force field: near the head and against it -> ε_i F.
        const Vec3 pi_ = p0 + d * dir;
        if (m_p.pseudo_force && double(i) <= m_p.epsilon_extent * k + 1e-9) {
          const Vec3 q = m_hull.normalized(pi_);
          if (q.norm() - 1.0 < m_p.near_head) {
            const Vec3 D = m_hull.gradient(pi_);  // (E_x, E_y, E_z)
            if (D.dot(a) < alpha * D.norm() * a.norm()) a *= m_p.epsilon;
          }
        }
        double G = m_gain[idx];
        if (m_p.top_inertia_scale != 1.0 && m_hull.normalized(p0).y() > m_p.top_height)
          G *= m_p.top_inertia_scale;
        if (m_p.rest_spring > 0 && G > 0) {
          const Vec3 dir0 = segment_direction(m_theta0[idx], m_phi0[idx]);
          a += (m_p.rest_spring / G) * (dir0 - dir);
        }
        const double sth = std::sin(th);
        double thn, phn;
        if (std::abs(sth) < m_p.parallel_threshold) {
          // Segment nearly parallel to y: the θ plane is spanned by y and F (Fig. 8), so the
          // segment turns towards the horizontal part of F with θ'' = c u F_θ. Near the pole this
          // is the small-angle form of (4)' for the horizontal offset h = (x, z) of the
          // direction, written as a vector so the state does not jump when the plane follows F.
          const Vec3 dirp = segment_direction(thp, php);
          const Vec2 h(dir.x(), dir.z()), hp(dirp.x(), dirp.z()), ah(a.x(), a.z());
          Vec2 hn = h + damp * (h - hp) + dt2 * G * ah;
          if (hn.norm() > 1.0) hn.normalize();
          const double yv =
              (dir.y() >= 0 ? 1.0 : -1.0) * std::sqrt(std::max(0.0, 1.0 - hn.squaredNorm()));
          const Vec3 nd0(hn.x(), yv, hn.y());
          direction_angles(nd0, ph, thn, phn);
          direction_angles(dir, phn, th, ph);  // the current angles on the same branch
        } else {
          const double cth = std::cos(th), sph = std::sin(ph), cph = std::cos(ph);
          const double Fth = a.x() * cth * sph - a.y() * sth + a.z() * cth * cph;  // (F, V_θ)
          const double sgn = sth >= 0 ? 1.0 : -1.0;
          const double Fph = sgn * (a.x() * cph - a.z() * sph);  // (F, V_φ)
          // (4)' and (5)': u_i = |s_i|/2, v_i = |s_i| |sin θ| / 2 -> v_i / u_i = |sin θ|.
          thn = th + damp * (th - thp) + dt2 * G * Fth;
          phn = ph + damp * (ph - php) + dt2 * G * std::abs(sth) * Fph;
        }
        if (fluct) {
          Rng rng = Rng::stream(m_seed ^ (st.step * 0x9E3779B97F4A7C15ull), idx);
          thn += m_p.fluctuation * rng.uniform(-1.0, 1.0);
          phn += m_p.fluctuation * rng.uniform(-1.0, 1.0);
        }
        Vec3 nd = segment_direction(thn, phn);
        bool changed = false;
        // §3.2.3 joint angle ϑ at p_{i-1} (the bend between s_{i-1} and s_i) limited to σ.
        if (i >= 2 && cs > -1.0) {
          const Vec3& pd = prev_dir[s - s0];
          const double c = pd.dot(nd);
          if (c < cs) {
            Vec3 perp = nd - c * pd;
            const double pn = perp.norm();
            perp = pn > 1e-12 ? Vec3(perp / pn) : Vec3(pd.unitOrthogonal());
            nd = cs * pd + ss * perp;
            changed = true;
          }
        }
        Vec3 pnew = p0 + d * nd;
        if (m_p.ellipsoid_constraint && m_hull.value(pnew) < 0) {
          const Vec3 out = m_hull.push_out(pnew);
          const Vec3 t = out - p0;
          if (t.norm() > 0) {
            nd = t.normalized();
            pnew = p0 + d * nd;
            changed = true;
          }
        }
        if (changed) direction_angles(nd, phn, thn, phn);
        st.theta_prev[idx] = th;
        st.theta[idx] = thn;
        st.phi_prev[idx] = ph;
        st.phi[idx] = phn;
        prev_dir[s - s0] = nd;
        Vec3& node = st.nodes[i * N + s];
        const double v = (pnew - node).norm() / dt;
        node = pnew;
        if (!std::isfinite(thn) || !std::isfinite(phn) || !pnew.allFinite())
          rep.mark_non_finite(s);
        else if (v > m_p.max_speed)
          rep.mark_blow_up(s);
        if (std::isfinite(v)) rep.max_speed = std::max(rep.max_speed, v);
      }
    }
    reports[s0 / kChunk] = rep;
  });
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
