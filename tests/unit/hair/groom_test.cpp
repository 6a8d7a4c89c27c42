// hair::Groom (ADR 0010): checks, root binding to a mesh (and following it when it moves),
// resampling that keeps length, and the Anjyo 1992 model behind the HairSimulation interface.
#include "follicle/hair/groom.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "follicle/core/context.hpp"
#include "follicle/core/error.hpp"
#include "follicle/geom/spatial_embree.hpp"
#include "follicle/hair/hair_model.hpp"

using namespace follicle;
using ::testing::HasSubstr;

namespace {

// A 2 x 2 m square in the plane y = 0 made of two triangles, normal +y.
geom::TriMesh plane() {
  geom::TriMesh m;
  m.positions = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}};
  m.faces = {{0, 2, 1}, {0, 3, 2}};
  return m;
}

// A quarter circle of radius r in the xy plane starting at `root`, n points.
std::vector<Vec3f> arc(const Vec3f& root, double r, int n) {
  std::vector<Vec3f> pts;
  for (int i = 0; i < n; ++i) {
    const double a = 0.5 * kPi * i / (n - 1);
    pts.push_back(root + Vec3f(float(r * (1 - std::cos(a))), float(r * std::sin(a)), 0.0f));
  }
  return pts;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Groom, CheckRejectsInconsistentGrooms) {
  hair::Groom g;
  g.strands.add_strand({{0, 0, 0}, {0, 1, 0}});
  EXPECT_NO_THROW(g.check("g"));
  g.roots.resize(2);
  EXPECT_THAT(error_of([&] { g.check("g"); }), HasSubstr("2 root bindings for 1 strands"));
  g.roots.clear();
  g.material.resize(3);
  EXPECT_THAT(error_of([&] { g.check("g"); }), HasSubstr("3 material indices"));
  g.material.clear();
  g.strands.add_strand({{0, 0, 0}});
  EXPECT_THAT(error_of([&] { g.check("g"); }), HasSubstr("strand 1 has 1 point(s)"));
  hair::Groom z;
  z.strands.add_strand({{0, 0, 0}, {0, 0, 0}});
  EXPECT_THAT(error_of([&] { z.check("g"); }), HasSubstr("zero length"));
}

TEST(Groom, RootsBindToTheNearestPointAndFollowTheMesh) {
  const Context ctx(2, 1);
  geom::TriMesh m = plane();
  hair::Groom g;
  // Roots slightly above the plane: they bind to the point straight below.
  const std::vector<Vec3f> roots = {{0.3f, 0.001f, 0.2f}, {-0.7f, 0.002f, 0.9f}, {0.f, 0.f, 0.f}};
  for (const auto& r : roots) g.strands.add_strand({r, r + Vec3f(0, 0.1f, 0)});
  const geom::MeshQuery q(m);
  const double far = hair::bind_roots(ctx, q, g);
  EXPECT_NEAR(far, 0.002, 1e-6);
  ASSERT_EQ(g.roots.size(), 3u);
  auto bound = hair::bound_root_positions(g, m);
  for (std::size_t s = 0; s < 3; ++s) {
    EXPECT_NEAR(bound[s].x(), roots[s].x(), 1e-6);
    EXPECT_NEAR(bound[s].y(), 0.0, 1e-12);
    EXPECT_NEAR(bound[s].z(), roots[s].z(), 1e-6);
  }
  // The mesh moves (any affine map): bound points move with it exactly.
  geom::TriMesh moved = m;
  for (auto& p : moved.positions) p = Vec3(2.0 * p.x() + 0.5, p.y() - 1.0, p.z() + 3.0 * p.x());
  bound = hair::bound_root_positions(g, moved);
  for (std::size_t s = 0; s < 3; ++s) {
    const Vec3 e(2.0 * roots[s].x() + 0.5, -1.0, roots[s].z() + 3.0 * roots[s].x());
    EXPECT_NEAR((bound[s] - e).norm(), 0.0, 1e-6) << s;
  }
  const auto normals = hair::bound_root_normals(g, m);
  for (const auto& n : normals) EXPECT_NEAR(n.y(), 1.0, 1e-12);
  // A mesh with fewer faces than the binding needs is refused.
  geom::TriMesh small = m;
  small.faces.resize(1);
  g.roots[0].face = 1;
  EXPECT_THAT(error_of([&] { hair::bound_root_positions(g, small); }),
              HasSubstr("bound to face 1 but the mesh has 1 faces"));
}

TEST(Groom, ResamplingKeepsLengthEndsAndAttributes) {
  hair::Groom g;
  g.strands.add_strand(arc({0, 0, 0}, 0.1, 200));   // a fine quarter circle: length ≈ π/20
  g.strands.add_strand({{1, 0, 0}, {1, 0.3f, 0}});  // straight
  g.strands.radius = std::vector<float>(g.strands.num_points(), 1e-4f);
  g.strands.radius[200] = 1e-4f;
  g.strands.radius[201] = 3e-4f;
  g.material = {3, 7};
  const double L0 = hair::strand_length(g.strands, 0);
  EXPECT_NEAR(L0, kPi * 0.1 / 2, 1e-5);

  const hair::Groom r = hair::resample_groom(g, 0.01);
  ASSERT_EQ(r.num_strands(), 2u);
  EXPECT_EQ(r.material, g.material);
  // ceil(L / 0.01) + 1 points: 17 for the arc (L ≈ 0.157), 31 for the 0.3 m line.
  EXPECT_EQ(r.strands.strand_size(0), 17u);
  EXPECT_EQ(r.strands.strand_size(1), 31u);
  // Length kept up to the chord error of 16 chords of a quarter circle (≈ 0.16 %).
  EXPECT_NEAR(hair::strand_length(r.strands, 0), L0, 0.002 * L0);
  EXPECT_NEAR(hair::strand_length(r.strands, 1), 0.3, 1e-6);
  // First and last points are the original ones, bit for bit.
  EXPECT_EQ(r.strands.points[0], g.strands.points[0]);
  EXPECT_EQ(r.strands.points[16], g.strands.points[199]);
  // Radii interpolated linearly along the straight strand: 1e-4 -> 3e-4.
  EXPECT_NEAR(r.strands.radius[17 + 15], 2e-4f, 1e-9);
  // Points are equally spaced along the straight strand.
  for (uint32_t i = 18; i < 48; ++i)
    EXPECT_NEAR((r.strands.points[i] - r.strands.points[i - 1]).norm(), 0.01, 1e-6);

  const hair::Groom f = hair::resample_groom_fixed(g, 5);
  EXPECT_EQ(f.strands.num_points(), 10u);
  EXPECT_THAT(error_of([&] { hair::resample_groom(g, 0.0); }), HasSubstr("segment length > 0"));
  EXPECT_THAT(error_of([&] { hair::resample_groom_fixed(g, 1); }), HasSubstr("at least 2"));
}

TEST(HairModel, AnjyoOnAnImportedGroomStaysAtRestWithoutForces) {
  const Context ctx(2, 1);
  hair::HairModelSetup setup;
  for (int s = 0; s < 20; ++s) {
    const float a = float(s) * 0.3f;
    setup.rest.strands.add_strand(
        arc(Vec3f(0.09f * std::cos(a), 0.05f, 0.09f * std::sin(a)), 0.05, 12));
  }
  setup.hull.radii = Vec3(0.08, 0.1, 0.1);
  hair::ProjectiveParams p;
  p.collision = "hull";
  p.pseudo_force = false;
  auto sim = hair::make_anjyo1992(ctx, p, setup);
  EXPECT_STREQ(sim->model(), "anjyo1992");
  const hair::EnvironmentFn still = [](double) {
    hair::HairEnvironment e;
    e.gravity = Vec3::Zero();
    return e;
  };
  const auto rep = sim->advance(ctx, 0.5, still);
  EXPECT_TRUE(rep.ok) << rep.message;
  EXPECT_EQ(sim->steps(), 30u);  // 0.5 s at dt = 1/60
  EXPECT_NEAR(sim->time(), 0.5, 1e-12);
  geom::StrandSet out;
  sim->strands(hair::HeadMotion{}, out);
  ASSERT_EQ(out.num_points(), setup.rest.strands.num_points());
  for (std::size_t i = 0; i < out.num_points(); ++i)
    EXPECT_LT((out.points[i] - setup.rest.strands.points[i]).norm(), 1e-5) << i;

  // Under gravity the strands fall; reset() returns to the rest shape and time 0.
  const hair::EnvironmentFn gravity = [](double) { return hair::HairEnvironment{}; };
  ASSERT_TRUE(sim->advance(ctx, 0.75, gravity).ok);
  sim->strands(hair::HeadMotion{}, out);
  double moved = 0;
  for (std::size_t i = 0; i < out.num_points(); ++i)
    moved = std::max(moved, double((out.points[i] - setup.rest.strands.points[i]).norm()));
  EXPECT_GT(moved, 0.005);
  sim->reset();
  EXPECT_EQ(sim->steps(), 0u);
  sim->strands(hair::HeadMotion{}, out);
  for (std::size_t i = 0; i < out.num_points(); ++i)
    EXPECT_LT((out.points[i] - setup.rest.strands.points[i]).norm(), 1e-5) << i;
}
