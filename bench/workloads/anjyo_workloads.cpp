// Anjyo 1992 workloads: cantilever styling and projective dynamics at the sizes.
#include <memory>
#include <utility>

#include "follicle/core/rng.hpp"
#include "follicle/hair/hairdressing_anjyo1992.hpp"
#include "follicle/hair/projective_anjyo1992.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {

namespace {

sim::Ellipsoid bench_hull() {
  sim::Ellipsoid e;  // the default head's fitted hull, approximately
  e.centre = Vec3(0.0, 0.09, 0.005);
  e.radii = Vec3(0.08, 0.1, 0.1);
  return e;
}

// `n` pores spread uniformly over the bob's scalp regions.
hair::HairRoots bench_roots(std::size_t n, double length) {
  const sim::Ellipsoid hull = bench_hull();
  hair::HairRoots r;
  Rng rng(7);
  for (std::size_t i = 0; i < n; ++i) {
    const double az = rng.uniform(-kPi, kPi), ze = std::acos(rng.uniform(std::cos(1.75), 1.0));
    const Vec3 p = hull.surface_point(az, ze);
    r.position.push_back(p);
    r.direction.push_back(hull.normal(p));
    r.polar.push_back(Vec2(az, ze));
    r.length.push_back(length);
    r.region.push_back(0);
  }
  return r;
}

class StyleInstance : public WorkloadInstance {
 public:
  StyleInstance(const Context& ctx, const Sizes& s)
      : m_ctx(ctx), m_roots(bench_roots(std::size_t(s.at("strands")), 0.24)) {
    m_part = hair::style_preset("bob").parts[0];
    m_part.beam.segments = int(s.at("segments"));
  }
  void run_once() override {
    geom::StrandSet out;
    hair::style_roots(m_ctx, bench_hull(), m_part, m_roots, 1, out);
  }
  double items_per_iter() const override { return double(m_roots.size()); }

 private:
  const Context& m_ctx;
  hair::HairRoots m_roots;
  hair::HairPart m_part;
};

// A closed triangulated ellipsoid: the bench hull grown by `grow` (the mesh collision's head).
geom::TriMesh ellipsoid_mesh(const sim::Ellipsoid& e, double grow, int rings, int sectors) {
  geom::TriMesh m;
  const sim::Ellipsoid g = e.grown(grow);
  m.positions.push_back(g.surface_point(0.0, 0.0));
  for (int r = 1; r < rings; ++r)
    for (int k = 0; k < sectors; ++k)
      m.positions.push_back(g.surface_point(-kPi + 2 * kPi * k / sectors, kPi * r / rings));
  m.positions.push_back(g.surface_point(0.0, kPi));
  auto at = [&](int r, int k) { return 1 + (r - 1) * sectors + (k % sectors); };
  const int last = int(m.positions.size()) - 1;
  for (int k = 0; k < sectors; ++k) {
    m.faces.push_back(Vec3i(0, at(1, k), at(1, k + 1)));
    m.faces.push_back(Vec3i(last, at(rings - 1, k + 1), at(rings - 1, k)));
    for (int r = 1; r + 1 < rings; ++r) {
      m.faces.push_back(Vec3i(at(r, k), at(r + 1, k), at(r + 1, k + 1)));
      m.faces.push_back(Vec3i(at(r, k), at(r + 1, k + 1), at(r, k + 1)));
    }
  }
  // Orientation: outward normals (the signed distance's sign).
  if (m.face_normal(0).dot(m.positions[std::size_t(m.faces[0][1])] - g.centre) < 0)
    for (auto& f : m.faces) std::swap(f[1], f[2]);
  return m;
}

class DynamicsInstance : public WorkloadInstance {
 public:
  DynamicsInstance(const Context& ctx, const Sizes& s, bool mesh = false) : m_ctx(ctx) {
    const auto roots = bench_roots(std::size_t(s.at("strands")), 0.24);
    hair::HairPart part = hair::style_preset("bob").parts[0];
    part.beam.segments = int(s.at("segments"));
    part.cuts.clear();  // every strand keeps all its segments
    geom::StrandSet rest;
    hair::style_roots(ctx, bench_hull(), part, roots, 1, rest);
    hair::ProjectiveParams p;
    p.dt = 1.0 / 60.0;
    p.stiffness_deg = 15.0;
    m_solver = std::make_unique<hair::ProjectiveSolver>(p, bench_hull(), rest, 1);
    if (mesh)
      m_solver->set_collision_grid(hair::head_collision_grid(
          ctx, ellipsoid_mesh(bench_hull(), 0.002, 64, 128), bench_hull(), p));
    m_state = m_solver->initial_state();
  }
  void run_once() override {
    hair::ProjectiveInput in;
    in.wind = hair::GustParams{}.at(double(m_state.step) * m_solver->params().dt);
    m_solver->step(m_ctx, in, m_state);
  }
  double items_per_iter() const override { return 1.0; }

 private:
  const Context& m_ctx;
  std::unique_ptr<hair::ProjectiveSolver> m_solver;
  hair::ProjectiveState m_state;
};

}  // namespace

void add_anjyo_workloads(std::vector<Workload>& out) {
  out.push_back({"anjyo-style",
                 "cantilever styling (Anjyo 1992 §2.1) of the bob's main part",
                 {{"strands", 100000}, {"segments", 20}},
                 "strands/s",
                 [](const Context& ctx, const Sizes& s) -> std::unique_ptr<WorkloadInstance> {
                   return std::make_unique<StyleInstance>(ctx, s);
                 }});
  out.push_back({"anjyo-dynamics",
                 "projective dynamics (Anjyo 1992 §3), one step with a gust",
                 {{"strands", 100000}, {"segments", 20}},
                 "steps/s",
                 [](const Context& ctx, const Sizes& s) -> std::unique_ptr<WorkloadInstance> {
                   return std::make_unique<DynamicsInstance>(ctx, s);
                 }});
  out.push_back({"anjyo-dynamics-mesh",
                 "anjyo-dynamics with the mesh collision (signed-distance grid of a triangulated "
                 "head 2 mm outside the hull)",
                 {{"strands", 100000}, {"segments", 20}},
                 "steps/s",
                 [](const Context& ctx, const Sizes& s) -> std::unique_ptr<WorkloadInstance> {
                   return std::make_unique<DynamicsInstance>(ctx, s, true);
                 }});
}

}  // namespace follicle::workloads
