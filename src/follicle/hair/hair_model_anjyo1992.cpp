// HairSimulation adapter of Anjyo, Usami, Kurihara 1992 §3 (projective_anjyo1992): any groom,
// stepped at ProjectiveParams::dt; the mesh collision uses the setup's head surface.
#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/hair/hair_model.hpp"

namespace follicle::hair {

namespace {

class Anjyo1992Simulation final : public HairSimulation {
 public:
  Anjyo1992Simulation(const Context& ctx, const ProjectiveParams& p, const HairModelSetup& setup)
      : m_solver(p, setup.hull, setup.rest.strands, setup.seed) {
    if (p.collision == "mesh" && setup.head_mesh) {
      geom::TriMesh head = *setup.head_mesh;
      head.normals.clear();
      m_solver.set_collision_grid(head_collision_grid(ctx, head, setup.hull, p));
    }
    reset();
  }
  const char* model() const override { return "anjyo1992"; }
  void reset() override { m_state = m_solver.initial_state(); }
  double time() const override { return double(m_state.step) * m_solver.params().dt; }
  uint64_t steps() const override { return m_state.step; }

  sim::StepReport advance(const Context& ctx, double t_end, const EnvironmentFn& env) override {
    const double dt = m_solver.params().dt;
    // Whole steps up to t_end (rounded, so frame times that are multiples of dt land exactly).
    const long long n = std::llround(t_end / dt);
    const uint64_t target = n > 0 ? uint64_t(n) : 0;
    sim::StepReport rep;
    while (m_state.step < target) {
      const double t = double(m_state.step) * dt;
      const HairEnvironment e = env(t);
      ProjectiveInput in;
      in.gravity = e.gravity;
      in.wind = e.wind;
      in.head = e.head;
      rep = m_solver.step(ctx, in, m_state);
      if (!rep.ok) return rep;
    }
    return rep;
  }

  void strands(const HeadMotion& head, geom::StrandSet& out) const override {
    m_solver.positions(m_state, head, out);
  }

 private:
  ProjectiveSolver m_solver;
  ProjectiveState m_state;
};

}  // namespace

std::unique_ptr<HairSimulation> make_anjyo1992(const Context& ctx, const ProjectiveParams& params,
                                               const HairModelSetup& setup) {
  setup.rest.check("anjyo1992 groom");
  return std::make_unique<Anjyo1992Simulation>(ctx, params, setup);
}

}  // namespace follicle::hair
