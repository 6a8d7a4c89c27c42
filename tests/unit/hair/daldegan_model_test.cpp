// The Daldegan 1993 model behind the HairSimulation interface (ADR 0010): typical strands
// (§3.3-3.4), the settled pose, the wisp hair at rest, determinism and the head frame.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "follicle/core/context.hpp"
#include "follicle/core/error.hpp"
#include "follicle/hair/hair_model_daldegan1993.hpp"

using namespace follicle;
using ::testing::HasSubstr;

namespace {

// A UV sphere of radius r (the head) with outward faces.
geom::TriMesh sphere(double r, int nu = 48, int nv = 24) {
  geom::TriMesh m;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double th = kPi * j / nv, ph = 2 * kPi * i / nu;
      m.positions.emplace_back(r * std::sin(th) * std::cos(ph), r * std::cos(th),
                               r * std::sin(th) * std::sin(ph));
    }
  auto id = [&](int i, int j) { return (j * nu) + (i % nu); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
    }
  m.compute_normals();
  return m;
}

// Strands growing out of the upper half of a sphere of radius 0.09 m, `n` strands of 21 points,
// first along the normal, then bending down.
hair::HairModelSetup setup(int n) {
  hair::HairModelSetup s;
  for (int k = 0; k < n; ++k) {
    const double ph = 2.399963 * k, cz = 0.2 + 0.75 * double(k) / n;  // golden-angle spiral
    const double sz = std::sqrt(1 - cz * cz);
    const Vec3 nrm(sz * std::cos(ph), cz, sz * std::sin(ph));
    std::vector<Vec3f> pts;
    Vec3 p = 0.09 * nrm;
    Vec3 d = nrm;
    for (int i = 0; i < 21; ++i) {
      pts.push_back(p.cast<float>());
      d = (d + Vec3(0, -0.15, 0)).normalized();
      p += 0.01 * d;
    }
    s.rest.strands.add_strand(pts);
  }
  s.hull.radii = Vec3(0.09, 0.09, 0.09);
  s.head_mesh = std::make_shared<const geom::TriMesh>(sphere(0.09));
  return s;
}

hair::HairEnvironment calm(double) {
  return hair::HairEnvironment{};
}

}  // namespace

TEST(DaldeganModel, GuidesAreSpreadThroughTheGroom) {
  EXPECT_EQ(hair::select_guides(5, 0), (std::vector<uint32_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(hair::select_guides(5, 9).size(), 5u);
  const auto g = hair::select_guides(1000, 10);
  ASSERT_EQ(g.size(), 10u);
  for (std::size_t k = 0; k < g.size(); ++k) EXPECT_EQ(g[k], 100 * k + 50);
}

TEST(DaldeganModel, AtRestTheWispHairIsTheGroom) {
  const Context ctx(2, 1);
  const auto s = setup(400);
  hair::DaldeganParams p;
  p.guides = 40;
  p.guide_segments = 10;
  auto sim = hair::make_daldegan1993(ctx, p, s);
  EXPECT_STREQ(sim->model(), "daldegan1993");
  geom::StrandSet out;
  sim->strands(hair::HeadMotion{}, out);
  ASSERT_EQ(out.num_strands(), 400u);
  ASSERT_EQ(out.num_points(), s.rest.strands.num_points());
  for (std::size_t i = 0; i < out.num_points(); ++i)
    ASSERT_LT((out.points[i] - s.rest.strands.points[i]).norm(), 1e-5f) << i;
  // A head pose moves the whole hair rigidly.
  hair::HeadMotion head;
  head.position = Vec3(0.1, 0.2, 0.3);
  head.rotation = Quat(Eigen::AngleAxisd(0.4, Vec3::UnitY()));
  sim->strands(head, out);
  for (std::size_t i = 0; i < out.num_points(); i += 37) {
    const Vec3 e = head.position + head.rotation * s.rest.strands.points[i].cast<double>();
    ASSERT_LT((out.points[i].cast<double>() - e).norm(), 1e-5) << i;
  }
}

TEST(DaldeganModel, HairFallsStaysOutsideTheHeadAndIsDeterministic) {
  const auto s = setup(300);
  hair::DaldeganParams p;
  p.guides = 60;
  p.guide_segments = 20;
  geom::StrandSet a, b;
  for (int threads : {1, 2}) {
    const Context ctx(threads, 1);
    auto sim = hair::make_daldegan1993(ctx, p, s);
    const auto rep = sim->advance(ctx, 0.5, calm);
    ASSERT_TRUE(rep.ok) << rep.message;
    EXPECT_EQ(sim->steps(), 120u);  // 0.5 s at the default dt = 1/240 s
    sim->strands(hair::HeadMotion{}, threads == 1 ? a : b);
  }
  ASSERT_EQ(a.points, b.points);  // bit-identical for 1 and 2 threads
  // Gravity pulled the hair down; the tips stay out of the head (the followers keep their rest
  // offsets from the guides, so allow the wisp's width).
  double mean_dy = 0, inside = 0;
  for (std::size_t k = 0; k < a.num_strands(); ++k) {
    const uint32_t tip = a.offsets[k + 1] - 1;
    mean_dy += double(a.points[tip].y() - s.rest.strands.points[tip].y());
    inside = std::max(inside, 0.09 - double(a.points[tip].norm()));
  }
  EXPECT_LT(mean_dy / double(a.num_strands()), -0.005);
  EXPECT_LT(inside, 0.01);
}

TEST(DaldeganModel, SettlingDrapesTheStyleAndResetReturnsThere) {
  const Context ctx(2, 1);
  const auto s = setup(200);
  hair::DaldeganParams p;
  p.guides = 0;  // every strand simulated
  p.guide_segments = 20;
  p.settle_time = 0.5;
  auto sim = hair::make_daldegan1993(ctx, p, s);
  geom::StrandSet settled, again;
  sim->strands(hair::HeadMotion{}, settled);
  double dy = 0;
  for (std::size_t k = 0; k < settled.num_strands(); ++k) {
    const uint32_t tip = settled.offsets[k + 1] - 1;
    dy += double(settled.points[tip].y() - s.rest.strands.points[tip].y());
  }
  EXPECT_LT(dy / double(settled.num_strands()), -0.005);
  ASSERT_TRUE(sim->advance(ctx, 0.25, calm).ok);
  sim->reset();
  EXPECT_EQ(sim->steps(), 0u);
  sim->strands(hair::HeadMotion{}, again);
  EXPECT_EQ(again.points, settled.points);
}

TEST(DaldeganModel, BadParametersAreRefused) {
  const Context ctx(1, 1);
  const auto s = setup(10);
  hair::DaldeganParams p;
  p.guide_segments = 0;
  try {
    hair::make_daldegan1993(ctx, p, s);
    FAIL() << "accepted guide_segments = 0";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("guide_segments"));
  }
}
