// The wisp model (Daldegan et al. 1993 §3.3): binding to the nearest guide root, followers that
// reproduce the rest hair, follow translations and rigid head motion, guides and followers of
// different point counts (arc-length fractions), the paper's jittered copies, bad inputs.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "follicle/core/context.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/hair/wisp_daldegan1993.hpp"

using namespace follicle;
using namespace follicle::hair;

namespace {

Vec3 cap_point(Rng& rng, double R) {
  const double a = rng.uniform(0.0, 1.3), b = rng.uniform(0.0, 2 * kPi);
  return R * Vec3(std::sin(a) * std::cos(b), std::cos(a), std::sin(a) * std::sin(b));
}

// A curly strand of `n` points and length about L from `root` (shape varies with `seed`).
std::vector<Vec3f> curly(const Vec3& root, int n, double L, double seed) {
  std::vector<Vec3f> pts;
  for (int i = 0; i < n; ++i) {
    const double u = double(i) / (n - 1);
    pts.push_back((root + L * Vec3(0.3 * std::sin(7 * u + seed), -u,
                                   0.2 * std::cos(5 * u + seed) - 0.2 * std::cos(seed)))
                      .cast<float>());
  }
  return pts;
}

struct Hair {
  geom::StrandSet guides, full;
};

Hair make_hair(int guides, int followers, uint64_t seed) {
  Hair h;
  Rng rng(seed);
  for (int g = 0; g < guides; ++g) h.guides.add_strand(curly(cap_point(rng, 0.1), 9, 0.2, g));
  for (int f = 0; f < followers; ++f)
    h.full.add_strand(curly(cap_point(rng, 0.1), 5 + f % 13, rng.uniform(0.1, 0.3), 0.1 * f));
  return h;
}

geom::StrandSet moved(const geom::StrandSet& s, const Mat3& R, const Vec3& t) {
  geom::StrandSet out = s;
  for (auto& p : out.points) p = (R * p.cast<double>() + t).cast<float>();
  return out;
}

}  // namespace

TEST(Wisps, BindingPicksTheNearestRoot) {
  const Hair h = make_hair(300, 2000, 3);
  const WispBinding b = bind_wisps(h.guides, h.full, WispParams{});
  ASSERT_EQ(b.num_followers(), h.full.num_strands());
  ASSERT_EQ(b.num_guides(), h.guides.num_strands());
  for (std::size_t f = 0; f < h.full.num_strands(); ++f) {
    const Vec3 r = h.full.points[h.full.offsets[f]].cast<double>();
    double best = 1e30;
    uint32_t bi = 0;
    for (std::size_t g = 0; g < h.guides.num_strands(); ++g) {
      const double d = (h.guides.points[h.guides.offsets[g]].cast<double>() - r).squaredNorm();
      if (d < best) {
        best = d;
        bi = uint32_t(g);
      }
    }
    ASSERT_EQ(b.guide[f], bi) << f;
  }
  // A follower far outside the guides' box still finds its nearest guide.
  geom::StrandSet far;
  far.add_strand({Vec3f(3.0f, -2.0f, 1.0f), Vec3f(3.0f, -2.1f, 1.0f)});
  const WispBinding bf = bind_wisps(h.guides, far, WispParams{});
  double best = 1e30;
  uint32_t bi = 0;
  for (std::size_t g = 0; g < h.guides.num_strands(); ++g) {
    const double d =
        (h.guides.points[h.guides.offsets[g]].cast<double>() - Vec3(3, -2, 1)).squaredNorm();
    if (d < best) {
      best = d;
      bi = uint32_t(g);
    }
  }
  EXPECT_EQ(bf.guide[0], bi);
  // The parallel binding is the same.
  Context ctx(2, 1);
  const WispBinding bp = bind_wisps(ctx, h.guides, h.full, WispParams{});
  EXPECT_EQ(bp.guide, b.guide);
  EXPECT_EQ(bp.u, b.u);
}

TEST(Wisps, StillGuidesReproduceTheRestHairExactly) {
  const Hair h = make_hair(40, 500, 5);
  const WispBinding b = bind_wisps(h.guides, h.full, WispParams{});
  geom::StrandSet out;
  apply_wisps(b, h.guides, h.guides, Quat::Identity(), out);
  ASSERT_EQ(out.offsets, h.full.offsets);
  ASSERT_EQ(out.points.size(), h.full.points.size());
  EXPECT_EQ(std::memcmp(out.points.data(), h.full.points.data(), out.points.size() * sizeof(Vec3f)),
            0);
  // Same through the HeadMotion overload and the parallel one.
  geom::StrandSet out2, out3;
  apply_wisps(b, h.guides, h.guides, HeadMotion{}, out2);
  Context ctx(2, 1);
  apply_wisps(ctx, b, h.guides, h.guides, Quat::Identity(), out3);
  EXPECT_EQ(out2.points, out.points);
  EXPECT_EQ(out3.points, out.points);
}

TEST(Wisps, FollowersFollowTranslationAndRigidHeadMotion) {
  const Hair h = make_hair(40, 500, 7);
  for (const char* mode : {"offset", "paper"}) {
    WispParams p;
    p.mode = mode;
    p.jitter = 0.0;
    const WispBinding b = bind_wisps(h.guides, h.full, p);
    geom::StrandSet rest_out;
    apply_wisps(b, h.guides, h.guides, Quat::Identity(), rest_out);
    // Translation of the guides translates the followers.
    const Vec3 t(0.03, -0.2, 0.11);
    geom::StrandSet out;
    apply_wisps(b, h.guides, moved(h.guides, Mat3::Identity(), t), Quat::Identity(), out);
    for (std::size_t k = 0; k < out.points.size(); ++k)
      ASSERT_LT((out.points[k] - rest_out.points[k] - t.cast<float>()).norm(), 1e-6) << mode << k;
    // A rigid head motion (guides rotated and moved, rotation given) moves the followers rigidly.
    const Quat q(Eigen::AngleAxisd(0.8, Vec3(0.2, 1.0, -0.3).normalized()));
    const Mat3 R = q.toRotationMatrix();
    apply_wisps(b, h.guides, moved(h.guides, R, t), q, out);
    for (std::size_t k = 0; k < out.points.size(); ++k)
      ASSERT_LT((out.points[k].cast<double>() - (R * rest_out.points[k].cast<double>() + t)).norm(),
                2e-6)
          << mode << k;
  }
}

TEST(Wisps, DifferentPointCountsUseArcLengthFractions) {
  // Guide: straight along +x, 5 points over 1 m; now bent into an L (up to x = 0.5, then +y).
  geom::StrandSet guide, guide_now, full;
  guide.add_strand(
      {Vec3f(0, 0, 0), Vec3f(0.25f, 0, 0), Vec3f(0.5f, 0, 0), Vec3f(0.75f, 0, 0), Vec3f(1, 0, 0)});
  guide_now.add_strand({Vec3f(0, 0, 0), Vec3f(0.25f, 0, 0), Vec3f(0.5f, 0, 0),
                        Vec3f(0.5f, 0.25f, 0), Vec3f(0.5f, 0.5f, 0)});
  // Follower: 11 points, half the length, 0.1 to the side, unevenly spaced.
  std::vector<Vec3f> f;
  for (int i = 0; i <= 10; ++i) {
    const double u = std::pow(i / 10.0, 1.5);
    f.push_back(Vec3f(float(0.5 * u), 0.0f, 0.1f));
  }
  full.add_strand(f);
  const WispBinding b = bind_wisps(guide, full, WispParams{});
  geom::StrandSet out;
  apply_wisps(b, guide, guide_now, Quat::Identity(), out);
  ASSERT_EQ(out.points.size(), 11u);
  for (int i = 0; i <= 10; ++i) {
    const double u = std::pow(i / 10.0, 1.5);  // the follower's arc-length fraction
    const Vec3 g_rest(u, 0, 0);
    const Vec3 g_now = u <= 0.5 ? Vec3(u, 0, 0) : Vec3(0.5, u - 0.5, 0);
    const Vec3 expect = g_now + (Vec3(0.5 * u, 0, 0.1) - g_rest);
    EXPECT_LT((out.points[std::size_t(i)].cast<double>() - expect).norm(), 1e-6) << i;
  }
  // Paper mode: the follower takes the guide's shape from its own root.
  WispParams pp;
  pp.mode = "paper";
  pp.jitter = 0.0;
  const WispBinding bp = bind_wisps(guide, full, pp);
  apply_wisps(bp, guide, guide_now, Quat::Identity(), out);
  for (int i = 0; i <= 10; ++i) {
    const double u = std::pow(i / 10.0, 1.5);
    const Vec3 g_now = u <= 0.5 ? Vec3(u, 0, 0) : Vec3(0.5, u - 0.5, 0);
    EXPECT_LT((out.points[std::size_t(i)].cast<double>() - (g_now + Vec3(0, 0, 0.1))).norm(), 1e-6);
  }
  // A one-point follower and a one-point guide.
  geom::StrandSet dot_guide, dot_full;
  dot_guide.add_strand({Vec3f(1, 2, 3)});
  dot_full.add_strand({Vec3f(1, 2, 4)});
  const WispBinding bd = bind_wisps(dot_guide, dot_full, WispParams{});
  apply_wisps(bd, dot_guide, moved(dot_guide, Mat3::Identity(), Vec3(1, 0, 0)), Quat::Identity(),
              out);
  EXPECT_LT((out.points[0] - Vec3f(2, 2, 4)).norm(), 1e-6);
}

TEST(Wisps, PaperModeJitterIsBoundedAndSeeded) {
  const Hair h = make_hair(30, 400, 11);
  WispParams p;
  p.mode = "paper";
  p.jitter = 0.003;
  const WispBinding b = bind_wisps(h.guides, h.full, p);
  geom::StrandSet out;
  apply_wisps(b, h.guides, h.guides, Quat::Identity(), out);
  double largest = 0;
  for (std::size_t f = 0; f < h.full.num_strands(); ++f) {
    const Vec3 root = h.full.points[h.full.offsets[f]].cast<double>();
    const double d = (out.points[out.offsets[f]].cast<double>() - root).norm();
    largest = std::max(largest, d);
    EXPECT_LE(d, 0.003 + 1e-6);
  }
  EXPECT_GT(largest, 0.002);  // the jitter is there
  const WispBinding same = bind_wisps(h.guides, h.full, p);
  EXPECT_EQ(same.shift.size(), b.shift.size());
  EXPECT_EQ(std::memcmp(same.shift.data(), b.shift.data(), b.shift.size() * sizeof(Vec3f)), 0);
  p.seed = 2;
  const WispBinding other = bind_wisps(h.guides, h.full, p);
  EXPECT_NE(std::memcmp(other.shift.data(), b.shift.data(), b.shift.size() * sizeof(Vec3f)), 0);
}

TEST(Wisps, BadInputs) {
  const Hair h = make_hair(5, 20, 13);
  WispParams p;
  p.mode = "tufts";
  try {
    bind_wisps(h.guides, h.full, p);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("wisps.mode"), std::string::npos);
  }
  p = {};
  p.jitter = -1;
  EXPECT_THROW(p.validate(), Error);
  EXPECT_THROW(bind_wisps(geom::StrandSet{}, h.full, WispParams{}), Error);
  const WispBinding b = bind_wisps(h.guides, h.full, WispParams{});
  geom::StrandSet fewer = h.guides, out;
  fewer.points.pop_back();
  fewer.offsets.back() -= 1;
  EXPECT_THROW(apply_wisps(b, h.guides, fewer, Quat::Identity(), out), Error);
  EXPECT_THROW(apply_wisps(b, fewer, h.guides, Quat::Identity(), out), Error);
}

// 150,000 followers on 1,000 guides (roots only matter): binds in well under a second on the
// reference machine; printed, never asserted.
TEST(Wisps, LargeBinding) {
  Rng rng(17);
  geom::StrandSet guides, full;
  for (int g = 0; g < 1000; ++g) {
    const Vec3 r = cap_point(rng, 0.1);
    guides.add_strand({r.cast<float>(), (1.1 * r).cast<float>()});
  }
  for (int f = 0; f < 150000; ++f) {
    const Vec3 r = cap_point(rng, 0.1);
    full.add_strand({r.cast<float>(), (1.1 * r).cast<float>()});
  }
  Context ctx(2, 1);
  const auto t0 = std::chrono::steady_clock::now();
  const WispBinding b = bind_wisps(ctx, guides, full, WispParams{});
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(b.num_followers(), 150000u);
  // Spot-check against brute force.
  for (std::size_t f = 0; f < 150000; f += 997) {
    const Vec3 r = full.points[full.offsets[f]].cast<double>();
    double best = 1e30;
    uint32_t bi = 0;
    for (std::size_t g = 0; g < 1000; ++g) {
      const double d = (guides.points[guides.offsets[g]].cast<double>() - r).squaredNorm();
      if (d < best) {
        best = d;
        bi = uint32_t(g);
      }
    }
    EXPECT_EQ(b.guide[f], bi);
  }
  if (std::getenv("FOLLICLE_HINGE_MEASURE")) std::printf("bind 150k x 1k: %.3f s\n", s);
}
