#include "follicle/hair/hair_model_daldegan1993.hpp"

#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/core/log.hpp"
#include "follicle/core/progress.hpp"

namespace follicle::hair {

void DaldeganParams::validate() const {
  validate_params(*this, "");
  hinge.validate();
  body.validate();
  wisps.validate();
}

std::vector<uint32_t> select_guides(std::size_t n, std::size_t count) {
  std::vector<uint32_t> out;
  if (count == 0 || count >= n) {
    out.resize(n);
    for (std::size_t i = 0; i < n; ++i) out[i] = uint32_t(i);
    return out;
  }
  out.reserve(count);
  for (std::size_t k = 0; k < count; ++k) out.push_back(uint32_t((k * n + n / 2) / count));
  return out;
}

namespace {

class Daldegan1993Simulation final : public HairSimulation {
 public:
  Daldegan1993Simulation(const Context& ctx, const DaldeganParams& p, const HairModelSetup& setup)
      : m_p(p) {
    const Groom& rest = setup.rest;
    m_full_rest = rest.strands;
    // §3.4 step 1: the typical strands, resampled to the simulation's segment count.
    const auto idx = select_guides(rest.num_strands(), std::size_t(p.guides));
    m_all_guides = idx.size() == rest.num_strands();
    Groom guides;
    for (uint32_t s : idx) {
      const uint32_t b = rest.strands.strand_begin(s);
      guides.strands.add_strand(
          std::vector<Vec3f>(rest.strands.points.begin() + b,
                             rest.strands.points.begin() + b + rest.strands.strand_size(s)));
    }
    if (m_all_guides && p.guide_segments + 1 == int(rest.strands.strand_size(0))) {
      m_guides_rest = guides.strands;
    } else {
      m_guides_rest = resample_groom_fixed(guides, std::size_t(p.guide_segments) + 1).strands;
    }
    // §3.4 step 2: radius tables of the body, about the head's up axis with the seam behind
    // (the hull's axes: the head's found or declared orientation).
    std::shared_ptr<const sim::CylinderBody> body;
    if (p.collision && setup.head_mesh)
      body = std::make_shared<const sim::CylinderBody>(sim::build_cylinder_body(
          ctx, *setup.head_mesh, setup.hull.rotation.col(1), setup.hull.rotation.col(2), p.body));
    m_solver = std::make_unique<HingeSolver>(p.hinge, m_guides_rest, std::move(body));
    // §3.3: every strand of the full hair follows its typical strand.
    if (!m_all_guides) m_wisps = bind_wisps(ctx, m_guides_rest, m_full_rest, p.wisps);
    // The settled pose (ours, settle_time): gravity alone, the head still in the head frame.
    m_start = m_solver->initial_state();
    HingeInput still;
    still.gravity = p.settle_gravity;
    const auto settle_steps = uint64_t(std::llround(p.settle_time / p.hinge.dt));
    if (settle_steps > 0)
      ctx.log().info("daldegan1993: settling {} s of simulated time ({} steps)", p.settle_time,
                     settle_steps);
    Progress progress("settling hair", std::size_t(settle_steps), ctx.progress());
    for (uint64_t k = 0; k < settle_steps; ++k) {
      const sim::StepReport rep = m_solver->step(ctx, still, m_start);
      if (!rep.ok) fail("settling the styled hair (settle_time) failed: {}", rep.message);
      progress.tick();
    }
    m_start.step = 0;
    m_start.time = 0.0;
    for (auto& w : m_start.dtheta) w = 0.0;  // start at rest in the settled pose
    for (auto& w : m_start.dphi) w = 0.0;
    reset();
  }

  const char* model() const override { return "daldegan1993"; }
  void reset() override { m_state = m_start; }
  double time() const override { return double(m_state.step) * m_p.hinge.dt; }
  uint64_t steps() const override { return m_state.step; }

  sim::StepReport advance(const Context& ctx, double t_end, const EnvironmentFn& env) override {
    const double dt = m_p.hinge.dt;
    const long long n = std::llround(t_end / dt);
    const uint64_t target = n > 0 ? uint64_t(n) : 0;
    sim::StepReport rep;
    while (m_state.step < target) {
      const HairEnvironment e = env(double(m_state.step) * dt);
      HingeInput in;
      // The uniform wind field (force per unit mass) acts like gravity; the air velocity
      // drives the drag of the hinge model.
      in.gravity = e.gravity + e.wind;
      in.wind_velocity = e.air_velocity;
      in.head = e.head;
      rep = m_solver->step(ctx, in, m_state);
      if (!rep.ok) return rep;
    }
    return rep;
  }

  void strands(const HeadMotion& head, geom::StrandSet& out) const override {
    if (m_all_guides) {
      m_solver->positions(m_state, head, out);
      return;
    }
    geom::StrandSet guides_world;
    m_solver->positions(m_state, head, guides_world);
    apply_wisps(m_wisps, m_guides_rest, guides_world, head, out);
  }

 private:
  DaldeganParams m_p;
  geom::StrandSet m_full_rest, m_guides_rest;  // head frame
  bool m_all_guides = false;
  std::unique_ptr<HingeSolver> m_solver;
  HingeState m_start, m_state;
  WispBinding m_wisps;
};

}  // namespace

std::unique_ptr<HairSimulation> make_daldegan1993(const Context& ctx, const DaldeganParams& params,
                                                  const HairModelSetup& setup) {
  params.validate();
  setup.rest.check("daldegan1993 groom");
  return std::make_unique<Daldegan1993Simulation>(ctx, params, setup);
}

}  // namespace follicle::hair
