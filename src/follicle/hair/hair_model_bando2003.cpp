#include "follicle/hair/hair_model_bando2003.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "follicle/core/error.hpp"
#include "follicle/core/log.hpp"
#include "follicle/core/progress.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/geom/sampling.hpp"

namespace follicle::hair {

void BandoParams::validate() const {
  validate_params(*this, "");
  dynamics.validate();
  body.validate();
  wisps.validate();
  if (dynamics.gravity != LcpParams{}.gravity)
    fail_at("dynamics.gravity",
            "hair[] models take gravity from animation.gravity; leave this key out");
}

namespace {

// Step 1: the strands whose roots are at least r apart: Poisson-disc darts over the roots in a
// seeded random order.
std::vector<uint32_t> spaced_strands(const geom::StrandSet& s, double r, uint64_t seed) {
  const std::size_t n = s.num_strands();
  std::vector<uint64_t> key(n);
  for (std::size_t i = 0; i < n; ++i) key[i] = Rng::stream(seed, i).next_u64();
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(),
            [&](uint32_t a, uint32_t b) { return key[a] != key[b] ? key[a] < key[b] : a < b; });
  std::vector<Vec3> roots(n);
  for (std::size_t k = 0; k < n; ++k) roots[k] = s.points[s.strand_begin(order[k])].cast<double>();
  std::vector<uint32_t> out;
  for (uint32_t k : geom::poisson_disc_accept(roots, r)) out.push_back(order[k]);
  std::sort(out.begin(), out.end());  // chains in groom order
  return out;
}

}  // namespace

BandoParticles bando_particles(const Context& ctx, const Groom& groom, const BandoParams& p,
                               uint64_t seed) {
  p.validate();
  groom.check("bando2003 groom");
  const double rs = p.strand_spacing > 0.0 ? p.strand_spacing : p.spacing;
  const std::vector<uint32_t> chosen = spaced_strands(groom.strands, rs, seed);
  // Step 2: each chosen strand resampled to the particle spacing (at least one free particle).
  Groom sel;
  for (uint32_t s : chosen) {
    const uint32_t b = groom.strands.strand_begin(s);
    sel.strands.add_strand(
        std::vector<Vec3f>(groom.strands.points.begin() + b,
                           groom.strands.points.begin() + b + groom.strands.strand_size(s)));
  }
  sel = resample_groom(sel, p.spacing, std::size_t(p.root_particles) + 1, 1u << 20);
  const std::size_t total = sel.strands.num_points();
  if (total > std::size_t(p.max_particles))
    fail_at("max_particles",
            "the groom needs {} particles ({} strands at spacing {} m), more than {}; raise "
            "spacing or strand_spacing",
            total, chosen.size(), p.spacing, p.max_particles);

  // Particles in chain order, with their chain and position in it.
  std::vector<Vec3> x, t, uvs;
  std::vector<uint32_t> chain_of, rank_of;
  const double nsel = double(std::max<std::size_t>(chosen.size(), 1));
  for (std::size_t c = 0; c < sel.strands.num_strands(); ++c) {
    const uint32_t b = sel.strands.strand_begin(c), m = sel.strands.strand_size(c);
    double arc = 0.0, arc0 = 0.0;
    for (uint32_t k = 0; k < m; ++k) {
      const Vec3 xk = sel.strands.points[b + k].cast<double>();
      if (k > 0) arc += (xk - sel.strands.points[b + k - 1].cast<double>()).norm();
      if (int(k) == p.root_particles) arc0 = arc;
      // Tangent: forward difference (backward at the tip).
      const Vec3 d = k + 1 < m ? Vec3(sel.strands.points[b + k + 1].cast<double>() - xk)
                               : Vec3(xk - sel.strands.points[b + k - 1].cast<double>());
      x.push_back(xk);
      t.push_back(d.norm() > 0 ? Vec3(d.normalized()) : Vec3::UnitY());
      uvs.emplace_back(double(c) / nsel, 0.0, arc);  // s fixed below
      chain_of.push_back(uint32_t(c));
      rank_of.push_back(k);
    }
    // s < 0 for the root particles, s = arc length past them for the others.
    const std::size_t first = x.size() - m;
    for (uint32_t k = 0; k < m; ++k) {
      double& s = uvs[first + k].z();
      s = int(k) < p.root_particles ? double(int(k) - p.root_particles) * p.spacing : s - arc0;
    }
  }
  // Numbered along a Z-order curve (neighbours near in memory, as initialize_lcp does).
  {
    const std::vector<uint32_t> order = lcp_zorder(x);
    auto permute = [&](auto& v) {
      auto o = v;
      for (std::size_t i = 0; i < order.size(); ++i) o[i] = v[order[i]];
      v.swap(o);
    };
    permute(x);
    permute(t);
    permute(uvs);
    permute(chain_of);
    permute(rank_of);
  }
  LcpInitParams ip;
  ip.spacing = p.spacing;
  ip.total_mass = p.total_mass;
  ip.hs_factor = p.hs_factor;
  ip.h_factor = p.h_factor;
  ip.a0 = p.a0;
  ip.n_n = p.n_n;
  ip.max_particles = p.max_particles;
  BandoParticles out;
  for (int pass = 0;; ++pass) {
    const std::vector<double> mass(x.size(), p.total_mass / double(x.size()));
    out.model = connect_particles(ctx, x, t, uvs, mass, ip);
    const std::vector<char> att = lcp_attached(out.model);
    // Step 3: a chain ends at its first particle not held by the head.
    const std::size_t nchains = sel.strands.num_strands();
    std::vector<uint32_t> cut(nchains, UINT32_MAX);
    for (std::size_t i = 0; i < x.size(); ++i)
      if (!att[i]) cut[chain_of[i]] = std::min(cut[chain_of[i]], rank_of[i]);
    std::vector<char> keep(x.size());
    std::size_t nkeep = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      keep[i] = rank_of[i] < cut[chain_of[i]] ? 1 : 0;
      nkeep += keep[i];
    }
    if (nkeep == x.size() || pass >= 8) {
      if (nkeep != x.size())
        fail_at("spacing", "particles of the groom stay apart from the head after 8 passes");
      break;
    }
    if (nkeep < 2)
      fail_at("spacing",
              "no particle of the groom is connected to a root particle; try a larger "
              "hs_factor or a smaller a0");
    out.dropped += x.size() - nkeep;
    std::size_t w = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (!keep[i]) continue;
      x[w] = x[i];
      t[w] = t[i];
      uvs[w] = uvs[i];
      chain_of[w] = chain_of[i];
      rank_of[w] = rank_of[i];
      ++w;
    }
    x.resize(w);
    t.resize(w);
    uvs.resize(w);
    chain_of.resize(w);
    rank_of.resize(w);
  }
  // Chains (root to tip) of the strands with at least two particles left.
  std::vector<std::vector<uint32_t>> chains(sel.strands.num_strands());
  for (std::size_t i = 0; i < x.size(); ++i) chains[chain_of[i]].push_back(uint32_t(i));
  for (std::size_t c = 0; c < chains.size(); ++c) {
    auto& ch = chains[c];
    std::sort(ch.begin(), ch.end(),
              [&](uint32_t a, uint32_t b) { return rank_of[a] < rank_of[b]; });
    if (ch.size() < 2) continue;
    out.chains.push_back(std::move(ch));
    out.chain_strand.push_back(chosen[c]);
  }
  if (out.chains.empty()) fail_at("spacing", "no strand of the groom keeps two particles");
  if (out.dropped > 0)
    ctx.log().info("bando2003: dropped {} particle(s) not held by the head", out.dropped);
  return out;
}

namespace {

anim::RigidSample rigid_sample(const HeadMotion& h, double t) {
  anim::RigidSample s;
  s.t = t;
  s.rotation = h.rotation.toRotationMatrix();
  s.translation = h.position;  // head frame origin = pivot 0
  s.velocity = h.velocity;
  s.acceleration = h.acceleration;
  s.angular_velocity = h.angular_velocity;
  s.angular_acceleration = h.angular_acceleration;
  return s;
}

class Bando2003Simulation final : public HairSimulation {
 public:
  Bando2003Simulation(const Context& ctx, const BandoParams& p, const HairModelSetup& setup)
      : m_p(p) {
    BandoParticles bp = bando_particles(ctx, setup.rest, p, setup.seed);
    m_chains = std::move(bp.chains);
    ctx.log().info("bando2003: {} particles on {} of {} strands, {} connections", bp.model.size(),
                   m_chains.size(), setup.rest.num_strands(), bp.model.num_pairs());
    if (p.dynamics.body_collision && setup.head_mesh) {
      std::vector<const geom::TriMesh*> body{setup.head_mesh.get()};
      m_body = std::make_unique<sim::VoxelPlanes>(sim::VoxelPlanes::build(body, p.body, 3));
    }
    LcpParams dp = p.dynamics;
    dp.gravity = Vec3::Zero();  // the environment's gravity enters as an external force
    m_solver = std::make_unique<LcpSolver>(dp, std::move(bp.model), m_body.get());
    const LcpModel& m = m_solver->model();
    for (const auto& ch : m_chains) {
      std::vector<Vec3f> pts;
      for (uint32_t i : ch) pts.push_back(m.rest_x[i].cast<float>());
      m_chains_rest.add_strand(pts);
    }
    // Step 5: the chains are the output when they are the whole groom, else the groom follows.
    bool cut = false;
    for (std::size_t c = 0; c < m_chains.size(); ++c) cut = cut || bp.chain_strand[c] != c;
    m_direct = !cut && m_chains.size() == setup.rest.num_strands() && bp.dropped == 0;
    if (!m_direct) m_wisps = bind_wisps(ctx, m_chains_rest, setup.rest.strands, p.wisps);
    m_start = m_solver->rest_state();
    if (p.settle_time > 0.0) settle(ctx, dp);
    reset();
  }

  const char* model() const override { return "bando2003"; }
  void reset() override {
    m_state = m_start;
    m_steps = 0;
    m_ws = LcpWorkspace{};
  }
  double time() const override { return double(m_steps) * m_p.dt; }
  uint64_t steps() const override { return m_steps; }

  sim::StepReport advance(const Context& ctx, double t_end, const EnvironmentFn& env) override {
    const double dt = m_p.dt;
    const long long n = std::llround(t_end / dt);
    const uint64_t target = n > 0 ? uint64_t(n) : 0;
    const LcpModel& m = m_solver->model();
    sim::StepReport rep;
    while (m_steps < target) {
      const double t = double(m_steps) * dt;
      const HairEnvironment e = env(t);
      // Gravity, the uniform wind field (force per unit mass) and the drag towards the air's
      // velocity (the solver's air_drag acts against the particle's world velocity): one world
      // acceleration for every particle.
      const Vec3 a = e.gravity + e.wind + m_p.dynamics.air_drag * e.air_velocity;
      m_force.resize(m.size());
      for (std::size_t i = 0; i < m.size(); ++i) m_force[i] = m.mass[i] * a;
      LcpStepInput in;
      in.dt = dt;
      in.head = rigid_sample(e.head, t);
      in.external_force = &m_force;
      const LcpStepReport r = m_solver->step(ctx, in, m_state, m_ws);
      rep = r;
      if (!r.ok) return rep;
      ++m_steps;
    }
    return rep;
  }

  void strands(const HeadMotion& head, geom::StrandSet& out) const override {
    std::vector<Vec3> x;
    lcp_world(m_state, rigid_sample(head, time()), &x);
    geom::StrandSet now;
    now.offsets = m_chains_rest.offsets;
    now.points.reserve(m_chains_rest.points.size());
    for (const auto& ch : m_chains)
      for (uint32_t i : ch) now.points.push_back(x[i].cast<float>());
    if (m_direct) {
      out = std::move(now);
      return;
    }
    apply_wisps(m_wisps, m_chains_rest, now, head, out);
  }

 private:
  // Ours, like LcpScenario::settle: gravity alone with extra drag, head still, then at rest.
  void settle(const Context& ctx, const LcpParams& dp) {
    LcpParams sp = dp;
    sp.gravity = m_p.settle_gravity;
    sp.air_drag = std::max(dp.air_drag, m_p.settle_drag);
    const LcpSolver solver(sp, m_solver->model(), m_body.get());
    const auto steps = std::max<long long>(1, std::llround(m_p.settle_time / m_p.dt));
    LcpStepInput in;
    in.dt = m_p.settle_time / double(steps);
    LcpWorkspace ws;
    ctx.log().info("bando2003: settling {} s of simulated time ({} steps)", m_p.settle_time, steps);
    Progress progress("settling hair", std::size_t(steps), ctx.progress());
    for (long long k = 0; k < steps; ++k) {
      const LcpStepReport r = solver.step(ctx, in, m_start, ws);
      if (!r.ok) fail_at("settle_time", "the hair blew up while settling: {}", r.message);
      progress.tick();
    }
    std::fill(m_start.v.begin(), m_start.v.end(), Vec3::Zero());
    m_start.time = 0.0;
  }

  BandoParams m_p;
  std::vector<std::vector<uint32_t>> m_chains;
  geom::StrandSet m_chains_rest;  // head frame
  bool m_direct = false;
  WispBinding m_wisps;
  std::unique_ptr<sim::VoxelPlanes> m_body;
  std::unique_ptr<LcpSolver> m_solver;
  LcpState m_start, m_state;
  LcpWorkspace m_ws;
  std::vector<Vec3> m_force;
  uint64_t m_steps = 0;
};

}  // namespace

std::unique_ptr<HairSimulation> make_bando2003(const Context& ctx, const BandoParams& params,
                                               const HairModelSetup& setup) {
  params.validate();
  setup.rest.check("bando2003 groom");
  return std::make_unique<Bando2003Simulation>(ctx, params, setup);
}

}  // namespace follicle::hair
