#include <gtest/gtest.h>
#include <cstdio>
#include "lcp_test_scenes.hpp"
using namespace follicle;
using namespace follicle::hair;
TEST(LcpDebug, DISABLED_Hang) {
  Context ctx(2);
  auto sc = test::lcp_small_scene(ctx);
  LcpParams p;
  p.hair_hair = std::getenv("HH") != nullptr;
  p.body_collision = std::getenv("BODY") != nullptr;
  if (std::getenv("SUB")) p.substeps = std::atoi(std::getenv("SUB"));
  if (std::getenv("E")) p.elastic_modulus = std::atof(std::getenv("E"));
  if (std::getenv("DAMP")) p.spring_damping = std::atof(std::getenv("DAMP"));
  if (std::getenv("CS")) p.compression_scale = std::atof(std::getenv("CS"));
  LcpSolver solver(p, sc.init.model, &sc.body);
  LcpState s = solver.rest_state();
  LcpWorkspace ws;
  const auto& m = solver.model();
  std::printf("n %zu pairs %zu h_s %.4f spacing %.4f\n", m.size(), m.num_pairs(), m.h_s, m.spacing);
  for (int k = 0; k < 60; ++k) {
    LcpStepInput in; in.dt = 1.0/60;
    auto rep = solver.step(ctx, in, s, ws);
    int broken = 0; double maxr = 0, meanr = 0;
    for (std::size_t q = 0; q < m.num_pairs(); ++q) {
      double r = (s.x[m.pair_b[q]] - s.x[m.pair_a[q]]).norm() / m.l0[q];
      maxr = std::max(maxr, r); meanr += r;
      if (ws.k[q] == 0) ++broken;
    }
    double miny = 1e9; for (auto& x : s.x) miny = std::min(miny, x.y());
    if (k % 5 == 0) std::printf("step %d sub %d ok %d vmax %.3f broken %d maxratio %.2f mean %.3f miny %.3f\n", k, rep.substeps, rep.ok, rep.max_speed, broken, maxr, meanr / m.num_pairs(), miny);
  }
}
TEST(LcpDebug, DISABLED_Lattice) {
  Context ctx(2);
  const double a = 0.01;
  std::vector<Vec3> x, t, uvs;
  int nk = std::getenv("NK") ? std::atoi(std::getenv("NK")) : 16;
  for (int layer = 0; layer < 4; ++layer)
    for (int k = 0; k < nk; ++k)
      for (int i = 0; i < 6; ++i) {
        x.push_back(Vec3(a * i, -a * k, a * layer));
        t.push_back(-Vec3::UnitY());
        uvs.push_back(Vec3(i / 10.0, layer / 4.0, a * (k - 0.5)));
      }
  LcpInitParams ip;
  ip.spacing = a;
  auto model = connect_particles(ctx, x, t, uvs, std::vector<double>(x.size(), 3.3e-5), ip);
  LcpParams p;
  p.hair_hair = false;
  if (std::getenv("SUB")) p.substeps = std::atoi(std::getenv("SUB"));
  if (std::getenv("CS")) p.compression_scale = std::atof(std::getenv("CS"));
  if (std::getenv("E")) p.elastic_modulus = std::atof(std::getenv("E"));
  LcpSolver solver(p, model);
  LcpState s = solver.rest_state();
  LcpWorkspace ws;
  const auto& m = solver.model();
  std::printf("n %zu pairs %zu\n", m.size(), m.num_pairs());
  for (int k = 0; k < 60; ++k) {
    LcpStepInput in; in.dt = 1.0/60;
    auto rep = solver.step(ctx, in, s, ws);
    double miny = 1e9; for (auto& xx : s.x) miny = std::min(miny, xx.y());
    if (k % 10 == 0) std::printf("step %d ok %d vmax %.3f miny %.3f (rest %.3f)\n", k, rep.ok, rep.max_speed, miny, -a * (nk - 1));
  }
}
