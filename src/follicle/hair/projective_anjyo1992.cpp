#include "follicle/hair/projective_anjyo1992.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "follicle/core/cpu.hpp"
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
  if (collision != "mesh" && collision != "hull")
    fail_at("projective.collision", "unknown collision \"{}\"; expected mesh or hull", collision);
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

std::shared_ptr<const geom::SignedDistanceGrid> head_collision_grid(
    const Context& ctx, const geom::TriMesh& head, const sim::Ellipsoid& hull,
    const ProjectiveParams& params) {
  const geom::MeshSignedDistance sd(head);
  geom::SignedDistanceGridParams gp;
  gp.cell = params.collision_cell;
  gp.band = std::max(0.01, 4.0 * gp.cell);
  // Box of the hull (any rotation) grown by 4 cm: the hair near the skin; beyond it, far outside.
  const Mat3 A = hull.rotation.cwiseAbs();
  const Vec3 ext = A * hull.radii + Vec3::Constant(0.04);
  return std::make_shared<const geom::SignedDistanceGrid>(ctx, sd, hull.centre - ext,
                                                          hull.centre + ext, gp);
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

// Everything a block of the step reads: the solver's arrays and the step's constants.
struct StepArgs {
  const ProjectiveParams* p = nullptr;
  const sim::Ellipsoid* hull = nullptr;
  const geom::SignedDistanceGrid* grid = nullptr;  // mesh collision (null: hull only)
  float margin = 0;
  std::size_t N = 0, K = 0;
  uint64_t seed = 0, step = 0;
  const int* nseg = nullptr;
  const double* len = nullptr;
  const float *lenf = nullptr, *gainf = nullptr;
  const float *dir0x = nullptr, *dir0y = nullptr, *dir0z = nullptr;
  const float *rootx = nullptr, *rooty = nullptr, *rootz = nullptr;
  double *TH = nullptr, *PH = nullptr, *THN = nullptr, *PHN = nullptr;
  Vec3* nodes = nullptr;
  double dt2 = 0, cos_sig_root = -1, cos_sig = -1, damp = 1, alpha = 0;
  bool fluct = false, top = false, rest = false, pseudo = false, rotating = false;
  Eigen::Matrix3f mq, mg;
  Eigen::Vector3f cf;
  float near2 = 0, alpha2 = 0, epsf = 0;
  float b[3] = {0, 0, 0}, w[3] = {0, 0, 0}, l[3] = {0, 0, 0};
  float dt2f = 0, top_scale = 1, top_h = 0, rest_k = 0, pole = 0, ext = 0, inv_dt2 = 0, max_v2 = 0;
};

// The block kernel, compiled for plain x86-64 and for AVX2 (hand-written SIMD: see the .inc).
namespace sse2 {
constexpr std::size_t kVecBytes = 16;
#define FOLLICLE_PROJECTIVE_AVX2 0
#include "follicle/hair/projective_anjyo1992_kernel.inc"
#undef FOLLICLE_PROJECTIVE_AVX2
}  // namespace sse2

#if defined(__x86_64__) && defined(__GNUC__)
FOLLICLE_AVX2_BEGIN
namespace avx2 {
constexpr std::size_t kVecBytes = 32;
#define FOLLICLE_PROJECTIVE_AVX2 1
#include "follicle/hair/projective_anjyo1992_kernel.inc"
#undef FOLLICLE_PROJECTIVE_AVX2
}  // namespace avx2
FOLLICLE_AVX2_END
#define FOLLICLE_PROJECTIVE_HAVE_AVX2 1
#endif

using BlockFn = void (*)(const StepArgs&, std::size_t, std::size_t, sim::StepReport&);

// AVX2 when the CPU has it (same results, twice the lanes), else SSE2.
BlockFn pick_block_kernel() {
#ifdef FOLLICLE_PROJECTIVE_HAVE_AVX2
  if (cpu_has_avx2()) return &avx2::step_block;
#endif
  return &sse2::step_block;
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

  StepArgs a;
  a.p = &m_p;
  a.hull = &m_hull;
  a.grid = collision_grid();
  a.margin = float(m_p.collision_margin);
  a.N = N;
  a.K = K;
  a.seed = m_seed;
  a.step = st.step;
  a.nseg = m_nseg.data();
  a.len = m_len.data();
  a.lenf = m_lenf.data();
  a.gainf = m_gainf.data();
  a.dir0x = m_dir0x.data();
  a.dir0y = m_dir0y.data();
  a.dir0z = m_dir0z.data();
  a.rootx = m_rootx.data();
  a.rooty = m_rooty.data();
  a.rootz = m_rootz.data();
  a.TH = TH;
  a.PH = PH;
  a.THN = THN;
  a.PHN = PHN;
  a.nodes = st.nodes.data();
  a.dt2 = dt2;
  a.cos_sig_root = cos_sig_root;
  a.cos_sig = cos_sig;
  a.damp = damp;
  a.alpha = alpha;
  a.fluct = fluct;
  a.top = top;
  a.rest = rest;
  a.pseudo = pseudo;
  a.rotating = rotating;
  a.mq = mq;
  a.mg = mg;
  a.cf = cf;
  a.near2 = near2;
  a.alpha2 = alpha2;
  a.epsf = epsf;
  a.b[0] = bx, a.b[1] = by, a.b[2] = bz;
  a.w[0] = wx, a.w[1] = wy, a.w[2] = wz;
  a.l[0] = lx, a.l[1] = ly, a.l[2] = lz;
  a.dt2f = dt2f;
  a.top_scale = top_scale;
  a.top_h = top_h;
  a.rest_k = rest_k;
  a.pole = pole;
  a.ext = ext;
  a.inv_dt2 = inv_dt2;
  a.max_v2 = max_v2;
  const BlockFn block = pick_block_kernel();
  parallel_chunks(ctx, N, kChunk, [&](std::size_t s0, std::size_t s1) {
    sim::StepReport rep;
    block(a, s0, s1, rep);
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
