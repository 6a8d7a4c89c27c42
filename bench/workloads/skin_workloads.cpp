// Skin workloads (issue 4): "face-update" (full muscle -> tissue -> wrinkle update of a
// 20,000-triangle face with 18 muscles and 10 refined wrinkles) and "harmonic-map" (distortion
// minimization of a 100,000-vertex mesh).
#include <fmt/format.h>

#include <cmath>
#include <memory>

#include "follicle/geom/harmonic_map.hpp"
#include "follicle/geom/projection.hpp"
#include "follicle/skin/face_rig.hpp"
#include "follicle/skin/forehead_validation.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {

namespace {

// A synthetic face-like half cylinder (radius 80 mm, 160 x 200 mm) with ~`tris` triangles.
geom::TriMesh face_patch(double tris) {
  const double w = 0.16, h = 0.2;
  const double spacing = std::sqrt(w * h * 2.0 / std::max(tris, 8.0));
  return skin::make_cylinder_patch(w, h, 0.08, spacing);
}

skin::MuscleSet synthetic_muscles(int n) {
  skin::MuscleSet set;
  skin::Expression e;
  e.name = "all";
  for (int i = 0; i < n; ++i) {
    skin::LinearMuscle m;
    m.name = fmt::format("m{}", i);
    const double a = -0.8 + 1.6 * (i % 9) / 8.0, y = i < 9 ? 0.06 : -0.04;
    m.origin = Vec3(0.09 * std::sin(a), y + 0.03, 0.09 * std::cos(a));
    m.insertion = Vec3(0.08 * std::sin(a), y - 0.01, 0.08 * std::cos(a));
    m.falloff_start = 0.005;
    m.falloff_end = 0.06;
    m.zone = 0.6;
    set.linear.push_back(m);
    e.contractions[m.name] = 1.0;
  }
  set.expressions.push_back(e);
  return set;
}

std::vector<skin::LargeWrinkle> synthetic_wrinkles(int n, double size) {
  std::vector<skin::LargeWrinkle> out;
  for (int i = 0; i < n; ++i) {
    skin::LargeWrinkle w;
    w.name = fmt::format("w{}", i);
    const double v = 0.1 + 0.8 * (i + 0.5) / n;
    const double u0 = 0.1, u1 = 0.16 / size - 0.1;
    w.control = {Vec2(u0, v), Vec2(u0 + (u1 - u0) / 3, v + 0.01),
                 Vec2(u0 + 2 * (u1 - u0) / 3, v + 0.01), Vec2(u1, v)};
    w.depth = 0.006;
    w.width = 0.003;
    out.push_back(w);
  }
  return out;
}

class FaceUpdate : public WorkloadInstance {
 public:
  FaceUpdate(const Context& ctx, const Sizes& s)
      : m_ctx(ctx),
        m_rig(face_patch(s.at("triangles")), synthetic_muscles(int(s.at("muscles"))),
              synthetic_wrinkles(int(s.at("wrinkles")), 0.2), skin::FaceRigParams{}) {
    m_pose = m_rig.expression_pose("all", 0.8);
  }
  void run_once() override { m_rig.update(m_ctx, m_pose, m_state); }
  double items_per_iter() const override { return 1.0; }

 private:
  const Context& m_ctx;
  skin::FaceRig m_rig;
  skin::MusclePose m_pose;
  skin::FaceState m_state;
};

class HarmonicMapWork : public WorkloadInstance {
 public:
  HarmonicMapWork(const Context&, const Sizes& s) {
    const int n = std::max(2, int(std::lround(std::sqrt(s.at("vertices")))) - 1);
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const double x = double(i) / n, y = double(j) / n;
        m_mesh.positions.emplace_back(x, y, 0.3 * std::sin(3 * x) * std::cos(2 * y));
      }
    auto id = [&](int i, int j) { return j * (n + 1) + i; };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        m_mesh.faces.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
        m_mesh.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
      }
    m_uv0 = geom::project_planar(m_mesh.positions, geom::PlanarProjection{});
  }
  void run_once() override {
    geom::HarmonicMapReport rep;
    m_uv = geom::harmonic_parameterize(m_mesh, m_uv0, geom::HarmonicMapParams{}, &rep);
  }
  double items_per_iter() const override { return double(m_mesh.positions.size()); }

 private:
  geom::TriMesh m_mesh;
  std::vector<Vec2> m_uv0, m_uv;
};

}  // namespace

void add_skin_workloads(std::vector<Workload>& out) {
  out.push_back({"face-update",
                 "full skin deformation update: muscles, tissue, refined wrinkles with shrinkage",
                 {{"triangles", 20000}, {"muscles", 18}, {"wrinkles", 10}},
                 "updates/s",
                 [](const Context& ctx, const Sizes& s) -> std::unique_ptr<WorkloadInstance> {
                   return std::make_unique<FaceUpdate>(ctx, s);
                 }});
  out.push_back({"harmonic-map",
                 "distortion minimization (Eck harmonic weights, sparse Cholesky) of a bumpy grid",
                 {{"vertices", 100000}},
                 "vertices/s",
                 [](const Context& ctx, const Sizes& s) -> std::unique_ptr<WorkloadInstance> {
                   return std::make_unique<HarmonicMapWork>(ctx, s);
                 }});
}

}  // namespace follicle::workloads
