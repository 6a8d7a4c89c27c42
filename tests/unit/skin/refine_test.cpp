#include <gtest/gtest.h>

#include "follicle/core/error.hpp"
#include "follicle/skin/adaptive_refine_volino1999.hpp"
#include "follicle/skin/forehead_validation.hpp"

using namespace follicle;
using namespace follicle::skin;

TEST(Refine, CrackFreeWithUvsAndParents) {
  const geom::TriMesh base = make_cylinder_patch(0.05, 0.04, 0.08, 0.004);
  LargeWrinkle w;
  w.control = {Vec2(0.2, 0.3), Vec2(0.4, 0.45), Vec2(0.6, 0.35),
               Vec2(0.8, 0.5)};  // curved, oblique
  w.width = 0.002;
  RefineParams rp;
  rp.max_levels = 3;
  rp.smooth = false;  // flat midpoints: exact parent averages (checked below)
  const RefinedMesh r = refine_around_wrinkles(base, {w}, rp);
  EXPECT_GT(r.mesh.faces.size(), base.faces.size());
  EXPECT_EQ(r.mesh.positions.size(), std::size_t(r.base_vertices) + r.parents.size());
  EXPECT_EQ(count_t_junctions(base), 0);
  EXPECT_EQ(count_t_junctions(r.mesh), 0);
  r.mesh.check("refined");
  // Midpoints: positions and UVs are parent averages; an affine function of UV is reproduced.
  const auto u = r.propagate(std::vector<double>(base.positions.size(), 2.0));
  for (double x : u) EXPECT_DOUBLE_EQ(x, 2.0);
  for (std::size_t k = 0; k < r.parents.size(); ++k) {
    const auto& pr = r.parents[k];
    const Vec3 mid =
        0.5 * (r.mesh.positions[std::size_t(pr[0])] + r.mesh.positions[std::size_t(pr[1])]);
    EXPECT_LT((r.mesh.positions[std::size_t(r.base_vertices) + k] - mid).norm(), 1e-15);
  }
  // Total area is preserved (flat midpoints on facets), orientation kept.
  double a0 = 0, a1 = 0;
  for (std::size_t f = 0; f < base.faces.size(); ++f) a0 += base.face_area(f);
  for (std::size_t f = 0; f < r.mesh.faces.size(); ++f) a1 += r.mesh.face_area(f);
  EXPECT_NEAR(a1, a0, 1e-12);
  for (std::size_t f = 0; f < r.mesh.faces.size(); ++f) EXPECT_GT(r.mesh.face_normal(f).z(), 0.0);
}

TEST(Refine, DetectsTJunction) {
  geom::TriMesh m;
  m.positions = {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 1, 0), Vec3(1, 0, 0), Vec3(1, -1, 0)};
  m.faces = {Vec3i(0, 1, 2), Vec3i(0, 4, 3),
             Vec3i(3, 4, 1)};  // vertex 3 splits edge 0-1 on one side only
  EXPECT_GT(count_t_junctions(m), 0);
}

TEST(Refine, SmoothMidpointsLieOnTheCurvedSurface) {
  // On a cylinder of radius R the flat midpoint of a chord sags inside by ~ L^2/(8R); the
  // PN-triangle midpoint must be much closer to the surface, with the same topology.
  const double R = 0.08;
  const geom::TriMesh base = make_cylinder_patch(0.05, 0.04, R, 0.004);
  LargeWrinkle w;
  w.control = {Vec2(0.2, 0.5), Vec2(0.4, 0.5), Vec2(0.6, 0.5), Vec2(0.8, 0.5)};
  w.width = 0.002;
  RefineParams flat, smooth;
  flat.smooth = false;
  const RefinedMesh a = refine_around_wrinkles(base, {w}, flat);
  const RefinedMesh b = refine_around_wrinkles(base, {w}, smooth);
  EXPECT_GT(b.mesh.faces.size(), base.faces.size());
  auto worst = [&](const RefinedMesh& r) {
    double e = 0;
    for (std::size_t v = std::size_t(r.base_vertices); v < r.mesh.positions.size(); ++v) {
      const Vec3& p = r.mesh.positions[v];
      // Interior only: at the patch border the vertex normals are one-sided.
      if (std::abs(p.y()) > 0.016 || std::abs(std::atan2(p.x(), p.z()) * R) > 0.021) continue;
      e = std::max(e, std::abs(std::hypot(p.x(), p.z()) - R));  // cylinder axis = y
    }
    return e;
  };
  const double ea = worst(a), eb = worst(b);
  EXPECT_GT(ea, 1e-6);
  EXPECT_LT(eb, 0.25 * ea);
  EXPECT_EQ(count_t_junctions(b.mesh, 1e-3), 0);
}

TEST(Refine, ALevelBeyondTheTriangleBudgetIsRefusedNamingTheFix) {
  // max_levels 8 at edge_factor 0.05 on the hand ran for minutes with growing memory.
  const geom::TriMesh base = make_cylinder_patch(0.05, 0.04, 0.08, 0.004);
  LargeWrinkle w;
  w.control = {Vec2(0.2, 0.3), Vec2(0.4, 0.45), Vec2(0.6, 0.35), Vec2(0.8, 0.5)};
  w.width = 0.002;
  RefineParams rp;
  rp.max_levels = 8;
  rp.edge_factor = 0.05;
  rp.max_triangles = 20000;
  try {
    (void)refine_around_wrinkles(base, {w}, rp);
    FAIL() << "accepted";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(e.where(), "refine.max_triangles");
    EXPECT_NE(msg.find("more than the budget of 20.0 k; raise edge_factor (now 0.05)"),
              std::string::npos)
        << msg;
  }
  // Within the budget the same refinement runs, and stays under it.
  rp.max_levels = 2;
  const RefinedMesh r = refine_around_wrinkles(base, {w}, rp);
  EXPECT_LE(double(r.mesh.faces.size()), rp.max_triangles);
}
