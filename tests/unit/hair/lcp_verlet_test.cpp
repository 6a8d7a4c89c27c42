// Verlet neighbour lists and once-per-pair evaluation of the LCP solver (performance work on
// Bando 2003 §3.3.3): they must not change which pairs interact nor the result.
#include <gtest/gtest.h>

#include "follicle/core/rng.hpp"
#include "follicle/hair/lcp_bando2003.hpp"
#include "follicle/hair/particle_grid.hpp"
#include "lcp_test_scenes.hpp"

using namespace follicle;
using namespace follicle::hair;

namespace {
// x, v and t of a state one after another, to compare trajectories bit for bit.
std::vector<Vec3> state_vectors(const LcpState& s) {
  std::vector<Vec3> out = s.x;
  out.insert(out.end(), s.v.begin(), s.v.end());
  out.insert(out.end(), s.t.begin(), s.t.end());
  return out;
}

// Fixed sub-steps; lists rebuilt every sub-step (k = 0: no skin) or kept (k = 1: skin 0.15).
LcpParams fixed_params(int substeps, int k) {
  LcpParams p;
  p.cfl = 0;
  p.substeps = substeps;
  p.neighbour_skin = k == 0 ? 0.0 : 0.15;
  return p;
}

void expect_same_bits(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(a[i] == b[i]) << i;
}
}  // namespace

TEST(LcpVerlet, SortAndMirrorPairsEveryEntryWithItsReverse) {
  Context ctx(2);
  Rng rng(11);
  std::vector<Vec3> x(600);
  for (auto& p : x) p = Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 0.1;
  ParticleGrid grid;
  grid.build(x, 0.02);
  std::vector<uint32_t> off, nb, mirror;
  grid.neighbour_lists(ctx, x, 0.02, off, nb);
  ASSERT_GT(nb.size(), 1000u);
  ASSERT_TRUE(sort_and_mirror(ctx, off, nb, mirror));
  ASSERT_EQ(mirror.size(), nb.size());
  for (std::size_t i = 0; i + 1 < off.size(); ++i)
    for (uint32_t e = off[i]; e < off[i + 1]; ++e) {
      if (e > off[i]) {
        EXPECT_LT(nb[e - 1], nb[e]);  // sorted, no duplicates
      }
      const uint32_t m = mirror[e];
      ASSERT_LT(m, nb.size());
      EXPECT_EQ(nb[m], i);  // the reverse entry belongs to j's list
      EXPECT_TRUE(m >= off[nb[e]] && m < off[nb[e] + 1]);
      EXPECT_EQ(mirror[m], e);
    }
  // An asymmetric list is rejected.
  std::vector<uint32_t> off2{0, 1, 1}, nb2{1};
  EXPECT_FALSE(sort_and_mirror(ctx, off2, nb2, mirror));
  // So is a self entry.
  std::vector<uint32_t> off3{0, 2, 3}, nb3{1, 0, 0};
  EXPECT_FALSE(sort_and_mirror(ctx, off3, nb3, mirror));
  // Duplicates that are symmetric as multisets: the k-th (0 -> 1) pairs with the k-th (1 -> 0).
  std::vector<uint32_t> off4{0, 2, 4}, nb4{1, 1, 0, 0};
  ASSERT_TRUE(sort_and_mirror(ctx, off4, nb4, mirror));
  EXPECT_EQ(mirror, (std::vector<uint32_t>{2, 3, 0, 1}));
  // Duplicates on one side only are not symmetric.
  std::vector<uint32_t> off5{0, 2, 3}, nb5{1, 1, 0};
  EXPECT_FALSE(sort_and_mirror(ctx, off5, nb5, mirror));
}

TEST(LcpVerlet, ACommonShiftOfTheHairKeepsTheLists) {
  // |d_i - d_j| <= |d_i - u| + |d_j - u| for any u: when the hair moves as a whole (roots fixed)
  // by more than half the skin, the lists still hold every pair within 2h with u = the centre
  // of the displacements, so they are not rebuilt; the result is that of lists rebuilt every
  // sub-step, bit for bit.
  Context ctx(2);
  auto sc = test::lcp_small_scene(ctx, 0.016);
  std::vector<Vec3> out[2];
  std::size_t builds[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    LcpSolver solver(fixed_params(1, k), sc.init.model, &sc.body);
    LcpState s = solver.rest_state();
    LcpWorkspace ws;
    LcpStepInput in;
    in.dt = 1e-4;
    ASSERT_TRUE(solver.step(ctx, in, s, ws).ok);
    // 0.8 skin: beyond the classic test (max |d| < skin / 2), within the centred one.
    const double shift = 0.8 * 0.15 * 2 * solver.model().h;
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (!solver.model().root[i]) s.x[i] += Vec3(shift, 0, 0);
    for (int f = 0; f < 3; ++f) ASSERT_TRUE(solver.step(ctx, in, s, ws).ok);
    out[k] = state_vectors(s);
    builds[k] = ws.nbr_builds;
  }
  expect_same_bits(out[0], out[1]);
  EXPECT_EQ(builds[0], 4u);  // every sub-step
  EXPECT_EQ(builds[1], 1u);  // the first one only
}

TEST(LcpVerlet, SkinChangesNothingButTheRebuildCount) {
  // The kernel vanishes beyond 2h, so lists with a skin (rebuilt rarely) and lists rebuilt every
  // sub-step (skin 0) must give bit-identical trajectories, during a head shake that moves the
  // particles enough to force several rebuilds.
  Context ctx(2);
  auto sc = test::lcp_small_scene(ctx, 0.016);
  const auto track = anim::RigidMotionTrack::shake(Vec3::Zero(), Vec3::UnitY(), 0.7, 2, 0.0, 0.75);
  std::vector<Vec3> out[2];
  std::size_t builds[2] = {0, 0}, early = 0;
  int substeps = 0;
  for (int k = 0; k < 2; ++k) {
    LcpParams p;
    p.neighbour_skin = k == 0 ? 0.0 : 0.15;
    LcpSolver solver(p, sc.init.model, &sc.body);
    LcpState s = solver.rest_state();
    LcpWorkspace ws;
    for (int f = 0; f < 6; ++f) {
      LcpStepInput in;
      in.dt = 1.0 / 60;
      in.head = track.sample(f * in.dt);
      const auto rep = solver.step(ctx, in, s, ws);
      ASSERT_TRUE(rep.ok) << rep.message;
      if (k == 0) substeps += rep.substeps;
    }
    out[k] = state_vectors(s);
    builds[k] = ws.nbr_builds;
    if (k == 1) early = ws.nbr_early_builds;
  }
  expect_same_bits(out[0], out[1]);
  EXPECT_EQ(builds[0], std::size_t(substeps));
  // Most rebuilds were decided from the displacements measured at the end of the sub-step
  // before (the first pass of the sub-step is then not run twice).
  EXPECT_GT(early, 0u);
  EXPECT_LE(early, builds[1]);
  EXPECT_GT(builds[1], 1u);             // the shake moved particles by more than the skin
  EXPECT_LT(builds[1] * 2, builds[0]);  // but far fewer rebuilds than sub-steps
  std::printf("Verlet lists: %zu builds for %d sub-steps (without skin: %zu)\n", builds[1],
              substeps, builds[0]);
}

TEST(LcpVerlet, PositionsScatteredBetweenStepsRebuildTheLists) {
  // The displacement test of a sub-step may use the displacements measured at the end of the
  // last one, but not when the caller moved particles in between: here by random offsets of up
  // to 1.5 skins per axis (new pairs come within 2h), which must give what lists rebuilt every
  // sub-step give, bit for bit.
  Context ctx(2);
  auto sc = test::lcp_small_scene(ctx, 0.016);
  std::vector<Vec3> out[2];
  for (int k = 0; k < 2; ++k) {
    LcpSolver solver(fixed_params(2, k), sc.init.model, &sc.body);
    LcpState s = solver.rest_state();
    LcpWorkspace ws;
    LcpStepInput in;
    in.dt = 1e-4;
    Rng rng(5);
    const double skin = 0.15 * 2 * solver.model().h;
    for (int f = 0; f < 4; ++f) {
      ASSERT_TRUE(solver.step(ctx, in, s, ws).ok);
      for (std::size_t i = 0; i < s.x.size(); ++i)
        if (!solver.model().root[i])
          s.x[i] += Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * 3 * skin;
    }
    out[k] = state_vectors(s);
  }
  expect_same_bits(out[0], out[1]);
}

TEST(LcpVerlet, ParallelGridBuildMatchesSerialBuild) {
  // ParticleGrid::build(ctx, ...) computes cells in parallel but must give the serial order.
  Context ctx(2);
  Rng rng(3);
  std::vector<Vec3> x(9000);
  for (auto& p : x)
    p = Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 0.2 - Vec3::Constant(0.1);
  ParticleGrid serial, parallel;
  serial.build(x, 0.015);
  parallel.build(ctx, x, 0.015);
  std::vector<uint32_t> off_s, nb_s, off_p, nb_p;
  serial.neighbour_lists(ctx, x, 0.015, off_s, nb_s);
  parallel.neighbour_lists(ctx, x, 0.015, off_p, nb_p);
  ASSERT_GT(nb_s.size(), x.size());
  EXPECT_EQ(off_s, off_p);
  EXPECT_EQ(nb_s, nb_p);  // same pairs in the same order
}

TEST(LcpVerlet, PositionsEditedBetweenStepsAreNotServedFromTheCache) {
  // step() keeps the connection geometry and the neighbour lists of the last sub-step for the
  // next call when the positions are unchanged. A caller that moves particles between steps
  // must get exactly what a fresh workspace gives.
  Context ctx(2);
  auto sc = test::lcp_small_scene(ctx, 0.016);
  LcpSolver solver(fixed_params(2, 1), sc.init.model, &sc.body);
  std::vector<Vec3> out[3];
  for (int k = 0; k < 3; ++k) {
    LcpState s = solver.rest_state();
    LcpWorkspace ws;
    LcpStepInput in;
    in.dt = 4e-4;
    for (int f = 0; f < 6; ++f) {
      const auto rep = solver.step(ctx, in, s, ws);
      ASSERT_TRUE(rep.ok) << rep.message;
      if (k > 0)  // the caller moves the hair (k = 2: and starts from a fresh workspace)
        for (std::size_t i = 0; i < s.x.size(); ++i)
          if (!solver.model().root[i]) s.x[i].y() -= 2e-4 * double(1 + i % 3);
      if (k == 2) ws = LcpWorkspace{};
    }
    out[k] = state_vectors(s);
  }
  expect_same_bits(out[1], out[2]);
  bool moved = false;  // the edit had an effect
  for (std::size_t i = 0; i < out[0].size() && !moved; ++i) moved = !(out[0][i] == out[1][i]);
  EXPECT_TRUE(moved);
}
